//! The plan of a model: everything about one crease-pattern graph that does not depend on
//! numbers or symbols, precomputed once (dense indices, ray orders, how each sector and
//! position is expressed, the order in which facets get their rigid maps).
//!
//! Evaluation ([`super::geometry`]) walks the plan generically over [`crate::kinematics::Scalar`].

use crate::grammar::{ConstraintSpec, CreaseGraph, CreaseOrigin, VarKind, VertexType};
use crate::kinematics::DriveExpr;
use std::collections::HashMap;
use std::fmt;

/// How a vertex's in-plane position is given.
#[derive(Clone, Debug, PartialEq)]
pub enum Position {
    /// Fixed coordinates (initial graph).
    Fixed([f64; 2]),
    /// Placed by r1 (Eq. 28): `x = x_parent + l · (cos θ, sin θ)`,
    /// `θ = angle(parent → reference) + sign · Σ sectors`.
    Placed {
        /// The vertex r1 extended.
        parent: usize,
        /// The vertex the angle is measured from.
        reference: usize,
        /// +1 counter-clockwise, −1 clockwise.
        sign: f64,
        /// Sector variables summed into the angle.
        sectors: Vec<usize>,
        /// Length variable.
        length: usize,
        /// The crease parent → this vertex.
        crease: usize,
    },
    /// An r2′ sink: the midpoint of the segment between two vertices (its predecessors),
    /// so that the two creases into it form one straight crease.
    Between {
        /// One end (the predecessor of the replaced c1).
        a: usize,
        /// The other end (the predecessor of c2).
        b: usize,
    },
    /// The image of vertex `source` under the pattern's symmetry `element`
    /// ([`Plan::isometries`]): `x = g(x_source)`.
    Image {
        /// The orbit's representative.
        source: usize,
        /// Index into [`Plan::isometries`].
        element: usize,
        /// The image of the source's placing crease, when it is this vertex's (its
        /// direction is the image of the source's exact placement angle): its tail and
        /// the crease.
        parent: Option<(usize, usize)>,
    },
}

impl Position {
    /// The vertex and crease that place this vertex along an exact angle (r1's placement
    /// or its image).
    pub fn placed_from(&self) -> Option<(usize, usize)> {
        match self {
            Position::Placed { parent, crease, .. } => Some((*parent, *crease)),
            Position::Image { parent, .. } => *parent,
            _ => None,
        }
    }
}

/// One crease leaving a vertex, seen from that vertex.
#[derive(Clone, Debug, PartialEq)]
pub struct Ray {
    /// The crease.
    pub crease: usize,
    /// The vertex at the other end.
    pub other: usize,
    /// Whether the crease leaves this vertex (tail here).
    pub outgoing: bool,
}

/// How the sector between two consecutive rays is computed.
#[derive(Clone, Debug, PartialEq)]
pub enum Sector {
    /// `Σ coefficient · variable`: both rays are measured from the same reference.
    Linear(Vec<(f64, usize)>),
    /// Between two fixed creases of the initial graph.
    Constant(f64),
    /// `2π −` the other sectors of the vertex (the sector s2 → s3, Eq. 29's u3).
    Remainder,
    /// From the in-plane coordinates: the counter-clockwise angle between the rays,
    /// `atan2(u × v, u · v)`, valid while the sector lies in (0, π) (Eq. 34–35).
    Geometric,
    /// Equal to sector `k` of vertex `vertex`, whose image this vertex is.
    Image {
        /// The orbit's representative.
        vertex: usize,
        /// Its sector.
        k: usize,
    },
}

/// A vertex of the plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Vertex {
    /// 1-based name (position in the vertex list).
    pub name: usize,
    /// In-plane position.
    pub position: Position,
    /// Rays counter-clockwise: incoming creases p1 … pm, then slots s1, s2, s3.
    pub rays: Vec<Ray>,
    /// Number of incoming creases (m).
    pub preds: usize,
    /// Whether r1 extended it.
    pub internal: bool,
    /// `sectors[k]` lies between `rays[k]` and `rays[k + 1]` (cyclic for internal
    /// vertices; only between consecutive incoming creases otherwise).
    pub sectors: Vec<Sector>,
}

/// A crease of the plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Crease {
    /// Tail vertex.
    pub tail: usize,
    /// Head vertex.
    pub head: usize,
    /// Facet on the left of tail → head.
    pub left: usize,
    /// Facet on the right.
    pub right: usize,
    /// Driving angle, for driven creases of the initial graph.
    pub drive: Option<DriveExpr>,
    /// For creases r1 made: the length variable, and whether the head is still the
    /// vertex placed with it (otherwise r2 moved it and the length is measured, Eq. 35).
    pub length: Option<(usize, bool)>,
}

/// One step of the facet walk: facet `facet` gets the map of `from` composed with the
/// rotation about ray `ray` of vertex `vertex` by that crease's dihedral angle.
#[derive(Clone, Debug, PartialEq)]
pub struct WalkStep {
    /// The facet that gets its map.
    pub facet: usize,
    /// The facet clockwise of the ray (already known).
    pub from: usize,
    /// The vertex walked around.
    pub vertex: usize,
    /// Index into that vertex's rays.
    pub ray: usize,
}

/// A cycle closed by r2′: the sink `vertex` on the straight crease `ends[0]` → sink ←
/// `ends[1]`, folded by both ends' PTU (thesis Sec. 5.7, Fig. 52b).
#[derive(Clone, Debug, PartialEq)]
pub struct Sink {
    /// The sink.
    pub vertex: usize,
    /// The two ends (internal vertices), p1 and p2.
    pub ends: [usize; 2],
    /// The creases p1 → sink and p2 → sink.
    pub creases: [usize; 2],
    /// The facet the two creases closed (right of p1 → sink).
    pub inner: usize,
    /// The merged facet on the far side (left of p1 → sink).
    pub outer: usize,
}

/// A design variable.
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    /// Sector angle or length.
    pub kind: VarKind,
    /// Readable name (`α_5`, `l_2,5`).
    pub name: String,
}

/// A constraint `g ≥ 0`, as the model states it.
#[derive(Clone, Debug, PartialEq)]
pub enum Constraint {
    /// `sector − α_min ≥ 0` (lower) or `α_max − sector ≥ 0` (upper) for sector `k` at
    /// `vertex` (Eq. 31, 34).
    Sector {
        /// Dense vertex index.
        vertex: usize,
        /// Sector index at that vertex.
        k: usize,
        /// Lower (`true`) or upper bound.
        lower: bool,
        /// Which equation of the thesis it comes from (for reports).
        source: &'static str,
    },
    /// `length − l_min ≥ 0` or `l_max − length ≥ 0` for a crease r2 moved (Eq. 35).
    Length {
        /// Dense crease index.
        crease: usize,
        /// Lower or upper bound.
        lower: bool,
    },
    /// `U_j + U_k − U_i ≥ 0` at t_max (Eq. 33): margin `i` of `vertex`.
    Rigid {
        /// Dense vertex index.
        vertex: usize,
        /// Which of the three margins.
        i: usize,
    },
}

/// A plan could not be built from a graph.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlanError(pub String);

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for PlanError {}

/// The actuation of the initial graph: one driven line folded mirror-symmetrically (SPEC
/// §4: the facet left of it turns by +ρ/2 about it, the facet right of it by −ρ/2), or a
/// fixed facet whose driven neighbours turn about their creases (a driven central facet,
/// thesis Sec. 3.4, 4.3).
#[derive(Clone, Debug, PartialEq)]
pub struct Actuation {
    /// A driven crease (the first): for the symmetric fold, the line it turns about.
    pub crease: usize,
    /// The facet that stays fixed, if any (else the fold about `crease` is symmetric).
    pub fixed: Option<usize>,
    /// Every driven crease.
    pub driven: Vec<usize>,
}

/// Everything about one graph that the model needs, with dense indices.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The rule sequence (`2, 3, (4, 8)`).
    pub sequence: String,
    /// Vertices in name order.
    pub vertices: Vec<Vertex>,
    /// Creases.
    pub creases: Vec<Crease>,
    /// Number of facets.
    pub facets: usize,
    /// Facet names (as in the graph).
    pub facet_names: Vec<String>,
    /// Each facet's polygon, counter-clockwise in the flat state, and whether its
    /// boundary closes through creases alone (otherwise the paper's edge closes it).
    pub polygons: Vec<(Vec<usize>, bool)>,
    /// Internal vertices in the order r1 extended them.
    pub internal: Vec<usize>,
    /// The actuation.
    pub actuation: Actuation,
    /// Facet walk, in evaluation order.
    pub walk: Vec<WalkStep>,
    /// For every vertex, a facet containing it (its 3D position is read from there).
    pub home_facet: Vec<usize>,
    /// All variables the rules introduced (some may end up unused).
    pub variables: Vec<Variable>,
    /// Constraints `g ≥ 0` (box bounds of plain variables are not listed).
    pub constraints: Vec<Constraint>,
    /// The three successors of the vertex extended last (gripping candidates).
    pub candidates: Option<[usize; 3]>,
    /// The cycles r2′ closed (empty for the thesis's acyclic grammar).
    pub sinks: Vec<Sink>,
    /// The pattern's symmetries (the identity first; only it without a symmetry).
    pub isometries: Vec<crate::task::Isometry>,
    /// For every vertex: its orbit's representative and the element taking it there.
    pub orbit: Vec<(usize, usize)>,
    /// The order in which vertex positions are computed (an image after its source, a
    /// placed vertex after its parent and reference).
    pub position_order: Vec<usize>,
    /// For every internal vertex (as in [`Plan::internal`]): the mode parameter it folds
    /// by. An image folds by its representative's mode, under a reflection too: each
    /// vertex's PTU reads its own creases counter-clockwise, so the mirrored vertex with
    /// the same mode is the mirror image of the folded representative (the paper's normal
    /// is kept by a reflection in its plane; `tests/pattern_families.rs` checks it).
    pub modes: Vec<usize>,
    /// Number of mode parameters: one per extended orbit (per internal vertex without a
    /// symmetry, or with [`Plan::with_vertex_modes`]).
    pub n_modes: usize,
}

impl Plan {
    /// Build the plan of `graph`.
    pub fn new(graph: &CreaseGraph) -> Result<Plan, PlanError> {
        Builder::new(graph)?.build(graph)
    }

    /// Dense index of the vertex named `name` (1-based).
    pub fn vertex_by_name(&self, name: usize) -> Option<usize> {
        self.vertices.iter().position(|v| v.name == name)
    }

    /// Sectors of vertex `v` that bound a facet (all of them for internal vertices).
    pub fn sector_count(&self, v: usize) -> usize {
        self.vertices[v].sectors.len()
    }

    /// The mode of every internal vertex (in the order of [`Plan::internal`]) from the
    /// mode parameters.
    pub fn vertex_modes<S: crate::kinematics::Scalar>(&self, modes: &[S]) -> Vec<S> {
        self.modes.iter().map(|&k| modes[k].clone()).collect()
    }

    /// The same plan with one mode parameter per internal vertex (images no longer fold
    /// like their representative: the star pattern's 2^8 assignments, Sec. 4.3.2).
    pub fn with_vertex_modes(mut self) -> Plan {
        self.modes = (0..self.internal.len()).collect();
        self.n_modes = self.internal.len();
        self
    }

    /// Whether the pattern has a symmetry.
    pub fn is_symmetric(&self) -> bool {
        self.isometries.len() > 1
    }
}

/// Dense index maps from the graph's stable ids.
struct Builder {
    vix: HashMap<crate::grammar::Vid, usize>,
    cix: HashMap<crate::grammar::Cid, usize>,
}

impl Builder {
    fn new(graph: &CreaseGraph) -> Result<Builder, PlanError> {
        let vix = graph
            .vertex_ids()
            .iter()
            .enumerate()
            .map(|(i, v)| (*v, i))
            .collect();
        let cix = graph
            .creases()
            .enumerate()
            .map(|(i, c)| (c.cid, i))
            .collect();
        Ok(Builder { vix, cix })
    }

    fn v(&self, id: crate::grammar::Vid) -> Result<usize, PlanError> {
        self.vix
            .get(&id)
            .copied()
            .ok_or_else(|| PlanError(format!("vertex {id:?} is not in the graph")))
    }

    fn c(&self, id: crate::grammar::Cid) -> Result<usize, PlanError> {
        self.cix
            .get(&id)
            .copied()
            .ok_or_else(|| PlanError(format!("crease {id:?} is not in the graph")))
    }

    fn build(&self, graph: &CreaseGraph) -> Result<Plan, PlanError> {
        let (creases, actuation) = self.creases(graph)?;
        let mut vertices = Vec::new();
        for v in graph.vertices() {
            let position = self.position(graph, v, &creases)?;
            self.v(v.vid)?;
            let rays = self.rays(v, &creases)?;
            vertices.push(Vertex {
                name: vertices.len() + 1,
                position,
                preds: v.preds.len(),
                internal: v.extended,
                rays,
                sectors: Vec::new(),
            });
        }
        for i in 0..vertices.len() {
            let sectors = sector_rules(&vertices, &creases, i)?;
            vertices[i].sectors = sectors;
        }
        for i in 0..vertices.len() {
            if let Some(image) = self.image_sectors(graph, &vertices, i)? {
                vertices[i].sectors = image;
            }
        }
        let position_order = position_order(&vertices)?;
        let facets = graph.facet_count();
        let polygons = facet_polygons(&creases, facets)?;
        let internal: Vec<usize> = graph
            .extension_order()
            .iter()
            .map(|v| self.v(*v))
            .collect::<Result<_, _>>()?;
        let (walk, known) = facet_walk(&vertices, &creases, &internal, &actuation, facets)?;
        if let Some(f) = known.iter().position(|k| !k)
            && polygons[f].0.len() >= 2
        {
            return Err(PlanError(format!(
                "facet {} cannot be placed: none of its creases has a known dihedral angle",
                graph.facet_name(crate::grammar::FacetId(f as u32))
            )));
        }
        let home_facet = home_facets(&polygons, &known, vertices.len())?;
        let variables = graph
            .variables()
            .iter()
            .map(|v| Variable {
                kind: v.kind,
                name: v.name.clone(),
            })
            .collect();
        let constraints = self.constraints(graph, &vertices, &creases)?;
        let sinks = sinks(&vertices, &creases)?;
        let candidates = match graph.gripping_candidates() {
            Some(c) => Some([self.v(c[0])?, self.v(c[1])?, self.v(c[2])?]),
            None => None,
        };
        let isometries = graph.group().map_or_else(
            || vec![crate::task::Isometry::identity()],
            |g| g.elements.clone(),
        );
        let orbit = graph
            .vertex_ids()
            .iter()
            .map(|&v| {
                let (r, g) = graph.orbit_source(v);
                Ok((self.v(r)?, g))
            })
            .collect::<Result<Vec<_>, PlanError>>()?;
        let (modes, n_modes) = self.modes(graph)?;
        Ok(Plan {
            sequence: graph.sequence(),
            vertices,
            creases,
            facets,
            facet_names: (0..facets)
                .map(|f| {
                    graph
                        .facet_name(crate::grammar::FacetId(f as u32))
                        .to_string()
                })
                .collect(),
            polygons,
            internal,
            actuation,
            walk,
            home_facet,
            variables,
            constraints,
            candidates,
            sinks,
            isometries,
            orbit,
            position_order,
            modes,
            n_modes,
        })
    }

    /// Every internal vertex's mode parameter.
    fn modes(&self, graph: &CreaseGraph) -> Result<(Vec<usize>, usize), PlanError> {
        let mut out = Vec::new();
        let mut n = 0;
        for &v in graph.extension_order() {
            let (slot, _) = graph.mode_slot(v).ok_or_else(|| {
                PlanError(format!(
                    "the extended vertex {v:?} has no mode of its orbit"
                ))
            })?;
            out.push(slot);
            n = n.max(slot + 1);
        }
        Ok((out, n))
    }

    /// For an image vertex, each sector as the representative's sector it is the image
    /// of (a reflection reverses the order of the rays); `None` for other vertices.
    fn image_sectors(
        &self,
        graph: &CreaseGraph,
        vertices: &[Vertex],
        i: usize,
    ) -> Result<Option<Vec<Sector>>, PlanError> {
        let Position::Image {
            source, element, ..
        } = vertices[i].position
        else {
            return Ok(None);
        };
        let ids = graph.vertex_ids();
        let (vi, vj) = (&vertices[i], &vertices[source]);
        if vi.rays.len() != vj.rays.len() || vi.sectors.len() != vj.sectors.len() {
            return Ok(None);
        }
        let n = vi.rays.len();
        let mut map = Vec::with_capacity(n);
        for r in &vi.rays {
            let k = vj
                .rays
                .iter()
                .position(|q| graph.image_of(ids[q.other], element) == ids[r.other])
                .ok_or_else(|| {
                    PlanError(format!(
                        "v{} is not the image of v{}: a crease has no counterpart",
                        vi.name, vj.name
                    ))
                })?;
            map.push(k);
        }
        let reflects = graph.group().is_some_and(|g| g.reflects(element));
        let mut out = Vec::with_capacity(vi.sectors.len());
        for k in 0..vi.sectors.len() {
            let (a, b) = (map[k], map[(k + 1) % n]);
            let src = if reflects { b } else { a };
            let next = if reflects { a } else { b };
            if (src + 1) % n != next || src >= vj.sectors.len() {
                return Err(PlanError(format!(
                    "v{}'s sector {k} has no counterpart at v{}",
                    vi.name, vj.name
                )));
            }
            out.push(Sector::Image {
                vertex: source,
                k: src,
            });
        }
        Ok(Some(out))
    }

    /// The creases with dense indices, and the one driven crease.
    fn creases(&self, graph: &CreaseGraph) -> Result<(Vec<Crease>, Actuation), PlanError> {
        let mut creases = Vec::new();
        let mut driven = Vec::new();
        for (i, c) in graph.creases().enumerate() {
            let (drive, length) = match &c.origin {
                CreaseOrigin::Initial { drive, .. } => {
                    let drive = match drive {
                        Some(d) => {
                            driven.push(i);
                            Some(d.expr().clone())
                        }
                        None => None,
                    };
                    (drive, None)
                }
                CreaseOrigin::Extension {
                    length, created, ..
                } => (None, Some((length.0 as usize, *created == c.head))),
            };
            creases.push(Crease {
                tail: self.v(c.tail)?,
                head: self.v(c.head)?,
                left: c.left.0 as usize,
                right: c.right.0 as usize,
                drive,
                length,
            });
        }
        let Some(&first) = driven.first() else {
            return Err(PlanError("the initial graph has no driven crease".into()));
        };
        let fixed = match graph.initial_graph().actuation {
            crate::task::G0Actuation::Split { .. } => None,
            crate::task::G0Actuation::Fixed { facet } => {
                // The facet every driven crease bounds (facet ids may have moved since G0,
                // names do not). Both of a single driven side's facets bound it: then the
                // one the task names.
                let c = &creases[first];
                let bounding: Vec<usize> = [c.left, c.right]
                    .into_iter()
                    .filter(|f| {
                        driven
                            .iter()
                            .all(|&i| creases[i].left == *f || creases[i].right == *f)
                    })
                    .collect();
                let named = &graph.initial_graph().facets[facet];
                match bounding.as_slice() {
                    [f] => Some(*f),
                    [..] => bounding
                        .iter()
                        .copied()
                        .find(|&f| graph.facet_name(crate::grammar::FacetId(f as u32)) == named)
                        .map(Some)
                        .ok_or_else(|| {
                            PlanError(format!(
                                "the driven creases no longer bound the fixed facet \"{named}\""
                            ))
                        })?,
                }
            }
        };
        if fixed.is_none() && driven.len() > 1 {
            let c = &creases[first];
            // A side split at its midpoint has halves pointing away from each other: the
            // same two facets, left and right traded.
            let between = |i: usize| {
                let (l, r) = (creases[i].left, creases[i].right);
                (l, r) == (c.left, c.right) || (r, l) == (c.left, c.right)
            };
            if !driven.iter().all(|&i| between(i)) {
                return Err(PlanError(
                    "driven creases folded symmetrically must lie between the same two facets"
                        .into(),
                ));
            }
        }
        let actuation = Actuation {
            crease: first,
            fixed,
            driven,
        };
        Ok((creases, actuation))
    }

    /// How vertex `v` of `graph` is positioned in the plane.
    fn position(
        &self,
        graph: &CreaseGraph,
        v: &crate::grammar::Vertex,
        creases: &[Crease],
    ) -> Result<Position, PlanError> {
        Ok(match (&v.placement, v.g0_coords) {
            (Some(p), _) => {
                let crease = graph
                    .creases()
                    .position(|c| matches!(c.origin, CreaseOrigin::Extension { created, .. } if created == v.vid))
                    .ok_or_else(|| PlanError(format!("no crease placed vertex {:?}", v.vid)))?;
                Position::Placed {
                    parent: self.v(p.parent)?,
                    reference: self.v(p.reference)?,
                    sign: p.sign,
                    sectors: p.sectors.iter().map(|s| s.0 as usize).collect(),
                    length: p.length.0 as usize,
                    crease,
                }
            }
            (None, Some(xy)) => Position::Fixed(xy),
            (None, None) if v.sink_between.is_some() => {
                let [a, b] = v.sink_between.expect("checked");
                Position::Between {
                    a: self.v(a)?,
                    b: self.v(b)?,
                }
            }
            (None, None) if graph.orbit_source(v.vid).0 != v.vid => {
                let (src, g) = graph.orbit_source(v.vid);
                let source = self.v(src)?;
                let me = self.v(v.vid)?;
                let sv = graph
                    .vertex(src)
                    .ok_or_else(|| PlanError(format!("vertex {src:?} is not in the graph")))?;
                // The image of the source's placing crease, if it ends here.
                let parent = match &sv.placement {
                    Some(p) => {
                        let tail = self.v(graph.image_of(p.parent, g))?;
                        creases
                            .iter()
                            .position(|c| c.tail == tail && c.head == me)
                            .map(|c| (tail, c))
                    }
                    None => None,
                };
                Position::Image {
                    source,
                    element: g,
                    parent,
                }
            }
            (None, None) => {
                return Err(PlanError(format!("vertex {:?} has no position", v.vid)));
            }
        })
    }

    /// The rays of vertex `v`: its incoming creases, then (once extended, or for a
    /// terminal vertex) its slots.
    fn rays(&self, v: &crate::grammar::Vertex, creases: &[Crease]) -> Result<Vec<Ray>, PlanError> {
        let mut rays = Vec::new();
        for &c in &v.preds {
            let k = self.c(c)?;
            rays.push(Ray {
                crease: k,
                other: creases[k].tail,
                outgoing: false,
            });
        }
        if v.extended || v.ty == VertexType::Terminal {
            for c in v.slots.iter().flatten() {
                let k = self.c(*c)?;
                rays.push(Ray {
                    crease: k,
                    other: creases[k].head,
                    outgoing: true,
                });
            }
        }
        Ok(rays)
    }

    /// The constraints the graph states, in the plan's terms (box bounds of plain
    /// variables left out, duplicates in a row merged).
    fn constraints(
        &self,
        graph: &CreaseGraph,
        vertices: &[Vertex],
        creases: &[Crease],
    ) -> Result<Vec<Constraint>, PlanError> {
        let mut constraints = Vec::new();
        for spec in graph.constraints() {
            match spec {
                ConstraintSpec::Sector {
                    vertex, from, to, ..
                } => {
                    let (v, k) = self.sector_index(vertices, vertex, from, to)?;
                    if !is_plain_variable(&vertices[v].sectors[k]) {
                        sector_bounds(&mut constraints, v, k, "Eq. 31");
                    }
                }
                ConstraintSpec::Remainder { vertex, from, to } => {
                    let (v, k) = self.sector_index(vertices, vertex, from, to)?;
                    // Eq. 31 bounds the closing sector from below only; we bound it from
                    // above too: a sector beyond π makes a unit angle > π, outside the
                    // Euler triangles the PTU's triangle inequality is valid for (Sec. 4.4).
                    sector_bounds(&mut constraints, v, k, "Eq. 31");
                }
                ConstraintSpec::MergedSector { vertex, from, to } => {
                    let (v, k) = self.sector_index(vertices, vertex, from, to)?;
                    sector_bounds(&mut constraints, v, k, "Eq. 34");
                }
                ConstraintSpec::Length { crease, .. } => {
                    let c = self.c(crease)?;
                    if let Some((_, false)) = creases[c].length {
                        for lower in [true, false] {
                            constraints.push(Constraint::Length { crease: c, lower });
                        }
                    }
                }
                ConstraintSpec::RigidFoldability { vertex } => {
                    let v = self.v(vertex)?;
                    for i in 0..3 {
                        constraints.push(Constraint::Rigid { vertex: v, i });
                    }
                }
            }
        }
        constraints.dedup();
        Ok(constraints)
    }

    /// The sector at `vertex` from crease `from` to crease `to` (counter-clockwise).
    fn sector_index(
        &self,
        vertices: &[Vertex],
        vertex: crate::grammar::Vid,
        from: crate::grammar::Cid,
        to: crate::grammar::Cid,
    ) -> Result<(usize, usize), PlanError> {
        let v = self.v(vertex)?;
        let (from, to) = (self.c(from)?, self.c(to)?);
        let rays = &vertices[v].rays;
        let n = rays.len();
        (0..vertices[v].sectors.len())
            .find(|&k| rays[k].crease == from && rays[(k + 1) % n].crease == to)
            .map(|k| (v, k))
            .ok_or_else(|| PlanError(format!("v{} has no sector between those creases", v + 1)))
    }
}

/// Both bounds of sector `k` at `vertex`.
fn sector_bounds(out: &mut Vec<Constraint>, vertex: usize, k: usize, source: &'static str) {
    for lower in [true, false] {
        out.push(Constraint::Sector {
            vertex,
            k,
            lower,
            source,
        });
    }
}

/// The facet walk: around each internal vertex in extension order, from a facet with a
/// known placement counter-clockwise, each facet not yet placed gets its map. Returns the
/// walk and which facets it placed (the actuated crease's two facets to begin with).
fn facet_walk(
    vertices: &[Vertex],
    creases: &[Crease],
    internal: &[usize],
    actuation: &Actuation,
    facets: usize,
) -> Result<(Vec<WalkStep>, Vec<bool>), PlanError> {
    let mut known = vec![false; facets];
    for &c in &actuation.driven {
        known[creases[c].left] = true;
        known[creases[c].right] = true;
    }
    let mut walk = Vec::new();
    for &a in internal {
        let v = &vertices[a];
        let n = v.rays.len();
        let ccw_facet = |k: usize| {
            let r = &v.rays[k];
            let c = &creases[r.crease];
            if r.outgoing { c.left } else { c.right }
        };
        let start = (0..n).find(|&k| known[ccw_facet(k)]).ok_or_else(|| {
            PlanError(format!("no facet around v{} has a known placement", v.name))
        })?;
        for j in 1..n {
            let k = (start + j) % n;
            let f = ccw_facet(k);
            if !known[f] {
                walk.push(WalkStep {
                    facet: f,
                    from: ccw_facet((k + n - 1) % n),
                    vertex: a,
                    ray: k,
                });
                known[f] = true;
            }
        }
    }
    Ok((walk, known))
}

/// For every vertex, the first placed facet (by index) whose polygon contains it.
fn home_facets(
    polygons: &[(Vec<usize>, bool)],
    known: &[bool],
    n_vertices: usize,
) -> Result<Vec<usize>, PlanError> {
    let mut home_facet = vec![usize::MAX; n_vertices];
    for (f, (poly, _)) in polygons.iter().enumerate() {
        for &v in poly {
            if home_facet[v] == usize::MAX && known[f] {
                home_facet[v] = f;
            }
        }
    }
    if let Some(v) = home_facet.iter().position(|f| *f == usize::MAX) {
        return Err(PlanError(format!(
            "vertex v{} lies on no placed facet",
            v + 1
        )));
    }
    Ok(home_facet)
}

/// The cycles r2′ closed: every vertex placed between two others, with the creases from
/// its two ends.
fn sinks(vertices: &[Vertex], creases: &[Crease]) -> Result<Vec<Sink>, PlanError> {
    let mut sinks = Vec::new();
    for (i, v) in vertices.iter().enumerate() {
        if let Position::Between { a, b } = v.position {
            let (c1, c2) = (v.rays[0].crease, v.rays[1].crease);
            if creases[c1].tail != a || creases[c2].tail != b {
                return Err(PlanError(format!(
                    "the sink v{} is not fed by its two ends",
                    v.name
                )));
            }
            sinks.push(Sink {
                vertex: i,
                ends: [a, b],
                creases: [c1, c2],
                inner: creases[c1].right,
                outer: creases[c1].left,
            });
        }
    }
    Ok(sinks)
}

/// An order of the vertices in which every position is computed after those it is
/// computed from.
fn position_order(vertices: &[Vertex]) -> Result<Vec<usize>, PlanError> {
    let deps = |v: &Vertex| -> Vec<usize> {
        match &v.position {
            Position::Fixed(_) => Vec::new(),
            Position::Placed {
                parent, reference, ..
            } => vec![*parent, *reference],
            Position::Between { a, b } => vec![*a, *b],
            Position::Image { source, .. } => vec![*source],
        }
    };
    let n = vertices.len();
    let mut state = vec![0u8; n]; // 0 new, 1 on the stack, 2 done
    let mut order = Vec::with_capacity(n);
    for root in 0..n {
        let mut stack = vec![(root, false)];
        while let Some((v, expanded)) = stack.pop() {
            if expanded {
                state[v] = 2;
                order.push(v);
                continue;
            }
            match state[v] {
                2 => continue,
                1 => {
                    return Err(PlanError(format!(
                        "the position of v{} depends on itself",
                        vertices[v].name
                    )));
                }
                _ => {}
            }
            state[v] = 1;
            stack.push((v, true));
            for d in deps(&vertices[v]) {
                if state[d] == 1 {
                    return Err(PlanError(format!(
                        "the position of v{} depends on itself",
                        vertices[v].name
                    )));
                }
                if state[d] == 0 {
                    stack.push((d, false));
                }
            }
        }
    }
    Ok(order)
}

/// A sector that is exactly one variable (its bounds are the variable's box).
fn is_plain_variable(s: &Sector) -> bool {
    matches!(s, Sector::Linear(t) if t.len() == 1 && t[0].0 == 1.0)
}

/// The angular recipe of a ray: its angle relative to a reference ray, when known
/// symbolically (`sign · Σ vars` from the ray to `reference`).
fn recipe(
    vertices: &[Vertex],
    creases: &[Crease],
    v: usize,
    ray: &Ray,
) -> (usize, Vec<(f64, usize)>) {
    let c = &creases[ray.crease];
    if ray.outgoing
        && let Some((_, true)) = c.length
        && let Position::Placed {
            parent,
            reference,
            sign,
            sectors,
            ..
        } = &vertices[c.head].position
        && *parent == v
    {
        return (*reference, sectors.iter().map(|s| (*sign, *s)).collect());
    }
    (ray.other, Vec::new())
}

/// How each sector of vertex `i` is computed.
fn sector_rules(
    vertices: &[Vertex],
    creases: &[Crease],
    i: usize,
) -> Result<Vec<Sector>, PlanError> {
    let v = &vertices[i];
    let n = v.rays.len();
    let count = if v.internal {
        n
    } else if v.preds >= 2 {
        v.preds - 1
    } else if matches!(v.position, Position::Fixed(_)) && n >= 2 {
        n - 1
    } else {
        0
    };
    if let Position::Between { .. } = v.position {
        // The straight crease through an r2′ sink: its sector is a straight angle.
        return Ok(vec![Sector::Constant(std::f64::consts::PI); count]);
    }
    let fixed = |u: usize| matches!(vertices[u].position, Position::Fixed(_));
    let mut out = Vec::with_capacity(count);
    for k in 0..count {
        let (a, b) = (&v.rays[k], &v.rays[(k + 1) % n]);
        if v.internal && k == v.preds + 1 {
            out.push(Sector::Remainder);
            continue;
        }
        let (ra, ta) = recipe(vertices, creases, i, a);
        let (rb, tb) = recipe(vertices, creases, i, b);
        if ra == rb {
            // Both measured from the same reference: the difference of the two sums,
            // with a common prefix cancelled.
            let mut terms: Vec<(f64, usize)> = tb.clone();
            for t in &ta {
                if let Some(p) = terms.iter().position(|u| u == t) {
                    terms.remove(p);
                } else {
                    terms.push((-t.0, t.1));
                }
            }
            out.push(Sector::Linear(terms));
        } else if fixed(i) && fixed(a.other) && fixed(b.other) {
            let (Position::Fixed(o), Position::Fixed(p), Position::Fixed(q)) = (
                &vertices[i].position,
                &vertices[a.other].position,
                &vertices[b.other].position,
            ) else {
                unreachable!("checked fixed above")
            };
            let (u, w) = ([p[0] - o[0], p[1] - o[1]], [q[0] - o[0], q[1] - o[1]]);
            let mut ang = (u[0] * w[1] - u[1] * w[0]).atan2(u[0] * w[0] + u[1] * w[1]);
            if ang <= 0.0 {
                ang += 2.0 * std::f64::consts::PI;
            }
            out.push(Sector::Constant(ang));
        } else {
            out.push(Sector::Geometric);
        }
    }
    Ok(out)
}

/// Each facet's polygon: the chain of its creases walked with the facet on the left
/// (tail → head for creases it lies left of, head → tail otherwise), closed by the
/// paper's edge when the chain is open.
fn facet_polygons(creases: &[Crease], facets: usize) -> Result<Vec<(Vec<usize>, bool)>, PlanError> {
    let mut next: Vec<HashMap<usize, usize>> = vec![HashMap::new(); facets];
    for c in creases {
        for (f, from, to) in [(c.left, c.tail, c.head), (c.right, c.head, c.tail)] {
            if next[f].insert(from, to).is_some() {
                return Err(PlanError(format!(
                    "facet {f} leaves a vertex twice along its boundary"
                )));
            }
        }
    }
    let mut out = Vec::with_capacity(facets);
    for (f, map) in next.iter().enumerate() {
        if map.is_empty() {
            out.push((Vec::new(), false));
            continue;
        }
        let heads: std::collections::HashSet<usize> = map.values().copied().collect();
        let mut starts: Vec<usize> = map.keys().filter(|k| !heads.contains(k)).copied().collect();
        starts.sort_unstable();
        let closed = starts.is_empty();
        let start = if closed {
            *map.keys().min().expect("non-empty")
        } else {
            starts[0]
        };
        if starts.len() > 1 {
            return Err(PlanError(format!("facet {f}'s boundary is not one chain")));
        }
        let mut poly = vec![start];
        let mut cur = start;
        while let Some(&nx) = map.get(&cur) {
            if nx == start {
                break;
            }
            if poly.len() > map.len() + 1 {
                return Err(PlanError(format!("facet {f}'s boundary does not close")));
            }
            poly.push(nx);
            cur = nx;
        }
        if poly.len() != map.len() + usize::from(!closed) {
            return Err(PlanError(format!("facet {f}'s boundary is not one chain")));
        }
        out.push((poly, closed));
    }
    Ok(out)
}
