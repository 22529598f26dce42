//! The robustness block of the compiled model (issue 12): its compiled values agree with
//! the plain f64 kinematics, and the gradient of its augmented-Lagrangian term — clearance
//! planes between facets of the arm, to the rotated copy and to the cylinder, crease and
//! rigid-margin constraints — agrees with central differences, in the design variables and
//! in the planes' own variables. Checked away from switches: every multiplier is set so
//! that no `max(0, ·)` of the merit changes branch near the point.

use foldsynth::compile::Options as CompileOptions;
use foldsynth::grammar::{Enumeration, Filters};
use foldsynth::model::Model;
use foldsynth::model::clearance::Group;
use foldsynth::model::compiled::{CompiledModel, ModelProblem, objective_target};
use foldsynth::model::robust::{RobustModel, RobustProblem, RobustSpec};
use foldsynth::optimize::{Options, Robust, minimize};
use foldsynth::task::Task;

const GRIPPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml");

/// The block's merit and its gradient in `x` and `z`.
fn merit(rp: &RobustProblem, x: &[f64], z: &[f64], mu: f64) -> (f64, Vec<f64>, Vec<f64>) {
    let (mut gx, mut gz) = (vec![0.0; x.len()], vec![0.0; z.len()]);
    let v = rp.merit(x, z, mu, &mut gx, &mut gz);
    (v, gx, gz)
}

/// Central differences of the merit along every coordinate of `x` (then `z`) against the
/// analytic gradient.
fn check_gradient(rp: &RobustProblem, x: &[f64], z: &[f64], mu: f64, what: &str) {
    let (_, gx, gz) = merit(rp, x, z, mu);
    let h = 1e-6;
    let f = |x: &[f64], z: &[f64]| merit(rp, x, z, mu).0;
    for i in 0..x.len() {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[i] += h;
        xm[i] -= h;
        let fd = (f(&xp, z) - f(&xm, z)) / (2.0 * h);
        assert!(
            (fd - gx[i]).abs() <= 1e-5 * (1.0 + gx[i].abs()),
            "{what}: d/dx{i}: analytic {} vs central differences {fd}",
            gx[i]
        );
    }
    for j in 0..z.len() {
        let (mut zp, mut zm) = (z.to_vec(), z.to_vec());
        zp[j] += h;
        zm[j] -= h;
        let fd = (f(x, &zp) - f(x, &zm)) / (2.0 * h);
        assert!(
            (fd - gz[j]).abs() <= 1e-5 * (1.0 + gz[j].abs()),
            "{what}: d/dz{j}: analytic {} vs central differences {fd}",
            gz[j]
        );
    }
}

#[test]
fn block_values_and_gradients_match_f64_kinematics_and_central_differences() {
    let task = Task::load(GRIPPER).unwrap();
    let enumeration = Enumeration::run(&task, 2, Filters::all());
    let spec = RobustSpec::from_task(&task, 181);
    assert!(spec.second_arm && !spec.cylinders.is_empty());
    // Groups of clearance pairs whose planes have been checked: the arm's own facets, the
    // rotated copy, the cylinder.
    let mut checked: Vec<Group> = Vec::new();
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
                // Planes fitted where pairs come close; every multiplier 1 with μ small
                // keeps every term of the merit on its smooth branch (λ − μh > 0).
                rp.update(x, None);
                rp.set_multipliers(1.0);
                let z = rp.variables();
                let planes = rp.variable_planes();
                let new: Vec<Group> = planes
                    .iter()
                    .map(|(_, p)| p.group)
                    .filter(|g| !checked.contains(g))
                    .collect();
                if new.is_empty() {
                    continue;
                }
                let what = format!(
                    "{} candidate {candidate} modes {modes:?}",
                    node.graph.sequence()
                );
                check_gradient(&rp, x, &z, 1e-3, &what);
                // Off the optimum too: the design variables nudged (the planes kept).
                let nudged: Vec<f64> = x
                    .iter()
                    .enumerate()
                    .map(|(i, v)| v + 1e-3 * ((i as f64 * 0.7).sin()))
                    .collect();
                check_gradient(&rp, &nudged, &z, 1e-3, &what);
                for g in new {
                    if !checked.contains(&g) {
                        checked.push(g);
                    }
                }
                if checked.len() == 3 {
                    break 'search;
                }
            }
        }
    }
    for g in [Group::SelfPair, Group::Arm, Group::Obstacle] {
        assert!(checked.contains(&g), "no plane of {g:?} was checked");
    }
}
