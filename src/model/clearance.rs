//! Clearance constraints as separating planes (issue 12).
//!
//! Two convex sets are at least `G` apart exactly when a plane separates them with `G/2`
//! on each side: for a unit normal `n` and offset `d`,
//! `n·x_a − d ≥ G/2` for every vertex `a` of one piece and `d − n·x_b ≥ G/2` for every
//! vertex `b` of the other. Every constraint is linear in the vertex positions, which are
//! smooth functions of the design variables (the compiled kinematics), so each is as
//! smooth as the model itself — what L-BFGS needs — and exact for convex pieces: a facet
//! is kept clear through its convex hull (conservative for the few non-convex facets).
//!
//! The planes of the pairs near contact are optimization variables next to the design's
//! (unit normal `n = v/|v|` from a free `v`, and `d`), so the optimizer tilts a plane and
//! moves the facets together; a plane is (re)fitted when its pair comes within reach, and
//! between outer iterations of the augmented Lagrangian when a better one exists (the
//! max-margin plane: the min-norm point of the Minkowski difference by the
//! Gilbert–Johnson–Keerthi iteration, or the best separating axis when the pieces
//! overlap). Whatever plane is
//! used, satisfying its constraints proves the clearance.
//!
//! Every pair of pieces falls under one rule:
//! - facets sharing no vertex ([`PairKind::Apart`]): distance ≥ `clearance`;
//! - facets meeting at a point ([`PairKind::Cone`]): a vertex they share, or, for a
//!   two-armed task whose arms grip the target together, the midpoint of the two tips
//!   (they meet there at the target). The plane passes through that apex and every other
//!   vertex keeps `n·(x − apex) ≥ (G/2)|x − apex|`, so the facets' cones at the apex are
//!   an angle `2 asin(G/2)` apart (a chord of at least G at unit distance from it); the
//!   two tips themselves, within the target's tolerance of their midpoint, only keep to
//!   their sides (`±n·(x − apex) ≥ 0`, smooth where the angular form has a kink);
//! - facets sharing a crease: its fold angle stays `2 asin(G/2)` short of ±π (the model's
//!   crease constraints, not here);
//! - a facet and a convex obstacle piece ([`PairKind::Obstacle`], see [`obstacle`]): its
//!   support points inflated by a radius (a cylinder: the capsule of radius
//!   `r + obstacle_clearance` around the axis segment, which contains the finite cylinder;
//!   a sphere: its centre; a box: its corners; a mesh: each triangle): the facet's
//!   vertices at `n·x ≥ d`, the piece's points at `n·x ≤ d − (r + obstacle_clearance)`.
//!
//! With `n` copies of the arm (issue 31), the arm is kept clear of copies `1..=n/2` (the
//! pair of copies i and j is the arm and copy `j − i` turned) and every copy's facets of
//! every obstacle piece the copy's rotation does not map onto itself.
//!
//! Scaling: with `F` facets there are `O(F²)` pairs (doubled for the rotated copy of a
//! two-armed task, halved again by its symmetry) and each contributes one constraint per
//! vertex of its two facets at each sampled state. Far pairs cost only a bounding-sphere
//! test per state: they get no plane and no constraints until they come within reach.

pub mod copies;
pub mod obstacle;

pub use copies::{CopyMap, copy_point};
pub use obstacle::Convex;

use crate::geom::{V3, add, cross, dot, norm, scale, sub};
use crate::model::plan::{Plan, Position};

/// A vertex of the arm (`copy = 0`) or of one of its rotated copies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VRef {
    /// Dense vertex index of the arm.
    pub vertex: usize,
    /// Which copy: 0 the arm, `k` the arm turned by `2πk/n`.
    pub copy: usize,
}

/// The positions of one state: the arm's vertices, their copies, and a bounding sphere of
/// every facet (arm, then each copy).
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Arm vertex positions.
    pub x: Vec<V3>,
    /// Copy k's vertices at `(k − 1)·n_vertices..`.
    copies: Vec<V3>,
    spheres: Vec<(V3, f64)>,
}

impl Scene {
    /// Refill from the arm's vertex positions.
    pub fn set(&mut self, x: &[V3], pairs: &Pairs) {
        let map = &pairs.copies;
        self.x.clear();
        self.x.extend_from_slice(x);
        self.copies.clear();
        for k in 1..map.n() {
            self.copies.extend(x.iter().map(|p| map.point(k, *p)));
        }
        self.spheres.clear();
        for (_, vs) in &pairs.facets {
            let c = scale(
                vs.iter().fold([0.0; 3], |s, v| add(s, x[*v])),
                1.0 / vs.len() as f64,
            );
            let r = vs.iter().map(|v| norm(sub(x[*v], c))).fold(0.0, f64::max);
            self.spheres.push((c, r));
        }
        let n = self.spheres.len();
        for k in 1..map.n() {
            for f in 0..n {
                let (c, r) = self.spheres[f];
                self.spheres.push((map.point(k, c), r));
            }
        }
    }

    /// Position of a vertex reference.
    pub fn at(&self, r: VRef) -> V3 {
        if r.copy == 0 {
            self.x[r.vertex]
        } else {
            self.copies[(r.copy - 1) * self.x.len() + r.vertex]
        }
    }

    /// The bounding sphere of facet `facet` (index into [`Pairs::facets`]) of copy `copy`.
    pub fn sphere(&self, facet: usize, copy: usize, n_facets: usize) -> (V3, f64) {
        self.spheres[facet + copy * n_facets]
    }
}

/// Which clearance a pair belongs to (the robustness record reports each separately).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Group {
    /// Two facets of the arm.
    SelfPair,
    /// A facet of the arm and one of a rotated copy.
    Arm,
    /// A facet and an obstacle.
    Obstacle,
}

/// How a pair is kept apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PairKind {
    /// No shared vertex: a plane `n·x = d` with the pieces on either side.
    Apart,
    /// Meeting at the apex `(x_a + x_b)/2` (a shared vertex has `a = b`): a plane through it.
    Cone {
        /// One vertex defining the apex.
        a: VRef,
        /// The other.
        b: VRef,
    },
    /// Facet and convex obstacle piece `k` ([`Pairs::obstacles`]), inflated by its radius.
    Obstacle {
        /// Index of the piece.
        k: usize,
        /// Number of its support points.
        points: usize,
    },
}

/// A pair of pieces with its constraint slots.
#[derive(Clone, Debug)]
pub struct Pair {
    /// Index into [`Pairs::facets`] of the first piece and which copy it is on.
    pub a: (usize, usize),
    /// The second facet (`None` for an obstacle).
    pub b: Option<(usize, usize)>,
    /// Kind of separation.
    pub kind: PairKind,
    /// Which clearance it counts toward.
    pub group: Group,
    /// Vertices of the first piece that get a constraint (a shared apex left out).
    pub a_verts: Vec<VRef>,
    /// Vertices of the second piece.
    pub b_verts: Vec<VRef>,
    /// Index of the pair's first slot: one per vertex of A, then of B (for an obstacle,
    /// one per support point: a cylinder's two axis ends).
    pub slot: usize,
}

impl Pair {
    /// Number of constraint slots.
    pub fn slots(&self) -> usize {
        self.a_verts.len()
            + match self.kind {
                PairKind::Obstacle { points, .. } => points,
                _ => self.b_verts.len(),
            }
    }

    /// Whether its plane has an offset `d` (cones pass through their apex).
    pub fn has_offset(&self) -> bool {
        !matches!(self.kind, PairKind::Cone { .. })
    }

    /// How much of the gap `g` each side needs from the plane: half each between facets,
    /// all of it on the obstacle's side.
    fn sides(&self, g: f64) -> (f64, f64) {
        match self.kind {
            PairKind::Obstacle { .. } => (0.0, g),
            _ => (0.5 * g, 0.5 * g),
        }
    }

    fn apex(&self, s: &Scene) -> V3 {
        match self.kind {
            PairKind::Cone { a, b } => scale(add(s.at(a), s.at(b)), 0.5),
            _ => [0.0; 3],
        }
    }
}

/// A fitted separating plane, `A` on its positive side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub n: V3,
    /// Offset (for an obstacle: the support of the axis ends; unused for cones, whose
    /// plane passes through the apex).
    pub d: f64,
}

/// All pairs of a plan for a task's settings.
#[derive(Clone, Debug)]
pub struct Pairs {
    /// The facets with at least three vertices: (plan facet index, vertex list).
    pub facets: Vec<(usize, Vec<usize>)>,
    /// The pairs.
    pub pairs: Vec<Pair>,
    /// Total number of slots.
    pub slots: usize,
    /// The convex obstacle pieces.
    pub obstacles: Vec<Convex>,
    /// The copies of the arm.
    pub copies: CopyMap,
}

/// An arm vertex.
fn arm(v: usize) -> VRef {
    VRef { vertex: v, copy: 0 }
}

/// The vertices `vs` but `skip`, as references by `r`.
fn without(vs: &[usize], skip: usize, r: impl Fn(usize) -> VRef) -> Vec<VRef> {
    vs.iter().copied().filter(|u| *u != skip).map(r).collect()
}

/// The arm vertex that copy `k` of vertex `j` coincides with, if any: both are fixed and
/// the rotation maps one onto the other (v1 at the origin for the gripper), so the arms
/// share it, as in `check::two_armed`.
fn copy_is(plan: &Plan, map: &CopyMap, k: usize, j: usize) -> Option<usize> {
    let fixed = |v: usize| match plan.vertices[v].position {
        Position::Fixed(p) => Some(p),
        Position::Placed { .. } | Position::Between { .. } | Position::Image { .. } => None,
    };
    let q = fixed(j)?;
    (0..plan.vertices.len()).find(|&i| fixed(i).is_some_and(|p| map.merges(k, q, p)))
}

/// The pairs built so far and the next free slot.
struct PairList {
    pairs: Vec<Pair>,
    slot: usize,
}

impl PairList {
    fn push(
        &mut self,
        a: (usize, usize),
        b: Option<(usize, usize)>,
        kind: PairKind,
        group: Group,
        a_verts: Vec<VRef>,
        b_verts: Vec<VRef>,
    ) {
        let p = Pair {
            a,
            b,
            kind,
            group,
            a_verts,
            b_verts,
            slot: self.slot,
        };
        self.slot += p.slots();
        self.pairs.push(p);
    }

    /// The arm's facet pairs: apart, or meeting at a vertex.
    fn self_pairs(&mut self, facets: &[(usize, Vec<usize>)]) {
        for (i, (_, va)) in facets.iter().enumerate() {
            for (j, (_, vb)) in facets.iter().enumerate().skip(i + 1) {
                let shared: Vec<usize> = va.iter().copied().filter(|v| vb.contains(v)).collect();
                match shared.as_slice() {
                    [] => self.push(
                        (i, 0),
                        Some((j, 0)),
                        PairKind::Apart,
                        Group::SelfPair,
                        va.iter().map(|v| arm(*v)).collect(),
                        vb.iter().map(|v| arm(*v)).collect(),
                    ),
                    [v] => self.push(
                        (i, 0),
                        Some((j, 0)),
                        PairKind::Cone {
                            a: arm(*v),
                            b: arm(*v),
                        },
                        Group::SelfPair,
                        without(va, *v, arm),
                        without(vb, *v, arm),
                    ),
                    // Facets sharing a crease: their fold angle (the model's crease
                    // constraints). Two shared vertices without a crease do not occur in
                    // the grammar's patterns.
                    _ => {}
                }
            }
        }
    }

    /// The pairs of an arm facet and a facet of copy `k` (whose tips meet when `tip`, the
    /// gripping vertex, is given).
    fn arm_pairs(
        &mut self,
        plan: &Plan,
        map: &CopyMap,
        k: usize,
        facets: &[(usize, Vec<usize>)],
        tip: Option<usize>,
    ) {
        let cpy = |v: usize| VRef { vertex: v, copy: k };
        // For the half turn (k = n/2), (f, copy g) and (g, copy f) are the same pair turned:
        // keep f ≤ g. Other turns pair every f with every g.
        let half = 2 * k == map.n();
        for (i, (_, va)) in facets.iter().enumerate() {
            for (j, (_, vb)) in facets.iter().enumerate().skip(if half { i } else { 0 }) {
                let shared: Vec<(usize, usize)> = vb
                    .iter()
                    .filter_map(|&q| {
                        copy_is(plan, map, k, q)
                            .filter(|a| va.contains(a))
                            .map(|a| (a, q))
                    })
                    .collect();
                let tips = tip.filter(|g| va.contains(g) && vb.contains(g));
                match (shared.as_slice(), tips) {
                    ([], None) => self.push(
                        (i, 0),
                        Some((j, k)),
                        PairKind::Apart,
                        Group::Arm,
                        va.iter().map(|v| arm(*v)).collect(),
                        vb.iter().map(|v| cpy(*v)).collect(),
                    ),
                    // The tips stay in the lists: each keeps to its side of the plane
                    // (see `constraints`), or the facets cross within the tips' offset.
                    ([], Some(g)) => self.push(
                        (i, 0),
                        Some((j, k)),
                        PairKind::Cone {
                            a: arm(g),
                            b: cpy(g),
                        },
                        Group::Arm,
                        va.iter().map(|v| arm(*v)).collect(),
                        vb.iter().map(|v| cpy(*v)).collect(),
                    ),
                    ([(a, q)], None) => self.push(
                        (i, 0),
                        Some((j, k)),
                        PairKind::Cone {
                            a: arm(*a),
                            b: arm(*a),
                        },
                        Group::Arm,
                        without(va, *a, arm),
                        without(vb, *q, cpy),
                    ),
                    // Touching at two points (a shared vertex and the tips): left to
                    // the intersection check.
                    _ => {}
                }
            }
        }
    }

    /// The pairs of a facet of every copy and every convex obstacle piece.
    fn obstacle_pairs(
        &mut self,
        facets: &[(usize, Vec<usize>)],
        obstacles: &[Convex],
        map: &CopyMap,
    ) {
        for (k, piece) in obstacles.iter().enumerate() {
            let points = piece.points.len();
            for copy in 0..map.n() {
                // A copy's facets only need their own pairs when the piece is not mapped
                // onto itself by the copy's rotation.
                if copy > 0 && piece.symmetric(|p| map.point(copy, p), map.tolerance()) {
                    continue;
                }
                for (i, (_, vs)) in facets.iter().enumerate() {
                    self.push(
                        (i, copy),
                        None,
                        PairKind::Obstacle { k, points },
                        Group::Obstacle,
                        vs.iter().map(|v| VRef { vertex: *v, copy }).collect(),
                        Vec::new(),
                    );
                }
            }
        }
    }
}

impl Pairs {
    /// The pairs of `plan`: arm facets among themselves, with copies `1..=n/2` (the others
    /// are the same pairs turned; the tips of all copies meet when `tip`, the gripping
    /// vertex, is given), and of every copy's facets with every obstacle piece.
    pub fn new(plan: &Plan, copies: CopyMap, tip: Option<usize>, obstacles: Vec<Convex>) -> Pairs {
        let facets: Vec<(usize, Vec<usize>)> = plan
            .polygons
            .iter()
            .enumerate()
            .filter(|(_, (p, _))| p.len() >= 3)
            .map(|(f, (p, _))| (f, p.clone()))
            .collect();
        let mut list = PairList {
            pairs: Vec::new(),
            slot: 0,
        };
        list.self_pairs(&facets);
        for k in 1..=copies.n() / 2 {
            list.arm_pairs(plan, &copies, k, &facets, tip);
        }
        list.obstacle_pairs(&facets, &obstacles, &copies);
        Pairs {
            facets,
            pairs: list.pairs,
            slots: list.slot,
            obstacles,
            copies,
        }
    }

    /// A lower bound on the distance between the pieces of `pair` (bounding spheres), or on
    /// the angle between their cones at the apex.
    /// A mesh triangle whose bounding ball is farther than `cull` gets that ball's distance
    /// (still a lower bound) without the exact distance.
    pub fn lower_bound(&self, pair: &Pair, s: &Scene, cull: f64, buf: &mut Buffers) -> f64 {
        let nf = self.facets.len();
        match pair.kind {
            PairKind::Cone { .. } => {
                let apex = pair.apex(s);
                let cone = |vs: &[VRef]| -> Option<(V3, f64)> {
                    let mut sum = [0.0; 3];
                    for r in vs {
                        if let Some(u) = unit(sub(s.at(*r), apex)) {
                            sum = add(sum, u);
                        }
                    }
                    let axis = unit(sum)?;
                    let half = vs
                        .iter()
                        .filter_map(|r| unit(sub(s.at(*r), apex)))
                        .map(|u| dot(axis, u).clamp(-1.0, 1.0).acos())
                        .fold(0.0, f64::max);
                    Some((axis, half))
                };
                let _ = buf;
                match (cone(&pair.a_verts), cone(&pair.b_verts)) {
                    (Some((ua, ha)), Some((ub, hb))) => {
                        dot(ua, ub).clamp(-1.0, 1.0).acos() - ha - hb
                    }
                    _ => f64::NEG_INFINITY,
                }
            }
            PairKind::Obstacle { k, .. } => {
                let (c, r) = s.sphere(pair.a.0, pair.a.1, nf);
                let piece = &self.obstacles[k];
                // A mesh's triangles are many: their balls first, the exact distance only
                // for those within reach.
                if piece.hull == obstacle::Hull::Triangle {
                    let far = norm(sub(c, piece.ball.0)) - piece.ball.1 - r;
                    if far > cull {
                        return far;
                    }
                }
                piece.distance(c) - r
            }
            PairKind::Apart => {
                let (ca, ra) = s.sphere(pair.a.0, pair.a.1, nf);
                let b = pair.b.expect("apart pairs have two facets");
                let (cb, rb) = s.sphere(b.0, b.1, nf);
                norm(sub(ca, cb)) - ra - rb
            }
        }
    }
}

fn unit(a: V3) -> Option<V3> {
    let n = norm(a);
    (n > 1e-12).then(|| scale(a, 1.0 / n))
}

/// Reusable point buffers for fits.
#[derive(Clone, Debug, Default)]
pub struct Buffers {
    a: Vec<V3>,
    b: Vec<V3>,
    u: Vec<V3>,
}

/// Fill `buf` with the points of `pair`'s pieces (A's vertices; B's, or the axis ends) and,
/// for cones, the directions from the apex (A's, then B's reversed).
fn points(pair: &Pair, s: &Scene, obstacles: &[Convex], buf: &mut Buffers) -> V3 {
    buf.a.clear();
    buf.b.clear();
    buf.u.clear();
    buf.a.extend(pair.a_verts.iter().map(|r| s.at(*r)));
    match pair.kind {
        PairKind::Obstacle { k, .. } => buf.b.extend_from_slice(&obstacles[k].points),
        _ => buf.b.extend(pair.b_verts.iter().map(|r| s.at(*r))),
    }
    let apex = pair.apex(s);
    if let PairKind::Cone { .. } = pair.kind {
        for p in &buf.a {
            if let Some(u) = unit(sub(*p, apex)) {
                buf.u.push(u);
            }
        }
        for p in &buf.b {
            if let Some(u) = unit(sub(*p, apex)) {
                buf.u.push(scale(u, -1.0));
            }
        }
    }
    apex
}

/// The gap along unit `n`: `min_a n·a − max_b n·b` (apart, obstacle), or the smallest
/// elevation `min n·u` of the cone directions (cones).
fn gap_along(kind: PairKind, n: V3, buf: &Buffers) -> f64 {
    match kind {
        PairKind::Cone { .. } => buf
            .u
            .iter()
            .map(|u| dot(n, *u))
            .fold(f64::INFINITY, f64::min),
        _ => {
            let lo = buf
                .a
                .iter()
                .map(|p| dot(n, *p))
                .fold(f64::INFINITY, f64::min);
            let hi = buf
                .b
                .iter()
                .map(|p| dot(n, *p))
                .fold(f64::NEG_INFINITY, f64::max);
            lo - hi
        }
    }
}

/// The point of the affine hull of `w` (1 to 4 points) nearest the origin, with its
/// barycentric coordinates, or `None` when the points are affinely dependent.
fn affine_nearest(w: &[V3]) -> Option<(V3, [f64; 4])> {
    let k = w.len() - 1;
    let e: Vec<V3> = (1..=k).map(|i| sub(w[i], w[0])).collect();
    // Gram system G μ = −[e_i · w_0].
    let mut g = [[0.0; 3]; 3];
    let mut r = [0.0; 3];
    for i in 0..k {
        for j in 0..k {
            g[i][j] = dot(e[i], e[j]);
        }
        r[i] = -dot(e[i], w[0]);
    }
    let mu: [f64; 3] = match k {
        0 => [0.0; 3],
        1 => {
            if g[0][0] <= 1e-300 {
                return None;
            }
            [r[0] / g[0][0], 0.0, 0.0]
        }
        2 => {
            let det = g[0][0] * g[1][1] - g[0][1] * g[1][0];
            if det.abs() <= 1e-14 * (g[0][0] * g[1][1]).max(1e-300) {
                return None;
            }
            [
                (r[0] * g[1][1] - g[0][1] * r[1]) / det,
                (g[0][0] * r[1] - r[0] * g[1][0]) / det,
                0.0,
            ]
        }
        _ => {
            let det = |m: &[[f64; 3]; 3]| {
                m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                    - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                    + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
            };
            let d = det(&g);
            if d.abs() <= 1e-14 * (g[0][0] * g[1][1] * g[2][2]).max(1e-300) {
                return None;
            }
            let mut mu = [0.0; 3];
            for (c, m) in mu.iter_mut().enumerate() {
                let mut gc = g;
                for row in 0..3 {
                    gc[row][c] = r[row];
                }
                *m = det(&gc) / d;
            }
            mu
        }
    };
    let mut p = w[0];
    let mut bary = [0.0; 4];
    bary[0] = 1.0 - mu[..k].iter().sum::<f64>();
    for i in 0..k {
        p = add(p, scale(e[i], mu[i]));
        bary[i + 1] = mu[i];
    }
    Some((p, bary))
}

/// The point of the convex hull of `w` (1 to 4 points) nearest the origin, and the smallest
/// subset of `w` it lies in (the GJK distance sub-algorithm, by enumeration of the subsets).
fn nearest_in_simplex(w: &[V3]) -> (V3, Vec<V3>) {
    let n = w.len();
    let mut best: Option<(f64, V3, Vec<V3>)> = None;
    for mask in 1..(1u32 << n) {
        let sub_w: Vec<V3> = (0..n)
            .filter(|i| mask >> i & 1 == 1)
            .map(|i| w[i])
            .collect();
        let Some((p, bary)) = affine_nearest(&sub_w) else {
            continue;
        };
        if bary[..sub_w.len()].iter().any(|b| *b < -1e-12) {
            continue;
        }
        let d = dot(p, p);
        if best.as_ref().is_none_or(|(bd, _, bw)| {
            d < bd - 1e-15 * (1.0 + bd) || (d <= bd + 1e-15 * (1.0 + bd) && sub_w.len() < bw.len())
        }) {
            best = Some((d, p, sub_w));
        }
    }
    match best {
        Some((_, p, s)) => (p, s),
        None => (w[0], vec![w[0]]),
    }
}

/// The min-norm point of the convex hull of a point set given by its support mapping
/// (`support(z)` = the point minimizing `z·p`), by the Gilbert–Johnson–Keerthi iteration
/// from the set's point `start`: finitely many steps, each adding the support point to a
/// simplex and keeping the face nearest the origin. Returns the origin (up to rounding)
/// when the hull contains it.
fn min_norm_point(support: impl Fn(V3) -> V3, start: V3, iters: usize, tol: f64) -> V3 {
    let mut w = vec![start];
    let mut z = start;
    for _ in 0..iters {
        let zz = dot(z, z);
        if zz <= 1e-24 {
            break;
        }
        let s = support(z);
        if zz - dot(z, s) <= tol * zz {
            break;
        }
        if w.iter().any(|p| dot(sub(*p, s), sub(*p, s)) <= 1e-24) {
            break;
        }
        w.push(s);
        let (p, keep) = nearest_in_simplex(&w);
        z = p;
        w = keep;
        if w.len() == 4 {
            // A full tetrahedron keeps its nearest point inside: the origin.
            break;
        }
    }
    z
}

fn argmin_dot(pts: &[V3], d: V3) -> &V3 {
    let mut best = &pts[0];
    let mut v = dot(d, *best);
    for p in &pts[1..] {
        let w = dot(d, *p);
        if w < v {
            v = w;
            best = p;
        }
    }
    best
}

/// How hard [`fit_plane`] tries.
#[derive(Clone, Copy, Debug)]
pub struct Effort {
    /// Keep the previous plane, without searching, when its gap is at least this.
    pub enough: f64,
    /// Iterations of the min-norm point search.
    pub iters: usize,
    /// Its relative stopping tolerance (duality gap).
    pub tol: f64,
    /// Try the separating axes (facet normals, cross products of edges) when the pieces
    /// seem to overlap.
    pub axes: bool,
}

/// Fit a separating plane for `pair`: the best of the previous plane, the max-margin
/// direction and (with `effort.axes`, when those leave the pieces overlapping) the
/// separating axes of the two pieces. Returns the plane and its gap along the normal
/// (elevation for cones).
#[allow(clippy::too_many_arguments)]
pub fn fit_plane(
    pair: &Pair,
    s: &Scene,
    obstacles: &[Convex],
    previous: Option<Plane>,
    need: f64,
    effort: Effort,
    buf: &mut Buffers,
) -> (Plane, f64) {
    let apex = points(pair, s, obstacles, buf);
    let buf = &*buf;
    // The offset that leaves both sides the same slack over what they need.
    let offset = |n: V3| {
        if !pair.has_offset() {
            return 0.0;
        }
        let (ga, gb) = pair.sides(need);
        let lo = buf
            .a
            .iter()
            .map(|p| dot(n, *p))
            .fold(f64::INFINITY, f64::min);
        let hi = buf
            .b
            .iter()
            .map(|p| dot(n, *p))
            .fold(f64::NEG_INFINITY, f64::max);
        0.5 * (lo - ga + hi + gb)
    };
    if let Some(p) = previous {
        let g = gap_along(pair.kind, p.n, buf);
        if g >= effort.enough {
            return (
                Plane {
                    n: p.n,
                    d: offset(p.n),
                },
                g,
            );
        }
    }
    let mut best: Option<(V3, f64)> = None;
    let consider = |best: &mut Option<(V3, f64)>, n: V3| {
        if let Some(n) = unit(n) {
            let g = gap_along(pair.kind, n, buf);
            if best.is_none_or(|(_, bg)| g > bg) {
                *best = Some((n, g));
            }
        }
    };
    if let Some(p) = previous {
        consider(&mut best, p.n);
    }
    let cone = matches!(pair.kind, PairKind::Cone { .. });
    if cone {
        // The plane through the apex with the largest smallest elevation is the direction
        // of the min-norm point of the directions' hull.
        if !buf.u.is_empty() {
            let mean = buf.u.iter().fold([0.0; 3], |s, p| add(s, *p));
            let start = *argmin_dot(&buf.u, scale(mean, -1.0));
            let z = min_norm_point(|d| *argmin_dot(&buf.u, d), start, effort.iters, effort.tol);
            consider(&mut best, z);
        }
    } else {
        // The Minkowski difference A − B; its support is A's minimizer minus B's maximizer.
        let support = |d: V3| {
            let neg = scale(d, -1.0);
            sub(*argmin_dot(&buf.a, d), *argmin_dot(&buf.b, neg))
        };
        let ca = buf.a.iter().fold([0.0; 3], |s, p| add(s, *p));
        let cb = buf.b.iter().fold([0.0; 3], |s, p| add(s, *p));
        let start = support(scale(sub(ca, cb), -1.0));
        let z = min_norm_point(support, start, effort.iters, effort.tol);
        consider(&mut best, z);
    }
    if effort.axes && best.is_none_or(|(_, g)| g <= 0.0) {
        // Overlapping (or touching): the best of the separating axes, which for convex
        // pieces includes a separating one whenever they are disjoint.
        let edges = |pts: &[V3]| -> Vec<V3> {
            let mut all: Vec<V3> = pts.to_vec();
            if cone {
                all.push(apex);
            }
            let m = all.len();
            (0..m)
                .flat_map(|i| (i + 1..m).map(move |j| (i, j)))
                .map(|(i, j)| sub(all[j], all[i]))
                .collect()
        };
        let ea = edges(&buf.a);
        let eb = edges(&buf.b);
        for e in &ea {
            for f in &eb {
                let c = cross(*e, *f);
                consider(&mut best, c);
                consider(&mut best, scale(c, -1.0));
            }
        }
        for es in [&ea, &eb] {
            for i in 0..es.len() {
                for j in i + 1..es.len() {
                    let c = cross(es[i], es[j]);
                    consider(&mut best, c);
                    consider(&mut best, scale(c, -1.0));
                }
            }
        }
    }
    let (n, gap) = best.unwrap_or(([0.0, 0.0, 1.0], f64::NEG_INFINITY));
    (Plane { n, d: offset(n) }, gap)
}

/// One constraint of a pair: its value (`h ≥ 0` required) and gradient.
#[derive(Clone, Copy, Debug)]
pub struct Slot<'a> {
    /// Index of the slot.
    pub slot: usize,
    /// The constraint's value.
    pub h: f64,
    /// `∂h/∂x` for the vertices it involves.
    pub dx: &'a [(VRef, V3)],
    /// `∂h/∂n` (the plane's unit normal).
    pub dn: V3,
    /// `∂h/∂d` (the plane's offset).
    pub dd: f64,
}

/// Visit every constraint of `pair` with plane `plane` in scene `s` for the required gap
/// `gap` (an obstacle piece's support points taken from `obstacles`).
pub fn constraints(
    pair: &Pair,
    plane: &Plane,
    gap: f64,
    s: &Scene,
    obstacles: &[Convex],
    mut visit: impl FnMut(Slot<'_>),
) {
    let n = plane.n;
    let (ga, gb) = pair.sides(gap);
    match pair.kind {
        PairKind::Apart | PairKind::Obstacle { .. } => {
            for (k, r) in pair.a_verts.iter().enumerate() {
                let p = s.at(*r);
                visit(Slot {
                    slot: pair.slot + k,
                    h: dot(n, p) - plane.d - ga,
                    dx: &[(*r, n)],
                    dn: p,
                    dd: -1.0,
                });
            }
            let m = scale(n, -1.0);
            let base = pair.slot + pair.a_verts.len();
            if let PairKind::Obstacle { k, .. } = pair.kind {
                for (j, p) in obstacles[k].points.iter().copied().enumerate() {
                    visit(Slot {
                        slot: base + j,
                        h: plane.d - dot(n, p) - gb,
                        dx: &[],
                        dn: scale(p, -1.0),
                        dd: 1.0,
                    });
                }
            } else {
                for (k, r) in pair.b_verts.iter().enumerate() {
                    let p = s.at(*r);
                    visit(Slot {
                        slot: base + k,
                        h: plane.d - dot(n, p) - gb,
                        dx: &[(*r, m)],
                        dn: scale(p, -1.0),
                        dd: 1.0,
                    });
                }
            }
        }
        PairKind::Cone { a, b } => {
            let apex = pair.apex(s);
            for (k, r) in pair.a_verts.iter().chain(&pair.b_verts).enumerate() {
                let sign = if k < pair.a_verts.len() { 1.0 } else { -1.0 };
                let d = sub(s.at(*r), apex);
                // A tip of a gripper's two arms (the apex is their midpoint) only keeps to
                // its side, `±n·d ≥ 0`: its offset d from the apex vanishes on every design
                // that meets its target, where the angular gap `(G/2)|d|` has its kink.
                // With every other vertex strictly inside its cone, each facet stays in its
                // closed half-space: they can touch at the tips, never cross.
                let (h, g) = if *r == a || *r == b {
                    (sign * dot(n, d), scale(n, sign))
                } else {
                    let len = norm(d);
                    let inv = if len > 0.0 { 1.0 / len } else { 0.0 };
                    (
                        sign * dot(n, d) - ga * len,
                        [
                            sign * n[0] - ga * d[0] * inv,
                            sign * n[1] - ga * d[1] * inv,
                            sign * n[2] - ga * d[2] * inv,
                        ],
                    )
                };
                let m = scale(g, -0.5);
                visit(Slot {
                    slot: pair.slot + k,
                    h,
                    dx: &[(*r, g), (a, m), (b, m)],
                    dn: scale(d, sign),
                    dd: 0.0,
                });
            }
        }
    }
}
