//! Checks over a whole folding motion: the flat layout, then evenly spaced states.

use serde::{Deserialize, Serialize};

use super::cylinder::Cylinder;
use super::self_intersection::{CheckError, Checker, Intersection, ObstacleHit, StateTracker};
use crate::pattern::Pattern;

/// Settings of a motion check.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MotionSettings {
    /// Number of evenly spaced states over `[t_start, t_end]`, both ends included
    /// (the thesis uses 16, Sec. 5.4.2). At least 2.
    pub n_states: usize,
    /// Stop at the first intersection or obstacle hit instead of collecting all.
    pub stop_at_first: bool,
    /// Obstacles every facet must stay out of.
    pub obstacles: Vec<Cylinder>,
}

impl Default for MotionSettings {
    fn default() -> Self {
        MotionSettings {
            n_states: 16,
            stop_at_first: false,
            obstacles: Vec::new(),
        }
    }
}

/// What a motion check found.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MotionReport {
    /// The driving parameters of the states checked, in order.
    pub states: Vec<f64>,
    /// Self-intersections, in the order found (state by state).
    pub intersections: Vec<Intersection>,
    /// Obstacle hits, in the order found.
    pub obstacle_hits: Vec<ObstacleHit>,
}

impl MotionReport {
    /// The first self-intersection, if any.
    pub fn first_intersection(&self) -> Option<&Intersection> {
        self.intersections.first()
    }

    /// The first obstacle hit, if any.
    pub fn first_obstacle_hit(&self) -> Option<&ObstacleHit> {
        self.obstacle_hits.first()
    }

    /// True when the motion is free of self-intersection.
    pub fn self_intersection_free(&self) -> bool {
        self.intersections.is_empty()
    }

    /// True when the motion is free of self-intersection and clears every obstacle.
    pub fn clear(&self) -> bool {
        self.intersections.is_empty() && self.obstacle_hits.is_empty()
    }
}

/// Check a motion given as a function `t ↦ vertex positions`: first the flat `layout` for
/// overlapping facets (reported at `t_start`), then `settings.n_states` evenly spaced
/// states over `[t_start, t_end]` for crossings, flips and obstacle hits.
pub fn check_motion<F>(
    checker: &Checker,
    layout: &[[f64; 2]],
    mut state: F,
    t_start: f64,
    t_end: f64,
    settings: &MotionSettings,
) -> Result<MotionReport, CheckError>
where
    F: FnMut(f64) -> Vec<[f64; 3]>,
{
    let n = settings.n_states.max(2);
    let ts: Vec<f64> = (0..n)
        .map(|k| t_start + (t_end - t_start) * k as f64 / (n - 1) as f64)
        .collect();
    check_states(
        checker,
        Some(layout),
        ts.iter().map(|&t| (t, state(t))),
        settings,
    )
}

/// Check every frame of a pattern in order (the producer of the frames chose the states),
/// after the flat layout. `settings.n_states` is not used.
pub fn check_frames(
    pattern: &Pattern,
    settings: &MotionSettings,
) -> Result<MotionReport, CheckError> {
    let checker = Checker::from_pattern(pattern)?;
    check_states(
        &checker,
        Some(&pattern.vertices),
        pattern.frames.iter().map(|f| (f.t, f.coords.clone())),
        settings,
    )
}

/// Check a sequence of `(t, positions)` states in order, optionally after a flat layout
/// (whose overlaps are reported at the first state's `t`).
pub fn check_states<I>(
    checker: &Checker,
    layout: Option<&[[f64; 2]]>,
    states: I,
    settings: &MotionSettings,
) -> Result<MotionReport, CheckError>
where
    I: IntoIterator<Item = (f64, Vec<[f64; 3]>)>,
{
    let mut report = MotionReport::default();
    let mut tracker = StateTracker::new(checker);
    let first = settings.stop_at_first;
    let mut flat_done = layout.is_none();
    for (t, coords) in states {
        if !flat_done {
            flat_done = true;
            if let Some(layout) = layout {
                report
                    .intersections
                    .extend(checker.flat_overlaps(layout, t, first));
                if first && !report.intersections.is_empty() {
                    return Ok(report);
                }
            }
        }
        checker.validate_state(&coords, t)?;
        report.states.push(t);
        report.intersections.extend(tracker.step(&coords, t, first));
        for (k, cyl) in settings.obstacles.iter().enumerate() {
            report
                .obstacle_hits
                .extend(checker.obstacle_hits(&coords, cyl, k, t, first));
        }
        if first && !(report.intersections.is_empty() && report.obstacle_hits.is_empty()) {
            break;
        }
    }
    Ok(report)
}
