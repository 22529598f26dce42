//! One `[[objective.targets]]` entry: a vertex, one `t` or a range of samples, exactly one
//! goal (`point`, `line`, `plane` or `surface`) and a weight, expanded into one
//! [`Target`] per sample.

use serde::Deserialize;

use super::meshes::{Meshes, RawSurface};
use super::terms::{Goal, Target};
use super::times::{Span, values};
use super::{Ctx, InitialGraph, Number, TaskError, names};
use crate::scene::shapes::MeshObstacle;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawTarget {
    vertex: Option<String>,
    t: Number,
    samples: Option<i64>,
    point: Option<Vec<Number>>,
    line: Option<RawLine>,
    plane: Option<RawPlane>,
    surface: Option<RawSurface>,
    weight: Option<Number>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLine {
    point: Vec<Number>,
    direction: Vec<Number>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPlane {
    point: Vec<Number>,
    normal: Vec<Number>,
}

/// What the targets read so far share: G0 (vertex names), the motion, the meshes of the
/// task and the objective's surfaces.
pub(crate) struct Reader<'a, 'p> {
    pub(crate) cx: &'a Ctx<'a>,
    pub(crate) g0: &'a InitialGraph,
    pub(crate) span: Span,
    pub(crate) meshes: &'a mut Meshes<'p>,
    pub(crate) surfaces: Vec<MeshObstacle>,
}

impl Reader<'_, '_> {
    /// Entry `i`, one target per value of its `t`.
    pub(crate) fn read(&mut self, i: usize, raw: &RawTarget) -> Result<Vec<Target>, TaskError> {
        let cx = self.cx;
        let f = format!("objective.targets[{i}]");
        let vertex = names::vertex(cx, &format!("{f}.vertex"), raw.vertex.as_deref(), self.g0)?;
        let ts = values(cx, &f, &raw.t, raw.samples, self.span)?;
        let weight = match &raw.weight {
            None => 1.0,
            Some(w) => cx.num(&format!("{f}.weight"), w)?,
        };
        if weight <= 0.0 {
            return Err(cx.err(
                format!("{f}.weight"),
                format!(
                    "{} is not allowed: weights must be > 0",
                    crate::text::num(weight)
                ),
            ));
        }
        let goals = self.goals(&f, raw, &ts)?;
        Ok(ts
            .into_iter()
            .zip(goals)
            .map(|(t, goal)| Target {
                t,
                vertex: vertex.clone(),
                goal,
                weight,
                entry: i,
            })
            .collect())
    }

    /// The goal at each of `ts`: exactly one of point, line, plane, surface.
    fn goals(&mut self, f: &str, raw: &RawTarget, ts: &[f64]) -> Result<Vec<Goal>, TaskError> {
        let cx = self.cx;
        let given: Vec<&str> = [
            ("point", raw.point.is_some()),
            ("line", raw.line.is_some()),
            ("plane", raw.plane.is_some()),
            ("surface", raw.surface.is_some()),
        ]
        .into_iter()
        .filter_map(|(k, on)| on.then_some(k))
        .collect();
        if given.len() != 1 {
            let what = if given.is_empty() {
                "no goal".to_owned()
            } else {
                format!("{} goals ({})", given.len(), given.join(", "))
            };
            return Err(cx.err(
                f,
                format!(
                    "{what}: a target has exactly one of point = [x, y, z], line = {{ point, direction }}, plane = {{ point, normal }}, surface = {{ file, scale, translate }}"
                ),
            ));
        }
        if let Some(p) = &raw.point {
            let points = cx.point_at(&format!("{f}.point"), p, ts)?;
            return Ok(points
                .into_iter()
                .map(|point| Goal::Point { point })
                .collect());
        }
        if let Some(l) = &raw.line {
            let direction = cx.direction(&format!("{f}.line.direction"), &l.direction)?;
            let points = cx.point_at(&format!("{f}.line.point"), &l.point, ts)?;
            return Ok(points
                .into_iter()
                .map(|point| Goal::Line { point, direction })
                .collect());
        }
        if let Some(p) = &raw.plane {
            let normal = cx.direction(&format!("{f}.plane.normal"), &p.normal)?;
            let points = cx.point_at(&format!("{f}.plane.point"), &p.point, ts)?;
            return Ok(points
                .into_iter()
                .map(|point| Goal::Plane { point, normal })
                .collect());
        }
        let s = raw.surface.as_ref().expect("one goal is given");
        let mesh = self.meshes.load(
            cx,
            &format!("{f}.surface"),
            &s.file,
            s.scale.as_ref(),
            s.translate.as_deref(),
        )?;
        let index = self.surfaces.len();
        self.surfaces.push(mesh);
        Ok(vec![Goal::Surface { index }; ts.len()])
    }
}
