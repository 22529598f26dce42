//! What the judges of a design look at: the pattern they check (the arm, with its rotated
//! copy for two-armed tasks), the task's obstacles, and the design's robustness measured
//! by `check::robustness` (for a new design and for a recorded one alike).

use super::record::FabricationRecord;
use crate::check::requirements::{self, JudgeInput, RequirementsReport};
use crate::check::robustness::{self, RobustnessInput, RobustnessReport, UnitCreases};
use crate::check::thick::ThickInput;
use crate::check::{Cylinder, two_armed};
use crate::fabricate::ThickDesign;
use crate::model::Model;
use crate::pattern::Pattern;
use crate::task::Task;
use crate::task::fabrication::Fabrication;

/// The obstacles of the task as the checks take them.
pub(super) fn obstacles(task: &Task) -> Vec<Cylinder> {
    task.scene.cylinders().copied().collect()
}

/// The pattern checks and exports work on: the arm, with its rotated copy for two-armed
/// tasks.
pub(super) fn checked_pattern(task: &Task, arm: &Pattern) -> Result<Pattern, String> {
    if task.scene.copies.n == 2 {
        two_armed(arm).map_err(|e| e.to_string())
    } else {
        Ok(arm.clone())
    }
}

/// The robustness of a design measured by `check::robustness` on the checked pattern
/// (`pat`: the arm, or both arms) at the sweep's frames.
pub(super) fn measure_robustness(
    task: &Task,
    model: &Model,
    arm: &Pattern,
    pat: &Pattern,
) -> Result<RobustnessReport, String> {
    let plan = &model.plan;
    let face_names: Vec<String> = plan
        .polygons
        .iter()
        .enumerate()
        .filter(|(_, (p, _))| p.len() >= 3)
        .map(|(f, _)| plan.facet_names[f].clone())
        .collect();
    let n = arm.vertices.len();
    let vertex_names = (0..pat.vertices.len())
        .map(|v| {
            if v < n {
                format!("v{}", plan.vertices[v].name)
            } else {
                format!("copy #{}", v - n + 1)
            }
        })
        .collect();
    let units = plan
        .internal
        .iter()
        .map(|&a| {
            let v = &plan.vertices[a];
            let m = v.preds;
            UnitCreases {
                vertex: a,
                ends: [0, 1, 2].map(|k| v.rays[m + k].other),
                label: format!("v{}", v.name),
            }
        })
        .collect();
    let cylinders = obstacles(task);
    let tip = tip_pair(model, arm, pat);
    let input = RobustnessInput {
        pattern: pat,
        arm_faces: arm.faces.len(),
        face_names,
        vertex_names,
        cylinders: &cylinders,
        units,
        tip,
        t_max: model.t_max,
        settings: task.robustness,
        arm,
    };
    robustness::measure(&input).map_err(|e| e.to_string())
}

/// The arms of a two-armed gripper meet at a target on the rotation axis: their tips touch
/// there by design. The gripping vertex and its copy (found by its flat position) in `pat`.
fn tip_pair(model: &Model, arm: &Pattern, pat: &Pattern) -> Option<(usize, usize)> {
    let n = arm.vertices.len();
    (pat.vertices.len() > n
        && model
            .targets
            .iter()
            .any(|t| t.point[0].abs() < 1e-9 && t.point[1].abs() < 1e-9))
    .then(|| {
        let g = model.gripping;
        let q = [-arm.vertices[g][0], -arm.vertices[g][1]];
        (n..pat.vertices.len())
            .find(|&j| (pat.vertices[j][0] - q[0]).hypot(pat.vertices[j][1] - q[1]) <= 1e-9)
            .map(|c| (g, c))
    })
    .flatten()
}

/// The thick panels of the checked pattern `pat` (its frames: the dense sweep) for the
/// task's `[fabrication]`, built for the largest folds seen on those frames.
pub(super) fn thick_design(
    spec: &Fabrication,
    pat: &Pattern,
) -> Result<ThickDesign, crate::fabricate::FabError> {
    let ranges = crate::fabricate::fold_ranges(pat, &pat.frames);
    crate::fabricate::build(pat, &ranges, spec)
}

/// A design made thick and its solids tested by `check::thick` on the frames of `pat` (the
/// arm with its copies, on the dense sweep): the other arm and the obstacles included, the
/// tips of a gripper's arms allowed to touch.
pub(super) fn measure_thick(
    task: &Task,
    model: &Model,
    arm: &Pattern,
    pat: &Pattern,
) -> FabricationRecord {
    let Some(spec) = &task.fabrication else {
        return FabricationRecord {
            refused: Some("the task has no [fabrication] table".to_string()),
            check: None,
        };
    };
    match thick_design(spec, pat) {
        Err(e) => FabricationRecord {
            refused: Some(e.to_string()),
            check: None,
        },
        Ok(design) => {
            let touching: Vec<(usize, usize)> = tip_pair(model, arm, pat).into_iter().collect();
            let report = crate::check::thick::check(&ThickInput {
                pattern: pat,
                design: &design,
                clearance: task.robustness.clearance,
                obstacle_clearance: task.robustness.obstacle_clearance,
                obstacles: &task.scene.obstacles,
                touching: &touching,
            });
            FabricationRecord {
                refused: None,
                check: Some(report),
            }
        }
    }
}

/// The states the judges look at: the dense sweep of `n` states, with every t a term of
/// the task names (targets, orientations, containment boxes, the packing term) that the
/// sweep does not already hold within [`T_TOL`](crate::check::requirements::T_TOL), so a
/// requirement at t = π/8 is judged at π/8 itself.
pub(super) fn judged_times(task: &Task, t_max: f64, n: usize) -> Vec<f64> {
    use crate::task::terms::AreaKind;
    let mut times = crate::model::numeric::sample_times(t_max, n);
    let objective = task.objective.as_ref();
    let named = objective
        .into_iter()
        .flat_map(|o| o.targets.iter().map(|t| t.t))
        .chain(objective.and_then(|o| match o.area.as_ref()?.kind {
            AreaKind::Packing { t } => Some(t),
            AreaKind::Flat => None,
        }))
        .chain(
            task.requirements
                .orientations
                .iter()
                .flat_map(|o| o.t.clone()),
        )
        .chain(task.scene.containment.iter().filter_map(|c| c.t));
    let near =
        |a: f64, b: f64| (a - b).abs() <= crate::check::requirements::T_TOL * (1.0 + b.abs());
    let extra: Vec<f64> = named
        .filter(|&t| !times.iter().any(|&s| near(s, t)))
        .collect();
    if !extra.is_empty() {
        times.extend(extra);
        times.sort_by(f64::total_cmp);
        times.dedup_by(|a, b| near(*a, *b));
    }
    times
}

/// The task's requirements, obstacles, copies, targets and area judged on the design's
/// sweep (`arm`: the arm with its frames) by `check::requirements`; the vertices and
/// creases the task names resolved in the model's plan (pattern indices are plan indices).
pub(super) fn judge_requirements(
    task: &Task,
    model: &Model,
    arm: &Pattern,
) -> Result<RequirementsReport, String> {
    use crate::model::select;
    let plan = &model.plan;
    let tip = model.gripping;
    let ends = |c: usize| (plan.creases[c].tail, plan.creases[c].head);
    let orientation_creases = task
        .requirements
        .orientations
        .iter()
        .map(|o| {
            let v = select::vertex(plan, tip, &o.vertex)?;
            select::crease_into(plan, v).map(ends)
        })
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    let fold_limit_creases = task
        .requirements
        .fold_limits
        .iter()
        .map(|l| select::crease(plan, tip, &l.crease).map(ends))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    let target_vertices = task
        .objective
        .iter()
        .flat_map(|o| &o.targets)
        .map(|t| select::vertex(plan, tip, &t.vertex))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    let input = JudgeInput {
        arm,
        scene: &task.scene,
        requirements: &task.requirements,
        objective: task.objective.as_ref(),
        orientation_creases,
        fold_limit_creases,
        target_vertices,
        obstacle_clearance: task.robustness.obstacle_clearance,
    };
    requirements::judge(&input).map_err(|e| e.to_string())
}
