//! Surface goals: the distance of a point from a triangle mesh, for targets that want a
//! vertex on a part's surface. A mesh cannot be written in the expression graph, so the
//! compiled model exports the vertex's position (with its gradient rows) and this is
//! evaluated beside it: the squared distance to the nearest triangle, whose gradient with
//! respect to the point is `2 (x − q)` at the nearest point `q` (Danskin's theorem: the
//! minimum over triangles is differentiable wherever the nearest point is unique, with the
//! gradient of the active piece).
//!
//! The search is brute force over the triangles (the mesh limit is 20,000), each skipped
//! when its bounding sphere is already farther than the nearest triangle so far.

use std::sync::Arc;

use crate::geom::{V3, add, dot, norm, scale, sub};
use crate::scene::TriangleMesh;

/// A mesh prepared for nearest-point queries: its triangles' corners and bounding spheres.
#[derive(Clone, Debug)]
pub struct Surface {
    /// The mesh, as the task loaded it (scaled and translated).
    pub mesh: Arc<TriangleMesh>,
    /// Per triangle: its corners.
    corners: Vec<[V3; 3]>,
    /// Per triangle: a sphere around it (centroid, farthest corner).
    spheres: Vec<(V3, f64)>,
}

/// The nearest point of a surface to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// The squared distance.
    pub d2: f64,
    /// The nearest point.
    pub point: V3,
    /// The triangle it lies on.
    pub triangle: usize,
}

impl Surface {
    /// Prepare `mesh`.
    pub fn new(mesh: Arc<TriangleMesh>) -> Surface {
        let corners: Vec<[V3; 3]> = (0..mesh.triangles.len())
            .map(|i| mesh.triangle(i))
            .collect();
        let spheres = corners
            .iter()
            .map(|t| {
                let c = scale(add(add(t[0], t[1]), t[2]), 1.0 / 3.0);
                let r = t.iter().map(|p| norm(sub(*p, c))).fold(0.0, f64::max);
                (c, r)
            })
            .collect();
        Surface {
            mesh,
            corners,
            spheres,
        }
    }

    /// The nearest point of the mesh to `x` (`None` for a mesh without triangles). Ties
    /// keep the first triangle.
    pub fn nearest(&self, x: V3) -> Option<Nearest> {
        let mut best: Option<Nearest> = None;
        for (i, t) in self.corners.iter().enumerate() {
            if let Some(b) = &best {
                // No point of the triangle is nearer than its sphere.
                let (c, r) = self.spheres[i];
                let gap = norm(sub(x, c)) - r;
                if gap > 0.0 && gap * gap >= b.d2 {
                    continue;
                }
            }
            let q = closest_on_triangle(x, t);
            let d = sub(x, q);
            let d2 = dot(d, d);
            if best.is_none_or(|b| d2 < b.d2) {
                best = Some(Nearest {
                    d2,
                    point: q,
                    triangle: i,
                });
            }
        }
        best
    }
}

/// The point of triangle `t` nearest to `p` (Ericson, *Real-Time Collision Detection*,
/// 5.1.5: the Voronoi regions of the corners, the edges and the face, in barycentric
/// terms).
pub fn closest_on_triangle(p: V3, t: &[V3; 3]) -> V3 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return add(a, scale(ab, d1 / (d1 - d3)));
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return add(a, scale(ac, d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return add(b, scale(sub(c, b), w));
    }
    let denom = va + vb + vc;
    if denom == 0.0 {
        // A degenerate (zero-area) triangle whose regions did not catch p: its nearest
        // point is on one of its edges.
        return [(a, b), (b, c), (c, a)]
            .iter()
            .map(|&(u, v)| closest_on_segment(p, u, v))
            .min_by(|x, y| dot(sub(p, *x), sub(p, *x)).total_cmp(&dot(sub(p, *y), sub(p, *y))))
            .expect("three edges");
    }
    let (v, w) = (vb / denom, vc / denom);
    add(a, add(scale(ab, v), scale(ac, w)))
}

/// The point of the segment `a b` nearest to `p`.
fn closest_on_segment(p: V3, a: V3, b: V3) -> V3 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    if l2 == 0.0 {
        return a;
    }
    let s = (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0);
    add(a, scale(ab, s))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nearest point by dense sampling of the triangle's barycentric coordinates.
    fn sampled(p: V3, t: &[V3; 3]) -> f64 {
        let n = 400;
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=(n - i) {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let q = add(
                    t[0],
                    add(scale(sub(t[1], t[0]), u), scale(sub(t[2], t[0]), v)),
                );
                best = best.min(norm(sub(p, q)));
            }
        }
        best
    }

    #[test]
    fn closest_point_agrees_with_sampling_in_every_region() {
        let t = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.5, 1.5, 0.0]];
        // Points over the face, beyond each corner and each edge, above and below.
        let points = [
            [0.7, 0.4, 0.8],
            [-1.0, -1.0, 0.3],
            [3.0, -0.5, -0.2],
            [0.5, 2.5, 0.1],
            [1.0, -1.0, 0.5],
            [1.6, 1.2, -0.4],
            [-0.5, 0.9, 0.0],
        ];
        for p in points {
            let q = closest_on_triangle(p, &t);
            let d = norm(sub(p, q));
            let s = sampled(p, &t);
            // Sampling finds a point at most one grid step (≈ 0.005) farther.
            assert!(d <= s + 1e-12 && s - d < 6e-3, "{p:?}: {d} vs sampled {s}");
        }
    }

    #[test]
    fn the_sphere_cull_keeps_the_nearest_triangle() {
        // A strip of triangles along x; the nearest one to points above it.
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..40 {
            let x = i as f64 * 0.25;
            vertices.push([x, 0.0, (x * 0.7).sin()]);
            vertices.push([x, 1.0, (x * 0.7).sin()]);
        }
        for i in 0..39u32 {
            triangles.push([2 * i, 2 * i + 2, 2 * i + 1]);
            triangles.push([2 * i + 1, 2 * i + 2, 2 * i + 3]);
        }
        let mesh = TriangleMesh {
            vertices,
            triangles,
            closed: false,
        };
        let s = Surface::new(Arc::new(mesh));
        for k in 0..30 {
            let p = [
                k as f64 * 0.33 - 0.5,
                0.3 + 0.02 * k as f64,
                0.5 - 0.04 * k as f64,
            ];
            let brute = s
                .corners
                .iter()
                .map(|t| {
                    let d = sub(p, closest_on_triangle(p, t));
                    dot(d, d)
                })
                .fold(f64::INFINITY, f64::min);
            let n = s.nearest(p).expect("triangles");
            assert_eq!(n.d2, brute, "{p:?}");
        }
    }
}
