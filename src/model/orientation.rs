//! Orientation requirements as constraints of the compiled model (issue 31): at each listed
//! t, the angle between a direction of the folded pattern — the crease into a vertex (from
//! its predecessor to it) or the normal of the facet left or right of that crease — and a
//! reference direction `d` stays within `tolerance` of `angle`. With `u` the unit pointer,
//! `cos(angle + tol) ≤ u · d ≤ cos(angle − tol)`, as smooth inequalities `g ≥ 0`; a side
//! is left out where it says nothing (`angle − tol ≤ 0`: the upper one; `angle + tol ≥ π`:
//! the lower one).

use super::geometry::{self, Flat, Folded};
use super::linalg::Vec3;
use super::plan::Plan;
use crate::kinematics::Scalar;
use crate::task::terms::Pointer;
use std::f64::consts::PI;

/// One orientation requirement resolved on a graph.
#[derive(Clone, Debug, PartialEq)]
pub struct Orientation {
    /// Its label (the task's name, or `orientation[k]`).
    pub name: String,
    /// Index into the task's `requirements.orientations`.
    pub index: usize,
    /// The vertex (dense index).
    pub vertex: usize,
    /// The crease into it (dense index; its tail is the predecessor, its head the vertex).
    pub crease: usize,
    /// Which direction.
    pub of: Pointer,
    /// The reference direction (unit).
    pub direction: [f64; 3],
    /// The wanted angle (rad).
    pub angle: f64,
    /// The tolerance (rad).
    pub tolerance: f64,
    /// The states it applies at.
    pub t: Vec<f64>,
}

/// Which side of the band `cos(angle + tol) ≤ u · d ≤ cos(angle − tol)` a constraint is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// `u · d − cos(angle + tol) ≥ 0`: the angle is at most `angle + tol`.
    AtMost,
    /// `cos(angle − tol) − u · d ≥ 0`: the angle is at least `angle − tol`.
    AtLeast,
}

impl Orientation {
    /// The sides that constrain anything, in constraint order.
    pub fn sides(&self) -> Vec<Side> {
        let mut out = Vec::with_capacity(2);
        if self.angle + self.tolerance < PI {
            out.push(Side::AtMost);
        }
        if self.angle - self.tolerance > 0.0 {
            out.push(Side::AtLeast);
        }
        out
    }

    /// The constraint of `side` given the cosine `u · d`.
    pub fn constraint<S: Scalar>(&self, side: Side, cosine: S) -> S {
        match side {
            Side::AtMost => cosine - (self.angle + self.tolerance).cos(),
            Side::AtLeast => S::from_f64((self.angle - self.tolerance).cos()) - cosine,
        }
    }

    /// The unit pointer in the folded state `folded`: the crease's direction from its tail
    /// to its head (normalized difference of the 3D positions), or the normal of the facet
    /// left or right of it (the facet's rigid map applied to +z, the third column of its
    /// rotation: the paper's upper side).
    pub fn pointer<S: Scalar>(&self, plan: &Plan, flat: &Flat<S>, folded: &Folded<S>) -> Vec3<S> {
        let c = &plan.creases[self.crease];
        let facet = match self.of {
            Pointer::Crease => {
                let a = geometry::position(plan, flat, folded, c.tail);
                let b = geometry::position(plan, flat, folded, c.head);
                let d: Vec3<S> = std::array::from_fn(|i| b[i].clone() - a[i].clone());
                let len = (d[0].clone() * d[0].clone()
                    + d[1].clone() * d[1].clone()
                    + d[2].clone() * d[2].clone())
                .sqrt();
                return std::array::from_fn(|i| d[i].clone() / len.clone());
            }
            Pointer::FacetLeft => c.left,
            Pointer::FacetRight => c.right,
        };
        let r = &folded.rot[facet];
        std::array::from_fn(|i| r[i][2].clone())
    }

    /// `u · d` in the folded state `folded`.
    pub fn cosine<S: Scalar>(&self, plan: &Plan, flat: &Flat<S>, folded: &Folded<S>) -> S {
        let u = self.pointer(plan, flat, folded);
        let d = self.direction;
        u[0].clone() * d[0] + u[1].clone() * d[1] + u[2].clone() * d[2]
    }
}
