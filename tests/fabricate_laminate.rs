//! A laminate that can be made (issue 50): `foldsynth fabricate` with kerf, tabs, a sheet,
//! registration crosses and alignment holes, its DXF plies read back with ezdxf
//! (tests/common/fab_files.rs) and judged as geometry: the crosses and holes at the same
//! places on every ply and no flip of a ply bringing its holes onto themselves; every cut
//! half a kerf off its nominal outline; every panel inside the sheet; tab gaps of the tab
//! width; two designs side by side on one sheet; bad values refused naming the flag.

use foldsynth::export::samples;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

#[path = "common/fab_files.rs"]
#[allow(dead_code)]
mod fab_files;
use fab_files::pt;

/// The sample with one crease (an L-shaped, non-convex facet on one side) folded to 2 rad,
/// as a design file named `name`.
fn design(dir: &Path, name: &str) -> PathBuf {
    let p = samples::single_crease(2.0, 9);
    let path = dir.join(name);
    let text = serde_json::json!({"pattern": p, "meta": {"task": "fab-test"}});
    std::fs::write(&path, text.to_string()).unwrap();
    path
}

/// `foldsynth fabricate` at 4 mm and 50 mm per unit with `extra`.
fn fabricate(designs: &[&Path], out: &Path, extra: &[&str]) -> std::process::Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_foldsynth"));
    c.arg("fabricate").args(designs);
    c.args([
        "--thickness",
        "4",
        "--scale",
        "50",
        "--states",
        "flat,folded",
    ]);
    c.args(extra).arg("--out").arg(out);
    c.output().unwrap()
}

fn ok(o: std::process::Output) {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Distance of `p` from the line through `a` and `b`, signed: positive on its right.
fn right_of(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let u = [b[0] - a[0], b[1] - a[1]];
    let l = u[0].hypot(u[1]);
    ((p[0] - a[0]) * u[1] - (p[1] - a[1]) * u[0]) / l
}

fn points(v: &Value) -> Vec<[f64; 2]> {
    v.as_array().unwrap().iter().map(pt).collect()
}

#[test]
fn crosses_and_holes_coincide_on_every_ply_and_panels_lie_inside_the_sheet() {
    let dir = tempfile::tempdir().unwrap();
    let d = design(dir.path(), "d.json");
    let out = dir.path().join("fab");
    ok(fabricate(
        &[&d],
        &out,
        &["--sides", "both", "--sheet", "300x200", "--kerf", "0.2"],
    ));
    let rec = fab_files::record(&out);
    let lam = &rec["laminate"];
    assert_eq!(pt(&lam["sheet_mm"]), [300.0, 200.0]);
    assert_eq!(lam["sheet_given"], true);
    let Some(r) = fab_files::independent_readers(&out) else {
        return;
    };
    let plies = r["plies"].as_object().unwrap();
    assert_eq!(plies.len(), 3, "top, bottom, hinge");
    let holes: Vec<[f64; 2]> = points(&lam["holes_mm"]);
    let marks: Vec<[f64; 2]> = points(&lam["marks_mm"]);
    let arm = lam["mark_arm_mm"].as_f64().unwrap();
    for (name, ply) in plies {
        // The same three holes, half a kerf inside their nominal 3 mm, on every ply.
        let circles = ply["circles"].as_array().unwrap();
        for (c, h) in circles.iter().zip(&holes) {
            assert!((c[0].as_f64().unwrap() - h[0]).abs() < 1e-9, "{name}");
            assert!((c[1].as_f64().unwrap() - h[1]).abs() < 1e-9, "{name}");
            assert!((c[2].as_f64().unwrap() - 1.4).abs() < 1e-9, "{name}");
        }
        // A cross of two lines at each corner mark.
        let reg = ply["register"].as_array().unwrap();
        for m in &marks {
            let through = reg
                .iter()
                .filter(|l| {
                    let (a, b) = (pt(&l[0]), pt(&l[1]));
                    let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
                    let len = (b[0] - a[0]).hypot(b[1] - a[1]);
                    (mid[0] - m[0]).hypot(mid[1] - m[1]) < 1e-9 && (len - 2.0 * arm).abs() < 1e-9
                })
                .count();
            assert_eq!(through, 2, "{name}: cross at {m:?}");
        }
        // Every cut inside the sheet's outline (itself half a kerf outside the sheet).
        for c in ply["cut"].as_array().unwrap() {
            for p in points(&c["points"]) {
                assert!(p[0] >= -0.1 - 1e-9 && p[0] <= 300.1 + 1e-9, "{name}: {p:?}");
                assert!(p[1] >= -0.1 - 1e-9 && p[1] <= 200.1 + 1e-9, "{name}: {p:?}");
            }
        }
    }
    // A ply flipped about either axis or turned half round does not fit: no hole lands on
    // a hole.
    let (w, h) = (300.0, 200.0);
    let flips: [&dyn Fn([f64; 2]) -> [f64; 2]; 3] =
        [&|p| [w - p[0], p[1]], &|p| [p[0], h - p[1]], &|p| {
            [w - p[0], h - p[1]]
        }];
    for f in flips {
        for a in &holes {
            let b = f(*a);
            assert!(
                holes.iter().all(|c| (c[0] - b[0]).hypot(c[1] - b[1]) > 3.0),
                "{a:?}"
            );
        }
    }
}

#[test]
fn every_cut_is_half_a_kerf_off_its_nominal_outline() {
    let dir = tempfile::tempdir().unwrap();
    let d = design(dir.path(), "d.json");
    let (nominal, offset) = (dir.path().join("k0"), dir.path().join("k02"));
    ok(fabricate(&[&d], &nominal, &[]));
    ok(fabricate(&[&d], &offset, &["--kerf", "0.2"]));
    let (Some(a), Some(b)) = (
        fab_files::read_back(&nominal),
        fab_files::read_back(&offset),
    ) else {
        return;
    };
    let shift = |out: &Path| pt(&fab_files::record(out)["laminate"]["offset_mm"]);
    let (sa, sb) = (shift(&nominal), shift(&offset));
    let mut corners = 0;
    for ply in ["rigid", "hinge"] {
        let (ca, cb) = (
            a["plies"][ply]["cut"].as_array().unwrap(),
            b["plies"][ply]["cut"].as_array().unwrap(),
        );
        assert_eq!(ca.len(), cb.len(), "{ply}");
        // Every outline but the sheet's (the last), back in the design's coordinates.
        for (pa, pb) in ca.iter().zip(cb).take(ca.len() - 1) {
            let back = |v: &Value, s: [f64; 2]| -> Vec<[f64; 2]> {
                points(&v["points"])
                    .into_iter()
                    .map(|p| [p[0] - s[0], p[1] - s[1]])
                    .collect()
            };
            let (na, nb) = (back(pa, sa), back(pb, sb));
            let n = na.len();
            assert_eq!(n, nb.len(), "{ply}");
            for k in 0..n {
                // Half a kerf to the right of (outside) both nominal sides at the corner.
                let (prev, here, next) = (na[(k + n - 1) % n], na[k], na[(k + 1) % n]);
                for (x, y) in [(prev, here), (here, next)] {
                    let d = right_of(nb[k], x, y);
                    assert!((d - 0.1).abs() < 1e-9, "{ply}: corner {k}: {d}");
                }
                corners += 1;
            }
        }
        // The sheet's outline: half a kerf outside the sheet.
        let sheet = points(&cb[cb.len() - 1]["points"]);
        assert!((sheet[0][0] + 0.1).abs() < 1e-9 && (sheet[0][1] + 0.1).abs() < 1e-9);
        // The holes: half a kerf inside.
        for c in b["plies"][ply]["circles"].as_array().unwrap() {
            assert!((c[2].as_f64().unwrap() - 1.4).abs() < 1e-9);
        }
    }
    assert!(corners >= 12, "{corners}");
    assert_eq!(fab_files::record(&offset)["laminate"]["kerf_mm"], 0.2);
}

#[test]
fn tabs_leave_gaps_of_the_tab_width_in_every_panel_cut() {
    let dir = tempfile::tempdir().unwrap();
    let d = design(dir.path(), "d.json");
    let out = dir.path().join("tabs");
    ok(fabricate(
        &[&d],
        &out,
        &["--tab-width", "1.5", "--kerf", "0.1"],
    ));
    let rec = fab_files::record(&out);
    let tabs = rec["laminate"]["tabs"].as_array().unwrap();
    let panels = rec["fabrication"]["panels"].as_array().unwrap();
    for p in panels {
        assert!(
            tabs.iter().any(|t| t["panel"] == p["facet"]),
            "P{} has no tab",
            p["facet"]
        );
    }
    let Some(r) = fab_files::read_back(&out) else {
        return;
    };
    let cut = r["plies"]["rigid"]["cut"].as_array().unwrap();
    let open: Vec<Vec<[f64; 2]>> = cut
        .iter()
        .filter(|c| c["closed"] == false)
        .map(|c| points(&c["points"]))
        .collect();
    // One piece of cut ends at each tab; the next piece starts across the gap.
    assert_eq!(open.len(), tabs.len());
    for t in tabs {
        let at = pt(&t["at_mm"]);
        let end = open
            .iter()
            .map(|p| p[p.len() - 1])
            .find(|e| ((e[0] - at[0]).hypot(e[1] - at[1]) - 0.75).abs() < 1e-9);
        let start = open
            .iter()
            .map(|p| p[0])
            .find(|s| ((s[0] - at[0]).hypot(s[1] - at[1]) - 0.75).abs() < 1e-9);
        let (e, s) = (
            end.expect("a cut ends at the tab"),
            start.expect("one starts"),
        );
        let gap = (e[0] - s[0]).hypot(e[1] - s[1]);
        assert!((gap - 1.5).abs() < 1e-9, "{gap}");
    }
    // The hinge ply keeps its cuts whole.
    let hinge = r["plies"]["hinge"]["cut"].as_array().unwrap();
    assert!(hinge.iter().all(|c| c["closed"] == true));
}

#[test]
fn two_designs_lie_side_by_side_on_one_sheet() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (design(dir.path(), "a.json"), design(dir.path(), "b.json"));
    let out = dir.path().join("sheet");
    ok(fabricate(
        &[&a, &b],
        &out,
        &["--sheet", "400x200", "--kerf", "0.2"],
    ));
    for f in [
        "sheet-ply-rigid.dxf",
        "sheet-ply-hinge.svg",
        "a/ply-rigid.dxf",
        "b/fabrication.json",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let layout: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("sheet-layout.json")).unwrap())
            .unwrap();
    assert_eq!(layout["designs"].as_array().unwrap().len(), 2);
    // Read the combined hinge ply back: one outline per design and the sheet's.
    let combined = dir.path().join("combined");
    std::fs::create_dir_all(&combined).unwrap();
    for n in ["rigid", "hinge"] {
        std::fs::copy(
            out.join(format!("sheet-ply-{n}.dxf")),
            combined.join(format!("ply-{n}.dxf")),
        )
        .unwrap();
    }
    let mut rec = fab_files::record(&out.join("a"));
    rec["fabrication"]["panels"] = serde_json::json!([]);
    rec["states"] = serde_json::json!([]);
    std::fs::write(combined.join("fabrication.json"), rec.to_string()).unwrap();
    let Some(r) = fab_files::read_back(&combined) else {
        return;
    };
    let cut = r["plies"]["hinge"]["cut"].as_array().unwrap();
    assert_eq!(cut.len(), 3);
    let boxes: Vec<([f64; 2], [f64; 2])> = cut[..2]
        .iter()
        .map(|c| {
            let p = points(&c["points"]);
            let lo = [0, 1].map(|k| p.iter().map(|q| q[k]).fold(f64::INFINITY, f64::min));
            let hi = [0, 1].map(|k| p.iter().map(|q| q[k]).fold(f64::NEG_INFINITY, f64::max));
            (lo, hi)
        })
        .collect();
    for (lo, hi) in &boxes {
        assert!(
            lo[0] > 0.0 && lo[1] > 0.0 && hi[0] < 400.0 && hi[1] < 200.0,
            "{lo:?} {hi:?}"
        );
    }
    let ((l0, h0), (l1, h1)) = (boxes[0], boxes[1]);
    let apart = h0[0] < l1[0] || h1[0] < l0[0] || h0[1] < l1[1] || h1[1] < l0[1];
    assert!(apart, "{boxes:?}");
    // Every ply of the sheet has the rigid panels of both designs.
    let rigid = r["plies"]["rigid"]["cut"].as_array().unwrap();
    assert_eq!(rigid.len(), 2 * 2 + 1);
    // Too small a sheet for both: refused, naming the flag, nothing written.
    let small = dir.path().join("small");
    let o = fabricate(&[&a, &b], &small, &["--sheet", "120x100"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--sheet") && err.contains("120x100"), "{err}");
    assert!(!small.exists());
}

#[test]
fn bad_laminate_values_exit_2_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (design(dir.path(), "a.json"), design(dir.path(), "b.json"));
    let out = dir.path().join("bad");
    for (extra, flag, words) in [
        (&["--kerf", "-0.2"][..], "--kerf", &["[0, "][..]),
        (&["--kerf", "nan"][..], "--kerf", &["[0, "][..]),
        (&["--sheet", "axb"][..], "--sheet", &["WxH"][..]),
        (&["--sheet", "20x20"][..], "--sheet", &["too small"][..]),
        (&["--tab-width", "-1"][..], "--tab-width", &["[0, "][..]),
        (
            &["--tab-width", "80"][..],
            "--tab-width",
            &["longest side"][..],
        ),
        (&["--hole", "0"][..], "--hole", &["(0, "][..]),
        (
            &["--hole", "0.1", "--kerf", "0.2"][..],
            "--hole",
            &["kerf"][..],
        ),
    ] {
        let o = fabricate(&[&a], &out, extra);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(flag), "{extra:?}: {err}");
        for w in words {
            assert!(err.contains(w), "{extra:?}: no {w:?} in {err}");
        }
        assert!(!err.contains("panicked"), "{err}");
    }
    // Several designs need a sheet.
    let o = fabricate(&[&a, &b], &out, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--sheet"), "{err}");
    assert!(!out.exists());
}
