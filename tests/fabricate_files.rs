//! `foldsynth fabricate` end to end (issue 32): the files it writes read back by
//! independent readers (ezdxf for the DXF, trimesh for STL and 3MF, when Python has them;
//! `FOLDSYNTH_REQUIRE_FAB_TOOLS=1` makes their absence a failure), the STL read back here
//! by `stl_io` and judged closed, outward and equal to the rigid motion of the flat panels,
//! and bad values refused with the flag named.

use foldsynth::export::samples;
use foldsynth::fabricate;
use foldsynth::geom;
use foldsynth::task::fabrication::{FabMethod, Fabrication, Sides};
use std::path::{Path, PathBuf};
use std::process::Command;

#[path = "common/fab_files.rs"]
#[allow(dead_code)]
mod fab_files;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_foldsynth"))
}

/// A design file of the sample with one crease (an L-shaped, non-convex facet on one side),
/// folded to 2 rad in 9 frames.
fn design(dir: &Path) -> (PathBuf, foldsynth::pattern::Pattern) {
    let p = samples::single_crease(2.0, 9);
    let path = dir.join("design.json");
    let text = serde_json::json!({"pattern": p, "meta": {"task": "fab-test"}});
    std::fs::write(&path, text.to_string()).unwrap();
    (path, p)
}

fn run(args: &[&str]) -> std::process::Output {
    bin().args(args).output().unwrap()
}

/// The STL's triangles with corners merged by exact value: closed (each directed edge once,
/// its opposite once), positive volume.
fn stl_closed_volume(path: &Path) -> f64 {
    let mut f = std::fs::File::open(path).unwrap();
    let mesh = stl_io::read_stl(&mut f).unwrap();
    let mut directed = std::collections::HashMap::new();
    let mut vol = 0.0;
    for t in &mesh.faces {
        let [a, b, c] = t.vertices;
        for (x, y) in [(a, b), (b, c), (c, a)] {
            *directed.entry((x, y)).or_insert(0) += 1;
        }
        let v = |i: usize| mesh.vertices[i].0.map(f64::from);
        vol += geom::dot(v(a), geom::cross(v(b), v(c))) / 6.0;
    }
    for (&(x, y), &n) in &directed {
        assert_eq!(n, 1, "{}: edge used {n} times", path.display());
        assert_eq!(
            directed.get(&(y, x)),
            Some(&1),
            "{}: open edge",
            path.display()
        );
    }
    vol
}

#[test]
fn written_files_read_back_as_built() {
    let dir = tempfile::tempdir().unwrap();
    let (path, pattern) = design(dir.path());
    let out = dir.path().join("fab");
    let o = run(&[
        "fabricate",
        path.to_str().unwrap(),
        "--thickness",
        "4",
        "--scale",
        "50",
        "--hinge-gap",
        "0.4",
        "--states",
        "flat,half,folded",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("thick check on the design's 9 frames: passes"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    // The same build here, for what the files must hold.
    let spec = Fabrication {
        thickness: 4.0,
        scale: 50.0,
        method: FabMethod::Tapered,
        sides: Sides::One,
        hinge_gap: 0.4,
        min_width: 2.0,
    };
    let ranges = fabricate::fold_ranges_refined(&pattern, &pattern.frames);
    let thick = fabricate::build(&pattern, &ranges, &spec).unwrap();
    // Every panel closed with its volume; the assembly at the last frame is the rigid motion
    // of the flat panels (STL holds f32: compare to 1e-4 mm).
    for (k, s) in thick.flat_solids().iter().enumerate() {
        let v = stl_closed_volume(&out.join(format!("panel-{k}.stl")));
        let want: f64 = s
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| geom::scale(s.vertices[i], 50.0));
                geom::dot(a, geom::cross(b, c)) / 6.0
            })
            .sum();
        assert!(
            want > 0.0 && (v - want).abs() < 1e-4 * want,
            "{v} vs {want}"
        );
    }
    let last = pattern.frames.last().unwrap();
    let mut f = std::fs::File::open(out.join("assembly-folded.stl")).unwrap();
    let mesh = stl_io::read_stl(&mut f).unwrap();
    let moved = thick.solids_at(&pattern, last);
    let mut i = 0;
    for s in &moved {
        for t in &s.triangles {
            let face = &mesh.faces[i];
            for (k, &vi) in t.iter().enumerate() {
                let got = mesh.vertices[face.vertices[k]].0.map(f64::from);
                let want = geom::scale(s.vertices[vi], 50.0);
                assert!(geom::dist(got, want) < 1e-4, "{got:?} vs {want:?}");
            }
            i += 1;
        }
    }
    assert_eq!(i, mesh.faces.len());
    assert!(stl_closed_volume(&out.join("assembly-folded.stl")) > 0.0);
    let bill: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("fabrication.json")).unwrap())
            .unwrap();
    // Two panels across one crease, trimmed for its largest fold: they never cross.
    assert_eq!(bill["check"]["states"], 9);
    assert_eq!(bill["check"]["crossings"], 0);
    assert!(bill["check"]["first_failure"].is_null());
    let crease = &bill["fabrication"]["creases"][0];
    // The bill's fold is the motion's: the sample folds its crease to 2 rad.
    assert!((crease["valley_deg"].as_f64().unwrap() - 2f64.to_degrees()).abs() < 1e-9);
    assert!((crease["hinge_length_mm"].as_f64().unwrap() - 50.0).abs() < 1e-9);
    let gap = 0.4 + 2.0 * 4.0 * 1f64.tan();
    assert!((crease["gap_mm"].as_f64().unwrap() - gap).abs() < 1e-9);
    independent_readers(&out, &thick);
}

/// The files read back independently (tests/common/fab_files.rs), and the rigid ply's cuts
/// the panels' top layers of this test's own build, in mm, moved onto the sheet.
fn independent_readers(out: &Path, thick: &fabricate::ThickDesign) {
    let Some(r) = fab_files::independent_readers(out) else {
        return;
    };
    let offset = fab_files::pt(&fab_files::record(out)["laminate"]["offset_mm"]);
    let cut = r["plies"]["rigid"]["cut"].as_array().unwrap();
    for (panel, poly) in thick.panels.iter().zip(cut) {
        let top = &panel.layers.last().unwrap().outline;
        let pts = poly["points"].as_array().unwrap();
        assert_eq!(pts.len(), top.len());
        for (p, q) in top.iter().zip(pts) {
            let q = fab_files::pt(q);
            for k in 0..2 {
                assert!((p[k] * 50.0 + offset[k] - q[k]).abs() < 1e-9);
            }
        }
    }
    assert_eq!(r["plies"]["hinge"]["lines"]["VALLEY"], 1);
}

#[test]
fn bad_values_are_refused_naming_the_flag_or_the_crease() {
    let dir = tempfile::tempdir().unwrap();
    let (path, _) = design(dir.path());
    let out = dir.path().join("fab");
    let base = |extra: &[&str]| {
        let mut a = vec![
            "fabricate",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        run(&a)
    };
    for (args, flag) in [
        (vec!["--thickness", "0", "--scale", "10"], "--thickness"),
        (vec!["--thickness", "-1", "--scale", "10"], "--thickness"),
        (vec!["--thickness", "nan", "--scale", "10"], "--thickness"),
        (vec!["--thickness", "inf", "--scale", "10"], "--thickness"),
        (vec!["--thickness", "1", "--scale", "0"], "--scale"),
        (
            vec!["--thickness", "1", "--scale", "10", "--method", "folded"],
            "--method",
        ),
        (
            vec!["--thickness", "1", "--scale", "10", "--sides", "three"],
            "--sides",
        ),
        (
            vec!["--thickness", "1", "--scale", "10", "--hinge-gap", "-1"],
            "--hinge-gap",
        ),
        (
            vec![
                "--thickness",
                "1",
                "--scale",
                "10",
                "--states",
                "flat,upside",
            ],
            "--states",
        ),
    ] {
        let o = base(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(flag), "{args:?}: {err}");
    }
    // Thickness that leaves no panel: named crease and file.
    let o = base(&["--thickness", "400", "--scale", "100"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("crease 0") && err.contains("design.json"),
        "{err}"
    );
}

/// Two unit squares apart in the flat layout (no crease between them); in the one folded
/// frame the second lies flat over the first at height `h` (paper units).
fn stacked_design(dir: &Path, h: f64) -> PathBuf {
    use foldsynth::pattern::{Edge, EdgeKind, Frame, Pattern};
    let sq = |x: f64| [[x, 0.0], [x + 1.0, 0.0], [x + 1.0, 1.0], [x, 1.0]];
    let vertices: Vec<[f64; 2]> = sq(0.0).into_iter().chain(sq(3.0)).collect();
    let mut coords: Vec<[f64; 3]> = sq(0.0).iter().map(|p| [p[0], p[1], 0.0]).collect();
    coords.extend(sq(0.0).iter().map(|p| [p[0], p[1], h]));
    let edges: Vec<Edge> = (0..8)
        .map(|i| Edge {
            v: [i, 4 * (i / 4) + (i + 1) % 4],
            kind: EdgeKind::Boundary,
        })
        .collect();
    let frame = |t: f64, coords: Vec<[f64; 3]>| Frame {
        t,
        coords,
        fold_angles: vec![0.0; 8],
    };
    let flat = vertices.iter().map(|v| [v[0], v[1], 0.0]).collect();
    let p = Pattern {
        vertices,
        edges,
        faces: vec![vec![0, 1, 2, 3], vec![4, 5, 6, 7]],
        frames: vec![frame(0.0, flat), frame(1.0, coords)],
    };
    let path = dir.join(format!("stacked-{h}.json"));
    let text = serde_json::json!({"pattern": p, "meta": {"task": "fab-test"}});
    std::fs::write(&path, text.to_string()).unwrap();
    path
}

#[test]
fn panels_that_collide_are_reported_naming_them() {
    // 2 mm panels at 100 mm per unit on one side: each slab reaches 0.02 units above its
    // facet, so a square 0.015 units over the other overlaps it, one 0.03 over it is 1 mm
    // clear of it (3 mm less the 2 mm slab).
    let dir = tempfile::tempdir().unwrap();
    let fab = |h: f64, clearance: &str| {
        let path = stacked_design(dir.path(), h);
        let out = dir.path().join(format!("fab-{h}-{clearance}"));
        let o = run(&[
            "fabricate",
            path.to_str().unwrap(),
            "--thickness",
            "2",
            "--scale",
            "100",
            "--clearance",
            clearance,
            "--states",
            "flat,folded",
            "--out",
            out.to_str().unwrap(),
        ]);
        // No bill when the command refuses its flags.
        let bill: serde_json::Value = std::fs::read_to_string(out.join("fabrication.json"))
            .map_or(serde_json::Value::Null, |t| {
                serde_json::from_str(&t).unwrap()
            });
        (o, bill)
    };
    let (o, bill) = fab(0.015, "0.5");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("collide") && err.contains("P0, P1") && err.contains("t = 1.0000"),
        "{err}"
    );
    assert_eq!(bill["check"]["first_failure"]["kind"], "clearance");
    assert_eq!(bill["check"]["least_apart"], 0.0);
    // 1 mm apart: clear with the default 0.5 mm, not with 1.5 mm.
    let (o, bill) = fab(0.03, "0.5");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let apart = bill["check"]["least_apart"].as_f64().unwrap();
    assert!((apart - 0.01).abs() < 1e-12, "{apart}");
    let (o, _) = fab(0.03, "1.5");
    assert_eq!(o.status.code(), Some(1));
    let (o, bill) = fab(0.03, "-1");
    assert_eq!(o.status.code(), Some(2));
    assert!(bill.is_null());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--clearance"));
}

/// `design(dir)` with the `fabrication` block a search writes for a task with
/// `[fabrication]`: the bill of the sample built at 4 mm and 50 mm per unit (`edit` changes
/// it before it is written).
fn design_with_bill(dir: &Path, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let p = samples::single_crease(2.0, 9);
    let spec = Fabrication {
        thickness: 4.0,
        scale: 50.0,
        method: FabMethod::Tapered,
        sides: Sides::Both,
        hinge_gap: 0.3,
        min_width: 1.0,
    };
    let ranges = fabricate::fold_ranges_refined(&p, &p.frames);
    let bill = fabricate::build(&p, &ranges, &spec).unwrap().bill();
    let mut doc = serde_json::json!({"pattern": p, "meta": {"task": "fab-test"},
        "fabrication": {"bill": bill}});
    edit(&mut doc);
    let path = dir.join("design-bill.json");
    std::fs::write(&path, doc.to_string()).unwrap();
    path
}

#[test]
fn the_material_comes_from_the_design_unless_a_flag_overrides_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = design_with_bill(dir.path(), |_| {});
    let fab = |extra: &[&str], out: &str| {
        let out = dir.path().join(out);
        let mut a = vec![
            "fabricate",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        let o = run(&a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = std::fs::read_to_string(out.join("fabrication.json")).unwrap();
        (
            o,
            serde_json::from_str::<serde_json::Value>(&text).unwrap(),
            out,
        )
    };
    // No flags: every value is the bill's (4 mm, 50 mm per unit, both sides, 0.3 mm gap).
    let (o, rec, out) = fab(&[], "from-design");
    let b = &rec["fabrication"];
    assert_eq!(b["thickness_mm"], 4.0);
    assert_eq!(b["scale_mm_per_unit"], 50.0);
    assert_eq!(b["sides"], "both");
    assert_eq!(b["hinge_gap_mm"], 0.3);
    for k in [
        "thickness",
        "scale",
        "sides",
        "hinge_gap",
        "min_width",
        "method",
    ] {
        assert_eq!(rec["material_from"][k], "design", "{k}");
    }
    assert!(out.join("ply-top.dxf").exists() && out.join("ply-bottom.dxf").exists());
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(
        said.contains("thickness from the design, scale from the design"),
        "{said}"
    );
    // A flag wins over the bill, and the record says so.
    let (_, rec, _) = fab(&["--thickness", "3", "--sides", "one"], "override");
    assert_eq!(rec["fabrication"]["thickness_mm"], 3.0);
    assert_eq!(rec["fabrication"]["sides"], "one");
    assert_eq!(rec["fabrication"]["scale_mm_per_unit"], 50.0);
    assert_eq!(rec["material_from"]["thickness"], "flag");
    assert_eq!(rec["material_from"]["sides"], "flag");
    assert_eq!(rec["material_from"]["scale"], "design");
    // The flagged thickness is the one built: the crease's gap is 0.3 + 2·3·tan(1).
    let gap = rec["fabrication"]["creases"][0]["gap_mm"].as_f64().unwrap();
    assert!((gap - (0.3 + 6.0 * 1f64.tan())).abs() < 1e-9, "{gap}");
}

#[test]
fn without_a_bill_or_with_a_bad_one_the_error_names_what_is_missing() {
    let dir = tempfile::tempdir().unwrap();
    let (plain, _) = design(dir.path());
    let out = dir.path().join("fab");
    let refused = |args: &[&str], want: &[&str]| {
        let o = run(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        for w in want {
            assert!(err.contains(w), "{args:?}: no {w:?} in {err}");
        }
    };
    let (p, o) = (plain.to_str().unwrap(), out.to_str().unwrap());
    refused(
        &["fabricate", p, "--out", o],
        &["--thickness: required", "design.json", "fabrication.bill"],
    );
    refused(
        &["fabricate", p, "--thickness", "2", "--out", o],
        &["--scale: required"],
    );
    let bad = design_with_bill(dir.path(), |d| {
        d["fabrication"]["bill"]["thickness_mm"] = serde_json::json!(-1.0)
    });
    refused(
        &["fabricate", bad.to_str().unwrap(), "--out", o],
        &[
            "design-bill.json",
            "fabrication.bill.thickness_mm",
            "(0, 10000]",
        ],
    );
    let bad = design_with_bill(dir.path(), |d| {
        d["fabrication"]["bill"]["sides"] = serde_json::json!("three")
    });
    refused(
        &["fabricate", bad.to_str().unwrap(), "--out", o],
        &["fabrication.bill.sides", "allowed: one, both"],
    );
    let bad = design_with_bill(dir.path(), |d| {
        d["fabrication"]["bill"] = serde_json::json!({"thickness_mm": "thick"})
    });
    refused(
        &["fabricate", bad.to_str().unwrap(), "--out", o],
        &["fabrication.bill is not a bill"],
    );
}
