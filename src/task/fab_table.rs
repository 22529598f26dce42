//! The `[fabrication]` table of a task file (issue 32): the sheet's thickness and the scale
//! read into a validated [`Fabrication`]; absent, the task designs zero-thickness facets.
//!
//! ```toml
//! [fabrication]
//! thickness = 2        # mm (required)
//! scale = 100          # mm per paper unit (required)
//! method = "tapered"   # default
//! sides = "one"        # "one" or "both", default "one"
//! hinge_gap = 0.5      # mm, default 0.5
//! min_width = 2        # mm, default 2
//! kerf = 0.15          # mm, default 0: cuts offset by half of it
//! tab_width = 1        # mm, default 0: no tabs
//! hole = 3             # mm, default 3: alignment-hole diameter
//! sheet = "600x400"    # mm, default: the pattern's bounds plus a margin
//! ```

use super::fabrication::{
    DEFAULT_HINGE_GAP_MM, DEFAULT_HOLE_MM, DEFAULT_MIN_WIDTH_MM, FabMethod, Fabrication, Laminate,
    Sides,
};
use super::{Ctx, InitialGraph, Number, Robustness, TaskError, robustness::unit_length};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawFabrication {
    thickness: Option<Number>,
    scale: Option<Number>,
    method: Option<String>,
    sides: Option<String>,
    hinge_gap: Option<Number>,
    min_width: Option<Number>,
    kerf: Option<Number>,
    tab_width: Option<Number>,
    hole: Option<Number>,
    sheet: Option<String>,
}

/// One name out of `names`, or an error naming the field and listing them.
fn choice<T>(
    cx: &Ctx<'_>,
    field: &str,
    given: Option<&str>,
    default: T,
    from: impl Fn(&str) -> Option<T>,
    names: &[&str],
) -> Result<T, TaskError> {
    let Some(name) = given else {
        return Ok(default);
    };
    from(name).ok_or_else(|| {
        cx.err(
            field,
            format!(
                "{:?} is not a known value: allowed {}",
                crate::text::excerpt(name, 40),
                names
                    .iter()
                    .map(|n| format!("\"{n}\""))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )
    })
}

/// The validated table, `None` when the task has none. Besides each value's own range, the
/// panels must fit the pattern: twice their reach plus the clearance (what the optimizer
/// keeps between facets) and the narrowest panel must stay below G0's shortest crease.
pub(crate) fn build(
    cx: &Ctx<'_>,
    raw: Option<&RawFabrication>,
    g0: &InitialGraph,
    robustness: &Robustness,
) -> Result<Option<Fabrication>, TaskError> {
    let Some(raw) = raw else { return Ok(None) };
    let required = |field: &str, n: &Option<Number>, what: &str| -> Result<f64, TaskError> {
        let Some(n) = n else {
            return Err(cx.err(field, format!("missing: [fabrication] needs {what}")));
        };
        cx.num(field, n)
    };
    let optional = |field: &str, n: &Option<Number>, default: f64| match n {
        Some(n) => cx.num(field, n),
        None => Ok(default),
    };
    let spec = Fabrication {
        thickness: required(
            "fabrication.thickness",
            &raw.thickness,
            "the panels' thickness in mm",
        )?,
        scale: required(
            "fabrication.scale",
            &raw.scale,
            "the scale in mm per paper unit (G0's crease = 1)",
        )?,
        method: choice(
            cx,
            "fabrication.method",
            raw.method.as_deref(),
            FabMethod::Tapered,
            FabMethod::from_name,
            &FabMethod::NAMES,
        )?,
        sides: choice(
            cx,
            "fabrication.sides",
            raw.sides.as_deref(),
            Sides::One,
            Sides::from_name,
            &Sides::NAMES,
        )?,
        hinge_gap: optional(
            "fabrication.hinge_gap",
            &raw.hinge_gap,
            DEFAULT_HINGE_GAP_MM,
        )?,
        min_width: optional(
            "fabrication.min_width",
            &raw.min_width,
            DEFAULT_MIN_WIDTH_MM,
        )?,
    };
    spec.validate()
        .map_err(|(field, m)| cx.err(format!("fabrication.{field}"), m))?;
    let unit = unit_length(g0);
    let needed = 2.0 * spec.reach_units() + robustness.clearance;
    if needed >= unit {
        return Err(cx.err(
            "fabrication.thickness",
            format!(
                "{} mm at {} mm per paper unit leaves no panel: two panels' reach plus the clearance is {} paper units, not below G0's shortest crease {} (allowed: thickness/scale < ({} − clearance)/{})",
                crate::text::num(spec.thickness),
                crate::text::num(spec.scale),
                crate::text::num(needed),
                crate::text::num(unit),
                crate::text::num(unit),
                if spec.sides == Sides::One { 2 } else { 1 },
            ),
        ));
    }
    if spec.min_width / spec.scale >= unit {
        return Err(cx.err(
            "fabrication.min_width",
            format!(
                "{} mm is {} paper units, not below G0's shortest crease {}: no panel can be that wide",
                crate::text::num(spec.min_width),
                crate::text::num(spec.min_width / spec.scale),
                crate::text::num(unit),
            ),
        ));
    }
    Ok(Some(spec))
}

/// The laminate's layout from the table's optional `kerf`, `tab_width`, `hole` and `sheet`
/// (the defaults without a table); errors name the field and what is allowed.
pub(crate) fn laminate(cx: &Ctx<'_>, raw: Option<&RawFabrication>) -> Result<Laminate, TaskError> {
    let Some(raw) = raw else {
        return Ok(Laminate::default());
    };
    let optional = |field: &str, n: &Option<Number>, default: f64| match n {
        Some(n) => cx.num(field, n),
        None => Ok(default),
    };
    let sheet = match &raw.sheet {
        Some(text) => {
            Some(Laminate::parse_sheet(text).map_err(|m| cx.err("fabrication.sheet", m))?)
        }
        None => None,
    };
    let lam = Laminate {
        kerf: optional("fabrication.kerf", &raw.kerf, 0.0)?,
        tab_width: optional("fabrication.tab_width", &raw.tab_width, 0.0)?,
        hole: optional("fabrication.hole", &raw.hole, DEFAULT_HOLE_MM)?,
        sheet,
    };
    lam.validate()
        .map_err(|(field, m)| cx.err(format!("fabrication.{field}"), m))?;
    Ok(lam)
}
