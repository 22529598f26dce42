//! SVG output parses as XML; the crease pattern has one line per edge with Origami
//! Simulator's colour for its assignment, its opacity encodes the final fold angle, and
//! its end points are the pattern's vertices.

use std::f64::consts::PI;

use foldsynth::export::fold::{Assignment, assignments};
use foldsynth::export::plots::{
    DistributionPlot, NodeStatus, Series, TreeNode, distribution_svg, search_tree_svg,
};
use foldsynth::export::render::{Camera, Scene};
use foldsynth::export::svg::{SvgOptions, crease_pattern_svg};
use foldsynth::export::{DesignMeta, samples};
use foldsynth::pattern::Pattern;

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
        // End points: x right, y flipped, 200 px per unit, 20 px margin.
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
