//! The `[objective]` table: targets the design's vertices should reach (Eq. 37–38,
//! generalized to paths, lines, planes and surfaces; `[[objective.targets]]`, read by
//! [`super::targets`]) and an optional area term to maximize (`[objective.area]`).

use serde::Deserialize;

use super::meshes::Meshes;
use super::targets::{RawTarget, Reader};
use super::terms::{AreaKind, AreaTerm, Objective};
use super::times::{Span, one};
use super::{Ctx, InitialGraph, Motion, Number, TaskError};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawObjective {
    threshold: Option<Number>,
    #[serde(default)]
    targets: Vec<RawTarget>,
    area: Option<RawArea>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawArea {
    kind: String,
    t: Option<Number>,
    weight: Option<Number>,
    at_least: Option<Number>,
}

/// The objective; its targets' t must lie in the motion range, so it needs `[motion]`.
pub(crate) fn build(
    cx: &Ctx<'_>,
    raw: Option<&RawObjective>,
    motion: Option<Motion>,
    g0: &InitialGraph,
    meshes: &mut Meshes<'_>,
) -> Result<Option<Objective>, TaskError> {
    let Some(o) = raw else { return Ok(None) };
    let Some(motion) = motion else {
        return Err(cx.err(
            "objective",
            "an objective needs the motion range: add [motion] with t_max",
        ));
    };
    let span = Span::of(motion);
    if o.targets.is_empty() && o.area.is_none() {
        return Err(cx.err(
            "objective.targets",
            "no targets: give at least one [[objective.targets]] with t and a goal (point, line, plane or surface), or an [objective.area] term",
        ));
    }
    let threshold = match &o.threshold {
        Some(n) => cx.num("objective.threshold", n)?,
        // Without targets Ω is 0: any threshold is met.
        None if o.targets.is_empty() => 0.0,
        None => {
            return Err(cx.err(
                "objective.threshold",
                "missing: Ω ≤ threshold meets the target; give threshold ≥ 0",
            ));
        }
    };
    if threshold < 0.0 {
        return Err(cx.err(
            "objective.threshold",
            format!("{threshold} is not allowed: the threshold must be ≥ 0"),
        ));
    }
    cx.entries("objective.targets", o.targets.len())?;
    let mut reader = Reader {
        cx,
        g0,
        span,
        meshes,
        surfaces: Vec::new(),
    };
    let mut targets = Vec::with_capacity(o.targets.len());
    for (i, t) in o.targets.iter().enumerate() {
        targets.extend(reader.read(i, t)?);
        let max = crate::limits::TARGETS_MAX;
        if targets.len() > max {
            return Err(cx.err(
                format!("objective.targets[{i}]"),
                format!(
                    "{} targets with the samples of the entries up to this one: a task has at most {max}",
                    targets.len()
                ),
            ));
        }
    }
    let area = o.area.as_ref().map(|a| area(cx, a, span)).transpose()?;
    Ok(Some(Objective {
        targets,
        threshold,
        surfaces: reader.surfaces,
        area,
    }))
}

/// `[objective.area]`: the kind (and packing's state), a weight > 0, a floor ≥ 0.
fn area(cx: &Ctx<'_>, a: &RawArea, span: Span) -> Result<AreaTerm, TaskError> {
    let kind = match (a.kind.as_str(), &a.t) {
        ("flat", None) => AreaKind::Flat,
        ("flat", Some(_)) => {
            return Err(cx.err(
                "objective.area.t",
                "t is only for kind = \"packing\" (the flat area does not depend on the state): drop it",
            ));
        }
        ("packing", Some(t)) => AreaKind::Packing {
            t: one(cx, "objective.area.t", t, span)?,
        },
        ("packing", None) => {
            return Err(cx.err(
                "objective.area.t",
                "missing: kind = \"packing\" needs t, the state whose bounding box counts",
            ));
        }
        (other, _) => {
            return Err(cx.err(
                "objective.area.kind",
                format!(
                    "unknown kind \"{}\": allowed \"flat\" (the flat pattern's area) or \"packing\" (flat area over the folded footprint at t)",
                    crate::text::excerpt(other, 40)
                ),
            ));
        }
    };
    let weight = match &a.weight {
        None => 1.0,
        Some(w) => cx.positive("objective.area.weight", w)?,
    };
    let at_least = match &a.at_least {
        None => 0.0,
        Some(n) => cx.num("objective.area.at_least", n)?,
    };
    if at_least < 0.0 {
        return Err(cx.err(
            "objective.area.at_least",
            format!(
                "{} is not allowed: at_least must be ≥ 0 (an area is never negative)",
                crate::text::num(at_least)
            ),
        ));
    }
    Ok(AreaTerm {
        kind,
        weight,
        at_least,
    })
}
