//! The bar-and-hinge simulator against motions known in closed form.

use std::f64::consts::PI;
use std::sync::Arc;

use foldsynth::simulate::{Drive, RIGID_DELTA, SimInput, SolverSettings, simulate};

fn base(
    initial: Vec<[f64; 3]>,
    faces: Vec<Vec<usize>>,
    drives: Vec<Drive>,
    t_end: f64,
    steps: usize,
) -> SimInput {
    SimInput {
        initial,
        faces,
        extra_bars: vec![],
        fixed: vec![],
        drives,
        t_start: 0.0,
        t_end,
        steps,
        first_step_offsets: vec![],
        check_intersections: true,
        solver: SolverSettings::default(),
    }
}

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() <= tol)
}

/// One square turning about a crease against a fixed square, nothing else: every state is
/// an exact rotation, so δ is rounding noise and the moving corner is on the circle.
#[test]
fn single_crease_rotation_is_rigid_and_exact() {
    let input = base(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
        ],
        vec![vec![0, 1, 2, 3], vec![0, 3, 4, 5]],
        vec![Drive::Crease {
            p: 0,
            q: 3,
            fixed_face: 0,
            moving_face: 1,
            angle: Arc::new(|t| t),
        }],
        2.5,
        25,
    );
    let r = simulate(&input).unwrap();
    assert!(r.rigid);
    assert!(r.gamma < 1e-12, "Γ = {}", r.gamma);
    assert_eq!(r.theta, 0.0);
    for (j, x) in r.states.iter().enumerate() {
        let rho = 2.5 * j as f64 / 25.0;
        // Valley positive: the moving facet rises to +z.
        assert!(
            close(x[5], [-rho.cos(), 0.0, rho.sin()], 1e-12),
            "j = {j}: {:?}",
            x[5]
        );
        assert!(close(x[4], [-rho.cos(), 1.0, rho.sin()], 1e-12));
    }
}

/// The degree-4 vertex v(M, (60), (120), ((90, 90), (t))) of SPEC §1 (thesis Fig. 28).
/// Creases from the origin O: c1 along +x, c2 at 60°, c3 along −x, c4 along −y; sectors
/// 60°, 120°, 90°, 90°. Facet F3 (between c3 and c4) is fixed and the crease c4 is driven
/// by ρ = t, so F4 turns about the y-axis: p1 = (cos ρ, 0, sin ρ). The free vertex p2 keeps
/// p2·p1 = cos 60° and p2·p3 = cos 120° with p3 = (−1, 0, 0), which gives
/// p2 = (1/2, √(3/4 − tan²(ρ/2)/4), tan(ρ/2)/2): real up to tan(ρ/2) = √3, i.e. ρ = 2π/3,
/// the limit the thesis states.
fn degree4(t_end: f64, steps: usize) -> SimInput {
    let s = 3f64.sqrt() / 2.0;
    base(
        // O, p1, p2, p3, p4
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, s, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
        ],
        vec![vec![0, 1, 2], vec![0, 2, 3], vec![0, 3, 4], vec![0, 4, 1]],
        vec![Drive::Crease {
            p: 0,
            q: 4,
            fixed_face: 2,
            moving_face: 3,
            angle: Arc::new(|t| t),
        }],
        t_end,
        steps,
    )
}

fn degree4_p2(rho: f64) -> [f64; 3] {
    let h = (rho / 2.0).tan();
    [0.5, (0.75 - 0.25 * h * h).sqrt(), 0.5 * h]
}

#[test]
fn degree4_vertex_follows_its_closed_form() {
    let t_end = 100f64.to_radians();
    let r = simulate(&degree4(t_end, 20)).unwrap();
    assert!(r.rigid);
    assert!(r.gamma <= 1e-8, "Γ = {}", r.gamma);
    for (j, x) in r.states.iter().enumerate() {
        let rho = t_end * j as f64 / 20.0;
        assert!(close(x[1], [rho.cos(), 0.0, rho.sin()], 1e-12));
        assert!(
            close(x[2], degree4_p2(rho), 1e-9),
            "j = {j}: {:?} vs {:?}",
            x[2],
            degree4_p2(rho)
        );
    }
    assert!(close(r.final_positions()[2], degree4_p2(t_end), 1e-9));
}

#[test]
fn degree4_vertex_driven_past_its_limit_distorts_after_and_only_after() {
    // 5° steps to 170°: the limit 120° is step 24.
    let r = simulate(&degree4(170f64.to_radians(), 34)).unwrap();
    assert!(!r.rigid);
    for s in &r.steps {
        let deg = s.t.to_degrees();
        if deg <= 120.0 + 1e-9 {
            assert!(s.delta <= RIGID_DELTA, "δ({}) = {} at {deg}°", s.j, s.delta);
        } else {
            assert!(s.delta > RIGID_DELTA, "δ({}) = {} at {deg}°", s.j, s.delta);
        }
    }
}

/// Two degree-4 vertices O = (0, 0) and O' = (4, 0), mirror images across x = 2, sharing
/// the crease O–O'. The bottom rectangle B is fixed; the lower-left facet F3 turns up about
/// x = 0 by ρ and its mirror F3' about x = 4 by ρ. The top trapezoid T turns about the
/// x-axis by φ, and F2 (sector 120° at O, between T and F3) stays rigid when
/// sin φ = −tan(ρ/2)/√3, so T's corners are q = (1/2, (√3/2) cos φ, (√3/2) sin φ) and its
/// mirror. Seven bars act on the six unknowns of q and q' (T is a rigid quadrilateral): a
/// consistent overconstrained system, as rigid patterns with cycles are.
fn two_vertices(t_end: f64, steps: usize) -> SimInput {
    let s = 3f64.sqrt() / 2.0;
    // 0 O, 1 O', 2 q, 3 q', 4 p3, 5 p3', 6 p4, 7 p4'
    let initial = vec![
        [0.0, 0.0, 0.0],
        [4.0, 0.0, 0.0],
        [0.5, s, 0.0],
        [3.5, s, 0.0],
        [-1.0, 0.0, 0.0],
        [5.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [4.0, -1.0, 0.0],
    ];
    let faces = vec![
        vec![6, 7, 1, 0], // B
        vec![0, 1, 3, 2], // T
        vec![0, 2, 4],    // F2
        vec![0, 4, 6],    // F3
        vec![1, 5, 3],    // F2'
        vec![1, 7, 5],    // F3'
    ];
    let drives = vec![
        Drive::Crease {
            p: 0,
            q: 6,
            fixed_face: 0,
            moving_face: 3,
            angle: Arc::new(|t| t),
        },
        Drive::Crease {
            p: 1,
            q: 7,
            fixed_face: 0,
            moving_face: 5,
            angle: Arc::new(|t| t),
        },
    ];
    base(initial, faces, drives, t_end, steps)
}

#[test]
fn two_vertex_pattern_follows_its_closed_form() {
    let t_end = 110f64.to_radians();
    let r = simulate(&two_vertices(t_end, 22)).unwrap();
    assert!(r.rigid);
    assert!(r.gamma <= 1e-8, "Γ = {}", r.gamma);
    assert_eq!(r.free_vertices, 2);
    let s = 3f64.sqrt() / 2.0;
    for (j, x) in r.states.iter().enumerate() {
        let rho = t_end * j as f64 / 22.0;
        let phi = -((rho / 2.0).tan() / 3f64.sqrt()).asin();
        assert!(close(x[4], [-rho.cos(), 0.0, rho.sin()], 1e-12));
        assert!(close(x[5], [4.0 + rho.cos(), 0.0, rho.sin()], 1e-12));
        assert!(
            close(x[2], [0.5, s * phi.cos(), s * phi.sin()], 1e-9),
            "j = {j}: {:?}",
            x[2]
        );
        assert!(
            close(x[3], [3.5, s * phi.cos(), s * phi.sin()], 1e-9),
            "j = {j}: {:?}",
            x[3]
        );
    }
}

#[test]
fn two_vertex_pattern_past_its_limit_is_not_rigid() {
    let r = simulate(&two_vertices(150f64.to_radians(), 30)).unwrap();
    assert!(!r.rigid);
    for s in &r.steps {
        let deg = s.t.to_degrees();
        if deg <= 120.0 + 1e-9 {
            assert!(s.delta <= RIGID_DELTA, "δ({}) = {} at {deg}°", s.j, s.delta);
        } else {
            assert!(s.delta > RIGID_DELTA, "δ({}) = {} at {deg}°", s.j, s.delta);
        }
    }
}

/// A quadrilateral facet (no triangle in it, so its bars include both diagonals) with three
/// corners fixed and the fourth pulled along x: nothing is free, so δ is exactly the sum of
/// the bar errors the drive imposes — bars 0–2 (diagonal), 1–2 and 2–3:
/// |(1 + t)² + 1 − 2| + |t² + 1 − 1| + |(1 + t)² − 1| = 4t + 3t².
#[test]
fn inconsistently_driven_quad_has_the_exact_distortion() {
    let mut input = base(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        vec![vec![0, 1, 2, 3]],
        vec![Drive::Trajectory {
            vertex: 2,
            path: Arc::new(|t| [1.0 + t, 1.0, 0.0]),
        }],
        0.2,
        10,
    );
    input.fixed = vec![0, 1, 3];
    let r = simulate(&input).unwrap();
    assert_eq!(r.bars, 6);
    for s in &r.steps {
        let want = 4.0 * s.t + 3.0 * s.t * s.t;
        assert!(
            (s.delta - want).abs() < 1e-12,
            "t = {}: δ = {} vs {want}",
            s.t,
            s.delta
        );
        assert!(s.delta > RIGID_DELTA);
    }
    assert!(!r.rigid);
    let mean = r.steps.iter().map(|s| s.delta).sum::<f64>() / 10.0;
    assert!((r.gamma - mean).abs() < 1e-15);
}

/// With one corner free, the pulled quad cannot be rigid either: the free corner would have
/// to be at distance 1 from corner 0, √2 from corner 1 and 1 from corner 2, and those three
/// spheres have no common point once corner 2 has moved (y = ((1 + t)² + 1)/2 > 1 would be
/// needed on the unit circle x = 0). The minimiser must therefore leave δ above the
/// drive's share 2t + 2t² of bars 0–2 and 1–2.
#[test]
fn quad_with_a_free_corner_pulled_apart_is_not_rigid() {
    let mut input = base(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        vec![vec![0, 1, 2, 3]],
        vec![Drive::Trajectory {
            vertex: 2,
            path: Arc::new(|t| [1.0 + t, 1.0, 0.0]),
        }],
        0.2,
        10,
    );
    input.fixed = vec![0, 1];
    let r = simulate(&input).unwrap();
    assert!(!r.rigid);
    for s in &r.steps {
        assert!(
            s.delta > 2.0 * s.t + 2.0 * s.t * s.t,
            "t = {}: δ = {}",
            s.t,
            s.delta
        );
    }
}

/// A rigid motion given by trajectories (a square turning about its fixed side, corners on
/// circles) is as exact as a crease drive.
#[test]
fn trajectory_drive_of_a_rigid_rotation_is_exact() {
    let mut input = base(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 2.0, 0.0],
        ],
        vec![vec![0, 1, 2, 3], vec![3, 2, 4]],
        vec![
            Drive::Trajectory {
                vertex: 2,
                path: Arc::new(|t: f64| [1.0, t.cos(), t.sin()]),
            },
            Drive::Trajectory {
                vertex: 3,
                path: Arc::new(|t: f64| [0.0, t.cos(), t.sin()]),
            },
        ],
        -PI / 2.0,
        12,
    );
    input.fixed = vec![0, 1];
    let r = simulate(&input).unwrap();
    assert!(r.rigid && r.gamma < 1e-12, "Γ = {}", r.gamma);
    // Vertex 4 keeps its distances 2^2 + .25 = |4-0|² etc.: check one of them.
    let x = r.final_positions();
    let d2 = |a: [f64; 3], b: [f64; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>();
    assert!((d2(x[4], x[2]) - 1.25).abs() < 1e-12);
    assert!((d2(x[4], x[3]) - 1.25).abs() < 1e-12);
}

#[test]
fn inconsistent_inputs_are_rejected() {
    // A trajectory that does not start at its vertex.
    let mut bad = degree4(1.0, 4);
    bad.drives = vec![Drive::Trajectory {
        vertex: 2,
        path: Arc::new(|t| [t, 0.0, 0.0]),
    }];
    assert!(simulate(&bad).is_err());
    // A crease drive on facets that do not share the crease.
    let mut bad = degree4(1.0, 4);
    bad.drives = vec![Drive::Crease {
        p: 0,
        q: 4,
        fixed_face: 0,
        moving_face: 3,
        angle: Arc::new(|t| t),
    }];
    assert!(simulate(&bad).is_err());
    // Zero steps, no drive, a vertex out of range.
    let mut bad = degree4(1.0, 4);
    bad.steps = 0;
    assert!(simulate(&bad).is_err());
    let mut bad = degree4(1.0, 4);
    bad.drives.clear();
    assert!(simulate(&bad).is_err());
    let mut bad = degree4(1.0, 4);
    bad.fixed = vec![9];
    assert!(simulate(&bad).is_err());
}

/// The G0 drive of the design tasks (SPEC §4) on a `Pattern`: v1 = (0, 0) and v2 = (1, 0)
/// on the rotation axis stay put, f1 = (v1, v2, a) turns by +t/2 and f2 = (v1, b, v2) by
/// −t/2 about the x-axis. With nothing else in the pattern every state is exact, and the
/// crease's fold angle (from the check module) equals t.
#[test]
fn g0_symmetric_drive_on_a_pattern() {
    use foldsynth::check::Checker;
    use foldsynth::pattern::{Frame, Pattern};
    let a = [0.3, 0.8];
    let b = [0.6, -0.7];
    let frames = (0..=8)
        .map(|k| Frame {
            t: std::f64::consts::FRAC_PI_2 * k as f64 / 8.0,
            coords: vec![],
            fold_angles: vec![],
        })
        .collect();
    let pattern = Pattern {
        vertices: vec![[0.0, 0.0], [1.0, 0.0], a, b],
        edges: vec![],
        faces: vec![vec![0, 1, 2], vec![0, 3, 1]],
        frames,
    };
    let mut input = SimInput::from_pattern(&pattern);
    assert_eq!((input.steps, input.t_start), (8, 0.0));
    input.fixed = vec![0, 1];
    input.drives = vec![
        Drive::rotation_about_axis(
            2,
            [a[0], a[1], 0.0],
            [0.0; 3],
            [1.0, 0.0, 0.0],
            Arc::new(|t| t / 2.0),
        ),
        Drive::rotation_about_axis(
            3,
            [b[0], b[1], 0.0],
            [0.0; 3],
            [1.0, 0.0, 0.0],
            Arc::new(|t| -t / 2.0),
        ),
    ];
    let r = simulate(&input).unwrap();
    assert!(r.rigid && r.gamma < 1e-14);
    let checker = Checker::from_pattern(&pattern).unwrap();
    for (x, s) in r.states.iter().skip(1).zip(&r.steps) {
        // Both facets rise (+z): a valley of angle t.
        assert!(x[2][2] > 0.0 && x[3][2] > 0.0);
        let rho = checker.fold_angles(x)[0];
        assert!((rho - s.t).abs() < 1e-12, "{rho} vs {}", s.t);
    }
}
