//! The finite-cylinder obstacle against brute-force sampling and along a motion.

use foldsynth::check::{Checker, Cylinder, MotionSettings, check_motion};
use nalgebra::Vector3;
use rand::{RngExt, SeedableRng};

type Tri = [Vector3<f64>; 3];

/// Distance to the axis line of the points of a fine barycentric grid on the triangle that
/// lie in the cylinder's slab (None when no grid point is in the slab), and the grid step.
fn sampled(tri: &Tri, c: &Cylinder, n: usize) -> (Option<f64>, f64) {
    let a = Vector3::from(c.a);
    let axis = Vector3::from(c.b) - a;
    let (len, u) = (axis.norm(), axis.normalize());
    let mut best: Option<f64> = None;
    for i in 0..=n {
        for j in 0..=n - i {
            let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
            let p = tri[0] + (tri[1] - tri[0]) * s + (tri[2] - tri[0]) * t;
            let along = u.dot(&(p - a));
            if (0.0..=len).contains(&along) {
                let d = (p - a - u * along).norm();
                best = Some(best.map_or(d, |b: f64| b.min(d)));
            }
        }
    }
    let longest = (0..3)
        .map(|k| (tri[(k + 1) % 3] - tri[k]).norm())
        .fold(0.0, f64::max);
    (best, longest / n as f64)
}

#[test]
fn exact_distance_matches_sampling() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let cyl = Cylinder::thesis_gripper();
    let (mut hits, mut misses) = (0, 0);
    for _ in 0..3000 {
        let mut p = || {
            Vector3::new(
                rng.random_range(-1.5..1.5),
                rng.random_range(-1.8..1.8),
                rng.random_range(-0.5..1.5),
            )
        };
        let tri: Tri = [p(), p(), p()];
        let exact = cyl.slab_axis_distance(&tri);
        let (samp, h) = sampled(&tri, &cyl, 120);
        // With the whole triangle between the caps, every point near the minimiser is a
        // candidate, so the grid must come within a grid step of the exact minimum.
        let within_caps = tri.iter().all(|p| (-1.0..=1.0).contains(&p.y));
        match (exact, samp) {
            (Some(e), Some(s)) => {
                assert!(s >= e - 1e-12, "sample {s} below exact {e}");
                if within_caps {
                    assert!(s - e <= 2.0 * h, "sample {s} far above exact {e} (h = {h})");
                }
            }
            (None, Some(_)) => {
                panic!("a sample lies in the slab but the exact test says none does")
            }
            (Some(_), None) => {} // the part between the caps is thinner than the grid
            (None, None) => {}
        }
        let hit = cyl.hits(&tri, 1e-9);
        if samp.is_some_and(|s| s < cyl.radius - 1e-9) {
            assert!(
                hit,
                "a sample lies inside the cylinder but no hit was reported"
            );
        }
        if within_caps && exact.is_some_and(|e| e < cyl.radius - 0.05) {
            assert!(
                samp.is_some_and(|s| s < cyl.radius),
                "deep hit not confirmed by sampling"
            );
        }
        if hit { hits += 1 } else { misses += 1 }
    }
    assert!(hits > 300 && misses > 300, "{hits} hits, {misses} misses");
}

/// The left square of a hinge turns up about x = 0: its points are
/// (−s cos ρ, y, s sin ρ), s ∈ [0, 1], y ∈ [0, 1]. A cylinder along y through
/// (x, z) = (−0.5, 0.6) with radius 0.1 and y ∈ [0.2, 0.8] is within the facet's reach in y,
/// and its axis is at distance |0.6 cos ρ − 0.5 sin ρ| from the facet's plane (the foot of
/// the perpendicular, at s = 0.5 cos ρ + 0.6 sin ρ ≤ 1, lies on the facet). So the facet
/// is inside exactly while that distance is below 0.1.
#[test]
fn motion_reports_the_facet_and_the_states_it_enters_the_cylinder() {
    let layout = [
        [0.0, 0.0],
        [1.0, 0.0],
        [1.0, 1.0],
        [0.0, 1.0],
        [-1.0, 1.0],
        [-1.0, 0.0],
    ];
    let faces = vec![vec![0, 1, 2, 3], vec![0, 3, 4, 5]];
    let checker = Checker::new(&layout, &faces).unwrap();
    let state = |r: f64| {
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [-r.cos(), 1.0, r.sin()],
            [-r.cos(), 0.0, r.sin()],
        ]
    };
    let settings = MotionSettings {
        n_states: 40,
        stop_at_first: false,
        obstacles: vec![Cylinder {
            a: [-0.5, 0.2, 0.6],
            b: [-0.5, 0.8, 0.6],
            radius: 0.1,
        }],
    };
    let report = check_motion(&checker, &layout, state, 0.0, 2.0, &settings).unwrap();
    assert!(report.self_intersection_free());
    let hit_states: Vec<f64> = report.obstacle_hits.iter().map(|h| h.t).collect();
    assert!(
        report
            .obstacle_hits
            .iter()
            .all(|h| h.face == 1 && h.obstacle == 0)
    );
    let mut expected = 0;
    for &t in &report.states {
        let d = (0.6 * t.cos() - 0.5 * t.sin()).abs();
        assert!((d - 0.1).abs() > 1e-6, "grid point on the boundary");
        let inside = d < 0.1;
        assert_eq!(hit_states.contains(&t), inside, "t = {t}, distance {d}");
        expected += inside as usize;
    }
    assert!(expected >= 2);
    assert_eq!(
        report.first_obstacle_hit().map(|h| h.t),
        hit_states.first().copied()
    );
}
