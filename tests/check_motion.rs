//! Motion checks on `Pattern`s, and the two-armed gripper built from one arm.

use foldsynth::check::{
    IntersectionKind, MotionSettings, RotatedCopyError, check_frames, two_armed,
};
use foldsynth::pattern::{Edge, EdgeKind, Frame, Pattern};

/// G0 of the thesis with one extra vertex on each side: v1 = (0, 0), v2 = (1, 0), the
/// driven crease v1→v2, facet f1 = (v1, v2, a) above it and f2 = (v1, b, v2) below it.
/// Folding by ρ turns f1 by +ρ/2 and f2 by −ρ/2 about the x-axis (SPEC §4), a valley.
fn arm(a: [f64; 2], b: [f64; 2], angles: &[f64]) -> Pattern {
    let vertices = vec![[0.0, 0.0], [1.0, 0.0], a, b];
    let rot = |p: [f64; 2], phi: f64| [p[0], p[1] * phi.cos(), p[1] * phi.sin()];
    let frames = angles
        .iter()
        .map(|&rho| Frame {
            t: rho,
            coords: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                rot(a, rho / 2.0),
                rot(b, -rho / 2.0),
            ],
            fold_angles: vec![rho, 0.0, 0.0, 0.0, 0.0],
        })
        .collect();
    Pattern {
        vertices,
        edges: vec![
            Edge {
                v: [0, 1],
                kind: EdgeKind::Crease { driven: true },
            },
            Edge {
                v: [1, 2],
                kind: EdgeKind::Boundary,
            },
            Edge {
                v: [2, 0],
                kind: EdgeKind::Boundary,
            },
            Edge {
                v: [0, 3],
                kind: EdgeKind::Boundary,
            },
            Edge {
                v: [3, 1],
                kind: EdgeKind::Boundary,
            },
        ],
        faces: vec![vec![0, 1, 2], vec![0, 3, 1]],
        frames,
    }
}

fn angles(n: usize, end: f64) -> Vec<f64> {
    (0..n).map(|k| end * k as f64 / (n - 1) as f64).collect()
}

#[test]
fn two_armed_gripper_shares_the_origin_and_mirrors_the_arm() {
    let one = arm(
        [0.5, 0.5],
        [0.5, -0.5],
        &angles(16, std::f64::consts::FRAC_PI_2),
    );
    let two = two_armed(&one).unwrap();
    // v1 at the origin is shared; the other three vertices are copied.
    assert_eq!(two.vertices.len(), 7);
    assert_eq!(two.faces.len(), 4);
    assert_eq!(two.edges.len(), 10);
    // The copy of v2 = (1, 0) is (−1, 0), and the copied crease runs from v1 to it.
    assert_eq!(two.vertices[4], [-1.0, -0.0]);
    assert!(
        two.edges
            .iter()
            .any(|e| e.v == [0, 4] && e.kind == EdgeKind::Crease { driven: true })
    );
    for (f1, f2) in one.frames.iter().zip(&two.frames) {
        assert_eq!(f2.coords.len(), 7);
        for (i, j) in [(1, 4), (2, 5), (3, 6)] {
            let (p, q) = (f1.coords[i], f2.coords[j]);
            assert!((q[0] + p[0]).abs() < 1e-15 && (q[1] + p[1]).abs() < 1e-15 && q[2] == p[2]);
        }
        assert_eq!(f2.fold_angles.len(), 10);
    }
    // The arms lie in x ≥ 0 and x ≤ 0 and meet only at v1: no intersection.
    let report = check_frames(&two, &MotionSettings::default()).unwrap();
    assert!(report.clear(), "{:?}", report.intersections);
    assert_eq!(report.states.len(), 16);
}

#[test]
fn overlapping_arms_are_caught_in_the_flat_state() {
    // f1 reaches past the y-axis to (−0.8, 0.5), where the copy of f2 lies: the copied
    // facet spans the directions 135°–180° at v1, f1 spans 0°–148°.
    let one = arm([-0.8, 0.5], [0.5, -0.5], &angles(4, 1.0));
    assert!(
        check_frames(&one, &MotionSettings::default())
            .unwrap()
            .clear()
    );
    let two = two_armed(&one).unwrap();
    let report = check_frames(&two, &MotionSettings::default()).unwrap();
    let first = report.first_intersection().unwrap();
    assert_eq!(first.kind, IntersectionKind::FlatOverlap);
    assert_eq!((first.face_a, first.face_b), (0, 3));
    assert_eq!(first.t, 0.0);
}

#[test]
fn a_copy_that_does_not_meet_the_original_on_the_axis_is_an_error() {
    let mut one = arm([0.5, 0.5], [0.5, -0.5], &angles(3, 1.0));
    one.frames[2].coords[0] = [0.0, 0.1, 0.0]; // v1 leaves the z-axis
    let err = two_armed(&one).unwrap_err();
    assert!(
        matches!(err, RotatedCopyError::SharedVertexMoves { vertex: 0, .. }),
        "{err}"
    );
}

/// Folding the G0 crease past π flips f1 through f2: reported as a Flip of the pair from
/// the first state beyond π on, and not before.
#[test]
fn folding_past_pi_is_a_flip_from_that_state_on() {
    let one = arm([0.5, 0.5], [0.5, -0.5], &angles(21, 4.0));
    let report = check_frames(&one, &MotionSettings::default()).unwrap();
    assert!(!report.intersections.is_empty());
    for i in &report.intersections {
        assert_eq!((i.face_a, i.face_b, i.kind), (0, 1, IntersectionKind::Flip));
    }
    let flagged: Vec<f64> = report.intersections.iter().map(|i| i.t).collect();
    for &t in &report.states {
        assert_eq!(flagged.contains(&t), t > std::f64::consts::PI, "t = {t}");
    }
    let first = check_frames(
        &one,
        &MotionSettings {
            stop_at_first: true,
            ..MotionSettings::default()
        },
    )
    .unwrap();
    assert_eq!(first.intersections.len(), 1);
    assert_eq!(first.intersections[0].t, flagged[0]);
}
