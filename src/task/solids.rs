//! The solids a task file writes, checked: cylinders, spheres, boxes (axis-aligned or
//! oriented), half-spaces. Shared by `[[obstacles]]`, the legacy `[[check.cylinders]]` and
//! `[[constraints.inside]]`; each takes the entry's TOML path and names its fields.

use super::{Ctx, Number, TaskError};
use crate::scene::shapes::frame;
use crate::scene::{Cylinder, HalfSpace, OrientedBox, Sphere};

/// A value the entry must give.
pub(crate) fn need<'a, T: ?Sized>(
    cx: &Ctx<'_>,
    entry: &str,
    key: &str,
    what: &str,
    v: Option<&'a T>,
) -> Result<&'a T, TaskError> {
    v.ok_or_else(|| cx.err(format!("{entry}.{key}"), format!("missing: {what}")))
}

/// A cylinder: a positive radius, an axis of two distinct points.
pub(crate) fn cylinder(
    cx: &Ctx<'_>,
    f: &str,
    radius: &Number,
    from: &[Number],
    to: &[Number],
) -> Result<Cylinder, TaskError> {
    let radius = cx.num(&format!("{f}.radius"), radius)?;
    if radius <= 0.0 {
        return Err(cx.err(
            format!("{f}.radius"),
            format!("{radius} is not allowed: the radius must be > 0"),
        ));
    }
    let from = cx.point(&format!("{f}.from"), from)?;
    let to = cx.point(&format!("{f}.to"), to)?;
    if from == to {
        return Err(cx.err(
            format!("{f}.to"),
            "the axis end equals its start: the axis needs two distinct points",
        ));
    }
    Ok(Cylinder {
        a: from,
        b: to,
        radius,
    })
}

/// A sphere: a centre and a positive radius.
pub(crate) fn sphere(
    cx: &Ctx<'_>,
    f: &str,
    center: &[Number],
    radius: &Number,
) -> Result<Sphere, TaskError> {
    Ok(Sphere {
        center: cx.point(&format!("{f}.center"), center)?,
        radius: cx.positive(&format!("{f}.radius"), radius)?,
    })
}

/// A half-space: a point of its boundary and the normal into free space.
pub(crate) fn halfspace(
    cx: &Ctx<'_>,
    f: &str,
    point: &[Number],
    normal: &[Number],
) -> Result<HalfSpace, TaskError> {
    Ok(HalfSpace {
        point: cx.point(&format!("{f}.point"), point)?,
        normal: cx.direction(&format!("{f}.normal"), normal)?,
    })
}

/// A box's fields as an entry gives them: `min`, `max` (axis-aligned) or `center`,
/// `half_extents`, `x_axis`, `y_axis` (oriented; the axes default to x and y).
#[derive(Clone, Copy, Default)]
pub(crate) struct BoxFields<'a> {
    pub(crate) min: Option<&'a [Number]>,
    pub(crate) max: Option<&'a [Number]>,
    pub(crate) center: Option<&'a [Number]>,
    pub(crate) half_extents: Option<&'a [Number]>,
    pub(crate) x_axis: Option<&'a [Number]>,
    pub(crate) y_axis: Option<&'a [Number]>,
}

/// The forms a box is written in, for messages.
const BOX_FORMS: &str = "min = [x, y, z] and max = [x, y, z] (axis-aligned), or center, half_extents and optionally x_axis, y_axis (oriented)";

/// A box with volume, in either form (one form only).
pub(crate) fn oriented_box(
    cx: &Ctx<'_>,
    f: &str,
    b: BoxFields<'_>,
) -> Result<OrientedBox, TaskError> {
    let aligned = b.min.is_some() || b.max.is_some();
    let oriented = [b.center, b.half_extents, b.x_axis, b.y_axis]
        .iter()
        .any(Option::is_some);
    if aligned && oriented {
        let key = if b.center.is_some() {
            "center"
        } else if b.half_extents.is_some() {
            "half_extents"
        } else if b.x_axis.is_some() {
            "x_axis"
        } else {
            "y_axis"
        };
        return Err(cx.err(
            format!("{f}.{key}"),
            format!("a box is written in one form, not both: {BOX_FORMS}"),
        ));
    }
    if aligned {
        let min = cx.point::<3>(&format!("{f}.min"), need(cx, f, "min", BOX_FORMS, b.min)?)?;
        let max = cx.point::<3>(&format!("{f}.max"), need(cx, f, "max", BOX_FORMS, b.max)?)?;
        for i in 0..3 {
            if max[i] <= min[i] {
                return Err(cx.err(
                    format!("{f}.max[{i}]"),
                    format!(
                        "{} ≤ min[{i}] = {}: max must exceed min on every axis (a box needs volume)",
                        crate::text::num(max[i]),
                        crate::text::num(min[i])
                    ),
                ));
            }
        }
        let bx = OrientedBox::aligned(min, max);
        // Ends a few ulps apart leave no half extent once halved.
        if let Some(i) = (0..3).find(|&i| bx.half[i] <= 0.0) {
            return Err(cx.err(
                format!("{f}.max[{i}]"),
                "max and min are too close: the box has no extent on this axis",
            ));
        }
        return Ok(bx);
    }
    let center = cx.point::<3>(
        &format!("{f}.center"),
        need(cx, f, "center", BOX_FORMS, b.center)?,
    )?;
    let half = cx.point::<3>(
        &format!("{f}.half_extents"),
        need(cx, f, "half_extents", BOX_FORMS, b.half_extents)?,
    )?;
    if let Some(i) = (0..3).find(|&i| half[i] <= 0.0) {
        return Err(cx.err(
            format!("{f}.half_extents[{i}]"),
            format!(
                "{} is not allowed: every half extent must be > 0 (a box needs volume)",
                crate::text::num(half[i])
            ),
        ));
    }
    let x = match b.x_axis {
        Some(p) => cx.point::<3>(&format!("{f}.x_axis"), p)?,
        None => [1.0, 0.0, 0.0],
    };
    let y = match b.y_axis {
        Some(p) => cx.point::<3>(&format!("{f}.y_axis"), p)?,
        None => [0.0, 1.0, 0.0],
    };
    let axes = frame(x, y).map_err(|m| {
        let key = if m.starts_with("x_axis") {
            "x_axis"
        } else {
            "y_axis"
        };
        cx.err(
            format!("{f}.{key}"),
            format!("{m}: the box's axes need two directions that are not parallel (y_axis is made orthogonal to x_axis)"),
        )
    })?;
    Ok(OrientedBox { center, half, axes })
}
