//! `foldsynth compile`: the ahead-of-time library is the function the JIT builds.
//!
//! A C program compiled with the system `cc` (`-Wall -Wextra -Werror -pedantic`) includes
//! the generated header, links the shared library (and, separately, the relocatable
//! object), reads the sizes, names and bounds through the library's functions and
//! evaluates points read from stdin. Its outputs must equal the in-process JIT's at the
//! same points to 1e-15 relative, its gradients must match central differences of its
//! own values, and what it reports must be the model's variables and bounds.

use foldsynth::compile::Options;
use foldsynth::grammar::CreaseGraph;
use foldsynth::model::Model;
use foldsynth::model::compiled::CompiledModel;
use foldsynth::task::Task;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const GRAPH: &str = "2, 3, (4, 8), 4, (7, 8)";

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_foldsynth")
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The system C compiler, or `None` (with a note) where there is none.
fn cc() -> Option<String> {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    match Command::new(&cc).arg("--version").output() {
        Ok(o) if o.status.success() => Some(cc),
        _ => {
            eprintln!("skipping: no C compiler '{cc}' to build the test program");
            None
        }
    }
}

/// The test program: prints the sizes, names and bounds, then for every line of
/// `n_vars + n_params` numbers on stdin the whole output buffer.
const PROGRAM: &str = r#"
#include <stdio.h>
#include <stdlib.h>
#include "@name@.h"

int main(void) {
    double vars[@UP@_N_VARS], params[@UP@_N_PARAMS], out[@UP@_N_OUT];
    const char *const *names = @name@_var_names();
    const char *const *pnames = @name@_param_names();
    const char *const *onames = @name@_output_names();
    const double *lo = @name@_lower_bounds(), *hi = @name@_upper_bounds();
    const double *def = @name@_default_params();
    static const char *literal[] = @UP@_VAR_NAMES;
    size_t i, n = 0;
    if (@name@_n_vars() != @UP@_N_VARS || @name@_n_params() != @UP@_N_PARAMS ||
        @name@_n_out() != @UP@_N_OUT || @name@_n_outputs() != @UP@_N_OUTPUTS ||
        @name@_n_constraints() + 1 != @UP@_N_OUTPUTS ||
        @name@_n_modes() + @name@_n_times() != @UP@_N_PARAMS ||
        @name@_gradient_offset() != @UP@_GRADIENT_OFFSET ||
        @name@_jacobian_offset() != @UP@_JACOBIAN_OFFSET ||
        @name@_constraints_offset() != @UP@_CONSTRAINTS_OFFSET || @name@_value_offset() != 0) {
        fprintf(stderr, "functions and macros disagree\n");
        return 2;
    }
    printf("sizes %zu %zu %zu %zu %zu %zu\n", @name@_n_vars(), @name@_n_params(), @name@_n_out(),
           @name@_n_constraints(), @name@_n_modes(), @name@_n_times());
    for (i = 0; i < @UP@_N_VARS; i++)
        printf("var %s %s %.17g %.17g\n", names[i], literal[i], lo[i], hi[i]);
    for (i = 0; i < @UP@_N_PARAMS; i++) printf("param %s %.17g\n", pnames[i], def[i]);
    for (i = 0; i < @UP@_N_OUTPUTS; i++) printf("output %s\n", onames[i]);
    for (;;) {
        for (i = 0; i < @UP@_N_VARS; i++)
            if (scanf("%lf", &vars[i]) != 1) goto done;
        for (i = 0; i < @UP@_N_PARAMS; i++)
            if (scanf("%lf", &params[i]) != 1) goto done;
        @name@_eval(vars, params, out);
        printf("out");
        for (i = 0; i < @UP@_N_OUT; i++) printf(" %.17g", out[i]);
        printf("\n");
        n++;
    }
done:
    printf("evaluated %zu\n", n);
    return 0;
}
"#;

struct Built {
    dir: tempfile::TempDir,
    shared: PathBuf,
    stat: PathBuf,
}

/// `foldsynth compile` the model, then build the test program against the shared
/// library and against the object.
fn build(cc: &str, task: &str, modes: &str, name: &str) -> Built {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(bin())
        .current_dir(root())
        .args(["compile", task, "--graph", GRAPH, "--modes", modes])
        .args(["--name", name, "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        format!("{name}.o"),
        format!("lib{name}.so"),
        format!("{name}.h"),
        format!("{name}.json"),
    ] {
        assert!(dir.path().join(&f).is_file(), "{f} missing");
    }
    let src = PROGRAM
        .replace("@name@", name)
        .replace("@UP@", &name.to_ascii_uppercase());
    std::fs::write(dir.path().join("main.c"), src).unwrap();
    let flags = [
        "-std=c99",
        "-Wall",
        "-Wextra",
        "-Werror",
        "-pedantic",
        "-O1",
    ];
    let shared = dir.path().join("main_shared");
    let d = dir.path().display().to_string();
    let status = Command::new(cc)
        .current_dir(dir.path())
        .args(flags)
        .args(["main.c", "-I", &d, "-L", &d])
        .arg(format!("-l{name}"))
        .arg(format!("-Wl,-rpath,{d}"))
        .args(["-lm", "-o"])
        .arg(&shared)
        .status()
        .unwrap();
    assert!(status.success(), "the test program did not build");
    let stat = dir.path().join("main_static");
    let status = Command::new(cc)
        .current_dir(dir.path())
        .args(flags)
        .args(["main.c", &format!("{name}.o"), "-I", &d, "-lm", "-o"])
        .arg(&stat)
        .status()
        .unwrap();
    assert!(
        status.success(),
        "the program linked with the object did not build"
    );
    Built { dir, shared, stat }
}

/// Run `program` on `points` (vars then params per point): the lines it printed and
/// the output buffers.
fn run(program: &Path, points: &[Vec<f64>]) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut child = Command::new(program)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    {
        let mut stdin = child.stdin.take().unwrap();
        for p in points {
            let line: Vec<String> = p.iter().map(|v| format!("{v:e}")).collect();
            writeln!(stdin, "{}", line.join(" ")).unwrap();
        }
    }
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "the test program failed");
    let text = String::from_utf8(out.stdout).unwrap();
    let mut info = Vec::new();
    let mut outs = Vec::new();
    for line in text.lines() {
        if let Some(rest) = line.strip_prefix("out ") {
            outs.push(rest.split(' ').map(|v| v.parse().unwrap()).collect());
        } else {
            info.push(line.to_string());
        }
    }
    assert_eq!(info.last().unwrap(), &format!("evaluated {}", points.len()));
    (info, outs)
}

/// `{v:e}` prints the shortest representation that reads back exactly, and `%.17g`
/// round-trips too; so these are the bits both sides computed.
fn rel_close(a: f64, b: f64, tol: f64) -> bool {
    a == b || (a - b).abs() <= tol * a.abs().max(b.abs())
}

/// Deterministic points spread over the bounds (a Halton-like sequence).
fn points(lo: &[f64], hi: &[f64], count: usize) -> Vec<Vec<f64>> {
    const PRIMES: [u64; 12] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37];
    (1..=count as u64)
        .map(|i| {
            (0..lo.len())
                .map(|k| {
                    let (mut f, mut r, mut j, b) = (1.0, 0.0, i, PRIMES[k % 12]);
                    while j > 0 {
                        f /= b as f64;
                        r += f * (j % b) as f64;
                        j /= b;
                    }
                    lo[k] + (hi[k] - lo[k]) * (0.05 + 0.9 * r)
                })
                .collect()
        })
        .collect()
}

fn check_task(task_file: &str, modes: &str, name: &str) {
    let Some(cc) = cc() else { return };
    let built = build(&cc, task_file, modes, name);
    let task = Task::load(root().join(task_file)).unwrap();
    let graph = CreaseGraph::from_sequence(&task, GRAPH).unwrap();
    let model = Model::new(&graph, &task, 0).unwrap();
    // The library is built for baseline CPUs (no FMA), so it rounds as the JIT does
    // without fusing the gradients' products; the default JIT (fused where this CPU has
    // FMA) agrees to 1e-12 below.
    let jit = CompiledModel::new(
        &model,
        &Options {
            fma: false,
            ..Options::default()
        },
    )
    .unwrap();
    let fused = CompiledModel::new(&model, &Options::default()).unwrap();
    let n = jit.n_vars;
    let m = jit.n_constraints;
    let (lo, hi): (Vec<f64>, Vec<f64>) = model.free.iter().map(|&i| model.var_bounds(i)).unzip();
    let signs: Vec<f64> = modes
        .split(',')
        .map(|m| if m == "up" { 1.0 } else { -1.0 })
        .collect();
    let default_params = jit.params(&model, &signs);

    // Points: the default parameters and others (flipped modes, other times).
    let xs = points(&lo, &hi, 8);
    let mut pts = Vec::new();
    for (j, x) in xs.iter().enumerate() {
        let mut p = default_params.clone();
        if j % 2 == 1 {
            p.iter_mut().take(signs.len()).for_each(|s| *s = -*s);
        }
        if j % 3 == 2 {
            let nm = signs.len();
            p.iter_mut()
                .skip(nm)
                .enumerate()
                .for_each(|(k, t)| *t = 0.3 + 0.1 * k as f64);
        }
        pts.push(x.iter().chain(&p).copied().collect::<Vec<f64>>());
    }
    let (info, shared_out) = run(&built.shared, &pts);
    let (_, static_out) = run(&built.stat, &pts);
    assert_eq!(shared_out.len(), pts.len());

    // What the library reports is the model.
    assert_eq!(
        info[0],
        format!(
            "sizes {n} {} {} {m} {} {}",
            default_params.len(),
            jit.buffer_len(),
            model.plan.internal.len(),
            model.times.len()
        )
    );
    for (k, &i) in model.free.iter().enumerate() {
        let v = &model.plan.variables[i].name;
        let line: Vec<&str> = info[1 + k].split(' ').collect();
        assert_eq!(&line[..3], &["var", v.as_str(), v.as_str()]);
        assert_eq!(line[3].parse::<f64>().unwrap(), lo[k]);
        assert_eq!(line[4].parse::<f64>().unwrap(), hi[k]);
    }
    for (k, p) in default_params.iter().enumerate() {
        let line: Vec<&str> = info[1 + n + k].split(' ').collect();
        assert_eq!(line[0], "param");
        assert_eq!(line[2].parse::<f64>().unwrap(), *p);
    }
    assert_eq!(info[1 + n + default_params.len()], "output objective");
    assert_eq!(
        info[2 + n + default_params.len()],
        format!("output {}", model.constraint_label(0))
    );

    // The library computes what the JIT computes.
    let mut buf = vec![0.0; jit.buffer_len()];
    let mut fbuf = vec![0.0; jit.buffer_len()];
    let mut worst: f64 = 0.0;
    for (p, (so, st)) in pts.iter().zip(shared_out.iter().zip(&static_out)) {
        jit.call(&p[..n], &p[n..], &mut buf);
        fused.call(&p[..n], &p[n..], &mut fbuf);
        for (k, ((a, b), c)) in buf.iter().zip(so).zip(st).enumerate() {
            assert!(
                rel_close(*a, *b, 1e-15) && rel_close(*a, *c, 1e-15),
                "output {k} at {p:?}: JIT {a:e}, shared library {b:e}, object {c:e}"
            );
            let f = fbuf[k];
            assert!(
                (f - b).abs() <= 1e-12 * f.abs().max(b.abs()).max(1.0),
                "output {k} at {p:?}: fused JIT {f:e}, shared library {b:e}"
            );
            if *a != 0.0 {
                worst = worst.max((a - b).abs() / a.abs());
            }
        }
    }
    eprintln!(
        "{name}: {} points × {} outputs, largest relative difference JIT vs library {worst:e}",
        pts.len(),
        buf.len()
    );

    // Gradients and the Jacobian match central differences of the library's values.
    let h = 1e-6;
    for p in pts.iter().take(3) {
        let mut fd_pts = Vec::new();
        for i in 0..n {
            for s in [1.0, -1.0] {
                let mut q = p.clone();
                q[i] += s * h;
                fd_pts.push(q);
            }
        }
        let (_, vals) = run(&built.shared, &fd_pts);
        let (_, at) = run(&built.shared, std::slice::from_ref(p));
        let at = &at[0];
        for i in 0..n {
            let (plus, minus) = (&vals[2 * i], &vals[2 * i + 1]);
            for k in 0..=m {
                let fd = (plus[k] - minus[k]) / (2.0 * h);
                let d = at[1 + m + k * n + i];
                assert!(
                    (fd - d).abs() <= 1e-6 * (1.0 + d.abs()),
                    "d out[{k}] / d vars[{i}] at {p:?}: library {d:e}, central difference {fd:e}"
                );
            }
        }
    }

    // The manifest states the same facts.
    let manifest: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(built.dir.path().join(format!("{name}.json"))).unwrap(),
    )
    .unwrap();
    assert_eq!(manifest["constants"]["n_vars"], n);
    assert_eq!(manifest["constants"]["n_out"], jit.buffer_len());
    assert_eq!(manifest["constants"]["jacobian_offset"], 1 + m + n);
    assert_eq!(manifest["layout"]["jacobian"]["offset"], 1 + m + n);
    assert_eq!(manifest["layout"]["jacobian"]["rows"], m);
    assert_eq!(manifest["layout"]["constraints"]["len"], m);
    assert_eq!(manifest["layout"]["len"], (1 + m) * (1 + n));
    assert_eq!(manifest["variables"][0]["lower"], lo[0]);
    assert_eq!(manifest["model"]["graph"], GRAPH);
    assert_eq!(
        manifest["outputs"].as_array().unwrap().len(),
        m + 1,
        "one label per output"
    );
}

#[test]
fn gripper_library_equals_jit() {
    check_task("grammar/gripper.toml", "up,down,up", "gripper");
}

#[test]
fn robotic_arm_library_with_eleven_times_equals_jit() {
    check_task("grammar/robotic_arm.toml", "down,up,up", "arm_model");
}

fn compile_err(args: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(bin())
        .current_dir(root())
        .arg("compile")
        .args(args)
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(!out.status.success(), "{args:?} succeeded");
    String::from_utf8_lossy(&out.stderr).to_string()
}

#[test]
fn bad_arguments_are_clear_errors() {
    let g = "grammar/gripper.toml";
    let e = compile_err(&[g, "--graph", GRAPH, "--name", "9lives"]);
    assert!(
        e.contains("--name") && e.contains("not a usable C name"),
        "{e}"
    );
    let e = compile_err(&[g, "--graph", GRAPH, "--name", "a-b"]);
    assert!(e.contains("not a usable C name"), "{e}");
    let e = compile_err(&[g, "--graph", GRAPH, "--emit", "dll"]);
    assert!(e.contains("obj") && e.contains("header"), "{e}");
    let e = compile_err(&[g, "--graph", "2, 9, 9"]);
    assert!(e.contains("--graph"), "{e}");
    let e = compile_err(&[g, "--graph", GRAPH, "--candidate", "4"]);
    assert!(e.contains("--candidate"), "{e}");
    let e = compile_err(&[g, "--graph", GRAPH, "--modes", "up,up"]);
    assert!(e.contains("3 internal vertices"), "{e}");
    let e = compile_err(&["grammar/missing.toml", "--graph", GRAPH]);
    assert!(e.contains("missing.toml"), "{e}");
}

#[test]
fn header_only_writes_header_and_manifest() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(bin())
        .current_dir(root())
        .args(["compile", "grammar/gripper.toml", "--graph", GRAPH])
        .args(["--emit", "header", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success());
    let mut files: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    files.sort();
    assert_eq!(files, ["gripper.h", "gripper.json"]);
}
