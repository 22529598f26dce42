//! Shards and merge (issue 15) on the gripper at N_max = 2 (66 alternatives, 18 models):
//! the shards partition the search model by model, and merging them gives the run one
//! machine writes — the same records (timings aside), summary, design files and exports.
//! Bad shard specifications and bad sets of shard directories are clear errors, and
//! nothing is merged from an incomplete or foreign shard.

use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

#[path = "common/runs.rs"]
mod runs;
use runs::{design_files, records, summary};

const GRIPPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml");

fn foldsynth(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(args)
        .output()
        .expect("run foldsynth")
}

fn ok(o: Output) -> Output {
    assert!(
        o.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn err(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The search settings every run here uses.
const SETTINGS: [&str; 6] = ["--n-max", "2", "--starts", "4", "--seed", "3"];

fn shard(out: &Path, spec: &str, extra: &[&str]) -> Output {
    let mut args = vec!["synthesize", GRIPPER, "--shard", spec, "--jobs", "2"];
    args.extend(SETTINGS);
    args.extend(["--out", out.to_str().unwrap(), "--json"]);
    args.extend(extra);
    foldsynth(&args)
}

fn merge(dirs: &[PathBuf], out: &Path, extra: &[&str]) -> Output {
    let mut args: Vec<&str> = vec!["merge"];
    args.extend(dirs.iter().map(|d| d.to_str().unwrap()));
    args.extend(["--out", out.to_str().unwrap(), "--json", "--jobs", "2"]);
    args.extend(extra);
    foldsynth(&args)
}

#[test]
fn merged_shards_are_the_single_machine_run() {
    let root = tempfile::tempdir().unwrap();
    let single = root.path().join("single");
    let mut args = vec!["synthesize", GRIPPER, "--jobs", "2", "--json"];
    args.extend(SETTINGS);
    args.extend(["--out", single.to_str().unwrap()]);
    ok(foldsynth(&args));

    let dirs: Vec<PathBuf> = (1..=3)
        .map(|k| root.path().join(format!("shard{k}")))
        .collect();
    let mut keys_per_shard = Vec::new();
    for (k, d) in dirs.iter().enumerate() {
        let o = ok(shard(d, &format!("{}/3", k + 1), &[]));
        let report: Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(report["shard"], format!("{}/3", k + 1));
        assert_eq!(report["records"], report["alternatives"]);
        // A shard writes records, not designs: the merge does.
        assert!(!d.join("designs").exists());
        assert!(d.join("task.toml").is_file());
        keys_per_shard.push(records(d).into_keys().collect::<BTreeSet<_>>());
    }
    // The shards partition the alternatives, model by model.
    let whole = records(&single);
    assert_eq!(whole.len(), 66);
    let mut union = BTreeSet::new();
    let mut model_shard: BTreeMap<String, usize> = BTreeMap::new();
    for (k, keys) in keys_per_shard.iter().enumerate() {
        assert!(!keys.is_empty(), "shard {} is empty", k + 1);
        for key in keys {
            assert!(union.insert(key.clone()), "{key} in two shards");
            let model = key.rsplit_once('|').unwrap().0.to_string();
            assert_eq!(
                *model_shard.entry(model).or_insert(k),
                k,
                "{key}: model split"
            );
        }
    }
    assert_eq!(union, whole.keys().cloned().collect());

    // Given in any order, the shards merge into the single machine's run.
    let merged = root.path().join("merged");
    let order = [dirs[2].clone(), dirs[0].clone(), dirs[1].clone()];
    ok(merge(&order, &merged, &[]));
    assert_eq!(records(&merged), whole, "merged records differ");
    assert_eq!(summary(&merged), summary(&single));
    let (a, b) = (design_files(&merged), design_files(&single));
    assert!(
        a.keys().any(|k| k.ends_with(".fold")),
        "no exported design at N_max = 2"
    );
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (k, bytes) in &a {
        assert!(bytes == &b[k], "{k} differs");
    }
    assert!(merged.join("report.html").is_file());
    assert_eq!(
        std::fs::read(merged.join("settings.json")).unwrap(),
        std::fs::read(single.join("settings.json")).unwrap()
    );
    // Merging again into the same directory replaces that run.
    ok(merge(&dirs, &merged, &["--no-export"]));
    assert_eq!(records(&merged), whole);
}

#[test]
fn an_incomplete_or_foreign_shard_is_named_and_nothing_is_merged() {
    let root = tempfile::tempdir().unwrap();
    let dirs: Vec<PathBuf> = (1..=2).map(|k| root.path().join(format!("s{k}"))).collect();
    for (k, d) in dirs.iter().enumerate() {
        ok(shard(d, &format!("{}/2", k + 1), &["--no-export"]));
    }
    let out = root.path().join("out");

    // A half-written shard: the first half of its records and a torn line.
    let full = std::fs::read_to_string(dirs[1].join("alternatives.jsonl")).unwrap();
    let lines: Vec<&str> = full.lines().collect();
    let keep = lines.len() / 2;
    let mut half = lines[..keep].join("\n");
    half.push('\n');
    half.push_str(&lines[keep][..30]);
    std::fs::write(dirs[1].join("alternatives.jsonl"), &half).unwrap();
    std::fs::remove_file(dirs[1].join("shard.json")).unwrap();
    let r = merge(&dirs, &out, &[]);
    assert_eq!(r.status.code(), Some(2), "{}", err(&r));
    let missing: BTreeSet<String> = lines[keep..]
        .iter()
        .map(|l| {
            serde_json::from_str::<Value>(l).unwrap()["key"]
                .as_str()
                .unwrap()
                .to_string()
        })
        .collect();
    let e = err(&r);
    assert!(e.contains("shard 2/2"), "{e}");
    assert!(
        e.contains(&format!(
            "lacks {} of its {}",
            lines.len() - keep,
            lines.len()
        )),
        "{e}"
    );
    // The keys it names (in plan order, not the order the file had) are all missing ones.
    let named = e
        .split("e.g. ")
        .nth(1)
        .unwrap()
        .split("; resume")
        .next()
        .unwrap();
    let named: Vec<&str> = named.split("; ").filter(|k| *k != "…").collect();
    assert!(!named.is_empty(), "{e}");
    for k in named {
        assert!(missing.contains(k), "{k} is not missing: {e}");
    }
    assert!(e.contains("--shard 2/2") && e.contains("--resume"), "{e}");
    assert!(!out.exists(), "something was written for a failed merge");

    // Resuming just that shard completes it; then the merge succeeds.
    let o = ok(shard(&dirs[1], "2/2", &["--resume"]));
    let report: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["records"], lines.len());
    ok(merge(&dirs, &out, &["--no-export"]));
    assert_eq!(records(&out).len(), 66);

    // A shard of another seed, a repeated shard, a missing shard, a missing directory, a
    // whole run, a shard of another split.
    let other = root.path().join("other-seed");
    let mut args = vec!["synthesize", GRIPPER, "--shard", "2/2"];
    args.extend([
        "--n-max",
        "2",
        "--starts",
        "4",
        "--seed",
        "4",
        "--no-export",
    ]);
    args.extend(["--out", other.to_str().unwrap()]);
    ok(foldsynth(&args));
    let whole = root.path().join("whole");
    let mut args = vec!["synthesize", GRIPPER, "--no-export"];
    args.extend(SETTINGS);
    args.extend(["--out", whole.to_str().unwrap()]);
    ok(foldsynth(&args));
    let three = root.path().join("three");
    ok(shard(&three, "3/3", &["--no-export"]));
    let out2 = root.path().join("out2");
    let cases: Vec<(Vec<PathBuf>, &str)> = vec![
        (vec![dirs[0].clone(), other.clone()], "seed: 3 in"),
        (vec![dirs[0].clone(), dirs[0].clone()], "given twice"),
        (vec![dirs[0].clone()], "2/2 of this search are not given"),
        (
            vec![dirs[0].clone(), root.path().join("nowhere")],
            "no such shard directory",
        ),
        (vec![dirs[0].clone(), whole.clone()], "not a shard"),
        (vec![dirs[0].clone(), three.clone()], "split into 3 shards"),
    ];
    for (given, says) in cases {
        let r = merge(&given, &out2, &[]);
        assert_eq!(r.status.code(), Some(2), "{says}: {}", err(&r));
        assert!(err(&r).contains(says), "expected '{says}': {}", err(&r));
        assert!(!out2.exists(), "{says}: something was written");
    }
    // The merged run into a shard's own directory.
    let r = merge(&dirs, &dirs[0], &["--force"]);
    assert_eq!(r.status.code(), Some(2));
    assert!(err(&r).contains("own directory"), "{}", err(&r));
    assert!(dirs[0].join("shard.json").is_file());
    // Records of another shard in a shard's directory.
    let mixed = root.path().join("mixed");
    std::fs::create_dir_all(&mixed).unwrap();
    for f in ["settings.json", "task.toml", "manifest.json"] {
        std::fs::copy(dirs[1].join(f), mixed.join(f)).unwrap();
    }
    std::fs::copy(
        dirs[0].join("alternatives.jsonl"),
        mixed.join("alternatives.jsonl"),
    )
    .unwrap();
    let r = merge(&[dirs[0].clone(), mixed], &out2, &[]);
    assert_eq!(r.status.code(), Some(2));
    assert!(err(&r).contains("belongs to another shard"), "{}", err(&r));
    assert!(!out2.exists());
}

#[test]
fn bad_shard_specifications_are_refused() {
    let root = tempfile::tempdir().unwrap();
    for (spec, says) in [
        ("0/4", "does not exist"),
        ("5/4", "does not exist"),
        ("a/b", "not a whole number"),
        ("3", "not a shard"),
        ("1/0", "allowed 1 to"),
    ] {
        let out = root.path().join("x");
        let r = shard(&out, spec, &[]);
        assert_eq!(r.status.code(), Some(2), "{spec}: {}", err(&r));
        assert!(err(&r).contains(says), "{spec}: {}", err(&r));
        assert!(!out.exists(), "{spec}: wrote {}", out.display());
    }
    // A shard directory is a run of its shard's settings: resuming it as another shard
    // would mix two shares.
    let out = root.path().join("s");
    ok(shard(&out, "1/2", &["--no-export"]));
    let r = shard(&out, "2/2", &["--resume"]);
    assert_eq!(r.status.code(), Some(2));
    assert!(err(&r).contains("shard"), "{}", err(&r));
}
