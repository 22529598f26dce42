//! Bounded, constrained, multi-start gradient optimization.
//!
//! `min f(x)` subject to `g(x) ≥ 0` and `lo ≤ x ≤ hi`:
//! - bounds by the smooth transform `x = lo + (hi − lo)(1 + sin y)/2` (y unbounded);
//! - inequality constraints by an augmented Lagrangian (Powell–Hestenes–Rockafellar):
//!   `L = f + Σ (max(0, λ_k − μ g_k)² − λ_k²) / 2μ`, multipliers updated
//!   `λ_k ← max(0, λ_k − μ g_k)`, μ raised while the violation does not shrink;
//! - each subproblem by argmin's L-BFGS with a Moré–Thuente line search;
//! - many deterministic starts from a randomly shifted Halton sequence across the box,
//!   stopping early once a start meets the target feasibly.
//!
//! The optimizer sees the problem only through [`Problem::eval`] (objective, constraints
//! and their gradients in one call), i.e. the compiled model.

use argmin::core::{CostFunction, Error, Executor, Gradient, State};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::quasinewton::LBFGS;
use rand::{RngExt, SeedableRng};
use serde::Serialize;
use std::cell::{Cell, RefCell};

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
}

impl Default for Options {
    fn default() -> Self {
        Options {
            starts: 16,
            seed: 0,
            max_outer: 12,
            max_inner: 200,
            feasibility_tol: 1e-9,
            target: None,
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
    /// Which start produced it.
    pub start: usize,
    /// Starts run.
    pub starts_run: usize,
    /// Problem evaluations spent.
    pub evaluations: usize,
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
    fn x(&self, y: &[f64]) -> Vec<f64> {
        y.iter()
            .enumerate()
            .map(|(i, y)| self.lo[i] + (self.hi[i] - self.lo[i]) * 0.5 * (1.0 + y.sin()))
            .collect()
    }
    fn dx_dy(&self, y: &[f64]) -> Vec<f64> {
        y.iter()
            .enumerate()
            .map(|(i, y)| (self.hi[i] - self.lo[i]) * 0.5 * y.cos())
            .collect()
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

/// The augmented Lagrangian of one subproblem, as argmin sees it.
struct Merit<'a, P: Problem> {
    problem: &'a P,
    transform: &'a Transform,
    lambda: &'a [f64],
    mu: f64,
    cache: RefCell<(Vec<f64>, f64, Vec<f64>)>,
    work: RefCell<Evaluation>,
    evaluations: &'a Cell<usize>,
}

impl<P: Problem> Merit<'_, P> {
    fn compute(&self, y: &[f64]) -> (f64, Vec<f64>) {
        {
            let c = self.cache.borrow();
            if c.0 == y {
                return (c.1, c.2.clone());
            }
        }
        let x = self.transform.x(y);
        let mut e = self.work.borrow_mut();
        self.problem.eval(&x, &mut e);
        self.evaluations.set(self.evaluations.get() + 1);
        let n = x.len();
        let mut value = e.f;
        let mut grad = e.df.clone();
        for (k, g) in e.g.iter().enumerate() {
            let a = (self.lambda[k] - self.mu * g).max(0.0);
            value += (a * a - self.lambda[k] * self.lambda[k]) / (2.0 * self.mu);
            if a > 0.0 {
                for (j, gj) in grad.iter_mut().enumerate() {
                    *gj -= a * e.dg[k * n + j];
                }
            }
        }
        let dxdy = self.transform.dx_dy(y);
        for (g, d) in grad.iter_mut().zip(&dxdy) {
            *g *= d;
        }
        if !value.is_finite() || grad.iter().any(|g| !g.is_finite()) {
            // Outside where the model is defined: a wall the line search backs off from.
            value = 1e30;
            grad.iter_mut().for_each(|g| *g = 0.0);
        }
        *self.cache.borrow_mut() = (y.to_vec(), value, grad.clone());
        (value, grad)
    }
}

impl<P: Problem> CostFunction for Merit<'_, P> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, y: &Vec<f64>) -> Result<f64, Error> {
        Ok(self.compute(y).0)
    }
}

impl<P: Problem> Gradient for Merit<'_, P> {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;
    fn gradient(&self, y: &Vec<f64>) -> Result<Vec<f64>, Error> {
        Ok(self.compute(y).1)
    }
}

/// Minimize the merit from `y0` with L-BFGS; returns the best point (or `y0`).
fn lbfgs<P: Problem>(merit: Merit<'_, P>, y0: Vec<f64>, max_iters: u64) -> Vec<f64> {
    let solver = LBFGS::new(MoreThuenteLineSearch::new(), 8)
        .with_tolerance_grad(1e-12)
        .and_then(|s| s.with_tolerance_cost(1e-16));
    let Ok(solver) = solver else { return y0 };
    match Executor::new(merit, solver)
        .configure(|s| s.param(y0.clone()).max_iters(max_iters))
        .run()
    {
        Ok(res) => res.state().get_best_param().cloned().unwrap_or(y0),
        // A failed line search leaves the start point; the outer loop moves on.
        Err(_) => y0,
    }
}

/// Minimize `problem` from many starts (see the module docs).
pub fn minimize<P: Problem>(problem: &P, opts: &Options) -> Solution {
    let (n, m) = (problem.n_vars(), problem.n_constraints());
    let (lo, hi): (Vec<f64>, Vec<f64>) = (0..n).map(|i| problem.bounds(i)).unzip();
    let transform = Transform { lo, hi };
    let mut eval = Evaluation::new(n, m);
    let mut best: Option<Solution> = None;
    let counter = Cell::new(0usize);
    let mut evaluations = 0;
    let points = quasi_random_points(n, opts.starts, opts.seed);
    for (start, u) in points.iter().enumerate() {
        // Starting points stay off the bounds, where the transform's slope vanishes.
        let x0: Vec<f64> = u
            .iter()
            .enumerate()
            .map(|(i, u)| {
                let (l, h) = (transform.lo[i], transform.hi[i]);
                l + (h - l) * (0.02 + 0.96 * u)
            })
            .collect();
        let mut y = transform.y(&x0);
        let mut lambda = vec![0.0; m];
        let mut mu = 10.0;
        let mut prev_violation = f64::INFINITY;
        for _ in 0..opts.max_outer {
            let merit = Merit {
                problem,
                transform: &transform,
                lambda: &lambda,
                mu,
                cache: RefCell::new((Vec::new(), 0.0, Vec::new())),
                work: RefCell::new(Evaluation::new(n, m)),
                evaluations: &counter,
            };
            y = lbfgs(merit, y.clone(), opts.max_inner);
            problem.eval(&transform.x(&y), &mut eval);
            evaluations += 1;
            let violation = eval.violation();
            for (l, g) in lambda.iter_mut().zip(&eval.g) {
                *l = (*l - mu * g).max(0.0);
            }
            if violation <= opts.feasibility_tol {
                if opts.target.is_some_and(|t| eval.f <= t) {
                    break;
                }
                if violation == 0.0
                    && lambda.iter().all(|l| *l == 0.0)
                    && prev_violation <= opts.feasibility_tol
                {
                    break;
                }
            } else if violation > 0.25 * prev_violation {
                mu = (mu * 10.0).min(1e9);
            }
            prev_violation = violation;
        }
        let x = transform.x(&y);
        problem.eval(&x, &mut eval);
        evaluations += 1;
        let violation = eval.violation();
        let feasible = violation <= opts.feasibility_tol && eval.f.is_finite();
        let met = feasible && opts.target.is_some_and(|t| eval.f <= t);
        let candidate = Solution {
            x,
            f: eval.f,
            g: eval.g.clone(),
            violation,
            feasible,
            met_target: met,
            start,
            starts_run: start + 1,
            evaluations,
        };
        let better = match &best {
            None => true,
            Some(b) => match (candidate.feasible, b.feasible) {
                (true, false) => true,
                (false, true) => false,
                (true, true) => candidate.f < b.f,
                (false, false) => candidate.violation < b.violation,
            },
        };
        if better {
            best = Some(candidate);
        }
        if met {
            break;
        }
    }
    let mut best = best.expect("at least one start");
    best.starts_run = if best.met_target {
        best.start + 1
    } else {
        points.len()
    };
    best.evaluations = evaluations + counter.get();
    best
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
}
