//! The `[motion]` table: the range of the driving parameter.

use serde::Deserialize;

use super::{Ctx, Number, TaskError};

/// The driving parameter t runs from 0 to `t_max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// End of the motion, in radians, nonzero, |t_max| ≤ π.
    pub t_max: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawMotion {
    t_max: Number,
}

pub(crate) fn build(cx: &Ctx<'_>, raw: Option<&RawMotion>) -> Result<Option<Motion>, TaskError> {
    let Some(m) = raw else { return Ok(None) };
    let t_max = cx.num("motion.t_max", &m.t_max)?;
    if t_max == 0.0 || t_max.abs() > std::f64::consts::PI + 1e-12 {
        return Err(cx.err(
            "motion.t_max",
            format!("{t_max} is not allowed: t_max must be nonzero and within [-pi, pi]"),
        ));
    }
    Ok(Some(Motion { t_max }))
}
