//! Design task files (`grammar/*.toml`): parsing and validation.
//!
//! A task file holds the initial graph G0 (vertices with in-plane coordinates and types,
//! creases with their facet labels and driving angles), the grammar's limit N_max, the
//! task's symmetry, and the design task the later stages use: the motion range, the
//! variable bounds, the objective (points, paths, lines, planes and mesh surfaces to reach,
//! an area to gain: [`terms`]), the intersection-check setup (thesis Sec. 5.1, 5.5; SPEC
//! §4), the scene ([`crate::scene::Scene`]: `[[obstacles]]` of every shape, `[copies]`,
//! `[[constraints.inside]]`) and the design constraints (`[constraints]`: `kawasaki = true`
//! for flat-foldable vertices, orientations, fold-angle limits). Every field is checked on
//! load; a bad file gets a [`TaskError`] naming the file, the field and what is allowed.
//! Mesh files are read relative to the task file's folder
//! ([`Task::from_toml_str_in`]) and their bytes enter [`Task::digest`].
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

mod actuation;
mod bounds;
mod check;
mod constraints;
mod ctx;
mod drive;
mod fab_table;
pub mod fabrication;
mod initial;
pub mod isometry;
mod meshes;
mod mirror;
mod motion;
mod names;
pub mod number;
mod objective;
mod obstacles;
pub(crate) mod parse;
mod robustness;
mod rotation;
mod solids;
mod symmetry;
mod targets;
pub mod terms;
pub mod times;

use std::path::PathBuf;

pub use bounds::Bounds;
pub use check::{CheckSpec, Cylinder, DEFAULT_OPTIMIZE_STATES};
pub(crate) use ctx::Ctx;
pub use drive::Drive;
pub use initial::{G0Actuation, InitialCrease, InitialGraph, InitialVertex, SplitSide, VertexType};
pub use isometry::{Group, Isometry, PatternSymmetry};
pub(crate) use mirror::mirror_map;
pub use motion::Motion;
pub use number::Number;
pub use robustness::{
    DEFAULT_CLEARANCE, DEFAULT_MIN_FEATURE, DEFAULT_RIGID_MARGIN, MAX_RIGID_MARGIN, Robustness,
};
pub use terms::{Objective, Target};

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
    /// Digest of the file's text and of the mesh files it names (FNV-1a, 64 bits, hex;
    /// [`digest_with_meshes`]): a search resumes only the same task. Without meshes it is
    /// [`digest`] of the text.
    pub digest: String,
    /// FNV-1a of the bytes of each mesh file the task names, in the order they were read
    /// (the targets' surfaces, then `[[obstacles]]`): with the text they give
    /// [`Task::digest`].
    pub mesh_digests: Vec<u64>,
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
    /// The world around the arm: obstacles, rotational copies, boxes to stay inside.
    pub scene: crate::scene::Scene,
    /// Hard requirements besides the scene and the margins: orientations, fold limits.
    pub requirements: terms::Requirements,
    /// Margins the optimizer keeps over the whole motion (`[robustness]`, defaults when
    /// absent).
    pub robustness: Robustness,
    /// `[constraints] kawasaki = true`: every internal vertex of even degree folds flat
    /// (Kawasaki's condition, imposed by the model); off when absent.
    pub kawasaki: bool,
    /// `[fabrication]`: the panels' thickness and how they are built (issue 32); the
    /// optimizer then keeps the thick panels clear (see `docs/tasks.md`). `None` when absent:
    /// zero-thickness facets, as before.
    pub fabrication: Option<fabrication::Fabrication>,
    /// `[fabrication]`'s `kerf`, `tab_width`, `hole` and `sheet`: how the plies are laid
    /// out to be cut (issue 50); the defaults without the table.
    pub laminate: fabrication::Laminate,
}

impl Task {
    /// Whether the gripping candidate changes the problem: some term names `tip` (a
    /// target, an orientation or a fold limit), or names `s1`–`s3` or `last` in a task with
    /// copies (there the gripping vertex is the one the arms may touch at, exempt from
    /// their clearance). When neither, the three gripping candidates of a graph are one
    /// and the same problem (`s1`–`s3` and `last` are the vertex extended last's, whichever
    /// successor grips), and the search optimizes one.
    pub fn uses_gripping_vertex(&self) -> bool {
        let targets = self.objective.iter().flat_map(|o| &o.targets);
        let mut named = targets
            .map(|t| &t.vertex)
            .chain(self.requirements.orientations.iter().map(|o| &o.vertex))
            .chain(
                self.requirements
                    .fold_limits
                    .iter()
                    .filter_map(|l| match &l.crease {
                        terms::CreaseRef::Into(v) => Some(v),
                        terms::CreaseRef::Initial { .. } => None,
                    }),
            );
        let copies = self.scene.copies.n >= 2;
        named.any(|v| match v {
            terms::VertexRef::Tip => true,
            terms::VertexRef::Initial { .. } => false,
            terms::VertexRef::Successor(_) | terms::VertexRef::Last => copies,
        })
    }
}

/// Symmetry of a design task.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Symmetry {
    /// Task and G0 are symmetric about the xz-plane (in-plane: the x-axis), so a graph and its
    /// mirror image give the same designs (thesis Sec. 5.5.2).
    pub mirror_xz: bool,
    /// The pattern's own symmetry (`rotations`, `center`, `mirror_axis`): one orbit
    /// representative is grown and its images follow (thesis Sec. 4.3).
    pub pattern: PatternSymmetry,
}

/// Largest N_max accepted: each extension multiplies the number of graphs by roughly
/// twenty (with all filters: 101 graphs at N_max = 3, 1,929 at 4, 41,549 at 5).
pub const N_MAX_LIMIT: usize = crate::limits::N_MAX;

/// FNV-1a (64 bits) of `bytes`, as 16 hex digits: enough to notice an edited file.
pub fn digest(bytes: &[u8]) -> String {
    format!("{:016x}", fnv(FNV_START, bytes))
}

/// FNV-1a's offset basis.
const FNV_START: u64 = 0xcbf2_9ce4_8422_2325;

/// FNV-1a (64 bits) of `bytes`, continuing from `h`.
fn fnv(mut h: u64, bytes: &[u8]) -> u64 {
    for b in bytes {
        h = (h ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// The digest of a task: its text's ([`digest`]) when it names no mesh file; otherwise
/// FNV-1a of the text followed by each mesh file's FNV-1a (`meshes`, in the order the task
/// reads them: [`Task::mesh_digests`]), so that editing a mesh changes the task.
pub fn digest_with_meshes(text: &str, meshes: &[u64]) -> String {
    let mut h = fnv(FNV_START, text.as_bytes());
    for m in meshes {
        h = fnv(h, &m.to_le_bytes());
    }
    format!("{h:016x}")
}
