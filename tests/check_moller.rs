//! Möller's triangle–triangle test: known cases, an independent oracle, and invariance.

use foldsynth::check::{DEFAULT_TOL, triangles_intersect};
use nalgebra::{Rotation3, Unit, Vector3};
use proptest::prelude::*;

type Tri = [Vector3<f64>; 3];

fn tri(p: [[f64; 3]; 3]) -> Tri {
    p.map(Vector3::from)
}

fn moved(t: &Tri, r: &Rotation3<f64>, shift: &Vector3<f64>) -> Tri {
    t.map(|p| r * p + shift)
}

/// Where segment p→q crosses the plane of `t` strictly inside `t`, with the smallest
/// distance of the crossing to the triangle's boundary and to the segment's ends
/// (both as margins; None when the segment does not cross the plane).
fn pierce(p: &Vector3<f64>, q: &Vector3<f64>, t: &Tri) -> Option<(bool, f64)> {
    let n = (t[1] - t[0]).cross(&(t[2] - t[0])).normalize();
    let (dp, dq) = (n.dot(&(p - t[0])), n.dot(&(q - t[0])));
    if dp * dq > 0.0 {
        return None;
    }
    let s = dp / (dp - dq);
    let x = p + (q - p) * s;
    let edge_margin = (0..3)
        .map(|i| {
            let e = t[(i + 1) % 3] - t[i];
            e.cross(&(x - t[i])).dot(&n) / e.norm()
        })
        .fold(f64::INFINITY, f64::min);
    let end_margin = dp.abs().min(dq.abs());
    Some((edge_margin > 0.0, edge_margin.abs().min(end_margin)))
}

/// Independent oracle for triangles in general position: two non-coplanar triangles
/// intersect exactly when an edge of one passes through the interior of the other.
/// Returns None when the configuration is too close to degenerate to decide robustly.
fn oracle(a: &Tri, b: &Tri) -> Option<bool> {
    let mut hit = false;
    for (s, t) in [(a, b), (b, a)] {
        for i in 0..3 {
            if let Some((inside, margin)) = pierce(&s[i], &s[(i + 1) % 3], t) {
                if margin < 1e-6 {
                    return None;
                }
                hit |= inside;
            }
        }
    }
    // Vertices too close to the other plane make "edge crosses plane" ambiguous too.
    for (s, t) in [(a, b), (b, a)] {
        let n = (t[1] - t[0]).cross(&(t[2] - t[0])).normalize();
        if s.iter().any(|p| n.dot(&(p - t[0])).abs() < 1e-6) {
            return None;
        }
    }
    Some(hit)
}

fn v3() -> impl Strategy<Value = Vector3<f64>> {
    (-2.0..2.0f64, -2.0..2.0f64, -2.0..2.0f64).prop_map(|(x, y, z)| Vector3::new(x, y, z))
}

fn triangle() -> impl Strategy<Value = Tri> {
    (v3(), v3(), v3())
        .prop_map(|(a, b, c)| [a, b, c])
        .prop_filter("not too thin", |t| {
            let area = (t[1] - t[0]).cross(&(t[2] - t[0])).norm();
            let longest = (0..3)
                .map(|i| (t[(i + 1) % 3] - t[i]).norm())
                .fold(0.0, f64::max);
            area > 0.05 * longest * longest
        })
}

fn rigid_motion() -> impl Strategy<Value = (Rotation3<f64>, Vector3<f64>)> {
    (v3(), -PI..PI, v3()).prop_filter_map("axis", |(axis, angle, shift)| {
        (axis.norm() > 0.1).then(|| {
            (
                Rotation3::from_axis_angle(&Unit::new_normalize(axis), angle),
                shift * 10.0,
            )
        })
    })
}

use std::f64::consts::PI;

#[test]
fn known_cases() {
    let a = tri([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]);
    let pierce = tri([[0.5, 0.5, -1.0], [0.6, 0.4, 1.0], [2.0, 2.0, 0.5]]);
    assert!(triangles_intersect(&a, &pierce, DEFAULT_TOL));
    // A vertical triangle standing in a's interior and reaching past its hypotenuse.
    let b = tri([[0.5, 0.2, -1.0], [0.5, 0.2, 1.0], [0.5, 3.0, 0.0]]);
    assert!(triangles_intersect(&a, &b, DEFAULT_TOL));
    // Separated by a plane.
    let above = tri([[0.0, 0.0, 0.1], [2.0, 0.0, 0.3], [0.0, 2.0, 0.2]]);
    assert!(!triangles_intersect(&a, &above, DEFAULT_TOL));
    // Planes cross but the triangles miss each other on the common line.
    let miss = tri([[3.0, 0.0, -1.0], [3.0, 0.0, 1.0], [3.0, 1.0, 0.0]]);
    assert!(!triangles_intersect(&a, &miss, DEFAULT_TOL));
    // Coplanar: overlapping, contained, disjoint, sharing an edge, sharing a vertex.
    let over = tri([[1.0, 1.0, 0.0], [3.0, 1.0, 0.0], [1.0, 3.0, 0.0]]);
    assert!(
        !triangles_intersect(&a, &over, DEFAULT_TOL),
        "touches a's hypotenuse at one point only"
    );
    let over = tri([[0.5, 0.5, 0.0], [3.0, 0.5, 0.0], [0.5, 3.0, 0.0]]);
    assert!(triangles_intersect(&a, &over, DEFAULT_TOL));
    let inside = tri([[0.1, 0.1, 0.0], [0.5, 0.1, 0.0], [0.1, 0.5, 0.0]]);
    assert!(triangles_intersect(&a, &inside, DEFAULT_TOL));
    let apart = tri([[3.0, 3.0, 0.0], [4.0, 3.0, 0.0], [3.0, 4.0, 0.0]]);
    assert!(!triangles_intersect(&a, &apart, DEFAULT_TOL));
    let edge = tri([[2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0]]);
    assert!(!triangles_intersect(&a, &edge, DEFAULT_TOL));
    let corner = tri([[0.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]);
    assert!(!triangles_intersect(&a, &corner, DEFAULT_TOL));
    // Folded neighbours across a crease, at any angle, only touch.
    for k in 1..12 {
        let r = k as f64 * 0.25;
        let folded = tri([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, -r.cos(), r.sin()]]);
        assert!(!triangles_intersect(&a, &folded, DEFAULT_TOL), "fold {r}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, failure_persistence: None, ..ProptestConfig::default() })]

    /// In general position Möller agrees with the edge-piercing oracle.
    #[test]
    fn agrees_with_edge_piercing(a in triangle(), b in triangle()) {
        if let Some(want) = oracle(&a, &b) {
            prop_assert_eq!(triangles_intersect(&a, &b, DEFAULT_TOL), want);
        }
    }

    /// The verdict does not depend on the order of the arguments or on where the pair is.
    #[test]
    fn invariant_under_rigid_motion_and_swap(a in triangle(), b in triangle(), m in rigid_motion()) {
        if oracle(&a, &b).is_some() {
            let (r, s) = m;
            let want = triangles_intersect(&a, &b, DEFAULT_TOL);
            prop_assert_eq!(triangles_intersect(&b, &a, DEFAULT_TOL), want);
            prop_assert_eq!(triangles_intersect(&moved(&a, &r, &s), &moved(&b, &r, &s), DEFAULT_TOL), want);
        }
    }

    /// A triangle pushed through another at an interior point intersects it, wherever the
    /// pair is; lifted clear of the other's plane it does not.
    #[test]
    fn constructed_piercing_and_separation(a in triangle(), w in (0.05..0.45f64, 0.05..0.45f64), dir in v3(), m in rigid_motion()) {
        let (u, v) = w;
        let n = (a[1] - a[0]).cross(&(a[2] - a[0])).normalize();
        let p = a[0] + (a[1] - a[0]) * u + (a[2] - a[0]) * v;
        let side = dir - n * n.dot(&dir);
        prop_assume!(side.norm() > 0.1);
        let b = [p + n * 0.5, p - n * 0.5, p + side.normalize() * 2.0];
        let (r, s) = m;
        prop_assert!(triangles_intersect(&moved(&a, &r, &s), &moved(&b, &r, &s), DEFAULT_TOL));
        let lifted = b.map(|q| q + n * 0.6);
        prop_assert!(!triangles_intersect(&moved(&a, &r, &s), &moved(&lifted, &r, &s), DEFAULT_TOL));
    }

    /// Coplanar pairs: a copy shifted within the plane by less than its inradius overlaps;
    /// shifted by more than both triangles' extent it does not — after any rigid motion.
    #[test]
    fn coplanar_overlap_and_disjoint(a in triangle(), dir in v3(), m in rigid_motion()) {
        let n = (a[1] - a[0]).cross(&(a[2] - a[0])).normalize();
        let side = dir - n * n.dot(&dir);
        prop_assume!(side.norm() > 0.1);
        let side = side.normalize();
        let perim: f64 = (0..3).map(|i| (a[(i + 1) % 3] - a[i]).norm()).sum();
        let area = 0.5 * (a[1] - a[0]).cross(&(a[2] - a[0])).norm();
        let inradius = 2.0 * area / perim;
        let (r, s) = m;
        let near = a.map(|q| q + side * (0.5 * inradius));
        prop_assert!(triangles_intersect(&moved(&a, &r, &s), &moved(&near, &r, &s), DEFAULT_TOL));
        let far = a.map(|q| q + side * (perim + 1.0));
        prop_assert!(!triangles_intersect(&moved(&a, &r, &s), &moved(&far, &r, &s), DEFAULT_TOL));
    }
}

/// The oracle comparison over many seeded random pairs, counting both verdicts so the
/// agreement is not carried by one kind of case alone.
#[test]
fn agrees_with_edge_piercing_on_both_verdicts() {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut p = || {
        Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
    };
    let (mut yes, mut no) = (0, 0);
    for _ in 0..20000 {
        let a = [p(), p(), p()];
        let b = [p(), p(), p()];
        if let Some(want) = oracle(&a, &b) {
            assert_eq!(
                triangles_intersect(&a, &b, DEFAULT_TOL),
                want,
                "{a:?} {b:?}"
            );
            if want { yes += 1 } else { no += 1 }
        }
    }
    assert!(yes > 1000 && no > 1000, "{yes} intersecting, {no} apart");
}
