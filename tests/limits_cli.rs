//! Issue 13's bad inputs through the real binary: every count beyond its documented limit
//! is refused before anything is allocated (exit 2, a message naming the limit), never an
//! abort; echoes of huge inputs are cut; OS errors are said once; a file of the wrong kind
//! says which command takes it; a design with absurd numbers is refused by export and
//! simulate; exit status 0 / 1 (a check failed) / 2 (bad input or usage).

use std::path::Path;
use std::process::{Command, Output};

const GRIPPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml");
const FLASHER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/flasher_adapted.toml");
const SPEC: &str = "v(up, ((80,40,40),(t,-t)), ((90,40,50),(t,-t)), (20))";

fn foldsynth(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(args)
        .output()
        .expect("run foldsynth")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Exit status 2 and every word in the message; no panic, no abort.
fn refused(args: &[&str], words: &[&str]) -> String {
    let o = foldsynth(args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    for w in words {
        assert!(err.contains(w), "{args:?}: '{w}' not in: {err}");
    }
    err
}

#[test]
fn every_count_has_a_limit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let o = out.to_str().unwrap();
    let synth = |extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = ["synthesize", GRIPPER, "--no-export", "--out", o]
            .iter()
            .map(|s| s.to_string())
            .collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let cases: Vec<(Vec<String>, &[&str])> = vec![
        (synth(&["--n-max", "50"]), &["--n-max", "allowed 1 to 6"]),
        (synth(&["--starts", "4000000000"]), &["--starts", "1000"]),
        (synth(&["--sweep", "1000000000"]), &["--sweep", "10000"]),
        (synth(&["--sweep", "0"]), &["--sweep", "allowed 2"]),
        (synth(&["--sweep", "1"]), &["--sweep", "allowed 2"]),
        (synth(&["--jobs", "100000"]), &["--jobs", "256"]),
    ];
    for (args, words) in &cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        refused(&args, words);
    }
    // Nothing was written for a refused run.
    assert!(!out.exists());
    let model = ["model", GRIPPER, "--graph", "2"];
    refused(
        &[&model[..], &["--sweep", "2000000000"]].concat(),
        &["--sweep"],
    );
    refused(
        &[&model[..], &["--optimize", "--starts", "3000000000"]].concat(),
        &["--starts"],
    );
    refused(
        &["vertex", SPEC, "--t", "0:pi:1000000000"],
        &["--t", "100000"],
    );
    refused(
        &["bench", "vertex", SPEC, "--millis", "1000000000000"],
        &["--millis"],
    );
    refused(
        &["simulate", FLASHER, "--steps", "1000000000"],
        &["--steps"],
    );
    refused(
        &["optimize-flasher", "--evals", "100000000000"],
        &["--evals"],
    );
    // check.states in a task file.
    let task = dir.path().join("states.toml");
    std::fs::write(
        &task,
        std::fs::read_to_string(GRIPPER)
            .unwrap()
            .replace("states = 16", "states = 1000000000"),
    )
    .unwrap();
    refused(
        &["synthesize", task.to_str().unwrap(), "--out", o],
        &["check.states", "at most 1000"],
    );
}

#[test]
fn echoes_are_cut_and_os_errors_said_once() {
    // A 309-digit number and a 100 KB input are not echoed back whole.
    let huge = format!("1{}", "0".repeat(308));
    let err = refused(
        &["vertex", &format!("v(up, ({huge}), (90), ((90,90),(t)))")],
        &[],
    );
    assert!(err.len() < 1500, "{} bytes: {err}", err.len());
    let big = "x".repeat(100_000);
    let err = refused(&["vertex", &big], &[]);
    assert!(err.len() < 3000, "{} bytes", err.len());
    let err = refused(&["vertex", SPEC, "--t", &big], &["--t"]);
    assert!(err.len() < 3000, "{} bytes", err.len());
    let err = refused(&["synthesize", GRIPPER, "--starts", &big], &["--starts"]);
    assert!(err.len() < 3000, "{} bytes", err.len());

    // An output directory inside a file: the OS error once.
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("file");
    std::fs::write(&file, "x").unwrap();
    let err = refused(
        &[
            "synthesize",
            GRIPPER,
            "--n-max",
            "1",
            "--out",
            file.join("sub").to_str().unwrap(),
        ],
        &["os error"],
    );
    assert_eq!(err.matches("os error").count(), 1, "{err}");

    // "vertices", not "vertexs".
    let fold = dir.path().join("x.fold");
    std::fs::write(
        &fold,
        r#"{"vertices_coords": [[0,0],[1,0],[0,1]], "faces_vertices": [[0,1,7]]}"#,
    )
    .unwrap();
    let err = refused(&["verify", fold.to_str().unwrap()], &["3 vertices"]);
    assert!(!err.contains("vertexs"), "{err}");
}

#[test]
fn a_file_of_the_wrong_kind_says_which_command_takes_it() {
    refused(
        &["simulate", GRIPPER],
        &["task file", "pattern file", "synthesize"],
    );
    refused(
        &["synthesize", FLASHER, "--no-export"],
        &["pattern file", "simulate"],
    );
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("x.toml");
    std::fs::write(&json, "{\"vertices_coords\": []}").unwrap();
    refused(&["enumerate", json.to_str().unwrap()], &["JSON"]);
}

#[test]
fn absurd_numbers_in_a_design_are_refused_by_export_and_simulate() {
    let dir = tempfile::tempdir().unwrap();
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/demo_gripper_design.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(src).unwrap()).unwrap();
    v["pattern"]["frames"][1]["coords"][2][0] = 1e308.into();
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, v.to_string()).unwrap();
    let b = bad.to_str().unwrap();
    let out = dir.path().join("bad.fold");
    refused(
        &[
            "export",
            b,
            "--format",
            "fold",
            "--out",
            out.to_str().unwrap(),
        ],
        &["pattern.frames[1].coords[2]", "1e308"],
    );
    assert!(!out.exists());
    refused(&["simulate", b], &["pattern.frames[1].coords[2]", "1e308"]);
}

#[test]
fn exit_status_is_0_1_or_2() {
    assert_eq!(
        foldsynth(&["vertex", SPEC, "--t", "1"]).status.code(),
        Some(0)
    );
    assert_eq!(foldsynth(&["--help"]).status.code(), Some(0));
    assert_eq!(foldsynth(&["no-such-command"]).status.code(), Some(2));
    assert_eq!(foldsynth(&["vertex"]).status.code(), Some(2));
    assert_eq!(
        foldsynth(&["verify", "/no/such/file.fold"]).status.code(),
        Some(2)
    );
    // A check that ran and failed: 1.
    let dir = tempfile::tempdir().unwrap();
    let fold = dir.path().join("bent.fold");
    std::fs::write(
        &fold,
        r#"{"frame_classes": ["creasePattern"], "vertices_coords": [[0,0,0],[1,0,0],[1,1,0.5],[0,1,0]],
            "faces_vertices": [[0,1,2],[0,2,3]]}"#,
    )
    .unwrap();
    assert_eq!(
        foldsynth(&["verify", fold.to_str().unwrap()]).status.code(),
        Some(1)
    );
}
