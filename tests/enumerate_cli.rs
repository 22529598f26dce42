//! `foldsynth enumerate`, driven through the real binary.

use std::process::Command;

use serde_json::Value;

fn foldsynth(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

#[test]
fn json_lists_every_generated_graph() {
    let (ok, out, err) = foldsynth(&["enumerate", "grammar/gripper.toml", "--format", "json"]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let mut keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    keys.sort_unstable();
    assert_eq!(keys, ["alternatives", "filtered", "generated", "graphs"]);
    let mut keys: Vec<&str> = v["graphs"][0]
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    keys.sort_unstable();
    assert_eq!(
        keys,
        [
            "alternatives",
            "internal_vertices",
            "level",
            "parent",
            "sequence",
            "status"
        ]
    );
    let graphs = v["graphs"].as_array().unwrap();
    assert_eq!(v["generated"].as_u64().unwrap() as usize, graphs.len());
    let count = |s: &str| graphs.iter().filter(|g| g["status"] == s).count() as u64;
    for s in ["isomorphic", "mirror", "invalid"] {
        assert_eq!(v["filtered"][s].as_u64().unwrap(), count(s), "{s}");
    }
    assert_eq!(count("meaningful"), 53);
    // alternatives = Σ 2^N × 3 over the meaningful graphs.
    let alt: u64 = graphs
        .iter()
        .filter(|g| g["status"] == "meaningful")
        .map(|g| 3 << g["internal_vertices"].as_u64().unwrap())
        .sum();
    assert_eq!(v["alternatives"].as_u64().unwrap(), alt);
    let g = graphs
        .iter()
        .find(|g| g["sequence"] == "2, 3, (4, 8), 4, (7, 8)")
        .unwrap();
    assert_eq!(
        (g["level"].as_u64(), g["internal_vertices"].as_u64()),
        (Some(5), Some(3))
    );
    assert_eq!(g["status"], "meaningful");
    // Parents come before their children, one level up.
    for (i, g) in graphs.iter().enumerate() {
        if let Some(p) = g["parent"].as_u64() {
            assert!((p as usize) < i);
            assert_eq!(
                graphs[p as usize]["level"].as_u64().unwrap() + 1,
                g["level"].as_u64().unwrap()
            );
        } else {
            assert_eq!(g["level"].as_u64(), Some(1));
        }
    }
}

#[test]
fn all_filters_off_gives_the_291() {
    let (ok, out, err) = foldsynth(&[
        "enumerate",
        "grammar/gripper.toml",
        "--no-iso",
        "--no-mirror",
        "--no-validity",
        "--format",
        "json",
    ]);
    assert!(ok, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["generated"], 291);
    assert_eq!(v["filtered"]["isomorphic"], 0);
    assert_eq!(v["filtered"]["mirror"], 0);
    assert_eq!(v["filtered"]["invalid"], 0);
}

#[test]
fn text_report_and_dot_tree() {
    let dir = tempfile::tempdir().unwrap();
    let dot = dir.path().join("tree.dot");
    let (ok, out, err) = foldsynth(&[
        "enumerate",
        "grammar/robotic_arm.toml",
        "--n-max",
        "2",
        "--tree",
        dot.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("N_max = 2"));
    assert!(out.contains("filters: isomorphism on, mirror on, semantic validity on"));
    assert!(out.contains("level  generated  isomorphic  mirror  invalid  meaningful"));
    // N_max = 2: 2; 2,3 2,4 (2,5 mirror); 2,3,(4,8) 2,4,(3,6) (2,4,(5,8) mirror); 2,4,(3,6),(4,7).
    assert!(out.contains("meaningful graphs (6):"), "{out}");
    assert!(out.contains("design alternatives: 66"), "{out}");
    let tree = std::fs::read_to_string(&dot).unwrap();
    assert!(tree.starts_with("digraph search_tree {"));
    assert_eq!(tree.matches(" -> ").count(), 8);
    assert_eq!(tree.matches("#aaaaaa").count(), 2);
}

#[test]
fn bad_input_is_reported_not_panicked() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        "[grammar]\nn_max = 3\n[initial_graph]\nvertices = []\n",
    )
    .unwrap();
    let (ok, _, err) = foldsynth(&["enumerate", bad.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        err.contains("bad.toml")
            && err.contains("initial_graph.vertices")
            && err.contains("no vertices"),
        "{err}"
    );
    let (ok, _, err) = foldsynth(&["enumerate", "grammar/gripper.toml", "--n-max", "9"]);
    assert!(!ok);
    assert!(
        err.contains("--n-max") && err.contains("9 is out of range") && err.contains("allowed"),
        "{err}"
    );
    let (ok, _, err) = foldsynth(&["enumerate", "no/such/task.toml"]);
    assert!(!ok);
    assert!(
        err.contains("no/such/task.toml") && err.contains("cannot read"),
        "{err}"
    );
    let (ok, _, err) = foldsynth(&["enumerate", "grammar/gripper.toml", "--format", "xml"]);
    assert!(!ok);
    assert!(err.contains("xml"), "{err}");
}
