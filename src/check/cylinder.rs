//! A finite solid cylinder obstacle (thesis Sec. 5.5, the gripper's cylinder) and its exact
//! intersection test with a triangle.
//!
//! The cylinder is the solid `{x : 0 ≤ s(x) ≤ L, dist(x, axis line) ≤ r}` with
//! `s(x) = (x − a)·â`, `L = |b − a|`: flat caps, not a capsule. A triangle meets it exactly
//! when the part of the triangle inside the slab `0 ≤ s ≤ L` comes closer than `r` to the
//! infinite axis line. That part is a convex polygon (the triangle clipped by two parallel
//! planes); the distance from a convex planar polygon to a line is 0 when the line pierces
//! it and otherwise is attained on its boundary (the distance to a line, restricted to a
//! plane, is a convex function whose only minimum is the piercing point), so it is the least
//! segment–line distance over the polygon's edges. Every step is closed form.

use nalgebra::Vector3;

use super::tri_tri::Tri;

/// A finite solid cylinder (defined with the other obstacle shapes in [`crate::scene`]);
/// its judge is here.
pub use crate::scene::Cylinder;

impl Cylinder {
    /// The obstacle of the thesis's gripper task (Sec. 5.5, Fig. 46a): radius 0.25, axis
    /// from (0, −1, 0.5) to (0, 1, 0.5).
    pub fn thesis_gripper() -> Self {
        Cylinder {
            a: [0.0, -1.0, 0.5],
            b: [0.0, 1.0, 0.5],
            radius: 0.25,
        }
    }

    /// Whether the cylinder is usable: finite coordinates, a > 0 radius and a > 0 length.
    pub fn validate(&self) -> Result<(), String> {
        let finite = self.a.iter().chain(&self.b).all(|x| x.is_finite());
        if !finite || !self.radius.is_finite() {
            return Err("cylinder coordinates and radius must be finite numbers".into());
        }
        if self.radius <= 0.0 {
            return Err(format!("cylinder radius must be > 0, got {}", self.radius));
        }
        let len = (Vector3::from(self.b) - Vector3::from(self.a)).norm();
        if len <= 0.0 {
            return Err("cylinder axis must have two distinct end points a and b".into());
        }
        Ok(())
    }

    /// Least distance from the part of `tri` inside the cylinder's slab to the axis line, or
    /// `None` when the triangle does not reach the slab. The triangle meets the solid
    /// cylinder exactly when this is `Some(d)` with `d ≤ radius`.
    pub fn slab_axis_distance(&self, tri: &Tri) -> Option<f64> {
        let a = Vector3::from(self.a);
        let axis = Vector3::from(self.b) - a;
        let len = axis.norm();
        let u = axis / len;
        let poly = clip_to_slab(tri, &a, &u, len);
        if poly.is_empty() {
            return None;
        }
        // Does the axis line pierce the triangle inside the slab?
        let n = (tri[1] - tri[0]).cross(&(tri[2] - tri[0]));
        let nu = n.dot(&u);
        if nu.abs() > 1e-14 * n.norm() {
            let s = n.dot(&(tri[0] - a)) / nu;
            if (0.0..=len).contains(&s) && point_in_triangle(&(a + u * s), tri, &n) {
                return Some(0.0);
            }
        }
        let m = poly.len();
        let d = (0..m)
            .map(|k| segment_line_distance(&poly[k], &poly[(k + 1) % m], &a, &u))
            .fold(f64::INFINITY, f64::min);
        Some(d)
    }

    /// Whether the interior of `tri` enters the solid cylinder by more than `tol` (contact
    /// within `tol` of the surface is not reported).
    pub fn hits(&self, tri: &Tri, tol: f64) -> bool {
        // Every point of the triangle is within its bounding sphere: when the sphere keeps
        // off the axis line by the radius, so does the triangle (no clipping needed).
        let a = Vector3::from(self.a);
        let u = (Vector3::from(self.b) - a).normalize();
        let c = (tri[0] + tri[1] + tri[2]) / 3.0;
        let rho = tri.iter().map(|p| (p - c).norm()).fold(0.0, f64::max);
        let w = c - a;
        if (w - u * w.dot(&u)).norm() - rho - 1e-12 > self.radius - tol {
            return false;
        }
        self.slab_axis_distance(tri)
            .is_some_and(|d| d < self.radius - tol)
    }
}

/// The triangle clipped to `0 ≤ (x − a)·u ≤ len` (Sutherland–Hodgman with two planes).
fn clip_to_slab(tri: &Tri, a: &Vector3<f64>, u: &Vector3<f64>, len: f64) -> Vec<Vector3<f64>> {
    let mut poly: Vec<Vector3<f64>> = tri.to_vec();
    // Keep s ≥ 0, then keep len − s ≥ 0.
    for keep in [
        &(|p: &Vector3<f64>| u.dot(&(p - a))) as &dyn Fn(&Vector3<f64>) -> f64,
        &(|p: &Vector3<f64>| len - u.dot(&(p - a))),
    ] {
        let mut out = Vec::with_capacity(poly.len() + 2);
        let m = poly.len();
        for k in 0..m {
            let p = poly[k];
            let q = poly[(k + 1) % m];
            let (fp, fq) = (keep(&p), keep(&q));
            if fp >= 0.0 {
                out.push(p);
            }
            if (fp >= 0.0) != (fq >= 0.0) {
                out.push(p + (q - p) * (fp / (fp - fq)));
            }
        }
        poly = out;
        if poly.is_empty() {
            break;
        }
    }
    poly
}

/// Whether `p`, a point of the triangle's plane, lies in the closed triangle (normal `n`).
fn point_in_triangle(p: &Vector3<f64>, tri: &Tri, n: &Vector3<f64>) -> bool {
    (0..3).all(|i| {
        let e = tri[(i + 1) % 3] - tri[i];
        e.cross(&(p - tri[i])).dot(n) >= 0.0
    })
}

/// Distance from the segment `p → q` to the infinite line through `a` with unit direction
/// `u`: minimise the component of `p + t(q − p) − a` perpendicular to `u` over `t ∈ [0, 1]`.
fn segment_line_distance(
    p: &Vector3<f64>,
    q: &Vector3<f64>,
    a: &Vector3<f64>,
    u: &Vector3<f64>,
) -> f64 {
    let perp = |v: Vector3<f64>| v - u * u.dot(&v);
    let w0 = perp(p - a);
    let d = perp(q - p);
    let dd = d.norm_squared();
    let t = if dd > 0.0 {
        (-w0.dot(&d) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (w0 + d * t).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(p: [[f64; 3]; 3]) -> Tri {
        p.map(Vector3::from)
    }

    fn cyl() -> Cylinder {
        Cylinder {
            a: [0.0, 0.0, 0.0],
            b: [0.0, 0.0, 2.0],
            radius: 0.5,
        }
    }

    #[test]
    fn pierced_triangle_is_at_distance_zero() {
        let tri = t([[-1.0, -1.0, 1.0], [2.0, -1.0, 1.0], [-1.0, 2.0, 1.0]]);
        assert_eq!(cyl().slab_axis_distance(&tri), Some(0.0));
        assert!(cyl().hits(&tri, 1e-9));
    }

    #[test]
    fn triangle_beyond_the_cap_misses_even_if_near_the_axis_line() {
        // Crosses the axis line at z = 2.2, above the cap at z = 2: a capsule of radius 0.5
        // would be hit, the flat-capped cylinder is not.
        let tri = t([[-1.0, -1.0, 2.2], [2.0, -1.0, 2.2], [-1.0, 2.0, 2.2]]);
        assert_eq!(cyl().slab_axis_distance(&tri), None);
        assert!(!cyl().hits(&tri, 1e-9));
    }

    #[test]
    fn side_distance_is_exact() {
        // A vertical triangle whose nearest edge runs parallel to the axis at distance 0.7.
        let tri = t([[0.7, -1.0, 0.5], [0.7, 1.0, 0.5], [2.0, 0.0, 1.5]]);
        let d = cyl().slab_axis_distance(&tri).unwrap();
        assert!((d - 0.7).abs() < 1e-12, "{d}");
        assert!(!cyl().hits(&tri, 1e-9));
        let closer = t([[0.3, -1.0, 0.5], [0.3, 1.0, 0.5], [2.0, 0.0, 1.5]]);
        assert!(cyl().hits(&closer, 1e-9));
    }

    #[test]
    fn validation_rejects_bad_cylinders() {
        let mut c = cyl();
        c.radius = 0.0;
        assert!(c.validate().is_err());
        let mut c = cyl();
        c.b = c.a;
        assert!(c.validate().is_err());
        assert!(Cylinder::thesis_gripper().validate().is_ok());
    }

    /// The bounding-sphere shortcut of `hits` never changes its answer: random triangles
    /// of all sizes around the thesis's cylinder, against the clipped distance alone.
    #[test]
    fn hits_agrees_with_the_clipped_distance() {
        let c = Cylinder::thesis_gripper();
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
        let mut rnd = move || rng.random_range(-1.0..1.0);
        let (mut hit, mut miss) = (0, 0);
        for k in 0..20000 {
            let size = [0.05, 0.3, 1.0][k % 3];
            let o = Vector3::new(rnd(), 1.3 * rnd(), 0.5 + rnd());
            let tri: Tri = [(); 3].map(|_| o + Vector3::new(rnd(), rnd(), rnd()) * size);
            let tol = [0.0, 1e-9][k % 2];
            let exact = c
                .slab_axis_distance(&tri)
                .is_some_and(|d| d < c.radius - tol);
            assert_eq!(c.hits(&tri, tol), exact, "{tri:?}");
            hit += usize::from(exact);
            miss += usize::from(!exact);
        }
        assert!(hit > 1000 && miss > 1000, "{hit} hits, {miss} misses");
    }
}
