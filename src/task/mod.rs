//! Design task files (`grammar/*.toml`): parsing and validation.
//!
//! A task file holds the initial graph G0 (vertices with in-plane coordinates and types,
//! creases with their facet labels and driving angles), the grammar's limit N_max, the
//! task's symmetry, and the design task the later stages use: the motion range, the
//! variable bounds, the objective (points to reach at given t), the intersection-check
//! setup (thesis Sec. 5.1, 5.5; SPEC §4) and optional design constraints (`[constraints]
//! kawasaki = true`: flat-foldable vertices). Every field is checked on load; a bad file gets a
//! [`TaskError`] naming the file, the field and what is allowed.
//!
//! ```toml
//! name = "gripper"
//! [grammar]
//! n_max = 3
//! [symmetry]
//! mirror_xz = true
//! [[initial_graph.vertices]]
//! id = "v1"
//! xy = [0.0, 0.0]
//! type = "terminal"      # ∅: a source, never extended
//! [[initial_graph.vertices]]
//! id = "v2"
//! xy = [1.0, 0.0]
//! type = "extendable"    # χ
//! [[initial_graph.creases]]
//! from = "v1"
//! to = "v2"
//! left = "f1"
//! right = "f2"
//! drive = "t"
//! ```

mod drive;
mod initial;
pub mod number;
mod robustness;
pub mod terms;

use std::path::{Path, PathBuf};

use serde::Deserialize;

pub use drive::Drive;
pub use initial::{InitialCrease, InitialGraph, InitialVertex};
pub use number::Number;
pub use robustness::{
    DEFAULT_CLEARANCE, DEFAULT_MIN_FEATURE, DEFAULT_RIGID_MARGIN, MAX_RIGID_MARGIN, Robustness,
};

use crate::grammar::VertexType;

/// A task file that failed to load: the file, the field (a TOML path such as
/// `initial_graph.creases[0].drive`) and what is wrong / what is allowed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{file}: {field}: {message}")]
pub struct TaskError {
    /// The file (or the label given to [`Task::from_toml_str`]).
    pub file: String,
    /// The offending field.
    pub field: String,
    /// What is wrong and what is allowed.
    pub message: String,
}

/// A validated design task.
#[derive(Clone, Debug)]
pub struct Task {
    /// The task's name (defaults to the file stem): at most [`crate::limits::NAME_MAX`]
    /// characters, no path separators, no `..`, no control characters.
    pub name: String,
    /// Digest of the file's text (FNV-1a, 64 bits, hex): a search resumes only the same
    /// task.
    pub digest: String,
    /// Free text.
    pub description: Option<String>,
    /// Where it was loaded from, if from a file.
    pub source: Option<PathBuf>,
    /// The initial graph G0 with its derived crease order.
    pub initial: InitialGraph,
    /// The maximum number of internal (extended) vertices, N_max.
    pub n_max: usize,
    /// Symmetry of the task.
    pub symmetry: Symmetry,
    /// The driving parameter's range, if the task defines a motion.
    pub motion: Option<Motion>,
    /// Variable bounds (Eq. 31–32), if given.
    pub bounds: Option<Bounds>,
    /// The objective (Eq. 37–38), if given.
    pub objective: Option<Objective>,
    /// Intersection-check setup (Sec. 5.4.2), if given.
    pub check: Option<CheckSpec>,
    /// Margins the optimizer keeps over the whole motion (`[robustness]`, defaults when
    /// absent).
    pub robustness: Robustness,
    /// `[constraints] kawasaki = true`: every internal vertex of even degree folds flat
    /// (Kawasaki's condition, imposed by the model); off when absent.
    pub kawasaki: bool,
}

/// Symmetry of a design task.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Symmetry {
    /// Task and G0 are symmetric about the xz-plane (in-plane: the x-axis), so a graph and its
    /// mirror image give the same designs (thesis Sec. 5.5.2).
    pub mirror_xz: bool,
}

/// The driving parameter t runs from 0 to `t_max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// End of the motion, in radians, nonzero, |t_max| ≤ π.
    pub t_max: f64,
}

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

/// Ω = Σ_i w_i ‖P_i − X_g(t_i)‖ over the targets; success when Ω* ≤ threshold.
#[derive(Clone, Debug, PartialEq)]
pub struct Objective {
    /// Points the gripping vertex should reach at given t.
    pub targets: Vec<Target>,
    /// Success threshold ϑ.
    pub threshold: f64,
}

/// One point to reach at one value of t.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// The driving parameter.
    pub t: f64,
    /// The 3D point.
    pub point: [f64; 3],
    /// Weight in the objective (1 unless given).
    pub weight: f64,
}

/// Intersection-check setup.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckSpec {
    /// Number of evenly spaced states over [0, t_max] to check (the thesis uses 16).
    pub states: usize,
    /// Cylindrical obstacles.
    pub cylinders: Vec<Cylinder>,
    /// The design is one arm of a two-armed device: checks and pictures include a copy
    /// rotated 180° about the z-axis (the gripper, Sec. 5.5.1).
    pub second_arm: bool,
    /// Number of evenly spaced states over [0, t_max] at which the optimizer imposes the
    /// clearance and margin constraints (more are added where a finer sweep finds the
    /// design closer than allowed).
    pub optimize_states: usize,
}

/// Default of `[check] optimize_states`.
pub const DEFAULT_OPTIMIZE_STATES: usize = 9;

/// A cylinder obstacle (axis segment `a → b` and radius): the checks' own type, so the
/// task, the intersection check and the pictures share one definition.
pub use crate::check::Cylinder;

/// Largest N_max accepted: each extension multiplies the number of graphs by roughly
/// twenty (with all filters: 101 graphs at N_max = 3, 1,929 at 4, 41,549 at 5).
pub const N_MAX_LIMIT: usize = crate::limits::N_MAX;

// ---------------------------------------------------------------------------------------
// Raw file format (serde), checked by `Task::from_toml_str`.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTask {
    name: Option<String>,
    description: Option<String>,
    grammar: RawGrammar,
    #[serde(default)]
    symmetry: RawSymmetry,
    initial_graph: RawInitial,
    motion: Option<RawMotion>,
    bounds: Option<RawBounds>,
    objective: Option<RawObjective>,
    check: Option<RawCheck>,
    robustness: Option<robustness::RawRobustness>,
    constraints: Option<RawConstraints>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConstraints {
    #[serde(default)]
    kawasaki: bool,
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
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawInitial {
    #[serde(default)]
    pub(crate) vertices: Vec<RawVertex>,
    #[serde(default)]
    pub(crate) creases: Vec<RawCrease>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawVertex {
    pub(crate) id: String,
    pub(crate) xy: Vec<Number>,
    #[serde(rename = "type")]
    pub(crate) ty: RawType,
}

#[derive(Deserialize, Clone, Copy)]
pub(crate) enum RawType {
    #[serde(rename = "extendable", alias = "chi", alias = "χ")]
    Extendable,
    #[serde(rename = "terminal", alias = "none", alias = "∅")]
    Terminal,
}

impl From<RawType> for VertexType {
    fn from(t: RawType) -> Self {
        match t {
            RawType::Extendable => VertexType::Extendable,
            RawType::Terminal => VertexType::Terminal,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawCrease {
    pub(crate) from: String,
    pub(crate) to: String,
    pub(crate) left: String,
    pub(crate) right: String,
    pub(crate) drive: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMotion {
    t_max: Number,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBounds {
    l_min: Number,
    l_max: Number,
    alpha_min: Number,
    alpha_max: Number,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawObjective {
    threshold: Number,
    targets: Vec<RawTarget>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTarget {
    t: Number,
    point: Vec<Number>,
    weight: Option<Number>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCheck {
    states: i64,
    #[serde(default)]
    cylinders: Vec<RawCylinder>,
    #[serde(default)]
    second_arm: bool,
    optimize_states: Option<i64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCylinder {
    radius: Number,
    from: Vec<Number>,
    to: Vec<Number>,
}

/// Builds errors for one file.
pub(crate) struct Ctx<'a> {
    pub(crate) file: &'a str,
}

impl Ctx<'_> {
    pub(crate) fn err(&self, field: impl Into<String>, message: impl Into<String>) -> TaskError {
        TaskError {
            file: self.file.to_owned(),
            field: field.into(),
            message: message.into(),
        }
    }

    /// A finite number within ±[`crate::limits::COORD_MAX`], evaluated.
    pub(crate) fn num(&self, field: &str, n: &Number) -> Result<f64, TaskError> {
        let v = n.value().map_err(|m| self.err(field, m))?;
        if !v.is_finite() {
            return Err(self.err(field, format!("{n} is not a finite number")));
        }
        if v.abs() > crate::limits::COORD_MAX {
            return Err(self.err(
                field,
                format!(
                    "{} is out of range: numbers in a task file lie within ±{} (beyond that, squared distances overflow)",
                    crate::text::num(v),
                    crate::text::num(crate::limits::COORD_MAX)
                ),
            ));
        }
        Ok(v)
    }

    /// Exactly `N` numbers (a point), each checked by [`Ctx::num`].
    pub(crate) fn point<const N: usize>(
        &self,
        field: &str,
        p: &[Number],
    ) -> Result<[f64; N], TaskError> {
        if p.len() != N {
            return Err(self.err(
                field,
                format!(
                    "{} values given; exactly {N} are needed ({})",
                    p.len(),
                    if N == 2 { "x, y" } else { "x, y, z" }
                ),
            ));
        }
        let mut out = [0.0; N];
        for (i, n) in p.iter().enumerate() {
            out[i] = self.num(&format!("{field}[{i}]"), n)?;
        }
        Ok(out)
    }
}

impl Task {
    /// Load and validate a task file.
    pub fn load(path: impl AsRef<Path>) -> Result<Task, TaskError> {
        let path = path.as_ref();
        let label = path.display().to_string();
        let text = crate::limits::read_text(path).map_err(|e| TaskError {
            file: label.clone(),
            field: "(file)".into(),
            message: format!("cannot read the task file: {e}"),
        })?;
        let mut task = Task::from_toml_str(&text, &label)?;
        task.source = Some(path.to_owned());
        if task.name.is_empty() {
            // The file stem, cut to the limit (the output directory is made safe from it).
            task.name = path
                .file_stem()
                .map(|s| {
                    s.to_string_lossy()
                        .chars()
                        .take(crate::limits::NAME_MAX)
                        .collect()
                })
                .unwrap_or_default();
        }
        Ok(task)
    }

    /// Parse and validate task text; `file` labels the messages.
    pub fn from_toml_str(text: &str, file: &str) -> Result<Task, TaskError> {
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
        let symmetry = Symmetry {
            mirror_xz: raw.symmetry.mirror_xz,
        };
        let initial = initial::build(&cx, &raw.initial_graph, symmetry.mirror_xz)?;
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

        let motion = match &raw.motion {
            None => None,
            Some(m) => {
                let t_max = cx.num("motion.t_max", &m.t_max)?;
                if t_max == 0.0 || t_max.abs() > std::f64::consts::PI + 1e-12 {
                    return Err(cx.err(
                        "motion.t_max",
                        format!(
                            "{t_max} is not allowed: t_max must be nonzero and within [-pi, pi]"
                        ),
                    ));
                }
                Some(Motion { t_max })
            }
        };

        let bounds = match &raw.bounds {
            None => None,
            Some(b) => {
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
                        format!("{alpha_max} is not allowed: alpha_max must lie in (alpha_min = {alpha_min}, pi)"),
                    ));
                }
                Some(Bounds {
                    l_min,
                    l_max,
                    alpha_min,
                    alpha_max,
                })
            }
        };

        let objective = match &raw.objective {
            None => None,
            Some(o) => {
                let Some(motion) = motion else {
                    return Err(cx.err(
                        "objective",
                        "an objective needs the motion range: add [motion] with t_max",
                    ));
                };
                let threshold = cx.num("objective.threshold", &o.threshold)?;
                if threshold < 0.0 {
                    return Err(cx.err(
                        "objective.threshold",
                        format!("{threshold} is not allowed: the threshold must be ≥ 0"),
                    ));
                }
                if o.targets.is_empty() {
                    return Err(cx.err(
                        "objective.targets",
                        "no targets: give at least one [[objective.targets]] with t and point",
                    ));
                }
                let (lo, hi) = if motion.t_max > 0.0 {
                    (0.0, motion.t_max)
                } else {
                    (motion.t_max, 0.0)
                };
                let mut targets = Vec::with_capacity(o.targets.len());
                for (i, t) in o.targets.iter().enumerate() {
                    let f = format!("objective.targets[{i}]");
                    let tv = cx.num(&format!("{f}.t"), &t.t)?;
                    if tv < lo - 1e-12 || tv > hi + 1e-12 {
                        return Err(cx.err(
                            format!("{f}.t"),
                            format!("{tv} is outside the motion range [{lo}, {hi}]"),
                        ));
                    }
                    let point = cx.point(&format!("{f}.point"), &t.point)?;
                    let weight = match &t.weight {
                        None => 1.0,
                        Some(w) => cx.num(&format!("{f}.weight"), w)?,
                    };
                    if weight <= 0.0 {
                        return Err(cx.err(
                            format!("{f}.weight"),
                            format!("{weight} is not allowed: weights must be > 0"),
                        ));
                    }
                    targets.push(Target {
                        t: tv,
                        point,
                        weight,
                    });
                }
                Some(Objective { targets, threshold })
            }
        };

        let check = match &raw.check {
            None => None,
            Some(c) => {
                let max = crate::limits::STATES_MAX as i64;
                if !(2..=max).contains(&c.states) {
                    return Err(cx.err(
                        "check.states",
                        format!(
                            "{} is not allowed: at least 2 states (0 and t_max), at most {max}",
                            c.states
                        ),
                    ));
                }
                let optimize_states = c.optimize_states.unwrap_or(DEFAULT_OPTIMIZE_STATES as i64);
                if !(2..=crate::limits::STATES_MAX as i64).contains(&optimize_states) {
                    return Err(cx.err(
                        "check.optimize_states",
                        format!(
                            "{optimize_states} is not allowed: at least 2 states (0 and t_max), at most {}", crate::limits::STATES_MAX
                        ),
                    ));
                }
                let mut cylinders = Vec::new();
                for (i, cy) in c.cylinders.iter().enumerate() {
                    let f = format!("check.cylinders[{i}]");
                    let radius = cx.num(&format!("{f}.radius"), &cy.radius)?;
                    if radius <= 0.0 {
                        return Err(cx.err(
                            format!("{f}.radius"),
                            format!("{radius} is not allowed: the radius must be > 0"),
                        ));
                    }
                    let from = cx.point(&format!("{f}.from"), &cy.from)?;
                    let to = cx.point(&format!("{f}.to"), &cy.to)?;
                    if from == to {
                        return Err(cx.err(
                            format!("{f}.to"),
                            "the axis end equals its start: the axis needs two distinct points",
                        ));
                    }
                    cylinders.push(Cylinder {
                        a: from,
                        b: to,
                        radius,
                    });
                }
                Some(CheckSpec {
                    states: c.states as usize,
                    cylinders,
                    second_arm: c.second_arm,
                    optimize_states: optimize_states as usize,
                })
            }
        };

        let robustness = robustness::build(&cx, raw.robustness.as_ref(), &initial)?;

        Ok(Task {
            name: name.trim().to_string(),
            digest: digest(text.as_bytes()),
            description: raw.description,
            source: None,
            initial,
            n_max: n_max as usize,
            symmetry,
            motion,
            bounds,
            objective,
            check,
            robustness,
            kawasaki: raw.constraints.is_some_and(|c| c.kawasaki),
        })
    }
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

/// FNV-1a (64 bits) of `bytes`, as 16 hex digits: enough to notice an edited file.
pub fn digest(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h = (h ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// A TOML syntax or schema error, located by line and column, with the offending key when
/// the span covers one.
fn syntax_error(file: &str, text: &str, e: &toml::de::Error) -> TaskError {
    let (field, loc) = match e.span() {
        Some(span) => {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            let snippet = text.get(span.clone()).unwrap_or("").trim();
            let field = if !snippet.is_empty() && snippet.len() <= 40 && !snippet.contains('\n') {
                format!("`{snippet}`")
            } else {
                "(syntax)".to_owned()
            };
            (field, format!("line {line}, column {col}: "))
        }
        None => ("(syntax)".to_owned(), String::new()),
    };
    TaskError {
        file: file.to_owned(),
        field,
        message: format!("{loc}{}", crate::text::excerpt(e.message().trim(), 300)),
    }
}
