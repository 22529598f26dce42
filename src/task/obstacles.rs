//! The `[[obstacles]]` list (every shape of [`crate::scene::Shape`], with an optional
//! name) and the `[copies]` table (the device as n rotated arms).

use serde::Deserialize;

use super::meshes::Meshes;
use super::solids::{BoxFields, cylinder, halfspace, need, oriented_box, sphere};
use super::{Ctx, Number, TaskError};
use crate::scene::{Copies, Obstacle, Shape};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawObstacle {
    shape: String,
    name: Option<String>,
    radius: Option<Number>,
    from: Option<Vec<Number>>,
    to: Option<Vec<Number>>,
    center: Option<Vec<Number>>,
    min: Option<Vec<Number>>,
    max: Option<Vec<Number>>,
    half_extents: Option<Vec<Number>>,
    x_axis: Option<Vec<Number>>,
    y_axis: Option<Vec<Number>>,
    point: Option<Vec<Number>>,
    normal: Option<Vec<Number>>,
    file: Option<String>,
    scale: Option<Number>,
    translate: Option<Vec<Number>>,
}

/// Each shape and the fields it takes.
const SHAPES: [(&str, &[&str]); 5] = [
    ("cylinder", &["radius", "from", "to"]),
    ("sphere", &["center", "radius"]),
    (
        "box",
        &["min", "max", "center", "half_extents", "x_axis", "y_axis"],
    ),
    ("halfspace", &["point", "normal"]),
    ("mesh", &["file", "scale", "translate"]),
];

impl RawObstacle {
    /// The shape fields given, by name.
    fn given(&self) -> Vec<&'static str> {
        [
            ("radius", self.radius.is_some()),
            ("from", self.from.is_some()),
            ("to", self.to.is_some()),
            ("center", self.center.is_some()),
            ("min", self.min.is_some()),
            ("max", self.max.is_some()),
            ("half_extents", self.half_extents.is_some()),
            ("x_axis", self.x_axis.is_some()),
            ("y_axis", self.y_axis.is_some()),
            ("point", self.point.is_some()),
            ("normal", self.normal.is_some()),
            ("file", self.file.is_some()),
            ("scale", self.scale.is_some()),
            ("translate", self.translate.is_some()),
        ]
        .into_iter()
        .filter_map(|(k, on)| on.then_some(k))
        .collect()
    }
}

/// The obstacles of `[[obstacles]]`, in file order.
pub(crate) fn build(
    cx: &Ctx<'_>,
    raw: &[RawObstacle],
    meshes: &mut Meshes<'_>,
) -> Result<Vec<Obstacle>, TaskError> {
    cx.entries("obstacles", raw.len())?;
    raw.iter()
        .enumerate()
        .map(|(k, o)| obstacle(cx, k, o, meshes))
        .collect()
}

/// A label a task gives an entry (`name = "table"`), or `default`.
pub(crate) fn label(
    cx: &Ctx<'_>,
    field: &str,
    name: Option<&str>,
    default: String,
) -> Result<String, TaskError> {
    let Some(name) = name else { return Ok(default) };
    let max = crate::limits::NAME_MAX;
    if name.trim().is_empty() || name.chars().count() > max || name.chars().any(char::is_control) {
        return Err(cx.err(
            field,
            format!(
                "{:?}: a name is 1 to {max} characters without control characters (it labels records and messages)",
                crate::text::excerpt(name, 40)
            ),
        ));
    }
    Ok(name.to_owned())
}

/// Obstacle `k`.
fn obstacle(
    cx: &Ctx<'_>,
    k: usize,
    o: &RawObstacle,
    meshes: &mut Meshes<'_>,
) -> Result<Obstacle, TaskError> {
    let f = format!("obstacles[{k}]");
    let allowed = SHAPES
        .iter()
        .map(|(s, _)| format!("\"{s}\""))
        .collect::<Vec<_>>();
    let Some((shape, fields)) = SHAPES.iter().find(|(s, _)| *s == o.shape) else {
        return Err(cx.err(
            format!("{f}.shape"),
            format!(
                "unknown shape \"{}\": allowed {}",
                crate::text::excerpt(&o.shape, 40),
                allowed.join(", ")
            ),
        ));
    };
    if let Some(extra) = o.given().into_iter().find(|g| !fields.contains(g)) {
        return Err(cx.err(
            format!("{f}.{extra}"),
            format!(
                "a {shape} takes {}; {extra} belongs to another shape",
                fields.join(", ")
            ),
        ));
    }
    let what = format!("a {shape} needs {}", fields.join(", "));
    let shape = match *shape {
        "cylinder" => Shape::Cylinder(cylinder(
            cx,
            &f,
            need(cx, &f, "radius", &what, o.radius.as_ref())?,
            need(cx, &f, "from", &what, o.from.as_deref())?,
            need(cx, &f, "to", &what, o.to.as_deref())?,
        )?),
        "sphere" => Shape::Sphere(sphere(
            cx,
            &f,
            need(cx, &f, "center", &what, o.center.as_deref())?,
            need(cx, &f, "radius", &what, o.radius.as_ref())?,
        )?),
        "box" => Shape::Box(oriented_box(
            cx,
            &f,
            BoxFields {
                min: o.min.as_deref(),
                max: o.max.as_deref(),
                center: o.center.as_deref(),
                half_extents: o.half_extents.as_deref(),
                x_axis: o.x_axis.as_deref(),
                y_axis: o.y_axis.as_deref(),
            },
        )?),
        "halfspace" => Shape::HalfSpace(halfspace(
            cx,
            &f,
            need(cx, &f, "point", &what, o.point.as_deref())?,
            need(cx, &f, "normal", &what, o.normal.as_deref())?,
        )?),
        _ => Shape::Mesh(meshes.load(
            cx,
            &f,
            need(cx, &f, "file", &what, o.file.as_deref())?,
            o.scale.as_ref(),
            o.translate.as_deref(),
        )?),
    };
    Ok(Obstacle {
        name: label(cx, &format!("{f}.name"), o.name.as_deref(), f.clone())?,
        shape,
    })
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawCopies {
    n: i64,
    axis: Option<RawAxis>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAxis {
    point: Option<Vec<Number>>,
    direction: Option<Vec<Number>>,
}

/// `[copies]`: n in 1..=[`crate::limits::COPIES_MAX`] about an axis (default: the z-axis
/// through the origin).
pub(crate) fn copies(cx: &Ctx<'_>, raw: &RawCopies) -> Result<Copies, TaskError> {
    let max = crate::limits::COPIES_MAX;
    if !(1..=max as i64).contains(&raw.n) {
        return Err(cx.err(
            "copies.n",
            format!(
                "{} is not allowed: 1 ≤ n ≤ {max} (the number of arms in the device; 1: the arm alone)",
                raw.n
            ),
        ));
    }
    let mut c = Copies::about_z(raw.n as usize);
    if let Some(axis) = &raw.axis {
        if let Some(p) = &axis.point {
            c.point = cx.point::<3>("copies.axis.point", p)?;
        }
        if let Some(d) = &axis.direction {
            c.direction = cx.direction("copies.axis.direction", d)?;
        }
    }
    Ok(c)
}
