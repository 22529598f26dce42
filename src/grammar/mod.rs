//! Crease pattern graphs, the rules r1 and r2, enumeration and filters (thesis Sec. 5.1–5.2,
//! 5.5.2; SPEC §2).
//!
//! ```
//! use foldsynth::grammar::{CreaseGraph, Enumeration, Filters};
//! use foldsynth::task::Task;
//!
//! let task = Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap();
//! // One graph, rebuilt from its rule sequence (r1 on v2, r1 on v3, r2 on v4 and v8, …).
//! let g = CreaseGraph::from_sequence(&task, "2, 3, (4, 8), 4, (7, 8)").unwrap();
//! assert_eq!(g.internal_count(), 3);
//! assert!(g.is_semantically_valid());
//! // All graphs up to N_max = 3, without any filter: the thesis's 291.
//! let all = Enumeration::run(&task, task.n_max, Filters::none());
//! assert_eq!(all.nodes.len(), 291);
//! ```
//!
//! # Representation
//!
//! A [`CreaseGraph`] is a petgraph [`StableDiGraph`](petgraph::stable_graph::StableDiGraph)
//! whose node weights are [`Vertex`] (the vertex label: predecessors counter-clockwise, the
//! outgoing slots s1 s2 s3, the type χ/∅) and whose edge weights are [`Crease`] (the edge
//! label: the facets left and right). Vertices and creases have stable ids ([`Vid`],
//! [`Cid`]) that are never reused; the thesis's vertex *names* are 1-based positions in the
//! vertex list and shift down when r2 deletes a vertex ([`CreaseGraph::name`]).
//!
//! Around every vertex the creases run counter-clockwise p1 … pm s1 s2 s3. An extendable
//! vertex has an open sector where its missing slots go; the facets on either side of it
//! are still open (they end at the paper's edge or at vertices yet to be extended).
//!
//! # Rules and what they record for the model
//!
//! [`CreaseGraph::extend`] (r1) fills the missing outgoing slots of a χ vertex — the six
//! scenarios of Tables 1–2 are the six ways one or two slots can already be taken in G0 —
//! and places every new vertex by a [`Placement`] (Eq. 28) with new sector and length
//! [`Variable`]s. [`CreaseGraph::combine`] (r2) merges two χ vertices. Both append a
//! [`StepRecord`] with the constraints they add ([`ConstraintSpec`], Eq. 31–34) and, for r2,
//! the variables it eliminates and their geometric substitutes (Eq. 35).
//! [`CreaseGraph::constraints`] gives the constraint set ψ of the final graph.
//!
//! # Readings where the thesis is silent or ambiguous
//!
//! - **r2's roles.** c1 is the vertex whose last incoming crease has the shared facet on
//!   its right; c2 is deleted unless only c2 is in G0. For a G0 vertex that already owns
//!   slots, the compared facets must be the open ones (c1 without s1, c2 without s3), and
//!   a vertex is never combined with its own ancestor (that would close a cycle; with
//!   vertices r1 created it cannot happen, only G0 vertices with successors could).
//! - **Eq. 35.** The deleted vertex's own length and sector leave Φ, except a sector a
//!   surviving placement still uses (s2 is placed by α_s1 + α_s2, so α_s1 outlives a
//!   deleted s1): substituting it by a measured angle would make s2's position depend on
//!   itself whenever the combined vertex descends from s2 (e.g. `2, 4, (3, 6)`). The
//!   sectors and lengths next to moved creases are measured from the coordinates instead.
//! - **Table 1, r1,3** writes `R(α_s3) d(a,p1)` for s3; Eq. 28 and r1,6 use `R(−α_s3)`,
//!   which is what keeps s3 clockwise of p1. We use the minus sign.
//! - **Isomorphism** fixes G0's vertices (they carry coordinates and drives); for the
//!   thesis's G0 every direction-preserving isomorphism does so anyway.
//! - **Filters' order.** Isomorphic (to any earlier graph) first; then mirror (its mirror
//!   image equals an earlier graph that was kept); then validity. A graph without an
//!   extended vertex has no gripping vertex and is invalid.
//!
//! # Rule r2′ (Sec. 5.7, Fig. 52b)
//!
//! [`CreaseGraph::combine_straight`] combines two χ vertices like r2 but replaces them by a
//! sink v′ on the straight segment between their predecessors (the thesis leaves the rule a
//! sketch; our readings): it matches where r2 does, with one predecessor each, neither in
//! G0, the predecessors not joined by a crease; v′ sits at the midpoint (any point of the
//! segment gives the same kinematics; the midpoint adds no variable); the two facets on
//! the far side of the straight crease become one. It is recorded as an [`R2Record`] with
//! [`Straight`] set and written `(a, b)'`. The enumeration applies it only when asked
//! ([`Rules`]), after r2's matches, so the thesis's counts below stay.
//!
//! # Counts (gripper and robotic arm, G0 of Fig. 40)
//!
//! Without filters N_max = 3 gives exactly the thesis's 291 graphs (G0, the root, not
//! counted). With all filters we find 53 meaningful graphs and 1194 design alternatives
//! against the thesis's 52 and 1170: 1194 − 1170 = 24 = 2³ × 3, so the thesis lists one
//! graph with N = 3 fewer. Reading the isomorphism without the mark gives 51 and loses
//! `2, 4, 3, (6, 11)`, which the thesis names as meaningful; reflection-insensitive
//! isomorphism, a mirror check that ignores the mark, comparing mirror images only with
//! meaningful graphs, or checking mirror before isomorphism all give 53 again.

mod canon;
mod enumerate;
mod graph;
mod notation;
mod orbits;
mod rules;
mod step;
mod straight;
mod symmetric;

pub use canon::Code;
pub use enumerate::{
    DOT_FOOTER, Enumeration, Filters, Generated, LevelCounts, Node, Rules, Status, Streamed,
    TooLarge, dot_header, dot_node,
};
pub use graph::{CreaseGraph, FacetBoundary, FacetError};
pub use notation::{NotationError, format_sequence, parse_sequence};
pub use rules::{R2Match, RuleError};
pub use step::Step;
pub use straight::StraightSink;

use serde::{Deserialize, Serialize};

use crate::task::Drive;
/// The vertex type T of the thesis (defined with G0, which the task file types).
pub use crate::task::VertexType;

/// Stable vertex id: never reused, independent of the shifting names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct Vid(pub u32);

/// Stable crease (directed edge) id: never reused; r2 moves a crease, it keeps its id.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct Cid(pub u32);

/// Facet id: G0's facets first (in order of appearance in the task file), then the facets
/// r1 creates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct FacetId(pub u32);

/// Optimization variable id (index into [`CreaseGraph::variables`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct VarId(pub u32);

impl Vid {
    fn ix(self) -> usize {
        self.0 as usize
    }
}
impl Cid {
    fn ix(self) -> usize {
        self.0 as usize
    }
}

/// A vertex and its label.
#[derive(Clone, Debug, PartialEq)]
pub struct Vertex {
    /// Stable id.
    pub vid: Vid,
    /// Incoming creases, counter-clockwise (p1 … pm).
    pub preds: Vec<Cid>,
    /// Outgoing creases by slot s1, s2, s3 (all three for extended vertices). For a
    /// terminal G0 vertex: its outgoing creases, counter-clockwise.
    pub slots: [Option<Cid>; 3],
    /// χ or ∅.
    pub ty: VertexType,
    /// Whether r1 extended this vertex (it is internal).
    pub extended: bool,
    /// Index in G0's vertex list, for vertices of the initial graph.
    pub g0: Option<usize>,
    /// In-plane coordinates given in the task file (G0 vertices only).
    pub g0_coords: Option<[f64; 2]>,
    /// How r1 placed this vertex (Eq. 28); `None` for G0 vertices and r2′ sinks.
    pub placement: Option<Placement>,
    /// For a sink made by r2′: the two vertices (the tails of its incoming creases) on
    /// whose straight segment it lies, at the midpoint. `None` for every other vertex.
    pub sink_between: Option<[Vid; 2]>,
}

impl Vertex {
    /// Whether the vertex belongs to the initial graph.
    pub fn in_g0(&self) -> bool {
        self.g0.is_some()
    }
    /// The outgoing creases in slot order.
    pub fn succ(&self) -> Vec<Cid> {
        self.slots.iter().flatten().copied().collect()
    }
}

/// Where r1 put a new vertex (Eq. 28, Tables 1–2):
/// `x = x_parent + l · R(sign · Σ sectors) · d(parent → reference)`, with `d` the unit
/// direction and `R` the 2D rotation (counter-clockwise positive).
///
/// - s1: reference p_m, sign +, `[α_s1]`;
/// - s2 when s1 is created in the same application: reference p_m, sign +, `[α_s1, α_s2]`;
/// - s2 when s1 already existed in G0 (r1,3, r1,5): reference s1, sign +, `[α_s2]`;
/// - s3: reference p_1, sign −, `[α_s3]`.
///
/// The reference was placed before the parent's extension and is never deleted (it is a
/// predecessor of the parent, hence ∅, or a G0 vertex). The placement is kept exactly as
/// created, also after r2 redirects creases around it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Placement {
    /// The extended vertex.
    pub parent: Vid,
    /// The vertex the angle is measured from (seen from the parent).
    pub reference: Vid,
    /// +1 counter-clockwise, −1 clockwise.
    pub sign: f64,
    /// The sector variables summed into the angle; the last one belongs to this vertex.
    pub sectors: Vec<VarId>,
    /// The length variable of the crease parent → vertex.
    pub length: VarId,
}

/// Where a crease came from.
#[derive(Clone, Debug, PartialEq)]
pub enum CreaseOrigin {
    /// A crease of G0.
    Initial {
        /// Index in G0's crease list.
        index: usize,
        /// Its driving angle (creases leaving terminal G0 vertices).
        drive: Option<Drive>,
    },
    /// Created by r1.
    Extension {
        /// Index of the r1 step in [`CreaseGraph::steps`].
        step: usize,
        /// The slot at the tail, 1..=3.
        slot: u8,
        /// Its sector variable.
        sector: VarId,
        /// Its length variable.
        length: VarId,
        /// The vertex created with it (its head until an r2 deletes that vertex).
        created: Vid,
    },
}

/// A directed crease and its label.
#[derive(Clone, Debug, PartialEq)]
pub struct Crease {
    /// Stable id.
    pub cid: Cid,
    /// Tail vertex.
    pub tail: Vid,
    /// Head vertex (current: r2 moves creases to the surviving vertex).
    pub head: Vid,
    /// Facet on the left of tail → head.
    pub left: FacetId,
    /// Facet on the right.
    pub right: FacetId,
    /// G0 or r1.
    pub origin: CreaseOrigin,
}

/// Kind of an optimization variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VarKind {
    /// A sector angle α.
    Sector,
    /// A crease length l.
    Length,
}

/// An optimization variable introduced by r1.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Variable {
    /// Id.
    pub id: VarId,
    /// Sector or length.
    pub kind: VarKind,
    /// Readable name from the names at creation: `α_5` (the sector placing v5), `l_2,5`
    /// (the crease v2 → v5). A name already used in this graph (names shift after r2) gets
    /// a prime: `α_8'`.
    pub name: String,
    /// Index of the r1 step that introduced it.
    pub step: usize,
    /// The crease it places.
    pub crease: Cid,
    /// The vertex it places (as created).
    pub vertex: Vid,
}

/// A constraint ψ as plain data. "Sector from `from` to `to`" is the counter-clockwise
/// sector at `vertex` between two consecutive creases.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ConstraintSpec {
    /// α_min ≤ sector ≤ α_max (Eq. 31). `var`: the variable equal to this sector, when it
    /// still is one; `None` when r2 moved a bounding crease, so the sector is measured from
    /// the coordinates (Eq. 35).
    Sector {
        /// The vertex.
        vertex: Vid,
        /// Clockwise bounding crease.
        from: Cid,
        /// Counter-clockwise bounding crease.
        to: Cid,
        /// The variable equal to the sector, if any.
        var: Option<VarId>,
    },
    /// The sector that closes the vertex: 2π − (all other sectors) ≥ α_min (Eq. 31, second
    /// row).
    Remainder {
        /// The vertex.
        vertex: Vid,
        /// Clockwise bounding crease.
        from: Cid,
        /// Counter-clockwise bounding crease.
        to: Cid,
    },
    /// l_min ≤ length ≤ l_max (Eq. 32); `var` as for [`ConstraintSpec::Sector`].
    Length {
        /// The crease.
        crease: Cid,
        /// The variable equal to its length, if any.
        var: Option<VarId>,
    },
    /// U_max ≤ U_med + U_min at t_max (Eq. 33).
    RigidFoldability {
        /// The extended vertex.
        vertex: Vid,
    },
    /// α_min ≤ ∠ x_p1 x_c1 x_p2 ≤ α_max (Eq. 34): the sector r2 closes between the last
    /// incoming crease of c1 and the first of c2.
    MergedSector {
        /// The combined vertex.
        vertex: Vid,
        /// Clockwise bounding crease.
        from: Cid,
        /// Counter-clockwise bounding crease.
        to: Cid,
    },
}

/// A geometric substitute for a variable r2 eliminated (Eq. 35).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Substitution {
    /// `var = ∠(d(at → reference), d(at → head(crease))) − Σ minus`, the angle measured in
    /// [0, 2π) counter-clockwise when `sign` is +1 and clockwise when it is −1, exactly as
    /// the crease's placement measured it.
    Sector {
        /// The eliminated variable.
        var: VarId,
        /// The tail of the crease.
        at: Vid,
        /// The placement's reference vertex.
        reference: Vid,
        /// The crease (its current head is wherever r2 moved it).
        crease: Cid,
        /// The placement's sign.
        sign: f64,
        /// The other sector variables of the placement.
        minus: Vec<VarId>,
    },
    /// `var = ‖x_head(crease) − x_tail(crease)‖`.
    Length {
        /// The eliminated variable.
        var: VarId,
        /// The crease.
        crease: Cid,
    },
}

/// A vertex r1 created.
#[derive(Clone, Debug, PartialEq)]
pub struct Created {
    /// Slot 1..=3 at the extended vertex.
    pub slot: u8,
    /// The new vertex.
    pub vertex: Vid,
    /// The new crease.
    pub crease: Cid,
    /// Its placement; `None` for the image of a representative's vertex under the
    /// pattern's symmetry (placed as that image, with the representative's variables).
    pub placement: Option<Placement>,
}

/// One application of r1.
#[derive(Clone, Debug, PartialEq)]
pub struct R1Record {
    /// The extended vertex.
    pub vertex: Vid,
    /// Its name when extended.
    pub name: usize,
    /// Scenario r1,1 … r1,6 (Tables 1–2), from the slots G0 already filled.
    pub scenario: u8,
    /// The new vertices and creases.
    pub created: Vec<Created>,
    /// The variables introduced.
    pub variables: Vec<VarId>,
    /// The constraints introduced (as created).
    pub constraints: Vec<ConstraintSpec>,
    /// Whether this application extends an image of an orbit's representative under the
    /// pattern's symmetry (it follows the representative's step, adds no variable and no
    /// constraint, and is not written in the rule sequence).
    pub image: bool,
}

/// One application of r2.
#[derive(Clone, Debug, PartialEq)]
pub struct R2Record {
    /// The vertex whose last incoming crease bounds the shared facet on its right.
    pub c1: Vid,
    /// The vertex whose first incoming crease bounds it on its left.
    pub c2: Vid,
    /// The names of c1 and c2 when combined.
    pub names: (usize, usize),
    /// The vertex that remains (c1, unless only c2 is in G0).
    pub survivor: Vid,
    /// The vertex deleted.
    pub deleted: Vid,
    /// The creases moved from the deleted vertex to the survivor.
    pub moved: Vec<Cid>,
    /// The deleted vertex's placement.
    pub removed_placement: Option<Placement>,
    /// Variables no surviving placement uses any more.
    pub eliminated: Vec<VarId>,
    /// Their geometric substitutes (Eq. 35).
    pub substitutions: Vec<Substitution>,
    /// The constraint added (Eq. 34). For r2′ the sector it names (at the sink, between
    /// the two straight halves) is π by construction and is not bounded: see
    /// [`CreaseGraph::constraints`].
    pub constraint: ConstraintSpec,
    /// `Some` when this application was r2′ (the combined vertex is a sink on the straight
    /// segment between the predecessors).
    pub straight: Option<Straight>,
    /// Whether this application combines images of a representative pair under the
    /// pattern's symmetry (it follows that pair's step and is not written in the rule
    /// sequence).
    pub image: bool,
}

/// What r2′ did beyond r2 (thesis Sec. 5.7, Fig. 52b): both combined vertices give way to
/// a new sink v′ at the midpoint of their predecessors, so the two creases into it form
/// one straight crease folded from both ends; the facets on its far side become one.
#[derive(Clone, Debug, PartialEq)]
pub struct Straight {
    /// The new sink v′ (it takes c1's name).
    pub sink: Vid,
    /// c1, replaced by v′ (`R2Record::deleted` is c2).
    pub replaced: Vid,
    /// c1's placement, removed with it.
    pub replaced_placement: Option<Placement>,
    /// The predecessors p1 (of c1) and p2 (of c2): the ends of the straight crease.
    pub between: [Vid; 2],
    /// The facet both creases bounded already (closed at v′ by a straight angle).
    pub inner: FacetId,
    /// The facet on the far side after the merge (as numbered right after this step).
    pub outer: FacetId,
    /// The name of the facet merged into `outer` (it no longer exists).
    pub merged_name: String,
}

/// One rule application.
#[derive(Clone, Debug, PartialEq)]
pub enum StepRecord {
    /// r1.
    R1(R1Record),
    /// r2.
    R2(R2Record),
}
