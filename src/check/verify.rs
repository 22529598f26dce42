//! Verification of an evaluated design against the invariants of SPEC §5: the project's
//! own oracle, independent of how the model composed its frames.
//!
//! - isometry: every facet's pairwise vertex distances in 3D equal the flat ones, with
//!   each vertex read through one fixed facet (so a wrong frame composition shows up as a
//!   distorted neighbour);
//! - closure at every internal vertex (the PTU's φ close the loop of rotations);
//! - developability measured on the flat coordinates (the angles between consecutive
//!   creases, not the model's own sector expressions, sum to 2π and equal them);
//! - fold angles: each crease's dihedral angle agrees with the angle between the 3D
//!   normals of its two facets;
//! - rigid foldability over a dense sweep of the motion (the thesis checks t_max only).

use crate::kinematics::{closure_residual, wrap_angle};
use crate::model::geometry::units;
use crate::model::numeric::Evaluated;
use serde::Serialize;
use std::f64::consts::PI;

/// What verification found.
#[derive(Clone, Debug, Serialize)]
pub struct VerifyReport {
    /// Worst relative distance error over every facet and sampled state.
    pub isometry_max: f64,
    /// Worst closure residual over every internal vertex and sampled state.
    pub closure_max: f64,
    /// Worst deviation of the flat sector angles from developability / from the model.
    pub developability_max: f64,
    /// Worst disagreement between a crease's dihedral angle and its facets' normals (rad).
    pub fold_angle_max: f64,
    /// Whether Eq. 25 holds at every internal vertex over the whole sweep.
    pub rigid_over_motion: bool,
    /// Whether Eq. 25 holds at t_max (the thesis's check).
    pub rigid_at_tmax: bool,
    /// Smallest rigid-foldability margin over the sweep and where it occurs.
    pub min_margin: f64,
    /// The t of `min_margin`.
    pub min_margin_t: f64,
    /// Number of states swept.
    pub states: usize,
}

/// Tolerances of a passing verification.
#[derive(Clone, Copy, Debug)]
pub struct Tolerances {
    /// Relative isometry error.
    pub isometry: f64,
    /// Closure residual.
    pub closure: f64,
    /// Developability (radians).
    pub developability: f64,
    /// Fold angle (radians).
    pub fold_angle: f64,
    /// Rigid-foldability margin (radians) below which a state counts as not rigid.
    pub margin: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances { isometry: 1e-9, closure: 1e-10, developability: 1e-9, fold_angle: 1e-8, margin: 1e-9 }
    }
}

impl VerifyReport {
    /// Whether every invariant holds within `tol` (rigidity over the whole motion included).
    pub fn passes(&self, tol: &Tolerances) -> bool {
        self.isometry_max <= tol.isometry
            && self.closure_max <= tol.closure
            && self.developability_max <= tol.developability
            && self.fold_angle_max <= tol.fold_angle
            && self.rigid_over_motion
    }

    /// The failed invariants, in words.
    pub fn failures(&self, tol: &Tolerances) -> Vec<String> {
        let mut out = Vec::new();
        if self.isometry_max > tol.isometry {
            out.push(format!("isometry {:.3e} > {:.0e}", self.isometry_max, tol.isometry));
        }
        if self.closure_max > tol.closure {
            out.push(format!("closure {:.3e} > {:.0e}", self.closure_max, tol.closure));
        }
        if self.developability_max > tol.developability {
            out.push(format!("developability {:.3e} > {:.0e}", self.developability_max, tol.developability));
        }
        if self.fold_angle_max > tol.fold_angle {
            out.push(format!("fold angles {:.3e} > {:.0e}", self.fold_angle_max, tol.fold_angle));
        }
        if !self.rigid_over_motion {
            out.push(format!("not rigid at t = {:.6} (margin {:.3e})", self.min_margin_t, self.min_margin));
        }
        out
    }
}

fn dist(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Unit normal of a polygon by Newell's method (counter-clockwise → +z when flat).
fn normal(points: &[[f64; 3]]) -> [f64; 3] {
    let mut n = [0.0; 3];
    for i in 0..points.len() {
        let (p, q) = (&points[i], &points[(i + 1) % points.len()]);
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    [n[0] / l, n[1] / l, n[2] / l]
}

/// Verify `design` at the states `ts` (the sweep; the last one is taken as t_max for
/// the thesis-style check).
pub fn verify(design: &Evaluated<'_>, ts: &[f64], tol: &Tolerances) -> VerifyReport {
    let plan = design.plan;
    let flat = &design.flat;
    let mut r = VerifyReport {
        isometry_max: 0.0,
        closure_max: 0.0,
        developability_max: 0.0,
        fold_angle_max: 0.0,
        rigid_over_motion: true,
        rigid_at_tmax: true,
        min_margin: f64::INFINITY,
        min_margin_t: 0.0,
        states: ts.len(),
    };

    // Developability on the flat coordinates.
    for (i, v) in plan.vertices.iter().enumerate() {
        if !v.internal {
            continue;
        }
        let n = v.rays.len();
        let mut sum = 0.0;
        for k in 0..n {
            let (a, b) = (&flat.pos[v.rays[k].other], &flat.pos[v.rays[(k + 1) % n].other]);
            let o = &flat.pos[i];
            let (u, w) = ([a[0] - o[0], a[1] - o[1]], [b[0] - o[0], b[1] - o[1]]);
            let mut ang = (u[0] * w[1] - u[1] * w[0]).atan2(u[0] * w[0] + u[1] * w[1]);
            if ang <= 0.0 {
                ang += 2.0 * PI;
            }
            sum += ang;
            r.developability_max = r.developability_max.max((ang - flat.sectors[i][k]).abs());
        }
        r.developability_max = r.developability_max.max((sum - 2.0 * PI).abs());
    }

    let flat3: Vec<[f64; 3]> = flat.pos.iter().map(|p| [p[0], p[1], 0.0]).collect();
    for (si, &t) in ts.iter().enumerate() {
        let folded = design.fold(t);
        let x = design.coords(&folded);
        // Isometry, relative to each facet's size.
        for (poly, _) in &plan.polygons {
            let size = poly
                .iter()
                .flat_map(|a| poly.iter().map(move |b| (a, b)))
                .map(|(a, b)| dist(&flat3[*a], &flat3[*b]))
                .fold(0.0, f64::max);
            for (ia, a) in poly.iter().enumerate() {
                for b in &poly[ia + 1..] {
                    let e = (dist(&x[*a], &x[*b]) - dist(&flat3[*a], &flat3[*b])).abs() / size.max(1e-300);
                    r.isometry_max = r.isometry_max.max(e);
                }
            }
        }
        // Closure and rigidity at every internal vertex.
        for &a in &plan.internal {
            let st = folded.states[a].as_ref().expect("internal vertices are solved");
            let margin = st.margins.iter().copied().fold(f64::INFINITY, f64::min);
            if margin < r.min_margin {
                r.min_margin = margin;
                r.min_margin_t = t;
            }
            if margin < -tol.margin {
                r.rigid_over_motion = false;
                if si + 1 == ts.len() {
                    r.rigid_at_tmax = false;
                }
                continue;
            }
            let rho: Vec<Option<f64>> = folded.rho.iter().map(|x| Some(*x)).collect();
            if let Some(u) = units(plan, flat, &rho, a) {
                r.closure_max = r.closure_max.max(closure_residual(&u, &st.phi));
            }
        }
        // Fold angles against the facets' normals.
        let normals: Vec<Option<[f64; 3]>> = plan
            .polygons
            .iter()
            .map(|(p, _)| (p.len() >= 3).then(|| normal(&p.iter().map(|v| x[*v]).collect::<Vec<_>>())))
            .collect();
        for (ci, c) in plan.creases.iter().enumerate() {
            let (Some(nl), Some(nr)) = (normals[c.left], normals[c.right]) else { continue };
            let e = {
                let (p, q) = (&x[c.tail], &x[c.head]);
                let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
                let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                [d[0] / l, d[1] / l, d[2] / l]
            };
            let cross = [
                nr[1] * nl[2] - nr[2] * nl[1],
                nr[2] * nl[0] - nr[0] * nl[2],
                nr[0] * nl[1] - nr[1] * nl[0],
            ];
            let geo = (cross[0] * e[0] + cross[1] * e[1] + cross[2] * e[2])
                .atan2(nr[0] * nl[0] + nr[1] * nl[1] + nr[2] * nl[2]);
            let err = wrap_angle(geo - folded.rho[ci]).abs();
            r.fold_angle_max = r.fold_angle_max.max(err);
        }
    }
    r
}
