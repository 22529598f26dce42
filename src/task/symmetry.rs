//! The symmetry of a pattern (`[symmetry] rotations`, `center`, `mirror_axis`): a finite
//! group of isometries of the plane that maps G0 onto itself (thesis Sec. 4.3: the rigid
//! flasher and the star repeat four times about the central facet, the chair is its own
//! mirror image). The grammar grows one representative of every orbit and its images
//! follow (`grammar::symmetric`).
//!
//! Not to be confused with `mirror_xz`, which says the *task* is symmetric about the
//! xz-plane, so that a graph and its mirror image are the same design (a filter).

use super::initial::InitialGraph;
use super::{Ctx, TaskError, VertexType};

/// Largest order of rotational symmetry accepted.
pub const MAX_ROTATIONS: usize = 12;

/// A plane isometry `x ↦ m x + c`: a rotation by `theta` (`reflects` false) or the
/// reflection about a line at angle `theta / 2` followed by a translation (`reflects`
/// true).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Isometry {
    /// The linear part.
    pub m: [[f64; 2]; 2],
    /// The translation.
    pub c: [f64; 2],
    /// Whether it reverses orientation.
    pub reflects: bool,
    /// Rotation angle, or twice the mirror line's angle.
    pub theta: f64,
}

impl Isometry {
    /// The identity.
    pub fn identity() -> Isometry {
        Isometry::linear(false, 0.0, [0.0, 0.0])
    }

    fn linear(reflects: bool, theta: f64, c: [f64; 2]) -> Isometry {
        let (s, co) = theta.sin_cos();
        let m = if reflects {
            [[co, s], [s, -co]]
        } else {
            [[co, -s], [s, co]]
        };
        Isometry {
            m,
            c,
            reflects,
            theta,
        }
    }

    /// The rotation by `theta` about `center`.
    pub fn rotation(center: [f64; 2], theta: f64) -> Isometry {
        let r = Isometry::linear(false, theta, [0.0, 0.0]);
        let rc = r.apply(center);
        Isometry::linear(false, theta, [center[0] - rc[0], center[1] - rc[1]])
    }

    /// The reflection about the line through `p` and `q`.
    pub fn reflection(p: [f64; 2], q: [f64; 2]) -> Isometry {
        let phi = (q[1] - p[1]).atan2(q[0] - p[0]);
        let r = Isometry::linear(true, 2.0 * phi, [0.0, 0.0]);
        let rp = r.apply(p);
        Isometry::linear(true, 2.0 * phi, [p[0] - rp[0], p[1] - rp[1]])
    }

    /// The image of point `p`.
    pub fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        [
            self.m[0][0] * p[0] + self.m[0][1] * p[1] + self.c[0],
            self.m[1][0] * p[0] + self.m[1][1] * p[1] + self.c[1],
        ]
    }

    /// The direction angle of the image of a direction at angle `a`.
    pub fn angle(&self, a: f64) -> f64 {
        if self.reflects {
            self.theta - a
        } else {
            a + self.theta
        }
    }

    /// `self ∘ other` (first `other`, then `self`).
    pub fn then_after(&self, other: &Isometry) -> Isometry {
        let c = self.apply(other.c);
        let reflects = self.reflects != other.reflects;
        let theta = match (self.reflects, other.reflects) {
            (false, false) | (false, true) => self.theta + other.theta,
            (true, false) => self.theta - other.theta,
            (true, true) => self.theta - other.theta,
        };
        let theta = theta.rem_euclid(std::f64::consts::TAU);
        Isometry::linear(reflects, theta, c)
    }

    fn close_to(&self, o: &Isometry, tol: f64) -> bool {
        self.reflects == o.reflects
            && (0..2).all(|i| (self.c[i] - o.c[i]).abs() <= tol)
            && (0..2).all(|i| (0..2).all(|j| (self.m[i][j] - o.m[i][j]).abs() <= 1e-9))
    }
}

/// The symmetry group of a pattern with its action on G0.
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    /// The elements; `elements[0]` is the identity.
    pub elements: Vec<Isometry>,
    /// `mul[a][b]`: the index of `elements[a] ∘ elements[b]`.
    pub mul: Vec<Vec<usize>>,
    /// `vertex[g][v]`: the G0 vertex at the image of G0 vertex `v`.
    pub vertex: Vec<Vec<usize>>,
    /// `crease[g][c]`: the image of G0 crease `c` (directions kept).
    pub crease: Vec<Vec<usize>>,
    /// `facet[g][f]`: the image of G0 facet `f`.
    pub facet: Vec<Vec<usize>>,
    /// The order of the rotations (1: none).
    pub rotations: usize,
    /// The centre of rotation.
    pub center: [f64; 2],
    /// The mirror axis, as two points, if the pattern is its own mirror image.
    pub mirror_axis: Option<[[f64; 2]; 2]>,
}

impl Group {
    /// Number of elements.
    pub fn order(&self) -> usize {
        self.elements.len()
    }

    /// The inverse of element `g`.
    pub fn inverse(&self, g: usize) -> usize {
        (0..self.order())
            .find(|&h| self.mul[g][h] == 0)
            .expect("a group has inverses")
    }

    /// Whether element `g` reverses orientation.
    pub fn reflects(&self, g: usize) -> bool {
        self.elements[g].reflects
    }

    /// The G0 vertex standing for the orbit of G0 vertex `v`: the first of its images in
    /// file order, and the element taking that representative to `v`.
    pub fn g0_source(&self, v: usize) -> (usize, usize) {
        let rep = (0..self.order())
            .map(|g| self.vertex[g][v])
            .min()
            .expect("the identity");
        let g = (0..self.order())
            .find(|&g| self.vertex[g][rep] == v)
            .expect("v is in rep's orbit");
        (rep, g)
    }

    /// As [`Group::g0_source`] for a G0 crease.
    pub fn g0_crease_source(&self, c: usize) -> (usize, usize) {
        let rep = (0..self.order())
            .map(|g| self.crease[g][c])
            .min()
            .expect("the identity");
        let g = (0..self.order())
            .find(|&g| self.crease[g][rep] == c)
            .expect("c is in rep's orbit");
        (rep, g)
    }
}

/// The symmetry as the task file gives it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PatternSymmetry {
    /// Order of rotational symmetry (1: none).
    pub rotations: usize,
    /// The centre of rotation (default: the centroid of G0's vertices).
    pub center: Option<[f64; 2]>,
    /// Two points of the mirror axis.
    pub mirror_axis: Option<[[f64; 2]; 2]>,
}

impl PatternSymmetry {
    /// Whether the pattern has a symmetry.
    pub fn any(&self) -> bool {
        self.rotations > 1 || self.mirror_axis.is_some()
    }
}

/// The group `sym` generates, with its action on `g` (positions within `tol`), or why G0
/// is not symmetric under it.
pub(crate) fn group(
    cx: &Ctx<'_>,
    g: &InitialGraph,
    sym: &PatternSymmetry,
    tol: f64,
) -> Result<Group, TaskError> {
    let vs = &g.vertices;
    let centroid = {
        let k = vs.len() as f64;
        [
            vs.iter().map(|v| v.xy[0]).sum::<f64>() / k,
            vs.iter().map(|v| v.xy[1]).sum::<f64>() / k,
        ]
    };
    let center = sym.center.unwrap_or(centroid);
    let mut gens = Vec::new();
    if sym.rotations > 1 {
        gens.push((
            "symmetry.rotations",
            Isometry::rotation(center, std::f64::consts::TAU / sym.rotations as f64),
        ));
    }
    if let Some([p, q]) = sym.mirror_axis {
        if sym.rotations > 1 {
            let d = [q[0] - p[0], q[1] - p[1]];
            let off =
                ((center[0] - p[0]) * d[1] - (center[1] - p[1]) * d[0]).abs() / d[0].hypot(d[1]);
            if off > tol {
                return Err(cx.err(
                    "symmetry.mirror_axis",
                    format!(
                        "the mirror axis misses the centre of rotation ({}, {}) by {}: with rotations the axis must pass through the centre (otherwise the symmetries generate an infinite group)",
                        crate::text::num(center[0]),
                        crate::text::num(center[1]),
                        crate::text::num(off)
                    ),
                ));
            }
        }
        gens.push(("symmetry.mirror_axis", Isometry::reflection(p, q)));
    }
    // Close the generators under composition.
    let mut elements = vec![Isometry::identity()];
    let mut k = 0;
    while k < elements.len() {
        for (_, gn) in &gens {
            let e = gn.then_after(&elements[k]);
            if !elements.iter().any(|x| x.close_to(&e, tol)) {
                elements.push(e);
            }
        }
        k += 1;
        if elements.len() > 4 * MAX_ROTATIONS {
            return Err(cx.err("symmetry", "the symmetries generate too many elements"));
        }
    }
    let find = |e: &Isometry| elements.iter().position(|x| x.close_to(e, tol));
    let mut mul = vec![vec![0; elements.len()]; elements.len()];
    for a in 0..elements.len() {
        for b in 0..elements.len() {
            mul[a][b] = find(&elements[a].then_after(&elements[b])).ok_or_else(|| {
                cx.err(
                    "symmetry",
                    "the symmetries do not form a finite group (check the centre and the axis)",
                )
            })?;
        }
    }
    let field = gens.first().map_or("symmetry", |g| g.0);
    let mut vertex = Vec::new();
    let mut crease = Vec::new();
    let mut facet = Vec::new();
    for e in &elements {
        let (v, c, f) = action(cx, g, e, tol, field)?;
        vertex.push(v);
        crease.push(c);
        facet.push(f);
    }
    // An extendable vertex must have as many images as the group has elements: one fixed
    // by a symmetry would need an extension symmetric in itself.
    for (i, v) in vs.iter().enumerate() {
        if v.ty != VertexType::Extendable {
            continue;
        }
        if let Some(gi) = (1..elements.len()).find(|&gi| vertex[gi][i] == i) {
            return Err(cx.err(
                field,
                format!(
                    "extendable vertex \"{}\" is its own image under a symmetry ({}): an extendable vertex must lie off the mirror axis and off the centre of rotation (its extension cannot be its own image); make it terminal or move it",
                    v.id,
                    if elements[gi].reflects {
                        "the mirror"
                    } else {
                        "a rotation"
                    }
                ),
            ));
        }
    }
    let out = Group {
        elements,
        mul,
        vertex,
        crease,
        facet,
        rotations: sym.rotations.max(1),
        center,
        mirror_axis: sym.mirror_axis,
    };
    fixed_part_invariant(cx, g, &out, field)?;
    Ok(out)
}

/// The permutations of G0's vertices, creases and facets under `e`, or why it does not map
/// G0 onto itself.
#[allow(clippy::type_complexity)]
fn action(
    cx: &Ctx<'_>,
    g: &InitialGraph,
    e: &Isometry,
    tol: f64,
    field: &str,
) -> Result<(Vec<usize>, Vec<usize>, Vec<usize>), TaskError> {
    let (vs, cs) = (&g.vertices, &g.creases);
    let mut vertex = Vec::with_capacity(vs.len());
    for v in vs {
        let p = e.apply(v.xy);
        let Some(m) = vs
            .iter()
            .position(|u| (u.xy[0] - p[0]).hypot(u.xy[1] - p[1]) <= tol.max(1e-9))
        else {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: no vertex at ({}, {}), the image of \"{}\"",
                    crate::text::num(p[0]),
                    crate::text::num(p[1]),
                    v.id
                ),
            ));
        };
        if vs[m].ty != v.ty {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: \"{}\" and its image \"{}\" have different types",
                    v.id, vs[m].id
                ),
            ));
        }
        vertex.push(m);
    }
    let mut crease = Vec::with_capacity(cs.len());
    let mut facet = vec![usize::MAX; g.facets.len()];
    for c in cs {
        let Some(d) = cs
            .iter()
            .position(|d| d.tail == vertex[c.tail] && d.head == vertex[c.head])
        else {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: crease {} → {} has no image running {} → {}",
                    vs[c.tail].id, vs[c.head].id, vs[vertex[c.tail]].id, vs[vertex[c.head]].id
                ),
            ));
        };
        if cs[d].drive != c.drive {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: crease {} → {} and its image have different drives (a symmetric pattern is driven alike on every side)",
                    vs[c.tail].id, vs[c.head].id
                ),
            ));
        }
        let pairs = if e.reflects {
            [(c.left, cs[d].right), (c.right, cs[d].left)]
        } else {
            [(c.left, cs[d].left), (c.right, cs[d].right)]
        };
        for (f, h) in pairs {
            if facet[f] != usize::MAX && facet[f] != h {
                return Err(cx.err(
                    field,
                    format!(
                        "G0's facet labels are not symmetric: facet {} maps to both {} and {}",
                        g.facets[f], g.facets[facet[f]], g.facets[h]
                    ),
                ));
            }
            facet[f] = h;
        }
        crease.push(d);
    }
    Ok((vertex, crease, facet))
}

/// The symmetry must keep what the drives hold in place where it is: the fixed facet, or
/// the two facets a straight driven line folds symmetrically.
fn fixed_part_invariant(
    cx: &Ctx<'_>,
    g: &InitialGraph,
    group: &Group,
    field: &str,
) -> Result<(), TaskError> {
    use super::initial::G0Actuation;
    let held: Vec<usize> = match g.actuation {
        G0Actuation::Fixed { facet } => vec![facet],
        G0Actuation::Split { crease } => vec![g.creases[crease].left, g.creases[crease].right],
    };
    for e in 0..group.order() {
        for &f in &held {
            if !held.contains(&group.facet[e][f]) {
                return Err(cx.err(
                    field,
                    format!(
                        "a symmetry moves facet {} to {}: it must keep the facet the drives hold fixed in place (the central facet), or the pattern's motion could not be symmetric",
                        g.facets[f], g.facets[group.facet[e][f]]
                    ),
                ));
            }
        }
    }
    Ok(())
}
