//! The `[bounds]` table: the bounds of the optimization variables (Eq. 31–32).

use serde::Deserialize;

use super::{Ctx, Number, TaskError};

/// Bounds of the optimization variables.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Shortest crease length, > 0.
    pub l_min: f64,
    /// Longest crease length, > l_min.
    pub l_max: f64,
    /// Smallest sector angle, in (0, α_max).
    pub alpha_min: f64,
    /// Largest sector angle, in (α_min, π).
    pub alpha_max: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawBounds {
    l_min: Number,
    l_max: Number,
    alpha_min: Number,
    alpha_max: Number,
}

pub(crate) fn build(cx: &Ctx<'_>, raw: Option<&RawBounds>) -> Result<Option<Bounds>, TaskError> {
    let Some(b) = raw else { return Ok(None) };
    let l_min = cx.num("bounds.l_min", &b.l_min)?;
    let l_max = cx.num("bounds.l_max", &b.l_max)?;
    let alpha_min = cx.num("bounds.alpha_min", &b.alpha_min)?;
    let alpha_max = cx.num("bounds.alpha_max", &b.alpha_max)?;
    if l_min <= 0.0 {
        return Err(cx.err(
            "bounds.l_min",
            format!("{l_min} is not allowed: lengths must be > 0"),
        ));
    }
    if l_max <= l_min {
        return Err(cx.err(
            "bounds.l_max",
            format!("{l_max} is not allowed: l_max must exceed l_min = {l_min}"),
        ));
    }
    if !(alpha_min > 0.0 && alpha_min < std::f64::consts::PI) {
        return Err(cx.err(
            "bounds.alpha_min",
            format!("{alpha_min} is not allowed: sector angles lie in (0, pi)"),
        ));
    }
    if !(alpha_max > alpha_min && alpha_max < std::f64::consts::PI) {
        return Err(cx.err(
            "bounds.alpha_max",
            format!(
                "{alpha_max} is not allowed: alpha_max must lie in (alpha_min = {alpha_min}, pi)"
            ),
        ));
    }
    Ok(Some(Bounds {
        l_min,
        l_max,
        alpha_min,
        alpha_max,
    }))
}
