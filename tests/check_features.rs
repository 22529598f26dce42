//! Feature size of a flat layout (issue 20): the distance from a point to a segment is the
//! minimum over the segment's points, the minimum feature is the smallest of the
//! pairwise, point–segment and edge-length distances, and it is invariant under rigid
//! motions and scales with the layout.

use foldsynth::check::features::{
    FeatureKind, features, min_feature, pattern_min_feature, point_segment_distance,
};
use foldsynth::export::samples;
use proptest::prelude::*;

fn d(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

#[test]
fn point_segment_distance_by_cases() {
    let (a, b) = ([0.0, 0.0], [2.0, 0.0]);
    // Foot of the perpendicular inside the segment.
    assert!((point_segment_distance([1.0, 0.5], a, b) - 0.5).abs() < 1e-15);
    // Beyond either end: the distance to that end (3-4-5 triangle).
    assert!((point_segment_distance([-3.0, 4.0], a, b) - 5.0).abs() < 1e-15);
    assert!((point_segment_distance([5.0, -4.0], a, b) - 5.0).abs() < 1e-15);
    // On the segment.
    assert_eq!(point_segment_distance([1.5, 0.0], a, b), 0.0);
    // A degenerate segment is its point.
    assert!((point_segment_distance([3.0, 4.0], a, a) - 5.0).abs() < 1e-15);
}

proptest! {
    /// The point–segment distance is the minimum over the segment's points: no sampled
    /// point is closer, and some sample is within half a sample spacing of it.
    #[test]
    fn point_segment_distance_is_the_minimum(
        p in prop::array::uniform2(-2.0f64..2.0),
        a in prop::array::uniform2(-2.0f64..2.0),
        b in prop::array::uniform2(-2.0f64..2.0),
    ) {
        let dist = point_segment_distance(p, a, b);
        let n = 2000;
        let mut best = f64::INFINITY;
        for k in 0..=n {
            let s = k as f64 / n as f64;
            let q = [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])];
            let dq = d(p, q);
            prop_assert!(dq >= dist - 1e-12);
            best = best.min(dq);
        }
        prop_assert!(best - dist <= 0.5 * d(a, b) / n as f64 + 1e-12);
    }

    /// Rotating and translating a layout leaves its minimum feature alone; scaling by k
    /// scales it by k and keeps where it is.
    #[test]
    fn min_feature_is_invariant_and_scales(
        pts in prop::collection::vec(prop::array::uniform2(-1.0f64..1.0), 3..9),
        angle in 0.0f64..std::f64::consts::TAU,
        shift in prop::array::uniform2(-5.0f64..5.0),
        k in 0.01f64..100.0,
    ) {
        // A closed polygon through the points plus one chord.
        let n = pts.len();
        let mut edges: Vec<[usize; 2]> = (0..n).map(|i| [i, (i + 1) % n]).collect();
        edges.push([0, n / 2]);
        let f = min_feature(&pts, &edges).unwrap();
        let (c, s) = (angle.cos(), angle.sin());
        let moved: Vec<[f64; 2]> = pts
            .iter()
            .map(|p| [c * p[0] - s * p[1] + shift[0], s * p[0] + c * p[1] + shift[1]])
            .collect();
        let g = min_feature(&moved, &edges).unwrap();
        prop_assert!((g.value - f.value).abs() <= 1e-9 * (1.0 + f.value.abs()) + 1e-12);
        let scaled: Vec<[f64; 2]> = pts.iter().map(|p| [k * p[0], k * p[1]]).collect();
        let h = min_feature(&scaled, &edges).unwrap();
        prop_assert!((h.value - k * f.value).abs() <= 1e-9 * k * (1.0 + f.value));
        // The minimum is the smallest of all features, and no smaller than any one kind's
        // brute-force minimum.
        let all = features(&pts, &edges);
        prop_assert!(all.iter().all(|x| x.value >= f.value));
        let pairs = (0..n)
            .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
            .map(|(a, b)| d(pts[a], pts[b]))
            .fold(f64::INFINITY, f64::min);
        // Brute force over every vertex pair and every vertex with every edge it does not
        // end on (nearest point anywhere on the edge): the same minimum.
        let to_edges = (0..n)
            .flat_map(|v| edges.iter().filter(move |e| !e.contains(&v)).map(move |e| (v, *e)))
            .map(|(v, e)| point_segment_distance(pts[v], pts[e[0]], pts[e[1]]))
            .fold(f64::INFINITY, f64::min);
        prop_assert!((f.value - pairs.min(to_edges)).abs() <= 1e-12, "{f:?} {pairs} {to_edges}");
    }
}

#[test]
fn each_kind_is_found_and_labelled() {
    // A unit square with a crease from v1 to v3 (the diagonal) and a fifth vertex.
    let square = |p: [f64; 2]| {
        (
            vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], p],
            vec![[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]],
        )
    };
    // A loose vertex 0.01 from the top side's interior: vertex–edge.
    let (v, e) = square([0.5, 0.99]);
    let f = min_feature(&v, &e).unwrap();
    assert_eq!(f.kind, FeatureKind::VertexEdge { v: 4, a: 2, b: 3 });
    assert!((f.value - 0.01).abs() < 1e-12);
    assert_eq!(f.label(), "v5 ↔ edge v3–v4");
    // The vertex 0.001 beyond corner v3, on the diagonal's extension, joined to v3: the
    // length of that edge (the nearest point of every other edge is v3 itself).
    let (v, mut e) = square([1.0 + 0.001 / 2f64.sqrt(), 1.0 + 0.001 / 2f64.sqrt()]);
    e.push([2, 4]);
    let f = min_feature(&v, &e).unwrap();
    assert!((f.value - 0.001).abs() < 1e-12, "{f:?}");
    assert_eq!(f.kind, FeatureKind::Edge { a: 2, b: 4 });
    assert_eq!(f.label(), "edge v3–v5");
    // Not joined: two vertices.
    e.pop();
    let f = min_feature(&v, &e).unwrap();
    assert_eq!(f.kind, FeatureKind::Vertices { a: 2, b: 4 });
    assert_eq!(f.label(), "v3 ↔ v5");
    // One vertex has no features.
    assert!(min_feature(&[[0.0, 0.0]], &[]).is_none());
}

#[test]
fn sample_patterns_have_their_designed_features() {
    // single_crease: an L-shaped hexagon on a rectangle; the closest parts are 0.3 apart
    // (the notch's inner corner (0.5, 0.3) is 0.3 above the crease and 0.3 below the top).
    let f = pattern_min_feature(&samples::single_crease(1.0, 2)).unwrap();
    assert!((f.value - 0.3).abs() < 1e-12, "{f:?}");
}
