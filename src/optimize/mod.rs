//! Bounded, constrained, multi-start gradient optimization.
//!
//! `min f(x)` subject to `g(x) ≥ 0` and `lo ≤ x ≤ hi`:
//! - bounds by the smooth transform `x = lo + (hi − lo)(1 + sin y)/2` (y unbounded);
//! - inequality constraints by an augmented Lagrangian (Powell–Hestenes–Rockafellar):
//!   `L = f + Σ (max(0, λ_k − μ g_k)² − λ_k²) / 2μ`, multipliers updated
//!   `λ_k ← max(0, λ_k − μ g_k)`, μ raised while the violation does not shrink;
//! - each subproblem by L-BFGS with a Moré–Thuente line search (`optimize/lbfgs.rs`: argmin's
//!   arithmetic without its allocations);
//! - many deterministic starts from a randomly shifted Halton sequence across the box,
//!   stopping early once a start meets the target feasibly, or giving up after
//!   [`Options::give_up_after`] starts none of which came within
//!   [`Options::give_up_factor`] of the target (issue 14).
//!
//! Problems that are one function (alternatives whose differing modes reach no output of
//! the model) can share their starts' phase A through [`SharedStarts`]: a start's phase A
//! depends only on the problem and its starting point, so a second problem replays it.
//!
//! The optimizer sees the problem only through [`Problem::eval`] (objective, constraints
//! and their gradients in one call), i.e. the compiled model.
//!
//! [`minimize_robust`] adds a second phase for constraints the problem keeps itself (a
//! [`Robust`] block: clearances and margins over the motion, issue 12): a start first
//! solves the plain problem (phase A, exactly [`minimize`]); when that meets the target
//! but violates the block, the same augmented Lagrangian continues from there with the
//! block's terms in the merit (phase B: lazily added active constraints, warm-started
//! from the unconstrained optimum). A start counts only when the block accepts it.

use rand::{RngExt, SeedableRng};
use serde::Serialize;
use std::cell::{Cell, RefCell};

mod lbfgs;

/// A smooth constrained problem with box bounds.
pub trait Problem {
    /// Number of variables.
    fn n_vars(&self) -> usize;
    /// Number of constraints `g ≥ 0`.
    fn n_constraints(&self) -> usize;
    /// Lower and upper bound of variable `i`.
    fn bounds(&self, i: usize) -> (f64, f64);
    /// Evaluate at `x`: the objective, its gradient (length n), the constraints (length m)
    /// and their Jacobian (m × n, row-major) into `out`.
    fn eval(&self, x: &[f64], out: &mut Evaluation);
}

/// Constraints `h_k(x, z) ≥ 0` a problem keeps itself, with their own multipliers and
/// their own unbounded variables `z` (separating planes): many, and changing between outer
/// iterations (active sets, planes refitted), so they reach the optimizer as a term of the
/// augmented-Lagrangian merit rather than as rows of [`Evaluation`], and `z` joins the
/// design variables in each L-BFGS run. The block uses the same penalty
/// `Σ (max(0, λ_k − μ h_k)² − λ_k²)/2μ` and update `λ_k ← max(0, λ_k − μ h_k)` as the
/// optimizer's own constraints.
pub trait Robust {
    /// Forget the multipliers and active sets of an earlier start.
    fn reset(&self);
    /// End of an outer iteration at `x`: with `mu`, update the multipliers from the
    /// constraints the last subproblem saw; then refit (active sets, planes) for the next
    /// one. Returns the largest violation `max(0, −min h)` after the refit.
    fn update(&self, x: &[f64], mu: Option<f64>) -> f64;
    /// The block's own variables for the next subproblem (their number may change at each
    /// [`Robust::update`]).
    fn variables(&self) -> Vec<f64>;
    /// Keep the block's variables a subproblem ended with.
    fn set_variables(&self, z: &[f64]);
    /// The block's merit at `x`, `z` with penalty `mu`; adds its gradients into `grad_x`
    /// and `grad_z`.
    fn merit(&self, x: &[f64], z: &[f64], mu: f64, grad_x: &mut [f64], grad_z: &mut [f64]) -> f64;
    /// Whether `x`, feasible at the states sampled so far, also holds on the block's finer
    /// sweep; if not, the offending states are added (and fitted) for the next outer
    /// iterations, or the start is given up.
    fn accept(&self, x: &[f64]) -> Acceptance;
}

/// What [`Robust::accept`] decided.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Acceptance {
    /// The point holds everywhere the block looks.
    Accepted,
    /// It does not; states were added where it fails: optimize on.
    Refined,
    /// It does not, and more states will not help (e.g. a facet flipped between states).
    Rejected,
}

/// One evaluation of a [`Problem`].
#[derive(Clone, Debug, Default)]
pub struct Evaluation {
    /// Objective.
    pub f: f64,
    /// Its gradient.
    pub df: Vec<f64>,
    /// Constraints `g ≥ 0`.
    pub g: Vec<f64>,
    /// Their Jacobian, row-major.
    pub dg: Vec<f64>,
}

impl Evaluation {
    /// Buffers sized for `n` variables and `m` constraints.
    pub fn new(n: usize, m: usize) -> Evaluation {
        Evaluation {
            f: 0.0,
            df: vec![0.0; n],
            g: vec![0.0; m],
            dg: vec![0.0; m * n],
        }
    }

    /// The largest constraint violation, `max(0, −min g)`.
    pub fn violation(&self) -> f64 {
        self.g.iter().fold(0.0_f64, |v, g| v.max(-g))
    }
}

/// Settings of [`minimize`].
#[derive(Clone, Debug, Serialize)]
pub struct Options {
    /// Number of starting points (at most).
    pub starts: usize,
    /// Seed of the quasi-random starting points.
    pub seed: u64,
    /// Augmented-Lagrangian iterations per start.
    pub max_outer: usize,
    /// L-BFGS iterations per subproblem.
    pub max_inner: u64,
    /// Constraint violation accepted as feasible.
    pub feasibility_tol: f64,
    /// Stop as soon as a feasible point has `f ≤ target`.
    pub target: Option<f64>,
    /// A start has converged when it is feasible and an outer iteration changes the
    /// objective by less than this, relative to `1 + |f|`.
    pub rel_tol: f64,
    /// An L-BFGS subproblem stops when its last `stall_window` iterations together lowered
    /// the merit by less than `stall_tol` times the merit it started from (0: never; the
    /// iterates up to that point are unchanged). Without it the robotic arm's subproblems
    /// ran to their iteration cap while the merit crept, most of them on starts that never
    /// reach the target. Default 10 iterations and 1e-8: see README for what it saves and
    /// what it moves.
    pub stall_window: usize,
    /// See [`Options::stall_window`].
    pub stall_tol: f64,
    /// Phase B ([`minimize_robust`]): augmented-Lagrangian iterations.
    pub robust_outer: usize,
    /// Phase B: L-BFGS iterations per subproblem. Default 60: the multipliers and planes
    /// are updated sooner and a start that cannot satisfy the block reaches its plateau
    /// test in fewer evaluations. Gripper, 2 Dec 2026, one run each: 100 / 80 / 60 / 40
    /// gave 760 / 742 / 719 / 683 designs for 21.8 / 19.5 / 17.3 / 15.0 optimize CPU s; the
    /// robotic arm 110 designs at 100, 109 at 60 (its time is phase A).
    pub robust_inner: u64,
    /// Phase B is tried on at most this many starts per problem (later starts still run
    /// phase A and count when the block accepts them as they are); with
    /// [`Options::all_starts`] on every start.
    pub robust_starts: usize,
    /// Give up on a problem with a positive target after this many starts (0: never) when
    /// none of them found a feasible point with `f ≤ give_up_factor · target`: the rest of
    /// the starts would mostly go to alternatives that never reach the threshold (issue 14).
    /// Default 10 (of 16) with factor 4: after 8 starts the gripper kept too few designs
    /// (743, merged with main's code of 2 Dec 2026); see README for the measured effect.
    pub give_up_after: usize,
    /// See [`Options::give_up_after`]; values below 1 count as 1.
    pub give_up_factor: f64,
    /// Run every start and keep the best objective among the points that meet the target,
    /// instead of stopping at the first start that meets it: for objectives with no natural
    /// zero (an area to maximize, whose target is written as constraints, so any feasible
    /// point meets it). Each start then runs its augmented Lagrangian until it converges
    /// (or its outer iterations end) rather than returning at its first point that meets
    /// the target, and [`Options::give_up_after`] does not apply. Off by default.
    pub all_starts: bool,
    /// Starting points to try after the quasi-random ones when none of those succeeded
    /// (a guided search's warm starts from a parent's optimum, issue 34): points in the
    /// variables' own units, moved 2 % inside their bounds. They run even when the
    /// quasi-random starts gave up, and never share phase A with other problems.
    #[serde(skip)]
    pub warm_starts: Vec<Vec<f64>>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            starts: 16,
            seed: 0,
            max_outer: 10,
            max_inner: 150,
            feasibility_tol: 1e-9,
            target: None,
            rel_tol: 1e-10,
            stall_window: 10,
            stall_tol: 1e-8,
            robust_outer: 20,
            robust_inner: 60,
            robust_starts: 4,
            give_up_after: 10,
            give_up_factor: 4.0,
            all_starts: false,
            warm_starts: Vec::new(),
        }
    }
}

/// The result of [`minimize`].
#[derive(Clone, Debug, Serialize)]
pub struct Solution {
    /// Best point found (feasible if any start found a feasible point).
    pub x: Vec<f64>,
    /// Objective there.
    pub f: f64,
    /// Constraints there.
    pub g: Vec<f64>,
    /// Largest violation there.
    pub violation: f64,
    /// Whether the violation is within the tolerance.
    pub feasible: bool,
    /// Whether a feasible point met the target.
    pub met_target: bool,
    /// With a [`Robust`] block: whether the block accepted the point.
    pub robust: Option<bool>,
    /// With a [`Robust`] block: its largest violation at the point.
    pub robust_violation: Option<f64>,
    /// Starts on which phase B ran.
    pub robust_attempts: usize,
    /// Which start produced it.
    pub start: usize,
    /// Starts run.
    pub starts_run: usize,
    /// Problem evaluations spent.
    pub evaluations: usize,
    /// It came from one of [`Options::warm_starts`] (its `start` counts on from the
    /// quasi-random starts).
    pub warm: bool,
}

/// The i-th radical inverse in base `b` (Halton).
fn radical_inverse(mut i: u64, b: u64) -> f64 {
    let (mut inv, mut f) = (0.0, 1.0 / b as f64);
    while i > 0 {
        inv += (i % b) as f64 * f;
        i /= b;
        f /= b as f64;
    }
    inv
}

const PRIMES: [u64; 32] = [
    2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71, 73, 79, 83, 89, 97,
    101, 103, 107, 109, 113, 127, 131,
];

/// `count` points of a Halton sequence in `[0, 1)^n` shifted by a random vector
/// (Cranley–Patterson rotation) drawn from `seed`: deterministic, well spread.
pub fn quasi_random_points(n: usize, count: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let shift: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
    (0..count)
        .map(|k| {
            (0..n)
                .map(|i| {
                    let base = PRIMES[i % PRIMES.len()];
                    // Beyond 32 dimensions, reuse primes with a skip so coordinates differ.
                    let idx = (k as u64 + 1) * (1 + (i / PRIMES.len()) as u64);
                    (radical_inverse(idx, base) + shift[i]).fract()
                })
                .collect()
        })
        .collect()
}

/// The bound transform `x = lo + (hi − lo)(1 + sin y)/2`.
struct Transform {
    lo: Vec<f64>,
    hi: Vec<f64>,
}

impl Transform {
    /// The starting point for `u` in the unit cube; it stays off the bounds, where the
    /// transform's slope vanishes.
    fn start(&self, u: &[f64]) -> Vec<f64> {
        u.iter()
            .enumerate()
            .map(|(i, u)| {
                let (l, h) = (self.lo[i], self.hi[i]);
                l + (h - l) * (0.02 + 0.96 * u)
            })
            .collect()
    }
    /// `x` moved inside its bounds as far as [`Transform::start`] keeps its points.
    fn inside(&self, x: &[f64]) -> Vec<f64> {
        x.iter()
            .enumerate()
            .map(|(i, &x)| {
                let (l, h) = (self.lo[i], self.hi[i]);
                let u = if h > l { (x - l) / (h - l) } else { 0.5 };
                l + (h - l) * (0.02 + 0.96 * u.clamp(0.0, 1.0))
            })
            .collect()
    }
    fn x(&self, y: &[f64]) -> Vec<f64> {
        let mut x = Vec::with_capacity(y.len());
        self.x_into(y, &mut x, None);
        x
    }
    /// `x(y)` into `x` and, with `slope`, `dx/dy` into it: one batched `sin_cos` over all
    /// variables (the crate's fdlibm kernels, as in the compiled models).
    fn x_into(&self, y: &[f64], x: &mut Vec<f64>, slope: Option<&mut Vec<f64>>) {
        let n = y.len();
        let mut spare = Vec::new();
        let c = slope.unwrap_or(&mut spare);
        x.resize(n, 0.0);
        c.resize(n, 0.0);
        crate::trig::batch::sin_cos(y, x, c);
        for i in 0..n {
            let half = (self.hi[i] - self.lo[i]) * 0.5;
            x[i] = self.lo[i] + half * (1.0 + x[i]);
            c[i] *= half;
        }
    }
    fn y(&self, x: &[f64]) -> Vec<f64> {
        x.iter()
            .enumerate()
            .map(|(i, x)| {
                let w = self.hi[i] - self.lo[i];
                if w <= 0.0 {
                    0.0
                } else {
                    (2.0 * (x - self.lo[i]) / w - 1.0).clamp(-1.0, 1.0).asin()
                }
            })
            .collect()
    }
}

/// The augmented Lagrangian of one subproblem, as L-BFGS sees it.
struct Merit<'a, P: Problem> {
    problem: &'a P,
    robust: Option<&'a dyn Robust>,
    /// Number of design variables; the block's variables follow them.
    n: usize,
    transform: &'a Transform,
    lambda: &'a [f64],
    mu: f64,
    /// The last point evaluated, its merit and gradient: the line search may ask again for
    /// the point it evaluated last.
    cache: (Vec<f64>, f64, Vec<f64>),
    /// The design variables of the last evaluation (a reused buffer).
    x: Vec<f64>,
    /// `dx/dy` there.
    slope: Vec<f64>,
    work: Evaluation,
    evaluations: &'a Cell<usize>,
}

impl<'a, P: Problem> Merit<'a, P> {
    /// The merit of one subproblem (`lambda`, `mu`), with fresh buffers and cache.
    fn new(
        problem: &'a P,
        robust: Option<&'a dyn Robust>,
        transform: &'a Transform,
        lambda: &'a [f64],
        mu: f64,
        n: usize,
        evaluations: &'a Cell<usize>,
    ) -> Self {
        Merit {
            problem,
            robust,
            n,
            transform,
            lambda,
            mu,
            cache: (Vec::new(), 0.0, Vec::new()),
            x: Vec::new(),
            slope: Vec::new(),
            work: Evaluation::new(n, lambda.len()),
            evaluations,
        }
    }
}

impl<P: Problem> lbfgs::Smooth for Merit<'_, P> {
    /// The merit and its gradient at `y` (design variables, then the block's), without
    /// allocating.
    fn eval(&mut self, y: &[f64], grad: &mut [f64]) -> f64 {
        if self.cache.0 == y {
            grad.copy_from_slice(&self.cache.2);
            return self.cache.1;
        }
        let (yd, z) = y.split_at(self.n);
        self.transform
            .x_into(yd, &mut self.x, Some(&mut self.slope));
        let e = &mut self.work;
        self.problem.eval(&self.x, e);
        self.evaluations.set(self.evaluations.get() + 1);
        let n = self.n;
        let mut value = e.f;
        grad[..n].copy_from_slice(&e.df);
        grad[n..].iter_mut().for_each(|g| *g = 0.0);
        let (grad_x, grad_z) = grad.split_at_mut(n);
        for (k, g) in e.g.iter().enumerate() {
            let a = (self.lambda[k] - self.mu * g).max(0.0);
            value += (a * a - self.lambda[k] * self.lambda[k]) / (2.0 * self.mu);
            if a > 0.0 {
                for (j, gj) in grad_x.iter_mut().enumerate() {
                    *gj -= a * e.dg[k * n + j];
                }
            }
        }
        if let Some(r) = self.robust {
            value += r.merit(&self.x, z, self.mu, grad_x, grad_z);
        }
        for (g, d) in grad_x.iter_mut().zip(self.slope.iter()) {
            *g *= d;
        }
        if !value.is_finite() || grad.iter().any(|g| !g.is_finite()) {
            // Outside where the model is defined: a wall the line search backs off from.
            value = 1e30;
            grad.iter_mut().for_each(|g| *g = 0.0);
        }
        self.cache.0.clear();
        self.cache.0.extend_from_slice(y);
        self.cache.1 = value;
        self.cache.2.clear();
        self.cache.2.extend_from_slice(grad);
        value
    }
}

/// Minimize the merit from `y0` with L-BFGS; returns the best point (or `y0`).
/// The cost tolerances are absolute; `scale` (the merit at the start) makes them relative.
fn lbfgs<P: Problem>(
    mut merit: Merit<'_, P>,
    y0: Vec<f64>,
    max_iters: u64,
    opts: &Options,
) -> Vec<f64> {
    let mut grad = vec![0.0; y0.len()];
    let scale = lbfgs::Smooth::eval(&mut merit, &y0, &mut grad)
        .abs()
        .clamp(1e-12, 1e12);
    let settings = lbfgs::Settings {
        memory: 8,
        max_iters,
        tol_grad: 1e-10,
        tol_cost: opts.rel_tol * 1e-3 * scale,
        stall_window: opts.stall_window,
        stall_tol: opts.stall_tol * scale,
    };
    if settings.tol_cost < 0.0 {
        return y0;
    }
    lbfgs::minimize(&mut merit, &y0, &settings)
}

/// The state of one start's augmented Lagrangian, carried from phase A into phase B.
struct Lagrangian<'a, P: Problem> {
    problem: &'a P,
    transform: &'a Transform,
    opts: &'a Options,
    counter: &'a Cell<usize>,
    y: Vec<f64>,
    lambda: Vec<f64>,
    mu: f64,
    eval: Evaluation,
    evaluations: usize,
}

impl<P: Problem> Lagrangian<'_, P> {
    /// Outer iterations; with `robust`, its terms join the merit and a feasible point that
    /// meets the target must also pass [`Robust::accept`]. Returns whether it did.
    fn run(&mut self, robust: Option<&dyn Robust>, max_outer: usize, max_inner: u64) -> bool {
        let opts = self.opts;
        let n = self.y.len();
        let mut prev_violation = f64::INFINITY;
        let mut prev_f = f64::INFINITY;
        // Phase B gives up on a start that stalls: infeasible with a violation that no
        // longer shrinks under a stiff penalty, or feasible at a local minimum short of the
        // target.
        let mut history: Vec<(f64, f64)> = Vec::new();
        for outer in 0..max_outer {
            let merit = Merit::new(
                self.problem,
                robust,
                self.transform,
                &self.lambda,
                self.mu,
                n,
                self.counter,
            );
            let mut yz = self.y.clone();
            if let Some(r) = robust {
                yz.extend(r.variables());
            }
            let yz = lbfgs(merit, yz, max_inner, opts);
            self.y = yz[..n].to_vec();
            if let Some(r) = robust {
                r.set_variables(&yz[n..]);
            }
            let x = self.transform.x(&self.y);
            self.problem.eval(&x, &mut self.eval);
            self.evaluations += 1;
            let mut violation = self.eval.violation();
            for (l, g) in self.lambda.iter_mut().zip(&self.eval.g) {
                *l = (*l - self.mu * g).max(0.0);
            }
            if let Some(r) = robust {
                violation = violation.max(r.update(&x, Some(self.mu)));
            }
            let f = self.eval.f;
            if violation <= opts.feasibility_tol {
                // With `all_starts` a start keeps improving its objective: it is judged
                // (and the block asked) once it has converged or its iterations end.
                let settled = !opts.all_starts
                    || outer + 1 == max_outer
                    || (f - prev_f).abs() <= opts.rel_tol * (1.0 + f.abs());
                if settled && opts.target.is_some_and(|t| f <= t) {
                    let acc = robust.map(|r| r.accept(&x));
                    match acc {
                        None | Some(Acceptance::Accepted) => return true,
                        Some(Acceptance::Rejected) => return false,
                        // States were added: keep going with them.
                        Some(Acceptance::Refined) => {
                            prev_violation = f64::INFINITY;
                            prev_f = f;
                            continue;
                        }
                    }
                }
                // Converged: feasible, and the last outer step no longer moves f.
                if (f - prev_f).abs() <= opts.rel_tol * (1.0 + f.abs()) {
                    break;
                }
            } else if violation > 0.25 * prev_violation {
                self.mu = (self.mu * 10.0).min(1e9);
            }
            if robust.is_some() {
                history.push((f, violation));
                let k = history.len();
                let far = opts.target.is_some_and(|t| f > 1e4 * t.max(1e-300));
                // A plateau short of the target (feasible or not): f has not improved by
                // a tenth over two outer iterations.
                if far && k >= 3 && f >= 0.9 * history[k - 3].0 {
                    return false;
                }
                // Infeasible, and the violation no longer shrinks.
                if violation > opts.feasibility_tol && k >= 4 && violation > 0.9 * history[k - 4].1
                {
                    return false;
                }
            }
            prev_violation = violation;
            prev_f = f;
        }
        false
    }
}

/// The phase-A outcome of one start: where the augmented Lagrangian ended.
#[derive(Clone, Debug)]
struct PhaseA {
    y: Vec<f64>,
    lambda: Vec<f64>,
    mu: f64,
    met: bool,
    /// Evaluations it took: a replay counts them too, so a record does not depend on which
    /// member ran first (or on what a resumed run had already done).
    evaluations: usize,
}

/// The phase-A outcomes of the starts of problems that are the same function with the same
/// [`Options`] (issue 14: the alternatives of a model whose differing modes reach no
/// output). The first problem to run a start records it; the others replay it, so their
/// solutions are those they would compute themselves, without computing them (their
/// [`Solution::evaluations`] still count the replayed ones). Phase B ([`Robust`]) is each
/// problem's own.
#[derive(Debug)]
pub struct SharedStarts {
    /// The seed of the starting points the outcomes belong to; problems of another seed
    /// neither read nor write.
    seed: u64,
    starts: RefCell<Vec<Option<PhaseA>>>,
    replayed: Cell<usize>,
}

impl SharedStarts {
    /// Empty, for problems optimized with `Options::seed == seed`.
    pub fn new(seed: u64) -> SharedStarts {
        SharedStarts {
            seed,
            starts: RefCell::new(Vec::new()),
            replayed: Cell::new(0),
        }
    }

    /// The seed the outcomes belong to.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Starts replayed so far instead of computed.
    pub fn replayed(&self) -> usize {
        self.replayed.get()
    }

    fn get(&self, opts: &Options, start: usize) -> Option<PhaseA> {
        if opts.seed != self.seed {
            return None;
        }
        let a = self.starts.borrow().get(start).cloned().flatten();
        if a.is_some() {
            self.replayed.set(self.replayed.get() + 1);
        }
        a
    }

    fn put(&self, opts: &Options, start: usize, a: PhaseA) {
        if opts.seed != self.seed {
            return;
        }
        let mut s = self.starts.borrow_mut();
        if s.len() <= start {
            s.resize(start + 1, None);
        }
        s[start] = Some(a);
    }
}

/// Whether [`Options::give_up_after`] stops a problem after `starts_run` starts whose
/// best feasible objective is `best_feasible_f` (infinite when none was feasible).
pub fn gives_up(opts: &Options, starts_run: usize, best_feasible_f: f64) -> bool {
    if opts.all_starts {
        return false;
    }
    match opts.target {
        Some(t) if t > 0.0 && opts.give_up_after > 0 && starts_run >= opts.give_up_after => {
            // Never NaN: only finite objectives count as feasible, and `max` drops a NaN factor.
            best_feasible_f > opts.give_up_factor.max(1.0) * t
        }
        _ => false,
    }
}

/// The starting points [`minimize`] runs `problem` from with `opts`, in order (for a peer
/// solver to start from the same points).
pub fn start_points<P: Problem>(problem: &P, opts: &Options) -> Vec<Vec<f64>> {
    let n = problem.n_vars();
    let (lo, hi): (Vec<f64>, Vec<f64>) = (0..n).map(|i| problem.bounds(i)).unzip();
    let transform = Transform { lo, hi };
    quasi_random_points(n, opts.starts, opts.seed)
        .iter()
        .map(|u| transform.start(u))
        .collect()
}

/// Minimize `problem` from many starts (see the module docs).
pub fn minimize<P: Problem>(problem: &P, opts: &Options) -> Solution {
    minimize_robust(problem, None, opts)
}

/// Minimize `problem` from many starts with an optional [`Robust`] block (phase B, see the
/// module docs). Without the block this is [`minimize`].
pub fn minimize_robust<P: Problem>(
    problem: &P,
    robust: Option<&dyn Robust>,
    opts: &Options,
) -> Solution {
    minimize_shared(problem, robust, opts, None)
}

/// [`minimize_robust`] replaying and recording the starts' phase A in `shared` (see
/// [`SharedStarts`]): the caller vouches that every problem given the same `shared` is
/// the same function.
pub fn minimize_shared<P: Problem>(
    problem: &P,
    robust: Option<&dyn Robust>,
    opts: &Options,
    shared: Option<&SharedStarts>,
) -> Solution {
    let (n, m) = (problem.n_vars(), problem.n_constraints());
    let (lo, hi): (Vec<f64>, Vec<f64>) = (0..n).map(|i| problem.bounds(i)).unzip();
    let transform = Transform { lo, hi };
    let mut best: Option<Solution> = None;
    let counter = Cell::new(0usize);
    let mut evaluations = 0;
    let mut attempts = 0;
    let fresh = quasi_random_points(n, opts.starts, opts.seed)
        .into_iter()
        .map(|u| (transform.start(&u), false));
    let warm = opts.warm_starts.iter().map(|x| (transform.inside(x), true));
    // Best feasible phase-A objective so far, for the give-up rule.
    let mut best_feasible_f = f64::INFINITY;
    let mut starts_run = 0;
    let mut replayed_evaluations = 0;
    let mut gave_up = false;
    for (start, (x0, is_warm)) in fresh.chain(warm).enumerate() {
        if gave_up && !is_warm {
            continue;
        }
        starts_run += 1;
        // Warm starts are this problem's own: no class shares them.
        let shared = if is_warm { None } else { shared };
        let mut al = Lagrangian {
            problem,
            transform: &transform,
            opts,
            counter: &counter,
            y: transform.y(&x0),
            lambda: vec![0.0; m],
            mu: 10.0,
            eval: Evaluation::new(n, m),
            evaluations: 0,
        };
        let met_a = al.phase_a(shared, start, &mut replayed_evaluations);
        let (robust_ok, robust_violation) = match robust {
            Some(r) if met_a => {
                let (ok, violation) = al.phase_b(r, &mut attempts);
                (Some(ok), Some(violation))
            }
            _ => (None, None),
        };
        evaluations += al.evaluations;
        let x = transform.x(&al.y);
        problem.eval(&x, &mut al.eval);
        evaluations += 1;
        let eval = &al.eval;
        let violation = eval.violation();
        let feasible = violation <= opts.feasibility_tol && eval.f.is_finite();
        let met = feasible && opts.target.is_some_and(|t| eval.f <= t);
        if feasible {
            best_feasible_f = best_feasible_f.min(eval.f);
        }
        let candidate = Solution {
            x,
            f: eval.f,
            g: eval.g.clone(),
            violation,
            feasible,
            met_target: met,
            robust: robust.map(|_| met && robust_ok == Some(true)),
            robust_violation,
            robust_attempts: 0,
            start,
            starts_run,
            evaluations,
            warm: is_warm,
        };
        if best.as_ref().is_none_or(|b| candidate.better_than(b)) {
            best = Some(candidate);
        }
        let done = match robust {
            None => met,
            Some(_) => met && robust_ok == Some(true),
        };
        if done && !opts.all_starts {
            break;
        }
        gave_up = gave_up || (!is_warm && gives_up(opts, start + 1, best_feasible_f));
    }
    let mut best = best.expect("at least one start");
    let done = best.met_target && best.robust != Some(false) && !opts.all_starts;
    best.starts_run = if done { best.starts_run } else { starts_run };
    best.evaluations = evaluations + counter.get() + replayed_evaluations;
    best.robust_attempts = attempts;
    best
}

impl Solution {
    /// Whether this start's solution beats `b`: robust first, then meeting the target, then
    /// feasible; among equals the lower objective (feasible) or violation (not).
    fn better_than(&self, b: &Solution) -> bool {
        let rank = |s: &Solution| (s.robust == Some(true), s.met_target, s.feasible);
        match rank(self).cmp(&rank(b)) {
            std::cmp::Ordering::Greater => true,
            std::cmp::Ordering::Less => false,
            std::cmp::Ordering::Equal => {
                if self.feasible {
                    self.f < b.f
                } else {
                    self.violation < b.violation
                }
            }
        }
    }
}

impl<P: Problem> Lagrangian<'_, P> {
    /// Phase A of start `start`: replayed from `shared` when it holds it (adding the
    /// evaluations it stands for to `replayed`), else run (and recorded there). Returns
    /// whether it met the target.
    fn phase_a(
        &mut self,
        shared: Option<&SharedStarts>,
        start: usize,
        replayed: &mut usize,
    ) -> bool {
        let opts = self.opts;
        match shared.and_then(|s| s.get(opts, start)) {
            Some(a) => {
                (self.y, self.lambda, self.mu) = (a.y, a.lambda, a.mu);
                *replayed += a.evaluations;
                a.met
            }
            None => {
                let before = self.counter.get();
                let met = self.run(None, opts.max_outer, opts.max_inner);
                if let Some(s) = shared {
                    let a = PhaseA {
                        y: self.y.clone(),
                        lambda: self.lambda.clone(),
                        mu: self.mu,
                        met,
                        evaluations: self.evaluations + self.counter.get() - before,
                    };
                    s.put(opts, start, a);
                }
                met
            }
        }
    }

    /// Phase B after a phase A that met the target: whether the block accepts the point
    /// (after optimizing with its constraints, if it refined and `attempts` is below
    /// [`Options::robust_starts`]; counted there), and the block's violation at the end.
    fn phase_b(&mut self, r: &dyn Robust, attempts: &mut usize) -> (bool, f64) {
        let opts = self.opts;
        r.reset();
        let x = self.transform.x(&self.y);
        let v = r.update(&x, None);
        let first = if v <= opts.feasibility_tol {
            r.accept(&x)
        } else {
            Acceptance::Refined
        };
        let mut ok = first == Acceptance::Accepted;
        // With `all_starts` every start is a candidate optimum of its own (an area has no
        // natural zero), so each gets its phase B: the Sec. 3.4 flasher's only designs
        // inside the cuboid at N = 2 came from its 5th to 16th starts.
        let limit = if opts.all_starts {
            usize::MAX
        } else {
            opts.robust_starts
        };
        if first == Acceptance::Refined && *attempts < limit {
            *attempts += 1;
            // Phase B: the block's constraints join, warm-started from phase A's optimum
            // with its multipliers; μ restarts low so the new terms are not ill-conditioned.
            self.mu = 10.0;
            ok = self.run(Some(r), opts.robust_outer, opts.robust_inner);
        }
        let x = self.transform.x(&self.y);
        (ok, r.update(&x, None))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rosenbrock inside a disk: min (1−x)² + 100(y−x²)² s.t. x² + y² ≤ 1.5 in [-2, 2]².
    /// The unconstrained optimum (1, 1) lies outside, so the optimum is on the circle.
    struct DiskRosenbrock;

    impl Problem for DiskRosenbrock {
        fn n_vars(&self) -> usize {
            2
        }
        fn n_constraints(&self) -> usize {
            1
        }
        fn bounds(&self, _: usize) -> (f64, f64) {
            (-2.0, 2.0)
        }
        fn eval(&self, x: &[f64], out: &mut Evaluation) {
            let (a, b) = (x[0], x[1]);
            out.f = (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2);
            out.df[0] = -2.0 * (1.0 - a) - 400.0 * a * (b - a * a);
            out.df[1] = 200.0 * (b - a * a);
            out.g[0] = 1.5 - a * a - b * b;
            out.dg[0] = -2.0 * a;
            out.dg[1] = -2.0 * b;
        }
    }

    #[test]
    fn finds_the_constrained_rosenbrock_optimum_on_the_circle() {
        let s = minimize(
            &DiskRosenbrock,
            &Options {
                starts: 4,
                ..Options::default()
            },
        );
        assert!(s.feasible, "{s:?}");
        // KKT for min f s.t. g ≥ 0: ∇f = ν ∇g with ν ≥ 0.
        let (a, b) = (s.x[0], s.x[1]);
        assert!((a * a + b * b - 1.5).abs() < 1e-7, "{s:?}");
        let df = [
            -2.0 * (1.0 - a) - 400.0 * a * (b - a * a),
            200.0 * (b - a * a),
        ];
        let dg = [-2.0 * a, -2.0 * b];
        let nu = (df[0] * dg[0] + df[1] * dg[1]) / (dg[0] * dg[0] + dg[1] * dg[1]);
        assert!(nu > 0.0, "{s:?}");
        let res = ((df[0] - nu * dg[0]).powi(2) + (df[1] - nu * dg[1]).powi(2)).sqrt();
        assert!(res < 1e-5, "KKT residual {res} at {s:?}");
    }

    #[test]
    fn shared_starts_replay_the_same_solution_without_evaluating() {
        let opts = Options {
            starts: 5,
            seed: 3,
            ..Options::default()
        };
        let alone = minimize(&DiskRosenbrock, &opts);
        let shared = SharedStarts::new(3);
        let first = minimize_shared(&DiskRosenbrock, None, &opts, Some(&shared));
        let second = minimize_shared(&DiskRosenbrock, None, &opts, Some(&shared));
        for s in [&first, &second] {
            assert_eq!(s.x, alone.x);
            assert_eq!(s.f.to_bits(), alone.f.to_bits());
            assert_eq!(s.starts_run, alone.starts_run);
        }
        // The replay counts the evaluations it stands for.
        assert_eq!(first.evaluations, alone.evaluations);
        assert_eq!(second.evaluations, alone.evaluations);
        assert_eq!(shared.replayed(), second.starts_run);
        // Another seed neither reads nor writes the outcomes.
        let other = Options { seed: 4, ..opts };
        minimize_shared(&DiskRosenbrock, None, &other, Some(&shared));
        assert_eq!(shared.replayed(), second.starts_run);
    }

    #[test]
    fn same_seed_same_points_and_they_fill_the_cube() {
        let a = quasi_random_points(5, 64, 7);
        assert_eq!(a, quasi_random_points(5, 64, 7));
        assert_ne!(a, quasi_random_points(5, 64, 8));
        for d in 0..5 {
            // Stratified: each eighth of every coordinate holds 8 ± 2 of the 64 points
            // (independent uniform points stray by ±2.6 at one standard deviation).
            let mut bins = [0; 8];
            for p in &a {
                bins[(p[d] * 8.0) as usize] += 1;
            }
            assert!(
                bins.iter().all(|b| (6..=10).contains(b)),
                "dimension {d}: {bins:?}"
            );
        }
    }

    /// A double well on [-2, 2]: `(x² − 1)² + (1 − x)/2`, with a local minimum f ≈ 0.98 near
    /// x = −0.93 and the global one f ≈ −0.015 near x = 1.06.
    struct DoubleWell;

    impl Problem for DoubleWell {
        fn n_vars(&self) -> usize {
            1
        }
        fn n_constraints(&self) -> usize {
            0
        }
        fn bounds(&self, _: usize) -> (f64, f64) {
            (-2.0, 2.0)
        }
        fn eval(&self, x: &[f64], out: &mut Evaluation) {
            let x = x[0];
            out.f = (x * x - 1.0).powi(2) + 0.5 * (1.0 - x);
            out.df[0] = 4.0 * x * (x * x - 1.0) - 0.5;
        }
    }

    /// A bowl whose minimum, 10 at x = 1, lies far above any target below 2.5.
    struct HighBowl;

    impl Problem for HighBowl {
        fn n_vars(&self) -> usize {
            1
        }
        fn n_constraints(&self) -> usize {
            0
        }
        fn bounds(&self, _: usize) -> (f64, f64) {
            (-2.0, 2.0)
        }
        fn eval(&self, x: &[f64], out: &mut Evaluation) {
            out.f = 10.0 + (x[0] - 1.0).powi(2);
            out.df[0] = 2.0 * (x[0] - 1.0);
        }
    }

    #[test]
    fn gives_up_after_k_starts_far_above_the_target_and_not_within_the_factor() {
        let opts = |after, factor| Options {
            starts: 12,
            target: Some(1.0),
            give_up_after: after,
            give_up_factor: factor,
            ..Options::default()
        };
        // min f = 10: more than 4 × the target, so 3 starts and no more.
        let s = minimize(&HighBowl, &opts(3, 4.0));
        assert!(s.feasible && !s.met_target, "{s:?}");
        assert_eq!(s.starts_run, 3, "{s:?}");
        assert!((s.f - 10.0).abs() < 1e-9, "{s:?}");
        // Within the factor (10 ≤ 20 × 1): every start runs.
        assert_eq!(minimize(&HighBowl, &opts(3, 20.0)).starts_run, 12);
        // The rule off: every start runs.
        assert_eq!(minimize(&HighBowl, &opts(0, 4.0)).starts_run, 12);
    }

    #[test]
    fn a_start_after_k_still_runs_when_the_early_ones_are_within_the_factor() {
        let opts = |seed, after, factor| Options {
            starts: 16,
            seed,
            target: Some(0.5),
            give_up_after: after,
            give_up_factor: factor,
            ..Options::default()
        };
        // A seed whose first start to meet the target (the global well) is the third or later:
        // the starts before it ended in the local well, f ≈ 0.98.
        let (seed, k) = (0..200)
            .find_map(|seed| {
                let s = minimize(&DoubleWell, &opts(seed, 0, 1.0));
                (s.met_target && s.start >= 2).then_some((seed, s.start))
            })
            .expect("some seed starts in the local well twice");
        // 0.98 ≤ 4 × 0.5: start k + 1 runs and meets the target.
        let s = minimize(&DoubleWell, &opts(seed, k, 4.0));
        assert!(s.met_target, "{s:?}");
        assert_eq!((s.start, s.starts_run), (k, k + 1), "{s:?}");
        // 0.98 > 1.5 × 0.5: after k starts it gives up, at the local minimum.
        let s = minimize(&DoubleWell, &opts(seed, k, 1.5));
        assert!(s.feasible && !s.met_target, "{s:?}");
        assert_eq!(s.starts_run, k, "{s:?}");
        assert!((s.f - 0.98).abs() < 0.01, "{s:?}");
    }
}
