//! The compiled model of a cyclic pattern (r2′): the compatibility constraints compile to
//! the same values as the f64 path, their gradients agree with central differences, and
//! Newton's polish brings a cell nudged off a compatible family back onto one.

use foldsynth::check::cycle::{CYCLE_TOL, verify_cycles};
use foldsynth::check::verify::{Tolerances, verify};
use foldsynth::compile::Options;
use foldsynth::grammar::CreaseGraph;
use foldsynth::kinematics::closure_residual;
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

/// The model's free variables in its order, from named values (every one must be given).
fn free_values(m: &Model, vars: &[(&str, f64)]) -> Vec<f64> {
    m.free
        .iter()
        .map(|&i| {
            let name = &m.plan.variables[i].name;
            vars.iter()
                .find(|(n, _)| n == name)
                .map(|(_, v)| *v)
                .unwrap_or_else(|| panic!("no value for {name}"))
        })
        .collect()
}

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

/// The optimizer's Fig. 52b design on the gripper task (`model --graph "2, 3, 4, 8, (9, 14)'"
/// --candidate 2 --modes down,up,up,up --optimize`, Ω = 1.2e-6): compatible to 5e-13 and an
/// isometry, but two of its creases fold on through ±π — its facets pass through each
/// other, so the cycle sweep must fail it. The Miura cell, whose creases stay inside
/// (−π, π), still passes.
#[test]
fn a_crease_folding_through_flat_fails_the_sweep() {
    let m = model(1);
    let vars: [(&str, f64); 15] = [
        ("l_2,3", 1.28668077747507),
        ("l_2,4", 1.4578067207899132),
        ("l_3,8", 0.14435439817941612),
        ("l_8,13", 0.7541491432423296),
        ("α_10", 0.37331546631203527),
        ("α_11", 2.824488079368098),
        ("α_12", 2.561110737651746),
        ("α_13", 1.9929461460816855),
        ("α_3", 0.7457671478371456),
        ("α_4", 2.5789766761829633),
        ("α_5", 1.2333386493075686),
        ("α_6", 1.7961054206767704),
        ("α_7", 0.5628655650496057),
        ("α_8", 2.9669575201189273),
        ("α_9", 2.7363488524356057),
    ];
    let free = free_values(&m, &vars);
    let ts = sample_times(m.t_max, 181);
    let d = Evaluated::new(&m.plan, m.full_vars(&free), vec![-1.0, 1.0, 1.0, 1.0]);
    let r = verify_cycles(&d, &ts, 1e-12);
    // Compatible and continuous in wrapped angles: only the new measure sees it.
    assert!(r.compatibility_max < 1e-9, "{r:?}");
    assert!(r.position_max < 1e-9, "{r:?}");
    let (crease, t) = r.through_flat.clone().expect("a crease passes through ±π");
    assert!(t > 0.0 && t < m.t_max, "{t}");
    assert!(!r.passes(CYCLE_TOL));
    assert!(
        r.failures(CYCLE_TOL).iter().any(|f| f.contains(&crease)),
        "{:?}",
        r.failures(CYCLE_TOL)
    );
    // The Miura cell over the same sweep: no crease passes ±π.
    let c = model(0);
    let miura = Evaluated::new(&c.plan, c.full_vars(&miura_free(&c)), MIURA_MODES.to_vec());
    let r = verify_cycles(&miura, &ts, 1e-12);
    assert!(r.through_flat.is_none(), "{r:?}");
}

/// A design of `synthesize grammar/gripper.toml --rules r1,r2,r2p` (`model --graph
/// "2, 3, 8, (4, 11)'" --candidate 2 --modes down,down,up --optimize`): cyclic, compatible
/// to 2e-13 over the sweep, and at t = 0 every vertex triangle has perimeter 2π (each
/// unit spans at most π), where the PTU's θ come from sin s ≈ 1e-16 and its φ are ~1e-7
/// of noise. The flat state of a cyclic design is flat by definition (every fold angle 0);
/// its vertex states must say so too, or closure, measured on fold angles and φ together,
/// fails by that noise (it did: 8.6e-8 against 1e-10, counted as a verification failure).
#[test]
fn the_flat_state_of_a_cyclic_design_closes_exactly() {
    let task = Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap();
    let g = CreaseGraph::from_sequence(&task, "2, 3, 8, (4, 11)'").unwrap();
    let m = Model::new(&g, &task, 1).unwrap();
    let vars: [(&str, f64); 10] = [
        ("α_3", 1.7727240987035973),
        ("l_2,3", 0.20099461765543536),
        ("α_5", 0.34988032748083936),
        ("α_6", 0.9673436594046511),
        ("α_7", 2.967042900988319),
        ("α_8", 0.17456692753679198),
        ("l_3,8", 0.3949348113626515),
        ("α_9", 2.074580258477363),
        ("α_10", 2.9662694348862426),
        ("l_8,10", 1.4999120281956797),
    ];
    let free = free_values(&m, &vars);
    let modes = vec![-1.0, -1.0, 1.0];
    let d = Evaluated::new(&m.plan, m.full_vars(&free), modes.clone());

    // The PTU itself at t = 0: perimeter 2π at every vertex, φ off zero by noise.
    let raw = geometry::fold(&m.plan, &d.flat, &modes, &0.0);
    let noisy = m.plan.internal.iter().any(|&a| {
        let st = raw.states[a].as_ref().unwrap();
        let s = (st.u[0] + st.u[1] + st.u[2]) / 2.0;
        assert!((s - PI).abs() < 1e-14, "{:?}", st.u);
        st.phi.iter().any(|p| p.abs() > 1e-9)
    });
    assert!(
        noisy,
        "the case this test is about: φ at the flat state is noise"
    );

    // The design's flat state: fold angles 0 and, at every vertex, φ equal to the fold
    // angles of its three outgoing creases, closing the loop to rounding.
    let flat = d.fold(0.0);
    let rho: Vec<Option<f64>> = flat.rho.iter().map(|r| Some(*r)).collect();
    for &a in &m.plan.internal {
        let st = flat.states[a].as_ref().unwrap();
        let v = &m.plan.vertices[a];
        for (slot, phi) in [(0, 2), (1, 0), (2, 1)] {
            assert_eq!(st.phi[phi], flat.rho[v.rays[v.preds + slot].crease]);
        }
        let u = geometry::units(&m.plan, &d.flat, &rho, a).unwrap();
        let c = closure_residual(&u, &st.phi);
        assert!(c < 1e-14, "v{}: closure {c:e}", v.name);
    }

    // So the whole verification passes, the flat state included.
    let ts = sample_times(m.t_max, 181);
    let tol = Tolerances::default();
    let v = verify(&d, &ts, &tol);
    assert_eq!(v.rigid_states, ts.len(), "{v:?}");
    assert!(v.passes(&tol), "{:?}", v.failures(&tol));
    assert!(verify_cycles(&d, &ts, 1e-12).passes(CYCLE_TOL));
}
