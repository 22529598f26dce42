//! Self-intersection of folded states (thesis Sec. 3.2.4 and 5.4.2).
//!
//! Facets are triangulated once in the flat layout. At each state:
//!
//! * **Crossing** — Möller's triangle–triangle test ([`super::tri_tri`]) between the
//!   triangles of every pair of facets. The test reports only proper crossings of the
//!   interiors, never contact, so it is applied uniformly:
//!   - facets sharing no vertex: the thesis's case;
//!   - facets sharing exactly one vertex (which the thesis does not test): the shared
//!     vertex lies on both planes, and two triangles that meet only there have intervals on
//!     the planes' common line that touch in a single point, so they are not reported,
//!     while facets that really cut into each other near the vertex (their intervals overlap
//!     along the line) are. This is exact, unlike shrinking the triangles toward their
//!     centroids (which misses shallow crossings) or skipping the triangles at the vertex
//!     (which misses crossings that start there, the typical way facets around a vertex
//!     collide);
//!   - facets sharing a crease: their triangles at the crease meet the other plane in an
//!     edge (contact, not reported); other triangles of non-convex facets are still tested.
//! * **Flip** — for facets sharing a crease, the flip test of Sec. 3.2.4 (Fig. 6). Take the
//!   vectors `u_A`, `u_B` in each facet, perpendicular to the crease and pointing away from
//!   it; with `ê` along the crease, facet A on its left in the flat layout,
//!   `ρ = atan2((u_A × u_B)·ê, −u_A·u_B)` is the crease's fold angle, valley positive (0 flat,
//!   ±π folded flat). The cross product `u_A × u_B` reverses direction when `ρ` passes ±π —
//!   the thesis's criterion — and also when it passes 0, which is legal; the two are told
//!   apart by following `ρ` continuously from state to state (unwrapping). A crease whose
//!   unwrapped angle exceeds π in magnitude has one facet flipped through the other, and it
//!   stays reported for every state until it unfolds back. This assumes successive states
//!   are close enough that no fold angle changes by π or more between them.

use std::collections::HashMap;

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::cylinder::Cylinder;
use super::tri_tri::{DEFAULT_TOL, Tri, triangles_intersect};
use super::triangulate::{TriangulateError, triangulate_faces};
use crate::pattern::Pattern;

/// How two facets intersect.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IntersectionKind {
    /// Their interiors cross (Möller test), in a folded state.
    Crossing,
    /// They share a crease whose fold angle has passed ±π: one flipped through the other.
    Flip,
    /// They overlap in the flat layout (the pattern itself is invalid).
    FlatOverlap,
}

/// An intersection between two facets at one state.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Intersection {
    /// The lower facet index.
    pub face_a: usize,
    /// The higher facet index.
    pub face_b: usize,
    /// The driving parameter of the state.
    pub t: f64,
    /// What kind of intersection.
    pub kind: IntersectionKind,
}

/// A facet entering an obstacle at one state.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObstacleHit {
    /// The facet.
    pub face: usize,
    /// Index of the obstacle in the list that was checked.
    pub obstacle: usize,
    /// The driving parameter of the state.
    pub t: f64,
}

/// Errors building a [`Checker`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CheckError {
    /// A facet could not be triangulated.
    #[error(transparent)]
    Triangulate(#[from] TriangulateError),
    /// Two facets traverse the same directed edge: orientations disagree or facets overlap.
    #[error(
        "facets {face_a} and {face_b} both run along edge {p}→{q} in the same direction; \
         adjacent counter-clockwise facets traverse a shared crease in opposite directions"
    )]
    InconsistentOrientation {
        /// First facet.
        face_a: usize,
        /// Second facet.
        face_b: usize,
        /// Tail of the directed edge.
        p: usize,
        /// Head of the directed edge.
        q: usize,
    },
    /// A state's coordinate list does not match the pattern.
    #[error("a state has {got} vertex positions, the pattern has {expected} vertices")]
    WrongVertexCount {
        /// Number of vertices in the pattern.
        expected: usize,
        /// Number of positions given.
        got: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate at t = {t}")]
    NonFinite {
        /// The vertex.
        vertex: usize,
        /// The state.
        t: f64,
    },
}

/// A crease between two facets, for the flip test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hinge {
    /// The facet left of `p → q` in the flat layout (it traverses `p → q`).
    pub face_a: usize,
    /// The facet right of `p → q` (it traverses `q → p`).
    pub face_b: usize,
    /// Tail of the crease.
    pub p: usize,
    /// Head of the crease.
    pub q: usize,
    /// The vertex of `face_a` farthest from the crease line in the flat layout.
    witness_a: usize,
    /// The vertex of `face_b` farthest from the crease line in the flat layout.
    witness_b: usize,
}

impl Hinge {
    /// The fold angle of this crease in radians, valley positive, in (−π, π].
    pub fn fold_angle(&self, coords: &[[f64; 3]]) -> f64 {
        let v = |i: usize| Vector3::from(coords[i]);
        let (p, q) = (v(self.p), v(self.q));
        let e = q - p;
        let perp = |w: Vector3<f64>| {
            let r = w - p;
            r - e * (e.dot(&r) / e.norm_squared())
        };
        let ua = perp(v(self.witness_a));
        let ub = perp(v(self.witness_b));
        ua.cross(&ub).dot(&e).atan2(-ua.dot(&ub) * e.norm())
    }
}

/// The triangulated facets of a pattern and its creases, ready to check states.
#[derive(Clone, Debug)]
pub struct Checker {
    n_vertices: usize,
    tris: Vec<Vec<[usize; 3]>>,
    hinges: Vec<Hinge>,
    tol: f64,
    /// See [`Checker::with_half_turn_copy`].
    copies_from: Option<usize>,
}

impl Checker {
    /// Triangulate `faces` (counter-clockwise vertex lists) in the flat `layout` and find
    /// the creases (edges shared by two facets).
    pub fn new(layout: &[[f64; 2]], faces: &[Vec<usize>]) -> Result<Self, CheckError> {
        let tris = triangulate_faces(layout, faces)?;
        let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
        for (f, poly) in faces.iter().enumerate() {
            for k in 0..poly.len() {
                let (p, q) = (poly[k], poly[(k + 1) % poly.len()]);
                if let Some(&g) = directed.get(&(p, q)) {
                    return Err(CheckError::InconsistentOrientation {
                        face_a: g,
                        face_b: f,
                        p,
                        q,
                    });
                }
                directed.insert((p, q), f);
            }
        }
        // The vertex of facet `f` farthest from the line p → q on the facet's own side
        // (`side` = +1 left, −1 right). Signed, because a non-convex facet can reach
        // farther on the other side of its crease: a witness there makes the flat fold
        // angle ±π instead of 0, and the flip test then fires (or misses) at random.
        let witness = |f: usize, p: usize, q: usize, side: f64| {
            let (a, b) = (layout[p], layout[q]);
            let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
            let left = |v: usize| side * (ex * (layout[v][1] - a[1]) - ey * (layout[v][0] - a[0]));
            faces[f]
                .iter()
                .copied()
                .max_by(|&x, &y| left(x).total_cmp(&left(y)))
                .unwrap_or(p)
        };
        let mut hinges: Vec<Hinge> = directed
            .iter()
            .filter_map(|(&(p, q), &fa)| {
                let &fb = directed.get(&(q, p))?;
                (fa < fb).then(|| Hinge {
                    face_a: fa,
                    face_b: fb,
                    p,
                    q,
                    witness_a: witness(fa, p, q, 1.0),
                    witness_b: witness(fb, p, q, -1.0),
                })
            })
            .collect();
        hinges.sort_by_key(|h| (h.face_a, h.face_b, h.p, h.q));
        Ok(Checker {
            n_vertices: layout.len(),
            tris,
            hinges,
            tol: DEFAULT_TOL,
            copies_from: None,
        })
    }

    /// A checker for a [`Pattern`]'s facets in its flat layout.
    pub fn from_pattern(pattern: &Pattern) -> Result<Self, CheckError> {
        Self::new(&pattern.vertices, &pattern.faces)
    }

    /// Use `tol` (a length) as the contact tolerance instead of [`DEFAULT_TOL`].
    pub fn with_tolerance(mut self, tol: f64) -> Self {
        self.tol = tol;
        self
    }

    /// The contact tolerance in use.
    pub fn tolerance(&self) -> f64 {
        self.tol
    }

    /// The triangles of every facet (vertex-index triples).
    pub fn triangles(&self) -> &[Vec<[usize; 3]>] {
        &self.tris
    }

    /// The creases between pairs of facets, for the flip test.
    pub fn hinges(&self) -> &[Hinge] {
        &self.hinges
    }

    /// Number of vertices the checker expects in a state.
    pub fn n_vertices(&self) -> usize {
        self.n_vertices
    }

    /// Reject states with the wrong length or non-finite coordinates.
    pub fn validate_state(&self, coords: &[[f64; 3]], t: f64) -> Result<(), CheckError> {
        if coords.len() != self.n_vertices {
            return Err(CheckError::WrongVertexCount {
                expected: self.n_vertices,
                got: coords.len(),
            });
        }
        if let Some(vertex) = coords.iter().position(|c| c.iter().any(|x| !x.is_finite())) {
            return Err(CheckError::NonFinite { vertex, t });
        }
        Ok(())
    }

    /// Declare facets `arm_faces..` the copies of facets `0..arm_faces` turned by exactly
    /// 180° about the z-axis (`check::two_armed`: `(x, y, z) → (−x, −y, z)`, exact in
    /// floating point, and the same triangulation since orientation tests are unchanged by
    /// it). Two copies then cross exactly when their originals do, and those come first in
    /// the search order, so [`Checker::crossings`] with `first_only` skips pairs of two
    /// copies: the same answer for a quarter fewer pairs (issue 14).
    pub fn with_half_turn_copy(mut self, arm_faces: usize) -> Self {
        self.copies_from = Some(arm_faces);
        self
    }

    /// Möller crossings between facets at one state (`coords` must pass
    /// [`Checker::validate_state`]). With `first_only`, stops at the first pair found.
    /// The pairs come in increasing `(face_a, face_b)` order.
    pub fn crossings(&self, coords: &[[f64; 3]], t: f64, first_only: bool) -> Vec<Intersection> {
        self.crossings_of_kind(coords, t, first_only, IntersectionKind::Crossing)
    }

    fn crossings_of_kind(
        &self,
        coords: &[[f64; 3]],
        t: f64,
        first_only: bool,
        kind: IntersectionKind,
    ) -> Vec<Intersection> {
        let tri = |ix: &[usize; 3]| -> Tri { ix.map(|i| Vector3::from(coords[i])) };
        let boxes: Vec<([f64; 3], [f64; 3])> = self
            .tris
            .iter()
            .map(|ts| {
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                for &i in ts.iter().flatten() {
                    for k in 0..3 {
                        lo[k] = lo[k].min(coords[i][k]);
                        hi[k] = hi[k].max(coords[i][k]);
                    }
                }
                (lo, hi)
            })
            .collect();
        let mut out = Vec::new();
        // Only with `first_only`: a full list keeps the copies' own crossings.
        let pairs_end = match self.copies_from {
            Some(arm) if first_only => arm.min(self.tris.len()),
            _ => self.tris.len(),
        };
        for fa in 0..pairs_end {
            for fb in fa + 1..self.tris.len() {
                let (la, ha) = boxes[fa];
                let (lb, hb) = boxes[fb];
                if (0..3).any(|k| la[k] > hb[k] + self.tol || lb[k] > ha[k] + self.tol) {
                    continue;
                }
                let hit = self.tris[fa].iter().any(|ta| {
                    let ta = tri(ta);
                    self.tris[fb]
                        .iter()
                        .any(|tb| triangles_intersect(&ta, &tri(tb), self.tol))
                });
                if hit {
                    out.push(Intersection {
                        face_a: fa,
                        face_b: fb,
                        t,
                        kind,
                    });
                    if first_only {
                        return out;
                    }
                }
            }
        }
        out
    }

    /// Overlaps of facets in the flat layout (all facets lie in one plane there), reported
    /// as [`IntersectionKind::FlatOverlap`] at `t`.
    pub fn flat_overlaps(
        &self,
        layout: &[[f64; 2]],
        t: f64,
        first_only: bool,
    ) -> Vec<Intersection> {
        let flat: Vec<[f64; 3]> = layout.iter().map(|p| [p[0], p[1], 0.0]).collect();
        self.crossings_of_kind(&flat, t, first_only, IntersectionKind::FlatOverlap)
    }

    /// Facets entering `cylinder` at one state (first triangle per facet decides).
    pub fn obstacle_hits(
        &self,
        coords: &[[f64; 3]],
        cylinder: &Cylinder,
        obstacle: usize,
        t: f64,
        first_only: bool,
    ) -> Vec<ObstacleHit> {
        let mut out = Vec::new();
        for (face, ts) in self.tris.iter().enumerate() {
            let hit = ts.iter().any(|ix| {
                let tri: Tri = ix.map(|i| Vector3::from(coords[i]));
                cylinder.hits(&tri, self.tol)
            });
            if hit {
                out.push(ObstacleHit { face, obstacle, t });
                if first_only {
                    break;
                }
            }
        }
        out
    }

    /// Fold angles of all hinges at a state, valley positive, each in (−π, π].
    pub fn fold_angles(&self, coords: &[[f64; 3]]) -> Vec<f64> {
        self.hinges.iter().map(|h| h.fold_angle(coords)).collect()
    }
}

/// Follows a motion state by state: Möller crossings at each state and the flip test
/// between successive states.
#[derive(Clone, Debug)]
pub struct StateTracker<'a> {
    checker: &'a Checker,
    /// Unwrapped fold angle of every hinge at the last state seen.
    unwrapped: Option<Vec<f64>>,
}

impl<'a> StateTracker<'a> {
    /// Start tracking; the first state seen is the reference for the fold angles.
    pub fn new(checker: &'a Checker) -> Self {
        StateTracker {
            checker,
            unwrapped: None,
        }
    }

    /// Check the next state of the motion: crossings, then flips (creases whose unwrapped
    /// fold angle exceeds π in magnitude). `coords` must pass [`Checker::validate_state`].
    pub fn step(&mut self, coords: &[[f64; 3]], t: f64, first_only: bool) -> Vec<Intersection> {
        let mut out = self.checker.crossings(coords, t, first_only);
        let raw = self.checker.fold_angles(coords);
        let next: Vec<f64> = match &self.unwrapped {
            None => raw,
            Some(prev) => prev
                .iter()
                .zip(&raw)
                .map(|(&p, &r)| p + wrap_pi(r - p))
                .collect(),
        };
        let limit = std::f64::consts::PI + 1e-9;
        for (h, &rho) in self.checker.hinges.iter().zip(&next) {
            if rho.abs() > limit && (out.is_empty() || !first_only) {
                out.push(Intersection {
                    face_a: h.face_a,
                    face_b: h.face_b,
                    t,
                    kind: IntersectionKind::Flip,
                });
            }
        }
        self.unwrapped = Some(next);
        out
    }

    /// The unwrapped fold angles at the last state (None before the first state).
    pub fn unwrapped_angles(&self) -> Option<&[f64]> {
        self.unwrapped.as_deref()
    }
}

/// `x` wrapped into (−π, π].
fn wrap_pi(x: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let mut y = x.rem_euclid(TAU);
    if y > PI {
        y -= TAU;
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Two unit squares sharing the crease x = 0 (from (0,0) to (0,1)); the right square is
    /// fixed, the left one rotates about the crease by `rho` (valley positive).
    fn hinge_state(rho: f64) -> Vec<[f64; 3]> {
        // Vertices: 0 (0,0), 1 (1,0), 2 (1,1), 3 (0,1), 4 (-1,1), 5 (-1,0).
        // Left square in 3D: points at x = -1 become (-cos ρ, y, sin ρ) for a valley.
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [-rho.cos(), 1.0, rho.sin()],
            [-rho.cos(), 0.0, rho.sin()],
        ]
    }

    fn hinge_checker() -> Checker {
        let layout = [
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [-1.0, 1.0],
            [-1.0, 0.0],
        ];
        Checker::new(&layout, &[vec![0, 1, 2, 3], vec![0, 3, 4, 5]]).unwrap()
    }

    /// A non-convex facet whose farthest corner lies across the line of its crease: the
    /// fold angle must still be the rotation about the crease, 0 when flat, and the
    /// exactly flat start must not count as a flip.
    #[test]
    fn non_convex_facet_reaching_across_its_crease() {
        let layout = [
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [3.0, 1.5],
            [-1.0, 2.0],
            [-1.0, 0.0],
        ];
        let faces = [vec![0, 1, 2, 3], vec![0, 3, 4, 5, 6]];
        let c = Checker::new(&layout, &faces).unwrap();
        assert_eq!(c.hinges().len(), 1);
        // Facet 1 turns about the crease (the y axis) by rho, valley positive.
        let state = |rho: f64| -> Vec<[f64; 3]> {
            layout
                .iter()
                .enumerate()
                .map(|(v, p)| {
                    if [4, 5, 6].contains(&v) {
                        [p[0] * rho.cos(), p[1], -p[0] * rho.sin()]
                    } else {
                        [p[0], p[1], 0.0]
                    }
                })
                .collect()
        };
        for rho in [0.0, 0.4, -0.4, 2.0, -2.0] {
            let got = c.fold_angles(&state(rho))[0];
            assert!((got - rho).abs() < 1e-12, "{rho} vs {got}");
        }
        for sign in [1.0, -1.0] {
            let mut tr = StateTracker::new(&c);
            for k in 0..=10 {
                let rho = sign * 0.1 * f64::from(k);
                let flips: Vec<_> = tr
                    .step(&state(rho), rho, false)
                    .into_iter()
                    .filter(|i| i.kind == IntersectionKind::Flip)
                    .collect();
                assert!(flips.is_empty(), "flip reported at rho = {rho}");
            }
        }
    }

    #[test]
    fn fold_angle_is_valley_positive_and_exact() {
        let c = hinge_checker();
        assert_eq!(c.hinges().len(), 1);
        for rho in [-2.5, -1.0, 0.0, 0.3, 1.2, 3.0] {
            let got = c.fold_angles(&hinge_state(rho))[0];
            assert!((got - rho).abs() < 1e-12, "{rho} vs {got}");
        }
    }

    #[test]
    fn flip_through_pi_is_detected_and_persists() {
        let c = hinge_checker();
        let mut tr = StateTracker::new(&c);
        let mut flagged = Vec::new();
        for k in 0..=40 {
            let rho = k as f64 * 0.1; // up to 4.0 > π
            let hits = tr.step(&hinge_state(rho), rho, false);
            assert!(hits.iter().all(|h| h.kind == IntersectionKind::Flip));
            flagged.push(!hits.is_empty());
        }
        for (k, &f) in flagged.iter().enumerate() {
            assert_eq!(f, k as f64 * 0.1 > PI, "state {k}");
        }
    }

    #[test]
    fn passing_through_flat_is_not_a_flip() {
        let c = hinge_checker();
        let mut tr = StateTracker::new(&c);
        for k in -20..=20 {
            let rho = k as f64 * 0.1;
            assert!(tr.step(&hinge_state(rho), rho, false).is_empty());
        }
    }

    #[test]
    fn flat_layout_overlap_is_reported() {
        let layout = [
            [0.0, 0.0],
            [2.0, 0.0],
            [0.0, 2.0],
            [0.5, 0.5],
            [3.0, 0.5],
            [0.5, 3.0],
        ];
        let c = Checker::new(&layout, &[vec![0, 1, 2], vec![3, 4, 5]]).unwrap();
        let hits = c.flat_overlaps(&layout, 0.0, false);
        assert_eq!(hits.len(), 1);
        assert_eq!(hits[0].kind, IntersectionKind::FlatOverlap);
        assert!(
            hinge_checker()
                .flat_overlaps(
                    &[
                        [0.0, 0.0],
                        [1.0, 0.0],
                        [1.0, 1.0],
                        [0.0, 1.0],
                        [-1.0, 1.0],
                        [-1.0, 0.0]
                    ],
                    0.0,
                    false
                )
                .is_empty()
        );
    }

    #[test]
    fn inconsistent_orientation_is_an_error() {
        let layout = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]];
        // Both faces traverse 0→1.
        let err = Checker::new(&layout, &[vec![0, 1, 2], vec![0, 1, 3]]).unwrap_err();
        assert!(matches!(err, CheckError::InconsistentOrientation { .. }));
    }

    /// The half-turn copy crosses exactly where its original does: with the copy declared,
    /// the first crossing found is the same at every state, while the full list shows the
    /// copies' own crossing (so the skipped pairs did cross). Two unit squares, one sliding
    /// through the other along a random path.
    #[test]
    fn half_turn_copies_cross_where_their_originals_do() {
        use crate::check::rotated_copy::two_armed;
        use crate::pattern::Frame;
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut rnd = move || rng.random_range(0.0..1.0);
        let square = |x0: f64, y0: f64| {
            [
                [x0, y0],
                [x0 + 1.0, y0],
                [x0 + 1.0, y0 + 1.0],
                [x0, y0 + 1.0],
            ]
        };
        let mut vertices: Vec<[f64; 2]> = square(1.0, 0.5).to_vec();
        vertices.extend(square(3.0, 0.5));
        let frames: Vec<Frame> = (0..200)
            .map(|k| {
                // A fixed in z = 0; B stood up (in a plane x = const) and moved about.
                let (bx, by, bz) = (1.0 + 1.2 * rnd(), 0.2 + rnd(), -0.8 + 0.6 * rnd());
                let mut coords: Vec<[f64; 3]> =
                    square(1.0, 0.5).iter().map(|p| [p[0], p[1], 0.0]).collect();
                coords.extend([
                    [bx, by, bz],
                    [bx, by + 1.0, bz],
                    [bx, by + 1.0, bz + 1.0],
                    [bx, by, bz + 1.0],
                ]);
                Frame {
                    t: k as f64,
                    coords,
                    fold_angles: Vec::new(),
                }
            })
            .collect();
        let arm = Pattern {
            vertices,
            edges: Vec::new(),
            faces: vec![vec![0, 1, 2, 3], vec![4, 5, 6, 7]],
            frames,
        };
        let both = two_armed(&arm).unwrap();
        let plain = Checker::from_pattern(&both).unwrap();
        let declared = Checker::from_pattern(&both).unwrap().with_half_turn_copy(2);
        let mut crossing = 0;
        for f in &both.frames {
            let first = declared.crossings(&f.coords, f.t, true);
            assert_eq!(first, plain.crossings(&f.coords, f.t, true));
            let all = plain.crossings(&f.coords, f.t, false);
            let original = all.iter().any(|c| (c.face_a, c.face_b) == (0, 1));
            let copies = all.iter().any(|c| (c.face_a, c.face_b) == (2, 3));
            assert_eq!(original, copies, "t {}", f.t);
            assert_eq!(declared.crossings(&f.coords, f.t, false), all);
            crossing += usize::from(original);
        }
        assert!(
            crossing > 20 && crossing < 180,
            "{crossing} of 200 states cross"
        );
    }
}
