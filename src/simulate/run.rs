//! One bar-and-hinge simulation over J steps (thesis Sec. 3.2).

use serde::{Deserialize, Serialize};
use thiserror::Error;

// The default refinement budget lives with the settings it is the default of.
pub use super::input::REFINE_ITERATION_BUDGET;
use super::input::{InputError, SimInput, Supports};
use super::solver::{Bars, predict, solve};
use crate::check::{CheckError, Checker, Intersection, StateTracker};

/// The thesis's bound on the distortion for a rigid step (Sec. 3.2.3).
pub const RIGID_DELTA: f64 = 1e-4;

/// Why a simulation could not run.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SimError {
    /// The input is inconsistent.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The facets cannot be checked for intersection (in the xy-projection of the initial
    /// state they are not simple counter-clockwise polygons).
    #[error("intersection check: {0}")]
    Check(#[from] CheckError),
    /// A drive produced a non-finite position.
    #[error("a drive gave a non-finite position for vertex {vertex} at t = {t}")]
    NonFiniteDrive {
        /// The vertex.
        vertex: usize,
        /// The parameter value.
        t: f64,
    },
}

/// One folding step j.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepReport {
    /// The step number, 1..=J.
    pub j: usize,
    /// The driving parameter t_j.
    pub t: f64,
    /// δ(j) = Σ_b |l_b² − l_t,b²| at the solution (Eq. 3 with the squared lengths of Eq. 2).
    pub delta: f64,
    /// Σ_b |l_b − l_t,b| at the solution (the same distortion in plain lengths).
    pub delta_length: f64,
    /// Solver iterations spent on this step (all substeps and trial solves).
    pub iterations: usize,
    /// Substeps the step was finally taken in (1 unless a branch jump forced refinement).
    pub substeps: usize,
    /// Whether refinement stopped at its budget ([`REFINE_ITERATION_BUDGET`] by default) before the half steps
    /// agreed: a motion no small step can follow (e.g. a prescribed vertex that jumps).
    #[serde(default)]
    pub refinement_capped: bool,
    /// The first self-intersection found at this step, if any (with the check on).
    pub intersection: Option<Intersection>,
}

/// The result of a simulation (thesis Sec. 3.2.5).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SimReport {
    /// Every step j = 1..=J.
    pub steps: Vec<StepReport>,
    /// Rigidity error Γ = (1/J) Σ δ(j) (Eq. 4).
    pub gamma: f64,
    /// Self-intersection measure θ: the share of steps with a self-intersection.
    pub theta: f64,
    /// True when every δ(j) ≤ [`RIGID_DELTA`].
    pub rigid: bool,
    /// Self-intersections already present in the initial state (t_start).
    pub initial_intersections: Vec<Intersection>,
    /// Vertex positions at t_0 … t_J (J + 1 states).
    pub states: Vec<Vec<[f64; 3]>>,
    /// Number of bars.
    pub bars: usize,
    /// Number of free (unknown) vertices.
    pub free_vertices: usize,
}

impl SimReport {
    /// The positions at the last step j = J.
    pub fn final_positions(&self) -> &[[f64; 3]] {
        self.states.last().map(Vec::as_slice).unwrap_or(&[])
    }

    /// The largest δ(j).
    pub fn max_delta(&self) -> f64 {
        self.steps.iter().map(|s| s.delta).fold(0.0, f64::max)
    }
}

/// Largest disagreement (relative to the pattern's size) between reaching a state in one
/// step and in two half steps before the step is refined.
pub const BRANCH_TOLERANCE: f64 = 1e-4;

/// Takes one reported step by continuation.
///
/// Each step starts from the previous solution (Eq. 3), moved along the motion's tangent
/// ([`super::solver::predict`]). Near a bifurcation — the flat state, or where a vertex's
/// unit triangle degenerates — a large step can still land on the mirror branch, which the
/// thesis's small-step intent does not mean. So a step is also taken as two half steps;
/// when the two results differ by more than `BRANCH_TOLERANCE` × size, the step is halved
/// recursively, so the solution follows the branch it is on as the limit of small steps
/// would.
struct Stepper<'a> {
    input: &'a SimInput,
    supports: &'a Supports,
    bars: &'a Bars,
    slot: &'a [Option<usize>],
    n_free: usize,
    branch_tol: f64,
    iterations: usize,
    substeps: usize,
    /// The first step's displacement of every vertex (from `first_step_offsets`, zero
    /// elsewhere) and the step's length in t; `None` without offsets.
    hint: Option<(Vec<[f64; 3]>, f64)>,
    /// How far the last solve moved the free vertices from its predicted start.
    last_correction: f64,
    /// Whether this step's refinement stopped at the budget.
    capped: bool,
}

impl Stepper<'_> {
    /// Solve at `t` starting from the state `start` reached at `t_from`; `before` is an
    /// earlier state on the same branch and its t, when there is one.
    fn solve_at(
        &mut self,
        t: f64,
        start: &[[f64; 3]],
        t_from: f64,
        before: Option<(&[[f64; 3]], f64)>,
    ) -> Result<Vec<[f64; 3]>, SimError> {
        let mut x = start.to_vec();
        for (v, xv) in x.iter_mut().enumerate() {
            if let Some(p) = self.supports.position(v, t, &self.input.initial[v]) {
                if p.iter().any(|c| !c.is_finite()) {
                    return Err(SimError::NonFiniteDrive { vertex: v, t });
                }
                *xv = p;
            }
        }
        match &self.hint {
            // Within the first step, which leaves the initial state (a bifurcation such
            // as the flat state, where the tangent is not unique), follow the given
            // first-step displacement, scaled to this (sub)step: the straight path to
            // X(t₁) stays nearer the intended branch than to any other, as branches part
            // linearly in t.
            Some((dx, len)) if (t_from - self.input.t_start).abs() < 0.5 * len.abs() => {
                let s = (t - t_from) / len;
                for (v, s_v) in self.slot.iter().enumerate() {
                    if s_v.is_some() {
                        for u in 0..3 {
                            x[v][u] = start[v][u] + s * dx[v][u];
                        }
                    }
                }
            }
            // With a state behind, extrapolate along the secant: it follows the branch the
            // motion is on even where the linearised bars barely tell the branches apart
            // (near the flat state, where a vertex's creases have only just begun to fold),
            // which the tangent predictor, solved from those bars, cannot.
            _ => match before {
                Some((xb, tb)) if tb != t_from => {
                    let s = (t - t_from) / (t_from - tb);
                    for (v, s_v) in self.slot.iter().enumerate() {
                        if s_v.is_some() {
                            for u in 0..3 {
                                x[v][u] = start[v][u] + s * (start[v][u] - xb[v][u]);
                            }
                        }
                    }
                }
                _ => predict(self.bars, self.slot, self.n_free, start, &mut x),
            },
        }
        let predicted = x.clone();
        let stats = solve(
            self.bars,
            self.slot,
            self.n_free,
            &mut x,
            &self.input.solver,
        );
        self.iterations += stats.iterations;
        self.last_correction = x
            .iter()
            .zip(&predicted)
            .flat_map(|(a, b)| (0..3).map(move |u| (a[u] - b[u]).abs()))
            .fold(0.0, f64::max);
        Ok(x)
    }

    fn advance(
        &mut self,
        x0: &[[f64; 3]],
        t0: f64,
        t1: f64,
        depth: usize,
        before: Option<(&[[f64; 3]], f64)>,
    ) -> Result<Vec<[f64; 3]>, SimError> {
        let full = self.solve_at(t1, x0, t0, before)?;
        let corrected = self.last_correction;
        let moved = full
            .iter()
            .zip(x0)
            .flat_map(|(a, b)| (0..3).map(move |u| (a[u] - b[u]).abs()))
            .fold(0.0, f64::max);
        // A first step whose given displacement already lands on a solution is the branch
        // the caller chose; the half-step test would only second-guess it with the cruder
        // linear path to t_m.
        if depth == 0
            && self.hint.is_some()
            && t0 == self.input.t_start
            && self.last_correction <= self.branch_tol
        {
            self.substeps += 1;
            return Ok(full);
        }
        if depth >= self.input.solver.max_refine {
            self.substeps += 1;
            return Ok(full);
        }
        if self.iterations >= self.input.solver.refine_budget {
            self.capped = true;
            self.substeps += 1;
            return Ok(full);
        }
        let tm = 0.5 * (t0 + t1);
        let mid = self.solve_at(tm, x0, t0, before)?;
        let two = self.solve_at(t1, &mid, tm, Some((x0, t0)))?;
        let gap = full
            .iter()
            .zip(&two)
            .flat_map(|(a, b)| (0..3).map(move |u| (a[u] - b[u]).abs()))
            .fold(0.0, f64::max);
        let kappa = self.input.solver.max_correction;
        if gap <= self.branch_tol && corrected <= kappa * moved {
            self.substeps += 1;
            return Ok(two);
        }
        let xa = self.advance(x0, t0, tm, depth + 1, before)?;
        self.advance(&xa, tm, t1, depth + 1, Some((x0, t0)))
    }
}

/// The intersection checker for an input: its facets triangulated in the xy-projection of
/// the initial state.
pub fn checker_for(input: &SimInput) -> Result<Checker, CheckError> {
    let layout: Vec<[f64; 2]> = input.initial.iter().map(|p| [p[0], p[1]]).collect();
    Checker::new(&layout, &input.faces)
}

/// Run the simulation.
pub fn simulate(input: &SimInput) -> Result<SimReport, SimError> {
    let checker = if input.check_intersections {
        Some(checker_for(input)?)
    } else {
        None
    };
    simulate_with_checker(input, checker.as_ref())
}

/// Run the simulation with a prepared checker (`None`: no intersection check, θ = 0).
pub fn simulate_with_checker(
    input: &SimInput,
    checker: Option<&Checker>,
) -> Result<SimReport, SimError> {
    let supports = input.resolve()?;
    let n = input.initial.len();
    let bars = Bars::from_faces(&input.faces, &input.extra_bars, &input.initial);
    let mut slot = vec![None; n];
    let mut n_free = 0;
    for (s, role) in slot.iter_mut().zip(&supports.role) {
        if role.is_none() {
            *s = Some(n_free);
            n_free += 1;
        }
    }
    let mut tracker = checker.map(StateTracker::new);
    let mut x = input.initial.clone();
    let initial_intersections = match &mut tracker {
        Some(tr) => tr.step(&x, input.t_start, false),
        None => Vec::new(),
    };
    let mut states = Vec::with_capacity(input.steps + 1);
    states.push(x.clone());
    let mut steps = Vec::with_capacity(input.steps);
    let jj = input.steps;
    let scale = input
        .initial
        .iter()
        .flatten()
        .fold(1.0_f64, |m, v| m.max(v.abs()));
    let mut stepper = Stepper {
        input,
        supports: &supports,
        bars: &bars,
        slot: &slot,
        n_free,
        branch_tol: BRANCH_TOLERANCE * scale,
        iterations: 0,
        substeps: 0,
        hint: None,
        last_correction: 0.0,
        capped: false,
    };
    if !input.first_step_offsets.is_empty() {
        let mut dx = vec![[0.0; 3]; n];
        for &(v, off) in &input.first_step_offsets {
            dx[v] = off;
        }
        stepper.hint = Some((dx, (input.t_end - input.t_start) / jj as f64));
    }
    let mut t_prev = input.t_start;
    let mut before: Option<(Vec<[f64; 3]>, f64)> = None;
    for j in 1..=jj {
        let t = input.t_start + (input.t_end - input.t_start) * j as f64 / jj as f64;
        stepper.iterations = 0;
        stepper.substeps = 0;
        stepper.capped = false;
        let next = stepper.advance(
            &x,
            t_prev,
            t,
            0,
            before.as_ref().map(|(xb, tb)| (xb.as_slice(), *tb)),
        )?;
        before = Some((std::mem::replace(&mut x, next), t_prev));
        t_prev = t;
        let intersection = match &mut tracker {
            Some(tr) => tr.step(&x, t, true).into_iter().next(),
            None => None,
        };
        steps.push(StepReport {
            j,
            t,
            delta: bars.delta(&x),
            delta_length: bars.delta_length(&x),
            iterations: stepper.iterations,
            substeps: stepper.substeps,
            refinement_capped: stepper.capped,
            intersection,
        });
        states.push(x.clone());
    }
    let gamma = steps.iter().map(|s| s.delta).sum::<f64>() / jj as f64;
    let theta = steps.iter().filter(|s| s.intersection.is_some()).count() as f64 / jj as f64;
    let rigid = steps.iter().all(|s| s.delta <= RIGID_DELTA);
    Ok(SimReport {
        steps,
        gamma,
        theta,
        rigid,
        initial_intersections,
        states,
        bars: bars.pairs.len(),
        free_vertices: n_free,
    })
}
