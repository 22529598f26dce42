//! The compatibility of cycles closed by r2′ (thesis Sec. 4.2.5.2, 4.3.3, 5.7; Fig. 52b).
//!
//! The PTU propagates dihedral angles along the graph's edges from G0's driven crease. An
//! r2′ sink v′ is reached along two paths: its straight crease p1 → v′ ← p2 gets one
//! dihedral angle from p1's PTU and one from p2's. The pattern folds only if both agree —
//! ρ(p1, v′) = ρ(p2, v′), the thesis's ρ_{8,9′} = ρ_{4,9′} — which holds only for special,
//! symmetric sector configurations (Sec. 4.3.3). Its collinearity needs no constraint: the
//! plan places v′ at the midpoint of p1 and p2 (`Position::Between`).
//!
//! Both conditions enter the compiled model as constraints `g ≥ 0`, at the model's
//! [`states`] (each equality as a pair `±r ≥ 0`), per sink and state:
//!
//! 1. the dihedral angles, `r = 2 sin((ρ(p1, v′) − ρ(p2, v′)) / 2)` (zero exactly when
//!    they agree modulo 2π — the PTU's φ may jump by a full turn — smooth, slope 1 at 0);
//! 2. the folded positions along both paths around the cycle: the facet on one side of
//!    the straight crease at the later-extended end L, once through the facet walk (its map
//!    comes from the other end's side), once by turning around L from the facet on the
//!    other side, crease by crease, away from the straight crease — with L's own PTU
//!    angles. `r` is the difference of the two positions of the vertex next to L on that
//!    facet (three components).
//!
//! 3. at t_max, the straight crease folds at least by α_min: `cos α_min − cos ρ(p1, v′)
//!    ≥ 0`. Otherwise the cycle closes trivially — both ends fold about other lines, the
//!    crease stays flat, the sink is a point inside one flat piece of paper — which satisfies
//!    (1) and (2) for free and is what the optimizer finds first (issue 19's notes).
//!
//! Given closure at every vertex (the PTU's own guarantee), (2) vanishes exactly when (1)
//! does; (2) is the geometric statement that the two paths meet. Neither certifies the
//! motion *between* the states: every cyclic design is verified on a dense sweep
//! (`check::cycle`) and by the bar-and-hinge simulation (`simulate::crossval`), the
//! independent kinematics that decides.

use super::Model;
use super::geometry::{Flat, Folded, position_on};
use super::linalg::{self, Mat3, Vec3};
use super::plan::{Plan, Sink};
use crate::kinematics::Scalar;

/// Number of states, evenly spaced over (0, t_max], at which a cyclic model imposes
/// compatibility. More states than the design has spare freedom, so that matching them
/// without matching the whole motion is unlikely; the dense sweep judges anyway.
pub const CYCLE_STATES: usize = 6;

/// Augmented-Lagrangian iterations per start for a cyclic model (the optimizer's default
/// is 10): its 8 equalities per sink and state, each a pair of inequalities, need more
/// multiplier updates. Measured on `grammar/miura.toml` (`2, 3, 4, 8, (9, 14)'`, candidate
/// 2, modes down,up,up,down, Kawasaki's condition): with 10, 32 starts end infeasible at
/// Ω = 0.39 at best; with 30, the 4th start meets the target.
pub const MAX_OUTER: usize = 30;

/// Constraints per sink and state: the dihedral pair, then three position pairs.
pub const PER_STATE: usize = 8;

/// The values of t at which the model imposes compatibility: `t_max·k/CYCLE_STATES`.
pub fn states(t_max: f64) -> Vec<f64> {
    (1..=CYCLE_STATES)
        .map(|k| t_max * k as f64 / CYCLE_STATES as f64)
        .collect()
}

/// The two residuals of one sink at one folded state.
#[derive(Clone, Debug)]
pub struct Residual<S> {
    /// `2 sin((ρ(p1, v′) − ρ(p2, v′)) / 2)`.
    pub dihedral: S,
    /// The position of the check vertex along the second path minus along the first.
    pub position: Vec3<S>,
}

/// The end of `sink` extended later (its facet walk finds both facets of the straight
/// crease already placed), and its crease into the sink.
pub fn later_end(plan: &Plan, sink: &Sink) -> (usize, usize) {
    let order = |v: usize| plan.internal.iter().position(|&u| u == v);
    if order(sink.ends[0]) > order(sink.ends[1]) {
        (sink.ends[0], sink.creases[0])
    } else {
        (sink.ends[1], sink.creases[1])
    }
}

/// The vertex whose positions the second path compares: the neighbour of the later end
/// clockwise of its straight crease (it lies on the facet both paths reach).
pub fn check_vertex(plan: &Plan, sink: &Sink) -> usize {
    let (l, e) = later_end(plan, sink);
    let rays = &plan.vertices[l].rays;
    let k = rays.iter().position(|r| r.crease == e).expect("ray of L");
    rays[(k + rays.len() - 1) % rays.len()].other
}

/// The residuals of `sink` at the folded state `folded` (see the module docs).
pub fn residual<S: Scalar>(
    plan: &Plan,
    flat: &Flat<S>,
    folded: &Folded<S>,
    sink: &Sink,
) -> Residual<S> {
    let half = (folded.rho[sink.creases[0]].clone() - folded.rho[sink.creases[1]].clone()) * 0.5;
    let dihedral = half.sin() * 2.0;

    let (l, e) = later_end(plan, sink);
    let v = &plan.vertices[l];
    let n = v.rays.len();
    let k = v.rays.iter().position(|r| r.crease == e).expect("ray of L");
    let c = &plan.creases[e];
    // L → v′ leaves L: the facet counter-clockwise of it is its left, clockwise its right.
    let (from, to) = (c.left, c.right);
    let z = || S::from_f64(0.0);
    let xl: Vec3<S> = [flat.pos[l][0].clone(), flat.pos[l][1].clone(), z()];
    let anchor = linalg::add(&linalg::apply(&folded.rot[from], &xl), &folded.trans[from]);
    let mut r: Mat3<S> = folded.rot[from].clone();
    for j in 1..n {
        let ray = (k + j) % n;
        let d = &flat.dirs[l][ray];
        let turn = linalg::rot_in_plane_axis(&d[0], &d[1], &folded.rho[v.rays[ray].crease]);
        r = linalg::mul(&r, &turn);
    }
    let t = linalg::sub(&anchor, &linalg::apply(&r, &xl));
    let w = check_vertex(plan, sink);
    let xw: Vec3<S> = [flat.pos[w][0].clone(), flat.pos[w][1].clone(), z()];
    let second = linalg::add(&linalg::apply(&r, &xw), &t);
    let first = position_on(flat, folded, w, to);
    Residual {
        dihedral,
        position: linalg::sub(&second, &first),
    }
}

/// Indices into `model.times` of the compatibility states.
fn state_indices(model: &Model) -> Vec<usize> {
    if model.plan.sinks.is_empty() {
        return Vec::new();
    }
    // `times[0]` is the t_max the model was built with.
    states(model.times[0])
        .iter()
        .map(|t| {
            model
                .times
                .iter()
                .position(|s| s == t)
                .expect("every compatibility state is in the model's times")
        })
        .collect()
}

/// The compatibility constraints `g ≥ 0` of `model` (empty without r2′), appended after
/// the plan's: per state, per sink, `±dihedral`, then `±position` component by component;
/// then per sink the fold of its straight crease at t_max. `folded[i]` is the state at
/// `model.times[i]` (`folded[0]` at t_max).
pub fn constraints<S: Scalar>(model: &Model, flat: &Flat<S>, folded: &[Folded<S>]) -> Vec<S> {
    let mut out = Vec::new();
    for k in state_indices(model) {
        for sink in &model.plan.sinks {
            let r = residual(&model.plan, flat, &folded[k], sink);
            out.push(r.dihedral.clone());
            out.push(-r.dihedral);
            for x in r.position {
                out.push(x.clone());
                out.push(-x);
            }
        }
    }
    let min = model.bounds.alpha_min.cos();
    for sink in &model.plan.sinks {
        out.push(S::from_f64(min) - folded[0].rho[sink.creases[0]].cos());
    }
    out
}

/// Number of compatibility constraints of `model`.
pub fn count(model: &Model) -> usize {
    let n = model.plan.sinks.len();
    CYCLE_STATES * n * PER_STATE + n
}

/// The label of compatibility constraint `j` (0-based among them).
pub fn label(model: &Model, j: usize) -> String {
    let p = &model.plan;
    let per_state = p.sinks.len() * PER_STATE;
    let name = |v: usize| p.vertices[v].name;
    if let Some(k) = j.checked_sub(CYCLE_STATES * per_state) {
        let sink = &p.sinks[k];
        return format!(
            "r2′ the straight crease v{}–v{}′–v{} folds at t_max: |ρ| ≥ α_min",
            name(sink.ends[0]),
            name(sink.vertex),
            name(sink.ends[1])
        );
    }
    let (state, rest) = (j / per_state, j % per_state);
    let (sink, kind) = (&p.sinks[rest / PER_STATE], rest % PER_STATE);
    let t = states(model.times[0])[state];
    let sign = if kind % 2 == 0 { "≥" } else { "≤" };
    if kind < 2 {
        format!(
            "r2′ compatibility at t = {t:.6}: ρ(v{}, v{}′) − ρ(v{}, v{}′) {sign} 0",
            name(sink.ends[0]),
            name(sink.vertex),
            name(sink.ends[1]),
            name(sink.vertex)
        )
    } else {
        let (l, _) = later_end(p, sink);
        format!(
            "r2′ cycle closure at t = {t:.6}: v{} around v{} − through the facet walk, {} {sign} 0",
            name(check_vertex(p, sink)),
            name(l),
            ["x", "y", "z"][(kind - 2) / 2]
        )
    }
}

/// Newton's method on the compatibility equations, after the optimizer: the augmented
/// Lagrangian leaves equality residuals of ~1e-9 (its feasibility tolerance, no tighter),
/// while a cyclic design must agree to 1e-9 over a whole sweep. Starting from the
/// optimizer's point (free variables `free`), damped minimum-norm steps `Δx = −J⁺ r` on
/// the dihedral residuals `r` at the model's states (Jacobian by central differences of
/// the f64 kinematics) move the point onto the manifold where they vanish to rounding.
/// The residuals at neighbouring states are nearly dependent (a smooth function of t
/// sampled six times: on the cells tried, singular values 20, 1.3, 1e-3, then 6e-7 and
/// below, at the level of the differences' own error), so singular values below
/// 1e-6 σ_max are dropped: on an exactly compatible family the residuals then vanish; near
/// one that is only almost compatible they stay, and the sweep rejects the design.
/// Returns the refined point, or `None` if the residuals did not shrink (the caller keeps
/// the optimizer's point). Bounds are respected by clamping; the caller re-evaluates every
/// constraint and the objective.
pub fn polish(model: &Model, free: &[f64], modes: &[f64]) -> Option<Vec<f64>> {
    if model.plan.sinks.is_empty() {
        return None;
    }
    let ts = states(model.times[0]);
    let residuals = |x: &[f64]| -> Vec<f64> {
        let flat = super::geometry::flat(&model.plan, &model.full_vars(x));
        let mut r = Vec::new();
        for t in &ts {
            let folded = super::geometry::fold(&model.plan, &flat, modes, t);
            for s in &model.plan.sinks {
                r.push(residual(&model.plan, &flat, &folded, s).dihedral);
            }
        }
        r
    };
    let norm = |r: &[f64]| r.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let mut x = free.to_vec();
    let mut r = residuals(&x);
    let start = norm(&r);
    if !start.is_finite() {
        return None;
    }
    let (n, m) = (x.len(), r.len());
    for _ in 0..20 {
        if norm(&r) <= 1e-14 {
            break;
        }
        let h = 1e-6;
        let mut j = nalgebra::DMatrix::<f64>::zeros(m, n);
        for k in 0..n {
            let (mut xp, mut xm) = (x.clone(), x.clone());
            xp[k] += h;
            xm[k] -= h;
            let (rp, rm) = (residuals(&xp), residuals(&xm));
            for i in 0..m {
                j[(i, k)] = (rp[i] - rm[i]) / (2.0 * h);
            }
        }
        let svd = j.svd(true, true);
        let eps = 1e-6 * svd.singular_values.max();
        let Ok(step) = svd.solve(&nalgebra::DVector::from_vec(r.clone()), eps) else {
            break;
        };
        // Damped: halve the step until the residuals shrink.
        let mut better = None;
        let mut scale = 1.0;
        for _ in 0..8 {
            let next: Vec<f64> = x
                .iter()
                .enumerate()
                .map(|(k, v)| {
                    let (lo, hi) = model.var_bounds(model.free[k]);
                    (v - scale * step[k]).clamp(lo, hi)
                })
                .collect();
            let rn = residuals(&next);
            if norm(&rn) < norm(&r) {
                better = Some((next, rn));
                break;
            }
            scale *= 0.5;
        }
        let Some((next, rn)) = better else {
            break;
        };
        x = next;
        r = rn;
    }
    (norm(&r) < start).then_some(x)
}

/// [`polish`] an optimizer's solution of `problem` (the compiled model of `model` with
/// `modes`) in place: the refined point replaces it when its largest constraint violation
/// is no worse (or within `feasibility_tol`); objective, constraints, feasibility and
/// `met_target` are re-evaluated there.
pub fn polish_solution<P: crate::optimize::Problem>(
    problem: &P,
    model: &Model,
    modes: &[f64],
    sol: &mut crate::optimize::Solution,
    feasibility_tol: f64,
    target: Option<f64>,
) {
    let Some(x) = polish(model, &sol.x, modes) else {
        return;
    };
    let mut e = crate::optimize::Evaluation::new(problem.n_vars(), problem.n_constraints());
    problem.eval(&x, &mut e);
    let violation = e.violation();
    // A NaN violation (a polish gone astray) keeps the optimizer's point too.
    if violation.is_nan() || violation > sol.violation.max(feasibility_tol) {
        return;
    }
    sol.feasible = violation <= feasibility_tol && e.f.is_finite();
    sol.met_target = sol.feasible && target.is_some_and(|t| e.f <= t);
    sol.x = x;
    sol.f = e.f;
    sol.g = e.g;
    sol.violation = violation;
}
