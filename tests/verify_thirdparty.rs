//! `foldsynth verify` on valid FOLD files of other tools' kinds (issues 13 and 20): a
//! crease pattern in the plane y = 0 labelled `foldedForm` with float32 coordinates (as
//! Origami Simulator's examples are), a folded form without a crease pattern, a
//! flat-folded state, no `edges_assignment`, 7 significant digits in a tilted plane. Each
//! passes (exit 0) and says what it could not check; a real violation in each still
//! fails (exit 1); the file's precision is what widens the tolerance (with the numbers
//! taken as exact, rounding to 7 digits fails). The fixtures are written by
//! `tests/data/thirdparty/make.py`.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/thirdparty")
        .join(name)
}

fn verify(path: &Path, extra: &[&str]) -> (Output, Value) {
    let mut args = vec!["verify", path.to_str().unwrap(), "--json"];
    args.extend_from_slice(extra);
    let o = Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(&args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    let v = serde_json::from_slice(&o.stdout).unwrap_or(Value::Null);
    (o, v)
}

fn check<'a>(report: &'a Value, name: &str) -> &'a Value {
    report["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == name)
        .unwrap_or_else(|| panic!("no check {name}: {report}"))
}

/// Write `doc` (a fixture edited) to a temporary file.
fn edited(dir: &Path, name: &str, fixture: &str, edit: impl FnOnce(&mut Value)) -> PathBuf {
    let mut v: Value =
        serde_json::from_str(&std::fs::read_to_string(data(fixture)).unwrap()).unwrap();
    edit(&mut v);
    let p = dir.join(name);
    std::fs::write(&p, v.to_string()).unwrap();
    p
}

#[test]
fn valid_files_of_other_tools_pass_and_say_what_was_not_checked() {
    // (file, what frame 0 is, checks that cannot be made)
    let cases: [(&str, &str, &[&str]); 5] = [
        (
            "pleat_in_plane_y0.fold",
            "crease_pattern",
            &["folded frames"],
        ),
        (
            "folded_form_only.fold",
            "folded_form",
            &["flat crease pattern", "faces oriented"],
        ),
        (
            "flat_folded_state.fold",
            "flat_folded",
            &["flat crease pattern", "faces oriented", "folded frames"],
        ),
        ("no_assignment.fold", "crease_pattern", &[]),
        ("seven_digits_tilted.fold", "crease_pattern", &[]),
    ];
    for (file, kind, unchecked) in cases {
        let (o, r) = verify(&data(file), &[]);
        assert_eq!(o.status.code(), Some(0), "{file}: {r}");
        assert_eq!(r["ok"], true, "{file}");
        assert_eq!(r["key_frame"], kind, "{file}");
        for name in unchecked {
            let c = check(&r, name);
            assert_eq!(c["checked"], false, "{file}: {name}");
            assert!(!c["detail"].as_str().unwrap().is_empty());
        }
        // Every check that could be made was made and passed.
        for c in r["checks"].as_array().unwrap() {
            assert_eq!(c["ok"], true, "{file}: {c}");
        }
    }
    // The pleats lie in y = 0 (the fitted plane's normal is ±y) and are float32.
    let (_, r) = verify(&data("pleat_in_plane_y0.fold"), &[]);
    let normal = &r["plane"][1];
    assert!(
        (normal[1].as_f64().unwrap().abs() - 1.0).abs() < 1e-12,
        "{r}"
    );
    assert_eq!(r["precision"]["float32"], true);
    // Without edges_assignment the boundary comes from the faces.
    let (_, r) = verify(&data("no_assignment.fold"), &[]);
    assert_eq!(r["assignment_derived"], true);
    assert_eq!(r["frames"].as_array().unwrap().len(), 1);
    // Folded form only: the later frame is still compared with frame 0.
    let (_, r) = verify(&data("folded_form_only.fold"), &[]);
    assert!(r["frames"][0]["max_isometry_error"].as_f64().unwrap() < 1e-12);
    assert!(r["frames"][0]["max_fold_angle_error_deg"].as_f64().unwrap() < 1e-9);
}

#[test]
fn rounding_is_allowed_for_what_it_is_and_no_more() {
    let file = data("seven_digits_tilted.fold");
    let (_, r) = verify(&file, &[]);
    assert_eq!(r["precision"]["digits"], 7);
    // Rounding to 7 digits moves the folded frame's distances by about 1e-7 …
    let iso = r["frames"][0]["max_isometry_error"].as_f64().unwrap();
    assert!(iso > 1e-8 && iso < 2e-6, "{iso}");
    // … which fails when the numbers are taken as exact …
    let (o, r) = verify(&file, &["--digits", "17"]);
    assert_eq!(o.status.code(), Some(1), "{r}");
    // … and a user tolerance as wide as the rounding passes again.
    let (o, _) = verify(
        &file,
        &["--digits", "17", "--tol", "1e-5", "--angle-tol", "1e-3"],
    );
    assert_eq!(o.status.code(), Some(0));
}

#[test]
fn real_violations_still_fail() {
    let dir = tempfile::tempdir().unwrap();
    let bad = [
        // A folded frame stretched by 1e-4: not isometric to frame 0.
        edited(dir.path(), "a.fold", "folded_form_only.fold", |v| {
            let z = v["file_frames"][0]["vertices_coords"][7][2]
                .as_f64()
                .unwrap();
            v["file_frames"][0]["vertices_coords"][7][2] = (z + 1e-4).into();
        }),
        // The same, at 7 digits: far beyond the rounding.
        edited(dir.path(), "b.fold", "seven_digits_tilted.fold", |v| {
            let z = v["file_frames"][0]["vertices_coords"][7][2]
                .as_f64()
                .unwrap();
            v["file_frames"][0]["vertices_coords"][7][2] = (z + 1e-4).into();
        }),
        // Declared a crease pattern, but folded.
        edited(dir.path(), "c.fold", "folded_form_only.fold", |v| {
            v["frame_classes"] = serde_json::json!(["creasePattern"]);
        }),
        // A flat-folded state whose stated fold angle is not its geometry.
        edited(dir.path(), "d.fold", "flat_folded_state.fold", |v| {
            v["edges_foldAngle"][8] = 90.into();
        }),
        // A crease pattern whose mountain has a valley's angle.
        edited(dir.path(), "e.fold", "pleat_in_plane_y0.fold", |v| {
            let m = v["edges_assignment"]
                .as_array()
                .unwrap()
                .iter()
                .position(|a| a == "M")
                .unwrap();
            v["edges_foldAngle"][m] = 180.into();
        }),
    ];
    for p in bad {
        let (o, r) = verify(&p, &[]);
        assert_eq!(o.status.code(), Some(1), "{}: {r}", p.display());
        assert_eq!(r["ok"], false);
    }
    // Not FOLD at all: bad input (2), not a failed check.
    let p = dir.path().join("x.fold");
    std::fs::write(&p, "{\"vertices_coords\": 3}").unwrap();
    let (o, _) = verify(&p, &[]);
    assert_eq!(o.status.code(), Some(2));
}
