//! Reading a task file table by table. [`Draft::parse`] reads the file and checks the
//! name, `[grammar]`, `[symmetry]` and G0 on its own; `Task::from_toml_str` then checks G0
//! against the grammar's graph (which this module cannot see: the grammar reads the task);
//! [`Draft::finish`] checks every other table, each in its own module (a raw serde struct
//! and a `build` function), in a fixed order: the first error found is the one reported. A
//! new table is a module, a field of `RawTask` and one line in `finish`.

use serde::Deserialize;

use super::ctx::syntax_error;
use super::{
    Ctx, InitialGraph, N_MAX_LIMIT, Symmetry, Task, TaskError, VertexType, bounds, check,
    constraints, digest_with_meshes, fab_table, initial, meshes::Meshes, motion, objective,
    obstacles, robustness,
};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTask {
    name: Option<String>,
    description: Option<String>,
    grammar: RawGrammar,
    #[serde(default)]
    symmetry: RawSymmetry,
    initial_graph: initial::RawInitial,
    motion: Option<motion::RawMotion>,
    bounds: Option<bounds::RawBounds>,
    objective: Option<objective::RawObjective>,
    check: Option<check::RawCheck>,
    robustness: Option<robustness::RawRobustness>,
    constraints: Option<constraints::RawConstraints>,
    #[serde(default)]
    obstacles: Vec<obstacles::RawObstacle>,
    copies: Option<obstacles::RawCopies>,
    fabrication: Option<fab_table::RawFabrication>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawGrammar {
    n_max: i64,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawSymmetry {
    #[serde(default)]
    mirror_xz: bool,
    rotations: Option<i64>,
    center: Option<Vec<super::Number>>,
    mirror_axis: Option<Vec<Vec<super::Number>>>,
}

/// A task file read up to G0's crease order.
pub(crate) struct Draft<'a> {
    pub(crate) cx: Ctx<'a>,
    text: &'a str,
    raw: RawTask,
    name: String,
    n_max: usize,
    pub(crate) symmetry: Symmetry,
    /// G0 with its crease order; its mirror map is filled in by `Task::from_toml_str`.
    pub(crate) initial: InitialGraph,
    /// Distance below which two positions of G0 are one.
    pub(crate) tol: f64,
}

impl<'a> Draft<'a> {
    /// Parse `text` (`file` labels the messages) and check the name, N_max, the symmetry
    /// and G0 on its own.
    pub(crate) fn parse(text: &'a str, file: &'a str) -> Result<Draft<'a>, TaskError> {
        let cx = Ctx { file };
        if let Some(kind) = crate::text::other_kind(text, "task") {
            return Err(cx.err("(file)", kind));
        }
        let raw: RawTask = toml::from_str(text).map_err(|e| syntax_error(file, text, &e))?;
        let name = raw.name.clone().unwrap_or_default();
        check_name(&name).map_err(|m| cx.err("name", m))?;

        let n_max = raw.grammar.n_max;
        if !(1..=N_MAX_LIMIT as i64).contains(&n_max) {
            return Err(cx.err(
                "grammar.n_max",
                format!(
                    "{n_max} is out of range: allowed 1..={N_MAX_LIMIT} (at least one vertex to extend; the number of graphs grows about twentyfold per internal vertex)"
                ),
            ));
        }
        let pattern = pattern_symmetry(&cx, &raw.symmetry)?;
        let symmetry = Symmetry {
            mirror_xz: raw.symmetry.mirror_xz,
            pattern,
        };
        let (initial, tol) = initial::build(&cx, &raw.initial_graph)?;
        Ok(Draft {
            cx,
            text,
            raw,
            name,
            n_max: n_max as usize,
            symmetry,
            initial,
            tol,
        })
    }

    /// G0's actuation (which facet stays fixed) and the pattern's symmetry group, once the
    /// facet labels are known to be consistent.
    pub(crate) fn actuate(&mut self) -> Result<(), TaskError> {
        let g = &mut self.initial;
        g.actuation = super::actuation::actuation(
            &self.cx,
            &g.vertices,
            &g.creases,
            &g.facets,
            &self.raw.initial_graph,
        )?;
        if self.symmetry.pattern.any() {
            g.group = Some(super::symmetry::group(
                &self.cx,
                g,
                &self.symmetry.pattern,
                self.tol,
            )?);
        }
        Ok(())
    }

    /// Check the remaining tables and assemble the task; mesh files named by a relative
    /// path are read from `dir` (the task file's folder).
    pub(crate) fn finish(self, dir: &std::path::Path) -> Result<Task, TaskError> {
        let Draft {
            cx,
            text,
            raw,
            name,
            n_max,
            symmetry,
            initial,
            tol: _,
        } = self;
        if !initial
            .vertices
            .iter()
            .any(|v| v.ty == VertexType::Extendable)
        {
            return Err(cx.err(
                "initial_graph.vertices",
                "no vertex has type = \"extendable\": the grammar extends only extendable (χ) vertices, so this G0 generates no crease pattern",
            ));
        }
        let motion = motion::build(&cx, raw.motion.as_ref())?;
        let bounds = bounds::build(&cx, raw.bounds.as_ref())?;
        let mut meshes = Meshes::new(dir);
        let objective =
            objective::build(&cx, raw.objective.as_ref(), motion, &initial, &mut meshes)?;
        let (check, legacy) = check::build(&cx, raw.check.as_ref())?;
        let (requirements, containment) =
            constraints::build(&cx, raw.constraints.as_ref(), motion, &initial)?;
        let scene = scene(&cx, &raw, legacy, containment, &mut meshes)?;
        let robustness = robustness::build(&cx, raw.robustness.as_ref(), &initial)?;
        let fabrication = fab_table::build(&cx, raw.fabrication.as_ref(), &initial, &robustness)?;
        let laminate = fab_table::laminate(&cx, raw.fabrication.as_ref())?;

        Ok(Task {
            name: name.trim().to_string(),
            digest: digest_with_meshes(text, &meshes.digests),
            mesh_digests: meshes.digests,
            description: raw.description,
            source: None,
            initial,
            n_max,
            symmetry,
            motion,
            bounds,
            objective,
            check,
            scene,
            requirements,
            robustness,
            kawasaki: constraints::kawasaki(raw.constraints.as_ref()),
            fabrication,
            laminate,
        })
    }
}

/// The scene: the legacy `[[check.cylinders]]` first, then `[[obstacles]]`; the copies of
/// `[copies]` or the legacy `second_arm` (not both); the boxes of `[[constraints.inside]]`.
fn scene(
    cx: &Ctx<'_>,
    raw: &RawTask,
    legacy: check::LegacyScene,
    containment: Vec<crate::scene::Containment>,
    meshes: &mut Meshes<'_>,
) -> Result<crate::scene::Scene, TaskError> {
    let mut obstacles = legacy.obstacles;
    obstacles.extend(obstacles::build(cx, &raw.obstacles, meshes)?);
    let copies = match (&raw.copies, legacy.copies) {
        (Some(_), Some(_)) => {
            return Err(cx.err(
                "copies",
                "[copies] and [check] second_arm = true both give the copies: keep [copies] (second_arm = true means n = 2 about the z-axis)",
            ));
        }
        (Some(c), None) => obstacles::copies(cx, c)?,
        (None, legacy) => legacy.unwrap_or_default(),
    };
    Ok(crate::scene::Scene {
        obstacles,
        copies,
        containment,
    })
}

/// `[symmetry] rotations`, `center` and `mirror_axis`, read and range-checked.
fn pattern_symmetry(cx: &Ctx<'_>, raw: &RawSymmetry) -> Result<super::PatternSymmetry, TaskError> {
    let max = super::isometry::MAX_ROTATIONS as i64;
    let rotations = match raw.rotations {
        None => 1,
        Some(n) if (2..=max).contains(&n) => n as usize,
        Some(n) => {
            return Err(cx.err(
                "symmetry.rotations",
                format!(
                    "{n} is out of range: the order of rotational symmetry is 2..={max} (leave it out for none)"
                ),
            ));
        }
    };
    let center = match &raw.center {
        None => None,
        Some(_) if rotations == 1 => {
            return Err(cx.err(
                "symmetry.center",
                "a centre needs rotations: give symmetry.rotations (2 or more) or drop the centre",
            ));
        }
        Some(c) => Some(cx.point::<2>("symmetry.center", c)?),
    };
    let mirror_axis = match &raw.mirror_axis {
        None => None,
        Some(pts) => {
            if pts.len() != 2 {
                return Err(cx.err(
                    "symmetry.mirror_axis",
                    format!(
                        "{} points given: the mirror axis is the line through two points, [[x0, y0], [x1, y1]]",
                        pts.len()
                    ),
                ));
            }
            let p = cx.point::<2>("symmetry.mirror_axis[0]", &pts[0])?;
            let q = cx.point::<2>("symmetry.mirror_axis[1]", &pts[1])?;
            if (q[0] - p[0]).hypot(q[1] - p[1]) <= 1e-9 {
                return Err(cx.err(
                    "symmetry.mirror_axis",
                    "the two points coincide: the axis needs two distinct points",
                ));
            }
            Some([p, q])
        }
    };
    Ok(super::PatternSymmetry {
        rotations,
        center,
        mirror_axis,
    })
}

/// Why `name` cannot name a task (it names the output directory `out/<name>`).
fn check_name(name: &str) -> Result<(), String> {
    let shown = crate::text::excerpt(name, 40);
    let max = crate::limits::NAME_MAX;
    if name.chars().count() > max {
        return Err(format!(
            "\"{shown}\" is longer than {max} characters (the name becomes a directory name)"
        ));
    }
    if name.contains(['/', '\\']) || name.chars().any(char::is_control) {
        return Err(format!(
            "{shown:?}: a task name may not contain path separators or control characters (it becomes the directory out/<name>)"
        ));
    }
    if name.contains("..") || name.trim() == "." {
        return Err(format!(
            "{shown:?}: a task name may not contain \"..\" or be \".\" (it becomes the directory out/<name>)"
        ));
    }
    Ok(())
}
