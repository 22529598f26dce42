//! `foldsynth vertex` end to end: the JSON it prints and the errors it gives.

use std::process::Command;

fn foldsynth(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(args)
        .output()
        .expect("run foldsynth")
}

#[test]
fn json_has_the_documented_shape_and_the_fig28_facts() {
    let out = foldsynth(&[
        "vertex",
        "v(up, (60), (120), ((90,90),(t)))",
        "--t",
        "0:pi:13",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let samples = v["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 13);
    for key in ["U", "theta", "beta", "delta", "phi"] {
        assert_eq!(samples[3][key].as_array().unwrap().len(), 3, "{key}");
    }
    // U3 = π − t (thesis Sec. 4.2.4.2), in radians.
    let t = samples[5]["t"].as_f64().unwrap();
    let u3 = samples[5]["U"][2].as_f64().unwrap();
    assert!((u3 - (std::f64::consts::PI - t)).abs() < 1e-12);
    let iv = v["rigid_intervals"].as_array().unwrap();
    assert_eq!(iv.len(), 1);
    assert!((iv[0][1].as_f64().unwrap() - 2.0 * std::f64::consts::PI / 3.0).abs() < 1e-9);
    assert_eq!(v["flat_foldable"], false);
    assert!(v["closure_max"].as_f64().unwrap() < 1e-12);
    assert!(
        samples
            .iter()
            .filter(|s| s["t"].as_f64().unwrap() > 2.1)
            .all(|s| s["rigid"] == false)
    );
}

#[test]
fn table_reports_flat_foldability_of_fig29() {
    let out = foldsynth(&[
        "vertex",
        "v(up, ((80,40,40),(t,-t)), ((90,40,50),(t,-t)), (20))",
    ]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("flat foldable (Eq. 26): yes"), "{text}");
    assert!(text.contains("[0.0000000000, 3.1415926536]"), "{text}");
}

#[test]
fn bad_input_is_a_clear_error_and_a_nonzero_exit() {
    let cases: [(&[&str], &str); 7] = [
        (
            &["vertex", "v(up, (60), (120), ((90,90),(t))"],
            "expected ')'",
        ),
        (
            &["vertex", "v(up, (60), (200), ((90,90),(t)))"],
            "outside (0°, 180°)",
        ),
        (
            &["vertex", "v(up, (60), (120), ((90,90),(t, t)))"],
            "needs 1 driving angles",
        ),
        (
            &["vertex", "v(up, (60), (120), (180))"],
            "outside (0°, 180°)",
        ),
        (
            &["vertex", "v(up, (60), (120), (90))"],
            "at least 4 sectors",
        ),
        (
            &[
                "vertex",
                "v(up, (60), (120), ((90,90),(t)))",
                "--t",
                "2:1:5",
            ],
            "is empty",
        ),
        (
            &[
                "vertex",
                "v(up, (60), (120), ((90,90),(t)))",
                "--t",
                "0:1:1",
            ],
            "at least 2 samples",
        ),
    ];
    for (args, msg) in cases {
        let out = foldsynth(args);
        assert!(!out.status.success(), "{args:?} should fail");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(msg), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}
