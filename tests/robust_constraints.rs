//! The robustness block of the compiled model (issue 12): its compiled values (vertex
//! positions, Eq. 25 margins, fold angles at t) agree with the plain f64 kinematics, and its
//! compiled pullback `∇(Σ w·values)` — the gradient every clearance, crease and margin
//! constraint is assembled from — agrees with central differences, at target-meeting optima
//! where planes between the arm's facets, to the rotated copy and to the cylinder are live;
//! and so does the block's augmented-Lagrangian merit, in the design variables and in the
//! planes' own variables, at those optima and next to them.

use foldsynth::compile::Options as CompileOptions;
use foldsynth::grammar::{Enumeration, Filters};
use foldsynth::model::Model;
use foldsynth::model::clearance::{Group, Pair};
use foldsynth::model::compiled::{CompiledModel, ModelProblem, objective_target};
use foldsynth::model::robust::{RobustModel, RobustProblem, RobustSpec};
use foldsynth::optimize::{Options, Robust, minimize};
use foldsynth::task::Task;

const GRIPPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml");

#[test]
fn block_values_and_gradients_match_f64_kinematics_and_central_differences() {
    let task = Task::load(GRIPPER).unwrap();
    let enumeration = Enumeration::run(&task, 2, Filters::all());
    let spec = RobustSpec::from_task(&task, 181);
    assert!(spec.second_arm && !spec.cylinders.is_empty());
    // Groups of clearance pairs whose planes have been checked: the arm's own facets, the
    // rotated copy, the cylinder.
    let mut checked: Vec<Group> = Vec::new();
    // Designs whose block merit was checked against central differences.
    let mut designs = 0;
    'search: for node in enumeration.meaningful() {
        let n = node.graph.internal_count();
        for candidate in 0..3 {
            let Ok(model) = Model::new(&node.graph, &task, candidate) else {
                continue;
            };
            let compiled = CompiledModel::new(&model, &CompileOptions::default()).unwrap();
            let block = RobustModel::new(&model, spec.clone()).unwrap();
            for m in 0..(1u32 << n) {
                let modes: Vec<f64> = (0..n)
                    .map(|i| if m >> i & 1 == 1 { -1.0 } else { 1.0 })
                    .collect();
                let problem = ModelProblem::new(&model, &compiled, &modes);
                let sol = minimize(
                    &problem,
                    &Options {
                        starts: 4,
                        seed: 1,
                        target: Some(objective_target(&model)),
                        ..Default::default()
                    },
                );
                if !sol.met_target {
                    continue;
                }
                let x = &sol.x;
                // Compiled values = the f64 kinematics, at every sampled state.
                let mut work = block.work();
                let rp = RobustProblem::new(&model, &block, &modes);
                for &t in &rp.sampled_times() {
                    block.eval(x, &modes, t, &mut work);
                    let plain = block.eval_f64(&model, x, &modes, t);
                    for (a, b) in work.values.scene.x.iter().zip(&plain.scene.x) {
                        for k in 0..3 {
                            assert!((a[k] - b[k]).abs() < 1e-9, "position at t {t}");
                        }
                    }
                    for (a, b) in work
                        .values
                        .margins
                        .iter()
                        .chain(&work.values.rho)
                        .zip(plain.margins.iter().chain(&plain.rho))
                    {
                        assert!((a - b).abs() < 1e-9, "margin or fold angle at t {t}");
                    }
                }
                // The compiled pullback ∇(Σ w·values) against central differences of the
                // compiled values, for fixed weights.
                let nw = block.n_weights();
                let w: Vec<f64> = (0..nw).map(|k| ((k as f64) * 0.37).cos()).collect();
                let s_of = |x: &[f64], t: f64, work: &mut foldsynth::model::robust::Work| {
                    block.eval(x, &modes, t, work);
                    let v = &work.values;
                    let flat = v.scene.x.iter().flatten().chain(&v.margins).chain(&v.rho);
                    flat.zip(&w).map(|(a, b)| a * b).sum::<f64>()
                };
                for &t in rp.sampled_times().iter().filter(|t| **t > 0.0) {
                    let mut g = vec![0.0; x.len()];
                    block.pullback(x, &modes, t, &w, &mut work, &mut g);
                    for i in 0..x.len() {
                        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
                        xp[i] += 1e-6;
                        xm[i] -= 1e-6;
                        let fd = (s_of(&xp, t, &mut work) - s_of(&xm, t, &mut work)) / 2e-6;
                        assert!(
                            (fd - g[i]).abs() <= 1e-5 * (1.0 + g[i].abs()),
                            "pullback at t {t}, x{i}: {} vs central differences {fd}",
                            g[i]
                        );
                    }
                }
                // Planes fitted where pairs come close: count which groups were exercised.
                rp.update(x, None);
                rp.set_multipliers(1.0);
                let z = rp.variables();
                let planes = rp.variable_planes();
                let new: Vec<Group> = planes
                    .iter()
                    .map(|(_, p)| p.group)
                    .filter(|g| !checked.contains(g))
                    .collect();
                if !planes.is_empty() {
                    merit_matches_central_differences(&rp, x, &z, &planes);
                    // Off the optimum too: the design variables nudged, the planes kept.
                    let nudged: Vec<f64> = x
                        .iter()
                        .enumerate()
                        .map(|(i, v)| v + 1e-3 * (i as f64 * 0.7).sin())
                        .collect();
                    merit_matches_central_differences(&rp, &nudged, &z, &planes);
                    designs += 1;
                }
                for g in new {
                    if !checked.contains(&g) {
                        checked.push(g);
                    }
                }
                if checked.len() == 3 && designs >= 4 {
                    break 'search;
                }
            }
        }
    }
    for g in [Group::SelfPair, Group::Arm, Group::Obstacle] {
        assert!(checked.contains(&g), "no plane of {g:?} was checked");
    }
    assert!(designs >= 4, "the merit was checked on {designs} designs");
}

/// The block's merit at `x`, `z` (every multiplier 1 and μ = 0.1: `λ − μh > 0` for every
/// constraint, so that no term switches): its
/// gradients with respect to the design variables and to every plane variable agree with
/// central differences of its value. The plane variables are named by their group.
fn merit_matches_central_differences(
    rp: &RobustProblem<'_>,
    x: &[f64],
    z: &[f64],
    planes: &[(f64, Pair)],
) {
    let mu = 0.1;
    let value = |x: &[f64], z: &[f64]| {
        let (mut gx, mut gz) = (vec![0.0; x.len()], vec![0.0; z.len()]);
        rp.merit(x, z, mu, &mut gx, &mut gz)
    };
    let (mut gx, mut gz) = (vec![0.0; x.len()], vec![0.0; z.len()]);
    let f = rp.merit(x, z, mu, &mut gx, &mut gz);
    assert!(f.is_finite() && f != 0.0, "merit {f}");
    let h = 1e-6;
    let close = |fd: f64, g: f64| (fd - g).abs() <= 1e-5 * (1.0 + g.abs());
    for i in 0..x.len() {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[i] += h;
        xm[i] -= h;
        let fd = (value(&xp, z) - value(&xm, z)) / (2.0 * h);
        assert!(
            close(fd, gx[i]),
            "merit gradient x{i}: {} vs central differences {fd}",
            gx[i]
        );
    }
    // The plane variables of each pair: n (3) and, except for cones, d.
    let mut owner = Vec::with_capacity(z.len());
    for (t, pair) in planes {
        let k = if pair.has_offset() { 4 } else { 3 };
        owner.extend(std::iter::repeat_n((*t, pair.group), k));
    }
    assert_eq!(owner.len(), z.len());
    for j in 0..z.len() {
        let (mut zp, mut zm) = (z.to_vec(), z.to_vec());
        zp[j] += h;
        zm[j] -= h;
        let fd = (value(x, &zp) - value(x, &zm)) / (2.0 * h);
        let (t, group) = owner[j];
        assert!(
            close(fd, gz[j]),
            "merit gradient z{j} ({group:?} plane at t {t}): {} vs central differences {fd}",
            gz[j]
        );
    }
}
