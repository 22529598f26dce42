"""alternatives.parquet read by pyarrow, pandas and DuckDB holds the records of
alternatives.jsonl (issue 35): every column of every row equals the record's value at the
column's path (the file's own `foldsynth:columns` metadata says which), and the derived
columns agree with summary.json."""

import json

import pytest

pq = pytest.importorskip("pyarrow.parquet")


@pytest.fixture(scope="module")
def run(tmp_path_factory, task):
    out = tmp_path_factory.mktemp("pq") / "run"
    task.synthesize(out=str(out), n_max=2, export=False)
    return out


def value_at(record, path):
    v = record
    for p in path:
        if not isinstance(v, dict) or p not in v:
            return None
        v = v[p]
    return v


def test_every_row_is_its_record(run):
    table = pq.read_table(run / "alternatives.parquet")
    columns = json.loads(table.schema.metadata[b"foldsynth:columns"])
    assert [c["name"] for c in columns] == table.column_names
    rows = table.to_pylist()
    with open(run / "alternatives.jsonl") as f:
        records = [json.loads(line) for line in f if line.strip()]
    assert len(rows) == len(records) > 0
    for row, rec in zip(rows, records):
        assert row["other"] is None, row["other"]
        for c in columns:
            if not c["path"]:
                continue
            want, got = value_at(rec, c["path"]), row[c["name"]]
            if c["kind"] == "json" and got is not None:
                got = json.loads(got)
            if c["kind"] == "joined" and got is not None:
                got = got.split(",")
            assert got == want, (rec["key"], c["name"])


def test_pandas_and_duckdb_see_the_designs(run):
    pd = pytest.importorskip("pandas")
    duckdb = pytest.importorskip("duckdb")
    with open(run / "summary.json") as f:
        summary = json.load(f)
    df = pd.read_parquet(run / "alternatives.parquet")
    assert len(df) == summary["alternatives"]
    assert sorted(df[df["design"]]["id"]) == sorted(summary["designs"])
    per_level = duckdb.sql(
        f"SELECT level, count(*) FROM '{run / 'alternatives.parquet'}' GROUP BY level ORDER BY level"
    ).fetchall()
    assert dict(per_level) == {
        lv["level"]: lv["alternatives"] for lv in summary["levels"] if lv["alternatives"]
    }
