//! The Principle of Three Units (thesis Sec. 4.2.3, Eq. 17–23, 25), generic over [`Scalar`].
//!
//! A degree-n vertex is cut at its three unknown creases into three *units*; each unit is an
//! open chain of sectors joined by driving angles. The angle spanned by a unit (its *unit
//! angle*) is one side of the spherical *vertex triangle*; the triangle's internal angles,
//! plus each unit's start and end angles, give the three unknown dihedral angles.
//!
//! Conventions (SPEC §1): sectors counter-clockwise; `M = +1` is mode "up", `-1` "down";
//! φ3 sits on the crease between u1 and u2, φ1 between u2 and u3, φ2 between u3 and u1.

use super::Scalar;

/// One unit: `m` sectors and the `m - 1` driving angles between consecutive sectors.
#[derive(Clone, Debug, PartialEq)]
pub struct Unit<S> {
    /// Sector angles `α_j1 … α_jm` in radians, counter-clockwise.
    pub sectors: Vec<S>,
    /// Driving angles `ρ_j1 … ρ_j(m-1)`; `ρ_ji` sits between sectors `i` and `i + 1`.
    pub driving: Vec<S>,
}

impl<S> Unit<S> {
    /// A unit from its sectors and driving angles.
    ///
    /// # Panics
    /// If `driving.len() + 1 != sectors.len()` or there are no sectors (a programming
    /// error: user input is validated by the notation parser before it gets here).
    pub fn new(sectors: Vec<S>, driving: Vec<S>) -> Self {
        assert!(!sectors.is_empty(), "a unit has at least one sector");
        assert_eq!(
            driving.len() + 1,
            sectors.len(),
            "a unit of m sectors has m-1 driving angles"
        );
        Unit { sectors, driving }
    }

    /// A unit of a single sector (constant unit angle, zero start and end angles).
    pub fn single(sector: S) -> Self {
        Unit {
            sectors: vec![sector],
            driving: Vec::new(),
        }
    }
}

/// The angles of one unit: its unit angle and its start and end angles.
#[derive(Clone, Debug, PartialEq)]
pub struct UnitAngles<S> {
    /// Unit angle `U_j` (Eq. 18).
    pub u: S,
    /// Start angle `β_j` (Eq. 20), signed.
    pub beta: S,
    /// End angle `δ_j` (Eq. 22), signed.
    pub delta: S,
}

/// The unit's chain `Q = R_z(α_1) R_x(ρ_1) … R_x(ρ_{m-1}) R_z(α_m)` as rows.
///
/// Its first column is `P_jm` of Eq. 17 (the last crease seen from the first) and its
/// first row is `P'_j0` of Eq. 21, because the reversed chain with negated angles is
/// `Q⁻¹ = Qᵀ`. Building `Q` once shares every sine and cosine between the two.
fn chain<S: Scalar>(sectors: &[S], driving: &[S]) -> [[S; 3]; 3] {
    let m = sectors.len();
    let (zero, one) = (S::from_f64(0.0), S::from_f64(1.0));
    let (c, s) = (sectors[m - 1].cos(), sectors[m - 1].sin());
    let mut q = [
        [c.clone(), -s.clone(), zero.clone()],
        [s, c, zero.clone()],
        [zero.clone(), zero, one],
    ];
    // Left-multiply by R_z(α_i) R_x(ρ_i) for i = m-1 … 1.
    for i in (0..m - 1).rev() {
        let (c, s) = (driving[i].cos(), driving[i].sin());
        let [r0, r1, r2] = q;
        let r1x: [S; 3] =
            std::array::from_fn(|k| c.clone() * r1[k].clone() - s.clone() * r2[k].clone());
        let r2x: [S; 3] =
            std::array::from_fn(|k| s.clone() * r1[k].clone() + c.clone() * r2[k].clone());
        let (c, s) = (sectors[i].cos(), sectors[i].sin());
        let r0z = std::array::from_fn(|k| c.clone() * r0[k].clone() - s.clone() * r1x[k].clone());
        let r1z = std::array::from_fn(|k| s.clone() * r0[k].clone() + c.clone() * r1x[k].clone());
        q = [r0z, r1z, r2x];
    }
    q
}

/// Unit angle, start and end angle of one unit (Eq. 17–22).
///
/// A single-sector unit has `U = α` and `β = δ = 0`.
///
/// The thesis writes `U = acos(P_0 · P_m)` and `β = −sgn(P_m^z) · acos(…)` (law of cosines
/// in the triangle `α_1, U, γ_s`). We evaluate the same angles as `atan2`s, which are
/// equal wherever the thesis's formulas are defined and stay exact where they are not:
/// - the start angle is the angle at `P_0 = e_x` between the arc to `P_1` (tangent
///   `+e_y`, since `0 < α_1 < π`) and the arc to `P_m` (tangent `(0, y, z)`), so
///   `−sgn(z)·acos(…) = −atan2(z, y)`; at `z = 0` this gives `±π` where `sgn(0) = 0`
///   would lose a half turn (a flat unit whose sectors sum past π); the end angle is the
///   mirror image on the reversed chain (Eq. 21–22), read off `Q` consistently with the
///   start angle (see the comment in the body);
/// - `U = atan2(√(y² + z²), x)` keeps full precision near 0 and π where `acos` loses
///   half the digits.
pub fn unit_angles<S: Scalar>(unit: &Unit<S>) -> UnitAngles<S> {
    let (sectors, driving) = (&unit.sectors, &unit.driving);
    if sectors.len() == 1 {
        return UnitAngles {
            u: sectors[0].clone(),
            beta: S::from_f64(0.0),
            delta: S::from_f64(0.0),
        };
    }
    let [[x, _, _], [y, q11, q12], [z, q21, q22]] = chain(sectors, driving);
    let r = (y.clone() * y.clone() + z.clone() * z.clone()).sqrt();
    let u = r.atan2(&x);
    let beta = -z.atan2(&y);
    // End angle. Q = R_x(−β) R_z(U) R_x(−δ) (an X-Z-X Euler decomposition), so the last
    // row of R_x(β) Q is (0, −sin δ, cos δ). Reading δ there, with the β just computed,
    // keeps (U, β, δ) one consistent decomposition of Q even where β and δ are each
    // ill-defined (U → 0 or π, a unit folded onto itself or straight): reading δ from
    // Q's first row instead gives β and δ independent errors of ε/sin U, and closure
    // residuals of 1e-9 at such vertices. (cos β, −sin β) ∝ (y, z); at y = z = 0 the
    // direction is taken as (1, 0), β's own value there.
    let yy = y.clone() + (S::from_f64(1.0) - r.sgn());
    let delta = -(yy.clone() * q21 - z.clone() * q11).atan2(&(yy * q22 - z * q12));
    UnitAngles { u, beta, delta }
}

/// Internal angles θ of the vertex triangle with sides `u` (Eq. 19); `θ_i` is opposite `U_i`.
///
/// Eq. 19 is the spherical law of cosines. We evaluate the equivalent half-angle form
/// `tan(θ_i/2) = √(sin(s−U_j)·sin(s−U_k) / (sin s·sin(s−U_i)))`, `s = (U_1+U_2+U_3)/2`,
/// because every crease pattern passes through degenerate triangles (the flat state has
/// `s = π`; the end of the rigid range has a zero margin), where `acos` near ±1 loses half
/// the digits: closure residuals of ~1e-8 with the law of cosines, ~1e-16 with this form.
/// Outside the rigid range the radicands are clamped at 0, so `θ` stays finite (0 or π).
pub fn internal_angles<S: Scalar>(u: &[S; 3]) -> [S; 3] {
    let s = (u[0].clone() + u[1].clone() + u[2].clone()) * 0.5;
    let sin_s = s.sin();
    // sin(s − U_i) = sin(margin_i / 2)
    let h: [S; 3] = [
        (s.clone() - u[0].clone()).sin(),
        (s.clone() - u[1].clone()).sin(),
        (s - u[2].clone()).sin(),
    ];
    let angle = |i: usize, j: usize, k: usize| {
        let num = (h[j].clone() * h[k].clone()).max0().sqrt();
        let den = (sin_s.clone() * h[i].clone()).max0().sqrt();
        num.atan2(&den) * 2.0
    };
    [angle(0, 1, 2), angle(1, 0, 2), angle(2, 0, 1)]
}

/// The rigid-foldability margins of Eq. 25 as three smooth inequalities:
/// `U_j + U_k - U_i ≥ 0` for `i = 1, 2, 3`. The vertex folds rigidly iff all are ≥ 0.
pub fn rigid_margins<S: Scalar>(u: &[S; 3]) -> [S; 3] {
    [
        u[1].clone() + u[2].clone() - u[0].clone(),
        u[0].clone() + u[2].clone() - u[1].clone(),
        u[0].clone() + u[1].clone() - u[2].clone(),
    ]
}

/// Everything the PTU says about one vertex at one state.
#[derive(Clone, Debug, PartialEq)]
pub struct VertexState<S> {
    /// Unit angles `U_1..3`.
    pub u: [S; 3],
    /// Internal angles `θ_1..3` of the vertex triangle (`θ_i` opposite `U_i`).
    pub theta: [S; 3],
    /// Start angles `β_1..3`.
    pub beta: [S; 3],
    /// End angles `δ_1..3`.
    pub delta: [S; 3],
    /// Unknown dihedral angles `φ_1..3` (Eq. 23).
    pub phi: [S; 3],
    /// Rigid-foldability margins (Eq. 25), see [`rigid_margins`].
    pub margins: [S; 3],
}

/// Solve one vertex: units `u1, u2, u3` and the mode `M = ±1` (a scalar, so one symbolic
/// model serves both modes).
pub fn solve_vertex<S: Scalar>(units: &[Unit<S>; 3], mode: &S) -> VertexState<S> {
    let [a1, a2, a3] = [
        unit_angles(&units[0]),
        unit_angles(&units[1]),
        unit_angles(&units[2]),
    ];
    let u = [a1.u, a2.u, a3.u];
    let beta = [a1.beta, a2.beta, a3.beta];
    let delta = [a1.delta, a2.delta, a3.delta];
    let theta = internal_angles(&u);
    let pi = std::f64::consts::PI;
    let turn = |th: &S| mode.clone() * (S::from_f64(pi) - th.clone());
    let phi = [
        beta[2].clone() + turn(&theta[0]) + delta[1].clone(),
        beta[0].clone() + turn(&theta[1]) + delta[2].clone(),
        beta[1].clone() + turn(&theta[2]) + delta[0].clone(),
    ];
    let margins = rigid_margins(&u);
    VertexState {
        u,
        theta,
        beta,
        delta,
        phi,
        margins,
    }
}

/// The creases of a solved vertex walked counter-clockwise: each sector followed by the
/// dihedral angle of the crease after it (driving angles inside units, then φ3, φ1, φ2).
pub fn ccw_sequence(units: &[Unit<f64>; 3], phi: &[f64; 3]) -> Vec<(f64, f64)> {
    let after_unit = [phi[2], phi[0], phi[1]];
    let mut seq = Vec::new();
    for (unit, closing) in units.iter().zip(after_unit) {
        for (i, &a) in unit.sectors.iter().enumerate() {
            let rho = if i + 1 < unit.sectors.len() {
                unit.driving[i]
            } else {
                closing
            };
            seq.push((a, rho));
        }
    }
    seq
}

/// Closure residual (SPEC §1): walking counter-clockwise around the vertex,
/// `Π_k R_z(α_k) R_x(ρ_k)` over all creases must be the identity. Returns the largest
/// absolute entry of the product minus the identity.
pub fn closure_residual(units: &[Unit<f64>; 3], phi: &[f64; 3]) -> f64 {
    let mut m = nalgebra::Matrix3::<f64>::identity();
    for (a, rho) in ccw_sequence(units, phi) {
        let rz = nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::z_axis(), a);
        let rx = nalgebra::Rotation3::from_axis_angle(&nalgebra::Vector3::x_axis(), rho);
        m = m * rz.matrix() * rx.matrix();
    }
    (m - nalgebra::Matrix3::identity()).amax()
}

/// An angle wrapped to `(−π, π]` (a dihedral angle of `φ + 2πk` is the same fold).
pub fn wrap_angle(a: f64) -> f64 {
    let tau = 2.0 * std::f64::consts::PI;
    let w = a - tau * (a / tau).round();
    if w <= -std::f64::consts::PI {
        w + tau
    } else {
        w
    }
}

/// Fully folded unit angle (Sec. 4.2.4.3): with every driving angle at ±π,
/// `U_j(π) = |α_j1 − α_j2 + α_j3 − …|`.
pub fn folded_unit_angle(sectors: &[f64]) -> f64 {
    sectors
        .iter()
        .enumerate()
        .map(|(i, a)| if i % 2 == 0 { *a } else { -*a })
        .sum::<f64>()
        .abs()
}

/// Flat foldability (Eq. 26): the fully folded unit angles satisfy
/// `U(π)_max = U(π)_med + U(π)_min` within `tol` (radians). Returns the verdict and `U(π)`.
pub fn flat_foldable(units: &[Unit<f64>; 3], tol: f64) -> (bool, [f64; 3]) {
    let u_pi = [
        folded_unit_angle(&units[0].sectors),
        folded_unit_angle(&units[1].sectors),
        folded_unit_angle(&units[2].sectors),
    ];
    let mut s = u_pi;
    s.sort_by(f64::total_cmp);
    ((s[2] - s[1] - s[0]).abs() <= tol, u_pi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn deg(x: f64) -> f64 {
        x.to_radians()
    }

    #[test]
    fn fig28_unit_angle_is_pi_minus_t() {
        // u3 = ((90, 90), (t)): U3 = acos(-cos t) = π - t (thesis Sec. 4.2.4.2).
        for t in [0.1, 0.7, 1.3, 2.0, 2.9] {
            let unit = Unit::new(vec![deg(90.0), deg(90.0)], vec![t]);
            let a = unit_angles(&unit);
            assert!((a.u - (PI - t)).abs() < 1e-12, "t={t}: U={}", a.u);
        }
    }

    #[test]
    fn chain_rows_are_the_reversed_chain_of_eq21() {
        // P'_0 computed literally as R_z(-α_m) R_x(-ρ_{m-1}) … R_z(-α_1) e_x.
        use nalgebra::{Rotation3, Vector3};
        let s = [deg(40.0), deg(70.0), deg(35.0), deg(80.0)];
        let d = [0.4, -1.1, 0.9];
        let rz = |a: f64| Rotation3::from_axis_angle(&Vector3::z_axis(), a);
        let rx = |a: f64| Rotation3::from_axis_angle(&Vector3::x_axis(), a);
        let mut p = rz(-s[0]) * Vector3::x();
        for i in 0..3 {
            p = rz(-s[i + 1]) * (rx(-d[i]) * p);
        }
        let q = chain(&s, &d);
        for k in 0..3 {
            assert!((q[0][k] - p[k]).abs() < 1e-14);
        }
    }

    #[test]
    fn closure_holds_for_the_fig29_vertex_in_both_modes() {
        for mode in [1.0, -1.0] {
            for t in [0.3, 1.0, 2.1, 3.0] {
                let units = [
                    Unit::new(vec![deg(80.0), deg(40.0), deg(40.0)], vec![t, -t]),
                    Unit::new(vec![deg(90.0), deg(40.0), deg(50.0)], vec![t, -t]),
                    Unit::single(deg(20.0)),
                ];
                let v = solve_vertex(&units, &mode);
                let r = closure_residual(&units, &v.phi);
                assert!(r < 1e-10, "mode {mode} t {t}: residual {r}");
            }
        }
    }

    #[test]
    fn flat_foldability_of_fig29() {
        let units = [
            Unit::new(vec![deg(80.0), deg(40.0), deg(40.0)], vec![0.0, 0.0]),
            Unit::new(vec![deg(90.0), deg(40.0), deg(50.0)], vec![0.0, 0.0]),
            Unit::single(deg(20.0)),
        ];
        let (ok, u) = flat_foldable(&units, 1e-9);
        assert!(ok);
        for (got, want) in u.iter().zip([80.0, 100.0, 20.0]) {
            assert!((got.to_degrees() - want).abs() < 1e-9);
        }
    }
}
