//! Verification of cyclic designs (r2′) over a dense sweep, by code that shares nothing
//! with the model's compatibility constraints (`model::cycle`).
//!
//! - compatibility residual: the two dihedral angles the PTU gives the straight crease of
//!   every r2′ sink (one from each end), their difference wrapped into (−π, π];
//! - position disagreement: every vertex read through *every* facet that contains it,
//!   against its reading through its home facet. On an acyclic design this is closure in
//!   disguise (rounding); on a cyclic one it is exactly where the two paths around the
//!   cycle meet or miss;
//! - continuity: no fold angle jumps between consecutive states (from the flat state on),
//!   so that the states checked are one motion, not a branch reached by a jump.
//!
//! Only states on which every internal vertex is rigid (margin at least the geometry
//! margin of [`super::verify::Tolerances`]) have a configuration to check; the others are
//! counted. The PTU alone cannot certify motion between states: the bar-and-hinge
//! simulation (`simulate::crossval`) is the last word.

use crate::kinematics::wrap_angle;
use crate::model::geometry::{position, position_on};
use crate::model::numeric::Evaluated;
use serde::{Deserialize, Serialize};

/// Largest compatibility residual (rad) and position disagreement (paper units) of a
/// passing cyclic design.
pub const CYCLE_TOL: f64 = 1e-9;

/// Largest change of any fold angle between consecutive states of the sweep (rad) of a
/// continuous motion. A dense sweep (181 states over π/2: 0.0087 rad of the driving angle
/// per step) moves a smooth fold angle by a small multiple of that; a branch of the PTU
/// that sets a crease to ±π for every t > 0 (a straight line folded flat at once, which
/// makes a cycle compatible trivially) jumps by π right after the flat state.
pub const JUMP_TOL: f64 = 0.5;

/// What the sweep found.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CycleReport {
    /// Number of r2′ sinks.
    pub sinks: usize,
    /// States swept.
    pub states: usize,
    /// States on which every internal vertex is rigid (the ones checked).
    pub checked_states: usize,
    /// Largest |ρ(p1, v′) − ρ(p2, v′)| (wrapped) over sinks and checked states.
    pub compatibility_max: f64,
    /// Where it occurs.
    pub compatibility_t: f64,
    /// Largest distance between two readings of one vertex through two of its facets.
    pub position_max: f64,
    /// Where it occurs.
    pub position_t: f64,
    /// Largest change of a fold angle between consecutive checked states, from the flat
    /// state on, per sweep step between them (wrapped; the motion is continuous when it is
    /// small, see [`JUMP_TOL`]).
    #[serde(default)]
    pub jump_max: f64,
    /// The t after which it occurs.
    #[serde(default)]
    pub jump_t: f64,
    /// Largest |fold angle| of a sink's straight crease over the checked states. Near 0,
    /// the cycle closes trivially: the shared crease never folds (both ends fold about
    /// other lines), and the pattern moves like an acyclic one.
    #[serde(default)]
    pub shared_fold_max: f64,
}

impl CycleReport {
    /// Both measures within `tol` on every checked state, and some state checked.
    /// Rigidity over the motion is [`super::verify`]'s verdict: a state left unchecked here
    /// is either not rigid (and fails there) or has a degenerate vertex triangle, as the
    /// flat state of every flat-foldable vertex does.
    pub fn passes(&self, tol: f64) -> bool {
        self.checked_states > 0
            && self.compatibility_max <= tol
            && self.position_max <= tol
            && self.jump_max <= JUMP_TOL
    }

    /// Whether some sink's straight crease really folds (see
    /// [`CycleReport::shared_fold_max`]; 1e-6 rad).
    pub fn folds_shared_crease(&self) -> bool {
        self.shared_fold_max > 1e-6
    }

    /// The failed conditions, in words.
    pub fn failures(&self, tol: f64) -> Vec<String> {
        let mut out = Vec::new();
        if self.checked_states == 0 {
            out.push(format!("none of {} states is rigid", self.states));
        }
        if self.compatibility_max > tol {
            out.push(format!(
                "compatibility {:.3e} > {tol:.0e} at t = {:.6}",
                self.compatibility_max, self.compatibility_t
            ));
        }
        if self.position_max > tol {
            out.push(format!(
                "positions {:.3e} > {tol:.0e} at t = {:.6}",
                self.position_max, self.position_t
            ));
        }
        if self.jump_max > JUMP_TOL {
            out.push(format!(
                "a fold angle jumps by {:.3} rad after t = {:.6}: not one continuous motion",
                self.jump_max, self.jump_t
            ));
        }
        out
    }
}

/// Sweep `design` over the states `ts`; `geometry_margin` as in
/// [`super::verify::Tolerances::geometry_margin`].
pub fn verify_cycles(design: &Evaluated<'_>, ts: &[f64], geometry_margin: f64) -> CycleReport {
    let plan = design.plan;
    let mut r = CycleReport {
        sinks: plan.sinks.len(),
        states: ts.len(),
        checked_states: 0,
        compatibility_max: 0.0,
        compatibility_t: 0.0,
        position_max: 0.0,
        position_t: 0.0,
        jump_max: 0.0,
        jump_t: 0.0,
        shared_fold_max: 0.0,
    };
    // Fold angles of the previous checked state, from the flat one (all creases at 0; the
    // PTU's own flat state can be degenerate, e.g. a flat-foldable vertex at t = 0, and is
    // then not checked), and the number of sweep steps since it.
    let mut prev: (f64, Vec<f64>) = (0.0, vec![0.0; plan.creases.len()]);
    let mut steps: u32 = 0;
    for &t in ts {
        let folded = design.fold(t);
        if t > 0.0 {
            steps += 1;
        }
        let rigid = plan.internal.iter().all(|&a| {
            folded.states[a]
                .as_ref()
                .is_some_and(|s| s.margins.iter().all(|m| *m >= geometry_margin))
        });
        if !rigid {
            continue;
        }
        r.checked_states += 1;
        // Per sweep step, so that unchecked states in between do not count as a jump.
        for (a, b) in folded.rho.iter().zip(&prev.1) {
            let d = wrap_angle(a - b).abs() / f64::from(steps.max(1));
            if d > r.jump_max || d.is_nan() {
                r.jump_max = if d.is_nan() { f64::INFINITY } else { d };
                r.jump_t = prev.0;
            }
        }
        prev = (t, folded.rho.clone());
        steps = 0;
        for s in &plan.sinks {
            r.shared_fold_max = r
                .shared_fold_max
                .max(wrap_angle(folded.rho[s.creases[0]]).abs());
            let d = wrap_angle(folded.rho[s.creases[0]] - folded.rho[s.creases[1]]).abs();
            if d > r.compatibility_max || d.is_nan() {
                r.compatibility_max = if d.is_nan() { f64::INFINITY } else { d };
                r.compatibility_t = t;
            }
        }
        for (f, (poly, _)) in plan.polygons.iter().enumerate() {
            for &v in poly {
                let home = position(plan, &design.flat, &folded, v);
                let here = position_on(&design.flat, &folded, v, f);
                let d = (0..3)
                    .map(|k| (home[k] - here[k]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                if d > r.position_max || d.is_nan() {
                    r.position_max = if d.is_nan() { f64::INFINITY } else { d };
                    r.position_t = t;
                }
            }
        }
    }
    r
}
