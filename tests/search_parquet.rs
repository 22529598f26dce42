//! `alternatives.parquet` (issue 35): every run, every shard and every merge writes the
//! records of `alternatives.jsonl` again as a columnar file; read back, every row is the
//! record of the same line, field for field, and the derived columns agree with the
//! summary (the designs and their ids).

use foldsynth::search::AlternativeRecord;
use foldsynth::search::parquet::{read_records, read_rows, write_parquet};
use serde_json::{Value, json};
use std::path::Path;
use std::process::{Command, Output};

const GRIPPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml");

fn foldsynth(cwd: &Path, args: &[&str]) -> Output {
    let o = Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("run foldsynth");
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// A record as its type writes it: absent and null optional fields alike, every number
/// as the record holds it.
fn typed(v: &Value) -> Value {
    let rec: AlternativeRecord = serde_json::from_value(v.clone()).expect("a record");
    serde_json::to_value(rec).unwrap()
}

/// Every line of `OUT/alternatives.jsonl` is the row of the same place in
/// `OUT/alternatives.parquet`; the number of rows.
fn same_records(out: &Path) -> usize {
    let text = std::fs::read_to_string(out.join("alternatives.jsonl")).unwrap();
    let lines: Vec<Value> = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let rows = read_records(&out.join("alternatives.parquet")).unwrap();
    assert_eq!(rows.len(), lines.len());
    for (k, (line, row)) in lines.iter().zip(&rows).enumerate() {
        assert_eq!(typed(line), typed(row), "record {k} ({})", line["key"]);
    }
    rows.len()
}

/// The derived columns: `design` marks exactly the summary's designs, `id` names them.
fn designs_agree(out: &Path, summary: &Value) {
    let rows = read_rows(&out.join("alternatives.parquet")).unwrap();
    let mut designs: Vec<String> = rows
        .iter()
        .filter(|r| r["design"] == json!(true))
        .map(|r| r["id"].as_str().unwrap().to_string())
        .collect();
    let mut expected: Vec<String> = summary["designs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d.as_str().unwrap().to_string())
        .collect();
    designs.sort();
    expected.sort();
    assert_eq!(designs, expected);
    for r in &rows {
        assert!(r["id"].as_str().unwrap().starts_with('g'), "{r:?}");
    }
}

#[test]
fn a_run_its_resume_and_a_merge_of_shards_write_the_same_records_as_parquet() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tmp.path().join("run");
    let run_s = run.to_str().unwrap();
    let base = [
        "synthesize",
        GRIPPER,
        "--n-max",
        "2",
        "--no-export",
        "--json",
    ];
    let o = foldsynth(tmp.path(), &[&base[..], &["--out", run_s]].concat());
    let summary: Value = serde_json::from_slice(&o.stdout).unwrap();
    let n = same_records(&run);
    assert_eq!(n as u64, summary["alternatives"].as_u64().unwrap());
    designs_agree(&run, &summary);
    assert!(
        !summary["designs"].as_array().unwrap().is_empty(),
        "the check of the derived columns needs a design"
    );

    // A resumed run reuses every record and writes the file again from them.
    foldsynth(
        tmp.path(),
        &[&base[..], &["--out", run_s, "--resume"]].concat(),
    );
    assert_eq!(same_records(&run), n);

    // Two shards and their merge: each shard's file, and the merged run's.
    let mut shards = Vec::new();
    for k in 1..=2 {
        let dir = tmp.path().join(format!("shard{k}"));
        let spec = format!("{k}/2");
        foldsynth(
            tmp.path(),
            &[
                &base[..],
                &["--out", dir.to_str().unwrap(), "--shard", &spec],
            ]
            .concat(),
        );
        same_records(&dir);
        shards.push(dir);
    }
    let merged = tmp.path().join("merged");
    let o = foldsynth(
        tmp.path(),
        &[
            "merge",
            shards[0].to_str().unwrap(),
            shards[1].to_str().unwrap(),
            "--out",
            merged.to_str().unwrap(),
            "--no-export",
            "--json",
        ],
    );
    let merged_summary: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(same_records(&merged), n);
    designs_agree(&merged, &merged_summary);
}

#[test]
fn fields_no_column_holds_come_back_whole() {
    let tmp = tempfile::tempdir().unwrap();
    let run = tmp.path().join("run");
    foldsynth(
        tmp.path(),
        &[
            "synthesize",
            GRIPPER,
            "--n-max",
            "1",
            "--no-export",
            "--out",
            run.to_str().unwrap(),
        ],
    );
    let text = std::fs::read_to_string(run.join("alternatives.jsonl")).unwrap();
    let records: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let verified = records.iter().position(|r| r["verification"].is_object());
    let mut first = records[verified.expect("a verified alternative")].clone();
    // A field newer than the schema, a verification with a field more, a graph index no
    // i64 holds, and modes a joined text could not give back.
    first["future"] = json!({"a": [1, 2.5, "x"]});
    first["verification"]["new_measure"] = json!(3);
    first["graph"] = json!(1u64 << 63);
    first["modes"] = json!(["up,down"]);
    let lines = format!("{first}\n{}\n", records[0]);
    let jsonl = tmp.path().join("edited.jsonl");
    std::fs::write(&jsonl, &lines).unwrap();
    let (pq, part) = (tmp.path().join("edited.parquet"), tmp.path().join("t"));
    assert_eq!(write_parquet(&jsonl, &part, &pq).unwrap(), 2);
    let rows = read_records(&pq).unwrap();
    let back = rows[0].as_object().unwrap();
    for field in ["future", "verification", "graph", "modes"] {
        assert_eq!(back[field], first[field], "{field}");
    }
    for (k, v) in first.as_object().unwrap() {
        if !v.is_null() {
            assert!(back.contains_key(k), "{k} lost");
        }
    }
    let raw = read_rows(&pq).unwrap();
    assert!(raw[0].contains_key("other") && !raw[1].contains_key("other"));
    assert!(!raw[0].contains_key("verification_isometry_max") && !raw[0].contains_key("graph"));
    assert!(raw[1].contains_key("graph") && raw[1].contains_key("key"));
}
