//! The area term of the objective (issue 31): the flat pattern's area (shoelace over the
//! facets, every copy counted), and the packing ratio — that area over the footprint of the
//! folded pattern's bounding box across the copies' axis. Written over [`Scalar`], so the
//! compiled term and the f64 path are the same code.
//!
//! The bounding box is exact: its sides are maxima and minima of vertex coordinates,
//! written as chains of [`Scalar::max0`] (`max(m, x) = m + max0(x − m)`), piecewise smooth
//! with the gradient of the extreme vertex.

use super::geometry::Flat;
use super::linalg::Vec3;
use super::plan::Plan;
use crate::geom::{V3, cross, dot, normalize};
use crate::kinematics::Scalar;
use crate::scene::Copies;

/// The flat area of one copy: Σ over the plan's facets of its polygon's shoelace area in
/// the flat layout (polygons are counter-clockwise, so each term is positive; an open
/// facet's polygon is closed by the paper's edge from its last vertex to its first).
pub fn flat_area<S: Scalar>(plan: &Plan, flat: &Flat<S>) -> S {
    let mut total = S::from_f64(0.0);
    for (poly, _) in &plan.polygons {
        if poly.len() < 3 {
            continue;
        }
        let mut twice = S::from_f64(0.0);
        for (k, &i) in poly.iter().enumerate() {
            let j = poly[(k + 1) % poly.len()];
            let (p, q) = (&flat.pos[i], &flat.pos[j]);
            twice = twice + (p[0].clone() * q[1].clone() - q[0].clone() * p[1].clone());
        }
        total = total + twice * 0.5;
    }
    total
}

/// Two unit vectors spanning the plane normal to the copies' axis: x and y when the axis is
/// z (exactly), otherwise the x-axis (or, nearly parallel to the axis, the y-axis) made
/// normal to it, and the axis crossed with that.
pub fn footprint_frame(copies: &Copies) -> [V3; 2] {
    let a = copies.direction;
    if a == [0.0, 0.0, 1.0] {
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    }
    let seed = if a[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let s = dot(seed, a);
    let e1 = normalize([seed[0] - s * a[0], seed[1] - s * a[1], seed[2] - s * a[2]])
        .expect("a unit axis is not parallel to both x and y");
    [e1, cross(a, e1)]
}

/// The coordinate `e · X` of copy `k`'s image of the arm's point `x`, as an affine function
/// of `x`: `(c, o)` with `e · (p + R_k (x − p)) = c · x + o`.
fn copy_coordinate(copies: &Copies, k: usize, e: V3) -> (V3, f64) {
    let c = copies.turn_back(k, e);
    let p = copies.point;
    (c, dot(e, p) - dot(c, p))
}

/// `c · x + o`, skipping zero coefficients (the z-axis frame reads plain coordinates).
fn affine<S: Scalar>(c: V3, o: f64, x: &Vec3<S>) -> S {
    let mut acc: Option<S> = None;
    for i in 0..3 {
        if c[i] == 0.0 {
            continue;
        }
        let term = if c[i] == 1.0 {
            x[i].clone()
        } else {
            x[i].clone() * c[i]
        };
        acc = Some(match acc {
            None => term,
            Some(a) => a + term,
        });
    }
    let acc = acc.unwrap_or_else(|| S::from_f64(0.0));
    if o == 0.0 { acc } else { acc + o }
}

/// The footprint of the bounding box of `points` (the arm's vertices at one state) and of
/// their images in every copy, across the copies' axis: the product of the extents along
/// the two directions of [`footprint_frame`].
pub fn footprint<S: Scalar>(points: &[Vec3<S>], copies: &Copies) -> S {
    let frame = footprint_frame(copies);
    let n = copies.n.max(1);
    let mut area = S::from_f64(1.0);
    for (axis, e) in frame.iter().enumerate() {
        let mut hi: Option<S> = None;
        let mut lo: Option<S> = None;
        for k in 0..n {
            let (c, o) = copy_coordinate(copies, k, *e);
            for x in points {
                let u = affine(c, o, x);
                hi = Some(match hi {
                    None => u.clone(),
                    Some(m) => m.clone() + (u.clone() - m).max0(),
                });
                lo = Some(match lo {
                    None => u,
                    Some(m) => m.clone() - (m - u).max0(),
                });
            }
        }
        let extent = match (hi, lo) {
            (Some(h), Some(l)) => h - l,
            _ => S::from_f64(0.0),
        };
        area = if axis == 0 { extent } else { area * extent };
    }
    area
}
