//! Exact distances between points, segments and triangles (Ericson, Real-Time Collision
//! Detection, ch. 5): what the judges of `check/` measure clearances with. Closed form and
//! independent of the optimizer's separating planes.

use nalgebra::Vector3;

use super::tri_tri::{Tri, triangles_intersect};

type V = Vector3<f64>;

/// Closest point of triangle `t` to `p` (Ericson, Real-Time Collision Detection, 5.1.5).
pub fn closest_on_triangle(p: &V, t: &Tri) -> V {
    let (a, b, c) = (t[0], t[1], t[2]);
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Distance between segments `p1 q1` and `p2 q2` (Ericson 5.1.9).
pub fn segment_distance(p1: &V, q1: &V, p2: &V, q2: &V) -> f64 {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.dot(&d1), d2.dot(&d2), d2.dot(&r));
    let eps = 1e-300;
    let (s, t) = if a <= eps && e <= eps {
        (0.0, 0.0)
    } else if a <= eps {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= eps {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    ((p1 + d1 * s) - (p2 + d2 * t)).norm()
}

/// Distance from `p` to segment `a b`.
pub fn point_segment_distance(p: &V, a: &V, b: &V) -> f64 {
    let ab = b - a;
    let l = ab.norm_squared();
    let s = if l > 0.0 {
        ((p - a).dot(&ab) / l).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * s)).norm()
}

/// Rounding allowance of the pruning bounds here and in the judges (paper units or
/// radians).
pub(super) const SLACK: f64 = 1e-12;

/// A sphere around a triangle: its centroid and the farthest corner's distance.
pub(super) fn bounding_sphere(t: &Tri) -> (V, f64) {
    let c = (t[0] + t[1] + t[2]) / 3.0;
    let r = t.iter().map(|p| (p - c).norm()).fold(0.0, f64::max);
    (c, r)
}

/// Whether everything in two bounding spheres is farther apart than `limit`: then no
/// exact distance between what they hold can come out below it.
pub(super) fn apart_beyond(a: (V, f64), b: (V, f64), limit: f64) -> bool {
    sphere_gap(a, b) > limit
}

/// A lower bound of the distance between anything in two bounding spheres (less the
/// rounding allowance): the gap between them, negative when they overlap.
pub(super) fn sphere_gap((ca, ra): (V, f64), (cb, rb): (V, f64)) -> f64 {
    (ca - cb).norm() - ra - rb - SLACK
}

/// A lower bound of the distance between two triangles (less the rounding allowance): the
/// gap between them along the line through their centroids (a projection shortens no
/// distance). Never below the gap of their bounding spheres, and often well above it.
pub(super) fn projected_gap(a: &Tri, b: &Tri) -> f64 {
    let ca = (a[0] + a[1] + a[2]) / 3.0;
    let cb = (b[0] + b[1] + b[2]) / 3.0;
    let u = cb - ca;
    let len = u.norm();
    if !len.is_normal() {
        // Coincident centroids (or a degenerate input): no direction, no bound.
        return f64::NEG_INFINITY;
    }
    let u = u / len;
    let hi_a = a.iter().map(|p| u.dot(p)).fold(f64::NEG_INFINITY, f64::max);
    let lo_b = b.iter().map(|p| u.dot(p)).fold(f64::INFINITY, f64::min);
    lo_b - hi_a - SLACK
}

/// Exact distance between two triangles (0 when they cross).
pub fn triangle_distance(a: &Tri, b: &Tri) -> f64 {
    if triangles_intersect(a, b, 0.0) {
        return 0.0;
    }
    let mut d = f64::INFINITY;
    for p in a {
        d = d.min((p - closest_on_triangle(p, b)).norm());
    }
    for p in b {
        d = d.min((p - closest_on_triangle(p, a)).norm());
    }
    for i in 0..3 {
        for j in 0..3 {
            d = d.min(segment_distance(
                &a[i],
                &a[(i + 1) % 3],
                &b[j],
                &b[(j + 1) % 3],
            ));
        }
    }
    d
}

/// Exact distance between segment `p q` and a triangle (0 when it pierces it).
pub fn segment_triangle_distance(p: &V, q: &V, t: &Tri) -> f64 {
    let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
    let (dp, dq) = (n.dot(&(p - t[0])), n.dot(&(q - t[0])));
    if dp * dq <= 0.0 && dp != dq {
        let x = p + (q - p) * (dp / (dp - dq));
        if (x - closest_on_triangle(&x, t)).norm() <= 1e-15 * (1.0 + x.norm()) {
            return 0.0;
        }
    }
    let mut d = (p - closest_on_triangle(p, t))
        .norm()
        .min((q - closest_on_triangle(q, t)).norm());
    for j in 0..3 {
        d = d.min(segment_distance(p, q, &t[j], &t[(j + 1) % 3]));
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(p: [[f64; 3]; 3]) -> Tri {
        p.map(V::from)
    }

    /// The distance between two triangles is the least distance between points of them:
    /// dense sampling of both (barycentric grid) never goes below it and comes within the
    /// grid's resolution of it.
    #[test]
    fn triangle_distance_matches_sampling() {
        let cases = [
            (
                t([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
                t([[0.2, 0.3, 0.5], [1.0, 1.0, 0.8], [-0.5, 1.0, 1.5]]),
            ),
            (
                t([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
                t([[1.5, 1.5, -1.0], [1.5, 1.5, 1.0], [3.0, 0.0, 0.0]]),
            ),
            (
                t([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]),
                t([[0.5, 0.5, 0.3], [0.6, 0.4, 2.0], [0.4, 0.7, 2.5]]),
            ),
        ];
        let n = 60;
        let pts = |tr: &Tri| -> Vec<V> {
            let mut out = Vec::new();
            for i in 0..=n {
                for j in 0..=n - i {
                    let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                    out.push(tr[0] + (tr[1] - tr[0]) * u + (tr[2] - tr[0]) * v);
                }
            }
            out
        };
        for (a, b) in &cases {
            let d = triangle_distance(a, b);
            let (pa, pb) = (pts(a), pts(b));
            let sampled = pa
                .iter()
                .flat_map(|p| pb.iter().map(move |q| (p - q).norm()))
                .fold(f64::INFINITY, f64::min);
            assert!(sampled >= d - 1e-12, "{sampled} < {d}");
            assert!(sampled - d < 0.05, "{sampled} vs {d}");
        }
        // Crossing triangles are at distance 0.
        let a = t([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
        let b = t([[0.5, 0.5, -1.0], [0.5, 0.5, 1.0], [1.5, -1.0, 0.0]]);
        assert_eq!(triangle_distance(&a, &b), 0.0);
    }

    #[test]
    fn segment_triangle_distance_is_exact() {
        let tri = t([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        // Parallel above the interior.
        let d = segment_triangle_distance(&V::new(0.1, 0.1, 0.3), &V::new(0.3, 0.1, 0.3), &tri);
        assert!((d - 0.3).abs() < 1e-15);
        // Piercing.
        let d = segment_triangle_distance(&V::new(0.2, 0.2, -1.0), &V::new(0.2, 0.2, 1.0), &tri);
        assert_eq!(d, 0.0);
        // Beyond an edge: closest to the edge x + y = 1 from (1, 1, 0) along z.
        let d = segment_triangle_distance(&V::new(1.0, 1.0, -1.0), &V::new(1.0, 1.0, 1.0), &tri);
        assert!((d - 0.5_f64.sqrt()).abs() < 1e-15, "{d}");
    }

    /// The spheres' gap is a lower bound of the triangles' distance (what lets the judges
    /// skip a pair): checked on a grid of placements of a second triangle around the first.
    #[test]
    fn sphere_and_projected_gaps_never_exceed_triangle_distance() {
        let a = t([[0.0, 0.0, 0.0], [1.0, 0.2, 0.1], [0.3, 1.0, -0.2]]);
        let b0 = [
            V::new(0.0, 0.0, 0.0),
            V::new(0.4, -0.3, 0.5),
            V::new(-0.2, 0.6, 0.3),
        ];
        let (mut skipped, mut tighter) = (0, 0);
        for i in -3..=3 {
            for j in -3..=3 {
                for k in -3..=3 {
                    let off = V::new(i as f64, j as f64, k as f64) * 0.7;
                    let b = b0.map(|p| p + off);
                    let (sa, sb) = (bounding_sphere(&a), bounding_sphere(&b));
                    let d = triangle_distance(&a, &b);
                    let gap = (sa.0 - sb.0).norm() - sa.1 - sb.1;
                    assert!(gap <= d + 1e-15, "{gap} > {d}");
                    // The projection onto the centroids' line: between the two.
                    let proj = projected_gap(&a, &b);
                    assert!(proj <= d && proj >= sphere_gap(sa, sb), "{proj}, {d}");
                    tighter += usize::from(proj > gap + 1e-3);
                    if apart_beyond(sa, sb, 0.5) {
                        skipped += 1;
                        assert!(d > 0.5);
                    }
                }
            }
        }
        assert!(skipped > 0 && tighter > 0);
    }
}
