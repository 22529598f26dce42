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

use crate::geom;
use crate::kinematics::{closure_residual, wrap_angle};
use crate::model::Plan;
use crate::model::geometry::{Flat, Folded, units};
use crate::model::numeric::Evaluated;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// What verification found.
#[derive(Clone, Debug, Serialize, Deserialize)]
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
    /// States on which every internal vertex is rigid with at least the geometry margin
    /// (the geometric invariants are checked on these: a non-rigid state has no closed
    /// configuration to check).
    pub rigid_states: usize,
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
    /// Smallest margin at which the geometric invariants are checked: nearer to a
    /// degenerate vertex triangle its angles move with √margin, so rounding alone gives
    /// closure errors of 1e-16/√margin.
    pub geometry_margin: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            isometry: 1e-9,
            closure: 1e-10,
            developability: 1e-9,
            fold_angle: 1e-8,
            margin: 1e-12,
            geometry_margin: 1e-12,
        }
    }
}

impl VerifyReport {
    /// Whether every invariant holds within `tol` (rigidity over the whole motion included).
    pub fn passes(&self, tol: &Tolerances) -> bool {
        self.geometry_passes(tol) && self.rigid_over_motion
    }

    /// Whether the geometric invariants (isometry, closure, developability, fold angles)
    /// hold on every rigid state: if not, the model computed a wrong shape — a bug, not
    /// a property of the design.
    pub fn geometry_passes(&self, tol: &Tolerances) -> bool {
        self.isometry_max <= tol.isometry
            && self.closure_max <= tol.closure
            && self.developability_max <= tol.developability
            && self.fold_angle_max <= tol.fold_angle
    }

    /// The failed invariants, in words.
    pub fn failures(&self, tol: &Tolerances) -> Vec<String> {
        let mut out = Vec::new();
        if self.isometry_max > tol.isometry {
            out.push(format!(
                "isometry {:.3e} > {:.0e}",
                self.isometry_max, tol.isometry
            ));
        }
        if self.closure_max > tol.closure {
            out.push(format!(
                "closure {:.3e} > {:.0e}",
                self.closure_max, tol.closure
            ));
        }
        if self.developability_max > tol.developability {
            out.push(format!(
                "developability {:.3e} > {:.0e}",
                self.developability_max, tol.developability
            ));
        }
        if self.fold_angle_max > tol.fold_angle {
            out.push(format!(
                "fold angles {:.3e} > {:.0e}",
                self.fold_angle_max, tol.fold_angle
            ));
        }
        if !self.rigid_over_motion {
            out.push(format!(
                "not rigid at t = {:.6} (margin {:.3e})",
                self.min_margin_t, self.min_margin
            ));
        }
        out
    }
}

/// Verify `design` at the states `ts` (the sweep; the last one is taken as t_max for
/// the thesis-style check).
pub fn verify(design: &Evaluated<'_>, ts: &[f64], tol: &Tolerances) -> VerifyReport {
    verify_folded(design, ts, &design.fold_all(ts), tol)
}

/// [`verify`] on states already folded at `ts` (`folds[i]` at `ts[i]`, from
/// [`Evaluated::fold`]): what is checked are those states' geometry and angles.
pub fn verify_folded(
    design: &Evaluated<'_>,
    ts: &[f64],
    folds: &[Folded<f64>],
    tol: &Tolerances,
) -> VerifyReport {
    let plan = design.plan;
    let flat = &design.flat;
    let mut r = VerifyReport {
        isometry_max: 0.0,
        closure_max: 0.0,
        developability_max: developability(plan, flat),
        fold_angle_max: 0.0,
        rigid_over_motion: true,
        rigid_at_tmax: true,
        min_margin: f64::INFINITY,
        min_margin_t: 0.0,
        states: ts.len(),
        rigid_states: 0,
    };
    let flat3: Vec<[f64; 3]> = flat.pos.iter().map(|p| [p[0], p[1], 0.0]).collect();
    // Facets whose flat normal is −z (the same at every state).
    let flat_reversed: Vec<bool> = plan
        .polygons
        .iter()
        .map(|(p, _)| {
            geom::newell_normal(&p.iter().map(|v| flat3[*v]).collect::<Vec<_>>())[2] < 0.0
        })
        .collect();
    for (si, (&t, folded)) in ts.iter().zip(folds).enumerate() {
        // Rigidity first: the geometry of a state is only defined where every vertex is.
        let (rigid, state_margin) = rigidity(plan, folded, t, tol, &mut r);
        if !rigid {
            r.rigid_over_motion = false;
            if si + 1 == ts.len() {
                r.rigid_at_tmax = false;
            }
            continue;
        }
        if state_margin < tol.geometry_margin {
            continue;
        }
        r.rigid_states += 1;
        let x = design.coords(folded);
        isometry(plan, &flat3, &x, &mut r.isometry_max);
        // Closure at every internal vertex.
        let rho: Vec<Option<f64>> = folded.rho.iter().map(|x| Some(*x)).collect();
        for &a in &plan.internal {
            let st = folded.states[a]
                .as_ref()
                .expect("internal vertices are solved");
            if let Some(u) = units(plan, flat, &rho, a) {
                r.closure_max = r.closure_max.max(closure_residual(&u, &st.phi));
            }
        }
        fold_angles(plan, &flat_reversed, folded, &x, &mut r.fold_angle_max);
    }
    r
}

/// The worst deviation of the angles between consecutive creases on the flat
/// coordinates from the model's sectors, or of their sum from 2π, at every internal vertex.
fn developability(plan: &Plan, flat: &Flat<f64>) -> f64 {
    let mut worst = 0.0f64;
    for (i, v) in plan.vertices.iter().enumerate() {
        if !v.internal {
            continue;
        }
        let n = v.rays.len();
        let mut sum = 0.0;
        for k in 0..n {
            let (a, b) = (
                &flat.pos[v.rays[k].other],
                &flat.pos[v.rays[(k + 1) % n].other],
            );
            let o = &flat.pos[i];
            let (u, w) = ([a[0] - o[0], a[1] - o[1]], [b[0] - o[0], b[1] - o[1]]);
            let mut ang = (u[0] * w[1] - u[1] * w[0]).atan2(u[0] * w[0] + u[1] * w[1]);
            if ang <= 0.0 {
                ang += 2.0 * PI;
            }
            sum += ang;
            worst = worst.max((ang - flat.sectors[i][k]).abs());
        }
        worst = worst.max((sum - 2.0 * PI).abs());
    }
    worst
}

/// Whether every internal vertex of the state `folded` at `t` is rigid, and its smallest
/// margin; the report's least margin is updated on the way.
fn rigidity(
    plan: &Plan,
    folded: &Folded<f64>,
    t: f64,
    tol: &Tolerances,
    r: &mut VerifyReport,
) -> (bool, f64) {
    let mut rigid = true;
    let mut state_margin = f64::INFINITY;
    for &a in &plan.internal {
        let st = folded.states[a]
            .as_ref()
            .expect("internal vertices are solved");
        let margin = st.margins.iter().copied().fold(f64::INFINITY, f64::min);
        if margin < r.min_margin {
            r.min_margin = margin;
            r.min_margin_t = t;
        }
        if margin < -tol.margin {
            rigid = false;
        }
        state_margin = state_margin.min(margin);
    }
    (rigid, state_margin)
}

/// Isometry at positions `x`: every facet's pairwise vertex distances against the flat
/// ones (`flat3`), relative to the facet's size; the worst into `worst`.
fn isometry(plan: &Plan, flat3: &[[f64; 3]], x: &[[f64; 3]], worst: &mut f64) {
    for (poly, _) in &plan.polygons {
        let size = poly
            .iter()
            .flat_map(|a| poly.iter().map(move |b| (a, b)))
            .map(|(a, b)| geom::dist(flat3[*a], flat3[*b]))
            .fold(0.0, f64::max);
        for (ia, a) in poly.iter().enumerate() {
            for b in &poly[ia + 1..] {
                let e = (geom::dist(x[*a], x[*b]) - geom::dist(flat3[*a], flat3[*b])).abs()
                    / size.max(1e-300);
                *worst = worst.max(e);
            }
        }
    }
}

/// Fold angles against the facets' normals (`geom::fold_angle`) at positions `x`, each
/// facet's points ordered so its flat normal is +z (`flat_reversed`: an inverted facet is
/// a layout defect the intersection check reports, not a wrong fold angle); the worst
/// disagreement into `worst`.
fn fold_angles(
    plan: &Plan,
    flat_reversed: &[bool],
    folded: &Folded<f64>,
    x: &[[f64; 3]],
    worst: &mut f64,
) {
    let facet_points: Vec<Vec<[f64; 3]>> = plan
        .polygons
        .iter()
        .zip(flat_reversed)
        .map(|((p, _), &reversed)| {
            let mut pts: Vec<[f64; 3]> = p.iter().map(|v| x[*v]).collect();
            if reversed {
                pts.reverse();
            }
            pts
        })
        .collect();
    for (ci, c) in plan.creases.iter().enumerate() {
        let (l, rt) = (&facet_points[c.left], &facet_points[c.right]);
        if l.len() < 3 || rt.len() < 3 {
            continue;
        }
        if let Some(geo) = geom::fold_angle(x[c.tail], x[c.head], l, rt) {
            *worst = worst.max(wrap_angle(geo - folded.rho[ci]).abs());
        }
    }
}
