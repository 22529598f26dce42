"""foldsynth.synthesize → Run → DataFrames, designs, FOLD documents, frames and models
(issue 35): each checked against the files the run wrote, the CLI, or geometry."""

import json
import os
import pathlib
import signal
import subprocess

import numpy as np
import pytest

import foldsynth
from conftest import ROOT

N_MAX, STARTS = 2, 8


@pytest.fixture(scope="module")
def events():
    return []


@pytest.fixture(scope="module")
def run(task, events, tmp_path_factory):
    out = tmp_path_factory.mktemp("py") / "run"
    return foldsynth.synthesize(
        task, out=out, n_max=N_MAX, starts=STARTS, export=False, progress=events.append
    )


def lines(path):
    return [json.loads(l) for l in pathlib.Path(path).read_text().splitlines() if l.strip()]


def test_the_callback_hears_every_phase_to_its_end(run, events):
    assert all(isinstance(e, foldsynth.ProgressEvent) for e in events)
    ends = [e for e in events if e.finished]
    phases = [e.phase for e in ends]
    assert phases[0] == "enumerate graphs" and "compile + optimize + check" in phases
    (optimize,) = [e for e in ends if e.phase == "compile + optimize + check"]
    # A fresh run evaluates every alternative once: the phase's count is the records'.
    assert optimize.done == optimize.total == run.summary["alternatives"]
    assert optimize.unit == "alternatives"
    # Counts within a phase never go back.
    for a, b in zip(events, events[1:]):
        if a.phase == b.phase and not a.finished:
            assert b.done >= a.done


def test_a_run_as_data_is_its_files(run):
    records = lines(run.path / "alternatives.jsonl")
    df = run.alternatives()
    assert len(df) == len(records) == run.summary["alternatives"]
    assert list(df["key"]) == [r["key"] for r in records]
    # Nested fields as dotted columns, values unchanged.
    r = next(r for r in records if r.get("robustness"))
    row = df[df["key"] == r["key"]].iloc[0]
    assert row["robustness.score"] == r["robustness"]["score"]
    assert row["verification.isometry_max"] == r["verification"]["isometry_max"]
    for name, value in r["variables"].items():
        assert row[f"variables.{name}"] == value

    designs = run.designs()
    assert list(designs["id"]) == run.ranking == [d["id"] for d in run.summary["ranking"]]
    assert list(designs["rank"]) == list(range(1, len(designs) + 1))
    assert sorted(run.ranking) == sorted(run.design_ids)
    assert len(designs) == run.summary["feasible"] > 0
    assert designs["verification.rigid_over_motion"].all()
    assert designs["meets_target"].all() and designs["obstacle_free"].all()
    assert list(designs["score"]) == sorted(designs["score"], reverse=True)
    # Every id names the design file the search wrote.
    assert all((run.path / "designs" / f"{i}.json").exists() for i in designs["id"])


def test_pyarrow_and_records_hold_the_same_rows(run):
    pa = pytest.importorskip("pyarrow")
    table = run.alternatives(as_="arrow")
    assert isinstance(table, pa.Table)
    rows = run.alternatives(as_="records")
    df = run.alternatives(as_="pandas")
    assert table.num_rows == len(rows) == len(df)
    assert table.column_names == list(df.columns)
    assert table.column("objective").to_pylist() == [r["objective"] for r in rows]


def test_open_reads_what_synthesize_returned(run):
    again = foldsynth.Run.open(run.path)
    assert again.summary == run.summary and again.settings == run.settings
    assert again.task is None
    with pytest.raises(foldsynth.FoldsynthError, match="does not know its task"):
        again.design(1).model()
    with pytest.raises(foldsynth.FoldsynthError, match="not a foldsynth run"):
        foldsynth.Run.open(ROOT / "grammar")
    with pytest.raises(foldsynth.FoldsynthError, match="no design of rank"):
        run.design(len(run.ranking) + 1)


def test_a_design_folds_rigidly_and_its_model_agrees(run, task):
    best = run.design(1)
    assert best.id == run.ranking[0] and best.rank == 1
    f = best.frames
    pattern = best.data["pattern"]
    n_v, n_e = len(pattern["vertices"]), len(pattern["edges"])
    assert f.coords.shape == (len(f.t), n_v, 3) and f.fold_angles.shape == (len(f.t), n_e)
    assert f.t[0] == 0.0 and np.all(np.diff(f.t) > 0)
    # Rigid folding is an isometry: every edge keeps its flat length in every state.
    flat = np.array(pattern["vertices"], dtype=float)
    ends = np.array([e["v"] for e in pattern["edges"]])
    length0 = np.linalg.norm(flat[ends[:, 0]] - flat[ends[:, 1]], axis=1)
    lengths = np.linalg.norm(f.coords[:, ends[:, 0]] - f.coords[:, ends[:, 1]], axis=2)
    assert np.abs(lengths - length0).max() < 1e-9
    # The flat state, to the ten significant digits a design file stores positions with.
    np.testing.assert_allclose(f.coords[0][:, :2], flat, rtol=1e-9, atol=1e-12)
    # Its fold angles are read from the positions: valley positive, 0 on the boundary, and
    # each crease's angle at the folded form is the one the FOLD file carries.
    kinds = [e["kind"] for e in pattern["edges"]]
    assert all(f.fold_angles[:, k].max() == 0.0 for k, kd in enumerate(kinds) if kd == "boundary")
    # (read from ten-digit positions: within 1e-7 rad; docs/outputs.md measured 4.6e-8)
    np.testing.assert_allclose(f.fold_angles[0], 0.0, atol=1e-7)
    assert np.array_equal(best.tip_path, f.coords[:, best.gripping_vertex - 1])

    # The compiled model at the design reproduces the search's Ω*.
    model = best.model()
    assert model.graph == best.sequence and model.candidate == best.candidate
    x = best.x(model)
    assert model.omega(x, best.modes) == pytest.approx(best.objective, rel=1e-9, abs=1e-15)
    assert best.objective <= model.threshold
    g, _ = model.constraints_and_jacobian(x, best.modes)
    assert g.min() >= -1e-6
    assert best.verification["rigid_over_motion"] is True
    assert best.robustness["score"] == run.summary["ranking"][0]["score"]


def test_a_designs_fold_is_the_clis(run, cli, tmp_path):
    best = run.design(1)
    doc = best.fold()
    out = tmp_path / "cli.fold"
    subprocess.run(
        [str(cli), "export", str(best.path), "--format", "fold", "--out", str(out)], check=True
    )
    assert doc == json.loads(out.read_text())
    pattern = best.data["pattern"]
    assert len(doc["vertices_coords"]) == len(pattern["vertices"])
    assert doc["edges_vertices"] == [e["v"] for e in pattern["edges"]]
    saved = best.save_fold(tmp_path / "best.fold")
    assert json.loads(saved.read_text()) == doc


def test_ctrl_c_stops_the_search_and_resume_finishes_it(run, task, tmp_path):
    out = tmp_path / "stopped"

    def interrupt(e):
        if e.phase == "compile + optimize + check":
            signal.raise_signal(signal.SIGINT)

    # Python turns SIGINT into KeyboardInterrupt only where it was not ignored when the
    # interpreter started; a job started in the background by a non-interactive shell (as
    # CI may be) inherits it ignored. Ctrl-C at a terminal is what this test stands for.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            foldsynth.synthesize(
                task, out=out, n_max=N_MAX, starts=STARTS, export=False, jobs=1, progress=interrupt
            )
    finally:
        signal.signal(signal.SIGINT, previous)
    stopped = foldsynth.Run.open(out)
    assert not stopped.finished
    with pytest.raises(foldsynth.FoldsynthError, match="resume"):
        stopped.summary
    kept = len(lines(out / "alternatives.jsonl"))
    assert kept < run.summary["alternatives"]

    resumed = foldsynth.synthesize(
        task, out=out, n_max=N_MAX, starts=STARTS, export=False, resume=True, progress=False
    )
    assert resumed.summary["settings"]["resumed"] == kept
    # Records are deterministic: the interrupted and resumed run is the uninterrupted one.
    full = {r["key"]: r["objective"] for r in run.records()}
    assert {r["key"]: r["objective"] for r in resumed.records()} == full
    assert resumed.ranking == run.ranking


def test_an_exception_from_the_callback_stops_the_search(task, tmp_path):
    class Stop(Exception):
        pass

    def stop(e):
        if e.phase == "compile + optimize + check":
            raise Stop

    with pytest.raises(Stop):
        # N_max 2 on one thread runs for seconds: the callback hears the optimize phase
        # long before the search ends (N_max 1 could finish between two polls).
        foldsynth.synthesize(
            task, out=tmp_path / "r", n_max=N_MAX, starts=STARTS, export=False, jobs=1, progress=stop
        )
    assert not foldsynth.Run.open(tmp_path / "r").finished


def test_open_reads_a_run_merged_from_shards(run, cli, tmp_path):
    task_file = str(ROOT / "grammar" / "gripper.toml")
    common = ["--n-max", str(N_MAX), "--starts", str(STARTS), "--no-export"]
    shards = []
    for k in (1, 2):
        d = tmp_path / f"shard{k}"
        if k == 1:
            # One shard from Python, one from the CLI: the same kind of directory.
            foldsynth.synthesize(
                task_file, out=d, shard="1/2", n_max=N_MAX, starts=STARTS, export=False,
                progress=False,
            )
        else:
            subprocess.run(
                [str(cli), "synthesize", task_file, "--shard", f"{k}/2", "--out", str(d)]
                + common,
                check=True,
                capture_output=True,
            )
        shard = foldsynth.Run.open(d)
        assert not shard.finished
        with pytest.raises(foldsynth.FoldsynthError, match="shard"):
            shard.summary
        shards.append(str(d))
    merged = tmp_path / "merged"
    subprocess.run(
        [str(cli), "merge", *shards, "--out", str(merged), "--no-export"],
        check=True,
        capture_output=True,
    )
    m = foldsynth.Run.open(merged)
    assert sorted(m.alternatives()["key"]) == sorted(run.alternatives()["key"])
    assert m.ranking == run.ranking
    assert m.design(1).objective == run.design(1).objective


def test_export_counts_as_the_cli(run, task, tmp_path):
    # export=N: every design gets its FOLD file, the N most robust every file (as --export N).
    r = foldsynth.synthesize(
        task,
        out=tmp_path / "three",
        n_max=N_MAX,
        starts=STARTS,
        export=3,
        report_motions=2,
        report_designs=4,
        progress=False,
    )
    ids = list(r.designs()["id"])
    assert ids == list(run.designs()["id"]) and len(ids) > 4
    designs = tmp_path / "three" / "designs"
    assert all((designs / f"{i}.fold").is_file() for i in ids)
    assert all(len(list((designs / i).iterdir())) == 17 for i in ids[:3])  # 15 + the print sheet (PDF, SVG)
    assert not any((designs / i).exists() for i in ids[3:])
    # report_motions=2 (--report-motions 2): the page draws the motion of the 2 most
    # robust designs, the folded form (one frame) of the others.
    html = (tmp_path / "three" / "report.html").read_text(encoding="utf-8")
    tag = '<script type="application/json" id="foldsynth-data">'
    data = json.loads(html[html.index(tag) + len(tag) :].split("</script>", 1)[0])
    drawn = {d["id"]: len(d["geometry"]["frames"]) for d in data["designs"]}
    # report_designs=4 (--report-designs 4): the 4 most robust in full, every design a row.
    assert list(drawn) == ids[:4]
    assert [drawn[i] for i in ids[:4]] == [33, 33, 1, 1]
    assert [row[0] for row in data["rows"]] == ids


def test_synthesize_rejects_bad_settings(task, tmp_path):
    for bad in (-1, 2.5, "some"):
        with pytest.raises(ValueError, match="export"):
            foldsynth.synthesize(task, out=tmp_path / "e", export=bad, progress=False)
        with pytest.raises(ValueError, match="report_motions"):
            foldsynth.synthesize(task, out=tmp_path / "m", report_motions=bad, progress=False)
        with pytest.raises(ValueError, match="report_designs"):
            foldsynth.synthesize(task, out=tmp_path / "d", report_designs=bad, progress=False)
    with pytest.raises(ValueError, match="shard"):
        foldsynth.synthesize(task, out=tmp_path / "s", shard="3/2", progress=False)
    with pytest.raises(ValueError, match="starts"):
        foldsynth.synthesize(task, out=tmp_path / "a", starts=0, progress=False)
    with pytest.raises(ValueError, match="rules"):
        foldsynth.synthesize(task, out=tmp_path / "b", rules="r9", progress=False)
    with pytest.raises(foldsynth.FoldsynthError, match="nope.toml"):
        foldsynth.synthesize(tmp_path / "nope.toml", out=tmp_path / "c", progress=False)


@pytest.mark.skipif(not os.environ.get("FOLDSYNTH_WHEEL_TEST"), reason="CI's installed-wheel run")
def test_the_package_under_test_is_the_installed_wheel():
    # CI installs the wheel `pip wheel ./python` built into a fresh venv: the tests must
    # exercise that installation, not the source tree.
    here = pathlib.Path(foldsynth.__file__).resolve()
    assert ROOT / "python" not in here.parents, here
    assert "site-packages" in here.parts
    native = pathlib.Path(foldsynth._native.__file__).name
    assert ".abi3." in native, native


def test_the_example_runs(tmp_path):
    # examples/most_robust_design.py as a user runs it, on a smaller search.
    import shutil
    import sys

    shutil.copytree(ROOT / "grammar", tmp_path / "grammar")
    script = ROOT / "examples" / "most_robust_design.py"
    r = subprocess.run(
        [sys.executable, str(script), "--n-max", "2", "--out", "ex"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    out = tmp_path / "ex"
    run = foldsynth.Run.open(out / "run")
    best = run.design(1)
    assert json.loads((out / "best.fold").read_text()) == best.fold()
    rows = (out / "tip_path.csv").read_text().splitlines()
    assert len(rows) == 1 + len(best.frames.t)
    np.testing.assert_allclose(
        [float(v) for v in rows[-1].split(",")[1:]], best.tip_path[-1], rtol=1e-15
    )
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return
    assert (out / "tip_path.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_guided_search_spends_its_budget(task, tmp_path):
    # A budget of 50 alternatives: whole models in the guided order, at least 50 and less
    # than 50 plus one model's 2^N; the summary says how much of the space it covered.
    run = foldsynth.synthesize(
        task,
        out=tmp_path / "guided",
        n_max=3,
        starts=4,
        export=False,
        strategy="guided",
        budget_alternatives=50,
        progress=False,
    )
    coverage = run.summary["coverage"]
    assert coverage["strategy"] == "guided"
    assert coverage["budget"] == {"alternatives": 50}
    assert 50 <= coverage["alternatives"] < 50 + 3 * 2**3
    assert coverage["total"] == 1194
    assert len(run.alternatives(as_="records")) == coverage["alternatives"]
    with pytest.raises(foldsynth.FoldsynthError, match="--strategy guided"):
        foldsynth.synthesize(task, out=tmp_path / "b", budget_alternatives=5, progress=False)
    with pytest.raises(ValueError, match="strategy"):
        foldsynth.synthesize(task, out=tmp_path / "c", strategy="random", progress=False)
