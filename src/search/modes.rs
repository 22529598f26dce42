//! Every rigid body mode assignment of one design's geometry (thesis Sec. 4.3.2, the star
//! pattern's 2^8 = 256 folded shapes for one actuation): one mode per internal vertex,
//! images of a symmetric pattern included (each folds by its own PTU, no longer like its
//! representative), each judged as the search judges a design: rigid over the dense sweep
//! (Eq. 25 at every state, not only at t_max), free of self-intersection between every
//! pair of facets of the whole sheet, and clear of the task's obstacles.

use super::evaluate::{CheckFailure, check_intersections};
use super::measure::judged_times;
use super::options::SearchOptions;
use crate::check::verify::{Tolerances, verify_folded};
use crate::model::Model;
use crate::model::numeric::Evaluated;
use crate::task::Task;
use serde::Serialize;

/// The most internal vertices whose assignments [`census`] enumerates (2^16 shapes).
pub const MAX_VERTICES: usize = 16;

/// One mode assignment of a [`census`].
#[derive(Clone, Debug, Serialize)]
pub struct ModeVerdict {
    /// "up"/"down" per internal vertex, in [`Plan::internal`](crate::model::Plan) order.
    pub modes: Vec<&'static str>,
    /// Every vertex rigidly foldable (Eq. 25) at every state of the sweep.
    pub rigid_over_motion: bool,
    /// No two facets cross at any state (judged only where the motion is rigid).
    pub self_intersection_free: Option<bool>,
    /// Clear of every obstacle of the task (judged only where the motion is rigid).
    pub obstacle_free: Option<bool>,
}

impl ModeVerdict {
    /// Rigid, intersection-free and clear of the obstacles: a shape the design can fold.
    pub fn folds(&self) -> bool {
        self.rigid_over_motion
            && self.self_intersection_free == Some(true)
            && self.obstacle_free == Some(true)
    }
}

/// Judge every assignment of one mode per internal vertex of `model`'s pattern at the
/// free variables `x`, over `sweep` states of [0, t_max]. An error when the pattern has
/// more than [`MAX_VERTICES`] internal vertices.
pub fn census(
    task: &Task,
    model: &Model,
    x: &[f64],
    sweep: usize,
) -> Result<Vec<ModeVerdict>, String> {
    let plan = model.plan.clone().with_vertex_modes();
    let n = plan.internal.len();
    if n > MAX_VERTICES {
        return Err(format!(
            "the pattern has {n} internal vertices: 2^{n} mode assignments are more than the 2^{MAX_VERTICES} this enumerates"
        ));
    }
    let full = model.full_vars(x);
    let sweep_t = judged_times(task, model.t_max, sweep);
    let opts = SearchOptions {
        sweep,
        ..SearchOptions::default()
    };
    let tol = Tolerances::default();
    let mut out = Vec::with_capacity(1 << n);
    for bits in 0..(1u32 << n) {
        let modes: Vec<f64> = (0..n)
            .map(|i| if bits >> i & 1 == 1 { -1.0 } else { 1.0 })
            .collect();
        let design = Evaluated::new(&plan, full.clone(), modes.clone());
        let folds = design.fold_all(&sweep_t);
        let report = verify_folded(&design, &sweep_t, &folds, &tol);
        let rigid = report.rigid_over_motion;
        let (mut free, mut clear) = (None, None);
        if rigid {
            match check_intersections(task, &design.pattern_of(&sweep_t, &folds), &opts) {
                Ok((s, hit, _)) => {
                    free = Some(s.self_intersection_free());
                    clear = Some(hit.is_none());
                }
                Err(CheckFailure::Layout(_)) => free = Some(false),
                Err(CheckFailure::Other(e)) => return Err(e),
            }
        }
        out.push(ModeVerdict {
            modes: modes
                .iter()
                .map(|&m| if m > 0.0 { "up" } else { "down" })
                .collect(),
            rigid_over_motion: rigid,
            self_intersection_free: free,
            obstacle_free: clear,
        });
    }
    Ok(out)
}
