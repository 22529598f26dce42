//! The initial graph G0: its file format, checked, with the counter-clockwise crease order
//! around every vertex derived from the coordinates and the facet labels ([`super::rotation`]).

use std::collections::HashMap;

use petgraph::algo::{connected_components, toposort};
use petgraph::graph::DiGraph;
use serde::{Deserialize, Serialize};

use super::rotation::{order_vertex, ring_at};
use super::{Ctx, Drive, Number, TaskError};

/// The vertex type T of the thesis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum VertexType {
    /// χ: can be extended by r1 (and combined by r2).
    Extendable,
    /// ∅: a source, a vertex already extended, or a G0 vertex the user marked terminal.
    Terminal,
}

/// A vertex of G0.
#[derive(Clone, Debug, PartialEq)]
pub struct InitialVertex {
    /// The id used in the task file.
    pub id: String,
    /// In-plane coordinates.
    pub xy: [f64; 2],
    /// χ (extendable) or ∅ (terminal).
    pub ty: VertexType,
    /// Incoming creases (indices into [`InitialGraph::creases`]), counter-clockwise: for an
    /// extendable vertex p1 … pm, with the open sector (where new creases go) between pm
    /// and p1.
    pub preds: Vec<usize>,
    /// Outgoing creases by slot s1, s2, s3 (rotation p1 … pm s1 s2 s3). For an extendable
    /// vertex the slots follow Tables 1–2: s1 shares a facet with pm, s3 with p1. For a
    /// terminal vertex they are just its outgoing creases in counter-clockwise order.
    pub slots: [Option<usize>; 3],
    /// All incident creases counter-clockwise, starting at p1 when there are incoming ones.
    pub ring: Vec<usize>,
}

/// A crease of G0.
#[derive(Clone, Debug, PartialEq)]
pub struct InitialCrease {
    /// Tail vertex (index into [`InitialGraph::vertices`]).
    pub tail: usize,
    /// Head vertex.
    pub head: usize,
    /// Facet on the left of tail → head (index into [`InitialGraph::facets`]).
    pub left: usize,
    /// Facet on the right.
    pub right: usize,
    /// The driving angle, for creases leaving a terminal vertex.
    pub drive: Option<Drive>,
}

/// The checked initial graph.
#[derive(Clone, Debug, PartialEq)]
pub struct InitialGraph {
    /// Vertices in file order (their names v1, v2, … are their 1-based positions).
    pub vertices: Vec<InitialVertex>,
    /// Creases in file order.
    pub creases: Vec<InitialCrease>,
    /// Facet names in order of first appearance.
    pub facets: Vec<String>,
    /// For tasks symmetric about the xz-plane: the mirror image (x, y) → (x, −y) of every
    /// vertex and facet.
    pub mirror: Option<MirrorMap>,
    /// The driven creases between two extendable vertices (the thesis's double-sided
    /// arrows, Fig. 32), each split at its midpoint into two halves driven from a terminal
    /// source there, in the order the task file gives them.
    pub split: Vec<SplitSide>,
    /// How the drives move the paper.
    pub actuation: G0Actuation,
    /// The pattern's symmetry group (`[symmetry] rotations`, `mirror_axis`): the grammar
    /// grows one orbit representative and its images follow; `None` without one.
    pub group: Option<super::isometry::Group>,
}

/// A driven crease between two extendable vertices, incoming at both ends: G0 holds it as
/// two collinear halves from a terminal source at its midpoint, so that each end gets the
/// drive as an incoming crease and the graph stays acyclic.
#[derive(Clone, Debug, PartialEq)]
pub struct SplitSide {
    /// The crease as the task file gives it (index into its `[[initial_graph.creases]]`).
    pub file_index: usize,
    /// Its ends as written: `from`, `to` (vertex indices).
    pub ends: [usize; 2],
    /// The midpoint source (vertex index, after the task's own vertices).
    pub mid: usize,
    /// The halves mid → `to` and mid → `from` (crease indices).
    pub halves: [usize; 2],
}

/// How G0's driven creases move the paper (SPEC §4, §7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum G0Actuation {
    /// The driven creases lie on one straight line between the same two facets (the
    /// thesis's gripper and arm: one crease): the facet left of crease `crease` turns by
    /// +ρ/2 about it, the facet right of it by −ρ/2.
    Split {
        /// A driven crease (any of them: they are collinear).
        crease: usize,
    },
    /// One facet stays fixed (the central facet of Sec. 3.4 and 4.3, or the facet the task
    /// names with `initial_graph.fixed`) and every facet across a driven crease from it
    /// turns about that crease by its driving angle.
    Fixed {
        /// The fixed facet.
        facet: usize,
    },
}

/// The mirror image of G0's vertices and facets.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MirrorMap {
    /// `vertex[i]` is the vertex at the mirror position of vertex i.
    pub vertex: Vec<usize>,
    /// `facet[f]` is the facet that f's mirror image is.
    pub facet: Vec<usize>,
}

// ---------------------------------------------------------------------------------------
// Raw file format (serde): `[initial_graph]`.

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawInitial {
    #[serde(default)]
    pub(crate) vertices: Vec<RawVertex>,
    #[serde(default)]
    pub(crate) creases: Vec<RawCrease>,
    /// The facet that stays fixed while the drives fold the paper.
    pub(crate) fixed: Option<String>,
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

// ---------------------------------------------------------------------------------------
// Checks.

pub(super) fn vf(i: usize) -> String {
    format!("initial_graph.vertices[{i}]")
}

pub(super) fn cf(i: usize) -> String {
    format!("initial_graph.creases[{i}]")
}

/// G0 checked on its own, with the crease order around every vertex, and the distance
/// below which two of its positions are one. Its facet labels and mirror image are checked
/// against the grammar's graph afterwards (`Task::from_toml_str`); `mirror` is `None` here.
pub(crate) fn build(cx: &Ctx<'_>, raw: &RawInitial) -> Result<(InitialGraph, f64), TaskError> {
    if raw.vertices.is_empty() {
        return Err(cx.err(
            "initial_graph.vertices",
            "no vertices: G0 needs at least one crease and its two vertices",
        ));
    }
    if raw.creases.is_empty() {
        return Err(cx.err(
            "initial_graph.creases",
            "no creases: G0 needs at least one crease",
        ));
    }
    let (mut vertices, index) = vertices(cx, raw)?;
    let tol = distinct_positions(cx, &vertices)?;
    let (mut creases, facets) = creases(cx, raw, &index)?;
    check_drives(cx, &vertices, &creases, raw)?;
    check_simple(cx, &vertices, &creases, raw, tol)?;
    let split = split_sides(&mut vertices, &mut creases, raw);
    check_topology(cx, &vertices, &creases)?;

    // The counter-clockwise order around every vertex.
    for vi in 0..vertices.len() {
        let ring = ring_at(cx, &vertices, &creases, vi)?;
        order_vertex(cx, &mut vertices, &creases, &facets, vi, ring)?;
    }
    check_corners(cx, &vertices, &creases)?;
    // Filled in by `Draft::actuate`, after the facet labels are checked.
    let actuation = G0Actuation::Split { crease: 0 };
    let g = InitialGraph {
        vertices,
        creases,
        facets,
        mirror: None,
        split,
        actuation,
        group: None,
    };
    Ok((g, tol))
}

/// The vertices (unique ids, finite coordinates, no order yet) and their index by id.
fn vertices<'r>(
    cx: &Ctx<'_>,
    raw: &'r RawInitial,
) -> Result<(Vec<InitialVertex>, HashMap<&'r str, usize>), TaskError> {
    let mut index: HashMap<&str, usize> = HashMap::new();
    let mut vertices = Vec::with_capacity(raw.vertices.len());
    for (i, v) in raw.vertices.iter().enumerate() {
        if v.id.trim().is_empty() {
            return Err(cx.err(
                format!("{}.id", vf(i)),
                "empty id: give every vertex a name",
            ));
        }
        if let Some(j) = index.insert(v.id.as_str(), i) {
            return Err(cx.err(
                format!("{}.id", vf(i)),
                format!(
                    "duplicate id \"{}\" (also {}): vertex ids must be unique",
                    v.id,
                    vf(j)
                ),
            ));
        }
        let xy = cx.point::<2>(&format!("{}.xy", vf(i)), &v.xy)?;
        vertices.push(InitialVertex {
            id: v.id.clone(),
            xy,
            ty: v.ty.into(),
            preds: Vec::new(),
            slots: [None; 3],
            ring: Vec::new(),
        });
    }
    Ok((vertices, index))
}

/// Checks that no two vertices share a position; returns the tolerance used (scaled to G0's
/// extent).
fn distinct_positions(cx: &Ctx<'_>, vertices: &[InitialVertex]) -> Result<f64, TaskError> {
    let scale = vertices
        .iter()
        .map(|v| v.xy[0].abs().max(v.xy[1].abs()))
        .fold(1.0_f64, f64::max);
    let tol = 1e-9 * scale;
    for i in 0..vertices.len() {
        for j in 0..i {
            let (a, b) = (vertices[i].xy, vertices[j].xy);
            if (a[0] - b[0]).hypot(a[1] - b[1]) <= tol {
                return Err(cx.err(
                    format!("{}.xy", vf(i)),
                    format!(
                        "vertex \"{}\" lies on vertex \"{}\": vertices need distinct positions",
                        vertices[i].id, vertices[j].id
                    ),
                ));
            }
        }
    }
    Ok(tol)
}

/// The creases (known, distinct endpoints; one crease per pair; two different facets; a
/// parsed drive) and the facet names in order of first appearance.
fn creases(
    cx: &Ctx<'_>,
    raw: &RawInitial,
    index: &HashMap<&str, usize>,
) -> Result<(Vec<InitialCrease>, Vec<String>), TaskError> {
    let mut facets: Vec<String> = Vec::new();
    let mut facet_ix = |name: &str, field: String| -> Result<usize, TaskError> {
        if name.trim().is_empty() {
            return Err(cx.err(field, "empty facet name"));
        }
        Ok(match facets.iter().position(|f| f == name) {
            Some(k) => k,
            None => {
                facets.push(name.to_owned());
                facets.len() - 1
            }
        })
    };
    let mut creases = Vec::with_capacity(raw.creases.len());
    let mut pairs: HashMap<(usize, usize), usize> = HashMap::new();
    for (i, c) in raw.creases.iter().enumerate() {
        let lookup = |id: &str, field: &str| {
            index.get(id).copied().ok_or_else(|| {
                cx.err(
                    format!("{}.{field}", cf(i)),
                    format!(
                        "unknown vertex \"{id}\" (defined: {})",
                        raw.vertices
                            .iter()
                            .map(|v| v.id.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                )
            })
        };
        let tail = lookup(&c.from, "from")?;
        let head = lookup(&c.to, "to")?;
        if tail == head {
            return Err(cx.err(
                format!("{}.to", cf(i)),
                format!(
                    "crease from \"{}\" to itself: a crease joins two different vertices",
                    c.from
                ),
            ));
        }
        let key = (tail.min(head), tail.max(head));
        if let Some(j) = pairs.insert(key, i) {
            return Err(cx.err(cf(i), format!("second crease between \"{}\" and \"{}\" (also {}): at most one crease per pair", c.from, c.to, cf(j))));
        }
        if c.left == c.right {
            return Err(cx.err(
                format!("{}.right", cf(i)),
                format!(
                    "left and right facet are both \"{}\": a crease separates two different facets",
                    c.left
                ),
            ));
        }
        let left = facet_ix(&c.left, format!("{}.left", cf(i)))?;
        let right = facet_ix(&c.right, format!("{}.right", cf(i)))?;
        let drive = match &c.drive {
            None => None,
            Some(d) => Some(Drive::parse(d).map_err(|m| cx.err(format!("{}.drive", cf(i)), m))?),
        };
        creases.push(InitialCrease {
            tail,
            head,
            left,
            right,
            drive,
        });
    }
    Ok((creases, facets))
}

/// Extendable vertices have incoming creases; the creases leaving terminal vertices are
/// driven, and so may be creases between two extendable vertices (driven from both ends);
/// no other crease takes a drive (the PTU gives its angle), and every drive starts flat.
fn check_drives(
    cx: &Ctx<'_>,
    vertices: &[InitialVertex],
    creases: &[InitialCrease],
    raw: &RawInitial,
) -> Result<(), TaskError> {
    // An extendable vertex needs incoming creases: r1 places new creases from p1 and pm. A
    // crease driven from both ends counts as incoming at both.
    for (i, v) in vertices.iter().enumerate() {
        let incoming = creases.iter().any(|c| {
            c.head == i
                || (c.tail == i
                    && c.drive.is_some()
                    && vertices[c.head].ty == VertexType::Extendable)
        });
        if v.ty == VertexType::Extendable && !incoming {
            return Err(cx.err(
                format!("{}.type", vf(i)),
                format!("vertex \"{}\" has no incoming crease (a source) and cannot be extendable: make it \"terminal\"", v.id),
            ));
        }
    }
    for (i, (c, raw)) in creases.iter().zip(&raw.creases).enumerate() {
        // A crease leaving a terminal vertex is driven: its angle is prescribed. A crease
        // leaving an extendable vertex gets its angle from the PTU when the tail is
        // extended, unless it is driven and ends at an extendable vertex too: then the drive
        // enters both ends (the thesis's double-sided arrows, Fig. 32).
        match (vertices[c.tail].ty, vertices[c.head].ty, &c.drive) {
            (VertexType::Terminal, _, None) => {
                return Err(cx.err(
                    format!("{}.drive", cf(i)),
                    format!(
                        "crease {} → {} leaves terminal vertex \"{}\", so it is driven and needs a driving angle, e.g. drive = \"t\"",
                        raw.from, raw.to, raw.from
                    ),
                ));
            }
            (VertexType::Extendable, VertexType::Terminal, Some(_)) => {
                return Err(cx.err(
                    format!("{}.drive", cf(i)),
                    format!(
                        "crease {} → {} leaves extendable vertex \"{}\" and ends at terminal \"{}\": its angle follows from the PTU once \"{}\" is extended, so it takes no drive (a drive belongs on a crease leaving a terminal vertex, or on a crease between two extendable vertices, which the drive then enters at both ends)",
                        raw.from, raw.to, raw.from, raw.to, raw.from
                    ),
                ));
            }
            _ => {}
        }
        if let Some(d) = &c.drive {
            let at0: f64 = d.eval(&0.0);
            if !at0.is_finite() || at0.abs() > 1e-12 {
                return Err(cx.err(
                    format!("{}.drive", cf(i)),
                    format!(
                        "\"{d}\" is {} at t = 0: the paper starts flat, so every driving angle must be 0 at t = 0 (e.g. \"t\", \"-t\", \"t/1.2\")",
                        crate::text::num(at0)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// G0 must be drawn without crossings: two creases meet only at a common end (a closed
/// chain of creases, the central facet, is then a simple polygon).
fn check_simple(
    cx: &Ctx<'_>,
    vertices: &[InitialVertex],
    creases: &[InitialCrease],
    raw: &RawInitial,
    tol: f64,
) -> Result<(), TaskError> {
    let seg = |c: &InitialCrease| (vertices[c.tail].xy, vertices[c.head].xy);
    for i in 0..creases.len() {
        for j in 0..i {
            let (a, b) = (&creases[i], &creases[j]);
            let shared = [a.tail, a.head]
                .iter()
                .filter(|v| **v == b.tail || **v == b.head)
                .count();
            if shared > 0 {
                continue; // same direction at a shared end is ring_at's error
            }
            let ((p, q), (r, s)) = (seg(a), seg(b));
            if segments_meet(p, q, r, s, tol) {
                return Err(cx.err(
                    cf(i),
                    format!(
                        "crease {} → {} crosses or touches crease {} → {} ({}): G0 is drawn without crossings, so a closed chain of creases must be a simple polygon",
                        raw.creases[i].from,
                        raw.creases[i].to,
                        raw.creases[j].from,
                        raw.creases[j].to,
                        cf(j)
                    ),
                ));
            }
        }
        // A vertex lying on a crease it is not an end of.
        for (k, v) in vertices.iter().enumerate() {
            let c = &creases[i];
            if k == c.tail || k == c.head {
                continue;
            }
            let (p, q) = seg(c);
            if point_segment_distance(v.xy, p, q) <= tol {
                return Err(cx.err(
                    cf(i),
                    format!(
                        "vertex \"{}\" lies on crease {} → {}: a crease runs between its two ends only; split it at the vertex",
                        v.id, raw.creases[i].from, raw.creases[i].to
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Whether segments pq and rs (no common end) intersect or come within `tol`.
fn segments_meet(p: [f64; 2], q: [f64; 2], r: [f64; 2], s: [f64; 2], tol: f64) -> bool {
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let (d1, d2) = (cross(p, q, r), cross(p, q, s));
    let (d3, d4) = (cross(r, s, p), cross(r, s, q));
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return true;
    }
    point_segment_distance(r, p, q) <= tol
        || point_segment_distance(s, p, q) <= tol
        || point_segment_distance(p, r, s) <= tol
        || point_segment_distance(q, r, s) <= tol
}

/// Distance from `x` to the segment pq.
fn point_segment_distance(x: [f64; 2], p: [f64; 2], q: [f64; 2]) -> f64 {
    let d = [q[0] - p[0], q[1] - p[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    let u = if l2 > 0.0 {
        (((x[0] - p[0]) * d[0] + (x[1] - p[1]) * d[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (x[0] - p[0] - u * d[0]).hypot(x[1] - p[1] - u * d[1])
}

/// Topology: acyclic, connected, fewer than three successors.
fn check_topology(
    cx: &Ctx<'_>,
    vertices: &[InitialVertex],
    creases: &[InitialCrease],
) -> Result<(), TaskError> {
    let mut dg: DiGraph<(), ()> = DiGraph::new();
    let nodes: Vec<_> = (0..vertices.len()).map(|_| dg.add_node(())).collect();
    for c in creases {
        dg.add_edge(nodes[c.tail], nodes[c.head], ());
    }
    if let Err(cycle) = toposort(&dg, None) {
        let v = cycle.node_id().index();
        return Err(cx.err(
            "initial_graph.creases",
            format!("the creases form a directed cycle through vertex \"{}\": G0 must be acyclic (thesis Sec. 5.2)", vertices[v].id),
        ));
    }
    if connected_components(&dg) != 1 {
        let mut seen = vec![false; vertices.len()];
        let mut stack = vec![0];
        while let Some(v) = stack.pop() {
            if !std::mem::replace(&mut seen[v], true) {
                for c in creases {
                    if c.tail == v {
                        stack.push(c.head);
                    } else if c.head == v {
                        stack.push(c.tail);
                    }
                }
            }
        }
        let apart = seen.iter().position(|s| !s).unwrap_or(0);
        return Err(cx.err(
            "initial_graph",
            format!("G0 is disconnected: \"{}\" is not joined to \"{}\" by creases; G0 must be one connected graph", vertices[apart].id, vertices[0].id),
        ));
    }
    for (i, v) in vertices.iter().enumerate() {
        let out = creases.iter().filter(|c| c.tail == i).count();
        if out >= 3 {
            return Err(cx.err(
                vf(i),
                format!("vertex \"{}\" already has {out} outgoing creases: G0 vertices must have fewer than 3 (thesis Sec. 5.2)", v.id),
            ));
        }
    }
    Ok(())
}

/// Split every driven crease between two extendable vertices at its midpoint: the crease
/// becomes the half mid → `to` in place, the half mid → `from` is appended, and the
/// midpoint (terminal, named `mid(from,to)`) is appended to the vertices.
pub(crate) fn split_sides(
    vertices: &mut Vec<InitialVertex>,
    creases: &mut Vec<InitialCrease>,
    raw: &RawInitial,
) -> Vec<SplitSide> {
    let mut split = Vec::new();
    for i in 0..creases.len() {
        let c = creases[i].clone();
        let two_sided = c.drive.is_some()
            && vertices[c.tail].ty == VertexType::Extendable
            && vertices[c.head].ty == VertexType::Extendable;
        if !two_sided {
            continue;
        }
        let (a, b) = (vertices[c.tail].xy, vertices[c.head].xy);
        let mid = vertices.len();
        vertices.push(InitialVertex {
            id: format!("mid({},{})", raw.creases[i].from, raw.creases[i].to),
            xy: [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])],
            ty: VertexType::Terminal,
            preds: Vec::new(),
            slots: [None; 3],
            ring: Vec::new(),
        });
        // mid → to keeps the crease's sides; mid → from runs the other way, so they swap.
        creases[i].tail = mid;
        let back = creases.len();
        creases.push(InitialCrease {
            tail: mid,
            head: c.tail,
            left: c.right,
            right: c.left,
            drive: c.drive.clone(),
        });
        split.push(SplitSide {
            file_index: i,
            ends: [c.tail, c.head],
            mid,
            halves: [i, back],
        });
    }
    split
}

/// Every closed sector between two incoming creases of an extendable G0 vertex (a corner
/// of a driven polygon, say) is a sector of its PTU, so it must lie in (0, π): a polygon
/// driven from its sides must be convex.
pub(crate) fn check_corners(
    cx: &Ctx<'_>,
    vertices: &[InitialVertex],
    creases: &[InitialCrease],
) -> Result<(), TaskError> {
    for (i, v) in vertices.iter().enumerate() {
        if v.ty != VertexType::Extendable {
            continue;
        }
        for w in v.preds.windows(2) {
            let dir = |c: usize| {
                let o = vertices[creases[c].tail].xy;
                (o[1] - v.xy[1]).atan2(o[0] - v.xy[0])
            };
            let mut a = dir(w[1]) - dir(w[0]);
            if a <= 0.0 {
                a += std::f64::consts::TAU;
            }
            if a >= std::f64::consts::PI - 1e-9 {
                return Err(cx.err(
                    format!("initial_graph.vertices[{i}]"),
                    format!(
                        "the sector of \"{}\" between its incoming creases from \"{}\" and \"{}\" is {:.1}°: a vertex's sectors lie below 180° (the PTU's units are Euler triangles' sides), so a polygon driven from its sides must be convex at every corner",
                        v.id,
                        vertices[creases[w[0]].tail].id,
                        vertices[creases[w[1]].tail].id,
                        a.to_degrees()
                    ),
                ));
            }
        }
    }
    Ok(())
}
