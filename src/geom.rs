//! Small geometry kernel shared by verification, export and FOLD reading: vectors, face
//! normals, signed fold angles, corner angles, and faces of a planar straight-line graph.
//! (Facet triangulation lives with the intersection checks, `check::triangulate`.)
//!
//! ## The fold-angle sign
//!
//! Faces are counter-clockwise in the flat state, so their right-hand normals point to +z
//! there. Take a crease from vertex `a` to vertex `b` and call L the face that traverses
//! `a → b` (the edge has L on its left) and R the face that traverses `b → a`. With unit
//! normals n_L, n_R and e = (b − a)/|b − a| in the folded state,
//!
//! ```text
//! ρ = atan2((n_R × n_L) · e, n_L · n_R)        (radians, in (−π, π])
//! ```
//!
//! Why this sign is "valley positive": keep R fixed (n_R = +z) and turn L about e by +ρ
//! (right-hand rule). For e = +x the left side (+y) rises toward +z, the two faces turn
//! their front sides toward each other: a valley (FOLD: "a valley crease points the two
//! face normals into each other"). Then n_L = (0, −sin ρ, cos ρ), n_R × n_L = (sin ρ, 0, 0),
//! so (n_R × n_L)·e = sin ρ and n_L·n_R = cos ρ: the formula returns +ρ. It does not depend
//! on which face is held fixed (only relative rotation about e enters), and swapping the
//! edge direction swaps L and R and negates e, which leaves ρ unchanged.

/// A 3D vector.
pub type V3 = [f64; 3];

/// a − b.
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// a + b.
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// s · a.
pub fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Dot product.
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product.
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Euclidean length.
pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

/// Distance between two points.
pub fn dist(a: V3, b: V3) -> f64 {
    norm(sub(a, b))
}

/// The largest of `xs` (0 for none), NaN if any is NaN: `f64::max` would drop a NaN and
/// let a failed comparison pass.
pub fn max_or_nan(xs: impl IntoIterator<Item = f64>) -> f64 {
    xs.into_iter().fold(0.0, |m: f64, x| {
        if x.is_nan() || m.is_nan() {
            f64::NAN
        } else {
            m.max(x)
        }
    })
}

/// a / |a|, or `None` for a zero vector.
pub fn normalize(a: V3) -> Option<V3> {
    let n = norm(a);
    (n > 0.0 && n.is_finite()).then(|| scale(a, 1.0 / n))
}

/// Newell's normal of a polygon: its direction follows the right-hand rule of the vertex
/// order and its length is twice the (vector) area. Robust for non-convex polygons.
pub fn newell_normal(pts: &[V3]) -> V3 {
    let mut n = [0.0; 3];
    for i in 0..pts.len() {
        let p = pts[i];
        let q = pts[(i + 1) % pts.len()];
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    n
}

/// Signed area of a 2D polygon (positive when counter-clockwise).
pub fn signed_area_2d(pts: &[[f64; 2]]) -> f64 {
    let mut s = 0.0;
    for i in 0..pts.len() {
        let p = pts[i];
        let q = pts[(i + 1) % pts.len()];
        s += p[0] * q[1] - q[0] * p[1];
    }
    0.5 * s
}

/// Signed fold angle (radians, valley positive) of the crease `a → b` between the face
/// `left` (traversing a → b) and the face `right` (traversing b → a); see the module docs.
/// `None` when a face or the crease is degenerate (zero normal or zero length).
pub fn fold_angle(a: V3, b: V3, left: &[V3], right: &[V3]) -> Option<f64> {
    let nl = normalize(newell_normal(left))?;
    let nr = normalize(newell_normal(right))?;
    let e = normalize(sub(b, a))?;
    Some(dot(cross(nr, nl), e).atan2(dot(nl, nr)))
}

/// The interior angle at `v` of a polygon whose boundary runs `prev → v → next` counter-
/// clockwise about `normal`: the angle from (next − v) to (prev − v), in [0, 2π).
pub fn corner_angle(prev: V3, v: V3, next: V3, normal: V3) -> f64 {
    let a = sub(next, v);
    let b = sub(prev, v);
    let s = dot(cross(a, b), normal);
    let c = dot(a, b) * norm(normal);
    let ang = s.atan2(c);
    if ang < 0.0 {
        ang + std::f64::consts::TAU
    } else {
        ang
    }
}

/// Rotation of `p` by `angle` (right-hand rule) about the axis through the origin along
/// the unit vector `axis` (Rodrigues' formula).
pub fn rotate(p: V3, axis: V3, angle: f64) -> V3 {
    let (s, c) = angle.sin_cos();
    let kxp = cross(axis, p);
    let kdp = dot(axis, p);
    [
        p[0] * c + kxp[0] * s + axis[0] * kdp * (1.0 - c),
        p[1] * c + kxp[1] * s + axis[1] * kdp * (1.0 - c),
        p[2] * c + kxp[2] * s + axis[2] * kdp * (1.0 - c),
    ]
}

/// Faces of a planar straight-line graph: every bounded face, counter-clockwise, found by
/// walking half-edges (at each vertex turn to the neighbour just clockwise of where we
/// came from). The unbounded face (clockwise) is dropped, and so is any face all of whose
/// sides are in `boundary` when there is more than one face (a hole in the sheet).
pub fn faces_of_planar_graph(
    coords: &[[f64; 2]],
    edges: &[[usize; 2]],
    boundary: &[bool],
) -> Result<Vec<Vec<usize>>, String> {
    use std::collections::HashMap;
    let n = coords.len();
    let mut nbrs: Vec<Vec<usize>> = vec![Vec::new(); n];
    for e in edges {
        if !nbrs[e[0]].contains(&e[1]) {
            nbrs[e[0]].push(e[1]);
            nbrs[e[1]].push(e[0]);
        }
    }
    for (v, list) in nbrs.iter_mut().enumerate() {
        let p = coords[v];
        list.sort_by(|&a, &b| {
            let ta = (coords[a][1] - p[1]).atan2(coords[a][0] - p[0]);
            let tb = (coords[b][1] - p[1]).atan2(coords[b][0] - p[0]);
            ta.total_cmp(&tb)
        });
    }
    let mut is_boundary: HashMap<(usize, usize), bool> = HashMap::new();
    for (e, &b) in edges.iter().zip(boundary) {
        is_boundary.insert((e[0].min(e[1]), e[0].max(e[1])), b);
    }
    let mut used: HashMap<(usize, usize), bool> = HashMap::new();
    let mut faces = Vec::new();
    for u in 0..n {
        for &v in &nbrs[u] {
            if used.contains_key(&(u, v)) {
                continue;
            }
            // Follow half-edges until the walk returns to (u, v): the rotation system
            // makes "next half-edge" a permutation, so every walk closes.
            let mut face = Vec::new();
            let (mut a, mut b) = (u, v);
            loop {
                used.insert((a, b), true);
                face.push(a);
                if face.len() > 2 * edges.len() + 2 {
                    return Err("face walk did not close (graph not planar?)".into());
                }
                // Next half-edge: at b, the neighbour preceding a in ccw order.
                let list = &nbrs[b];
                let pos = list
                    .iter()
                    .position(|&w| w == a)
                    .ok_or("broken adjacency")?;
                let w = list[(pos + list.len() - 1) % list.len()];
                (a, b) = (b, w);
                if (a, b) == (u, v) {
                    break;
                }
            }
            faces.push(face);
        }
    }
    let ccw: Vec<Vec<usize>> = faces
        .into_iter()
        .filter(|f| {
            let pts: Vec<[f64; 2]> = f.iter().map(|&i| coords[i]).collect();
            f.len() >= 3 && signed_area_2d(&pts) > 0.0
        })
        .collect();
    if ccw.len() <= 1 {
        return Ok(ccw);
    }
    Ok(ccw
        .into_iter()
        .filter(|f| {
            !(0..f.len()).all(|i| {
                let (a, b) = (f[i], f[(i + 1) % f.len()]);
                is_boundary
                    .get(&(a.min(b), a.max(b)))
                    .copied()
                    .unwrap_or(false)
            })
        })
        .collect())
}

/// The least-squares plane of a point set: through the centroid, normal along the
/// covariance's eigenvector of the smallest eigenvalue (unit length, sign arbitrary).
/// `None` for fewer than three points or points on one line or point.
pub fn fit_plane(points: &[V3]) -> Option<(V3, V3)> {
    if points.len() < 3 {
        return None;
    }
    let n = points.len() as f64;
    let c = scale(points.iter().fold([0.0; 3], |a, &p| add(a, p)), 1.0 / n);
    let mut m = nalgebra::Matrix3::<f64>::zeros();
    for p in points {
        let d = nalgebra::Vector3::from(sub(*p, c));
        m += d * d.transpose();
    }
    if !m.iter().all(|x| x.is_finite()) {
        return None;
    }
    let eig = nalgebra::SymmetricEigen::new(m);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    // Points on a line (two vanishing eigenvalues) span no plane.
    if eig.eigenvalues[order[1]] <= f64::EPSILON * eig.eigenvalues[order[2]].abs() {
        return None;
    }
    let v = eig.eigenvectors.column(order[0]);
    normalize([v[0], v[1], v[2]]).map(|nrm| (c, nrm))
}

/// 2D cross product (z component of (a, 0) × (b, 0)).
pub fn cross_2d(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Whether the closed segments `p0 p1` and `q0 q1` share a point (touching counts).
pub fn segments_meet_2d(p0: [f64; 2], p1: [f64; 2], q0: [f64; 2], q1: [f64; 2]) -> bool {
    let d = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        cross_2d([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]])
    };
    let on = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        c[0] >= a[0].min(b[0])
            && c[0] <= a[0].max(b[0])
            && c[1] >= a[1].min(b[1])
            && c[1] <= a[1].max(b[1])
    };
    let (d1, d2) = (d(q0, q1, p0), d(q0, q1, p1));
    let (d3, d4) = (d(p0, p1, q0), d(p0, p1, q1));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && on(q0, q1, p0))
        || (d2 == 0.0 && on(q0, q1, p1))
        || (d3 == 0.0 && on(p0, p1, q0))
        || (d4 == 0.0 && on(p0, p1, q1))
}

/// Whether a closed polygon is simple: no two non-adjacent sides meet.
pub fn polygon_is_simple_2d(pts: &[[f64; 2]]) -> bool {
    let n = pts.len();
    for i in 0..n {
        for j in i + 1..n {
            let adjacent = j == i + 1 || (i == 0 && j == n - 1);
            if !adjacent && segments_meet_2d(pts[i], pts[(i + 1) % n], pts[j], pts[(j + 1) % n]) {
                return false;
            }
        }
    }
    true
}

/// Triangles of a simple counter-clockwise polygon by ear clipping, as index triples into
/// `pts`, each counter-clockwise; `None` when no ear is found (not simple or not ccw).
/// Collinear corners are clipped as flat ears, so every side of the polygon is a side of
/// exactly one triangle (what a closed mesh needs).
pub fn triangulate_2d(pts: &[[f64; 2]]) -> Option<Vec<[usize; 3]>> {
    let mut idx: Vec<usize> = (0..pts.len()).collect();
    let mut out = Vec::with_capacity(pts.len().saturating_sub(2));
    let sub2 = |a: [f64; 2], b: [f64; 2]| [a[0] - b[0], a[1] - b[1]];
    while idx.len() > 3 {
        let m = idx.len();
        let ear = (0..m).find(|&k| {
            let (a, b, c) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            let turn = cross_2d(sub2(pts[b], pts[a]), sub2(pts[c], pts[b]));
            turn >= 0.0
                && idx.iter().all(|&q| {
                    q == a || q == b || q == c || {
                        let p = pts[q];
                        let s1 = cross_2d(sub2(pts[b], pts[a]), sub2(p, pts[a]));
                        let s2 = cross_2d(sub2(pts[c], pts[b]), sub2(p, pts[b]));
                        let s3 = cross_2d(sub2(pts[a], pts[c]), sub2(p, pts[c]));
                        // Strictly outside, or on the ear's new diagonal's far side.
                        s1 < 0.0 || s2 < 0.0 || s3 < 0.0 || turn == 0.0
                    }
                })
        })?;
        let (a, b, c) = (idx[(ear + m - 1) % m], idx[ear], idx[(ear + 1) % m]);
        out.push([a, b, c]);
        idx.remove(ear);
    }
    if idx.len() == 3 {
        out.push([idx[0], idx[1], idx[2]]);
    }
    Some(out)
}

/// The point where the lines `p + s·u` and `q + r·w` cross, or `None` when they are
/// parallel (|u × w| ≤ 1e-12·|u||w|).
pub fn line_intersection_2d(
    p: [f64; 2],
    u: [f64; 2],
    q: [f64; 2],
    w: [f64; 2],
) -> Option<[f64; 2]> {
    let den = cross_2d(u, w);
    let size = (u[0].hypot(u[1])) * (w[0].hypot(w[1]));
    if den.abs() <= 1e-12 * size || !den.is_finite() {
        return None;
    }
    let s = cross_2d([q[0] - p[0], q[1] - p[1]], w) / den;
    Some([p[0] + s * u[0], p[1] + s * u[1]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    #[test]
    fn max_or_nan_keeps_a_nan() {
        assert_eq!(super::max_or_nan([1.0, 3.0, 2.0]), 3.0);
        assert!(super::max_or_nan([1.0, f64::NAN, 2.0]).is_nan());
        // What f64::max would have said.
        assert_eq!([1.0, f64::NAN, 2.0].into_iter().fold(0.0, f64::max), 2.0);
        assert_eq!(super::max_or_nan(std::iter::empty()), 0.0);
    }

    #[test]
    fn fit_plane_finds_a_tilted_plane() {
        let n = super::normalize([1.0, -2.0, 2.0]).unwrap();
        let (u, v) = ([2.0, 1.0, 0.0], [0.0, 1.0, 1.0]);
        let pts: Vec<[f64; 3]> = (0..12)
            .map(|k| {
                let (a, b) = ((k % 4) as f64, (k / 4) as f64);
                super::add(
                    [0.5, 0.25, -1.0],
                    super::add(super::scale(u, a), super::scale(v, b)),
                )
            })
            .collect();
        let (c, m) = super::fit_plane(&pts).unwrap();
        assert!((super::dot(m, n).abs() - 1.0).abs() < 1e-12);
        for p in &pts {
            assert!(super::dot(super::sub(*p, c), m).abs() < 1e-12);
        }
        // Points on a line span no plane.
        assert!(super::fit_plane(&[[0.0; 3], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]]).is_none());
    }

    /// Square [0,2]×[−1,1] cut by the crease (0,0)→(2,0); left face y ≥ 0.
    fn two_faces(left_up: V3, right_up: V3) -> (Vec<V3>, Vec<V3>) {
        // Left face ccw: a=(0,0), b=(2,0), (2,1), (0,1) mapped to 3D.
        let a = [0.0, 0.0, 0.0];
        let b = [2.0, 0.0, 0.0];
        let left = vec![a, b, add(b, left_up), add(a, left_up)];
        // Right face ccw: b, a, (0,-1), (2,-1).
        let right = vec![b, a, add(a, right_up), add(b, right_up)];
        (left, right)
    }

    #[test]
    fn flat_is_zero() {
        let (l, r) = two_faces([0.0, 1.0, 0.0], [0.0, -1.0, 0.0]);
        let rho = fold_angle([0.0; 3], [2.0, 0.0, 0.0], &l, &r).unwrap();
        assert!(rho.abs() < 1e-15);
    }

    #[test]
    fn both_faces_rising_is_valley() {
        let s = (PI / 4.0).sin();
        let c = (PI / 4.0).cos();
        // Left face turned up by 45°, right face up by 45°: valley of 90°.
        let (l, r) = two_faces([0.0, c, s], [0.0, -c, s]);
        let rho = fold_angle([0.0; 3], [2.0, 0.0, 0.0], &l, &r).unwrap();
        assert!((rho - FRAC_PI_2).abs() < 1e-14, "{rho}");
        // Both falling: mountain of 90°.
        let (l, r) = two_faces([0.0, c, -s], [0.0, -c, -s]);
        let rho = fold_angle([0.0; 3], [2.0, 0.0, 0.0], &l, &r).unwrap();
        assert!((rho + FRAC_PI_2).abs() < 1e-14, "{rho}");
    }

    #[test]
    fn one_face_fixed_large_angles() {
        for deg in [-170.0f64, -150.0, -30.0, 10.0, 120.0, 150.0, 179.0] {
            let r = deg.to_radians();
            // Right face fixed; left face's free side at (0, cos ρ, sin ρ).
            let (l, rt) = two_faces([0.0, r.cos(), r.sin()], [0.0, -1.0, 0.0]);
            let rho = fold_angle([0.0; 3], [2.0, 0.0, 0.0], &l, &rt).unwrap();
            assert!((rho - r).abs() < 1e-14, "{deg}: {}", rho.to_degrees());
            // Reversing the edge direction swaps the faces' roles: same angle.
            let rho2 = fold_angle([2.0, 0.0, 0.0], [0.0; 3], &rt, &l).unwrap();
            assert!((rho2 - r).abs() < 1e-14);
        }
    }

    #[test]
    fn rigid_motion_does_not_change_the_angle() {
        let r = 1.1f64;
        let (l, rt) = two_faces([0.0, r.cos(), r.sin()], [0.0, -1.0, 0.0]);
        let axis = normalize([0.3, -0.5, 0.8]).unwrap();
        let m = |p: V3| add(rotate(p, axis, 2.3), [5.0, -1.0, 0.25]);
        let l2: Vec<V3> = l.iter().map(|&p| m(p)).collect();
        let r2: Vec<V3> = rt.iter().map(|&p| m(p)).collect();
        let rho = fold_angle(m([0.0; 3]), m([2.0, 0.0, 0.0]), &l2, &r2).unwrap();
        assert!((rho - r).abs() < 1e-13);
    }

    #[test]
    fn corner_angles_of_non_convex_polygon_sum_up() {
        // An L-shape (ccw): interior angles sum to (n − 2)π, one of them 3π/2.
        let p: Vec<V3> = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ]
        .iter()
        .map(|q| [q[0], q[1], 0.0])
        .collect();
        let n = newell_normal(&p);
        let angles: Vec<f64> = (0..6)
            .map(|i| corner_angle(p[(i + 5) % 6], p[i], p[(i + 1) % 6], n))
            .collect();
        let sum: f64 = angles.iter().sum();
        assert!((sum - 4.0 * PI).abs() < 1e-12);
        assert!((angles[3] - 1.5 * PI).abs() < 1e-12);
    }

    #[test]
    fn faces_of_a_square_with_a_diagonal() {
        let coords = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let edges = [[0, 1], [1, 2], [2, 3], [3, 0], [3, 1]];
        let b = [true, true, true, true, false];
        let mut faces = faces_of_planar_graph(&coords, &edges, &b).unwrap();
        for f in &mut faces {
            let m = f.iter().enumerate().min_by_key(|x| x.1).unwrap().0;
            f.rotate_left(m);
        }
        faces.sort();
        assert_eq!(faces, vec![vec![0, 1, 3], vec![1, 2, 3]]);
    }
}
