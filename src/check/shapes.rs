//! Exact clearance between a facet (its triangles, [`super::triangulate`]) and an obstacle
//! of any shape (issue 31), written from the geometry alone: nothing here shares code with
//! the optimizer's separating planes in `model/`.
//!
//! The clearance of a triangle is positive when it keeps off the solid by that distance and
//! 0 or negative when it meets it:
//! - sphere: the point–triangle distance of the centre minus the radius (negative: how far
//!   the triangle reaches into the ball);
//! - box (any orientation): 0 when the separating-axis test finds no separating axis among
//!   the 13 candidates (the box's 3 face normals, the triangle's normal, the 9 cross
//!   products of their edges), else the least vertex–box, corner–triangle and edge–edge
//!   distance (for two disjoint convex polytopes the closest points are a vertex and a face
//!   or two edges);
//! - half-space: the least signed height of the triangle's vertices above the boundary
//!   plane (a triangle is convex, so its least height is at a vertex);
//! - cylinder: the distance from the triangle to the axis segment minus the radius, the
//!   judge `check::robustness` has always used (the capsule around the axis contains the
//!   flat-capped cylinder, so this never reports a hit as clear);
//! - mesh: the least triangle–triangle distance to the mesh's triangles (brute force, with
//!   a bounding-box bound that skips only triangles provably farther than the best so
//!   far); for a closed mesh a facet vertex inside it (generalized winding number ≥ ½)
//!   makes the clearance minus that vertex's depth (its distance to the surface). An open
//!   mesh is a surface: only the distance counts.

use nalgebra::Vector3;

use super::distance::triangle_distance;
use super::distance::{closest_on_triangle, segment_distance, segment_triangle_distance};
use super::tri_tri::Tri;
use crate::scene::{Cylinder, HalfSpace, OrientedBox, Shape, Sphere, TriangleMesh};

type V = Vector3<f64>;

/// The clearance of the facet made of `tris` from `shape` (see the module docs): the least
/// over its triangles. `None` for a mesh obstacle whose file was not loaded
/// ([`crate::scene::shapes::MeshObstacle::load`]) or a facet without triangles.
pub fn facet_clearance(shape: &Shape, tris: &[Tri]) -> Option<f64> {
    if tris.is_empty() {
        return None;
    }
    let least = |f: &dyn Fn(&Tri) -> f64| tris.iter().map(f).fold(f64::INFINITY, f64::min);
    Some(match shape {
        Shape::Cylinder(c) => least(&|t| cylinder_clearance(c, t)),
        Shape::Sphere(s) => least(&|t| sphere_clearance(s, t)),
        Shape::Box(b) => least(&|t| box_clearance(b, t)),
        Shape::HalfSpace(h) => least(&|t| halfspace_clearance(h, t)),
        Shape::Mesh(m) => mesh_clearance(m.triangles()?, tris),
    })
}

/// The clearance of triangle `t` from a cylinder: triangle–axis-segment distance minus the
/// radius (today's judge, see the module docs).
pub fn cylinder_clearance(c: &Cylinder, t: &Tri) -> f64 {
    segment_triangle_distance(&V::from(c.a), &V::from(c.b), t) - c.radius
}

/// The clearance of triangle `t` from a ball: centre–triangle distance minus the radius.
pub fn sphere_clearance(s: &Sphere, t: &Tri) -> f64 {
    let c = V::from(s.center);
    (c - closest_on_triangle(&c, t)).norm() - s.radius
}

/// The clearance of triangle `t` from a half-space: its least signed height.
pub fn halfspace_clearance(h: &HalfSpace, t: &Tri) -> f64 {
    let (p, n) = (V::from(h.point), V::from(h.normal));
    t.iter()
        .map(|x| n.dot(&(x - p)))
        .fold(f64::INFINITY, f64::min)
}

/// Distance from `p` to the solid box (0 inside).
pub fn point_box_distance(b: &OrientedBox, p: &V) -> f64 {
    let q = b.local([p.x, p.y, p.z]);
    let mut s = 0.0;
    for (x, h) in q.iter().zip(&b.half) {
        let d = x.abs() - h;
        if d > 0.0 {
            s += d * d;
        }
    }
    s.sqrt()
}

/// Whether triangle `t` and the solid box meet: no separating axis among the 13 of the
/// separating-axis test (touching counts as meeting).
pub fn box_meets_triangle(b: &OrientedBox, t: &Tri) -> bool {
    let c = V::from(b.center);
    let axes = b.axes.map(V::from);
    let v = t.map(|x| x - c);
    let e = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let separates = |a: V| {
        let len = a.norm();
        if len <= 1e-12 * (1.0 + e.iter().map(|x| x.norm()).fold(0.0, f64::max)) {
            // Parallel edges: no axis; the other candidates decide.
            return false;
        }
        let r: f64 = (0..3).map(|i| b.half[i] * a.dot(&axes[i]).abs()).sum();
        let p = v.map(|x| x.dot(&a));
        let lo = p[0].min(p[1]).min(p[2]);
        let hi = p[0].max(p[1]).max(p[2]);
        lo > r || hi < -r
    };
    if axes.iter().any(|a| separates(*a)) || separates(e[0].cross(&e[1])) {
        return false;
    }
    !axes
        .iter()
        .any(|a| e.iter().any(|ed| separates(a.cross(ed))))
}

/// The clearance of triangle `t` from a box in any orientation (see the module docs).
pub fn box_clearance(b: &OrientedBox, t: &Tri) -> f64 {
    if box_meets_triangle(b, t) {
        return 0.0;
    }
    let corners = b.corners().map(V::from);
    let mut d = t
        .iter()
        .map(|p| point_box_distance(b, p))
        .fold(f64::INFINITY, f64::min);
    for p in &corners {
        d = d.min((p - closest_on_triangle(p, t)).norm());
    }
    // The 12 edges join corners differing in one bit.
    for k in 0..8 {
        for bit in [1, 2, 4] {
            if k & bit == 0 {
                let (p, q) = (&corners[k], &corners[k | bit]);
                for j in 0..3 {
                    d = d.min(segment_distance(p, q, &t[j], &t[(j + 1) % 3]));
                }
            }
        }
    }
    d
}

/// Generalized winding number of a closed, consistently oriented mesh about `p` (Jacobson
/// et al. 2013): the solid angles of its triangles seen from `p` (Van Oosterom–Strackee)
/// over 4π. ±1 inside (the sign follows the orientation), 0 outside.
pub fn winding_number(mesh: &TriangleMesh, p: &V) -> f64 {
    let mut total = 0.0;
    for i in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.triangle(i).map(|x| V::from(x) - p);
        let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
        let num = a.dot(&b.cross(&c));
        let den = la * lb * lc + a.dot(&b) * lc + b.dot(&c) * la + c.dot(&a) * lb;
        total += 2.0 * num.atan2(den);
    }
    total / (4.0 * std::f64::consts::PI)
}

/// Distance from `p` to the nearest triangle of `mesh` (brute force).
pub fn point_mesh_distance(mesh: &TriangleMesh, p: &V) -> f64 {
    (0..mesh.triangles.len())
        .map(|i| {
            let t = mesh.triangle(i).map(V::from);
            (p - closest_on_triangle(p, &t)).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Axis-aligned bounds of a triangle.
fn bounds(t: &Tri) -> (V, V) {
    (t[0].inf(&t[1]).inf(&t[2]), t[0].sup(&t[1]).sup(&t[2]))
}

/// A lower bound of the distance between two axis-aligned boxes (their gap).
fn box_gap((lo_a, hi_a): &(V, V), (lo_b, hi_b): &(V, V)) -> f64 {
    let mut s = 0.0;
    for i in 0..3 {
        let g = (lo_b[i] - hi_a[i]).max(lo_a[i] - hi_b[i]).max(0.0);
        s += g * g;
    }
    s.sqrt()
}

/// The clearance of a facet (`tris`) from a mesh obstacle (see the module docs).
pub fn mesh_clearance(mesh: &TriangleMesh, tris: &[Tri]) -> f64 {
    if mesh.closed {
        let depth = tris
            .iter()
            .flatten()
            .filter(|p| winding_number(mesh, p).abs() >= 0.5)
            .map(|p| point_mesh_distance(mesh, p))
            .fold(f64::NEG_INFINITY, f64::max);
        if depth > f64::NEG_INFINITY {
            return -depth;
        }
    }
    let facet: Vec<(Tri, (V, V))> = tris.iter().map(|t| (*t, bounds(t))).collect();
    let mut best = f64::INFINITY;
    for i in 0..mesh.triangles.len() {
        let m = mesh.triangle(i).map(V::from);
        let mb = bounds(&m);
        for (t, tb) in &facet {
            // The boxes' gap never exceeds the triangles' distance: skipping what lies
            // beyond the best so far cannot change the least.
            if box_gap(&mb, tb) <= best {
                best = best.min(triangle_distance(t, &m));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(p: [[f64; 3]; 3]) -> Tri {
        p.map(V::from)
    }

    #[test]
    fn halfspace_is_the_least_vertex_height() {
        let h = HalfSpace {
            point: [0.0, 0.0, 1.0],
            normal: [0.0, 0.0, 1.0],
        };
        let t = tri([[0.0, 0.0, 3.0], [1.0, 0.0, 1.5], [0.0, 1.0, 2.0]]);
        assert_eq!(halfspace_clearance(&h, &t), 0.5);
    }

    #[test]
    fn box_edge_to_edge_distance() {
        // The unit cube about the origin; a triangle whose edge runs parallel to the box's
        // top front edge (y = 1, z = 1 along x) at distance 1 diagonally.
        let b = OrientedBox::aligned([-1.0; 3], [1.0; 3]);
        let s = 1.0 / 2f64.sqrt();
        let t = tri([
            [-0.5, 1.0 + s, 1.0 + s],
            [0.5, 1.0 + s, 1.0 + s],
            [0.0, 3.0, 3.0],
        ]);
        assert!((box_clearance(&b, &t) - 1.0).abs() < 1e-12);
    }
}
