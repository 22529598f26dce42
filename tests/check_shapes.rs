//! The obstacle judges of `check::shapes` against analytic distances written here again
//! (projection onto the plane, point–segment distances, clamping in a box's frame) on
//! random points, triangles and boxes in any orientation; the winding number against a
//! convex polytope's own inside test.

use foldsynth::check::shapes::{
    box_clearance, box_meets_triangle, facet_clearance, halfspace_clearance, mesh_clearance,
    point_mesh_distance, sphere_clearance, winding_number,
};
use foldsynth::scene::{HalfSpace, OrientedBox, Shape, Sphere, TriangleMesh};
use nalgebra::{UnitQuaternion, Vector3};
use rand::{RngExt, SeedableRng};

type V = Vector3<f64>;
type Tri = [V; 3];

fn rng(seed: u64) -> impl FnMut() -> f64 {
    let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    move || r.random_range(-1.0..1.0)
}

/// Distance from `p` to segment `a b`.
fn seg(p: V, a: V, b: V) -> f64 {
    let ab = b - a;
    let s = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
    (p - a - ab * s).norm()
}

/// Point–triangle distance: to the plane when the foot lies inside (barycentric
/// coordinates from the normal), else to the nearest edge.
fn point_triangle(p: V, t: &Tri) -> f64 {
    let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
    let h = n.dot(&(p - t[0])) / n.norm();
    let foot = p - n.normalize() * h;
    let inside = (0..3).all(|i| {
        let (a, b) = (t[i], t[(i + 1) % 3]);
        (b - a).cross(&(foot - a)).dot(&n) >= 0.0
    });
    if inside {
        h.abs()
    } else {
        (0..3)
            .map(|i| seg(p, t[i], t[(i + 1) % 3]))
            .fold(f64::INFINITY, f64::min)
    }
}

/// Points of a barycentric grid on `t` (vertices included) and the grid's step.
fn grid(t: &Tri, n: usize) -> (Vec<V>, f64) {
    let mut out = Vec::new();
    for i in 0..=n {
        for j in 0..=n - i {
            let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
            out.push(t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v);
        }
    }
    let longest = (0..3)
        .map(|k| (t[(k + 1) % 3] - t[k]).norm())
        .fold(0.0, f64::max);
    (out, longest / n as f64)
}

fn random_tri(rnd: &mut impl FnMut() -> f64, centre: V, size: f64) -> Tri {
    [(); 3].map(|_| centre + V::new(rnd(), rnd(), rnd()) * size)
}

/// A box in a random orientation (a random unit quaternion), random centre and sizes.
fn random_box(rnd: &mut impl FnMut() -> f64) -> OrientedBox {
    let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(rnd(), rnd(), rnd(), rnd()));
    let m = q.to_rotation_matrix();
    let axes = [0, 1, 2].map(|i| {
        let c = m.matrix().column(i);
        [c[0], c[1], c[2]]
    });
    OrientedBox {
        center: [0.3 * rnd(), 0.3 * rnd(), 0.3 * rnd()],
        half: [
            0.2 + 0.6 * rnd().abs(),
            0.2 + 0.6 * rnd().abs(),
            0.2 + 0.6 * rnd().abs(),
        ],
        axes,
    }
}

/// Distance from `p` to the solid box, by clamping its local coordinates (the frame built
/// here from the axes, not the box's own `local`).
fn box_distance(b: &OrientedBox, p: V) -> f64 {
    let d = p - V::from(b.center);
    let mut s = 0.0;
    for (axis, h) in b.axes.iter().zip(&b.half) {
        let x = d.dot(&V::from(*axis));
        let c = x.clamp(-h, *h);
        s += (x - c) * (x - c);
    }
    s.sqrt()
}

#[test]
fn sphere_clearance_is_the_centre_distance_less_the_radius() {
    let mut rnd = rng(11);
    for k in 0..3000 {
        let t = random_tri(&mut rnd, V::zeros(), [0.3, 1.0, 2.0][k % 3]);
        let s = Sphere {
            center: [2.0 * rnd(), 2.0 * rnd(), 2.0 * rnd()],
            radius: 0.1 + rnd().abs(),
        };
        let want = point_triangle(V::from(s.center), &t) - s.radius;
        let got = sphere_clearance(&s, &t);
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
    // A centre on the triangle: the clearance is minus the radius (it reaches in fully).
    let t = [V::zeros(), V::x(), V::y()];
    let s = Sphere {
        center: [0.25, 0.25, 0.0],
        radius: 0.3,
    };
    assert!((sphere_clearance(&s, &t) + 0.3).abs() < 1e-15);
    let shape = Shape::Sphere(s);
    assert_eq!(
        facet_clearance(&shape, &[t]),
        Some(sphere_clearance(&s, &t))
    );
}

#[test]
fn box_clearance_agrees_with_sampling_in_any_orientation() {
    let mut rnd = rng(12);
    let (mut met, mut apart) = (0, 0);
    for k in 0..1500 {
        let b = random_box(&mut rnd);
        let centre = V::new(rnd(), rnd(), rnd()) * 1.5;
        let t = random_tri(&mut rnd, centre, [0.3, 0.8][k % 2]);
        let got = box_clearance(&b, &t);
        let (pts, step) = grid(&t, 40);
        let sampled = pts
            .iter()
            .map(|p| box_distance(&b, *p))
            .fold(f64::INFINITY, f64::min);
        // The exact distance is never above a sampled point's, and the grid comes within
        // its step of it (the distance is 1-Lipschitz).
        assert!(got <= sampled + 1e-12, "{got} > sampled {sampled}");
        assert!(sampled - got <= step, "{sampled} vs {got} (step {step})");
        // A vertex inside the box: they meet.
        if t.iter().any(|p| box_distance(&b, *p) == 0.0) {
            assert_eq!(got, 0.0);
            assert!(box_meets_triangle(&b, &t));
        }
        if got == 0.0 {
            met += 1;
        } else {
            apart += 1;
        }
    }
    assert!(met > 100 && apart > 100, "{met} met, {apart} apart");
}

#[test]
fn box_separating_axis_finds_edge_crossings() {
    // A thin triangle piercing the unit cube through two faces, no vertex inside.
    let b = OrientedBox::aligned([-1.0; 3], [1.0; 3]);
    let t = [
        V::new(-3.0, 0.0, 0.0),
        V::new(3.0, 0.1, 0.0),
        V::new(3.0, -0.1, 0.0),
    ];
    assert!(box_meets_triangle(&b, &t));
    assert_eq!(box_clearance(&b, &t), 0.0);
    // Beside a cube's edge, diagonally: the nearest points are on two parallel edges.
    let t = [
        V::new(1.2, 1.2, -3.0),
        V::new(1.2, 1.2, 3.0),
        V::new(3.0, 3.0, 0.0),
    ];
    assert!(!box_meets_triangle(&b, &t));
    assert!((box_clearance(&b, &t) - 0.2 * 2f64.sqrt()).abs() < 1e-12);
}

#[test]
fn halfspace_clearance_is_the_least_height() {
    let mut rnd = rng(13);
    for _ in 0..2000 {
        let n = V::new(rnd(), rnd(), rnd()).normalize();
        let h = HalfSpace {
            point: [rnd(), rnd(), rnd()],
            normal: [n.x, n.y, n.z],
        };
        let t = random_tri(&mut rnd, V::zeros(), 1.0);
        let (pts, _) = grid(&t, 20);
        let least = pts
            .iter()
            .map(|p| n.dot(&(p - V::from(h.point))))
            .fold(f64::INFINITY, f64::min);
        let got = halfspace_clearance(&h, &t);
        assert!((got - least).abs() < 1e-12, "{got} vs {least}");
    }
}

/// The octahedron |x| + |y| + |z| ≤ r about `c`: 8 triangles, outward.
fn octahedron(c: V, r: f64) -> TriangleMesh {
    let vertices: Vec<[f64; 3]> = [V::x(), -V::x(), V::y(), -V::y(), V::z(), -V::z()]
        .iter()
        .map(|d| {
            let p = c + d * r;
            [p.x, p.y, p.z]
        })
        .collect();
    let mut triangles = Vec::new();
    for (x, y) in [(0u32, 2u32), (2, 1), (1, 3), (3, 0)] {
        triangles.push([x, y, 4]);
        triangles.push([y, x, 5]);
    }
    TriangleMesh {
        vertices,
        triangles,
        closed: true,
    }
}

#[test]
fn winding_number_is_the_convex_inside() {
    let c = V::new(0.2, -0.1, 0.3);
    let mesh = octahedron(c, 1.0);
    let mut rnd = rng(14);
    let (mut inside, mut outside) = (0, 0);
    for _ in 0..3000 {
        let p = c + V::new(rnd(), rnd(), rnd()) * 1.2;
        let l1 = (p - c).abs().sum();
        if (l1 - 1.0).abs() < 1e-6 {
            continue;
        }
        let w = winding_number(&mesh, &p);
        let want = if l1 < 1.0 { 1.0 } else { 0.0 };
        assert!((w - want).abs() < 1e-9, "w = {w} at {p:?} (|p|₁ = {l1})");
        if l1 < 1.0 {
            inside += 1;
        } else {
            outside += 1;
        }
    }
    assert!(inside > 300 && outside > 300);
}

#[test]
fn mesh_distance_is_the_nearest_triangle() {
    let mesh = octahedron(V::zeros(), 1.0);
    let tris: Vec<Tri> = (0..mesh.triangles.len())
        .map(|i| mesh.triangle(i).map(V::from))
        .collect();
    let mut rnd = rng(15);
    for _ in 0..2000 {
        let p = V::new(rnd(), rnd(), rnd()) * 2.0;
        let want = tris
            .iter()
            .map(|t| point_triangle(p, t))
            .fold(f64::INFINITY, f64::min);
        let got = point_mesh_distance(&mesh, &p);
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
    // Facets outside: the clearance is the least distance between them and the surface,
    // within a grid's step of the sampled points' and never above it.
    for k in 0..300 {
        let centre = V::new(1.5, 0.5 * rnd(), 0.5 * rnd());
        let t = random_tri(&mut rnd, centre, [0.2, 0.5][k % 2]);
        let (pts, step) = grid(&t, 30);
        let sampled: Vec<f64> = pts.iter().map(|p| point_mesh_distance(&mesh, p)).collect();
        let least = sampled.iter().copied().fold(f64::INFINITY, f64::min);
        let got = mesh_clearance(&mesh, &[t]);
        let any_inside = t.iter().any(|p| p.abs().sum() < 1.0);
        if any_inside {
            assert!(
                got < 0.0,
                "a vertex inside gives a negative clearance: {got}"
            );
        } else {
            assert!(
                got <= least + 1e-12 && least - got <= step,
                "{got} vs {least}"
            );
        }
    }
    // A facet wholly inside the closed solid: minus its deepest vertex's depth; the same
    // facet and an open mesh (one triangle removed): only the distance, positive.
    let t = [
        V::new(0.1, 0.0, 0.0),
        V::new(0.0, 0.1, 0.0),
        V::new(0.0, 0.0, 0.1),
    ];
    let depth = (1.0 - 0.1) / 3f64.sqrt();
    assert!((mesh_clearance(&mesh, &[t]) + depth).abs() < 1e-12);
    let mut open = mesh.clone();
    open.triangles.pop();
    open.closed = false;
    let d = mesh_clearance(&open, &[t]);
    assert!((d - depth).abs() < 1e-12, "{d}");
}
