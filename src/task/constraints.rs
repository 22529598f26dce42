//! The `[constraints]` table: design constraints beyond the thesis's (`kawasaki = true`:
//! every internal vertex of even degree folds flat), the hard requirements of issue 31
//! (`[[constraints.orientation]]`, `max_fold`, `[[constraints.fold_limits]]`) and the boxes
//! the folded pattern stays inside (`[[constraints.inside]]`, part of the scene).

use serde::Deserialize;

use super::obstacles::label;
use super::solids::{BoxFields, oriented_box};
use super::terms::{FoldLimit, Orientation, Pointer, Requirements};
use super::times::{Span, one, values};
use super::{Ctx, InitialGraph, Motion, Number, TaskError, names};
use crate::scene::Containment;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawConstraints {
    #[serde(default)]
    kawasaki: bool,
    max_fold: Option<Number>,
    #[serde(default)]
    fold_limits: Vec<RawFoldLimit>,
    #[serde(default)]
    orientation: Vec<RawOrientation>,
    #[serde(default)]
    inside: Vec<RawInside>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFoldLimit {
    crease: String,
    max: Number,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOrientation {
    vertex: Option<String>,
    of: Option<String>,
    direction: Vec<Number>,
    angle: Option<Number>,
    tolerance: Number,
    t: Number,
    samples: Option<i64>,
    name: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInside {
    min: Option<Vec<Number>>,
    max: Option<Vec<Number>>,
    center: Option<Vec<Number>>,
    half_extents: Option<Vec<Number>>,
    x_axis: Option<Vec<Number>>,
    y_axis: Option<Vec<Number>>,
    t: Option<Number>,
    name: Option<String>,
}

/// Whether Kawasaki's condition is imposed (off when the table or the key is absent).
pub(crate) fn kawasaki(raw: Option<&RawConstraints>) -> bool {
    raw.is_some_and(|c| c.kawasaki)
}

/// Whether the table uses a key that needs the motion range.
fn needs_motion(c: &RawConstraints) -> Option<&'static str> {
    if !c.orientation.is_empty() {
        Some("constraints.orientation")
    } else if c.inside.iter().any(|b| b.t.is_some()) {
        Some("constraints.inside")
    } else {
        None
    }
}

/// The requirements and the containment boxes of `[constraints]` (none when absent).
pub(crate) fn build(
    cx: &Ctx<'_>,
    raw: Option<&RawConstraints>,
    motion: Option<Motion>,
    g0: &InitialGraph,
) -> Result<(Requirements, Vec<Containment>), TaskError> {
    let Some(c) = raw else {
        return Ok(Default::default());
    };
    let span = match (motion, needs_motion(c)) {
        (Some(m), _) => Some(Span::of(m)),
        (None, Some(field)) => {
            return Err(cx.err(
                field,
                "a requirement at given t needs the motion range: add [motion] with t_max",
            ));
        }
        (None, None) => None,
    };
    cx.entries("constraints.orientation", c.orientation.len())?;
    cx.entries("constraints.fold_limits", c.fold_limits.len())?;
    cx.entries("constraints.inside", c.inside.len())?;
    let mut req = Requirements {
        max_fold: c
            .max_fold
            .as_ref()
            .map(|n| fold_angle(cx, "constraints.max_fold", n))
            .transpose()?,
        ..Requirements::default()
    };
    for (i, f) in c.fold_limits.iter().enumerate() {
        let e = format!("constraints.fold_limits[{i}]");
        req.fold_limits.push(FoldLimit {
            crease: names::crease(cx, &format!("{e}.crease"), &f.crease, g0)?,
            max: fold_angle(cx, &format!("{e}.max"), &f.max)?,
        });
    }
    for (i, o) in c.orientation.iter().enumerate() {
        let span = span.expect("checked: orientations need the motion");
        req.orientations.push(orientation(cx, i, o, span, g0)?);
    }
    let boxes = c
        .inside
        .iter()
        .enumerate()
        .map(|(i, b)| inside(cx, i, b, span))
        .collect::<Result<_, _>>()?;
    Ok((req, boxes))
}

/// A fold angle limit: rad in (0, π).
fn fold_angle(cx: &Ctx<'_>, field: &str, n: &Number) -> Result<f64, TaskError> {
    let v = cx.num(field, n)?;
    if !(v > 0.0 && v < std::f64::consts::PI) {
        return Err(cx.err(
            field,
            format!(
                "{} is not allowed: a fold-angle limit is in radians, 0 < max < pi (pi: folded flat)",
                crate::text::num(v)
            ),
        ));
    }
    Ok(v)
}

/// `[[constraints.orientation]]` entry `i`.
fn orientation(
    cx: &Ctx<'_>,
    i: usize,
    o: &RawOrientation,
    span: Span,
    g0: &InitialGraph,
) -> Result<Orientation, TaskError> {
    let e = format!("constraints.orientation[{i}]");
    let vertex = names::vertex(cx, &format!("{e}.vertex"), o.vertex.as_deref(), g0)?;
    let of = match o.of.as_deref() {
        None | Some("crease") => Pointer::Crease,
        Some("facet_left") => Pointer::FacetLeft,
        Some("facet_right") => Pointer::FacetRight,
        Some(other) => {
            return Err(cx.err(
                format!("{e}.of"),
                format!(
                    "unknown \"{}\": allowed \"crease\" (from the predecessor to the vertex), \"facet_left\", \"facet_right\" (the normals of the facets beside that crease)",
                    crate::text::excerpt(other, 40)
                ),
            ));
        }
    };
    let direction = cx.direction(&format!("{e}.direction"), &o.direction)?;
    let angle = match &o.angle {
        None => 0.0,
        Some(a) => cx.num(&format!("{e}.angle"), a)?,
    };
    if !(0.0..=std::f64::consts::PI).contains(&angle) {
        return Err(cx.err(
            format!("{e}.angle"),
            format!(
                "{} is not allowed: an angle between directions is in radians, 0 ≤ angle ≤ pi",
                crate::text::num(angle)
            ),
        ));
    }
    let tolerance = cx.positive(&format!("{e}.tolerance"), &o.tolerance)?;
    let t = values(cx, &e, &o.t, o.samples, span)?;
    Ok(Orientation {
        name: label(cx, &format!("{e}.name"), o.name.as_deref(), e.clone())?,
        vertex,
        of,
        direction,
        angle,
        tolerance,
        t,
    })
}

/// `[[constraints.inside]]` entry `i`.
fn inside(
    cx: &Ctx<'_>,
    i: usize,
    b: &RawInside,
    span: Option<Span>,
) -> Result<Containment, TaskError> {
    let e = format!("constraints.inside[{i}]");
    let bounds = oriented_box(
        cx,
        &e,
        BoxFields {
            min: b.min.as_deref(),
            max: b.max.as_deref(),
            center: b.center.as_deref(),
            half_extents: b.half_extents.as_deref(),
            x_axis: b.x_axis.as_deref(),
            y_axis: b.y_axis.as_deref(),
        },
    )?;
    let t = match &b.t {
        None => None,
        Some(t) => Some(one(
            cx,
            &format!("{e}.t"),
            t,
            span.expect("checked: a box at t needs the motion"),
        )?),
    };
    Ok(Containment {
        bounds,
        t,
        name: label(cx, &format!("{e}.name"), b.name.as_deref(), e.clone())?,
    })
}
