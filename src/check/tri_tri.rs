//! Möller's triangle–triangle intersection test (T. Möller, "A Fast Triangle-Triangle
//! Intersection Test", Journal of Graphics Tools 2(2), 1997), with a tolerance so that
//! contact is not intersection.
//!
//! The structure is Möller's: reject when one triangle lies strictly on one side of the
//! other's plane; otherwise intersect both triangles with the line where the planes meet
//! and compare the two intervals on it; coplanar triangles get a 2D test.
//!
//! What is reported is a *proper crossing of the interiors*, not mere contact:
//!
//! * signed distances to a plane with |d| ≤ `tol` count as 0 (Möller's own robustness
//!   device), and each triangle must then have vertices strictly on *both* sides of the
//!   other's plane — a triangle that only touches a plane with a vertex or an edge meets the
//!   other triangle on its own boundary, which is contact;
//! * the two intervals on the intersection line must overlap by more than `tol` (a length);
//! * coplanar triangles must overlap by more than `tol` along every separating axis of the
//!   2D separating-axis test (the six edge normals), which is Möller's coplanar case (edge
//!   tests plus point-in-triangle) restated so that a tolerance has a meaning.
//!
//! Two facets that share a crease, or a single vertex, therefore never "intersect" through
//! the shared points, and the same test can be used for every pair of facets.

use nalgebra::Vector3;

/// A triangle in 3D.
pub type Tri = [Vector3<f64>; 3];

/// Default tolerance (a length in pattern units) for contact versus intersection.
pub const DEFAULT_TOL: f64 = 1e-9;

/// Whether the interiors of two triangles cross (see the module docs for the tolerance).
///
/// Degenerate (zero-area) triangles have no interior and never intersect.
pub fn triangles_intersect(a: &Tri, b: &Tri, tol: f64) -> bool {
    let na = (a[1] - a[0]).cross(&(a[2] - a[0]));
    let nb = (b[1] - b[0]).cross(&(b[2] - b[0]));
    let (la, lb) = (na.norm(), nb.norm());
    let tiny = 1e-300;
    if la <= tiny || lb <= tiny {
        return false;
    }
    let (na, nb) = (na / la, nb / lb);

    // Signed distances of a's vertices to b's plane and vice versa, snapped to 0 within tol.
    let snap = |d: f64| if d.abs() <= tol { 0.0 } else { d };
    let da = [0, 1, 2].map(|i| snap(nb.dot(&(a[i] - b[0]))));
    let db = [0, 1, 2].map(|i| snap(na.dot(&(b[i] - a[0]))));
    let one_side = |d: &[f64; 3]| d.iter().all(|&x| x > 0.0) || d.iter().all(|&x| x < 0.0);
    if one_side(&da) || one_side(&db) {
        return false;
    }
    if da.iter().all(|&x| x == 0.0) {
        return coplanar_overlap(a, b, &nb, tol);
    }
    if db.iter().all(|&x| x == 0.0) {
        return coplanar_overlap(a, b, &na, tol);
    }
    let straddles = |d: &[f64; 3]| d.iter().any(|&x| x > 0.0) && d.iter().any(|&x| x < 0.0);
    if !straddles(&da) || !straddles(&db) {
        return false; // contact on a vertex or an edge only
    }
    let dir = na.cross(&nb);
    let ldir = dir.norm();
    if ldir <= 1e-12 {
        // Planes parallel to rounding yet each triangle straddles the other: nearly
        // coplanar, so the 2D test decides.
        return coplanar_overlap(a, b, &nb, tol);
    }
    let dir = dir / ldir;
    let (a0, a1) = interval(a, &da, &dir);
    let (b0, b1) = interval(b, &db, &dir);
    a1.min(b1) - a0.max(b0) > tol
}

/// The interval, in arc length along `dir`, where a straddling triangle crosses the plane
/// whose signed distances are `d`.
fn interval(t: &Tri, d: &[f64; 3], dir: &Vector3<f64>) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let mut push = |p: Vector3<f64>| {
        let s = dir.dot(&p);
        lo = lo.min(s);
        hi = hi.max(s);
    };
    for i in 0..3 {
        let j = (i + 1) % 3;
        if d[i] == 0.0 {
            push(t[i]);
        }
        if d[i] * d[j] < 0.0 {
            push(t[i] + (t[j] - t[i]) * (d[i] / (d[i] - d[j])));
        }
    }
    (lo, hi)
}

/// 2D separating-axis test of two (nearly) coplanar triangles, in the plane with unit
/// normal `n`: they overlap when every edge normal shows an overlap of more than `tol`.
fn coplanar_overlap(a: &Tri, b: &Tri, n: &Vector3<f64>, tol: f64) -> bool {
    // An orthonormal basis of the plane keeps lengths true, so `tol` stays a length.
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = n.cross(&helper).normalize();
    let e2 = n.cross(&e1);
    let to2 = |p: &Vector3<f64>| [e1.dot(p), e2.dot(p)];
    let pa = [to2(&a[0]), to2(&a[1]), to2(&a[2])];
    let pb = [to2(&b[0]), to2(&b[1]), to2(&b[2])];
    for tri in [&pa, &pb] {
        for i in 0..3 {
            let p = tri[i];
            let q = tri[(i + 1) % 3];
            let (ex, ey) = (q[0] - p[0], q[1] - p[1]);
            let len = (ex * ex + ey * ey).sqrt();
            if len <= 1e-300 {
                continue;
            }
            let axis = [-ey / len, ex / len];
            let proj = |t: &[[f64; 2]; 3]| {
                let s = t.map(|v| v[0] * axis[0] + v[1] * axis[1]);
                (s[0].min(s[1]).min(s[2]), s[0].max(s[1]).max(s[2]))
            };
            let (a0, a1) = proj(&pa);
            let (b0, b1) = proj(&pb);
            if a1.min(b1) - a0.max(b0) <= tol {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(p: [[f64; 3]; 3]) -> Tri {
        p.map(Vector3::from)
    }

    #[test]
    fn piercing_triangles_intersect() {
        let a = t([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
        let b = t([[0.5, 0.5, -1.0], [0.5, 0.5, 1.0], [1.5, -1.0, 0.0]]);
        assert!(triangles_intersect(&a, &b, DEFAULT_TOL));
        assert!(triangles_intersect(&b, &a, DEFAULT_TOL));
    }

    #[test]
    fn separated_triangles_do_not_intersect() {
        let a = t([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        let b = t([[0.0, 0.0, 0.5], [1.0, 0.0, 0.5], [0.0, 1.0, 0.7]]);
        assert!(!triangles_intersect(&a, &b, DEFAULT_TOL));
        // Planes cross, triangles do not reach each other on the common line.
        let c = t([[3.0, 3.0, -1.0], [3.0, 3.0, 1.0], [4.0, 3.0, 0.0]]);
        assert!(!triangles_intersect(&a, &c, DEFAULT_TOL));
    }

    #[test]
    fn touching_is_not_intersection() {
        let a = t([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        // Shared edge, folded at 90°.
        let b = t([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
        assert!(!triangles_intersect(&a, &b, DEFAULT_TOL));
        // A vertex resting on the interior of a.
        let c = t([[0.2, 0.2, 0.0], [0.2, 0.2, 1.0], [1.0, 1.0, 1.0]]);
        assert!(!triangles_intersect(&a, &c, DEFAULT_TOL));
        // An edge lying on a's interior, the rest above.
        let d = t([[0.1, 0.1, 0.0], [0.4, 0.1, 0.0], [0.2, 0.2, 1.0]]);
        assert!(!triangles_intersect(&a, &d, DEFAULT_TOL));
        // Shared vertex only.
        let e = t([[0.0, 0.0, 0.0], [-1.0, 0.0, 1.0], [0.0, -1.0, 1.0]]);
        assert!(!triangles_intersect(&a, &e, DEFAULT_TOL));
    }

    #[test]
    fn shared_vertex_with_crossing_interiors_intersects() {
        // b shares vertex 0 of a and cuts through a's interior.
        let a = t([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        let b = t([[0.0, 0.0, 0.0], [0.5, 0.5, 1.0], [0.5, 0.5, -1.0]]);
        assert!(triangles_intersect(&a, &b, DEFAULT_TOL));
    }

    #[test]
    fn coplanar_overlapping_and_disjoint() {
        let a = t([[0.0, 0.0, 1.0], [2.0, 0.0, 1.0], [0.0, 2.0, 1.0]]);
        let b = t([[0.5, 0.5, 1.0], [3.0, 0.5, 1.0], [0.5, 3.0, 1.0]]);
        assert!(triangles_intersect(&a, &b, DEFAULT_TOL));
        // Contained triangle.
        let c = t([[0.1, 0.1, 1.0], [0.5, 0.1, 1.0], [0.1, 0.5, 1.0]]);
        assert!(triangles_intersect(&a, &c, DEFAULT_TOL));
        // Disjoint, and sharing an edge only.
        let d = t([[3.0, 3.0, 1.0], [4.0, 3.0, 1.0], [3.0, 4.0, 1.0]]);
        assert!(!triangles_intersect(&a, &d, DEFAULT_TOL));
        let e = t([[2.0, 0.0, 1.0], [2.0, 2.0, 1.0], [0.0, 2.0, 1.0]]);
        assert!(!triangles_intersect(&a, &e, DEFAULT_TOL));
    }

    #[test]
    fn degenerate_triangle_never_intersects() {
        let a = t([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        let b = t([[0.2, 0.2, -1.0], [0.2, 0.2, 0.0], [0.2, 0.2, 1.0]]);
        assert!(!triangles_intersect(&a, &b, DEFAULT_TOL));
    }
}
