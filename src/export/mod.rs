//! Files people open: FOLD, SVG, OBJ/STL, pictures, animations, plots, report.
//!
//! Everything here starts from the numeric [`Pattern`] (flat layout plus folded frames)
//! and a [`DesignMeta`] describing where the design came from (task, rule sequence,
//! modes, gripping vertex, target points, obstacle). The entry point for one design is
//! [`write_all`]; the pieces are public for callers that need only one format:
//!
//! - [`fold`]: FOLD 1.1/1.2 writer and a reader for any FOLD file,
//! - [`verify`]: the independent check behind `foldsynth verify`,
//! - [`svg`]: the crease pattern in Origami Simulator's SVG convention,
//! - [`render`]: folded states as PNG, SVG and animated GIF,
//! - [`raster`]: the GIF's frames drawn straight into palette entries,
//! - [`lzw`]: the GIF frames' LZW compression, with a fast path for runs,
//! - [`mesh`]: OBJ and STL of a folded state,
//! - [`motion`]: a design's frames as its JSON stores them (positions; fold angles read back),
//! - [`plots`]: the search tree (thesis Fig. 48) and the distribution of designs (Fig. 51),
//! - [`report`]: the self-contained, interactive `report.html` (three.js inlined),
//! - [`laser`], [`print`](mod@print): a thick design's ply drawings (DXF, SVG) and solids (STL, 3MF),
//! - [`samples`]: small patterns with exact rigid motions (tests and demos).
//!
//! ```
//! use foldsynth::export::{samples, DesignMeta, ExportOptions, write_all};
//! let pattern = samples::single_crease(std::f64::consts::FRAC_PI_2, 5);
//! let meta = DesignMeta { task: "demo".into(), ..DesignMeta::default() };
//! let dir = tempfile::tempdir().unwrap();
//! let files = write_all(dir.path(), &pattern, &meta, &ExportOptions::default()).unwrap();
//! assert!(files.fold.exists());
//! ```

pub mod fabrication_files;
pub mod fold;
pub mod laminate;
pub mod laser;
pub mod lzw;
pub mod mesh;
pub mod meta_file;
pub mod motion;
pub mod palette;
pub mod plots;
pub mod print;
pub mod raster;
pub mod render;
pub mod report;
pub mod samples;
pub mod scene_mesh;
pub mod scene_polys;
pub mod sheet;
pub mod svg;
pub mod verify;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::pattern::Pattern;

/// Rigid-body mode of an internal vertex (thesis Eq. 23): M↑ or M↓.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// M = +1 ("up").
    Up,
    /// M = −1 ("down").
    Down,
}

impl Mode {
    /// The string used in files: `"up"` or `"down"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Mode::Up => "up",
            Mode::Down => "down",
        }
    }
}

/// A point the design should reach, optionally at a given driving parameter `t`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetPoint {
    /// Position in 3D.
    pub p: [f64; 3],
    /// The driving parameter at which the gripping vertex should be at `p`, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t: Option<f64>,
}

/// A cylindrical obstacle (axis segment `a → b`, radius), shared with the checks.
pub use crate::scene::Cylinder;
use crate::scene::Scene;
use crate::scene::shapes::MeshObstacle;
use crate::task::terms::Target;

/// Where a design came from and what it should do; filled by the synthesis stage.
///
/// Serialized with snake_case keys; every field but `task` may be omitted. Files written
/// before the scene existed name one cylinder (`obstacle`) and a half-turn copy
/// (`second_arm`); they are still read, as a scene with that cylinder (named
/// `check.cylinders[0]`) and two copies about z (see [`meta_file`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "meta_file::MetaFile")]
pub struct DesignMeta {
    /// Name of the design task (e.g. `"gripper"`).
    pub task: String,
    /// Rule application sequence in the thesis's notation, e.g. `"2, 3, (4, 8)"`.
    pub rule_sequence: String,
    /// RBM of every internal vertex, in the order of the internal vertices.
    pub modes: Vec<Mode>,
    /// The gripping vertex by its name: 1-based, as vertices are numbered everywhere
    /// foldsynth talks to people (task files, rule sequences, the report, the design JSON's
    /// top-level `gripping_vertex`), so vertex `vK` is [`Pattern::vertices`]`[K − 1]`.
    pub gripping_vertex: Option<usize>,
    /// The objective value Ω* of the optimized design.
    pub objective: Option<f64>,
    /// Target points (gripper: P_G; robotic arm: P_Ti with their t_i), drawn as dots.
    pub targets: Vec<TargetPoint>,
    /// A trajectory to draw as a polyline (e.g. the robotic arm's arc).
    pub trajectory: Vec<[f64; 3]>,
    /// The world around the design: obstacles of every shape, the rotational copies of
    /// the arm, containment boxes. Mesh obstacles name their file (loaded to draw).
    pub scene: Scene,
    /// The objective's targets of every kind (point, line, plane, surface) with their
    /// vertex, t and weight, as the task gives them (paths expanded). Point goals are
    /// drawn from [`DesignMeta::targets`]; the others from here.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub goals: Vec<Target>,
    /// The meshes [`crate::task::terms::Goal::Surface`] goals refer to (by index), named by
    /// their files like mesh obstacles.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub surfaces: Vec<MeshObstacle>,
    /// Anything else worth keeping (written to FOLD under `foldsynth:extra`).
    pub extra: BTreeMap<String, serde_json::Value>,
}

impl DesignMeta {
    /// The first cylinder of the scene (what files before the scene called `obstacle`).
    pub fn first_cylinder(&self) -> Option<&Cylinder> {
        self.scene.cylinders().next()
    }

    /// Whether the copies are exactly the thesis's second arm: a half turn about the
    /// z-axis, drawn and meshed as `(−x, −y, z)` (the code paths of files before the
    /// scene, kept so their bytes do not change).
    pub fn second_arm(&self) -> bool {
        self.scene.copies == crate::scene::Copies::about_z(2)
    }
}

/// Errors of the export stage.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The input (pattern, metadata, plot data) is not usable; `what` names the field.
    #[error("{what}: {message}")]
    Invalid {
        /// The offending field, e.g. `pattern.edges[3].v[1]`.
        what: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// A FOLD file could not be read.
    #[error(transparent)]
    Fold(#[from] fold::FoldError),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// Encoding an image failed.
    #[error("image encoding: {0}")]
    Image(String),
}

impl ExportError {
    pub(crate) fn invalid(what: impl Into<String>, message: impl Into<String>) -> Self {
        ExportError::Invalid {
            what: what.into(),
            message: message.into(),
        }
    }
}

/// Result type of this module.
pub type Result<T, E = ExportError> = std::result::Result<T, E>;

/// Write `bytes` to `path`, mapping the error to [`ExportError::Io`].
pub(crate) fn write_file(path: &Path, bytes: impl AsRef<[u8]>) -> Result<()> {
    std::fs::write(path, bytes).map_err(|source| ExportError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Every number finite and within ±[`crate::limits::COORD_MAX`]: larger ones overflow
/// squared distances (1e308 gives an infinite error that compares as "within bounds").
pub(crate) fn check_finite(what: impl FnOnce() -> String, xs: &[f64]) -> Result<()> {
    match xs
        .iter()
        .find(|x| !(x.is_finite() && x.abs() <= crate::limits::COORD_MAX))
    {
        None => Ok(()),
        Some(x) => Err(ExportError::invalid(
            what(),
            format!(
                "{} is not allowed: numbers must be finite and within ±{}",
                crate::text::num(*x),
                crate::text::num(crate::limits::COORD_MAX)
            ),
        )),
    }
}

/// Check that a pattern is self-consistent: indices in range, lengths matching, finite
/// numbers, faces with at least 3 vertices. Every writer calls this first, so bad input
/// (e.g. a hand-edited design JSON) gets an error naming the field instead of a panic.
pub fn validate_pattern(p: &Pattern) -> Result<()> {
    let n = p.vertices.len();
    if n == 0 {
        return Err(ExportError::invalid("pattern.vertices", "empty"));
    }
    for (i, v) in p.vertices.iter().enumerate() {
        check_finite(|| format!("pattern.vertices[{i}]"), v)?;
    }
    for (i, e) in p.edges.iter().enumerate() {
        for k in 0..2 {
            if e.v[k] >= n {
                return Err(ExportError::invalid(
                    format!("pattern.edges[{i}].v[{k}]"),
                    format!(
                        "vertex {} out of range (the pattern has {n} vertices)",
                        e.v[k]
                    ),
                ));
            }
        }
        if e.v[0] == e.v[1] {
            return Err(ExportError::invalid(
                format!("pattern.edges[{i}].v"),
                "both ends are the same vertex",
            ));
        }
    }
    for (i, f) in p.faces.iter().enumerate() {
        if f.len() < 3 {
            return Err(ExportError::invalid(
                format!("pattern.faces[{i}]"),
                format!("{} vertices; a face needs at least 3", f.len()),
            ));
        }
        for (k, &v) in f.iter().enumerate() {
            if v >= n {
                return Err(ExportError::invalid(
                    format!("pattern.faces[{i}][{k}]"),
                    format!("vertex {v} out of range (the pattern has {n} vertices)"),
                ));
            }
        }
    }
    for (j, fr) in p.frames.iter().enumerate() {
        check_finite(|| format!("pattern.frames[{j}].t"), &[fr.t])?;
        if fr.coords.len() != n {
            return Err(ExportError::invalid(
                format!("pattern.frames[{j}].coords"),
                format!("{} entries, expected one per vertex ({n})", fr.coords.len()),
            ));
        }
        if fr.fold_angles.len() != p.edges.len() {
            return Err(ExportError::invalid(
                format!("pattern.frames[{j}].fold_angles"),
                format!(
                    "{} entries, expected one per edge ({})",
                    fr.fold_angles.len(),
                    p.edges.len()
                ),
            ));
        }
        for (i, c) in fr.coords.iter().enumerate() {
            check_finite(|| format!("pattern.frames[{j}].coords[{i}]"), c)?;
        }
        check_finite(
            || format!("pattern.frames[{j}].fold_angles"),
            &fr.fold_angles,
        )?;
    }
    Ok(())
}

/// A pattern as a design file gives it, made whole and checked: the fold angles it leaves
/// out ([`motion`]) read from the positions once the indices are known to be valid, then
/// [`validate_pattern`].
pub fn read_pattern(p: &mut Pattern) -> Result<()> {
    let bare = Pattern {
        vertices: p.vertices.clone(),
        edges: p.edges.clone(),
        faces: p.faces.clone(),
        frames: Vec::new(),
    };
    validate_pattern(&bare)?;
    for (j, f) in p.frames.iter().enumerate() {
        if f.coords.len() != p.vertices.len() {
            return Err(ExportError::invalid(
                format!("pattern.frames[{j}].coords"),
                format!(
                    "{} entries, expected one per vertex ({})",
                    f.coords.len(),
                    p.vertices.len()
                ),
            ));
        }
    }
    motion::fill_fold_angles(p)?;
    validate_pattern(p)
}

/// Check the metadata against the pattern it describes.
pub fn validate_meta(meta: &DesignMeta, p: &Pattern) -> Result<()> {
    if let Some(g) = meta.gripping_vertex
        && !(1..=p.vertices.len()).contains(&g)
    {
        return Err(ExportError::invalid(
            "meta.gripping_vertex",
            format!(
                "vertex {g} out of range: vertices are numbered 1 to {} (v1, v2, …)",
                p.vertices.len()
            ),
        ));
    }
    if let Some(o) = meta.objective
        && !o.is_finite()
    {
        return Err(ExportError::invalid("meta.objective", "non-finite number"));
    }
    for (i, tp) in meta.targets.iter().enumerate() {
        check_finite(|| format!("meta.targets[{i}].p"), &tp.p)?;
        if let Some(t) = tp.t {
            check_finite(|| format!("meta.targets[{i}].t"), &[t])?;
        }
    }
    for (i, q) in meta.trajectory.iter().enumerate() {
        check_finite(|| format!("meta.trajectory[{i}]"), q)?;
    }
    meta_file::validate_scene(meta)?;
    Ok(())
}

/// The FOLD spec version to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum FoldSpec {
    /// FOLD 1.1.
    #[value(name = "1.1")]
    V1_1,
    /// FOLD 1.2 (the current version; the default).
    #[default]
    #[value(name = "1.2")]
    V1_2,
}

impl FoldSpec {
    /// The number written to `file_spec`.
    pub fn number(self) -> f64 {
        match self {
            FoldSpec::V1_1 => 1.1,
            FoldSpec::V1_2 => 1.2,
        }
    }
}

/// Options of [`write_all`] and the single-format writers.
#[derive(Clone, Debug)]
pub struct ExportOptions {
    /// Base name of the files (`<name>.fold`, `<name>.svg`, …).
    pub name: String,
    /// FOLD spec version written to `file_spec`.
    pub fold_spec: FoldSpec,
    /// Vertex numbers in the crease-pattern SVG.
    pub labels: bool,
    /// Draw flat creases grey instead of Origami Simulator's yellow (see [`svg`]).
    pub flat_grey: bool,
    /// Width and height of raster pictures in pixels.
    pub image_size: (u32, u32),
    /// How many folded states to render as PNG/SVG pictures (evenly over the frames).
    pub picture_states: usize,
    /// Write the animated GIF.
    pub gif: bool,
    /// Delay between GIF frames in hundredths of a second.
    pub gif_delay_cs: u16,
    /// At most this many GIF frames (picked evenly over the pattern's frames).
    pub gif_max_frames: usize,
    /// The camera of pictures and animation.
    pub camera: render::Camera,
    /// Binary STL (`true`) or ASCII STL (`false`).
    pub stl_binary: bool,
    /// The print sheet (`<name>.print.pdf` and its SVGs; [`sheet`]), `None` for none. Its
    /// `title` and `copies` are set from `name` and the design's meta when written.
    pub print: Option<sheet::SheetOptions>,
}

impl Default for ExportOptions {
    fn default() -> Self {
        ExportOptions {
            name: "design".into(),
            fold_spec: FoldSpec::default(),
            labels: false,
            flat_grey: false,
            image_size: (480, 360),
            picture_states: 4,
            gif: true,
            gif_delay_cs: 8,
            gif_max_frames: 60,
            camera: render::Camera::default(),
            stl_binary: true,
            print: Some(sheet::SheetOptions::default()),
        }
    }
}

/// The files [`write_all`] wrote for one design.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Files {
    /// The FOLD file (crease pattern plus every folded frame).
    pub fold: PathBuf,
    /// The crease pattern SVG (Origami Simulator convention).
    pub svg: PathBuf,
    /// OBJ of the final folded state.
    pub obj: PathBuf,
    /// STL of the final folded state.
    pub stl: PathBuf,
    /// OBJ of the scene at the final state: every copy and every obstacle (`<name>-scene.obj`).
    pub scene_obj: PathBuf,
    /// STL of the same scene (`<name>-scene.stl`).
    pub scene_stl: PathBuf,
    /// PNG pictures of selected folded states, in order of t.
    pub pngs: Vec<PathBuf>,
    /// SVG pictures of the same folded states.
    pub folded_svgs: Vec<PathBuf>,
    /// The animated GIF of the motion, if written.
    pub gif: Option<PathBuf>,
    /// The print sheet: the PDF, then one SVG per sheet (empty without one).
    pub print: Vec<PathBuf>,
}

/// Indices of `count` frames spread evenly over `n` frames, always including the last.
pub fn picked_frames(n: usize, count: usize) -> Vec<usize> {
    if n == 0 || count == 0 {
        return Vec::new();
    }
    if count >= n {
        return (0..n).collect();
    }
    if count == 1 {
        return vec![n - 1];
    }
    let mut out: Vec<usize> = (0..count)
        .map(|k| ((k as f64) * (n - 1) as f64 / (count - 1) as f64).round() as usize)
        .collect();
    out.dedup();
    out
}

impl Files {
    /// Every path, in writing order.
    pub fn all(&self) -> Vec<PathBuf> {
        let mut v = vec![
            self.fold.clone(),
            self.svg.clone(),
            self.obj.clone(),
            self.stl.clone(),
            self.scene_obj.clone(),
            self.scene_stl.clone(),
        ];
        for (png, svg) in self.pngs.iter().zip(&self.folded_svgs) {
            v.push(png.clone());
            v.push(svg.clone());
        }
        v.extend(self.gif.clone());
        v.extend(self.print.iter().cloned());
        v
    }
}

/// The files [`write_all`] writes for `pattern` with `opts` into `out_dir` (so a caller can
/// list them before they exist).
pub fn planned_files(
    out_dir: &Path,
    pattern: &Pattern,
    meta: &DesignMeta,
    opts: &ExportOptions,
) -> Files {
    let path = |ext: &str| out_dir.join(format!("{}.{ext}", opts.name));
    let picked = picked_frames(pattern.frames.len(), opts.picture_states);
    Files {
        fold: path("fold"),
        svg: path("svg"),
        obj: path("obj"),
        stl: path("stl"),
        scene_obj: out_dir.join(format!("{}-scene.obj", opts.name)),
        scene_stl: out_dir.join(format!("{}-scene.stl", opts.name)),
        pngs: picked
            .iter()
            .map(|k| out_dir.join(format!("{}_state{k}.png", opts.name)))
            .collect(),
        folded_svgs: picked
            .iter()
            .map(|k| out_dir.join(format!("{}_state{k}.svg", opts.name)))
            .collect(),
        gif: (opts.gif && !pattern.frames.is_empty()).then(|| path("gif")),
        print: match print_options(meta, opts) {
            // A layout that fails here fails again in write_all, which says why.
            Some(o) => {
                let sheets = sheet::layout(pattern, &o).map_or(1, |p| p.pages.len());
                sheet::planned(&path("print.pdf"), sheets)
            }
            None => Vec::new(),
        },
    }
}

/// The print sheet's options of a design: `opts.print` with its name and copies.
fn print_options(meta: &DesignMeta, opts: &ExportOptions) -> Option<sheet::SheetOptions> {
    opts.print.clone().map(|o| sheet::SheetOptions {
        title: opts.name.clone(),
        copies: meta.scene.copies,
        ..o
    })
}

/// Write every file for one design into `out_dir` (created if missing): FOLD, crease
/// pattern SVG, OBJ and STL of the final state, PNG and SVG pictures of a few states,
/// the scene (every copy, every obstacle) as OBJ and STL, and the GIF animation. Pictures
/// and meshes show every copy of `meta.scene`. Mesh obstacles are read from their files
/// (an error names a missing one).
pub fn write_all(
    out_dir: &Path,
    pattern: &Pattern,
    meta: &DesignMeta,
    opts: &ExportOptions,
) -> Result<Files> {
    validate_pattern(pattern)?;
    validate_meta(meta, pattern)?;
    if opts.name.is_empty() || opts.name.contains(['/', '\\']) {
        return Err(ExportError::invalid(
            "options.name",
            format!("{:?}: must be a plain, non-empty file name", opts.name),
        ));
    }
    std::fs::create_dir_all(out_dir).map_err(|source| ExportError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let files = planned_files(out_dir, pattern, meta, opts);
    let loaded = with_meshes(meta)?;
    let meta = &*loaded;
    write_file(
        &files.fold,
        fold::to_fold_string(pattern, meta, opts.fold_spec)?,
    )?;
    write_file(
        &files.svg,
        svg::crease_pattern_svg(
            pattern,
            &svg::SvgOptions {
                labels: opts.labels,
                flat_grey: opts.flat_grey,
                ..svg::SvgOptions::default()
            },
        )?,
    )?;
    let last = pattern.frames.len().checked_sub(1);
    let state = mesh::state_mesh_copies(pattern, last, &meta.scene.copies)?;
    write_file(&files.obj, mesh::to_obj(&state, &opts.name))?;
    let stl = |m: &mesh::StateMesh| {
        if opts.stl_binary {
            mesh::to_stl_binary(m)
        } else {
            mesh::to_stl_ascii(m, &opts.name).into_bytes()
        }
    };
    write_file(&files.stl, stl(&state))?;
    let world = scene_mesh::scene_mesh(pattern, last, meta)?;
    write_file(&files.scene_obj, scene_mesh::to_obj(&world, &opts.name))?;
    write_file(&files.scene_stl, stl(&world.as_state_mesh()))?;

    let scene = render::Scene::new(pattern, meta, opts.camera)?;
    let picked = picked_frames(pattern.frames.len(), opts.picture_states);
    // With the GIF, the pictures' states are drawn once, for both (the GIF shows them all
    // unless gif_max_frames picks fewer; the others are drawn on their own).
    let pngs = match &files.gif {
        Some(gif) => {
            let (bytes, pngs) = scene.gif_and_pngs(
                opts.image_size,
                opts.gif_delay_cs,
                opts.gif_max_frames,
                &picked,
            )?;
            write_file(gif, bytes)?;
            pngs
        }
        None => picked
            .iter()
            .map(|&k| scene.png(Some(k), opts.image_size))
            .collect::<Result<_>>()?,
    };
    for ((k, png), (path, fsvg)) in picked
        .iter()
        .zip(pngs)
        .zip(files.pngs.iter().zip(&files.folded_svgs))
    {
        write_file(path, png)?;
        write_file(fsvg, scene.svg(Some(*k), opts.image_size))?;
    }
    if let (Some(o), Some(pdf)) = (print_options(meta, opts), files.print.first()) {
        sheet::write(pdf, pattern, &o)?;
    }
    Ok(files)
}

/// `meta` with every mesh it names read from its file: borrowed when there is none to read
/// (or all are read already), else a copy with the meshes loaded.
pub fn with_meshes(meta: &DesignMeta) -> Result<std::borrow::Cow<'_, DesignMeta>> {
    use crate::scene::Shape;
    let unloaded = meta
        .scene
        .obstacles
        .iter()
        .any(|o| matches!(&o.shape, Shape::Mesh(m) if m.triangles().is_none()))
        || meta.surfaces.iter().any(|m| m.triangles().is_none());
    if !unloaded {
        return Ok(std::borrow::Cow::Borrowed(meta));
    }
    let mut m = meta.clone();
    meta_file::load_meshes(&mut m)?;
    Ok(std::borrow::Cow::Owned(m))
}

/// The JSON file `foldsynth export` reads: `{"pattern": <Pattern>, "meta": <DesignMeta>}`.
///
/// `pattern` is [`Pattern`] as serde writes it (`vertices`, `edges` with
/// `{"v": [i, j], "kind": "boundary" | {"crease": {"driven": bool}}}`, `faces`, `frames`
/// with `t`, `coords`, `fold_angles` in radians; `fold_angles` may be left out, and
/// then they are read from `coords`, see [`motion`]); `meta` is [`DesignMeta`].
///
/// Other keys are allowed and ignored: `foldsynth synthesize` writes its designs
/// (`OUT/designs/<id>.json`) as such files with the optimization's figures beside them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DesignFile {
    /// The crease pattern and its folded states.
    pub pattern: Pattern,
    /// What the design is for.
    #[serde(default)]
    pub meta: DesignMeta,
}

impl DesignFile {
    /// Read and validate a design JSON file.
    pub fn read(path: &Path) -> Result<DesignFile> {
        let text = crate::limits::read_text(path).map_err(|source| ExportError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        DesignFile::parse(&text, &path.display().to_string())
    }

    /// Parse and validate design JSON text; `source` names it in messages.
    pub fn parse(text: &str, source: &str) -> Result<DesignFile> {
        let mut d: DesignFile = serde_json::from_str(text).map_err(|e| {
            ExportError::invalid(
                source,
                format!(
                    "not a design file ({}); expected {{\"pattern\": {{vertices, edges, faces, frames}}, \"meta\": {{task, …}}}}",
                    crate::text::excerpt(&e.to_string(), 200)
                ),
            )
        })?;
        read_pattern(&mut d.pattern)
            .and_then(|()| validate_meta(&d.meta, &d.pattern))
            .map_err(|e| ExportError::invalid(source, e.to_string()))?;
        Ok(d)
    }
}
