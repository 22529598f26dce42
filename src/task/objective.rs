//! The `[objective]` table: points the gripping vertex should reach (Eq. 37–38).

use serde::Deserialize;

use super::terms::{Goal, Objective, Target, VertexRef};
use super::{Ctx, Motion, Number, TaskError};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawObjective {
    threshold: Number,
    targets: Vec<RawTarget>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTarget {
    t: Number,
    point: Vec<Number>,
    weight: Option<Number>,
}

/// The objective; its targets' t must lie in the motion range, so it needs `[motion]`.
pub(crate) fn build(
    cx: &Ctx<'_>,
    raw: Option<&RawObjective>,
    motion: Option<Motion>,
) -> Result<Option<Objective>, TaskError> {
    let Some(o) = raw else { return Ok(None) };
    let Some(motion) = motion else {
        return Err(cx.err(
            "objective",
            "an objective needs the motion range: add [motion] with t_max",
        ));
    };
    let threshold = cx.num("objective.threshold", &o.threshold)?;
    if threshold < 0.0 {
        return Err(cx.err(
            "objective.threshold",
            format!("{threshold} is not allowed: the threshold must be ≥ 0"),
        ));
    }
    if o.targets.is_empty() {
        return Err(cx.err(
            "objective.targets",
            "no targets: give at least one [[objective.targets]] with t and point",
        ));
    }
    let (lo, hi) = if motion.t_max > 0.0 {
        (0.0, motion.t_max)
    } else {
        (motion.t_max, 0.0)
    };
    let mut targets = Vec::with_capacity(o.targets.len());
    for (i, t) in o.targets.iter().enumerate() {
        targets.push(target(cx, i, t, lo, hi)?);
    }
    Ok(Some(Objective {
        targets,
        threshold,
        surfaces: Vec::new(),
        area: None,
    }))
}

/// Target `i`, its t within [lo, hi].
fn target(cx: &Ctx<'_>, i: usize, t: &RawTarget, lo: f64, hi: f64) -> Result<Target, TaskError> {
    let f = format!("objective.targets[{i}]");
    let tv = cx.num(&format!("{f}.t"), &t.t)?;
    if tv < lo - 1e-12 || tv > hi + 1e-12 {
        return Err(cx.err(
            format!("{f}.t"),
            format!("{tv} is outside the motion range [{lo}, {hi}]"),
        ));
    }
    let point = cx.point(&format!("{f}.point"), &t.point)?;
    let weight = match &t.weight {
        None => 1.0,
        Some(w) => cx.num(&format!("{f}.weight"), w)?,
    };
    if weight <= 0.0 {
        return Err(cx.err(
            format!("{f}.weight"),
            format!("{weight} is not allowed: weights must be > 0"),
        ));
    }
    Ok(Target {
        t: tv,
        vertex: VertexRef::Tip,
        goal: Goal::Point { point },
        weight,
        entry: i,
    })
}
