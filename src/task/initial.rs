//! The initial graph G0: checked, with the counter-clockwise crease order around every
//! vertex derived from the coordinates and the facet labels.

use std::collections::HashMap;
use std::sync::Arc;

use petgraph::algo::{connected_components, toposort};
use petgraph::graph::DiGraph;

use super::{Ctx, Drive, RawInitial, TaskError};
use crate::grammar::{CreaseGraph, VertexType};

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
}

/// The mirror image of G0's vertices and facets.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MirrorMap {
    /// `vertex[i]` is the vertex at the mirror position of vertex i.
    pub vertex: Vec<usize>,
    /// `facet[f]` is the facet that f's mirror image is.
    pub facet: Vec<usize>,
}

/// Angles closer than this are one direction (two creases on top of each other).
const ANGLE_EPS: f64 = 1e-9;

pub(crate) fn build(
    cx: &Ctx<'_>,
    raw: &RawInitial,
    mirror_xz: bool,
) -> Result<InitialGraph, TaskError> {
    let vf = |i: usize| format!("initial_graph.vertices[{i}]");
    let cf = |i: usize| format!("initial_graph.creases[{i}]");

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

    // Vertices: unique ids, finite and distinct coordinates.
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

    // Creases: known, distinct endpoints; one crease per pair; two different facets.
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

    // An extendable vertex needs incoming creases: r1 places new creases from p1 and pm.
    for (i, v) in vertices.iter().enumerate() {
        if v.ty == VertexType::Extendable && !creases.iter().any(|c| c.head == i) {
            return Err(cx.err(
                format!("{}.type", vf(i)),
                format!("vertex \"{}\" has no incoming crease (a source) and cannot be extendable: make it \"terminal\"", v.id),
            ));
        }
    }
    for (i, (c, raw)) in creases.iter().zip(&raw.creases).enumerate() {
        // A crease leaving a terminal vertex is driven: its angle is prescribed. A crease
        // leaving an extendable vertex gets its angle from the PTU when the tail is extended.
        match (vertices[c.tail].ty, &c.drive) {
            (VertexType::Terminal, None) => {
                return Err(cx.err(
                    format!("{}.drive", cf(i)),
                    format!(
                        "crease {} → {} leaves terminal vertex \"{}\", so it is driven and needs a driving angle, e.g. drive = \"t\"",
                        raw.from, raw.to, raw.from
                    ),
                ));
            }
            (VertexType::Extendable, Some(_)) => {
                return Err(cx.err(
                    format!("{}.drive", cf(i)),
                    format!(
                        "crease {} → {} leaves extendable vertex \"{}\"; its angle follows from the PTU once \"{}\" is extended, so it takes no drive",
                        raw.from, raw.to, raw.from, raw.from
                    ),
                ));
            }
            _ => {}
        }
    }

    // Topology: acyclic, connected, fewer than three successors.
    let mut dg: DiGraph<(), ()> = DiGraph::new();
    let nodes: Vec<_> = (0..vertices.len()).map(|_| dg.add_node(())).collect();
    for c in &creases {
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
                for c in &creases {
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

    // The counter-clockwise order around every vertex.
    for vi in 0..vertices.len() {
        let ring = ring_at(cx, &vertices, &creases, vi)?;
        order_vertex(cx, &mut vertices, &creases, &facets, vi, ring)?;
    }

    let mut g = InitialGraph {
        vertices,
        creases,
        facets,
        mirror: None,
    };

    // Facets: every facet's boundary must be one chain (closed, or open at the paper's edge).
    let graph = CreaseGraph::from_initial(Arc::new(g.clone()));
    if let Err(e) = graph.facet_boundaries() {
        return Err(cx.err(
            "initial_graph.creases",
            format!("inconsistent facet labels: {e}"),
        ));
    }
    if !mirror_xz {
        return Ok(g);
    }
    g.mirror = Some(mirror_map(cx, &g.vertices, &g.creases, &g.facets, tol)?);
    let graph = CreaseGraph::from_initial(Arc::new(g.clone()));
    if g.mirror.is_some() && graph.mirror_code().as_ref() != Some(&graph.canonical_code()) {
        return Err(cx.err(
            "symmetry.mirror_xz",
            "the mirror image of G0 orders its creases differently from G0 (check the facet labels of creases on the x-axis)",
        ));
    }
    Ok(g)
}

/// The facet on the counter-clockwise / clockwise side of crease `c` seen from vertex `v`.
fn sides(c: &InitialCrease, v: usize) -> (usize, usize) {
    if c.tail == v {
        (c.left, c.right)
    } else {
        (c.right, c.left)
    }
}

/// Incident creases sorted counter-clockwise by direction.
fn ring_at(
    cx: &Ctx<'_>,
    vs: &[InitialVertex],
    cs: &[InitialCrease],
    v: usize,
) -> Result<Vec<usize>, TaskError> {
    let p = vs[v].xy;
    let mut rays: Vec<(f64, usize)> = cs
        .iter()
        .enumerate()
        .filter(|(_, c)| c.tail == v || c.head == v)
        .map(|(i, c)| {
            let o = vs[if c.tail == v { c.head } else { c.tail }].xy;
            ((o[1] - p[1]).atan2(o[0] - p[0]), i)
        })
        .collect();
    rays.sort_by(|a, b| a.0.total_cmp(&b.0));
    for k in 1..rays.len() {
        if rays[k].0 - rays[k - 1].0 < ANGLE_EPS {
            let (a, b) = (&cs[rays[k - 1].1], &cs[rays[k].1]);
            return Err(cx.err(
                "initial_graph.creases",
                format!(
                    "creases {}→{} and {}→{} leave vertex \"{}\" in the same direction",
                    vs[a.tail].id, vs[a.head].id, vs[b.tail].id, vs[b.head].id, vs[v].id
                ),
            ));
        }
    }
    Ok(rays.into_iter().map(|r| r.1).collect())
}

/// Derive preds (p1 … pm), slots and the ring of vertex `v` from its ccw ring.
fn order_vertex(
    cx: &Ctx<'_>,
    vs: &mut [InitialVertex],
    cs: &[InitialCrease],
    facets: &[String],
    v: usize,
    ring: Vec<usize>,
) -> Result<(), TaskError> {
    let n = ring.len();
    // Sector k lies counter-clockwise from ring[k] to ring[k+1]; it is closed when one facet
    // fills it, i.e. both creases name the same facet on that side.
    let open: Vec<usize> = (0..n)
        .filter(|&k| sides(&cs[ring[k]], v).0 != sides(&cs[ring[(k + 1) % n]], v).1)
        .collect();
    let id = vs[v].id.clone();
    let field = format!("initial_graph.vertices[{v}]");
    let is_in = |c: usize| cs[c].head == v;
    let start = open.first().map_or(0, |&k| (k + 1) % n);
    let rotated: Vec<usize> = (0..n).map(|k| ring[(start + k) % n]).collect();

    if vs[v].ty == VertexType::Terminal {
        // Never extended or combined: any consistent arrangement is fine.
        let preds: Vec<usize> = rotated.iter().copied().filter(|&c| is_in(c)).collect();
        let outs: Vec<usize> = rotated.iter().copied().filter(|&c| !is_in(c)).collect();
        let mut slots = [None; 3];
        for (k, c) in outs.into_iter().enumerate() {
            slots[k] = Some(c);
        }
        let vx = &mut vs[v];
        // The true ccw order, for facet walks; preds and slots are storage only here.
        vx.ring = rotated;
        vx.preds = preds;
        vx.slots = slots;
        return Ok(());
    }

    if !rotated.iter().any(|&c| is_in(c)) {
        return Err(cx.err(
            format!("{field}.type"),
            format!("vertex \"{id}\" has no incoming crease (a source) and cannot be extendable: make it \"terminal\""),
        ));
    }
    let names = |k: usize| {
        let (a, b) = (sides(&cs[ring[k]], v).0, sides(&cs[ring[(k + 1) % n]], v).1);
        format!("{} | {}", facets[a], facets[b])
    };
    match open.len() {
        1 => {}
        0 => {
            return Err(cx.err(
                format!("{field}.type"),
                format!("every sector around extendable vertex \"{id}\" is closed by one facet, so new creases have nowhere to go; make it \"terminal\" or fix the facet labels"),
            ));
        }
        k => {
            return Err(cx.err(
                "initial_graph.creases",
                format!(
                    "inconsistent facet labels around extendable vertex \"{id}\": {k} sectors are open ({}); it needs exactly one open sector, where its new creases go",
                    open.iter().map(|&s| names(s)).collect::<Vec<_>>().join("; ")
                ),
            ));
        }
    }
    // After the open sector, going ccw: [outgoing before p1 (… s3)] p1 … pm [s1 (s2) after pm].
    let first_in = rotated.iter().position(|&c| is_in(c)).unwrap_or(0);
    let last_in = rotated.iter().rposition(|&c| is_in(c)).unwrap_or(0);
    if rotated[first_in..=last_in].iter().any(|&c| !is_in(c)) {
        return Err(cx.err(
            "initial_graph.creases",
            format!("at extendable vertex \"{id}\" an outgoing crease lies between incoming ones; its incoming creases must be adjacent (rotation p1 … pm s1 s2 s3)"),
        ));
    }
    let after_gap = &rotated[..first_in];
    let preds = rotated[first_in..=last_in].to_vec();
    let before_gap = &rotated[last_in + 1..];
    let mut slots = [None; 3];
    for (k, &c) in before_gap.iter().enumerate() {
        slots[k] = Some(c);
    }
    for (k, &c) in after_gap.iter().rev().enumerate() {
        slots[2 - k] = Some(c);
    }
    let vx = &mut vs[v];
    vx.ring = preds
        .iter()
        .chain(slots.iter().flatten())
        .copied()
        .collect();
    vx.preds = preds;
    vx.slots = slots;
    Ok(())
}

fn mirror_map(
    cx: &Ctx<'_>,
    vs: &[InitialVertex],
    cs: &[InitialCrease],
    facets: &[String],
    tol: f64,
) -> Result<MirrorMap, TaskError> {
    let field = "symmetry.mirror_xz";
    let mut vertex = Vec::with_capacity(vs.len());
    for v in vs {
        let m = vs
            .iter()
            .position(|u| (u.xy[0] - v.xy[0]).abs() <= tol && (u.xy[1] + v.xy[1]).abs() <= tol);
        let Some(m) = m else {
            return Err(cx.err(
                field,
                format!("G0 is not symmetric about the x-axis: no vertex at the mirror position ({}, {}) of \"{}\"", v.xy[0], -v.xy[1], v.id),
            ));
        };
        if vs[m].ty != v.ty {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: \"{}\" and its mirror image \"{}\" have different types",
                    v.id, vs[m].id
                ),
            ));
        }
        vertex.push(m);
    }
    let mut facet = vec![usize::MAX; facets.len()];
    for c in cs {
        let Some(m) = cs
            .iter()
            .find(|d| d.tail == vertex[c.tail] && d.head == vertex[c.head])
        else {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: crease {} → {} has no mirror image",
                    vs[c.tail].id, vs[c.head].id
                ),
            ));
        };
        if c.drive != m.drive {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: crease {} → {} and its mirror image have different drives",
                    vs[c.tail].id, vs[c.head].id
                ),
            ));
        }
        // Mirroring swaps left and right.
        for (f, g) in [(c.left, m.right), (c.right, m.left)] {
            if facet[f] != usize::MAX && facet[f] != g {
                return Err(cx.err(
                    field,
                    format!("G0's facet labels are not mirror-symmetric: facet {} maps to both {} and {}", facets[f], facets[facet[f]], facets[g]),
                ));
            }
            facet[f] = g;
        }
    }
    Ok(MirrorMap { vertex, facet })
}
