//! The compiled model of a cyclic pattern (r2′): the compatibility constraints compile to
//! the same values as the f64 path, their gradients agree with central differences, and
//! Newton's polish brings a cell nudged off a compatible family back onto one.

use foldsynth::check::cycle::{CYCLE_TOL, verify_cycles};
use foldsynth::compile::Options;
use foldsynth::grammar::CreaseGraph;
use foldsynth::model::compiled::{CompiledModel, ModelProblem, outputs_f64};
use foldsynth::model::numeric::{Evaluated, sample_times};
use foldsynth::model::{Model, cycle, geometry};
use foldsynth::optimize::{Evaluation, Problem};
use foldsynth::task::Task;
use std::f64::consts::PI;

fn model(candidate: usize) -> Model {
    let task = Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap();
    let g = CreaseGraph::from_sequence(&task, "2, 3, 4, 8, (9, 14)'").unwrap();
    Model::new(&g, &task, candidate).unwrap()
}

/// The classic Miura-ori cell of `tests/cyclic_miura.rs` (zigzag 60°), as free variables.
fn miura_free(m: &Model) -> Vec<f64> {
    let s = 2.0 * PI / 3.0;
    m.free
        .iter()
        .map(|&i| match m.plan.variables[i].name.as_str() {
            "α_3" | "α_5" | "α_8" | "α_9" | "α_11" | "α_13" => s,
            "α_4" | "α_6" | "α_7" | "α_10" | "α_12" => PI - s,
            "l_2,4" | "l_3,8" => 1.0,
            _ => 0.8,
        })
        .collect()
}

const MIURA_MODES: [f64; 4] = [-1.0, 1.0, 1.0, -1.0];

#[test]
fn the_cycle_constraints_are_in_the_model() {
    let m = model(0);
    let n = m.plan.constraints.len() + cycle::count(&m);
    let (_, g) = outputs_f64(&m, &miura_free(&m), &MIURA_MODES);
    assert_eq!(g.len(), n);
    // Six states of (0, t_max], 8 per state (±dihedral, ±x, ±y, ±z) and one fold bound.
    assert_eq!(cycle::count(&m), cycle::CYCLE_STATES * 8 + 1);
    for t in cycle::states(m.t_max) {
        assert!(m.times.contains(&t));
    }
    // The Miura cell: every equality holds to rounding, and the straight crease folds.
    let tail = &g[m.plan.constraints.len()..];
    assert!(
        tail[..tail.len() - 1].iter().all(|r| r.abs() < 1e-12),
        "{tail:?}"
    );
    assert!(tail[tail.len() - 1] > 0.0);
    assert!(m.constraint_label(n - 1).contains("folds at t_max"));
}

/// Every vertex triangle at every time of the model clear of degeneracy (margins and
/// perimeter deficit at least 1e-2), where central differences mean something.
fn smooth(m: &Model, x: &[f64], modes: &[f64]) -> bool {
    let flat = geometry::flat(&m.plan, &m.full_vars(x));
    m.times.iter().all(|t| {
        let folded = geometry::fold(&m.plan, &flat, modes, t);
        folded.states.iter().flatten().all(|st| {
            let deficit = 2.0 * PI - st.u.iter().sum::<f64>();
            st.margins.iter().all(|g| g.abs() >= 1e-2) && deficit >= 1e-2
        })
    })
}

#[test]
fn compiled_equals_f64_and_gradients_agree_with_central_differences() {
    let m = model(1);
    let compiled = CompiledModel::new(&m, &Options::default()).unwrap();
    let problem = ModelProblem::new(&m, &compiled, &MIURA_MODES);
    let mut e = Evaluation::new(problem.n_vars(), problem.n_constraints());
    let base = miura_free(&m);
    let first = m.plan.constraints.len();
    let mut checked = 0;
    // Points around the Miura cell, off its family (the residuals are not zero there).
    for (k, u) in foldsynth::optimize::quasi_random_points(base.len(), 60, 5)
        .iter()
        .enumerate()
    {
        let x: Vec<f64> = base
            .iter()
            .zip(u)
            .zip(&m.free)
            .map(|((b, u), &i)| {
                let (lo, hi) = m.var_bounds(i);
                (b + 0.2 * (u - 0.5)).clamp(lo, hi)
            })
            .collect();
        problem.eval(&x, &mut e);
        let (f, g) = outputs_f64(&m, &x, &MIURA_MODES);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0);
        assert!(close(e.f, f), "point {k}: objective {} vs {f}", e.f);
        for (j, gj) in g.iter().enumerate() {
            assert!(close(e.g[j], *gj), "point {k}: g{j} {} vs {gj}", e.g[j]);
        }
        if !smooth(&m, &x, &MIURA_MODES) {
            continue;
        }
        checked += 1;
        let h = 1e-6;
        for v in 0..x.len() {
            let (mut xp, mut xm) = (x.clone(), x.clone());
            xp[v] += h;
            xm[v] -= h;
            let (_, gp) = outputs_f64(&m, &xp, &MIURA_MODES);
            let (_, gm) = outputs_f64(&m, &xm, &MIURA_MODES);
            for j in first..gp.len() {
                let fd = (gp[j] - gm[j]) / (2.0 * h);
                let an = e.dg[j * x.len() + v];
                assert!(
                    (fd - an).abs() <= 1e-5 * (1.0 + fd.abs()),
                    "point {k}: ∂{}/∂x{v}: {fd} vs {an}",
                    m.constraint_label(j)
                );
            }
        }
    }
    assert!(checked >= 10, "only {checked} smooth points");
}

#[test]
fn polish_brings_a_nudged_cell_back_to_a_compatible_one() {
    let m = model(0);
    let mut x = miura_free(&m);
    let k = m
        .free
        .iter()
        .position(|&i| m.plan.variables[i].name == "α_13")
        .unwrap();
    x[k] += 1e-5;
    let ts = sample_times(m.t_max, 181);
    let sweep = |x: &[f64]| {
        let d = Evaluated::new(&m.plan, m.full_vars(x), MIURA_MODES.to_vec());
        verify_cycles(&d, &ts, 1e-12)
    };
    let before = sweep(&x);
    assert!(before.compatibility_max > 1e-7, "{before:?}");
    let y = cycle::polish(&m, &x, &MIURA_MODES).expect("the residuals shrink");
    let after = sweep(&y);
    assert!(after.passes(CYCLE_TOL), "{after:?}");
    // A small move: the nudge, not a jump to some other cell.
    let d = x
        .iter()
        .zip(&y)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(d < 1e-3, "moved by {d}");
}
