//! `foldsynth formulas`, driven through the real binary: the Python output, executed by
//! `python3` with NumPy, reproduces the interpreter's values; the other formats carry
//! what they promise; bad input is an error, not a panic.

use foldsynth::cli::formulas::{Backend, FormatArg, FormulasArgs, formulas};
use foldsynth::expr::{NodeId, Tape};
use std::f64::consts::PI;
use std::process::Command;

const V7: &str = "v(up, ((40,50,45,35,40),(t,-t,t,-t)), (55), (95))";

fn foldsynth(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(args)
        .output()
        .expect("run foldsynth")
}

fn args(spec: &str, simplify: bool, gradient: bool, symbolic: bool) -> FormulasArgs {
    FormulasArgs {
        spec: spec.to_string(),
        format: FormatArg::Python,
        simplify,
        gradient,
        symbolic_sectors: symbolic,
        backend: Backend::Egg,
        output: None,
    }
}

/// Why the Python check cannot run here, if it cannot.
fn python_unavailable() -> Option<String> {
    match Command::new("python3")
        .args(["-c", "import numpy"])
        .output()
    {
        Err(e) => Some(format!("python3 not runnable: {e}")),
        Ok(o) if !o.status.success() => Some("numpy is not installed".to_string()),
        Ok(_) => None,
    }
}

const RUNNER: &str = r#"
import importlib.util, json, sys
spec = importlib.util.spec_from_file_location("formulas", sys.argv[1])
m = importlib.util.module_from_spec(spec)
spec.loader.exec_module(m)
points = json.loads(sys.argv[2])
print(json.dumps([[float(v) for v in m.f(x, p)] for x, p in points]))
"#;

fn check_python(spec: &str, simplify: bool, gradient: bool, symbolic: bool) {
    if let Some(why) = python_unavailable() {
        eprintln!("skipping the Python printer check: {why}");
        return;
    }
    let mut cli = vec!["formulas", spec, "--format", "python"];
    if simplify {
        cli.push("--simplify");
    }
    if gradient {
        cli.push("--gradient");
    }
    if symbolic {
        cli.push("--symbolic-sectors");
    }
    let out = foldsynth(&cli);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("formulas.py");
    std::fs::write(&file, &out.stdout).unwrap();

    // The interpreter on the very graph the binary printed.
    let f = formulas(&args(spec, simplify, gradient, symbolic)).unwrap();
    let ids: Vec<NodeId> = f.outputs.iter().map(|(_, id)| *id).collect();
    let tape = Tape::new(&f.graph, &ids, f.n_vars, f.n_params).unwrap();
    let mut points = Vec::new();
    for (k, t) in [1.7, 2.2, 2.6].into_iter().enumerate() {
        let m = if k % 2 == 0 { 1.0 } else { -1.0 };
        if symbolic {
            let x: Vec<f64> = f
                .spec
                .sectors_rad()
                .iter()
                .enumerate()
                .map(|(i, a)| a + 0.01 * (i as f64 + k as f64).sin())
                .collect();
            points.push((x, vec![t, m]));
        } else {
            points.push((vec![t], vec![m]));
        }
    }
    let json = serde_json::to_string(&points).unwrap();
    let run = Command::new("python3")
        .args(["-c", RUNNER, file.to_str().unwrap(), &json])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "python: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    let got: Vec<Vec<f64>> = serde_json::from_slice(&run.stdout).unwrap();
    for ((x, p), py) in points.iter().zip(&got) {
        let mut want = vec![0.0; ids.len()];
        tape.eval(x, p, &mut want).unwrap();
        assert_eq!(py.len(), want.len());
        for (k, (a, b)) in py.iter().zip(&want).enumerate() {
            // NumPy's libm may differ from ours by an ulp; angles may differ by full turns.
            let d = a - b;
            let d = d - 2.0 * PI * (d / (2.0 * PI)).round();
            assert!(
                d.abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0),
                "{}: python {a} vs interpreter {b} at {x:?} {p:?}",
                f.outputs[k].0
            );
        }
    }
}

#[test]
fn python_reproduces_the_interpreter() {
    check_python(V7, false, false, false);
    check_python(V7, true, true, true);
    check_python(
        "v(down, ((40,100,70),(t,-t)), (70), (80))",
        false,
        true,
        true,
    );
}

#[test]
fn formats_and_counts() {
    let run = |fmt: &str, extra: &[&str]| {
        let mut a = vec!["formulas", V7, "--symbolic-sectors", "--format", fmt];
        a.extend_from_slice(extra);
        let o = foldsynth(&a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap()
    };
    let plain = run("plain", &["--simplify", "--gradient"]);
    assert!(plain.contains("# after simplification:"), "{plain}");
    assert!(plain.contains("with the gradients of phi1..3"), "{plain}");
    assert!(plain.contains("\nphi1 = "), "{plain}");
    assert!(plain.contains("\ndphi3_dalpha7 = "), "{plain}");
    let m = run("mathematica", &[]);
    // atan2(y, x) is ArcTan[x, y] in Mathematica.
    assert!(m.contains("ArcTan["), "{m}");
    assert!(m.starts_with("(* vertex"), "{m}");
    assert!(m.contains("phi1 = "), "{m}");
    let l = run("latex", &[]);
    assert!(
        l.contains("\\begin{aligned}") && l.contains("\\phi_{1} &= "),
        "{l}"
    );
    let d = run("dot", &[]);
    assert!(
        d.contains("digraph expr {") && d.trim_end().ends_with('}'),
        "{d}"
    );

    // Counts are real: simplification shrinks this vertex.
    let f = formulas(&args(V7, true, true, true)).unwrap();
    assert!(f.after.ops < f.before.ops);
    assert!(f.with_gradients.unwrap().ops > f.values.ops);
}

#[test]
fn bad_input_is_an_error() {
    let o = foldsynth(&["formulas", "v(up, (40), (50))"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("invalid vertex"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    let o = foldsynth(&["formulas", V7, "--format", "fortran"]);
    assert!(!o.status.success());
}
