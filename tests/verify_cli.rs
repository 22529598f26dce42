//! `foldsynth verify` and `foldsynth export` through the real binary: exported FOLD
//! files pass, a nudged vertex fails with a non-zero exit, bad input gets clear errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use foldsynth::export::{DesignFile, DesignMeta, samples};
use serde_json::Value;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_foldsynth"))
}

fn run(args: &[&str]) -> Output {
    let out = bin().args(args).output().expect("run foldsynth");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    out
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn write_design(dir: &Path, name: &str, d: &DesignFile) -> PathBuf {
    let p = dir.join(format!("{name}.json"));
    std::fs::write(&p, serde_json::to_string(d).unwrap()).unwrap();
    p
}

fn designs() -> Vec<(&'static str, DesignFile)> {
    let (gp, gm) = samples::demo_gripper();
    vec![
        (
            "crease",
            DesignFile {
                pattern: samples::single_crease(2.8, 9),
                meta: DesignMeta {
                    task: "single crease".into(),
                    ..DesignMeta::default()
                },
            },
        ),
        (
            "degree4",
            DesignFile {
                pattern: samples::degree4(1.2, 3.0, 17),
                meta: DesignMeta::default(),
            },
        ),
        (
            "gripper",
            DesignFile {
                pattern: gp,
                meta: gm,
            },
        ),
    ]
}

fn export_fold(dir: &Path, name: &str, d: &DesignFile) -> PathBuf {
    let design = write_design(dir, name, d);
    let fold = dir.join(format!("{name}.fold"));
    let o = run(&[
        "export",
        design.to_str().unwrap(),
        "--format",
        "fold",
        "--out",
        fold.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    fold
}

#[test]
fn every_exported_fold_file_verifies() {
    let dir = tempfile::tempdir().unwrap();
    for (name, d) in designs() {
        let fold = export_fold(dir.path(), name, &d);
        let o = run(&["verify", fold.to_str().unwrap()]);
        assert!(o.status.success(), "{name}: {}{}", stdout(&o), stderr(&o));
        let text = stdout(&o);
        assert!(text.contains("result: OK"), "{text}");
        // The report names every folded frame.
        assert_eq!(
            text.lines()
                .filter(|l| l.trim_end().ends_with(" ok")
                    && l.trim_start().starts_with(char::is_numeric))
                .count(),
            d.pattern.frames.len(),
            "{text}"
        );
    }
}

#[test]
fn one_nudged_vertex_fails() {
    let dir = tempfile::tempdir().unwrap();
    let (_, d) = designs().remove(1);
    let fold = export_fold(dir.path(), "degree4", &d);
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(&fold).unwrap()).unwrap();
    let z = v["file_frames"][5]["vertices_coords"][7][2]
        .as_f64()
        .unwrap();
    v["file_frames"][5]["vertices_coords"][7][2] = (z + 1e-7).into();
    let bad = dir.path().join("nudged.fold");
    std::fs::write(&bad, serde_json::to_string(&v).unwrap()).unwrap();

    let o = run(&["verify", bad.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stdout(&o).contains("result: FAILED"), "{}", stdout(&o));
    assert!(stderr(&o).contains("verification failed"), "{}", stderr(&o));

    let o = run(&["verify", "--json", bad.to_str().unwrap()]);
    assert!(!o.status.success());
    let r: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(r["ok"], false);
    let frames = r["frames"].as_array().unwrap();
    let failed: Vec<u64> = frames
        .iter()
        .filter(|f| f["ok"] == false)
        .map(|f| f["frame"].as_u64().unwrap())
        .collect();
    assert_eq!(failed, vec![6]);
    // Vertex 7 = (−1,−1) lies only in face 2.
    assert_eq!(frames[5]["worst_face"], 2);
    let err = frames[5]["max_isometry_error"].as_f64().unwrap();
    assert!(err > 1e-9 && err < 1e-6, "{err}");

    // A tolerance above the nudge accepts it.
    let o = run(&[
        "verify",
        "--tol",
        "1e-6",
        "--angle-tol",
        "1e-3",
        bad.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stdout(&o));
}

#[test]
fn a_wrong_fold_angle_fails() {
    let dir = tempfile::tempdir().unwrap();
    let (_, d) = designs().remove(0);
    let fold = export_fold(dir.path(), "crease", &d);
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(&fold).unwrap()).unwrap();
    // Claim a mountain where the geometry folds a valley.
    let a = v["file_frames"][4]["edges_foldAngle"][0].as_f64().unwrap();
    assert!(a > 10.0);
    v["file_frames"][4]["edges_foldAngle"][0] = (-a).into();
    let bad = dir.path().join("sign.fold");
    std::fs::write(&bad, serde_json::to_string(&v).unwrap()).unwrap();
    let o = run(&["verify", "--json", bad.to_str().unwrap()]);
    assert!(!o.status.success());
    let r: Value = serde_json::from_str(&stdout(&o)).unwrap();
    let f = &r["frames"][4];
    assert_eq!(f["ok"], false);
    assert_eq!(f["worst_edge"], 0);
    assert!((f["max_fold_angle_error_deg"].as_f64().unwrap() - 2.0 * a).abs() < 1e-9);
    // Isometry itself is fine there.
    assert!(f["max_isometry_error"].as_f64().unwrap() < 1e-12);
}

#[test]
fn hand_written_files_verify() {
    for f in ["diagonal_spec_example.fold", "mountain_no_faces.fold"] {
        let p = format!("{}/tests/data/{f}", env!("CARGO_MANIFEST_DIR"));
        let o = run(&["verify", &p]);
        assert!(o.status.success(), "{f}: {}{}", stdout(&o), stderr(&o));
    }
}

#[test]
fn inconsistent_faces_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        // Second face clockwise in a declared crease pattern.
        (
            r#"{"frame_classes": ["creasePattern"], "vertices_coords": [[0,0],[1,0],[1,1],[0,1]], "edges_vertices": [[0,1],[1,2],[2,3],[3,0],[1,3]],
               "edges_assignment": ["B","B","B","B","V"], "faces_vertices": [[0,1,3],[1,3,2]]}"#,
            "faces oriented",
        ),
        // The same without frame_classes: faces turned both ways may be a flat-folded
        // state, so orientation is not held against it, but the two faces still run the
        // same way along their shared edge (a combinatorial fact).
        (
            r#"{"vertices_coords": [[0,0],[1,0],[1,1],[0,1]], "edges_vertices": [[0,1],[1,2],[2,3],[3,0],[1,3]],
               "edges_assignment": ["B","B","B","B","V"], "faces_vertices": [[0,1,3],[1,3,2]]}"#,
            "manifold",
        ),
        // A crease with a face on one side only.
        (
            r#"{"vertices_coords": [[0,0],[1,0],[1,1],[0,1]], "edges_vertices": [[0,1],[1,2],[2,3],[3,0],[1,3]],
               "edges_assignment": ["B","B","B","B","V"], "faces_vertices": [[0,1,3]]}"#,
            "manifold",
        ),
        // Overlapping faces: sector sums of 4π at the centre vertex.
        (
            r#"{"vertices_coords": [[0,0],[1,0],[0,1],[-1,0],[0,-1]],
               "edges_vertices": [[0,1],[0,2],[0,3],[0,4],[1,2],[2,3],[3,4],[4,1]],
               "edges_assignment": ["U","U","U","U","B","B","B","B"],
               "faces_vertices": [[0,1,2],[0,2,3],[0,3,4],[0,4,1],[0,1,2],[0,2,3],[0,3,4],[0,4,1]]}"#,
            "developability",
        ),
        // Sign of the fold angle against the assignment.
        (
            r#"{"vertices_coords": [[0,0],[1,0],[1,1],[0,1]], "edges_vertices": [[0,1],[1,2],[2,3],[3,0],[1,3]],
               "edges_assignment": ["B","B","B","B","V"], "edges_foldAngle": [0,0,0,0,-90],
               "faces_vertices": [[0,1,3],[1,2,3]]}"#,
            "assignment vs fold angle",
        ),
        // A crease pattern must be planar (in any plane: one triangle always is, so two
        // faces bent against each other).
        (
            r#"{"frame_classes": ["creasePattern"], "vertices_coords": [[0,0,0],[1,0,0],[1,1,0.5],[0,1,0]],
               "faces_vertices": [[0,1,2],[0,2,3]]}"#,
            "flat crease pattern",
        ),
    ];
    for (i, (text, check)) in cases.iter().enumerate() {
        let p = dir.path().join(format!("case{i}.fold"));
        std::fs::write(&p, text).unwrap();
        let o = run(&["verify", p.to_str().unwrap()]);
        assert!(!o.status.success(), "case {i} passed: {}", stdout(&o));
        let failing: Vec<String> = stdout(&o)
            .lines()
            .filter(|l| l.contains("[FAIL]"))
            .map(String::from)
            .collect();
        assert!(
            failing.iter().any(|l| l.contains(check)),
            "case {i}: expected {check:?} to fail:\n{}",
            stdout(&o)
        );
    }
}

#[test]
fn malformed_input_gets_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.fold");
    std::fs::write(
        &bad,
        r#"{"vertices_coords": [[0,0],[1,0],[0,1]], "faces_vertices": [[0,1,9]]}"#,
    )
    .unwrap();
    let o = run(&["verify", bad.to_str().unwrap()]);
    assert!(!o.status.success());
    let e = stderr(&o);
    assert!(
        e.contains("bad.fold") && e.contains("faces_vertices[0][2]") && e.contains("out of range"),
        "{e}"
    );

    let o = run(&["verify", dir.path().join("missing.fold").to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("missing.fold") && stderr(&o).contains("cannot read"),
        "{}",
        stderr(&o)
    );

    let good = format!(
        "{}/tests/data/diagonal_spec_example.fold",
        env!("CARGO_MANIFEST_DIR")
    );
    let o = run(&["verify", "--tol", "-1", &good]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--tol"), "{}", stderr(&o));
}

#[test]
fn export_writes_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let (name, d) = designs().remove(2);
    let design = write_design(dir.path(), name, &d);
    let ds = design.to_str().unwrap();
    let magic: [(&str, &[u8]); 4] = [
        ("png", b"\x89PNG"),
        ("gif", b"GIF89a"),
        ("fold", b"{"),
        ("svg", b"<?xml"),
    ];
    for (fmt, m) in magic {
        let out = dir.path().join(format!("o.{fmt}"));
        let o = run(&[
            "export",
            ds,
            "--format",
            fmt,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{fmt}: {}", stderr(&o));
        let bytes = std::fs::read(&out).unwrap();
        assert!(bytes.starts_with(m), "{fmt}");
    }
    // Default output path: next to the design, with the format's extension.
    let o = run(&["export", ds, "--format", "obj", "--frame", "0"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let obj = std::fs::read_to_string(dir.path().join("gripper.obj")).unwrap();
    // Two arms (second_arm is set): 2 × 9 vertices, 2 objects.
    assert_eq!(obj.lines().filter(|l| l.starts_with("v ")).count(), 18);
    assert_eq!(obj.lines().filter(|l| l.starts_with("o ")).count(), 2);
    // Frame 0 is flat: every z is 0.
    assert!(obj.lines().filter(|l| l.starts_with("v ")).all(|l| {
        l.split_whitespace()
            .nth(3)
            .and_then(|z| z.parse::<f64>().ok())
            == Some(0.0)
    }));

    let out = dir.path().join("a.stl");
    let o = run(&[
        "export",
        ds,
        "--format",
        "stl",
        "--stl-ascii",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    let stl = std::fs::read_to_string(&out).unwrap();
    assert!(stl.starts_with("solid "));
    // 4 quads → 8 triangles per arm.
    assert_eq!(stl.matches("endfacet").count(), 16);

    let all = dir.path().join("all");
    let o = run(&[
        "export",
        ds,
        "--format",
        "all",
        "--out",
        all.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let files: Value = serde_json::from_str(&stdout(&o)).unwrap();
    for key in ["fold", "svg", "obj", "stl", "gif"] {
        assert!(Path::new(files[key].as_str().unwrap()).is_file(), "{key}");
    }
    assert_eq!(files["pngs"].as_array().unwrap().len(), 4);
    let v = run(&["verify", files["fold"].as_str().unwrap()]);
    assert!(v.status.success());
}

#[test]
fn bad_design_files_get_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let (_, d) = designs().remove(0);
    let mut v: Value = serde_json::to_value(&d).unwrap();
    type Edit = Box<dyn Fn(&mut Value)>;
    let cases: Vec<(Edit, &str)> = vec![
        (
            Box::new(|v| v["pattern"]["edges"][0]["v"][1] = 99.into()),
            "pattern.edges[0].v[1]",
        ),
        (
            Box::new(|v| v["meta"]["gripping_vertex"] = 40.into()),
            "meta.gripping_vertex",
        ),
        (
            Box::new(|v| {
                v["pattern"]["frames"][1]["coords"]
                    .as_array_mut()
                    .unwrap()
                    .truncate(3)
            }),
            "pattern.frames[1].coords",
        ),
        (
            // A file from before the scene (no `scene`, a legacy `obstacle`).
            Box::new(|v| {
                v["meta"].as_object_mut().unwrap().remove("scene");
                v["meta"]["obstacle"] = serde_json::json!({"a": [0,0,0], "b": [0,1,0], "radius": 0})
            }),
            "meta.obstacle.radius",
        ),
        (
            Box::new(|v| v["meta"]["modes"] = serde_json::json!(["sideways"])),
            "unknown variant",
        ),
        (
            Box::new(|v| {
                v.as_object_mut()
                    .unwrap()
                    .remove("pattern")
                    .map(|_| ())
                    .unwrap_or(())
            }),
            "missing field `pattern`",
        ),
    ];
    for (i, (edit, what)) in cases.iter().enumerate() {
        let mut w = v.clone();
        edit(&mut w);
        let p = dir.path().join(format!("d{i}.json"));
        std::fs::write(&p, serde_json::to_string(&w).unwrap()).unwrap();
        let o = run(&["export", p.to_str().unwrap(), "--format", "fold"]);
        assert!(!o.status.success(), "case {i} accepted");
        let e = stderr(&o);
        assert!(
            e.contains(&format!("d{i}.json")) && e.contains(what),
            "case {i}: {e}"
        );
    }
    v["pattern"]["frames"] = serde_json::json!([]);
    let p = dir.path().join("noframes.json");
    std::fs::write(&p, serde_json::to_string(&v).unwrap()).unwrap();
    let o = run(&["export", p.to_str().unwrap(), "--format", "gif"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("nothing to animate"), "{}", stderr(&o));
    let o = run(&[
        "export",
        p.to_str().unwrap(),
        "--format",
        "png",
        "--frame",
        "3",
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--frame 3"), "{}", stderr(&o));
}

#[test]
fn documented_design_file_exports_and_verifies() {
    // tests/data/demo_gripper_design.json shows the design JSON `export` reads.
    let design = format!(
        "{}/tests/data/demo_gripper_design.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let d: DesignFile = serde_json::from_str(&std::fs::read_to_string(&design).unwrap()).unwrap();
    assert!(d.meta.second_arm() && d.meta.first_cylinder().is_some());
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.fold");
    let o = run(&[
        "export",
        &design,
        "--format",
        "fold",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run(&["verify", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stdout(&o));
}
