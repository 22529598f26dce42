//! The crease pattern graph: storage on petgraph, accessors, the rotation around every
//! vertex, facet boundaries and semantic validity.

use std::sync::Arc;

use petgraph::Direction;
use petgraph::stable_graph::{EdgeIndex, NodeIndex, StableDiGraph};
use petgraph::visit::{Dfs, Reversed};

use super::{
    Cid, ConstraintSpec, Crease, CreaseOrigin, FacetId, StepRecord, VarId, Variable, Vertex,
    VertexType, Vid,
};
use crate::task::{InitialGraph, Task};

/// A crease pattern graph (thesis Sec. 5.1) with the history of the rules that built it.
#[derive(Clone, Debug)]
pub struct CreaseGraph {
    pub(super) init: Arc<InitialGraph>,
    pub(super) g: StableDiGraph<Vertex, Crease>,
    /// Node of every vertex id; `None` once r2 deleted it.
    pub(super) node_of: Vec<Option<NodeIndex>>,
    /// Edge of every crease id (creases are moved, never deleted).
    pub(super) edge_of: Vec<EdgeIndex>,
    /// Living vertices in name order (name = position + 1).
    pub(super) order: Vec<Vid>,
    pub(super) facet_names: Vec<String>,
    pub(super) variables: Vec<Variable>,
    pub(super) steps: Vec<StepRecord>,
    pub(super) extension_order: Vec<Vid>,
    /// Orbits under the pattern's symmetry group (`None` without one).
    pub(super) sym: Option<super::orbits::SymState>,
}

/// One ray of the rotation around a vertex.
#[derive(Clone, Copy, Debug)]
pub(super) struct Ray {
    pub cid: Cid,
    /// The sector counter-clockwise after this ray (up to the next ray) is one facet.
    pub closed_after: bool,
}

/// The darts of a graph: a dart (v, k) is ray k at v, with its facet counter-clockwise of
/// it; walking along the crease away from v keeps that facet on the left.
struct Darts {
    /// Every living vertex with its rotation.
    rings: Vec<(Vid, Vec<Ray>)>,
    /// (position in `rings`, ray index) of every dart.
    darts: Vec<(usize, usize)>,
    /// The next dart along the same facet, if the sector at the far end is closed.
    next: Vec<Option<usize>>,
    /// Whether some dart leads to this one.
    has_prev: Vec<bool>,
}

/// The boundary of one facet, counter-clockwise (the facet on the left).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FacetBoundary {
    /// The facet.
    pub facet: FacetId,
    /// Its name (`f1`, `f2`, … as in the thesis).
    pub name: String,
    /// The vertices along the boundary; for an open chain the first and last lie where the
    /// paper's edge (or a vertex not yet extended) closes the facet.
    pub vertices: Vec<Vid>,
    /// The creases between consecutive vertices (one fewer than `vertices` for an open
    /// chain, as many for a closed one).
    pub creases: Vec<Cid>,
    /// Whether the creases alone enclose the facet.
    pub closed: bool,
}

/// A facet whose labels do not form one boundary chain.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct FacetError(pub String);

impl CreaseGraph {
    /// The initial graph G0 of a task.
    pub fn initial(task: &Task) -> CreaseGraph {
        CreaseGraph::from_initial(Arc::new(task.initial.clone()))
    }

    /// The graph of a checked initial graph: G0 vertex i gets id `Vid(i)`, G0 crease j gets
    /// `Cid(j)`, G0 facet k gets `FacetId(k)`.
    pub fn from_initial(init: Arc<InitialGraph>) -> CreaseGraph {
        let mut g = StableDiGraph::new();
        let mut node_of = Vec::new();
        for (i, v) in init.vertices.iter().enumerate() {
            let cid = |k: &Option<usize>| k.map(|k| Cid(k as u32));
            let n = g.add_node(Vertex {
                vid: Vid(i as u32),
                preds: v.preds.iter().map(|&k| Cid(k as u32)).collect(),
                slots: [cid(&v.slots[0]), cid(&v.slots[1]), cid(&v.slots[2])],
                ty: v.ty,
                extended: false,
                g0: Some(i),
                g0_coords: Some(v.xy),
                placement: None,
                sink_between: None,
            });
            node_of.push(Some(n));
        }
        let mut edge_of = Vec::new();
        for (j, c) in init.creases.iter().enumerate() {
            let e = g.add_edge(
                NodeIndex::new(c.tail),
                NodeIndex::new(c.head),
                Crease {
                    cid: Cid(j as u32),
                    tail: Vid(c.tail as u32),
                    head: Vid(c.head as u32),
                    left: FacetId(c.left as u32),
                    right: FacetId(c.right as u32),
                    origin: CreaseOrigin::Initial {
                        index: j,
                        drive: c.drive.clone(),
                    },
                },
            );
            edge_of.push(e);
        }
        let sym = init.group.as_ref().map(super::orbits::SymState::of_initial);
        CreaseGraph {
            order: (0..init.vertices.len()).map(|i| Vid(i as u32)).collect(),
            facet_names: init.facets.clone(),
            init,
            g,
            node_of,
            edge_of,
            variables: Vec::new(),
            steps: Vec::new(),
            extension_order: Vec::new(),
            sym,
        }
    }

    /// The initial graph this graph grew from.
    pub fn initial_graph(&self) -> &InitialGraph {
        &self.init
    }

    /// The underlying petgraph (node weights [`Vertex`], edge weights [`Crease`]).
    pub fn petgraph(&self) -> &StableDiGraph<Vertex, Crease> {
        &self.g
    }

    /// A compact copy for petgraph algorithms that need contiguous indices (isomorphism,
    /// matrices): node `i` is the vertex named `i + 1`, weights are the stable ids.
    pub fn compact_digraph(&self) -> petgraph::graph::DiGraph<Vid, Cid> {
        let mut d = petgraph::graph::DiGraph::with_capacity(self.order.len(), self.edge_of.len());
        let mut ix = vec![None; self.node_of.len()];
        for &v in &self.order {
            ix[v.ix()] = Some(d.add_node(v));
        }
        for c in self.creases() {
            if let (Some(a), Some(b)) = (ix[c.tail.ix()], ix[c.head.ix()]) {
                d.add_edge(a, b, c.cid);
            }
        }
        d
    }

    /// The petgraph node of a living vertex.
    pub fn node_index(&self, v: Vid) -> Option<NodeIndex> {
        self.node_of.get(v.ix()).copied().flatten()
    }

    /// The petgraph edge of a crease.
    pub fn edge_index(&self, c: Cid) -> Option<EdgeIndex> {
        self.edge_of.get(c.ix()).copied()
    }

    /// A living vertex.
    pub fn vertex(&self, v: Vid) -> Option<&Vertex> {
        self.node_index(v).map(|n| &self.g[n])
    }

    pub(super) fn vx(&self, v: Vid) -> &Vertex {
        &self.g[self.node_of[v.ix()].expect("living vertex")]
    }

    pub(super) fn vx_mut(&mut self, v: Vid) -> &mut Vertex {
        let n = self.node_of[v.ix()].expect("living vertex");
        &mut self.g[n]
    }

    /// A crease.
    pub fn crease(&self, c: Cid) -> Option<&Crease> {
        self.edge_index(c).map(|e| &self.g[e])
    }

    pub(super) fn cr(&self, c: Cid) -> &Crease {
        &self.g[self.edge_of[c.ix()]]
    }

    /// The living vertices in name order (v1, v2, …).
    pub fn vertices(&self) -> impl Iterator<Item = &Vertex> + '_ {
        self.order.iter().map(|&v| self.vx(v))
    }

    /// Vertex ids in name order.
    pub fn vertex_ids(&self) -> &[Vid] {
        &self.order
    }

    /// All creases, by id.
    pub fn creases(&self) -> impl Iterator<Item = &Crease> + '_ {
        self.edge_of.iter().map(|&e| &self.g[e])
    }

    /// Number of creases.
    pub fn crease_count(&self) -> usize {
        self.edge_of.len()
    }

    /// The current 1-based name of a living vertex.
    pub fn name(&self, v: Vid) -> Option<usize> {
        self.order.iter().position(|&u| u == v).map(|p| p + 1)
    }

    /// The vertex currently named `name` (1-based).
    pub fn vid_by_name(&self, name: usize) -> Option<Vid> {
        name.checked_sub(1).and_then(|i| self.order.get(i)).copied()
    }

    /// The name of a facet (`f1`, `f2`, …).
    pub fn facet_name(&self, f: FacetId) -> &str {
        &self.facet_names[f.0 as usize]
    }

    /// Number of facets.
    pub fn facet_count(&self) -> usize {
        self.facet_names.len()
    }

    /// All variables r1 introduced, free or eliminated.
    pub fn variables(&self) -> &[Variable] {
        &self.variables
    }

    /// Whether a variable still places a living vertex (it is an optimization variable);
    /// otherwise r2 eliminated it.
    pub fn is_free(&self, var: VarId) -> bool {
        self.vertices().any(|v| {
            v.placement
                .as_ref()
                .is_some_and(|p| p.length == var || p.sectors.contains(&var))
        })
    }

    /// The rule applications, in order.
    pub fn steps(&self) -> &[StepRecord] {
        &self.steps
    }

    /// Number of rule applications (the level in the search tree).
    pub fn level(&self) -> usize {
        self.steps.len()
    }

    /// Internal vertices in the order r1 extended them.
    pub fn extension_order(&self) -> &[Vid] {
        &self.extension_order
    }

    /// Number of internal (extended) vertices N as the grammar counts them (what N_max
    /// limits, and 2^N mode assignments): with a pattern symmetry, the extended orbits
    /// (each stands for all its images); otherwise every extended vertex.
    pub fn internal_count(&self) -> usize {
        match &self.sym {
            Some(s) => self
                .extension_order
                .iter()
                .filter(|v| s.is_rep(**v))
                .count(),
            None => self.extension_order.len(),
        }
    }

    /// Number of extended vertices of the whole pattern, images included (each has its
    /// own PTU).
    pub fn extended_count(&self) -> usize {
        self.extension_order.len()
    }

    /// The vertex extended last (the mark the isomorphism filter respects); with a pattern
    /// symmetry, the representative of the orbit extended last.
    pub fn last_extended(&self) -> Option<Vid> {
        match &self.sym {
            Some(s) => self
                .extension_order
                .iter()
                .rev()
                .find(|v| s.is_rep(**v))
                .copied(),
            None => self.extension_order.last().copied(),
        }
    }

    /// The gripping candidates: the current heads of the three creases of the vertex
    /// extended last, in slot order s1, s2, s3.
    pub fn gripping_candidates(&self) -> Option<[Vid; 3]> {
        let v = self.vx(self.last_extended()?);
        let mut out = [Vid(0); 3];
        for (k, s) in v.slots.iter().enumerate() {
            out[k] = self.cr((*s)?).head;
        }
        Some(out)
    }

    /// Semantic validity (thesis Sec. 5.5.2): every internal vertex is an ancestor of a
    /// gripping candidate. A graph without an extended vertex has no gripping vertex and
    /// is not valid.
    pub fn is_semantically_valid(&self) -> bool {
        let Some(cands) = self.gripping_candidates() else {
            return false;
        };
        let rev = Reversed(&self.g);
        let mut seen = vec![false; self.node_of.len()];
        for c in cands {
            let mut dfs = Dfs::new(rev, self.node_of[c.ix()].expect("living candidate"));
            while let Some(n) = dfs.next(rev) {
                seen[self.g[n].vid.ix()] = true;
            }
        }
        // With a symmetry, an orbit is an ancestor when any of its members is.
        self.extension_order.iter().all(|v| match &self.sym {
            Some(s) => s.orbit(*v).iter().any(|u| seen[u.ix()]),
            None => seen[v.ix()],
        })
    }

    /// Number of design alternatives this graph gives: 2^N RBM assignments × its gripping
    /// candidates (3; 0 without an extended vertex).
    pub fn alternatives(&self) -> u64 {
        if self.last_extended().is_some() {
            3u64 << self.internal_count()
        } else {
            0
        }
    }

    /// The rotation around `v`, counter-clockwise from p1, with the open sectors marked.
    pub(super) fn ring(&self, v: &Vertex) -> Vec<Ray> {
        if let (Some(i), VertexType::Terminal, false) = (v.g0, v.ty, v.extended) {
            // A terminal G0 vertex never changes: its order comes from the coordinates and
            // a sector is closed where both creases name the same facet.
            let ring = &self.init.vertices[i].ring;
            let n = ring.len();
            return (0..n)
                .map(|k| {
                    let (c, d) = (Cid(ring[k] as u32), Cid(ring[(k + 1) % n] as u32));
                    Ray {
                        cid: c,
                        closed_after: self.ccw_side(v.vid, c) == self.cw_side(v.vid, d),
                    }
                })
                .collect();
        }
        let mut rays: Vec<Ray> = v
            .preds
            .iter()
            .map(|&c| Ray {
                cid: c,
                closed_after: true,
            })
            .chain(v.slots.iter().flatten().map(|&c| Ray {
                cid: c,
                closed_after: true,
            }))
            .collect();
        if !v.extended && v.sink_between.is_none() {
            // (An r2′ sink has no open sector: the straight crease closes both sides.)
            // The open sector lies where the first missing slot goes: after the ray just
            // before it (p_m when s1 is missing).
            if let Some(first_missing) = v.slots.iter().position(Option::is_none) {
                let before = v.preds.len() + v.slots[..first_missing].iter().flatten().count();
                if let Some(r) = before.checked_sub(1).and_then(|k| rays.get_mut(k)) {
                    r.closed_after = false;
                }
            }
        }
        rays
    }

    /// The facet counter-clockwise of crease `c` as seen from its end `v`.
    pub(super) fn ccw_side(&self, v: Vid, c: Cid) -> FacetId {
        let c = self.cr(c);
        if c.tail == v { c.left } else { c.right }
    }

    /// The facet clockwise of crease `c` as seen from its end `v`.
    pub(super) fn cw_side(&self, v: Vid, c: Cid) -> FacetId {
        let c = self.cr(c);
        if c.tail == v { c.right } else { c.left }
    }

    /// The other end of crease `c` seen from `v`.
    fn other(&self, v: Vid, c: Cid) -> Vid {
        let c = self.cr(c);
        if c.tail == v { c.head } else { c.tail }
    }

    /// Every facet's boundary, walked counter-clockwise; an error when the labels around a
    /// vertex disagree or a facet's creases do not form one chain.
    pub fn facet_boundaries(&self) -> Result<Vec<FacetBoundary>, FacetError> {
        let rings: Vec<(Vid, Vec<Ray>)> = self.vertices().map(|v| (v.vid, self.ring(v))).collect();
        self.check_sector_labels(&rings)?;
        let darts = self.darts(rings);
        let mut out: Vec<FacetBoundary> = Vec::new();
        for f in 0..self.facet_names.len() {
            if let Some(fb) = self.facet_boundary(&darts, FacetId(f as u32))? {
                out.push(fb);
            }
        }
        Ok(out)
    }

    /// A vertex as facet errors name it.
    fn vlabel(&self, v: Vid) -> String {
        format!("v{}", self.name(v).unwrap_or(0))
    }

    /// Labels must agree across every closed sector.
    fn check_sector_labels(&self, rings: &[(Vid, Vec<Ray>)]) -> Result<(), FacetError> {
        for (v, ring) in rings {
            let n = ring.len();
            for k in 0..n {
                let (a, b) = (ring[k], ring[(k + 1) % n]);
                if a.closed_after && self.ccw_side(*v, a.cid) != self.cw_side(*v, b.cid) {
                    return Err(FacetError(format!(
                        "at {} the sector between its creases to {} and {} is one facet but they name {} and {}",
                        self.vlabel(*v),
                        self.vlabel(self.other(*v, a.cid)),
                        self.vlabel(self.other(*v, b.cid)),
                        self.facet_name(self.ccw_side(*v, a.cid)),
                        self.facet_name(self.cw_side(*v, b.cid)),
                    )));
                }
            }
        }
        Ok(())
    }

    /// Every dart with its successor along its facet.
    fn darts(&self, rings: Vec<(Vid, Vec<Ray>)>) -> Darts {
        let pos_of = |v: Vid| rings.iter().position(|(u, _)| *u == v).expect("living");
        // Successor of a dart: at the far end w, the next ray clockwise from the arriving
        // crease, if the sector between them is closed.
        let mut darts: Vec<(usize, usize)> = Vec::new();
        let mut offset = Vec::with_capacity(rings.len());
        for (i, (_, ring)) in rings.iter().enumerate() {
            offset.push(darts.len());
            for k in 0..ring.len() {
                darts.push((i, k));
            }
        }
        let dart_ix = |i: usize, k: usize| offset[i] + k;
        let mut next: Vec<Option<usize>> = vec![None; darts.len()];
        let mut has_prev = vec![false; darts.len()];
        for (d, &(i, k)) in darts.iter().enumerate() {
            let (v, ring) = (&rings[i].0, &rings[i].1);
            let c = ring[k].cid;
            let w = self.other(*v, c);
            let j = pos_of(w);
            let wr = &rings[j].1;
            let m = wr.len();
            let at = wr
                .iter()
                .position(|r| r.cid == c)
                .expect("crease in both rings");
            let prev = (at + m - 1) % m;
            if wr[prev].closed_after {
                let e = dart_ix(j, prev);
                next[d] = Some(e);
                has_prev[e] = true;
            }
        }
        Darts {
            rings,
            darts,
            next,
            has_prev,
        }
    }

    /// The boundary of facet `f` (`None` when no crease bounds it), or why its creases do
    /// not form one chain.
    fn facet_boundary(&self, w: &Darts, f: FacetId) -> Result<Option<FacetBoundary>, FacetError> {
        let (rings, darts) = (&w.rings, &w.darts);
        let mine: Vec<usize> = (0..darts.len())
            .filter(|&d| {
                let (i, k) = darts[d];
                self.ccw_side(rings[i].0, rings[i].1[k].cid) == f
            })
            .collect();
        if mine.is_empty() {
            return Ok(None);
        }
        let starts: Vec<usize> = mine.iter().copied().filter(|&d| !w.has_prev[d]).collect();
        if starts.len() > 1 {
            return Err(FacetError(format!(
                "facet {} has {} separate boundary pieces (starting at {}); a facet's creases must form one chain",
                self.facet_name(f),
                starts.len(),
                starts
                    .iter()
                    .map(|&d| self.vlabel(rings[darts[d].0].0))
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
        let closed = starts.is_empty();
        let first = starts.first().copied().unwrap_or(mine[0]);
        let mut fb = FacetBoundary {
            facet: f,
            name: self.facet_name(f).to_owned(),
            vertices: Vec::new(),
            creases: Vec::new(),
            closed,
        };
        let mut d = first;
        loop {
            let (i, k) = darts[d];
            let (v, c) = (rings[i].0, rings[i].1[k].cid);
            fb.vertices.push(v);
            fb.creases.push(c);
            match w.next[d] {
                Some(e) if e == first => break,
                Some(e) => {
                    if fb.creases.len() > mine.len() {
                        break;
                    }
                    d = e;
                }
                None => {
                    fb.vertices.push(self.other(v, c));
                    break;
                }
            }
        }
        if fb.creases.len() != mine.len() {
            return Err(FacetError(format!(
                "facet {} is bounded by {} crease sides but its chain from {} covers {}: its creases do not form one chain",
                self.facet_name(f),
                mine.len(),
                self.vlabel(rings[darts[first].0].0),
                fb.creases.len()
            )));
        }
        Ok(Some(fb))
    }

    /// Whether crease `c` still has the direction its placement gave it (seen from `at`):
    /// incoming creases and G0 creases always do; a crease r1 created does until r2 moves
    /// it to another vertex.
    pub(super) fn as_placed(&self, at: Vid, c: Cid) -> bool {
        let cr = self.cr(c);
        match cr.origin {
            CreaseOrigin::Extension { created, .. } if cr.tail == at => cr.head == created,
            _ => true,
        }
    }

    /// The constraint set ψ of this graph (Eq. 31–35): the constraints every rule added,
    /// with a sector or length measured from the coordinates (`var: None`) where r2 moved
    /// one of its creases away from the vertex its variable placed.
    pub fn constraints(&self) -> Vec<ConstraintSpec> {
        let mut out = Vec::new();
        for s in &self.steps {
            match s {
                StepRecord::R1(r) => {
                    for c in &r.constraints {
                        out.push(match *c {
                            ConstraintSpec::Sector {
                                vertex,
                                from,
                                to,
                                var,
                            } => ConstraintSpec::Sector {
                                vertex,
                                from,
                                to,
                                var: var.filter(|_| {
                                    self.as_placed(vertex, from) && self.as_placed(vertex, to)
                                }),
                            },
                            ConstraintSpec::Length { crease, var } => ConstraintSpec::Length {
                                crease,
                                var: var.filter(|_| self.as_placed(self.cr(crease).tail, crease)),
                            },
                            ref other => other.clone(),
                        });
                    }
                }
                // r2′ closes a straight angle at its sink: nothing to bound (its Eq. 31–32
                // constraints stay on the creases' ends, measured, as for r2). An image of a
                // representative's step repeats its constraint exactly.
                StepRecord::R2(r) if r.straight.is_some() || r.image => {}
                StepRecord::R2(r) => {
                    if let ConstraintSpec::MergedSector { from, to, .. } = r.constraint {
                        out.push(ConstraintSpec::MergedSector {
                            vertex: self.cr(from).head,
                            from,
                            to,
                        });
                    }
                }
            }
        }
        out
    }

    /// The incoming creases of `v` in petgraph (unordered); [`Vertex::preds`] has the order.
    pub fn in_degree(&self, v: Vid) -> usize {
        self.node_index(v)
            .map_or(0, |n| self.g.edges_directed(n, Direction::Incoming).count())
    }

    /// Whether the graph is acyclic (petgraph's toposort).
    pub fn is_acyclic(&self) -> bool {
        petgraph::algo::toposort(&self.g, None).is_ok()
    }
}
