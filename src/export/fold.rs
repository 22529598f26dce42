//! FOLD files (<https://github.com/edemaine/fold/blob/main/doc/spec.md>, versions 1.1/1.2).
//!
//! ## What foldsynth writes
//!
//! The key frame (top level) is the crease pattern: `frame_classes: ["creasePattern"]`,
//! 2D `vertices_coords`, `edges_vertices`, `edges_assignment`, `edges_foldAngle` (degrees,
//! valley positive, of the *final* folded state, so tools that fold a crease pattern to
//! its target, like Origami Simulator, reach our final state; `null` for boundary edges,
//! which have no fold angle), and counter-clockwise
//! `faces_vertices`. Every folded state is one entry of `file_frames` with
//! `frame_classes: ["foldedForm"]`, `frame_parent: 0`, `frame_inherit: true`, its own 3D
//! `vertices_coords` and `edges_foldAngle`, and `foldsynth:t`.
//!
//! **Mountain/valley rule.** A boundary edge is `B`. A crease whose fold angle is within
//! 1e-9 rad of zero in every frame is `F`. Otherwise the sign of its fold angle at the
//! last frame decides (`V` positive, `M` negative); if it is zero there (but not
//! everywhere), the sign of its largest-magnitude angle over the motion decides. Fold
//! angles are written wrapped into (−180°, 180°].
//!
//! foldsynth's own data uses the spec's custom-property convention (a colon in the key):
//! `foldsynth:task`, `foldsynth:ruleSequence`, `foldsynth:modes`, `foldsynth:grippingVertex`
//! (the vertex name K of `vK`, 1-based as in foldsynth's rule sequences, report and design
//! JSON: its coordinates are `vertices_coords[K − 1]`), `foldsynth:objective`, `foldsynth:frameT` (t of each entry of `file_frames`),
//! `foldsynth:targets`, `foldsynth:trajectory`, `foldsynth:obstacle`,
//! `foldsynth:secondArm`, `foldsynth:extra`, and per edge `edges_foldsynth:driven`.
//!
//! ## What the reader accepts
//!
//! Any FOLD file: 2D or 3D coordinates, with or without `file_frames` (inheritance via
//! `frame_parent`/`frame_inherit` is resolved; `frame_inherit: true` without a
//! `frame_parent` inherits from the key frame), with or without `edges_foldAngle` (also the
//! pre-1.1 name `edges_foldAngles`, and `null` entries), `edges_assignment` or
//! `faces_vertices`. Missing faces are derived from the planar graph of the key frame;
//! missing edges from the faces' sides. Every folded frame is compared with the key frame
//! vertex by vertex, so all frames share the key frame's mesh; a frame that states a
//! different mesh is rejected. Malformed input gets a [`FoldError`] naming the file and the
//! field (e.g. `file_frames[0].vertices_coords[3][1]`).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use serde_json::{Map, Value, json};

use super::{DesignMeta, ExportError, FoldSpec, validate_meta, validate_pattern};
use crate::geom;
use crate::pattern::{Edge, EdgeKind, Frame, Pattern};

/// An error reading a FOLD file: which file, which field, what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: {field}: {message}")]
pub struct FoldError {
    /// The file (or `<string>` when parsing text).
    pub file: String,
    /// The field, with indices, e.g. `edges_vertices[4][1]`; `(file)` for the whole file.
    pub field: String,
    /// What is wrong and what is allowed.
    pub message: String,
}

/// An edge assignment (`edges_assignment`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Assignment {
    /// `B`: boundary.
    B,
    /// `M`: mountain.
    M,
    /// `V`: valley.
    V,
    /// `F`: flat crease.
    F,
    /// `U`: unassigned crease.
    U,
    /// `J`: join edge (treated as a crease that stays flat).
    J,
}

impl Assignment {
    /// The one-letter code.
    pub fn as_str(self) -> &'static str {
        match self {
            Assignment::B => "B",
            Assignment::M => "M",
            Assignment::V => "V",
            Assignment::F => "F",
            Assignment::U => "U",
            Assignment::J => "J",
        }
    }
}

/// Tolerance (radians) below which a fold angle counts as zero for the `F` assignment.
pub const FLAT_EPS: f64 = 1e-9;

/// Assignments of a pattern's edges by the rule in the module docs.
pub fn assignments(p: &Pattern) -> Vec<Assignment> {
    p.edges
        .iter()
        .enumerate()
        .map(|(i, e)| match e.kind {
            EdgeKind::Boundary => Assignment::B,
            EdgeKind::Crease { .. } => {
                let angles: Vec<f64> = p.frames.iter().map(|f| wrap(f.fold_angles[i])).collect();
                let decisive = match angles.last() {
                    Some(&a) if a.abs() > FLAT_EPS => Some(a),
                    _ => angles
                        .iter()
                        .copied()
                        .filter(|a| a.abs() > FLAT_EPS)
                        .max_by(|a, b| a.abs().total_cmp(&b.abs())),
                };
                match decisive {
                    None => Assignment::F,
                    Some(a) if a > 0.0 => Assignment::V,
                    Some(_) => Assignment::M,
                }
            }
        })
        .collect()
}

/// Wrap an angle (radians) into (−π, π].
pub fn wrap(a: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let mut x = a % TAU;
    if x <= -PI {
        x += TAU;
    } else if x > PI {
        x -= TAU;
    }
    x
}

fn render_value(v: &Value, indent: usize) -> String {
    let compact = |v: &Value| serde_json::to_string(v).unwrap_or_else(|_| "null".into());
    match v {
        Value::Array(items) if items.iter().any(|x| x.is_array() || x.is_object()) => {
            let pad = " ".repeat(indent + 2);
            let body: Vec<String> = items
                .iter()
                .map(|x| format!("{pad}{}", compact(x)))
                .collect();
            format!("[\n{}\n{}]", body.join(",\n"), " ".repeat(indent))
        }
        Value::Array(items) => {
            let body: Vec<String> = items.iter().map(compact).collect();
            format!("[{}]", body.join(", "))
        }
        _ => compact(v),
    }
}

fn render_object(entries: &[(String, String)], indent: usize) -> String {
    let pad = " ".repeat(indent + 2);
    let body: Vec<String> = entries
        .iter()
        .map(|(k, v)| format!("{pad}{}: {v}", Value::String(k.clone())))
        .collect();
    format!("{{\n{}\n{}}}", body.join(",\n"), " ".repeat(indent))
}

/// The FOLD document of a pattern and its metadata (see the module docs), as JSON text.
pub fn to_fold_string(p: &Pattern, meta: &DesignMeta, spec: FoldSpec) -> super::Result<String> {
    validate_pattern(p)?;
    validate_meta(meta, p)?;
    let assign = assignments(p);
    let final_angles = angles_deg(p, p.frames.last());
    let mut top: Vec<(String, String)> = Vec::new();
    let title = if meta.rule_sequence.is_empty() {
        meta.task.clone()
    } else {
        format!("{} {}", meta.task, meta.rule_sequence)
    };
    top.push(put("file_spec", json!(spec.number()), 2));
    top.push(put("file_creator", json!("foldsynth"), 2));
    top.push(put("file_title", json!(title), 2));
    top.push(put("file_classes", json!(["singleModel"]), 2));
    top.push(put("frame_title", json!("crease pattern"), 2));
    top.push(put("frame_classes", json!(["creasePattern"]), 2));
    top.push(put("frame_attributes", json!(["2D"]), 2));
    top.push(put("frame_unit", json!("unit"), 2));
    top.push(put("vertices_coords", json!(p.vertices), 2));
    let ev: Vec<[usize; 2]> = p.edges.iter().map(|e| e.v).collect();
    top.push(put("edges_vertices", json!(ev), 2));
    let asg: Vec<&str> = assign.iter().map(|a| a.as_str()).collect();
    top.push(put("edges_assignment", json!(asg), 2));
    top.push(put("edges_foldAngle", json!(final_angles), 2));
    top.push(put("faces_vertices", json!(p.faces), 2));
    put_foldsynth_fields(&mut top, p, meta);
    if !p.frames.is_empty() {
        top.push(("file_frames".into(), file_frames(p)));
    }
    let mut s = render_object(&top, 0);
    s.push('\n');
    Ok(s)
}

/// A field of the top level: its key and its value rendered at `indent`.
fn put(k: &str, v: Value, indent: usize) -> (String, String) {
    (k.to_string(), render_value(&v, indent))
}

/// The fold angles (degrees) of frame `f` (`None`: the flat state, all 0). Boundary edges
/// have no fold angle: `null`, as Origami Simulator writes them (it draws a line with
/// opacity |angle|/180, so 0 would hide the boundary).
fn angles_deg(p: &Pattern, f: Option<&Frame>) -> Vec<Option<f64>> {
    p.edges
        .iter()
        .enumerate()
        .map(|(i, e)| match e.kind {
            EdgeKind::Boundary => None,
            EdgeKind::Crease { .. } => Some(f.map_or(0.0, |f| wrap(f.fold_angles[i]).to_degrees())),
        })
        .collect()
}

/// foldsynth's own fields of the top level (see the module docs), in their order.
fn put_foldsynth_fields(top: &mut Vec<(String, String)>, p: &Pattern, meta: &DesignMeta) {
    let driven: Vec<bool> = p
        .edges
        .iter()
        .map(|e| matches!(e.kind, EdgeKind::Crease { driven: true }))
        .collect();
    top.push(put("edges_foldsynth:driven", json!(driven), 2));
    top.push(put("foldsynth:task", json!(meta.task), 2));
    top.push(put("foldsynth:ruleSequence", json!(meta.rule_sequence), 2));
    let modes: Vec<&str> = meta.modes.iter().map(|m| m.as_str()).collect();
    top.push(put("foldsynth:modes", json!(modes), 2));
    if let Some(g) = meta.gripping_vertex {
        top.push(put("foldsynth:grippingVertex", json!(g), 2));
    }
    if let Some(o) = meta.objective {
        top.push(put("foldsynth:objective", json!(o), 2));
    }
    let ts: Vec<f64> = p.frames.iter().map(|f| f.t).collect();
    top.push(put("foldsynth:frameT", json!(ts), 2));
    if !meta.targets.is_empty() {
        top.push(put("foldsynth:targets", json!(meta.targets), 2));
    }
    if !meta.trajectory.is_empty() {
        top.push(put("foldsynth:trajectory", json!(meta.trajectory), 2));
    }
    // The first cylinder and the half-turn copy as files before the scene wrote them (for
    // readers that know only those), then the whole scene.
    if let Some(c) = meta.first_cylinder() {
        top.push(put("foldsynth:obstacle", json!(c), 2));
    }
    top.push(put("foldsynth:secondArm", json!(meta.second_arm()), 2));
    top.push(put("foldsynth:scene", json!(meta.scene), 2));
    if !meta.goals.is_empty() {
        top.push(put("foldsynth:goals", json!(meta.goals), 2));
    }
    if !meta.surfaces.is_empty() {
        top.push(put("foldsynth:surfaces", json!(meta.surfaces), 2));
    }
    if !meta.extra.is_empty() {
        top.push(put("foldsynth:extra", json!(meta.extra), 2));
    }
}

/// The value of `file_frames`: one folded form per frame, inheriting the key frame's mesh.
fn file_frames(p: &Pattern) -> String {
    let frames: Vec<String> = p
        .frames
        .iter()
        .map(|f| {
            let angles = angles_deg(p, Some(f));
            let entries = vec![
                (
                    "frame_title".to_string(),
                    render_value(&json!(format!("t = {}", f.t)), 6),
                ),
                (
                    "frame_classes".into(),
                    render_value(&json!(["foldedForm"]), 6),
                ),
                ("frame_attributes".into(), render_value(&json!(["3D"]), 6)),
                ("frame_parent".into(), "0".into()),
                ("frame_inherit".into(), "true".into()),
                ("vertices_coords".into(), render_value(&json!(f.coords), 6)),
                ("edges_foldAngle".into(), render_value(&json!(angles), 6)),
                ("foldsynth:t".into(), render_value(&json!(f.t), 6)),
            ];
            format!("    {}", render_object(&entries, 4))
        })
        .collect();
    format!("[\n{}\n  ]", frames.join(",\n"))
}

/// One frame of a FOLD file after inheritance, with the key frame's mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct FoldFrame {
    /// `frame_classes`.
    pub classes: Vec<String>,
    /// Vertex coordinates, padded to 3D (z = 0 for 2D input).
    pub coords: Vec<[f64; 3]>,
    /// Whether the coordinates were given in 2D.
    pub coords_2d: bool,
    /// Fold angles in degrees (`None` where the file has `null`), if the frame has any.
    pub fold_angles: Option<Vec<Option<f64>>>,
    /// Whether `fold_angles` were stated by this frame itself (not inherited).
    pub fold_angles_own: bool,
    /// `foldsynth:t`, if present.
    pub t: Option<f64>,
}

/// A FOLD file read into plain numbers. Frame 0 is the key frame (top level).
#[derive(Clone, Debug, PartialEq)]
pub struct FoldFile {
    /// Where it came from (for messages).
    pub source: String,
    /// `file_spec`, if present.
    pub spec: Option<f64>,
    /// `file_creator`, if present.
    pub creator: Option<String>,
    /// Edges (from `edges_vertices`, or derived from the faces' sides).
    pub edges: Vec<[usize; 2]>,
    /// Assignment per edge (from the file; else `B` for sides of one face, `U` otherwise).
    pub assignment: Vec<Assignment>,
    /// Faces, counter-clockwise as the file states them (or derived).
    pub faces: Vec<Vec<usize>>,
    /// Whether the edges were derived from the faces.
    pub edges_derived: bool,
    /// Whether the faces were derived from the planar graph.
    pub faces_derived: bool,
    /// Whether `edges_assignment` was absent: then edges of exactly one face are `B`,
    /// the others `U`.
    pub assignment_derived: bool,
    /// `edges_foldsynth:driven`, if present.
    pub driven: Option<Vec<bool>>,
    /// All frames; `frames[0]` is the key frame, `frames[i]` is `file_frames[i-1]`.
    pub frames: Vec<FoldFrame>,
    /// Top-level custom properties (keys with a colon), e.g. `foldsynth:task`.
    pub custom: BTreeMap<String, Value>,
}

struct Ctx<'a> {
    file: &'a str,
}

impl Ctx<'_> {
    fn err(&self, field: impl Into<String>, message: impl Into<String>) -> FoldError {
        FoldError {
            file: self.file.to_string(),
            field: field.into(),
            message: message.into(),
        }
    }

    fn number(&self, v: &Value, field: &str) -> Result<f64, FoldError> {
        match v.as_f64() {
            Some(x) if x.is_finite() => Ok(x),
            Some(x) => Err(self.err(field, format!("{x} is not a finite number"))),
            None => Err(self.err(field, format!("expected a number, found {}", kind(v)))),
        }
    }

    fn index(&self, v: &Value, field: &str, n: usize, what: &str) -> Result<usize, FoldError> {
        let i = v.as_u64().ok_or_else(|| {
            self.err(
                field,
                format!("expected a non-negative integer index, found {}", short(v)),
            )
        })?;
        if (i as usize) < n && i <= usize::MAX as u64 {
            Ok(i as usize)
        } else {
            Err(self.err(
                field,
                format!(
                    "{what} index {i} out of range (there {} {n} {}, 0-based)",
                    if n == 1 { "is" } else { "are" },
                    plural(what, n)
                ),
            ))
        }
    }

    fn array<'v>(&self, v: &'v Value, field: &str) -> Result<&'v Vec<Value>, FoldError> {
        v.as_array()
            .ok_or_else(|| self.err(field, format!("expected an array, found {}", kind(v))))
    }

    fn strings(&self, v: &Value, field: &str) -> Result<Vec<String>, FoldError> {
        self.array(v, field)?
            .iter()
            .enumerate()
            .map(|(i, s)| {
                s.as_str().map(str::to_string).ok_or_else(|| {
                    self.err(
                        format!("{field}[{i}]"),
                        format!("expected a string, found {}", kind(s)),
                    )
                })
            })
            .collect()
    }
}

/// A JSON syntax error, with a hint for the non-finite numbers JSON cannot carry.
fn json_error(text: &str, e: &serde_json::Error) -> String {
    let at = text
        .lines()
        .nth(e.line().saturating_sub(1))
        .map(|l| {
            let start = l
                .char_indices()
                .nth(e.column().saturating_sub(1))
                .map_or(l.len(), |(i, _)| i);
            &l[start..]
        })
        .unwrap_or("");
    let hint = if e.to_string().contains("number out of range") {
        " (a number too large to be finite; FOLD needs finite numbers)"
    } else if ["NaN", "Infinity", "-Infinity", "inf"]
        .iter()
        .any(|t| at.starts_with(t))
    {
        " (NaN and Infinity are not JSON; FOLD needs finite numbers)"
    } else {
        ""
    };
    format!("not valid JSON: {e}{hint}")
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// "vertex" → "vertices", "frame" → "frames" (for n ≠ 1).
fn plural(what: &str, n: usize) -> String {
    match (what, n) {
        (w, 1) => w.to_string(),
        ("vertex", _) => "vertices".to_string(),
        ("face", _) | ("edge", _) | ("frame", _) => format!("{what}s"),
        (w, _) => format!("{w} entries"),
    }
}

fn short(v: &Value) -> String {
    let s = v.to_string();
    if s.len() > 40 {
        format!("{}…", &s[..s.floor_char_boundary(40)])
    } else {
        s
    }
}

impl FoldFile {
    /// Read a FOLD file from disk.
    pub fn read(path: &Path) -> Result<FoldFile, FoldError> {
        let name = path.display().to_string();
        let text = crate::limits::read_text(path).map_err(|e| FoldError {
            file: name.clone(),
            field: "(file)".into(),
            message: format!("cannot read: {e}"),
        })?;
        FoldFile::parse(&text, &name)
    }

    /// Parse FOLD text; `source` names it in error messages.
    pub fn parse(text: &str, source: &str) -> Result<FoldFile, FoldError> {
        let cx = Ctx { file: source };
        let root: Value =
            serde_json::from_str(text).map_err(|e| cx.err("(file)", json_error(text, &e)))?;
        let top = root.as_object().ok_or_else(|| {
            cx.err(
                "(file)",
                format!("expected a JSON object at the top, found {}", kind(&root)),
            )
        })?;
        let (spec, creator) = parse_header(&cx, top)?;
        let raw = raw_frames(&cx, top)?;
        let resolved = resolve_inheritance(&cx, &raw)?;

        // Mesh from the key frame.
        let coords0 = parse_coords(&cx, &resolved[0], &raw[0].0)?;
        let mesh = Mesh::parse(&cx, top, &raw[0].0, &resolved[0], &coords0.0)?;

        let mut frames = Vec::with_capacity(raw.len());
        for (fi, (own, res)) in raw.iter().zip(&resolved).enumerate() {
            let coords = if fi == 0 {
                coords0.clone()
            } else {
                parse_coords(&cx, res, &own.0)?
            };
            let key = (fi > 0).then_some(&resolved[0]);
            let (n, ne) = (coords0.0.len(), mesh.edges.len());
            frames.push(parse_frame(&cx, own, res, key, coords, n, ne)?);
        }
        let custom = top
            .iter()
            .filter(|(k, _)| k.contains(':'))
            .map(|(k, v)| (k.clone(), v.clone()))
            .collect();
        let Mesh {
            edges,
            assignment,
            faces,
            edges_derived,
            faces_derived,
            assignment_derived,
            driven,
        } = mesh;
        Ok(FoldFile {
            source: source.to_string(),
            spec,
            creator,
            edges,
            assignment,
            faces,
            edges_derived,
            faces_derived,
            assignment_derived,
            driven,
            frames,
            custom,
        })
    }

    /// The key frame's coordinates in 2D, if the key frame is flat (all z = 0).
    pub fn flat_xy(&self) -> Option<Vec<[f64; 2]>> {
        let c = &self.frames[0].coords;
        c.iter()
            .all(|p| p[2] == 0.0)
            .then(|| c.iter().map(|p| [p[0], p[1]]).collect())
    }

    /// Convert to a [`Pattern`]: the key frame must be flat; every later frame with
    /// coordinates becomes a folded state (t from `foldsynth:t`, else the frame index).
    /// Fold angles come from the frame's own `edges_foldAngle`, else from the geometry.
    pub fn to_pattern(&self) -> Result<Pattern, FoldError> {
        let xy = self.flat_xy().ok_or_else(|| FoldError {
            file: self.source.clone(),
            field: "vertices_coords".into(),
            message: "the key frame is not flat (some z ≠ 0); a Pattern needs the flat crease pattern as frame 0".into(),
        })?;
        let edges: Vec<Edge> = self
            .edges
            .iter()
            .enumerate()
            .map(|(i, &v)| Edge {
                v,
                kind: if self.assignment[i] == Assignment::B {
                    EdgeKind::Boundary
                } else {
                    EdgeKind::Crease {
                        driven: self.driven.as_ref().is_some_and(|d| d[i]),
                    }
                },
            })
            .collect();
        let adj = EdgeFaces::new(&self.edges, &self.faces);
        let frames = self.frames[1..]
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let geo = adj.fold_angles(&self.faces, &f.coords);
                let fold_angles = (0..edges.len())
                    .map(|i| {
                        if self.assignment[i] == Assignment::B {
                            return 0.0;
                        }
                        let given = f
                            .fold_angles
                            .as_ref()
                            .filter(|_| f.fold_angles_own)
                            .and_then(|a| a[i]);
                        given.map(f64::to_radians).or(geo[i]).unwrap_or(0.0)
                    })
                    .collect();
                Frame {
                    t: f.t.unwrap_or((k + 1) as f64),
                    coords: f.coords.clone(),
                    fold_angles,
                }
            })
            .collect();
        Ok(Pattern {
            vertices: xy,
            edges,
            faces: self.faces.clone(),
            frames,
        })
    }
}

/// Which faces lie left and right of each edge (left: the face traversing
/// `edges[i][0] → edges[i][1]`), plus everything odd found on the way.
#[derive(Clone, Debug, Default)]
pub struct EdgeFaces {
    /// Face traversing the edge forward.
    pub left: Vec<Vec<usize>>,
    /// Faces traversing the edge backward.
    pub right: Vec<Vec<usize>>,
    /// Face sides `(face, u, v)` that are not an edge of the file.
    pub missing: Vec<(usize, usize, usize)>,
    /// The edges, as given.
    pub edges: Vec<[usize; 2]>,
}

impl EdgeFaces {
    /// Incidences of `faces` with `edges`.
    pub fn new(edges: &[[usize; 2]], faces: &[Vec<usize>]) -> EdgeFaces {
        let mut index: HashMap<(usize, usize), usize> = HashMap::new();
        for (i, e) in edges.iter().enumerate() {
            index.entry((e[0].min(e[1]), e[0].max(e[1]))).or_insert(i);
        }
        let mut out = EdgeFaces {
            left: vec![Vec::new(); edges.len()],
            right: vec![Vec::new(); edges.len()],
            missing: Vec::new(),
            edges: edges.to_vec(),
        };
        for (fi, f) in faces.iter().enumerate() {
            for k in 0..f.len() {
                let (u, v) = (f[k], f[(k + 1) % f.len()]);
                match index.get(&(u.min(v), u.max(v))) {
                    Some(&i) if edges[i][0] == u => out.left[i].push(fi),
                    Some(&i) => out.right[i].push(fi),
                    None => out.missing.push((fi, u, v)),
                }
            }
        }
        out
    }

    /// Fold angle (radians) of every edge with exactly one face on each side, from the
    /// geometry `coords`; `None` elsewhere or where a face is degenerate.
    pub fn fold_angles(&self, faces: &[Vec<usize>], coords: &[[f64; 3]]) -> Vec<Option<f64>> {
        let pts = |f: usize| -> Vec<[f64; 3]> { faces[f].iter().map(|&v| coords[v]).collect() };
        (0..self.left.len())
            .map(
                |i| match (self.left[i].as_slice(), self.right[i].as_slice()) {
                    ([l], [r]) => {
                        let [a, b] = self.edges[i];
                        geom::fold_angle(coords[a], coords[b], &pts(*l), &pts(*r))
                    }
                    _ => None,
                },
            )
            .collect()
    }
}

/// `file_spec` and `file_creator`; `file_classes` is checked to be strings.
fn parse_header(
    cx: &Ctx,
    top: &Map<String, Value>,
) -> Result<(Option<f64>, Option<String>), FoldError> {
    let spec = match top.get("file_spec") {
        None => None,
        Some(v) => Some(cx.number(v, "file_spec")?),
    };
    let creator = match top.get("file_creator") {
        None => None,
        Some(v) => Some(
            v.as_str()
                .ok_or_else(|| {
                    cx.err(
                        "file_creator",
                        format!("expected a string, found {}", kind(v)),
                    )
                })?
                .to_string(),
        ),
    };
    if let Some(v) = top.get("file_classes") {
        cx.strings(v, "file_classes")?;
    }
    Ok((spec, creator))
}

/// A frame as the file states it (before inheritance), with the prefix of its fields in
/// messages (`file_frames[2].`; empty for the key frame).
type RawFrame = (String, Map<String, Value>);

/// The frames as the file states them: the key frame is the top level without `file_*`
/// keys, then `file_frames`.
fn raw_frames(cx: &Ctx, top: &Map<String, Value>) -> Result<Vec<RawFrame>, FoldError> {
    let mut raw: Vec<RawFrame> = Vec::new();
    let key: Map<String, Value> = top
        .iter()
        .filter(|(k, _)| !k.starts_with("file_"))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    raw.push((String::new(), key));
    if let Some(ff) = top.get("file_frames") {
        for (i, f) in cx.array(ff, "file_frames")?.iter().enumerate() {
            let obj = f.as_object().ok_or_else(|| {
                cx.err(
                    format!("file_frames[{i}]"),
                    format!("expected an object, found {}", kind(f)),
                )
            })?;
            raw.push((format!("file_frames[{i}]."), obj.clone()));
        }
    }
    Ok(raw)
}

/// The mesh every frame shares, as the key frame states it or derived (see
/// [`FoldFile`]'s fields of the same names).
struct Mesh {
    edges: Vec<[usize; 2]>,
    assignment: Vec<Assignment>,
    faces: Vec<Vec<usize>>,
    edges_derived: bool,
    faces_derived: bool,
    assignment_derived: bool,
    driven: Option<Vec<bool>>,
}

impl Mesh {
    /// The key frame's (resolved: `key`, field prefix `p0`, coordinates `coords0`) faces,
    /// edges and assignment, what is missing derived; `edges_foldsynth:driven` from `top`.
    fn parse(
        cx: &Ctx,
        top: &Map<String, Value>,
        p0: &str,
        key: &Map<String, Value>,
        coords0: &[[f64; 3]],
    ) -> Result<Mesh, FoldError> {
        let n = coords0.len();
        let faces = match key.get("faces_vertices") {
            Some(v) => Some(parse_faces(cx, v, &format!("{p0}faces_vertices"), n)?),
            None => None,
        };
        let edges = match key.get("edges_vertices") {
            Some(v) => Some(parse_edges(cx, v, &format!("{p0}edges_vertices"), n)?),
            None => None,
        };
        let ne = edges.as_ref().map(Vec::len);
        let assignment = match key.get("edges_assignment") {
            None => None,
            Some(v) => {
                let ne = ne.ok_or_else(|| {
                    cx.err(
                        "edges_assignment",
                        "present without edges_vertices (which edge is which?)",
                    )
                })?;
                Some(parse_assignment(cx, v, "edges_assignment", ne)?)
            }
        };
        let driven = parse_driven(cx, top, ne)?;
        let mut mesh = Mesh::complete(cx, coords0, edges, faces, assignment)?;
        mesh.driven = driven;
        Ok(mesh)
    }

    /// Derive what the file leaves out: faces from the planar graph, edges from the faces'
    /// sides, the boundary from the faces (`driven` left `None`).
    fn complete(
        cx: &Ctx,
        coords0: &[[f64; 3]],
        mut edges: Option<Vec<[usize; 2]>>,
        mut faces: Option<Vec<Vec<usize>>>,
        assignment: Option<Vec<Assignment>>,
    ) -> Result<Mesh, FoldError> {
        let mut edges_derived = false;
        let mut faces_derived = false;
        let assignment_derived = assignment.is_none();
        let assignment = match (&mut edges, &mut faces) {
            (None, None) => {
                return Err(cx.err(
                    "faces_vertices",
                    "missing, and so is edges_vertices: the file needs at least one of them",
                ));
            }
            (Some(e), None) => {
                let asg = assignment.unwrap_or_else(|| vec![Assignment::U; e.len()]);
                faces = Some(derive_faces(cx, coords0, e, &asg)?);
                faces_derived = true;
                asg
            }
            (None, Some(f)) => {
                let (e, asg) = edges_from_faces(f);
                edges = Some(e);
                edges_derived = true;
                asg
            }
            (Some(e), Some(_)) => assignment.unwrap_or_else(|| vec![Assignment::U; e.len()]),
        };
        let mut assignment = assignment;
        if assignment_derived && !edges_derived {
            // No assignment: the boundary is where only one face is (FOLD leaves it
            // to the reader); every other edge is an unassigned crease.
            if let (Some(e), Some(f)) = (&edges, &faces) {
                let adj = EdgeFaces::new(e, f);
                for (i, a) in assignment.iter_mut().enumerate() {
                    if adj.left[i].len() + adj.right[i].len() == 1 {
                        *a = Assignment::B;
                    }
                }
            }
        }
        Ok(Mesh {
            edges: edges.unwrap_or_default(),
            assignment,
            faces: faces.unwrap_or_default(),
            edges_derived,
            faces_derived,
            assignment_derived,
            driven: None,
        })
    }
}

/// `edges_foldsynth:driven`, one boolean per edge (`ne` edges, if the file has edges).
fn parse_driven(
    cx: &Ctx,
    top: &Map<String, Value>,
    ne: Option<usize>,
) -> Result<Option<Vec<bool>>, FoldError> {
    let Some(v) = top.get("edges_foldsynth:driven") else {
        return Ok(None);
    };
    let a = cx.array(v, "edges_foldsynth:driven")?;
    if Some(a.len()) != ne {
        return Err(cx.err(
            "edges_foldsynth:driven",
            format!(
                "{} entries, expected one per edge ({})",
                a.len(),
                ne.unwrap_or(0)
            ),
        ));
    }
    a.iter()
        .enumerate()
        .map(|(i, b)| {
            b.as_bool()
                .ok_or_else(|| cx.err(format!("edges_foldsynth:driven[{i}]"), "expected a boolean"))
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

/// The faces of the planar graph of a flat key frame (`coords0`, all z = 0) with edges
/// `e`; the edges assigned `B` are the boundary.
fn derive_faces(
    cx: &Ctx,
    coords0: &[[f64; 3]],
    e: &[[usize; 2]],
    asg: &[Assignment],
) -> Result<Vec<Vec<usize>>, FoldError> {
    if !coords0.iter().all(|c| c[2] == 0.0) {
        return Err(cx.err(
            "faces_vertices",
            "missing, and the key frame is not flat (z ≠ 0), so faces cannot be derived from the planar graph",
        ));
    }
    let xy: Vec<[f64; 2]> = coords0.iter().map(|c| [c[0], c[1]]).collect();
    let b: Vec<bool> = asg.iter().map(|a| *a == Assignment::B).collect();
    let f = geom::faces_of_planar_graph(&xy, e, &b).map_err(|m| {
        cx.err(
            "faces_vertices",
            format!("missing and cannot be derived: {m}"),
        )
    })?;
    if f.is_empty() {
        return Err(cx.err(
            "faces_vertices",
            "missing, and the edges enclose no face (give faces_vertices)",
        ));
    }
    Ok(f)
}

/// One frame: its own fields `own` (field prefix `prefix`), after inheritance `res`, its
/// coordinates; `key` (the key frame, resolved) for every frame but the key frame, whose
/// mesh (`n` vertices, `ne` edges) it must share.
fn parse_frame(
    cx: &Ctx,
    (prefix, own): &RawFrame,
    res: &Map<String, Value>,
    key: Option<&Map<String, Value>>,
    (coords, coords_2d): (Vec<[f64; 3]>, bool),
    n: usize,
    ne: usize,
) -> Result<FoldFrame, FoldError> {
    if coords.len() != n {
        return Err(cx.err(
            format!("{prefix}vertices_coords"),
            format!("{} vertices, but the key frame has {n}; foldsynth compares frames vertex by vertex", coords.len()),
        ));
    }
    if let Some(key) = key {
        for (key_name, mine) in [("edges_vertices", "edges"), ("faces_vertices", "faces")] {
            if let Some(v) = own.get(key_name)
                && Some(v) != key.get(key_name)
            {
                return Err(cx.err(
                    format!("{prefix}{key_name}"),
                    format!("this frame has its own {mine}, different from the key frame's; every frame must share the key frame's mesh"),
                ));
            }
        }
    }
    let classes = match res.get("frame_classes") {
        Some(v) => cx.strings(v, &format!("{prefix}frame_classes"))?,
        None => Vec::new(),
    };
    let angles = parse_fold_angles(cx, res, prefix, ne)?;
    let fold_angles_own = angles.as_ref().is_some_and(|(_, k)| own.contains_key(*k));
    let fold_angles = angles.map(|(a, _)| a);
    let t = match res.get("foldsynth:t") {
        None => None,
        Some(v) => Some(cx.number(v, &format!("{prefix}foldsynth:t"))?),
    };
    Ok(FoldFrame {
        classes,
        coords,
        coords_2d,
        fold_angles,
        fold_angles_own,
        t,
    })
}

/// Fold angles in degrees per edge, `None` where the file has `null`.
type FoldAngles = Vec<Option<f64>>;

/// A frame's fold angles (`res`, after inheritance, `ne` edges), if it has any, with the
/// key they are under: `edges_foldAngle`, or the pre-1.1 `edges_foldAngles`.
fn parse_fold_angles(
    cx: &Ctx,
    res: &Map<String, Value>,
    prefix: &str,
    ne: usize,
) -> Result<Option<(FoldAngles, &'static str)>, FoldError> {
    let angle_key = if res.contains_key("edges_foldAngle") {
        Some("edges_foldAngle")
    } else if res.contains_key("edges_foldAngles") {
        Some("edges_foldAngles")
    } else {
        None
    };
    let Some(k) = angle_key else {
        return Ok(None);
    };
    let field = format!("{prefix}{k}");
    let a = cx.array(&res[k], &field)?;
    if a.len() != ne {
        return Err(cx.err(
            field,
            format!("{} entries, expected one per edge ({ne})", a.len()),
        ));
    }
    let mut out = Vec::with_capacity(ne);
    for (i, x) in a.iter().enumerate() {
        out.push(if x.is_null() {
            None
        } else {
            let d = cx.number(x, &format!("{field}[{i}]"))?;
            if d.abs() > 180.0 {
                return Err(cx.err(
                    format!("{field}[{i}]"),
                    format!("{d} is outside [-180, 180] degrees"),
                ));
            }
            Some(d)
        });
    }
    Ok(Some((out, k)))
}

fn resolve_inheritance(cx: &Ctx, raw: &[RawFrame]) -> Result<Vec<Map<String, Value>>, FoldError> {
    let n = raw.len();
    let mut out: Vec<Option<Map<String, Value>>> = vec![None; n];
    out[0] = Some(raw[0].1.clone());
    fn go(
        cx: &Ctx,
        raw: &[RawFrame],
        out: &mut Vec<Option<Map<String, Value>>>,
        i: usize,
        depth: usize,
    ) -> Result<Map<String, Value>, FoldError> {
        if let Some(m) = &out[i] {
            return Ok(m.clone());
        }
        let (prefix, own) = &raw[i];
        if depth > raw.len() {
            return Err(cx.err(
                format!("{prefix}frame_parent"),
                "frames inherit from each other in a cycle",
            ));
        }
        let inherit = match own.get("frame_inherit") {
            None => false,
            Some(Value::Bool(b)) => *b,
            Some(v) => {
                return Err(cx.err(
                    format!("{prefix}frame_inherit"),
                    format!("expected true or false, found {}", kind(v)),
                ));
            }
        };
        let parent = match own.get("frame_parent") {
            None => None,
            Some(v) => {
                let p = cx.index(v, &format!("{prefix}frame_parent"), raw.len(), "frame")?;
                if p == i {
                    return Err(cx.err(
                        format!("{prefix}frame_parent"),
                        "a frame cannot be its own parent",
                    ));
                }
                Some(p)
            }
        };
        let mut merged = Map::new();
        if inherit {
            // Inheriting without a parent has nothing to inherit from but the key frame;
            // Origami Simulator's "FOLD series" export writes exactly that.
            let p = parent.unwrap_or(0);
            merged = go(cx, raw, out, p, depth + 1)?;
            // Frame metadata describes the parent, not this frame.
            merged.retain(|k, _| !k.starts_with("frame_"));
        }
        for (k, v) in own {
            merged.insert(k.clone(), v.clone());
        }
        out[i] = Some(merged.clone());
        Ok(merged)
    }
    (1..n).try_for_each(|i| go(cx, raw, &mut out, i, 0).map(|_| ()))?;
    Ok(out.into_iter().map(Option::unwrap_or_default).collect())
}

fn parse_coords(
    cx: &Ctx,
    frame: &Map<String, Value>,
    prefix: &str,
) -> Result<(Vec<[f64; 3]>, bool), FoldError> {
    let field = format!("{prefix}vertices_coords");
    let v = frame.get("vertices_coords").ok_or_else(|| {
        cx.err(
            &field,
            "missing; foldsynth needs vertex coordinates (abstract frames are not supported)",
        )
    })?;
    let arr = cx.array(v, &field)?;
    if arr.is_empty() {
        return Err(cx.err(&field, "empty; a crease pattern needs vertices"));
    }
    let mut out = Vec::with_capacity(arr.len());
    let mut dim = None;
    for (i, p) in arr.iter().enumerate() {
        let f = format!("{field}[{i}]");
        let a = cx.array(p, &f)?;
        if a.len() != 2 && a.len() != 3 {
            return Err(cx.err(
                f,
                format!(
                    "{} coordinates; allowed are 2 (x, y) or 3 (x, y, z)",
                    a.len()
                ),
            ));
        }
        if *dim.get_or_insert(a.len()) != a.len() {
            return Err(cx.err(
                f,
                format!(
                    "{} coordinates, but earlier vertices have {}; use one dimension per frame",
                    a.len(),
                    dim.unwrap_or(0)
                ),
            ));
        }
        let mut c = [0.0; 3];
        for (k, x) in a.iter().enumerate() {
            let f = format!("{field}[{i}][{k}]");
            c[k] = cx.number(x, &f)?;
            if c[k].abs() > crate::limits::COORD_MAX {
                return Err(cx.err(
                    f,
                    format!(
                        "{} is out of range: coordinates lie within ±{} (larger ones overflow squared distances)",
                        crate::text::num(c[k]),
                        crate::text::num(crate::limits::COORD_MAX)
                    ),
                ));
            }
        }
        out.push(c);
    }
    Ok((out, dim == Some(2)))
}

fn parse_edges(cx: &Ctx, v: &Value, field: &str, n: usize) -> Result<Vec<[usize; 2]>, FoldError> {
    let arr = cx.array(v, field)?;
    let mut out = Vec::with_capacity(arr.len());
    for (i, e) in arr.iter().enumerate() {
        let f = format!("{field}[{i}]");
        let a = cx.array(e, &f)?;
        if a.len() != 2 {
            return Err(cx.err(f, format!("{} entries; an edge is [u, v]", a.len())));
        }
        let u = cx.index(&a[0], &format!("{f}[0]"), n, "vertex")?;
        let w = cx.index(&a[1], &format!("{f}[1]"), n, "vertex")?;
        if u == w {
            return Err(cx.err(f, format!("both ends are vertex {u}")));
        }
        out.push([u, w]);
    }
    Ok(out)
}

fn parse_faces(cx: &Ctx, v: &Value, field: &str, n: usize) -> Result<Vec<Vec<usize>>, FoldError> {
    let arr = cx.array(v, field)?;
    let mut out = Vec::with_capacity(arr.len());
    for (i, f) in arr.iter().enumerate() {
        let fi = format!("{field}[{i}]");
        let a = cx.array(f, &fi)?;
        if a.len() < 3 {
            return Err(cx.err(fi, format!("{} vertices; a face needs at least 3", a.len())));
        }
        out.push(
            a.iter()
                .enumerate()
                .map(|(k, x)| cx.index(x, &format!("{fi}[{k}]"), n, "vertex"))
                .collect::<Result<Vec<_>, _>>()?,
        );
    }
    Ok(out)
}

fn parse_assignment(
    cx: &Ctx,
    v: &Value,
    field: &str,
    ne: usize,
) -> Result<Vec<Assignment>, FoldError> {
    let arr = cx.array(v, field)?;
    if arr.len() != ne {
        return Err(cx.err(
            field,
            format!("{} entries, expected one per edge ({ne})", arr.len()),
        ));
    }
    arr.iter()
        .enumerate()
        .map(|(i, a)| {
            let f = format!("{field}[{i}]");
            match a.as_str() {
                Some("B" | "b") => Ok(Assignment::B),
                Some("M" | "m") => Ok(Assignment::M),
                Some("V" | "v") => Ok(Assignment::V),
                Some("F" | "f") => Ok(Assignment::F),
                Some("U" | "u") => Ok(Assignment::U),
                Some("J" | "j") => Ok(Assignment::J),
                Some("C" | "c") => Err(cx.err(
                    f,
                    "\"C\" (cut) is not supported; split the cut into two \"B\" edges",
                )),
                Some(s) => Err(cx.err(
                    f,
                    format!("{s:?} is not an assignment; allowed are \"B\", \"M\", \"V\", \"F\", \"U\", \"J\""),
                )),
                None => Err(cx.err(f, format!("expected a string, found {}", kind(a)))),
            }
        })
        .collect()
}

fn edges_from_faces(faces: &[Vec<usize>]) -> (Vec<[usize; 2]>, Vec<Assignment>) {
    let mut index: HashMap<(usize, usize), usize> = HashMap::new();
    let mut edges = Vec::new();
    let mut count = Vec::new();
    for f in faces {
        for k in 0..f.len() {
            let (u, v) = (f[k], f[(k + 1) % f.len()]);
            let key = (u.min(v), u.max(v));
            let i = *index.entry(key).or_insert_with(|| {
                edges.push([u, v]);
                count.push(0usize);
                edges.len() - 1
            });
            count[i] += 1;
        }
    }
    let asg = count
        .iter()
        .map(|&c| if c == 1 { Assignment::B } else { Assignment::U })
        .collect();
    (edges, asg)
}

/// Write a pattern to a FOLD file.
pub fn write_fold(
    path: &Path,
    p: &Pattern,
    meta: &DesignMeta,
    spec: FoldSpec,
) -> Result<(), ExportError> {
    super::write_file(path, to_fold_string(p, meta, spec)?)
}
