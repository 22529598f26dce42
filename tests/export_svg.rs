//! SVG output parses as XML; the crease pattern has one line per edge with Origami
//! Simulator's colour for its assignment, its opacity encodes the final fold angle, and
//! its end points are the pattern's vertices.

use std::f64::consts::PI;

use foldsynth::export::fold::{Assignment, assignments};
use foldsynth::export::plots::{
    DistributionPlot, NodeStatus, Series, TreeNode, distribution_svg, search_tree_svg,
};
use foldsynth::export::render::{Camera, Scene};
use foldsynth::export::svg::{SvgOptions, crease_pattern_svg, svg_scale};
use foldsynth::export::{DesignFile, DesignMeta, samples};
use foldsynth::pattern::Pattern;

#[path = "common/origami_simulator.rs"]
mod origami_simulator;
use origami_simulator::{DEFAULT_TOLERANCE, compare, import_svg};

fn expected_color(a: Assignment) -> &'static str {
    match a {
        Assignment::M => "#ff0000",
        Assignment::V => "#0000ff",
        Assignment::B => "#000000",
        Assignment::F => "#ffff00",
        other => panic!("unexpected assignment {other:?}"),
    }
}

fn check_crease_pattern(p: &Pattern, labels: bool) {
    let o = SvgOptions {
        labels,
        ..SvgOptions::default()
    };
    let text = crease_pattern_svg(p, &o).unwrap();
    let doc = roxmltree::Document::parse(&text).expect("well-formed XML");
    let root = doc.root_element();
    assert_eq!(root.tag_name().name(), "svg");
    assert_eq!(
        root.tag_name().namespace(),
        Some("http://www.w3.org/2000/svg")
    );
    let lines: Vec<_> = root.children().filter(|n| n.has_tag_name("line")).collect();
    // One line per edge, none nested in groups (Origami Simulator reads top-level shapes).
    assert_eq!(lines.len(), p.edges.len());
    assert_eq!(
        root.descendants()
            .filter(|n| n.has_tag_name("line"))
            .count(),
        p.edges.len()
    );
    assert_eq!(
        root.descendants()
            .filter(|n| n.has_tag_name("path"))
            .count(),
        0
    );
    let asg = assignments(p);
    let last = p.frames.last().unwrap();
    let (minx, maxy) = (
        p.vertices
            .iter()
            .map(|v| v[0])
            .fold(f64::INFINITY, f64::min),
        p.vertices
            .iter()
            .map(|v| v[1])
            .fold(f64::NEG_INFINITY, f64::max),
    );
    let mut seen = vec![false; p.edges.len()];
    for l in &lines {
        let i: usize = l.attribute("data-edge").unwrap().parse().unwrap();
        assert!(!seen[i]);
        seen[i] = true;
        assert_eq!(
            l.attribute("stroke"),
            Some(expected_color(asg[i])),
            "edge {i}"
        );
        assert_eq!(l.attribute("data-assignment"), Some(asg[i].as_str()));
        let op: f64 = l.attribute("stroke-opacity").unwrap().parse().unwrap();
        let angle = last.fold_angles[i].to_degrees();
        match asg[i] {
            Assignment::M | Assignment::V => {
                assert!((op - angle.abs() / 180.0).abs() < 1e-6, "edge {i}")
            }
            _ => assert_eq!(op, 1.0),
        }
        // End points: x right, y flipped, 200 px per unit (these samples' features are
        // large), 20 px margin.
        let e = &p.edges[i];
        let coord = |k: &str| -> f64 { l.attribute(k).unwrap().parse().unwrap() };
        for (end, (xa, ya)) in [("1", ("x1", "y1")), ("2", ("x2", "y2"))] {
            let v = p.vertices[e.v[if end == "1" { 0 } else { 1 }]];
            assert!((coord(xa) - ((v[0] - minx) * 200.0 + 20.0)).abs() < 1e-3);
            assert!((coord(ya) - ((maxy - v[1]) * 200.0 + 20.0)).abs() < 1e-3);
        }
    }
    let texts = root.children().filter(|n| n.has_tag_name("text")).count();
    assert_eq!(texts, if labels { p.vertices.len() } else { 0 });
    assert_eq!(svg_scale(p, &o).unwrap().px_per_unit, 200.0);
}

#[test]
fn crease_pattern_lines_have_the_right_colours() {
    check_crease_pattern(&samples::degree4(PI / 3.0, PI / 2.0, 5), false);
    check_crease_pattern(&samples::degree4(1.3, 2.0, 3), true);
    check_crease_pattern(&samples::single_crease(1.0, 4), true);
    // A crease that never folds is F (yellow).
    let mut p = samples::single_crease(1.0, 2);
    for f in &mut p.frames {
        f.fold_angles[0] = 0.0;
    }
    check_crease_pattern(&p, false);
    let grey = crease_pattern_svg(
        &p,
        &SvgOptions {
            flat_grey: true,
            ..SvgOptions::default()
        },
    )
    .unwrap();
    assert!(grey.contains("stroke=\"#808080\""));
}

#[test]
fn folded_state_svg_and_plots_parse() {
    let (p, m) = samples::demo_gripper();
    let scene = Scene::new(&p, &m, Camera::default()).unwrap();
    for k in [None, Some(0), Some(p.frames.len() - 1)] {
        let text = scene.svg(k, (400, 300));
        let doc = roxmltree::Document::parse(&text).unwrap();
        // Both arms' facets (2 × 4) plus the cylinder (24 sides + 2 caps).
        let polys = doc
            .descendants()
            .filter(|n| n.has_tag_name("polygon"))
            .count();
        assert_eq!(polys, 8 + 26);
        // The target is drawn.
        assert!(
            doc.descendants()
                .any(|n| n.has_tag_name("circle") && n.attribute("fill") == Some("#dc1e1e"))
        );
    }
    let nodes = vec![
        TreeNode {
            id: 1,
            parent: None,
            label: "2".into(),
            level: 1,
            status: NodeStatus::Meaningful,
        },
        TreeNode {
            id: 2,
            parent: Some(1),
            label: "2, 3".into(),
            level: 2,
            status: NodeStatus::Meaningful,
        },
        TreeNode {
            id: 3,
            parent: Some(1),
            label: "2, 5".into(),
            level: 2,
            status: NodeStatus::Mirror,
        },
    ];
    roxmltree::Document::parse(&search_tree_svg(&nodes).unwrap()).unwrap();
    let plot = DistributionPlot {
        title: "Gripper & co <test>".into(),
        x_label: "rule applications".into(),
        y_label: "designs".into(),
        series: vec![Series {
            name: "all".into(),
            points: vec![[1.0, 2.0], [2.0, 5.0]],
        }],
    };
    let doc_text = distribution_svg(&plot).unwrap();
    let doc = roxmltree::Document::parse(&doc_text).unwrap();
    assert!(
        doc.descendants()
            .any(|n| n.text() == Some("Gripper & co <test>"))
    );
}

#[test]
fn flat_pattern_without_frames_still_draws() {
    let mut p = samples::single_crease(1.0, 0);
    p.frames.clear();
    let text = crease_pattern_svg(&p, &SvgOptions::default()).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    // No motion: the crease is flat (F).
    assert!(
        doc.descendants()
            .any(|n| n.attribute("data-assignment") == Some("F"))
    );
    let meta = DesignMeta::default();
    let scene = Scene::new(&p, &meta, Camera::default()).unwrap();
    assert!(scene.png(None, (64, 64)).unwrap().starts_with(b"\x89PNG"));
    assert!(
        scene
            .gif((64, 64), 5, 10)
            .unwrap_err()
            .to_string()
            .contains("nothing to animate")
    );
}

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data");

/// The five gripper designs issue 20 found altered by Origami Simulator's SVG import (from
/// a search before `min_feature` existed; crease pattern and last frame only).
const SLIVERS: [&str; 5] = [
    "g16-c2-udd",
    "g25-c2-uuu",
    "g24-c3-ddd",
    "g40-c3-uuu",
    "g13-c3-udu",
];

fn sliver(id: &str) -> Pattern {
    DesignFile::read(std::path::Path::new(&format!("{DATA}/slivers/{id}.json")))
        .unwrap()
        .pattern
}

/// `p` with one vertex moved (the frames keep their states: the SVG draws the flat layout
/// and the last fold angles only).
fn moved(mut p: Pattern, v: usize, to: [f64; 2]) -> Pattern {
    p.vertices[v] = to;
    p
}

/// Every pattern the tests export: samples, the demo design, the sliver designs and
/// synthetic slivers of both kinds, small enough to need a larger page and too small for
/// the largest page.
fn exported_patterns() -> Vec<(String, Pattern)> {
    let mut v: Vec<(String, Pattern)> = vec![
        (
            "degree4 π/3".into(),
            samples::degree4(PI / 3.0, PI / 2.0, 5),
        ),
        ("degree4 1.3".into(), samples::degree4(1.3, 2.0, 3)),
        ("single crease".into(), samples::single_crease(1.0, 4)),
        ("demo gripper".into(), samples::demo_gripper().0),
        ("demo arm".into(), samples::demo_arm().0),
        (
            "demo design file".into(),
            DesignFile::read(std::path::Path::new(&format!(
                "{DATA}/demo_gripper_design.json"
            )))
            .unwrap()
            .pattern,
        ),
    ];
    for id in SLIVERS {
        v.push((id.into(), sliver(id)));
    }
    // single_crease's notch corner v4 (0.5, 0.3) moved down to 0.001 and 1e-5 above the
    // crease v1–v2; its corner v3 (1, 0.3) moved to 0.001 and 1e-5 above v2.
    for eps in [1e-3, 1e-5] {
        v.push((
            format!("vertex {eps} from a crease"),
            moved(samples::single_crease(1.0, 4), 3, [0.5, eps]),
        ));
        v.push((
            format!("edge of length {eps}"),
            moved(samples::single_crease(1.0, 4), 2, [1.0, eps]),
        ));
    }
    v
}

/// Origami Simulator's import rules applied to every SVG the tests export give back the
/// exported graph: at the default 3 px tolerance where the scale note says so, else at the
/// tolerance the note names.
#[test]
fn origami_simulator_imports_every_exported_svg_exactly() {
    let o = SvgOptions::default();
    let (mut fit, mut not_fit) = (0, Vec::new());
    for (name, p) in exported_patterns() {
        let sc = svg_scale(&p, &o).unwrap();
        let text = crease_pattern_svg(&p, &o).unwrap();
        let tol = sc.import_tolerance_px.expect("no coincident vertices");
        if sc.imports_with_default_tolerance() {
            fit += 1;
            assert_eq!(tol, DEFAULT_TOLERANCE);
            assert!(sc.min_feature_px.unwrap() >= 3.1, "{name}: {sc:?}");
            assert!(sc.width_px.max(sc.height_px) <= o.max_page_px || sc.px_per_unit == o.scale);
        } else {
            // The page is as large as allowed and the note says what to do.
            not_fit.push(name.clone());
            assert!(!sc.features_fit, "{name}: {sc:?}");
            let side = sc.width_px.max(sc.height_px);
            assert!((side - o.max_page_px).abs() < 1e-6, "{name}: {sc:?}");
            assert!(tol < sc.min_feature_px.unwrap(), "{name}: {sc:?}");
            assert!(
                sc.note.contains(&format!("{tol} px or less")),
                "{}",
                sc.note
            );
            assert!(text.contains("WARNING"), "{name}");
        }
        if let Err(e) = compare(&p, &o, &import_svg(&text, tol)) {
            panic!("{name}: {} at {tol} px: {e}", sc.note);
        }
    }
    // All but the two 1e-5 slivers and g16-c2-udd fit on a page within 16384 px: its
    // smallest feature, 0.00028 units (v4 from edge v8–v10), times the most the page allows
    // (16384 − 40 px over the layout's 1.56-unit height) is 2.97 px.
    assert_eq!(
        not_fit,
        [
            "g16-c2-udd",
            "vertex 0.00001 from a crease",
            "edge of length 0.00001"
        ]
    );
    assert_eq!(fit, exported_patterns().len() - 3);
}

/// The rules reproduce what issue 20 saw Origami Simulator do to the five designs at the
/// old fixed 200 px per unit, and the scale the export now picks imports them unchanged.
#[test]
fn at_200_px_per_unit_the_sliver_designs_changed_on_import() {
    let old = SvgOptions {
        min_feature_px: 0.0,
        ..SvgOptions::default()
    };
    let imported = |id: &str| {
        let p = sliver(id);
        let text = crease_pattern_svg(&p, &old).unwrap();
        assert_eq!(svg_scale(&p, &old).unwrap().px_per_unit, 200.0);
        (p.clone(), import_svg(&text, DEFAULT_TOLERANCE))
    };
    let count = |im: &origami_simulator::Imported, c: char| {
        im.assignment.iter().filter(|&&a| a == c).count()
    };
    let written = |p: &Pattern, c: &str| assignments(p).iter().filter(|a| a.as_str() == c).count();
    for id in SLIVERS {
        let (p, im) = imported(id);
        let e = compare(&p, &old, &im).expect_err(id);
        match id {
            // A vertex 0.00028 units (0.056 px) from a boundary edge splits it.
            // (v4 splits boundary edge v8–v10 into v8–v4, which is already a boundary edge
            // and is dropped as a duplicate, and v4–v10.)
            "g16-c2-udd" => {
                assert_eq!(im.coords.len(), p.vertices.len(), "{id}: {e}");
                assert_eq!(count(&im, 'B'), written(&p, "B"), "{id}: {e}");
                assert!(e.contains("(v4–v10) is no written edge"), "{id}: {e}");
            }
            // Two vertices 2.57 px apart merge.
            "g25-c2-uuu" => assert_eq!(im.coords.len(), p.vertices.len() - 1, "{id}: {e}"),
            // A valley crease is split, and a boundary edge becomes a valley at 44.7°.
            "g24-c3-ddd" => {
                assert!(count(&im, 'V') > written(&p, "V"), "{id}: {e}");
                assert!(
                    im.assignment
                        .iter()
                        .zip(&im.angle)
                        .any(|(&a, g)| a == 'V' && g.is_some_and(|g| (g - 44.7).abs() < 0.05)),
                    "{id}: {e}"
                );
            }
            // A mountain crease is split.
            "g40-c3-uuu" => assert_eq!(count(&im, 'M'), written(&p, "M") + 1, "{id}: {e}"),
            // A boundary edge is lost.
            "g13-c3-udu" => assert_eq!(count(&im, 'B'), written(&p, "B") - 1, "{id}: {e}"),
            _ => unreachable!(),
        }
        // At a tolerance below the smallest feature the old file imports exactly too.
        let m = svg_scale(&p, &old).unwrap().min_feature_px.unwrap();
        let text = crease_pattern_svg(&p, &old).unwrap();
        compare(&p, &old, &import_svg(&text, 0.9 * m)).unwrap();
    }
}

/// Where the page cannot reach 3 px, the default tolerance does change the pattern: the
/// note's warning is needed.
#[test]
fn below_the_tolerance_the_importer_merges_and_splits() {
    let o = SvgOptions::default();
    // Two vertices 1e-5 apart (0.14 px on the largest page) merge.
    let p = moved(samples::single_crease(1.0, 4), 2, [1.0, 1e-5]);
    let text = crease_pattern_svg(&p, &o).unwrap();
    let im = import_svg(&text, DEFAULT_TOLERANCE);
    assert_eq!(im.coords.len(), p.vertices.len() - 1);
    // A vertex 1e-5 above the crease splits it: one more valley edge.
    let p = moved(samples::single_crease(1.0, 4), 3, [0.5, 1e-5]);
    let text = crease_pattern_svg(&p, &o).unwrap();
    let im = import_svg(&text, DEFAULT_TOLERANCE);
    assert_eq!(im.assignment.iter().filter(|&&a| a == 'V').count(), 2);
    assert!(compare(&p, &o, &im).is_err());
}

#[test]
fn the_scale_is_a_round_number_when_it_grows() {
    // A feature of 0.001 units needs 3100 px per unit: 5000 it is (page 6040 px high).
    let p = moved(samples::single_crease(1.0, 4), 3, [0.5, 1e-3]);
    let sc = svg_scale(&p, &SvgOptions::default()).unwrap();
    assert_eq!(sc.px_per_unit, 5000.0);
    assert!((sc.height_px - (1.2 * 5000.0 + 40.0)).abs() < 1e-6);
    assert!((sc.min_feature_px.unwrap() - 5.0).abs() < 1e-9);
    assert_eq!(sc.min_feature_where.as_deref(), Some("v4 ↔ edge v1–v2"));
    // A smaller largest page: the exact need (3100), then the largest page.
    let o = SvgOptions {
        max_page_px: 4000.0,
        ..SvgOptions::default()
    };
    let sc = svg_scale(&p, &o).unwrap();
    assert!((sc.px_per_unit - 3100.0).abs() < 1e-6);
    let o = SvgOptions {
        max_page_px: 3000.0,
        ..SvgOptions::default()
    };
    let sc = svg_scale(&p, &o).unwrap();
    assert!((sc.px_per_unit - (3000.0 - 40.0) / 1.2).abs() < 1e-6);
    assert!(!sc.features_fit && !sc.imports_with_default_tolerance());
    assert_eq!(sc.import_tolerance_px, Some(2.0));
    // Bad options are errors, not panics.
    for bad in [
        SvgOptions {
            max_page_px: 30.0,
            ..SvgOptions::default()
        },
        SvgOptions {
            min_feature_px: f64::NAN,
            ..SvgOptions::default()
        },
    ] {
        assert!(svg_scale(&p, &bad).is_err());
        assert!(crease_pattern_svg(&p, &bad).is_err());
    }
}
