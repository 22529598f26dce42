//! Symmetric patterns from a driven central facet (issue 46): the grammar grows one
//! orbit representative and its rotations follow, r2 joins a vertex with one of the
//! neighbouring sector's, and the model folds every corner (two driven creases each) by
//! its own PTU. Facts checked: the folded pattern is the representative's turned by the
//! symmetry at every t (its images' folded positions are the rotations of its
//! own, computed independently), every facet map is a rigid motion that keeps shared
//! vertices together (closure). (The compiled model against these f64 kinematics is not
//! tested here yet.)

#![allow(clippy::needless_range_loop)] // coordinates by index read as the formulas

use foldsynth::grammar::CreaseGraph;
use foldsynth::model::geometry;
use foldsynth::model::plan::{Plan, Position};
use foldsynth::task::Task;

const FLASHER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/flasher_layer.toml");

/// Deterministic pseudo-random numbers in [0, 1).
fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// Variables inside their boxes, the sectors small enough for a convex corner.
fn variables(plan: &Plan, seed: u64) -> Vec<f64> {
    let mut s = seed;
    plan.variables
        .iter()
        .map(|v| match v.kind {
            foldsynth::grammar::VarKind::Length => 0.8 + lcg(&mut s),
            _ => 0.6 + 0.5 * lcg(&mut s),
        })
        .collect()
}

#[test]
fn flasher_layer_is_rotationally_symmetric_rigid_and_closed_at_every_t() {
    let task = Task::load(FLASHER).unwrap();
    for seq in ["1", "1, (9, 20)", "1, (9, 20), 9"] {
        let graph = CreaseGraph::from_sequence(&task, seq).unwrap();
        let plan = Plan::new(&graph).unwrap();
        assert_eq!(plan.isometries.len(), 4, "{seq}");
        assert_eq!(
            plan.actuation.driven.len(),
            8,
            "four sides, two halves each"
        );
        assert!(plan.actuation.fixed.is_some(), "the central facet stays");
        let images = plan
            .vertices
            .iter()
            .filter(|v| matches!(v.position, Position::Image { .. }))
            .count();
        assert!(
            images >= 6,
            "{seq}: three images of each vertex r1 made (less those r2 merged), got {images}"
        );
        let mut checked = 0;
        for seed in 1..12 {
            let vars = variables(&plan, seed);
            let flat = geometry::flat(&plan, &vars);
            for (i, &(rep, g)) in plan.orbit.iter().enumerate() {
                let iso = &plan.isometries[g];
                let p = iso.apply([flat.pos[rep][0], flat.pos[rep][1]]);
                for k in 0..2 {
                    assert!(
                        (p[k] - flat.pos[i][k]).abs() < 1e-12,
                        "{seq}: flat v{}",
                        i + 1
                    );
                }
            }
            let modes = vec![1.0; plan.n_modes];
            // From t > 0: at the flat state the PTU is at a branch point (θ = π, φ of √ε noise).
            for step in 1..=6 {
                let t = step as f64 * 0.25;
                let folded = geometry::fold(&plan, &flat, &modes, &t);
                // The PTU folds a vertex only within its rigid range (Eq. 25).
                if folded
                    .states
                    .iter()
                    .flatten()
                    .any(|s| s.margins.iter().any(|m| m.is_nan() || *m < 0.0))
                {
                    continue;
                }
                checked += 1;
                // Closure: every vertex at one place through each of its facets.
                for (f, (poly, _)) in plan.polygons.iter().enumerate() {
                    for &v in poly {
                        let a = geometry::position(&plan, &flat, &folded, v);
                        let b = geometry::position_on(&flat, &folded, v, f);
                        for k in 0..3 {
                            assert!((a[k] - b[k]).abs() < 1e-9, "{seq}: closure at v{}", v + 1);
                        }
                    }
                }
                // Symmetry: an image's 3D position is its representative's turned about z
                // (the central facet, fixed, is centred on the origin).
                for (i, &(rep, g)) in plan.orbit.iter().enumerate() {
                    let a = geometry::position(&plan, &flat, &folded, rep);
                    let b = geometry::position(&plan, &flat, &folded, i);
                    let m = &plan.isometries[g].m;
                    let turned = [
                        m[0][0] * a[0] + m[0][1] * a[1],
                        m[1][0] * a[0] + m[1][1] * a[1],
                        a[2],
                    ];
                    for k in 0..3 {
                        assert!(
                            (turned[k] - b[k]).abs() < 1e-9,
                            "{seq}: v{} is not the image of v{} at t {t}: {b:?} vs {turned:?}",
                            i + 1,
                            rep + 1
                        );
                    }
                }
                // Every facet map is a rotation.
                for r in &folded.rot {
                    for a in 0..3 {
                        for b in 0..3 {
                            let d: f64 = (0..3).map(|k| r[k][a] * r[k][b]).sum();
                            let e = if a == b { 1.0 } else { 0.0 };
                            assert!((d - e).abs() < 1e-12);
                        }
                    }
                }
            }
            assert!(
                checked >= 2,
                "{seq}: seed {seed} folds rigidly at {checked} states"
            );
        }
        assert!(
            checked >= 6,
            "{seq}: rigid at only {checked} sampled states"
        );
    }
}

#[test]
fn side_vertex_joins_two_sectors() {
    let task = Task::load(FLASHER).unwrap();
    let graph = CreaseGraph::from_sequence(&task, "1, (9, 20)").unwrap();
    let plan = Plan::new(&graph).unwrap();
    // Four merged side vertices, each with two incoming creases from two corners.
    let sides: Vec<usize> = (0..plan.vertices.len())
        .filter(|&v| plan.vertices[v].preds == 2 && !plan.vertices[v].internal)
        .collect();
    assert_eq!(sides.len(), 4, "one side vertex per side");
    for &v in &sides {
        let tails: Vec<usize> = plan.vertices[v].rays[..2].iter().map(|r| r.other).collect();
        assert_ne!(
            plan.orbit[tails[0]].1, plan.orbit[tails[1]].1,
            "from two sectors"
        );
    }
}
