//! `foldsynth simulate` and `foldsynth optimize-flasher` as a user runs them.

use std::path::Path;
use std::process::{Command, Output};

fn foldsynth(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn simulate_prints_the_table_and_the_verdict() {
    let out = foldsynth(&["simulate", "grammar/flasher_adapted.toml"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let s = text(&out.stdout);
    assert!(s.contains("delta(j)"));
    assert!(s.contains("verdict             rigid"));
    assert_eq!(
        s.lines()
            .filter(|l| l.trim_start().starts_with("30 "))
            .count(),
        1
    );
}

#[test]
fn simulate_json_honours_steps() {
    let out = foldsynth(&[
        "simulate",
        "grammar/flasher_adapted.toml",
        "--steps",
        "12",
        "--json",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["steps"].as_array().unwrap().len(), 12);
    assert_eq!(v["states"].as_array().unwrap().len(), 13);
    assert_eq!(v["rigid"], true);
    assert_eq!(v["theta"], 0.0);
    assert!(v["gamma"].as_f64().unwrap() < 1e-10);
}

/// The degree-4 vertex of tests/simulate_kinematics.rs written as a pattern file with a
/// crease drive: the file's crease, "moving" side and angle formula reach the simulator
/// with the valley-positive sign, and the end state is the closed form.
#[test]
fn crease_drive_from_a_file_gives_the_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("degree4.toml");
    std::fs::write(
        &path,
        r#"
name = "degree-4 vertex 60/120/90/90"
vertices = [
  { name = "o", at = [0, 0] },
  { name = "p1", at = [1, 0] },
  { name = "p2", at = [0.5, 0.8660254037844386] },
  { name = "p3", at = [-1, 0] },
  { name = "p4", at = [0, -1] },
]
faces = [["o", "p1", "p2"], ["o", "p2", "p3"], ["o", "p3", "p4"], ["o", "p4", "p1"]]

[motion]
t_start = 0
t_end = "5*pi/9"
steps = 20

[[drive]]
kind = "crease"
crease = ["o", "p4"]
moving = "p1"
angle = "t"
"#,
    )
    .unwrap();
    let out = foldsynth(&["simulate", path.to_str().unwrap(), "--json"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rho = 100f64.to_radians();
    let h = (rho / 2.0).tan();
    let want_p2 = [0.5, (0.75 - 0.25 * h * h).sqrt(), 0.5 * h];
    let want_p1 = [rho.cos(), 0.0, rho.sin()];
    let end = v["final_positions"].as_array().unwrap();
    for (idx, want) in [(1, want_p1), (2, want_p2)] {
        let got: Vec<f64> = end[idx]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        for k in 0..3 {
            assert!(
                (got[k] - want[k]).abs() < 1e-9,
                "vertex {idx}: {got:?} vs {want:?}"
            );
        }
    }
    assert!(v["gamma"].as_f64().unwrap() <= 1e-8);
}

fn rejects(file_body: &str, expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.toml");
    std::fs::write(&path, file_body).unwrap();
    let out = foldsynth(&["simulate", path.to_str().unwrap()]);
    let err = text(&out.stderr);
    assert!(!out.status.success(), "accepted:\n{file_body}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains(path.to_str().unwrap()),
        "no file name in: {err}"
    );
    for e in expect {
        assert!(err.contains(e), "missing '{e}' in: {err}");
    }
}

const GOOD_HEAD: &str = r#"
vertices = [
  { name = "a", at = [0, 0] },
  { name = "b", at = [0, 1] },
  { name = "c", at = [1, 0] },
  { name = "d", at = [-1, 0] },
]
faces = [["a", "c", "b"], ["a", "b", "d"]]
fixed = ["a", "b", "c"]
"#;

const GOOD_MOTION: &str = "\n[motion]\nt_start = 0\nt_end = 1\nsteps = 4\n";

fn with_drive(drive: &str) -> String {
    format!("{GOOD_HEAD}{GOOD_MOTION}\n[[drive]]\n{drive}\n")
}

#[test]
fn a_good_small_file_runs() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ok.toml");
    std::fs::write(
        &path,
        with_drive("kind = \"trajectory\"\nvertex = \"d\"\nx = \"-cos(t)\"\ny = 0\nz = \"sin(t)\""),
    )
    .unwrap();
    let out = foldsynth(&["simulate", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("verdict             rigid"));
}

#[test]
fn bad_files_get_clear_errors() {
    // A formula error points at the character.
    rejects(
        &with_drive("kind = \"trajectory\"\nvertex = \"d\"\nx = \"-cos(t\"\ny = 0\nz = \"sin(t)\""),
        &["drive[0].x", "expected ')'", "^"],
    );
    rejects(
        &with_drive(
            "kind = \"trajectory\"\nvertex = \"d\"\nx = \"-cos(t)\"\ny = 0\nz = \"2sin(t)\"",
        ),
        &["drive[0].z", "implicit multiplication"],
    );
    // A path that does not start at its vertex.
    rejects(
        &with_drive("kind = \"trajectory\"\nvertex = \"d\"\nx = \"cos(t)\"\ny = 0\nz = \"sin(t)\""),
        &["drive[0]", "must start at its vertex"],
    );
    // Unknown names, unknown fields, wrong shapes.
    rejects(
        &with_drive("kind = \"trajectory\"\nvertex = \"zz\"\nx = 0\ny = 0\nz = 0"),
        &["drive[0].vertex", "unknown vertex 'zz'"],
    );
    rejects(
        &with_drive("kind = \"spring\"\nvertex = \"d\""),
        &["toml", "spring"],
    );
    rejects(
        &format!("{GOOD_HEAD}{GOOD_MOTION}colour = 3\n"),
        &["toml", "colour"],
    );
    rejects(
        &format!(
            "{}{GOOD_MOTION}",
            GOOD_HEAD.replace("[0, 1] }", "[0, 1, 2, 3] }")
        ),
        &["vertices[1].at", "expected [x, y] or [x, y, z]"],
    );
    rejects(
        &format!(
            "{}{GOOD_MOTION}",
            GOOD_HEAD.replace("[\"a\", \"c\", \"b\"]", "[\"a\", \"c@1\", \"b\"]")
        ),
        &["faces[0]", "[symmetry]"],
    );
    rejects(
        &with_drive("kind = \"crease\"\ncrease = [\"a\", \"c\"]\nmoving = \"d\"\nangle = \"t\""),
        &["drive[0].crease", "exactly 2"],
    );
    // Motion fields.
    rejects(
        &format!("{GOOD_HEAD}\n[motion]\nt_start = 0\nt_end = \"t\"\nsteps = 4\n"),
        &["motion.t_end", "without t"],
    );
    rejects(
        &format!("{GOOD_HEAD}\n[motion]\nt_start = 0\nt_end = 1\nsteps = 0\n"),
        &["motion.steps", "at least 1"],
    );
    rejects(
        &format!("{GOOD_HEAD}\n[motion]\nt_start = 0\nt_end = 1\nsteps = -3\n"),
        &["toml", "steps"],
    );
    // No drive at all.
    rejects(
        &format!("{GOOD_HEAD}{GOOD_MOTION}"),
        &["nothing drives the motion"],
    );
    // A facet that is clockwise.
    rejects(
        &with_drive(
            "kind = \"trajectory\"\nvertex = \"d\"\nx = \"-cos(t)\"\ny = 0\nz = \"sin(t)\"",
        )
        .replace("[\"a\", \"b\", \"d\"]", "[\"a\", \"d\", \"b\"]"),
        &["clockwise"],
    );
}

#[test]
fn missing_file_and_bad_flags_fail_cleanly() {
    let out = foldsynth(&["simulate", "no/such/file.toml"]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(
        err.contains("no/such/file.toml") && err.contains("cannot read"),
        "{err}"
    );
    let out = foldsynth(&["simulate", "grammar/flasher_adapted.toml", "--steps", "0"]);
    assert!(!out.status.success());
    assert!(!text(&out.stderr).contains("panicked"));
    let out = foldsynth(&["optimize-flasher", "--evals", "0"]);
    assert!(!out.status.success());
}

/// Design JSON, FOLD, `--crossval` and `bench numeric` inputs that are wrong: a non-zero
/// exit, the file and what is wrong named, never a panic.
#[test]
fn bad_design_inputs_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, body: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, body).unwrap();
        p.to_str().unwrap().to_string()
    };
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["simulate".into(), write("a.json", "{\"id\": 3}")],
            "not a design file",
        ),
        (
            vec!["simulate".into(), write("b.json", "not json")],
            "not valid JSON",
        ),
        (vec!["simulate".into(), write("c.fold", "{}")], "c.fold"),
        (
            vec![
                "simulate".into(),
                "--crossval".into(),
                dir.path().join("none").display().to_string(),
            ],
            "cannot read the directory",
        ),
        (
            vec![
                "simulate".into(),
                "grammar/flasher_adapted.toml".into(),
                "--angle".into(),
                "t".into(),
            ],
            "are for FOLD and design files",
        ),
        (
            vec![
                "bench".into(),
                "numeric".into(),
                write("d.json", "{\"task\": \"gripper\"}"),
                "--task".into(),
                "grammar/gripper.toml".into(),
            ],
            "field 'sequence' is missing",
        ),
        (
            vec![
                "bench".into(),
                "numeric".into(),
                write("e.json", "{\"task\": \"nosuchtask\"}"),
            ],
            "give the task file with --task",
        ),
        (
            vec![
                "bench".into(),
                "numeric".into(),
                "grammar/gripper.toml".into(),
                "--task".into(),
                "grammar/gripper.toml".into(),
            ],
            "--task is for a design JSON",
        ),
    ];
    for (args, expect) in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = foldsynth(&args);
        let err = text(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(
            err.contains(expect),
            "{args:?}: expected '{expect}' in: {err}"
        );
    }
}

#[test]
fn optimize_flasher_is_deterministic_for_a_seed() {
    let run = || {
        let out = foldsynth(&["optimize-flasher", "--evals", "25", "--seed", "3", "--json"]);
        assert!(out.status.success(), "{}", text(&out.stderr));
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let (a, b) = (run(), run());
    assert_eq!(a["best"], b["best"]);
    assert_eq!(a["trace"], b["trace"]);
    assert_eq!(a["evaluations"], 25);
    assert_eq!(a["thesis"]["objective"], -0.88);
    assert!(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("grammar/flasher_adapted.toml")
            .exists()
    );
}
