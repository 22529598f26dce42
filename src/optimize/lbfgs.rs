//! L-BFGS with the Moré–Thuente line search, for the augmented-Lagrangian subproblems.
//!
//! The arithmetic is argmin 0.11's `LBFGS` with `MoreThuenteLineSearch` (memory 8, c1 = 1e-4,
//! c2 = 0.9, the same termination tests), operation for operation, so every iterate and
//! every evaluation is the one argmin computes (`tests::same_iterates_as_argmin` checks it
//! bit for bit). What differs is the cost around it (issue 14): argmin allocates a vector
//! for every vector operation, builds an executor with its own state and a hash map of
//! call counts for every line search, and asks for the cost and the gradient in separate
//! calls; here the buffers are allocated once per subproblem and one call returns both.
//! On the robotic arm that bookkeeping was about a tenth of the search's CPU time.

use std::collections::VecDeque;

/// A smooth function as the subproblems see it.
pub(super) trait Smooth {
    /// The value at `y`, with its gradient written into `grad` (same length as `y`).
    fn eval(&mut self, y: &[f64], grad: &mut [f64]) -> f64;
}

/// When L-BFGS stops (argmin's `with_tolerance_grad`, `with_tolerance_cost`, `max_iters`).
#[derive(Clone, Copy, Debug)]
pub(super) struct Settings {
    /// Stored correction pairs.
    pub memory: usize,
    /// Iterations at most.
    pub max_iters: u64,
    /// Stop when the gradient's Euclidean norm is below this.
    pub tol_grad: f64,
    /// Stop when an iteration changes the value by less than this (absolute).
    pub tol_cost: f64,
    /// Stop when the last `stall_window` iterations together lowered the value by less
    /// than [`Settings::stall_tol`]: a run creeping along a kink or a bound (issue 14).
    /// 0: no such test, as in argmin; the iterates up to the stop are the same either way.
    pub stall_window: usize,
    /// See [`Settings::stall_window`] (absolute, like `tol_cost`).
    pub stall_tol: f64,
}

/// `Σ a_i b_i`, summed in order as argmin-math sums.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

/// Minimize `f` from `y0`; returns the point of lowest value seen at the end of an
/// iteration (argmin's best parameter).
pub(super) fn minimize(f: &mut impl Smooth, y0: &[f64], s: &Settings) -> Vec<f64> {
    let n = y0.len();
    let mut param = y0.to_vec();
    let mut grad = vec![0.0; n];
    let mut cost = f.eval(&param, &mut grad);
    let mut prev_cost = f64::INFINITY;
    let mut best = param.clone();
    let mut best_cost = cost;
    // (s, y, yᵀs, yᵀy): dot products argmin recomputes every iteration, computed once
    // when the pair is stored (the same bits: each product commutes, the order is kept).
    let mut pairs: VecDeque<(Vec<f64>, Vec<f64>, f64, f64)> = VecDeque::with_capacity(s.memory);
    let (mut q, mut d) = (vec![0.0; n], vec![0.0; n]);
    let (mut alpha, mut rho) = (vec![0.0; s.memory + 1], vec![0.0; s.memory + 1]);
    let (mut x1, mut g1) = (vec![0.0; n], vec![0.0; n]);
    let mut iter = 0u64;
    // The values at the last `stall_window + 1` iterates, a ring indexed by iteration.
    let mut recent = vec![0.0; s.stall_window + 1];
    loop {
        if s.stall_window > 0 {
            let (k, len) = (iter as usize, recent.len());
            recent[k % len] = cost;
            if k >= s.stall_window && recent[(k + 1) % len] - cost < s.stall_tol {
                break;
            }
        }
        // argmin's termination order: the solver's tests, then the iteration cap.
        let norm = grad.iter().map(|a| a.powi(2)).sum::<f64>().sqrt();
        if norm < s.tol_grad || (prev_cost - cost).abs() < s.tol_cost || iter >= s.max_iters {
            break;
        }
        // The two-loop recursion.
        let gamma = match pairs.back() {
            Some((_, _, sy, yy)) => sy / yy,
            None => 1.0,
        };
        q.copy_from_slice(&grad);
        let m = pairs.len();
        for (i, (sk, yk, sy, _)) in pairs.iter().rev().enumerate() {
            let rho_t = 1.0 / sy;
            let alpha_t = dot(sk, &q) * rho_t;
            for (qj, y) in q.iter_mut().zip(yk) {
                *qj -= y * alpha_t;
            }
            rho[m - i - 1] = rho_t;
            alpha[m - i - 1] = alpha_t;
        }
        for qj in q.iter_mut() {
            *qj *= gamma;
        }
        for (i, (sk, yk, _, _)) in pairs.iter().enumerate() {
            let beta = dot(yk, &q) * rho[i];
            for (r, s) in q.iter_mut().zip(sk) {
                *r += s * (alpha[i] - beta);
            }
        }
        for (dj, r) in d.iter_mut().zip(&q) {
            *dj = r * -1.0;
        }
        let Some(next_cost) = more_thuente(f, &param, cost, &grad, &d, &mut x1, &mut g1) else {
            // Not a descent direction, or the line search met a NaN: argmin stops here.
            break;
        };
        // The oldest pair's buffers are reused once the memory is full (argmin: from
        // iteration `memory` on, which keeps one pair even at memory 0).
        let recycled = if pairs.len() >= s.memory {
            pairs.pop_front()
        } else {
            None
        };
        let (mut sk, mut yk, ..) =
            recycled.unwrap_or_else(|| (vec![0.0; n], vec![0.0; n], 0.0, 0.0));
        for j in 0..n {
            sk[j] = x1[j] - param[j];
            yk[j] = g1[j] - grad[j];
        }
        let (sy, yy) = (dot(yk.as_slice(), &sk), dot(&yk, &yk));
        pairs.push_back((sk, yk, sy, yy));
        std::mem::swap(&mut param, &mut x1);
        std::mem::swap(&mut grad, &mut g1);
        prev_cost = cost;
        cost = next_cost;
        if cost < best_cost {
            best.copy_from_slice(&param);
            best_cost = cost;
        }
        iter += 1;
    }
    best
}

/// A trial step: its length, value and directional derivative.
#[derive(Clone, Copy)]
struct Step {
    x: f64,
    fx: f64,
    gx: f64,
}

impl Step {
    fn new(x: f64, fx: f64, gx: f64) -> Step {
        Step { x, fx, gx }
    }
}

const FTOL: f64 = 1e-4;
const GTOL: f64 = 0.9;
const XTRAPF: f64 = 4.0;
const XTOL: f64 = 1e-10;

/// The Moré–Thuente line search from `x0` (value `f0`, gradient `g0`) along `d`, as argmin
/// 0.11 runs it (initial step 1, no evaluation cap). The accepted point goes into `x`, its
/// gradient into `g`; `None` when `d` is not a descent direction or the step's cubic model
/// meets a NaN (argmin's errors).
fn more_thuente(
    f: &mut impl Smooth,
    x0: &[f64],
    f0: f64,
    g0: &[f64],
    d: &[f64],
    x: &mut [f64],
    g: &mut [f64],
) -> Option<f64> {
    let (stpmin, stpmax) = (f64::EPSILON.sqrt(), f64::INFINITY);
    let dginit = dot(g0, d);
    if dginit >= 0.0 {
        return None;
    }
    let finit = f0;
    let mut stage1 = true;
    let mut brackt = false;
    let dgtest = FTOL * dginit;
    let mut width = stpmax - stpmin;
    let mut width1 = 2.0 * width;
    let mut stp = Step::new(1.0, f64::NAN, f64::NAN);
    let mut stx = Step::new(0.0, finit, dginit);
    let mut sty = Step::new(0.0, finit, dginit);
    let mut infoc = 1;
    loop {
        let (stmin, stmax) = if brackt {
            (stx.x.min(sty.x), stx.x.max(sty.x))
        } else {
            (stx.x, stp.x + XTRAPF * (stp.x - stx.x))
        };
        stp.x = stp.x.max(stpmin);
        stp.x = stp.x.min(stpmax);
        // An unusual termination: take the lowest point so far.
        if (brackt && (stp.x <= stmin || stp.x >= stmax || (stmax - stmin) <= XTOL * stmax))
            || infoc == 0
        {
            stp.x = stx.x;
        }
        for j in 0..x.len() {
            x[j] = x0[j] + d[j] * stp.x;
        }
        let fv = f.eval(x, g);
        let dg = dot(d, g);
        let ftest1 = finit + stp.x * dgtest;
        let done = ((brackt && (stp.x <= stmin || stp.x >= stmax)) || infoc == 0)
            || ((stp.x - stpmax).abs() < f64::EPSILON && fv <= ftest1 && dg <= dgtest)
            || ((stp.x - stpmin).abs() < f64::EPSILON && (fv > ftest1 || dg >= dgtest))
            || (brackt && stmax - stmin <= XTOL * stmax)
            || (fv <= ftest1 && dg.abs() <= GTOL * (-dginit));
        if done {
            return Some(fv);
        }
        if stage1 && fv <= ftest1 && dg >= FTOL.min(GTOL) * dginit {
            stage1 = false;
        }
        if stage1 && fv <= stp.fx && fv > ftest1 {
            // The modified function ψ(α) = φ(α) − φ(0) − c1 α φ'(0), as argmin writes it.
            let fm = fv - stp.x * dgtest;
            let fxm = stx.fx - stx.x * dgtest;
            let fym = sty.fx - sty.x * dgtest;
            let dgm = dg - dgtest;
            let dgxm = stx.gx - dgtest;
            let dgym = sty.gx - dgtest;
            let (stx1, sty1, stp1, brackt1, infoc1) = cstep(
                Step::new(stx.x, fxm, dgxm),
                Step::new(sty.x, fym, dgym),
                Step::new(stp.x, fm, dgm),
                brackt,
                stmin,
                stmax,
            )?;
            stx.x = stx1.x;
            sty.x = sty1.x;
            stx.fx += stx1.x * dgtest;
            sty.fx += sty1.x * dgtest;
            stx.gx += dgtest;
            sty.gx += dgtest;
            brackt = brackt1;
            stp = stp1;
            infoc = infoc1;
        } else {
            let (stx1, sty1, stp1, brackt1, infoc1) =
                cstep(stx, sty, Step::new(stp.x, fv, dg), brackt, stmin, stmax)?;
            stx = stx1;
            sty = sty1;
            stp = stp1;
            brackt = brackt1;
            infoc = infoc1;
        }
        if brackt {
            if (sty.x - stx.x).abs() >= 0.66 * width1 {
                stp.x = stx.x + 0.5 * (sty.x - stx.x);
            }
            width1 = width;
            width = (sty.x - stx.x).abs();
        }
    }
}

/// The scale of `cstep`'s cubic, the largest of `θ` and the two slopes as argmin takes it
/// (`Iterator::max_by`: the last of equals; not the largest magnitude, as in MINPACK);
/// `None` where one is NaN or infinite (argmin's error).
fn scale(v: [f64; 3]) -> Option<f64> {
    if v.iter().any(|n| n.is_nan() || n.is_infinite()) {
        return None;
    }
    let mut s = v[0];
    for &x in &v[1..] {
        if s <= x {
            s = x;
        }
    }
    Some(s)
}

/// One safeguarded step of the Moré–Thuente interval update (MINPACK's `dcstep` as argmin
/// 0.11 ports it). `None` where argmin reports a NaN or an infinity.
///
/// MINPACK writes it as one routine: the trial step from four cases (Moré and Thuente
/// 1994, Sec. 4), then the new interval of uncertainty. Here each case is a function of its
/// own, named by its condition, with the arithmetic of its branch unchanged (argmin's
/// operations in argmin's order); this function keeps the case analysis and the update, so
/// the published structure stays visible in one screen.
fn cstep(
    stx: Step,
    sty: Step,
    stp: Step,
    brackt: bool,
    stpmin: f64,
    stpmax: f64,
) -> Option<(Step, Step, Step, bool, usize)> {
    if (brackt && (stp.x <= stx.x.min(sty.x) || stp.x >= stx.x.max(sty.x)))
        || stx.gx * (stp.x - stx.x) >= 0.0
        || stpmax < stpmin
    {
        return Some((stx, sty, stp, brackt, 0));
    }
    let sgnd = stp.gx * (stx.gx / stx.gx.abs());
    // (info, whether the step is kept inside the interval, brackt, the trial step)
    let (info, bound, brackt, mut stpf) = if stp.fx > stx.fx {
        (1, true, true, higher_value(stx, stp)?)
    } else if sgnd < 0.0 {
        (2, false, true, slopes_of_opposite_sign(stx, stp)?)
    } else if stp.gx.abs() < stx.gx.abs() {
        let stpf = slope_shrinks(stx, stp, brackt, stpmin, stpmax)?;
        (3, true, brackt, stpf)
    } else {
        let stpf = slope_does_not_shrink(stx, sty, stp, brackt, stpmin, stpmax)?;
        (4, false, brackt, stpf)
    };
    // The new interval of uncertainty.
    let mut stx_o = stx;
    let mut sty_o = sty;
    let mut stp_o = stp;
    if stp_o.fx > stx_o.fx {
        sty_o = stp_o;
    } else {
        if sgnd < 0.0 {
            sty_o = stx_o;
        }
        stx_o = stp_o;
    }
    stpf = stpmax.min(stpf);
    stpf = stpmin.max(stpf);
    stp_o.x = stpf;
    if brackt && bound {
        if sty_o.x > stx_o.x {
            stp_o.x = stp_o.x.min(stx_o.x + 0.66 * (sty_o.x - stx_o.x));
        } else {
            stp_o.x = stp_o.x.max(stx_o.x + 0.66 * (sty_o.x - stx_o.x));
        }
    }
    Some((stx_o, sty_o, stp_o, brackt, info))
}

/// `cstep`'s first case, a higher value than at `stx`: the minimum is bracketed; the cubic
/// step if it is closer to `stx` than the quadratic one, else their midpoint.
fn higher_value(stx: Step, stp: Step) -> Option<f64> {
    let theta = 3.0 * (stx.fx - stp.fx) / (stp.x - stx.x) + stx.gx + stp.gx;
    let s = scale([theta, stx.gx, stp.gx])?;
    let mut gamma = s * ((theta / s).powi(2) - (stx.gx / s) * (stp.gx / s)).sqrt();
    if stp.x < stx.x {
        gamma = -gamma;
    }
    let p = (gamma - stx.gx) + theta;
    let q = ((gamma - stx.gx) + gamma) + stp.gx;
    let r = p / q;
    let stpc = stx.x + r * (stp.x - stx.x);
    let stpq =
        stx.x + ((stx.gx / ((stx.fx - stp.fx) / (stp.x - stx.x) + stx.gx)) / 2.0) * (stp.x - stx.x);
    Some(if (stpc - stx.x).abs() < (stpq - stx.x).abs() {
        stpc
    } else {
        stpc + (stpq - stpc) / 2.0
    })
}

/// `cstep`'s second case, a lower value and slopes of opposite sign: the minimum is
/// bracketed; the cubic step if it is farther from `stp` than the secant step, else that.
fn slopes_of_opposite_sign(stx: Step, stp: Step) -> Option<f64> {
    let theta = 3.0 * (stx.fx - stp.fx) / (stp.x - stx.x) + stx.gx + stp.gx;
    let s = scale([theta, stx.gx, stp.gx])?;
    let mut gamma = s * ((theta / s).powi(2) - (stx.gx / s) * (stp.gx / s)).sqrt();
    if stp.x > stx.x {
        gamma = -gamma;
    }
    let p = (gamma - stp.gx) + theta;
    let q = ((gamma - stp.gx) + gamma) + stx.gx;
    let r = p / q;
    let stpc = stp.x + r * (stx.x - stp.x);
    let stpq = stp.x + (stp.gx / (stp.gx - stx.gx)) * (stx.x - stp.x);
    Some(if (stpc - stp.x).abs() > (stpq - stp.x).abs() {
        stpc
    } else {
        stpq
    })
}

/// `cstep`'s third case, a lower value, slopes of the same sign, the slope's magnitude
/// shrinking: the cubic step only if the cubic tends to infinity in the step's direction
/// (else the bound), then the one closer to `stp` (bracketed) or farther (not).
fn slope_shrinks(stx: Step, stp: Step, brackt: bool, stpmin: f64, stpmax: f64) -> Option<f64> {
    let theta = 3.0 * (stx.fx - stp.fx) / (stp.x - stx.x) + stx.gx + stp.gx;
    let s = scale([theta, stx.gx, stp.gx])?;
    let mut gamma = s * 0.0f64
        .max((theta / s).powi(2) - (stx.gx / s) * (stp.gx / s))
        .sqrt();
    if stp.x > stx.x {
        gamma = -gamma;
    }
    let p = (gamma - stp.gx) + theta;
    let q = (gamma + (stx.gx - stp.gx)) + gamma;
    let r = p / q;
    let stpc = if r < 0.0 && gamma != 0.0 {
        stp.x + r * (stx.x - stp.x)
    } else if stp.x > stx.x {
        stpmax
    } else {
        stpmin
    };
    let stpq = stp.x + (stp.gx / (stp.gx - stx.gx)) * (stx.x - stp.x);
    Some(if brackt {
        if (stp.x - stpc).abs() < (stp.x - stpq).abs() {
            stpc
        } else {
            stpq
        }
    } else if (stp.x - stpc).abs() > (stp.x - stpq).abs() {
        stpc
    } else {
        stpq
    })
}

/// `cstep`'s fourth case, a lower value, slopes of the same sign, the slope's magnitude not
/// shrinking: the cubic step between `stp` and `sty` when bracketed, else a bound.
fn slope_does_not_shrink(
    stx: Step,
    sty: Step,
    stp: Step,
    brackt: bool,
    stpmin: f64,
    stpmax: f64,
) -> Option<f64> {
    Some(if brackt {
        let theta = 3.0 * (stp.fx - sty.fx) / (sty.x - stp.x) + sty.gx + stp.gx;
        let s = scale([theta, sty.gx, stp.gx])?;
        let mut gamma = s * ((theta / s).powi(2) - (sty.gx / s) * (stp.gx / s)).sqrt();
        if stp.x > sty.x {
            gamma = -gamma;
        }
        let p = (gamma - stp.gx) + theta;
        let q = ((gamma - stp.gx) + gamma) + sty.gx;
        let r = p / q;
        stp.x + r * (sty.x - stp.x)
    } else if stp.x > stx.x {
        stpmax
    } else {
        stpmin
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use argmin::core::{CostFunction, Error, Executor, Gradient, State};
    use argmin::solver::linesearch::MoreThuenteLineSearch;
    use argmin::solver::quasinewton::LBFGS;
    use std::cell::RefCell;

    /// A test function, with the points it was evaluated at (a point asked for again right
    /// after its evaluation is answered from a one-point cache, as the merit does).
    struct Recorded<F: Fn(&[f64], &mut [f64]) -> f64> {
        f: F,
        log: RefCell<Vec<Vec<f64>>>,
        last: RefCell<(Vec<f64>, f64, Vec<f64>)>,
    }

    impl<F: Fn(&[f64], &mut [f64]) -> f64> Recorded<F> {
        fn new(f: F) -> Self {
            Recorded {
                f,
                log: RefCell::new(Vec::new()),
                last: RefCell::new((Vec::new(), 0.0, Vec::new())),
            }
        }
        fn both(&self, y: &[f64]) -> (f64, Vec<f64>) {
            let mut last = self.last.borrow_mut();
            if last.0 != y {
                let mut g = vec![0.0; y.len()];
                let v = (self.f)(y, &mut g);
                *last = (y.to_vec(), v, g);
                self.log.borrow_mut().push(y.to_vec());
            }
            (last.1, last.2.clone())
        }
    }

    impl<F: Fn(&[f64], &mut [f64]) -> f64> Smooth for &Recorded<F> {
        fn eval(&mut self, y: &[f64], grad: &mut [f64]) -> f64 {
            let (v, g) = self.both(y);
            grad.copy_from_slice(&g);
            v
        }
    }

    impl<F: Fn(&[f64], &mut [f64]) -> f64> CostFunction for &Recorded<F> {
        type Param = Vec<f64>;
        type Output = f64;
        fn cost(&self, y: &Vec<f64>) -> Result<f64, Error> {
            Ok(self.both(y).0)
        }
    }

    impl<F: Fn(&[f64], &mut [f64]) -> f64> Gradient for &Recorded<F> {
        type Param = Vec<f64>;
        type Gradient = Vec<f64>;
        fn gradient(&self, y: &Vec<f64>) -> Result<Vec<f64>, Error> {
            Ok(self.both(y).1)
        }
    }

    /// Both implementations from `y0`: (best point, evaluated points) of ours, then argmin's.
    #[allow(clippy::type_complexity)]
    fn both_runs<F: Fn(&[f64], &mut [f64]) -> f64 + Copy>(
        f: F,
        y0: &[f64],
        s: &Settings,
    ) -> ((Vec<f64>, Vec<Vec<f64>>), (Vec<f64>, Vec<Vec<f64>>)) {
        let ours = Recorded::new(f);
        let best = minimize(&mut &ours, y0, s);
        let theirs = Recorded::new(f);
        let solver = LBFGS::new(MoreThuenteLineSearch::new(), s.memory)
            .with_tolerance_grad(s.tol_grad)
            .and_then(|l| l.with_tolerance_cost(s.tol_cost))
            .expect("valid tolerances");
        let res = Executor::new(&theirs, solver)
            .configure(|st| st.param(y0.to_vec()).max_iters(s.max_iters))
            .run()
            .expect("argmin runs");
        let their_best = res.state().get_best_param().cloned().expect("a best point");
        (
            (best, ours.log.into_inner()),
            (their_best, theirs.log.into_inner()),
        )
    }

    fn rosenbrock(y: &[f64], g: &mut [f64]) -> f64 {
        g.iter_mut().for_each(|g| *g = 0.0);
        let mut v = 0.0;
        for i in 0..y.len() - 1 {
            let (a, b) = (1.0 - y[i], y[i + 1] - y[i] * y[i]);
            v += a * a + 100.0 * b * b;
            g[i] += -2.0 * a - 400.0 * y[i] * b;
            g[i + 1] += 200.0 * b;
        }
        v
    }

    /// A steep exponential valley: first steps that overshoot by orders of magnitude.
    fn steep(y: &[f64], g: &mut [f64]) -> f64 {
        let e = (3.0 * y[0] + y[1]).exp();
        let v = e + y[0] * y[0] + 10.0 * (y[1] - y[2]).powi(2) + y[2] * y[2];
        g[0] = 3.0 * e + 2.0 * y[0];
        g[1] = e + 20.0 * (y[1] - y[2]);
        g[2] = -20.0 * (y[1] - y[2]) + 2.0 * y[2];
        v
    }

    /// A sum of distances with a kink at each zero (smoothed by 1e-9, as the objective is)
    /// seen through the bound transform's sines: the kind of function whose line searches
    /// run long.
    fn kinked(y: &[f64], g: &mut [f64]) -> f64 {
        let x: Vec<f64> = y.iter().map(|y| y.sin()).collect();
        let targets = [[0.3, -0.2], [0.5, 0.9], [-0.7, 0.1]];
        g.iter_mut().for_each(|g| *g = 0.0);
        let mut v = 0.0;
        for (k, t) in targets.iter().enumerate() {
            let (dx, dy) = (
                x[0] * x[1] + 0.5 * x[2] - t[0],
                x[2] - x[0] * (k as f64) - t[1],
            );
            let r = (dx * dx + dy * dy + 1e-18).sqrt();
            v += r;
            let (ax, ay) = (dx / r, dy / r);
            let gx = [ax * x[1] - ay * k as f64, ax * x[0], 0.5 * ax + ay];
            for i in 0..3 {
                g[i] += gx[i] * y[i].cos();
            }
        }
        v
    }

    #[test]
    fn same_iterates_as_argmin() {
        let s = Settings {
            memory: 8,
            max_iters: 150,
            tol_grad: 1e-10,
            tol_cost: 1e-14,
            stall_window: 0,
            stall_tol: 0.0,
        };
        type TestFn = fn(&[f64], &mut [f64]) -> f64;
        let cases: [(&[f64], TestFn); 7] = [
            (&[-1.2, 1.0, -0.5, 0.8, 1.5], rosenbrock),
            (&[2.0, -1.0], rosenbrock),
            (&[-3.0, -4.0], rosenbrock),
            (&[0.01, 3.0, 0.2], steep),
            (&[-2.0, 1.0, 0.5], steep),
            (&[0.4, -1.3, 2.2], kinked),
            (&[1.5, 1.5, -0.2], kinked),
        ];
        for (y0, f) in cases {
            let ((best, log), (their_best, their_log)) = both_runs(f, y0, &s);
            assert!(
                log.len() >= 10,
                "{} evaluations: too few to compare",
                log.len()
            );
            assert_eq!(log.len(), their_log.len(), "evaluation count from {y0:?}");
            for (a, b) in log.iter().zip(&their_log) {
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(a), bits(b), "an evaluated point from {y0:?}");
            }
            assert_eq!(best, their_best);
        }
        // And it minimizes: Rosenbrock's minimum is (1, …, 1).
        let ((best, _), _) = both_runs(rosenbrock, &[-1.2, 1.0, -0.5, 0.8, 1.5], &s);
        for b in best {
            assert!((b - 1.0).abs() < 1e-6, "{b}");
        }
    }

    #[test]
    fn same_iterates_as_argmin_at_other_memories() {
        for memory in [0, 1, 3] {
            let s = Settings {
                memory,
                max_iters: 60,
                tol_grad: 1e-10,
                tol_cost: 1e-14,
                stall_window: 0,
                stall_tol: 0.0,
            };
            let ((best, log), (their_best, their_log)) =
                both_runs(rosenbrock, &[-1.2, 1.0, -0.5], &s);
            assert!(
                log.len() >= 10,
                "memory {memory}: {} evaluations",
                log.len()
            );
            assert_eq!(log, their_log, "memory {memory}");
            assert_eq!(best, their_best, "memory {memory}");
        }
    }

    /// The stall test only cuts a run short: the points it evaluates are the first ones of
    /// the run without it; where the merit creeps (the kinked sum of distances) it stops
    /// early, and where progress is steady (Rosenbrock) it still reaches the minimum.
    #[test]
    fn the_stall_test_only_truncates_a_creeping_run() {
        let full = Settings {
            memory: 8,
            max_iters: 150,
            tol_grad: 1e-10,
            tol_cost: 0.0,
            stall_window: 0,
            stall_tol: 0.0,
        };
        let cut = Settings {
            stall_window: 10,
            stall_tol: 1e-8,
            ..full
        };
        type TestFn = fn(&[f64], &mut [f64]) -> f64;
        // (start, function, whether its progress is steady to the minimum)
        let cases: [(&[f64], TestFn, bool); 3] = [
            (&[0.4, -1.3, 2.2], kinked, false),
            (&[1.5, 1.5, -0.2], kinked, false),
            (&[-1.2, 1.0, -0.5, 0.8, 1.5], rosenbrock, true),
        ];
        let mut shortened = 0;
        for (y0, f, steady) in cases {
            let (a, b) = (Recorded::new(f), Recorded::new(f));
            minimize(&mut &a, y0, &full);
            let best = minimize(&mut &b, y0, &cut);
            let (a, b) = (a.log.into_inner(), b.log.into_inner());
            assert!(b.len() <= a.len(), "from {y0:?}");
            assert_eq!(
                b[..],
                a[..b.len()],
                "from {y0:?}: not the same first points"
            );
            shortened += usize::from(b.len() < a.len());
            if steady {
                for x in best {
                    assert!((x - 1.0).abs() < 1e-6, "{x}: stopped short of the minimum");
                }
            }
        }
        assert!(shortened >= 2, "the kinked runs were not cut short");
    }

    #[test]
    fn stops_at_the_iteration_cap_and_keeps_the_best_point() {
        let s = Settings {
            memory: 8,
            max_iters: 3,
            tol_grad: 0.0,
            tol_cost: 0.0,
            stall_window: 0,
            stall_tol: 0.0,
        };
        let f = Recorded::new(rosenbrock);
        let y0 = [-1.2, 1.0];
        let best = minimize(&mut &f, &y0, &s);
        let mut g = [0.0; 2];
        let (v0, v) = (rosenbrock(&y0, &mut g), rosenbrock(&best, &mut g));
        assert!(v < v0, "{v} ≥ {v0}");
        // Three line searches of at least one evaluation each, plus the start.
        assert!(f.log.borrow().len() >= 4);
        let ((b, log), (tb, tlog)) = both_runs(rosenbrock, &y0, &s);
        assert_eq!((b, log.len()), (tb, tlog.len()));
    }
}
