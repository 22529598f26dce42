//! The Symbolica commands (feature `symbolica`) through the real binary: `--json` output
//! stays JSON (the licence banner is kept off stdout), the peer agrees with ours to
//! 1e-12 in `bench vertex` and `bench model`, `formulas --backend symbolica` prints
//! Mathematica-compatible formulas with Symbolica's counts, and a second process that
//! wants Symbolica while another holds it gets an error instead of an abort.
//!
//! Every run gets its own `SYMBOLICA_LOCK_DIR`, so the tests do not contend for
//! Symbolica's one-thread-per-user lock.

use std::process::{Command, Output};

const V7: &str = "v(up, ((40,50,45,35,40),(t,-t,t,-t)), (55), (95))";

fn foldsynth_in(lock_dir: &std::path::Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("SYMBOLICA_LOCK_DIR", lock_dir)
        .env_remove("SYMBOLICA_HIDE_BANNER")
        .env_remove("SYMBOLICA_LICENSE")
        .args(args)
        .output()
        .expect("run foldsynth")
}

/// A fresh lock directory: Symbolica refuses a `SYMBOLICA_LOCK_DIR` that anyone but its
/// owner can open, and tempfile's directories follow the umask.
fn lock_dir() -> tempfile::TempDir {
    use std::os::unix::fs::PermissionsExt;
    tempfile::Builder::new()
        .permissions(std::fs::Permissions::from_mode(0o700))
        .tempdir()
        .unwrap()
}

fn foldsynth(args: &[&str]) -> Output {
    let dir = lock_dir();
    foldsynth_in(dir.path(), args)
}

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout.clone()).unwrap()
}

#[test]
fn bench_vertex_json_is_json_and_agrees() {
    let o = foldsynth(&[
        "bench",
        "vertex",
        V7,
        "--symbolic-sectors",
        "--peer",
        "symbolica",
        "--json",
        "--millis",
        "20",
    ]);
    let out = ok(&o);
    // The whole of stdout is one JSON object: no banner.
    let j: serde_json::Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}"));
    let s = &j["symbolica"];
    assert_eq!(s["agrees_1e-12"], true, "{s}");
    assert!(s["jit_value_grad_ns"].as_f64().unwrap() > 0.0);
    assert!(s["compile_ms"].as_f64().unwrap() > 0.0);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("without a licence key"), "{err}");
}

#[test]
fn bench_model_agrees() {
    let o = foldsynth(&[
        "bench",
        "model",
        "grammar/gripper.toml",
        "--graph",
        "2, 3",
        "--peer",
        "symbolica",
        "--json",
        "--millis",
        "20",
    ]);
    let out = ok(&o);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}"));
    assert_eq!(j["symbolica"]["agrees_1e-12"], true, "{}", j["symbolica"]);
    assert_eq!(j["values_agree"], true);
}

#[test]
fn formulas_by_symbolica() {
    let m = ok(&foldsynth(&[
        "formulas",
        V7,
        "--symbolic-sectors",
        "--backend",
        "symbolica",
        "--format",
        "mathematica",
    ]));
    assert!(m.starts_with("(* vertex"), "{m}");
    assert!(m.contains("(* printed by Symbolica"), "{m}");
    assert!(m.contains("(* Symbolica, canonical form: "), "{m}");
    assert!(m.contains("ArcTan["), "{m}");
    assert!(m.contains("phi1 = "), "{m}");
    // Mathematica syntax: calls in brackets, no Symbolica-style parentheses calls.
    assert!(!m.contains("atan2(") && !m.contains("sin("), "{m}");
    let g = ok(&foldsynth(&[
        "formulas",
        V7,
        "--backend",
        "symbolica",
        "--gradient",
    ]));
    assert!(g.contains("\ndphi3_dt = "), "{g}");
    let o = foldsynth(&[
        "formulas",
        V7,
        "--backend",
        "symbolica",
        "--format",
        "python",
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("plain, latex or mathematica"));
}

#[test]
fn a_second_symbolica_process_is_an_error_not_an_abort() {
    let dir = lock_dir();
    let lock =
        std::fs::File::create(dir.path().join("symbolica-restricted-thread-0.lock")).unwrap();
    lock.lock().unwrap();
    let o = foldsynth_in(dir.path(), &["formulas", V7, "--backend", "symbolica"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("another process of this user is using Symbolica"),
        "{err}"
    );
    assert!(
        o.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    drop(lock);
    ok(&foldsynth_in(
        dir.path(),
        &["formulas", V7, "--backend", "symbolica"],
    ));
}
