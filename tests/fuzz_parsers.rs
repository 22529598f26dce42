//! Fuzzing every parser (issue 13), a short bounded run: generated and mutated inputs of
//! every target under `catch_unwind` (0 panics), every input the long runs found
//! (`tests/data/fuzz/findings/`) as a regression, proptest properties of the parsers
//! and of the output-directory names, and `foldsynth fuzz` end to end in child processes.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use foldsynth::fuzz::{self, Target};
use proptest::prelude::*;

#[test]
fn a_short_run_of_every_target_has_no_panic() {
    fuzz::quiet_panics();
    let r = fuzz::run_batch(&Target::ALL, 20_260_501, 0, 2_400, None);
    let _ = std::panic::take_hook();
    let panics: Vec<_> = r.findings.iter().filter(|f| f.kind == "panic").collect();
    assert!(panics.is_empty(), "{panics:#?}");
    for t in Target::ALL {
        let c = &r.targets[t.name()];
        assert_eq!(c.inputs, 300, "{}", t.name());
        // The mutations keep some inputs valid, so the fuzzer reaches past the parser.
        assert!(c.accepted > 0, "{}: nothing accepted", t.name());
    }
}

#[test]
fn mutated_mesh_files_are_answered_without_a_panic() {
    use foldsynth::scene::TriangleMesh;
    fuzz::quiet_panics();
    let r = fuzz::run_batch(&[Target::Mesh], 20_261_203, 0, 1_500, None);
    let _ = std::panic::take_hook();
    assert!(r.findings.is_empty(), "{:#?}", r.findings);
    let c = &r.targets["mesh"];
    // Some mutations keep a readable mesh, others break it.
    assert!(c.accepted > 0 && c.accepted < c.inputs, "{c:?}");
    // A binary STL that announces 4 billion triangles in 84 bytes is refused before
    // anything is allocated for them; so is one announcing just over the limit.
    for n in [u32::MAX, 20_001] {
        let mut b = vec![0u8; 80];
        b.extend_from_slice(&n.to_le_bytes());
        let e = TriangleMesh::from_stl(&b).unwrap_err();
        assert!(e.contains(&format!("{n} triangles")), "{e}");
    }
    // An OBJ face naming a vertex far beyond the file's is an error.
    assert!(TriangleMesh::from_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4000000000\n").is_err());
}

#[test]
fn every_input_the_fuzzer_found_is_a_regression_test() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz/findings");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let Some(target) = name.split('-').next().and_then(Target::from_name) else {
            continue;
        };
        let bytes = std::fs::read(&path).unwrap();
        let r = catch_unwind(AssertUnwindSafe(|| fuzz::exercise(target, &bytes)));
        assert!(r.is_ok(), "{name} panics again");
        n += 1;
    }
    assert!(n > 0, "no findings in {}", dir.display());
}

#[test]
fn deep_nesting_is_an_error_not_a_stack_overflow() {
    use foldsynth::kinematics::{DriveExpr, VertexSpec};
    use foldsynth::simulate::Formula;
    use foldsynth::task::number::Expr;
    for depth in [10, 64, 65, 1_000, 100_000] {
        let e = format!("{}t{}", "(".repeat(depth), ")".repeat(depth));
        let ok = depth <= foldsynth::limits::EXPR_DEPTH_MAX;
        assert_eq!(DriveExpr::parse(&e).is_ok(), ok, "{depth}");
        assert_eq!(Formula::parse(&e).is_ok(), ok, "{depth}");
        let n = format!("{}1{}", "(".repeat(depth), ")".repeat(depth));
        assert_eq!(Expr::parse(&n).is_ok(), ok, "{depth}");
        let v = format!("v(up, (90), (90), ((90,90),({e})))");
        let r = VertexSpec::parse(&v);
        assert_eq!(
            r.is_ok(),
            depth + 3 <= foldsynth::limits::EXPR_DEPTH_MAX,
            "{depth}"
        );
        if let Err(err) = r {
            // The message points at the excess without echoing 100,000 characters.
            assert!(err.to_string().len() < 600, "{}", err.to_string().len());
        }
    }
    // A long chain without parentheses: refused past the operator limit.
    let chain = vec!["t"; 100_000].join("+");
    assert!(DriveExpr::parse(&chain).is_err());
    assert!(Formula::parse(&chain).is_err());
    let short = vec!["t"; 500].join("+");
    assert!((DriveExpr::parse(&short).unwrap().eval(&1.0_f64) - 500.0).abs() < 1e-9);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    /// Any text through every expression parser: an answer, never a panic.
    #[test]
    fn expression_parsers_answer_any_text(s in "\\PC{0,80}") {
        let _ = fuzz::exercise(Target::Expr, s.as_bytes());
        let _ = fuzz::exercise(Target::Vertex, s.as_bytes());
    }

    /// Expressions from a grammar evaluate to what the three parsers agree on.
    #[test]
    fn the_parsers_agree_on_arithmetic(a in -50i32..50, b in 1i32..50, c in -9i32..9) {
        let text = format!("({a} + {c}*t)/{b}");
        let t = 0.75;
        let want = (a as f64 + c as f64 * t) / b as f64;
        let d = foldsynth::kinematics::DriveExpr::parse(&text).unwrap().eval(&t);
        let f = foldsynth::simulate::Formula::parse(&text).unwrap().eval(t);
        prop_assert!((d - want).abs() < 1e-12 && (f - want).abs() < 1e-12);
    }

    /// Whatever a task is named, its default output directory is one plain name in out/.
    #[test]
    fn a_default_output_directory_stays_in_out(name in "\\PC{0,100}") {
        use std::path::Component;
        let d = foldsynth::search::output::default_dir(&name);
        let parts: Vec<Component> = d.components().collect();
        prop_assert_eq!(parts.len(), 2);
        prop_assert_eq!(parts[0], Component::Normal("out".as_ref()));
        prop_assert!(matches!(parts[1], Component::Normal(_)));
        let leaf = parts[1].as_os_str().to_string_lossy().into_owned();
        prop_assert!(!leaf.starts_with('.'));
        prop_assert!(leaf.chars().count() <= foldsynth::search::output::DIR_NAME_MAX);
    }

    /// Records files: every line is reused or reported.
    #[test]
    fn resume_reports_every_line(lines in proptest::collection::vec("\\PC{0,40}", 0..8)) {
        let text = lines.join("\n");
        let _ = fuzz::exercise(Target::Records, text.as_bytes());
    }
}

#[test]
fn the_fuzz_command_runs_batches_in_child_processes() {
    let dir = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args([
            "fuzz",
            "--inputs",
            "160",
            "--batch",
            "80",
            "--jobs",
            "2",
            "--seed",
            "5",
            "--json",
            "--findings",
        ])
        .arg(dir.path().join("findings"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["inputs"], 160);
    assert_eq!(v["panics"], 0);
    assert_eq!(v["aborts"], 0);
    assert_eq!(v["hangs"], 0);
    for t in Target::ALL {
        assert_eq!(v["targets"][t.name()]["inputs"], 20, "{}", t.name());
    }
    // Nothing to save, so nothing was written.
    assert!(!dir.path().join("findings").exists());
}
