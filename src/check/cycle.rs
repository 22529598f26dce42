//! Verification of cyclic designs (r2′) over a dense sweep, by code that shares nothing
//! with the model's compatibility constraints (`model::cycle`).
//!
//! - compatibility residual: the two dihedral angles the PTU gives the straight crease of
//!   every r2′ sink (one from each end), their difference wrapped into (−π, π];
//! - position disagreement: every vertex read through *every* facet that contains it,
//!   against its reading through its home facet. On an acyclic design this is closure in
//!   disguise (rounding); on a cyclic one it is exactly where the two paths around the
//!   cycle meet or miss.
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
}

impl CycleReport {
    /// Both measures within `tol` on every checked state, and some state checked.
    /// Rigidity over the motion is [`super::verify`]'s verdict: a state left unchecked here
    /// is either not rigid (and fails there) or has a degenerate vertex triangle, as the
    /// flat state of every flat-foldable vertex does.
    pub fn passes(&self, tol: f64) -> bool {
        self.checked_states > 0 && self.compatibility_max <= tol && self.position_max <= tol
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
    };
    for &t in ts {
        let folded = design.fold(t);
        let rigid = plan.internal.iter().all(|&a| {
            folded.states[a]
                .as_ref()
                .is_some_and(|s| s.margins.iter().all(|m| *m >= geometry_margin))
        });
        if !rigid {
            continue;
        }
        r.checked_states += 1;
        for s in &plan.sinks {
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
