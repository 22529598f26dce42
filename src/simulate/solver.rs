//! The per-step solve: Levenberg–Marquardt on the squared bar-length errors.
//!
//! Unknowns are the free vertices' coordinates. Each bar b between vertices i and j has the
//! residual `r_b = |x_i − x_j|² − l_b²` (Eq. 2, `l_b` the length in the initial state). One
//! step minimises `½ Σ r_b²`, starting from the previous step's positions moved along the
//! motion's tangent ([`predict`]).
//!
//! What the thesis does instead: Eq. 3 minimises the L1 sum `δ = Σ ε_b` subject to
//! `−ε_b ≤ l_a − l_t ≤ ε_b` with an interior-point method (Mathematica's FindMinimum),
//! the constraints "formulated according to Eq. (2)", i.e. in squared lengths. Both
//! formulations have the same minimisers whenever a rigid state exists (every r_b = 0),
//! which is the case that decides rigid foldability. What is *reported* is the thesis's
//! quantity at our solution: δ(j) = Σ_b |l_b² − l_t,b²| ([`Bars::delta`]), and also the
//! plain-length sum Σ_b |l_b − l_t,b| ([`Bars::delta_length`]) for readers who take Eq. 3
//! literally. For non-rigid steps the L2 and L1 minimisers differ, so δ(j) there is an
//! upper bound on the thesis's value at the same state (and of the same order); the
//! verdict δ(j) ≤ 1e-4 is unaffected in practice because non-rigid states sit orders of
//! magnitude above it.
//!
//! The normal equations `(JᵀJ + μI) h = −Jᵀr` are assembled bar by bar (each bar touches
//! two 3×3 blocks) and solved by Cholesky; μ follows Nielsen's update. The damping keeps
//! steps finite where the Jacobian is rank deficient (a flat state, where no bar resists
//! motion normal to the plane to first order). A rigid pattern converges quadratically to
//! residuals at rounding level (δ ~ 1e-14 on the flasher).

use nalgebra::{DMatrix, DVector};

use super::input::SolverSettings;

/// Bars of a pattern with their target squared lengths.
#[derive(Clone, Debug)]
pub struct Bars {
    /// Vertex pairs.
    pub pairs: Vec<[usize; 2]>,
    /// Squared target lengths, one per pair.
    pub target_sq: Vec<f64>,
}

impl Bars {
    /// Bars on every pair of vertices of each facet (its sides and all its diagonals) plus
    /// `extra`, without duplicates, with target lengths measured in `x`.
    pub fn from_faces(faces: &[Vec<usize>], extra: &[[usize; 2]], x: &[[f64; 3]]) -> Bars {
        let mut pairs: Vec<[usize; 2]> = Vec::new();
        for f in faces {
            for a in 0..f.len() {
                for b in a + 1..f.len() {
                    pairs.push([f[a].min(f[b]), f[a].max(f[b])]);
                }
            }
        }
        pairs.extend(extra.iter().map(|b| [b[0].min(b[1]), b[0].max(b[1])]));
        pairs.sort_unstable();
        pairs.dedup();
        pairs.retain(|b| b[0] != b[1]);
        let target_sq = pairs.iter().map(|&[i, j]| dist_sq(&x[i], &x[j])).collect();
        Bars { pairs, target_sq }
    }

    /// Residuals `|x_i − x_j|² − l²` of all bars at `x`.
    pub fn residuals(&self, x: &[[f64; 3]]) -> Vec<f64> {
        self.pairs
            .iter()
            .zip(&self.target_sq)
            .map(|(&[i, j], &l2)| dist_sq(&x[i], &x[j]) - l2)
            .collect()
    }

    /// δ = Σ |l_a² − l_t²| (the thesis's distortion, Eq. 3, in the squared form of Eq. 2).
    pub fn delta(&self, x: &[[f64; 3]]) -> f64 {
        self.residuals(x).iter().map(|r| r.abs()).sum()
    }

    /// Σ |l_a − l_t| (the distortion in plain lengths).
    pub fn delta_length(&self, x: &[[f64; 3]]) -> f64 {
        self.pairs
            .iter()
            .zip(&self.target_sq)
            .map(|(&[i, j], &l2)| (dist_sq(&x[i], &x[j]).sqrt() - l2.sqrt()).abs())
            .sum()
    }
}

fn dist_sq(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)
}

/// First-order predictor of a step: with the prescribed vertices already moved to their
/// new positions in `x` (free ones still at the last solution `from`), move the free vertices
/// along the motion's tangent. The linearised bar constraints `J_f d_f + J_p d_p = 0` are
/// solved for `d_f` in least squares with a tiny Tikhonov term (minimum norm where the
/// tangent is not unique, as at a flat state); steps longer than ten times the prescribed
/// displacement are scaled back, since near a fold the tangent stops being a guide.
///
/// Without it each step would start from the previous positions (as Eq. 3 does), and near a
/// bifurcation a coarse step can then converge to the mirror-image branch; starting on the
/// tangent keeps the solution on the branch it is following.
pub fn predict(
    bars: &Bars,
    slot: &[Option<usize>],
    n_free: usize,
    from: &[[f64; 3]],
    x: &mut [[f64; 3]],
) {
    let dim = 3 * n_free;
    if dim == 0 {
        return;
    }
    let moved = x
        .iter()
        .zip(from)
        .enumerate()
        .filter(|(v, _)| slot[*v].is_none())
        .map(|(_, (a, b))| (0..3).map(|u| (a[u] - b[u]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    if moved == 0.0 {
        return;
    }
    let mut a = DMatrix::<f64>::zeros(dim, dim);
    let mut g = DVector::<f64>::zeros(dim);
    for &[i, j] in &bars.pairs {
        let d = [0, 1, 2].map(|u| 2.0 * (from[i][u] - from[j][u]));
        // Known part of the linearised residual: the prescribed vertices' displacements.
        let known: f64 = [(i, 1.0), (j, -1.0)]
            .iter()
            .filter(|(v, _)| slot[*v].is_none())
            .map(|&(v, sg)| sg * (0..3).map(|u| d[u] * (x[v][u] - from[v][u])).sum::<f64>())
            .sum();
        let blocks = [(slot[i], 1.0), (slot[j], -1.0)];
        for &(si, sgi) in &blocks {
            let Some(ki) = si else { continue };
            for u in 0..3 {
                g[3 * ki + u] += sgi * d[u] * known;
            }
            for &(sj, sgj) in &blocks {
                let Some(kj) = sj else { continue };
                for u in 0..3 {
                    for w in 0..3 {
                        a[(3 * ki + u, 3 * kj + w)] += sgi * sgj * d[u] * d[w];
                    }
                }
            }
        }
    }
    let dmax = (0..dim).map(|k| a[(k, k)]).fold(0.0, f64::max);
    for k in 0..dim {
        a[(k, k)] += 1e-10 * dmax.max(1e-300);
    }
    let Some(chol) = a.cholesky() else {
        return;
    };
    let mut h = chol.solve(&(-g));
    let hmax = h.amax();
    if !hmax.is_finite() {
        return;
    }
    if hmax > 10.0 * moved {
        h *= 10.0 * moved / hmax;
    }
    for (v, s) in slot.iter().enumerate() {
        if let Some(k) = s {
            for u in 0..3 {
                x[v][u] = from[v][u] + h[3 * k + u];
            }
        }
    }
}

/// What one solve did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveStats {
    /// LM iterations taken (accepted or rejected).
    pub iterations: usize,
    /// `½ Σ r²` at the end.
    pub cost: f64,
}

/// Minimise `½ Σ r_b²` over the free vertices (`slot[v] = Some(k)`: coordinates
/// `3k..3k+3` of the unknown vector) starting from `x`, which is updated in place.
pub fn solve(
    bars: &Bars,
    slot: &[Option<usize>],
    n_free: usize,
    x: &mut [[f64; 3]],
    s: &SolverSettings,
) -> SolveStats {
    let dim = 3 * n_free;
    let residuals = |x: &[[f64; 3]]| bars.residuals(x);
    let cost_of = |r: &[f64]| 0.5 * r.iter().map(|v| v * v).sum::<f64>();
    let mut r = residuals(x);
    let mut cost = cost_of(&r);
    if dim == 0 {
        return SolveStats {
            iterations: 0,
            cost,
        };
    }
    let scale = x.iter().flatten().fold(1.0_f64, |m, v| m.max(v.abs()));
    let mut a = DMatrix::<f64>::zeros(dim, dim);
    let mut g = DVector::<f64>::zeros(dim);
    let mut mu = -1.0;
    let mut nu = 2.0;
    let mut it = 0;
    let mut trial = x.to_vec();
    while it < s.max_iterations {
        if r.iter().all(|v| v.abs() <= s.residual_tolerance) {
            break;
        }
        normal_equations(bars, slot, x, &r, &mut a, &mut g);
        if g.amax() == 0.0 {
            break; // stationary (e.g. a symmetric saddle); nothing more to gain
        }
        if mu < 0.0 {
            let dmax = (0..dim).map(|k| a[(k, k)]).fold(0.0, f64::max);
            mu = 1e-6 * dmax.max(1e-12);
        }
        // Solve (A + μI) h = −g, raising μ until the matrix factors and the step pays.
        loop {
            it += 1;
            let mut m = a.clone();
            for k in 0..dim {
                m[(k, k)] += mu;
            }
            let Some(chol) = m.cholesky() else {
                mu *= nu;
                nu *= 2.0;
                if it >= s.max_iterations {
                    break;
                }
                continue;
            };
            let h = chol.solve(&(-&g));
            let hmax = h.amax();
            stepped(slot, x, &h, &mut trial);
            let r_new = residuals(&trial);
            let cost_new = cost_of(&r_new);
            let predicted = 0.5 * h.dot(&(&h * mu - &g));
            let gain = (cost - cost_new) / predicted;
            if cost_new < cost && predicted > 0.0 {
                x.copy_from_slice(&trial);
                r = r_new;
                // A reliable model that gains almost nothing means a stationary point with
                // residual left (a non-rigid state): further digits do not change δ.
                let stalled = gain > 0.25 && cost - cost_new <= 1e-12 * cost;
                cost = cost_new;
                mu *= (1.0 - (2.0 * gain - 1.0).powi(3)).max(1.0 / 3.0);
                nu = 2.0;
                if hmax <= s.step_tolerance * scale || stalled {
                    return SolveStats {
                        iterations: it,
                        cost,
                    };
                }
                break;
            }
            if hmax <= s.step_tolerance * scale || it >= s.max_iterations {
                // No decrease even for a step at rounding level: converged as far as f64 goes.
                return SolveStats {
                    iterations: it,
                    cost,
                };
            }
            mu *= nu;
            nu *= 2.0;
        }
    }
    SolveStats {
        iterations: it,
        cost,
    }
}

/// The normal equations at `x` with residuals `r`: `a = JᵀJ`, `g = Jᵀr`, bar by bar.
fn normal_equations(
    bars: &Bars,
    slot: &[Option<usize>],
    x: &[[f64; 3]],
    r: &[f64],
    a: &mut DMatrix<f64>,
    g: &mut DVector<f64>,
) {
    a.fill(0.0);
    g.fill(0.0);
    for (&[i, j], &rb) in bars.pairs.iter().zip(r) {
        let d = [
            2.0 * (x[i][0] - x[j][0]),
            2.0 * (x[i][1] - x[j][1]),
            2.0 * (x[i][2] - x[j][2]),
        ];
        // ∂r/∂x_i = d, ∂r/∂x_j = −d.
        let blocks = [(slot[i], 1.0), (slot[j], -1.0)];
        for &(si, sgi) in &blocks {
            let Some(ki) = si else { continue };
            for u in 0..3 {
                g[3 * ki + u] += sgi * d[u] * rb;
            }
            for &(sj, sgj) in &blocks {
                let Some(kj) = sj else { continue };
                for u in 0..3 {
                    for w in 0..3 {
                        a[(3 * ki + u, 3 * kj + w)] += sgi * sgj * d[u] * d[w];
                    }
                }
            }
        }
    }
}

/// `trial` = `x` with the free coordinates moved by `h`.
fn stepped(slot: &[Option<usize>], x: &[[f64; 3]], h: &DVector<f64>, trial: &mut [[f64; 3]]) {
    for (v, slot_v) in slot.iter().enumerate() {
        if let Some(k) = slot_v {
            for u in 0..3 {
                trial[v][u] = x[v][u] + h[3 * k + u];
            }
        } else {
            trial[v] = x[v];
        }
    }
}

/// The Jacobian of the bar residuals with respect to the free coordinates (`slot[v] =
/// Some(k)`: columns `3k..3k+3`), one row per bar. Its smallest singular value bounds how
/// far a residual r can leave the vertices from an exact solution: ‖Δx‖ ≲ ‖r‖/σ_min.
pub fn jacobian(
    bars: &Bars,
    slot: &[Option<usize>],
    n_free: usize,
    x: &[[f64; 3]],
) -> DMatrix<f64> {
    let mut jac = DMatrix::<f64>::zeros(bars.pairs.len(), 3 * n_free);
    for (b, &[i, j]) in bars.pairs.iter().enumerate() {
        for u in 0..3 {
            let d = 2.0 * (x[i][u] - x[j][u]);
            if let Some(k) = slot[i] {
                jac[(b, 3 * k + u)] += d;
            }
            if let Some(k) = slot[j] {
                jac[(b, 3 * k + u)] -= d;
            }
        }
    }
    jac
}
