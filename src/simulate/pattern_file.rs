//! Pattern files for the simulator (`grammar/*.toml`).
//!
//! ```toml
//! name = "one crease"
//! vertices = [                       # name and position: [x, y] (z = 0) or [x, y, z]
//!   { name = "a", at = [0, 0] },
//!   { name = "b", at = [0, 1] },
//!   { name = "c", at = [1, 0] },
//!   { name = "d", at = [-1, 0] },
//! ]
//! faces = [["a", "c", "b"], ["a", "b", "d"]]   # counter-clockwise seen from +z
//! fixed = ["a", "b", "c"]                      # held in place
//!
//! [motion]
//! t_start = 0
//! t_end = "pi/2"          # a number or a formula without t
//! steps = 10              # J
//! check_intersections = true   # optional, default true
//!
//! [[drive]]               # a vertex on a path: formulas in t (see `formula`)
//! kind = "trajectory"
//! vertex = "d"
//! x = "-cos(t)"
//! y = 0
//! z = "sin(t)"
//! ```
//!
//! A crease drive instead names the crease, a vertex on the side that moves, and the fold
//! angle (valley positive; it must equal the crease's initial fold angle at `t_start`):
//!
//! ```toml
//! [[drive]]
//! kind = "crease"
//! crease = ["a", "b"]
//! moving = "d"            # the facet at the crease that contains d turns; the other is fixed
//! angle = "t"
//! ```
//!
//! Optional parts:
//!
//! * `[symmetry] rotations = n` replicates the pattern n times about the z-axis (copy k
//!   turned by k·360°/n counter-clockwise). Copy k of vertex `v` is named `v@k` (`v` itself
//!   is copy 0); a vertex on the axis is one vertex shared by all copies. Inside `faces`,
//!   `drive` and `first_step_offset`, which are replicated, `v@m` means "m copies further
//!   on" from the copy being built. `faces_once` and `fixed` are not replicated, and there
//!   `v@m` names copy m itself.
//! * `[[first_step_offset]] vertex = "v", offset = [dx, dy, dz]`: the vertex's displacement
//!   over the first step on the branch to follow (mountain or valley at the flat state);
//!   see [`SimInput::first_step_offsets`].
//!
//! Unknown keys are errors, and every error names the file and the field.

use std::collections::HashMap;
use std::f64::consts::TAU;
use std::path::Path;
use std::sync::Arc;

use serde::Deserialize;
use thiserror::Error;

use super::formula::Formula;
use super::input::{Drive, SimInput, SolverSettings};

/// A pattern file that could not be read, with the file, the field and what is allowed.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{origin}: {field}: {message}")]
pub struct PatternFileError {
    /// The file (or other origin) of the text.
    pub origin: String,
    /// The field at fault (e.g. `drive[0].y`), or `toml` for syntax errors.
    pub field: String,
    /// What is wrong and what is allowed.
    pub message: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Spec {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    description: Option<String>,
    vertices: Vec<VertexSpec>,
    faces: Vec<Vec<String>>,
    #[serde(default)]
    faces_once: Vec<Vec<String>>,
    #[serde(default)]
    fixed: Vec<String>,
    motion: MotionSpec,
    #[serde(default)]
    symmetry: Option<SymmetrySpec>,
    #[serde(default)]
    drive: Vec<DriveSpec>,
    #[serde(default)]
    first_step_offset: Vec<OffsetSpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct VertexSpec {
    name: String,
    at: Vec<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MotionSpec {
    t_start: Num,
    t_end: Num,
    steps: usize,
    #[serde(default = "yes")]
    check_intersections: bool,
}

fn yes() -> bool {
    true
}

#[derive(Deserialize, Clone)]
#[serde(untagged)]
enum Num {
    Value(f64),
    Text(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SymmetrySpec {
    rotations: usize,
}

#[derive(Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
enum DriveSpec {
    Trajectory {
        vertex: String,
        x: Num,
        y: Num,
        z: Num,
    },
    Crease {
        crease: [String; 2],
        moving: String,
        angle: Num,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OffsetSpec {
    vertex: String,
    offset: [f64; 3],
}

/// A loaded pattern file: the simulator input plus the names it was written with.
#[derive(Clone, Debug)]
pub struct PatternFile {
    /// The `name` field (or the origin when absent).
    pub name: String,
    /// The `description` field, if any.
    pub description: Option<String>,
    /// Name of every vertex of the expanded pattern (`v`, `v@1`, …).
    pub vertex_names: Vec<String>,
    /// The simulator input.
    pub input: SimInput,
    /// Number of rotational copies (1 without `[symmetry]`).
    pub rotations: usize,
    /// For every vertex written in the file, its index in each copy.
    copies: HashMap<String, Vec<usize>>,
}

impl PatternFile {
    /// Read and parse a pattern file.
    pub fn load(path: &Path) -> Result<PatternFile, PatternFileError> {
        let origin = path.display().to_string();
        let text = crate::limits::read_text(path).map_err(|e| PatternFileError {
            origin: origin.clone(),
            field: "file".into(),
            message: format!("cannot read: {e}"),
        })?;
        Self::parse(&text, &origin)
    }

    /// Parse the text of a pattern file; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<PatternFile, PatternFileError> {
        let err = |field: &str, message: String| error(origin, field, message);
        if let Some(kind) = crate::text::other_kind(text, "pattern") {
            return Err(err("(file)", kind));
        }
        let spec: Spec = toml::from_str(text).map_err(|e| {
            err(
                "toml",
                crate::text::excerpt(&e.to_string(), 600)
                    .trim_end()
                    .replace('\n', "\n    "),
            )
        })?;
        let rot = match &spec.symmetry {
            None => 1,
            Some(s) if (1..=360).contains(&s.rotations) => s.rotations,
            Some(s) => {
                return Err(err(
                    "symmetry.rotations",
                    format!("must be between 1 and 360, got {}", s.rotations),
                ));
            }
        };
        if spec.vertices.is_empty() {
            return Err(err("vertices", "at least one vertex is needed".into()));
        }
        if spec.faces.is_empty() && spec.faces_once.is_empty() {
            return Err(err(
                "faces",
                "at least one facet is needed (bars come from facets)".into(),
            ));
        }
        let mut r = Reader {
            origin,
            rot,
            names: Vec::new(),
            initial: Vec::new(),
            copies: HashMap::new(),
        };
        r.vertices(&spec.vertices)?;
        let faces = r.faces(&spec)?;
        let fixed = spec
            .fixed
            .iter()
            .map(|s| r.resolve("fixed", s, 0))
            .collect::<Result<Vec<_>, _>>()?;
        let t_start = r.constant("motion.t_start", &spec.motion.t_start)?;
        let t_end = r.constant("motion.t_end", &spec.motion.t_end)?;
        let max = crate::limits::STEPS_MAX;
        if spec.motion.steps == 0 || spec.motion.steps as u64 > max {
            return Err(err(
                "motion.steps",
                format!(
                    "{} is not allowed: must be at least 1 and at most {max}",
                    spec.motion.steps
                ),
            ));
        }
        let drives = r.drives(&spec.drive, &faces, t_start)?;
        let first_step_offsets = r.offsets(&spec.first_step_offset)?;
        let Reader {
            names,
            initial,
            copies,
            ..
        } = r;
        let input = SimInput {
            initial,
            faces,
            extra_bars: Vec::new(),
            fixed,
            drives,
            t_start,
            t_end,
            steps: spec.motion.steps,
            first_step_offsets,
            check_intersections: spec.motion.check_intersections,
            solver: SolverSettings::default(),
        };
        if let Err(e) = input.resolve() {
            let legend: Vec<String> = names
                .iter()
                .enumerate()
                .map(|(i, n)| format!("{i}={n}"))
                .collect();
            return Err(err(
                "drive/fixed",
                format!("{e} (vertex numbers: {})", legend.join(", ")),
            ));
        }
        Ok(PatternFile {
            name: spec.name.unwrap_or_else(|| origin.to_string()),
            description: spec.description,
            vertex_names: names,
            input,
            rotations: rot,
            copies,
        })
    }

    /// Index of a vertex by its expanded name (`v` or `v@k`).
    pub fn vertex(&self, name: &str) -> Option<usize> {
        self.vertex_names.iter().position(|n| n == name)
    }

    /// Indices of all copies of a vertex written in the file (one per rotation).
    pub fn copies(&self, name: &str) -> Option<&[usize]> {
        self.copies.get(name).map(Vec::as_slice)
    }

    /// Move a vertex written in the file to `p` (copy 0) and its copies to the rotations of
    /// `p`. Returns false when there is no such vertex.
    pub fn set_position(&mut self, name: &str, p: [f64; 3]) -> bool {
        let Some(idx) = self.copies.get(name) else {
            return false;
        };
        for (c, &i) in idx.iter().enumerate() {
            self.input.initial[i] = rotate(p, c, self.rotations);
        }
        true
    }
}

fn error(origin: &str, field: &str, message: String) -> PatternFileError {
    PatternFileError {
        origin: origin.to_string(),
        field: field.to_string(),
        message,
    }
}

/// The pattern as read so far: the vertices replicated over the rotations.
struct Reader<'a> {
    origin: &'a str,
    /// Number of rotational copies.
    rot: usize,
    /// Name of every vertex of the expanded pattern.
    names: Vec<String>,
    /// Its position.
    initial: Vec<[f64; 3]>,
    /// For every vertex written in the file, its index in each copy.
    copies: HashMap<String, Vec<usize>>,
}

impl Reader<'_> {
    fn err(&self, field: &str, message: String) -> PatternFileError {
        error(self.origin, field, message)
    }

    /// The vertices, replicated (a vertex on the axis is its own copy).
    fn vertices(&mut self, spec: &[VertexSpec]) -> Result<(), PatternFileError> {
        let rot = self.rot;
        for (k, v) in spec.iter().enumerate() {
            let field = format!("vertices[{k}]");
            if v.name.is_empty() || v.name.contains('@') || v.name.contains(char::is_whitespace) {
                return Err(self.err(
                    &format!("{field}.name"),
                    format!(
                        "'{}' is not allowed: names are non-empty, without '@' or spaces",
                        crate::text::excerpt(&v.name, 40)
                    ),
                ));
            }
            if self.copies.contains_key(&v.name) {
                return Err(self.err(
                    &format!("{field}.name"),
                    format!("'{}' is used twice", v.name),
                ));
            }
            let p = self.position(&field, &v.at)?;
            let on_axis = rot > 1 && p[0].abs() <= 1e-12 && p[1].abs() <= 1e-12;
            let mut idx = Vec::with_capacity(rot);
            for c in 0..rot {
                if on_axis && c > 0 {
                    idx.push(idx[0]);
                    continue;
                }
                idx.push(self.names.len());
                self.names.push(if c == 0 {
                    v.name.clone()
                } else {
                    format!("{}@{c}", v.name)
                });
                self.initial.push(rotate(p, c, rot));
            }
            self.copies.insert(v.name.clone(), idx);
        }
        Ok(())
    }

    /// A vertex's `at`: [x, y] or [x, y, z], finite and within range.
    fn position(&self, field: &str, at: &[f64]) -> Result<[f64; 3], PatternFileError> {
        let p = match at {
            &[x, y] => [x, y, 0.0],
            &[x, y, z] => [x, y, z],
            other => {
                return Err(self.err(
                    &format!("{field}.at"),
                    format!("expected [x, y] or [x, y, z], got {} numbers", other.len()),
                ));
            }
        };
        if p.iter()
            .any(|x| !(x.is_finite() && x.abs() <= crate::limits::COORD_MAX))
        {
            return Err(self.err(
                &format!("{field}.at"),
                format!(
                    "coordinates must be finite and within ±{}",
                    crate::text::num(crate::limits::COORD_MAX)
                ),
            ));
        }
        Ok(p)
    }

    /// Resolve `name` / `name@m` in copy `base` (relative) or absolutely (base = 0).
    fn resolve(&self, field: &str, s: &str, base: usize) -> Result<usize, PatternFileError> {
        let rot = self.rot;
        let (name, m) = match s.split_once('@') {
            None => (s, 0),
            Some((n, m)) => {
                if rot == 1 {
                    return Err(
                        self.err(field, format!("'{s}': copies (@) need a [symmetry] table"))
                    );
                }
                match m.parse::<usize>() {
                    Ok(m) if m < rot => (n, m),
                    _ => {
                        return Err(self.err(
                            field,
                            format!("'{s}': the copy after '@' must be 0..{}", rot - 1),
                        ));
                    }
                }
            }
        };
        let idx = self
            .copies
            .get(name)
            .ok_or_else(|| self.err(field, format!("unknown vertex '{name}'")))?;
        Ok(idx[(base + m) % rot])
    }

    /// The facets: `faces` in every copy, then `faces_once`; each of at least 3 distinct
    /// vertices.
    fn faces(&self, spec: &Spec) -> Result<Vec<Vec<usize>>, PatternFileError> {
        let mut faces: Vec<Vec<usize>> = Vec::new();
        for c in 0..self.rot {
            for (k, f) in spec.faces.iter().enumerate() {
                let field = format!("faces[{k}]");
                let face = f
                    .iter()
                    .map(|s| self.resolve(&field, s, c))
                    .collect::<Result<Vec<_>, _>>()?;
                faces.push(face);
            }
        }
        for (k, f) in spec.faces_once.iter().enumerate() {
            let field = format!("faces_once[{k}]");
            let face = f
                .iter()
                .map(|s| self.resolve(&field, s, 0))
                .collect::<Result<Vec<_>, _>>()?;
            faces.push(face);
        }
        for (k, f) in faces.iter().enumerate() {
            let mut s = f.clone();
            s.sort_unstable();
            s.dedup();
            if s.len() < 3 || s.len() != f.len() {
                return Err(self.err(
                    "faces",
                    format!(
                        "facet {k} ({}) must list at least 3 distinct vertices",
                        f.iter()
                            .map(|&v| self.names[v].as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ));
            }
        }
        Ok(faces)
    }

    /// A number, or a formula without t.
    fn constant(&self, field: &str, n: &Num) -> Result<f64, PatternFileError> {
        let x = match n {
            Num::Value(x) => *x,
            Num::Text(s) => {
                let f = Formula::parse(s).map_err(|e| self.err(field, e.to_string()))?;
                f.eval(f64::NAN)
            }
        };
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.err(
                field,
                "must be a finite number or a formula without t (e.g. \"pi/2\")".into(),
            ))
        }
    }

    /// A finite number or a formula in t.
    fn formula(&self, field: &str, n: &Num) -> Result<Formula, PatternFileError> {
        match n {
            Num::Value(x) if x.is_finite() => Ok(Formula::constant(*x)),
            Num::Value(_) => Err(self.err(field, "must be finite".into())),
            Num::Text(s) => Formula::parse(s).map_err(|e| self.err(field, e.to_string())),
        }
    }

    /// The drives, replicated.
    fn drives(
        &self,
        spec: &[DriveSpec],
        faces: &[Vec<usize>],
        t_start: f64,
    ) -> Result<Vec<Drive>, PatternFileError> {
        let mut drives = Vec::new();
        for (k, d) in spec.iter().enumerate() {
            let field = format!("drive[{k}]");
            match d {
                DriveSpec::Trajectory { vertex, x, y, z } => {
                    let fx = self.formula(&format!("{field}.x"), x)?;
                    let fy = self.formula(&format!("{field}.y"), y)?;
                    let fz = self.formula(&format!("{field}.z"), z)?;
                    for c in 0..self.rot {
                        let v = self.resolve(&format!("{field}.vertex"), vertex, c)?;
                        let f = [fx.clone(), fy.clone(), fz.clone()];
                        drives.push(self.trajectory(&field, v, c, f, t_start)?);
                    }
                }
                DriveSpec::Crease {
                    crease,
                    moving,
                    angle,
                } => {
                    let fa = self.formula(&format!("{field}.angle"), angle)?;
                    for c in 0..self.rot {
                        let p = self.resolve(&format!("{field}.crease"), &crease[0], c)?;
                        let q = self.resolve(&format!("{field}.crease"), &crease[1], c)?;
                        let m = self.resolve(&format!("{field}.moving"), moving, c)?;
                        let (fixed_face, moving_face) =
                            self.crease_faces(&field, faces, (p, q), m)?;
                        drives.push(Drive::crease_from_formula(
                            p,
                            q,
                            fixed_face,
                            moving_face,
                            fa.clone(),
                        ));
                    }
                }
            }
        }
        Ok(drives)
    }

    /// Vertex `v` (in copy `c`) on the path `f` turned into that copy; the path must start
    /// at the vertex.
    fn trajectory(
        &self,
        field: &str,
        v: usize,
        c: usize,
        f: [Formula; 3],
        t_start: f64,
    ) -> Result<Drive, PatternFileError> {
        let rot = self.rot;
        let [fx, fy, fz] = f;
        let at0 = rotate(
            [fx.eval(t_start), fy.eval(t_start), fz.eval(t_start)],
            c,
            rot,
        );
        let init = self.initial[v];
        let gap = (0..3).map(|i| (at0[i] - init[i]).abs()).fold(0.0, f64::max);
        let scale = init.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
        if gap.is_nan() || gap > 1e-9 * scale {
            return Err(self.err(
                field,
                format!(
                    "the trajectory of '{}' starts at ({:.6}, {:.6}, {:.6}) at t_start = {t_start}, \
                     but the vertex is at ({:.6}, {:.6}, {:.6}); a path must start at its vertex",
                    self.names[v], at0[0], at0[1], at0[2], init[0], init[1], init[2]
                ),
            ));
        }
        Ok(Drive::Trajectory {
            vertex: v,
            path: Arc::new(move |t| rotate([fx.eval(t), fy.eval(t), fz.eval(t)], c, rot)),
        })
    }

    /// The fixed and the moving facet of the crease p–q, the moving one holding `m`.
    fn crease_faces(
        &self,
        field: &str,
        faces: &[Vec<usize>],
        (p, q): (usize, usize),
        m: usize,
    ) -> Result<(usize, usize), PatternFileError> {
        let names = &self.names;
        let at_crease: Vec<usize> = (0..faces.len())
            .filter(|&f| has_side(&faces[f], p, q))
            .collect();
        if at_crease.len() != 2 {
            return Err(self.err(
                &format!("{field}.crease"),
                format!(
                    "{}–{} is a side of {} facets; a crease is a side of exactly 2",
                    names[p],
                    names[q],
                    at_crease.len()
                ),
            ));
        }
        let mv: Vec<usize> = at_crease
            .iter()
            .copied()
            .filter(|&f| faces[f].contains(&m) && m != p && m != q)
            .collect();
        if mv.len() != 1 {
            return Err(self.err(
                &format!("{field}.moving"),
                format!(
                    "'{}' must be a vertex (not on the crease) of exactly one of the two facets at {}–{}",
                    names[m], names[p], names[q]
                ),
            ));
        }
        let moving_face = mv[0];
        let fixed_face = at_crease[0] + at_crease[1] - moving_face;
        Ok((fixed_face, moving_face))
    }

    /// The first step's offsets, replicated.
    fn offsets(&self, spec: &[OffsetSpec]) -> Result<Vec<(usize, [f64; 3])>, PatternFileError> {
        let mut first_step_offsets = Vec::new();
        for (k, o) in spec.iter().enumerate() {
            let field = format!("first_step_offset[{k}]");
            if o.offset.iter().any(|x| !x.is_finite()) {
                return Err(self.err(&format!("{field}.offset"), "must be finite".into()));
            }
            for c in 0..self.rot {
                let v = self.resolve(&format!("{field}.vertex"), &o.vertex, c)?;
                first_step_offsets.push((v, rotate(o.offset, c, self.rot)));
            }
        }
        Ok(first_step_offsets)
    }
}

/// `p` turned by `c`·360°/`n` about the z-axis.
pub(crate) fn rotate(p: [f64; 3], c: usize, n: usize) -> [f64; 3] {
    if c.is_multiple_of(n) {
        return p;
    }
    let (s, co) = (TAU * c as f64 / n as f64).sin_cos();
    // Exact quarter turns keep integer layouts exact.
    let (co, s) = match (4 * c).is_multiple_of(n) {
        true => (co.round(), s.round()),
        false => (co, s),
    };
    [co * p[0] - s * p[1], s * p[0] + co * p[1], p[2]]
}

fn has_side(f: &[usize], p: usize, q: usize) -> bool {
    (0..f.len()).any(|k| {
        let (a, b) = (f[k], f[(k + 1) % f.len()]);
        (a == p && b == q) || (a == q && b == p)
    })
}
