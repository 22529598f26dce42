//! Numeric foldability analysis of one vertex: rigid intervals over a range of the driving
//! parameter, and the closed-form degree-4 results of thesis Sec. 4.1 (Eq. 9, 13, 14).

use super::notation::VertexSpec;
use super::{Scalar, solve_vertex};

/// A sample counts as rigid when its smallest Eq. 25 margin is at least `-RIGID_TOL`.
///
/// Why not 0: a unit folded exactly flat has a unit angle of exactly 0 or π, where `acos`
/// of a rounded dot product is off by up to ~1e-8; such states are rigid (equality in
/// Eq. 25) and must not be reported as breaking the motion.
pub const RIGID_TOL: f64 = 1e-7;

/// The smallest rigid-foldability margin of the vertex at `t` (≥ 0 iff Eq. 25 holds).
pub fn min_margin(spec: &VertexSpec, t: f64) -> f64 {
    let units = spec.units_at(t);
    let st = solve_vertex(&units, &spec.mode.sign());
    st.margins.iter().copied().fold(f64::INFINITY, f64::min)
}

/// Locate where `pred` changes between `lo` (where it is `at_lo`) and `hi` by bisection
/// until the bracket is narrower than `tol`; returns the midpoint of the final bracket.
pub fn bisect(mut lo: f64, mut hi: f64, at_lo: bool, tol: f64, pred: impl Fn(f64) -> bool) -> f64 {
    while (hi - lo).abs() > tol {
        let mid = 0.5 * (lo + hi);
        if pred(mid) == at_lo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The sub-intervals of the sampled range on which `margin(t) ≥ 0`.
///
/// `ts` are increasing sample points; a sample is rigid when `margin ≥ -RIGID_TOL`. Each
/// change between rigid and non-rigid samples is refined by bisection on `margin ≥ 0` to
/// `tol`; interval ends at the range ends stay there.
pub fn rigid_intervals(ts: &[f64], tol: f64, margin: impl Fn(f64) -> f64) -> Vec<[f64; 2]> {
    let rigid: Vec<bool> = ts.iter().map(|&t| margin(t) >= -RIGID_TOL).collect();
    let exact = |t: f64| margin(t) >= 0.0;
    let mut out = Vec::new();
    let mut start: Option<f64> = None;
    for i in 0..ts.len() {
        if rigid[i] && start.is_none() {
            start = Some(if i == 0 {
                ts[0]
            } else if exact(ts[i]) {
                bisect(ts[i], ts[i - 1], true, tol, exact)
            } else {
                ts[i]
            });
        }
        if rigid[i] && (i + 1 == ts.len() || !rigid[i + 1]) {
            let end = if i + 1 == ts.len() || !exact(ts[i]) {
                ts[i]
            } else {
                bisect(ts[i], ts[i + 1], true, tol, exact)
            };
            out.push([start.take().unwrap_or(ts[i]), end]);
        }
    }
    out
}

/// Degree-4 facts (thesis Sec. 4.1) for a vertex with one driving angle.
#[derive(Clone, Debug, PartialEq)]
pub struct Degree4 {
    /// The two sectors adjacent to the driving crease (α1, α4 of Fig. 19), radians.
    pub adjacent: [f64; 2],
    /// The two opposite sectors (α2, α3), radians.
    pub opposite: [f64; 2],
    /// Eq. 13: `|α1 − α4| ≥ |α2 − α3|`, rigid for every driving angle.
    pub sufficient: bool,
    /// Eq. 14: the extreme driving angle ρ1* ≥ 0 (the motion is symmetric: ±ρ1*), or `None`
    /// when the arccos argument is below −1 (the vertex reaches ρ = ±π, region C of Fig. 23).
    pub rho_star: Option<f64>,
}

/// Eq. 9's left side minus its right side: ≥ 0 iff the degree-4 vertex is rigid at `rho`.
pub fn eq9_margin<S: Scalar>(adjacent: [S; 2], opposite: [f64; 2], rho: &S) -> S {
    let [a, b] = adjacent;
    (a.cos() * b.cos() - rho.cos() * a.sin() * b.sin()).acos() - (opposite[0] - opposite[1]).abs()
}

/// Eq. 14: `ρ1* = acos((cos α1 cos α4 − cos(α2 − α3)) / (sin α1 sin α4))` when the argument
/// lies in `[-1, 1]`; returns the raw argument too.
pub fn eq14_rho_star(adjacent: [f64; 2], opposite: [f64; 2]) -> (Option<f64>, f64) {
    let [a, b] = adjacent;
    let arg = (a.cos() * b.cos() - (opposite[0] - opposite[1]).cos()) / (a.sin() * b.sin());
    if arg < -1.0 {
        (None, arg)
    } else {
        (Some(arg.min(1.0).acos()), arg)
    }
}

/// The degree-4 analysis, when the vertex has degree 4 (one unit of two sectors).
pub fn degree4(spec: &VertexSpec) -> Option<Degree4> {
    if spec.degree() != 4 {
        return None;
    }
    let k = spec.units.iter().position(|u| u.sectors_deg.len() == 2)?;
    let d = &spec.units[k].sectors_deg;
    let adjacent = [d[0].to_radians(), d[1].to_radians()];
    let opposite = [
        spec.units[(k + 1) % 3].sectors_deg[0].to_radians(),
        spec.units[(k + 2) % 3].sectors_deg[0].to_radians(),
    ];
    let sufficient = (adjacent[0] - adjacent[1]).abs() >= (opposite[0] - opposite[1]).abs();
    let (rho_star, _) = eq14_rho_star(adjacent, opposite);
    Some(Degree4 {
        adjacent,
        opposite,
        sufficient,
        rho_star,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn grid(a: f64, b: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
            .collect()
    }

    #[test]
    fn fig28_rigid_until_two_thirds_pi() {
        let v = VertexSpec::parse("v(up, (60), (120), ((90,90),(t)))").unwrap();
        let iv = rigid_intervals(&grid(0.0, PI, 61), 1e-11, |t| min_margin(&v, t));
        assert_eq!(iv.len(), 1);
        assert!(iv[0][0].abs() < 1e-12);
        assert!((iv[0][1] - 2.0 * PI / 3.0).abs() < 1e-9, "{:?}", iv);
        let d4 = degree4(&v).unwrap();
        assert!(!d4.sufficient);
        assert!((d4.rho_star.unwrap() - 2.0 * PI / 3.0).abs() < 1e-12);
    }

    #[test]
    fn fig38_becomes_rigid_at_1_2604() {
        let v = VertexSpec::parse("v(down, ((40,100,70),(t,-t)), (70), (80))").unwrap();
        let iv = rigid_intervals(&grid(0.0, PI, 181), 1e-11, |t| min_margin(&v, t));
        assert!(min_margin(&v, 0.05) < 0.0, "not rigid just after 0");
        let last = iv.last().unwrap();
        assert!((last[0] - 1.2604).abs() < 1e-3, "{iv:?}");
        assert!((last[1] - PI).abs() < 1e-12);
    }
}
