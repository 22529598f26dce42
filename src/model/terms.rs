//! The task language's terms on one model (issue 31): the targets of any vertex and goal,
//! the orientation requirements and the area term, resolved on the graph's plan and
//! written over [`Scalar`], so the compiled model and the f64 path are the same code.
//!
//! Output order (after the thesis's constraints, the cyclic ones and Kawasaki's):
//! orientation constraints (per requirement, per state, per non-vacuous side), the
//! one-state containment boxes (per box, copy, vertex, axis: the two walls), then with
//! an area term `threshold − Ω ≥ 0` (when there are targets) and `A − at_least ≥ 0`; the
//! auxiliary outputs (3 per surface target: its vertex's position) come after every
//! constraint, so the constraints' Jacobian stays one block.

use super::geometry::{self, Flat, Folded};
use super::linalg::Vec3;
use super::orientation::{Orientation, Side};
use super::surface::Surface;
use super::targets::{Combination, Target, squared_distance};
use super::{Model, ModelError, area, select};
use crate::kinematics::Scalar;
use crate::task::Task;
use crate::task::terms::{AreaKind, Goal, Objective};

/// The model's terms as the task states them, resolved on the plan.
pub(super) struct Resolved {
    pub targets: Vec<Target>,
    pub surfaces: Vec<Surface>,
    pub orientations: Vec<Orientation>,
}

/// Resolve the task's targets, surfaces and orientations on `plan` with `gripping` as the
/// tip. A name the graph lacks is an error of this model.
pub(super) fn resolve(
    plan: &super::Plan,
    task: &Task,
    objective: &Objective,
    gripping: usize,
) -> Result<Resolved, ModelError> {
    let err = |message: String| ModelError::Task {
        task: task.name.clone(),
        message,
    };
    let mut targets = Vec::with_capacity(objective.targets.len());
    for t in &objective.targets {
        let vertex = select::vertex(plan, gripping, &t.vertex)
            .map_err(|e| err(format!("objective.targets[{}]: {e}", t.entry)))?;
        if let Goal::Surface { index } = t.goal {
            let ok = objective
                .surfaces
                .get(index)
                .and_then(|m| m.mesh.as_ref())
                .is_some_and(|m| !m.triangles.is_empty());
            if !ok {
                return Err(err(format!(
                    "objective.targets[{}]: surface {index} has no loaded triangles",
                    t.entry
                )));
            }
        }
        // The thesis's target (a point for the tip) keeps its point for the code that
        // knows only those; NaN elsewhere.
        let point = match (&t.vertex, t.point()) {
            (crate::task::terms::VertexRef::Tip, Some(p)) => p,
            _ => [f64::NAN; 3],
        };
        targets.push(Target {
            t: t.t,
            vertex,
            goal: t.goal.clone(),
            weight: t.weight,
            entry: t.entry,
            point,
        });
    }
    let surfaces = objective
        .surfaces
        .iter()
        .map(|m| match &m.mesh {
            Some(mesh) => Surface::new(mesh.clone()),
            None => Surface::new(std::sync::Arc::new(crate::scene::TriangleMesh {
                vertices: Vec::new(),
                triangles: Vec::new(),
                closed: false,
            })),
        })
        .collect();
    let mut orientations = Vec::new();
    for (index, o) in task.requirements.orientations.iter().enumerate() {
        let at = |e: select::SelectError| err(format!("constraints.orientation[{index}]: {e}"));
        let vertex = select::vertex(plan, gripping, &o.vertex).map_err(at)?;
        let crease = select::crease_into(plan, vertex).map_err(at)?;
        orientations.push(Orientation {
            name: o.name.clone(),
            index,
            vertex,
            crease,
            of: o.of,
            direction: o.direction,
            angle: o.angle,
            tolerance: o.tolerance,
            t: o.t.clone(),
        });
    }
    Ok(Resolved {
        targets,
        surfaces,
        orientations,
    })
}

/// The states the new terms add to the model's times (orientation states, the packing
/// state), in order of appearance.
pub(super) fn extra_times(model: &Model) -> Vec<f64> {
    let mut out: Vec<f64> = model
        .orientations
        .iter()
        .flat_map(|o| o.t.iter().copied())
        .collect();
    if let Some(AreaKind::Packing { t }) = model.area.map(|a| a.kind) {
        out.push(t);
    }
    out.extend(model.boxes.iter().filter_map(|b| b.t));
    out
}

/// Index into `model.times` of `t` (every state a term uses is there by construction).
fn time_index(model: &Model, t: f64) -> usize {
    model
        .times
        .iter()
        .position(|s| *s == t)
        .expect("every state of a term is in the model's times")
}

/// Ω over the targets the graph can hold (point, line, plane), combined as
/// [`Model::combination`] says; surface targets are added numerically
/// ([`Model::surface_terms`]). The thesis's operations in the thesis's order for point
/// targets: one target `w² d²`, several `0 + Σ w √(d² + ε²)`.
pub(super) fn omega<S: Scalar>(model: &Model, flat: &Flat<S>, folded: &[Folded<S>]) -> S {
    // Every squared distance first, then the combination: the order the thesis's code
    // built its expressions in (the compiled graph of a bundled task stays the same).
    let mut terms = Vec::with_capacity(model.targets.len());
    for target in &model.targets {
        let x = geometry::position(
            &model.plan,
            flat,
            &folded[time_index(model, target.t)],
            target.vertex,
        );
        if let Some(d2) = squared_distance(&x, &target.goal) {
            terms.push((target.weight, d2));
        }
    }
    let c = model.combination;
    match c {
        Combination::Squared => terms
            .into_iter()
            .next()
            .map_or_else(|| S::from_f64(0.0), |(w, d2)| c.term(w, d2)),
        Combination::Smoothed => terms
            .into_iter()
            .fold(S::from_f64(0.0), |acc, (w, d2)| acc + c.term(w, d2)),
    }
}

/// The auxiliary outputs: the position of every surface target's vertex at its state, 3
/// per target, in target order.
pub(super) fn aux<S: Scalar>(model: &Model, flat: &Flat<S>, folded: &[Folded<S>]) -> Vec<S> {
    model
        .targets
        .iter()
        .filter(|t| t.surface().is_some())
        .flat_map(|t| {
            geometry::position(&model.plan, flat, &folded[time_index(model, t.t)], t.vertex)
        })
        .collect()
}

/// The area term `A` (flat area × copies, or that over the packing footprint at its t).
pub fn area_value<S: Scalar>(model: &Model, flat: &Flat<S>, folded: &[Folded<S>]) -> Option<S> {
    let term = model.area?;
    let flat_area = area::flat_area(&model.plan, flat) * (model.copies.n.max(1) as f64);
    Some(match term.kind {
        AreaKind::Flat => flat_area,
        AreaKind::Packing { t } => {
            let f = &folded[time_index(model, t)];
            let points: Vec<Vec3<S>> = (0..model.plan.vertices.len())
                .map(|v| geometry::position(&model.plan, flat, f, v))
                .collect();
            flat_area / area::footprint(&points, &model.copies)
        }
    })
}

/// The orientation constraints, then the area term's constraints (see the module doc).
pub(super) fn constraints<S: Scalar>(
    model: &Model,
    flat: &Flat<S>,
    folded: &[Folded<S>],
    omega: &S,
) -> Vec<S> {
    let mut out = Vec::new();
    for o in &model.orientations {
        let sides = o.sides();
        for &t in &o.t {
            let cosine = o.cosine(&model.plan, flat, &folded[time_index(model, t)]);
            for &side in &sides {
                out.push(o.constraint(side, cosine.clone()));
            }
        }
    }
    containment(model, flat, folded, &mut out);
    if let Some(term) = model.area {
        if !model.targets.is_empty() {
            out.push(S::from_f64(model.threshold) - omega.clone());
        }
        let a = area_value(model, flat, folded).expect("the model has an area term");
        out.push(a - term.at_least);
    }
    out
}

/// Every vertex of every copy inside each of [`Model::boxes`] at its state: per box, copy,
/// vertex and box axis `i`, `half_i ∓ a_i·(x − c) ≥ 0`, with the copy's rotation folded
/// into constant coefficients (the constraint is linear in the vertex's position).
fn containment<S: Scalar>(model: &Model, flat: &Flat<S>, folded: &[Folded<S>], out: &mut Vec<S>) {
    use crate::geom::{dot, sub};
    let n = model.copies.n.max(1);
    for b in &model.boxes {
        let f = &folded[time_index(model, b.t.expect("model boxes have a state"))];
        let x: Vec<Vec3<S>> = (0..model.plan.vertices.len())
            .map(|v| geometry::position(&model.plan, flat, f, v))
            .collect();
        let bx = &b.bounds;
        for copy in 0..n {
            // a_i·(R (x − P) + P − c) = Σ_j (a_i R)_j x_j + a_i·(g(0) − c), g(0) = P − R P.
            let r = model.copies.rotation(copy);
            let moved_origin = model.copies.apply(copy, [0.0; 3]);
            let rows: Vec<([f64; 3], f64)> = (0..3)
                .map(|i| {
                    let a = bx.axes[i];
                    let ar = [0, 1, 2].map(|j| (0..3).map(|k| a[k] * r[k][j]).sum::<f64>());
                    (ar, dot(a, sub(moved_origin, bx.center)))
                })
                .collect();
            for xv in &x {
                for (i, (ar, o)) in rows.iter().enumerate() {
                    let q = (0..3).fold(S::from_f64(*o), |acc, j| acc + xv[j].clone() * ar[j]);
                    out.push(S::from_f64(bx.half[i]) - q.clone());
                    out.push(q + bx.half[i]);
                }
            }
        }
    }
}

/// The number of constraints [`containment`] writes.
fn containment_count(model: &Model) -> usize {
    model.boxes.len() * model.copies.n.max(1) * model.plan.vertices.len() * 6
}

/// The number of constraints [`constraints`] writes.
pub(super) fn count(model: &Model) -> usize {
    let orient: usize = model
        .orientations
        .iter()
        .map(|o| o.sides().len() * o.t.len())
        .sum();
    let area = match model.area {
        None => 0,
        Some(_) => 1 + usize::from(!model.targets.is_empty()),
    };
    orient + containment_count(model) + area
}

/// The index, among [`constraints`], of `threshold − Ω ≥ 0` (an area term beside targets).
pub(super) fn omega_constraint(model: &Model) -> Option<usize> {
    (model.area.is_some() && !model.targets.is_empty()).then(|| count(model) - 2)
}

/// The label of constraint `j` of [`constraints`].
pub(super) fn label(model: &Model, j: usize) -> String {
    let mut k = j;
    for o in &model.orientations {
        let sides = o.sides();
        let n = sides.len() * o.t.len();
        if k < n {
            let (t, side) = (o.t[k / sides.len()], sides[k % sides.len()]);
            let (op, bound) = match side {
                Side::AtMost => ("≤", o.angle + o.tolerance),
                Side::AtLeast => ("≥", o.angle - o.tolerance),
            };
            return format!(
                "orientation '{}': {:?} of v{} at t = {t}: angle to [{}, {}, {}] {op} {bound}",
                o.name,
                o.of,
                model.plan.vertices[o.vertex].name,
                o.direction[0],
                o.direction[1],
                o.direction[2]
            );
        }
        k -= n;
    }
    let per_box = containment_count(model) / model.boxes.len().max(1);
    if k < containment_count(model) {
        let (b, rest) = (&model.boxes[k / per_box], k % per_box);
        let nv = model.plan.vertices.len();
        let (copy, vertex, wall) = (rest / (6 * nv), (rest / 6) % nv, rest % 6);
        return format!(
            "inside '{}' at t = {}: v{} (copy {copy}) {} {}-wall",
            b.name,
            b.t.unwrap_or(model.t_max),
            model.plan.vertices[vertex].name,
            if wall % 2 == 0 {
                "below the +"
            } else {
                "above the −"
            },
            ["x", "y", "z"][wall / 2]
        );
    }
    if Some(j) == omega_constraint(model) {
        return format!("objective: Ω (smoothed) ≤ threshold {}", model.threshold);
    }
    let at_least = model.area.map_or(0.0, |a| a.at_least);
    format!("objective: area term ≥ at_least {at_least}")
}
