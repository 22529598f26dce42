//! The terms of a design task beyond G0 and the grammar (issue 31): what the objective asks
//! for (points, paths, lines, planes and surfaces to reach, area to gain) and the hard
//! requirements (orientations, fold-angle limits). The world around the arm (obstacles,
//! copies, boxes to stay inside) is [`crate::scene::Scene`].
//!
//! These are the validated values; the file syntax and its checks are in `task/`'s parsers.

use serde::{Deserialize, Serialize};

use crate::geom::V3;

/// Which vertex a term is about, named independently of the graph the grammar generates
/// (vertex numbers differ from graph to graph; these do not).
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VertexRef {
    /// The gripping vertex: the successor of the vertex extended last that the search is
    /// optimizing as the tip (each of the three is tried; `"tip"`, the default).
    Tip,
    /// Successor `k` (0, 1, 2, counter-clockwise) of the vertex extended last, whichever is
    /// the tip (`"s1"`, `"s2"`, `"s3"`): a second effector beside the tip.
    Successor(u8),
    /// The vertex extended last (`"last"`): the tip's predecessor.
    Last,
    /// A vertex of G0, by its id in the task file (its dense index in G0's vertex list).
    Initial {
        /// The id as the task file writes it.
        id: String,
        /// Its index in `initial_graph.vertices`.
        index: usize,
    },
}

impl std::fmt::Display for VertexRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            VertexRef::Tip => f.write_str("tip"),
            VertexRef::Successor(k) => write!(f, "s{}", k + 1),
            VertexRef::Last => f.write_str("last"),
            VertexRef::Initial { id, .. } => f.write_str(id),
        }
    }
}

/// Where a target wants its vertex.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Goal {
    /// At this point (the thesis's targets, Eq. 37–38).
    Point {
        /// The point.
        point: V3,
    },
    /// On the line through `point` along the unit `direction`.
    Line {
        /// A point of the line.
        point: V3,
        /// Unit direction.
        direction: V3,
    },
    /// On the plane through `point` with unit `normal`.
    Plane {
        /// A point of the plane.
        point: V3,
        /// Unit normal.
        normal: V3,
    },
    /// On the surface of mesh `surfaces[index]` of the [`Objective`].
    Surface {
        /// Index into [`Objective::surfaces`].
        index: usize,
    },
}

/// One term of Ω: the distance of a vertex at one `t` from its goal, weighted. A path or a
/// range of t is expanded into one target per sample when the task is loaded.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Target {
    /// The driving parameter.
    pub t: f64,
    /// The vertex.
    pub vertex: VertexRef,
    /// Where it should be.
    pub goal: Goal,
    /// Weight in Ω (> 0; 1 unless given).
    pub weight: f64,
    /// Index of the `[[objective.targets]]` entry it comes from (a path's samples share
    /// one).
    pub entry: usize,
}

impl Target {
    /// The point of a [`Goal::Point`] target.
    pub fn point(&self) -> Option<V3> {
        match self.goal {
            Goal::Point { point } => Some(point),
            _ => None,
        }
    }
}

/// What an area term measures.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum AreaKind {
    /// The flat pattern's area, every copy counted (paper units²).
    Flat,
    /// The flat area divided by the footprint of the folded pattern's bounding box at `t`:
    /// its extent across the copies' axis (the z-axis without copies), a rectangle in the
    /// plane normal to that axis, aligned with x and y when the axis is z. Dimensionless:
    /// how many times the sheet's area folds into its footprint.
    Packing {
        /// The state whose bounding box counts.
        t: f64,
    },
}

/// An area term: maximized, a term with no natural zero. With one, a design *meets the
/// target* when it keeps every requirement, reaches Ω ≤ `threshold` (when the task also has
/// targets: then Ω ≤ threshold is a constraint of the optimization, not a term of it) and
/// has an area term of at least `at_least`; the optimizer then maximizes the term over every
/// start instead of stopping at the first that meets the target.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AreaTerm {
    /// What is measured.
    pub kind: AreaKind,
    /// Weight of the term (the objective minimized is `−weight · term`; > 0).
    pub weight: f64,
    /// The least value of the term a design must reach to meet the target (≥ 0).
    pub at_least: f64,
}

/// The objective: Ω over the targets, and optionally an area term.
#[derive(Clone, Debug, PartialEq)]
pub struct Objective {
    /// The targets, paths expanded (may be empty when there is an area term).
    pub targets: Vec<Target>,
    /// Success threshold ϑ on Ω (Eq. 37–38).
    pub threshold: f64,
    /// Meshes targets of kind [`Goal::Surface`] refer to.
    pub surfaces: Vec<crate::scene::shapes::MeshObstacle>,
    /// An area term to maximize.
    pub area: Option<AreaTerm>,
}

/// Which direction an orientation requirement is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Pointer {
    /// The crease into the vertex, from its predecessor to it (`"crease"`): for the tip,
    /// the fingertip's direction.
    Crease,
    /// The normal of the facet left of that crease (`"facet_left"`), oriented as the paper's
    /// upper side (+z in the flat state).
    FacetLeft,
    /// The normal of the facet right of that crease (`"facet_right"`).
    FacetRight,
}

/// A requirement on a direction of the folded pattern: the angle between the direction and
/// `direction` stays within `tolerance` of `angle` at every `t` listed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Orientation {
    /// `orientation[k]`, or the task's `name` for it.
    pub name: String,
    /// Whose crease or facet.
    pub vertex: VertexRef,
    /// The crease or one of its facets' normals.
    pub of: Pointer,
    /// The reference direction (unit).
    pub direction: V3,
    /// The wanted angle to it (rad, in [0, π]; 0 unless given: point along it).
    pub angle: f64,
    /// How far from `angle` the direction may be (rad, > 0).
    pub tolerance: f64,
    /// The states it applies at (one, or a range's samples).
    pub t: Vec<f64>,
}

/// Which crease a fold-angle limit is about.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CreaseRef {
    /// The crease into a vertex from its predecessor (`"tip"`, `"last"`, `"s2"`, …).
    Into(VertexRef),
    /// A crease of G0, by its end vertices' ids (`"v1-v2"`, either order).
    Initial {
        /// The crease as written (`"v1-v2"`).
        name: String,
        /// Index in G0's vertex list of one end.
        a: usize,
        /// Index of the other end.
        b: usize,
    },
}

/// The largest fold angle `|ρ|` a crease may reach over the whole motion (what a hinge or
/// a thick panel allows).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FoldLimit {
    /// The crease.
    pub crease: CreaseRef,
    /// Largest `|ρ|` (rad, in (0, π)).
    pub max: f64,
}

/// The hard requirements of a task besides obstacles and boxes (which are in the scene) and
/// the `[robustness]` margins.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Requirements {
    /// Orientation requirements.
    pub orientations: Vec<Orientation>,
    /// Largest fold angle of every crease (rad, in (0, π)), if limited.
    pub max_fold: Option<f64>,
    /// Limits of single creases (tighter than `max_fold` where both apply).
    pub fold_limits: Vec<FoldLimit>,
}
