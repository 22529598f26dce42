//! The targets of the objective Ω on one graph (thesis Eq. 37–38, generalized by issue 31):
//! a vertex at a value of t, and where it should be — at a point, on a line, on a plane (a
//! squared distance written as an expression, so it compiles with the rest), or on a
//! surface (a mesh: [`super::surface`], added numerically).

use super::linalg::Vec3;
use crate::kinematics::Scalar;
use crate::task::terms::Goal;

/// Smoothing of `‖d‖` in multi-target objectives: `√(‖d‖² + ε²)`, so the gradient exists
/// where a target is hit exactly. Far below any threshold a task can state.
pub const DISTANCE_SMOOTHING: f64 = 1e-9;

/// One target of a model: vertex `vertex` at parameter `t` should reach `goal`.
#[derive(Clone, Debug, PartialEq)]
pub struct Target {
    /// The driving parameter.
    pub t: f64,
    /// The vertex (dense index into the plan's vertices), resolved from the task's
    /// [`crate::task::terms::VertexRef`].
    pub vertex: usize,
    /// Where it should be.
    pub goal: Goal,
    /// Its weight in the objective.
    pub weight: f64,
    /// Index of the task's `[[objective.targets]]` entry it comes from.
    pub entry: usize,
    /// The point a point goal of the gripping vertex asks for, and `[NaN; 3]` for every
    /// other target (no comparison with it holds): what the code that knows only the
    /// thesis's targets (the two-armed gripper's tips meeting at a target on the axis, the
    /// exported target markers) reads. New code reads [`Target::tip_point`] or `goal`.
    pub point: [f64; 3],
}

impl Target {
    /// The point of a point goal of the gripping vertex (the thesis's target), if it is one.
    pub fn tip_point(&self) -> Option<[f64; 3]> {
        self.point.iter().all(|c| !c.is_nan()).then_some(self.point)
    }

    /// The mesh index of a surface goal.
    pub fn surface(&self) -> Option<usize> {
        match self.goal {
            Goal::Surface { index } => Some(index),
            _ => None,
        }
    }
}

/// The squared distance of `x` from a point, line or plane goal, as an expression (`None`
/// for a surface, which the graph cannot hold). Point: `Σ (x_i − p_i)²`, the thesis's
/// arithmetic operation for operation. Line through `p` along the unit `u`: the squared
/// length of the part of `x − p` normal to `u` (no cancellation of `‖x − p‖² − (…)²`).
/// Plane through `p` with unit normal `n`: `(n · (x − p))²`.
pub fn squared_distance<S: Scalar>(x: &Vec3<S>, goal: &Goal) -> Option<S> {
    let zero = || S::from_f64(0.0);
    match goal {
        Goal::Point { point } => Some((0..3).fold(zero(), |acc, i| {
            let d = x[i].clone() - point[i];
            acc + d.clone() * d
        })),
        Goal::Line { point, direction } => {
            let r: Vec3<S> = std::array::from_fn(|i| x[i].clone() - point[i]);
            let along = (0..3).fold(zero(), |acc, i| acc + r[i].clone() * direction[i]);
            Some((0..3).fold(zero(), |acc, i| {
                let e = r[i].clone() - along.clone() * direction[i];
                acc + e.clone() * e
            }))
        }
        Goal::Plane { point, normal } => {
            let h = (0..3).fold(zero(), |acc, i| acc + (x[i].clone() - point[i]) * normal[i]);
            Some(h.clone() * h)
        }
        Goal::Surface { .. } => None,
    }
}

/// How the terms of Ω enter the compiled model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Combination {
    /// One target and no area term: the objective is `w² d²` (smooth at the optimum, the
    /// same minimizer as Eq. 37's `w d`).
    Squared,
    /// Several targets, or targets beside an area term: `Σ w √(d² + ε²)` (Eq. 38, smoothed
    /// at [`DISTANCE_SMOOTHING`]); with an area term it is the constraint
    /// `threshold − Σ w √(d² + ε²) ≥ 0`.
    Smoothed,
}

impl Combination {
    /// The term of one target with weight `w` and squared distance `d2`.
    pub fn term<S: Scalar>(self, w: f64, d2: S) -> S {
        match self {
            Combination::Squared => d2 * (w * w),
            Combination::Smoothed => (d2 + DISTANCE_SMOOTHING * DISTANCE_SMOOTHING).sqrt() * w,
        }
    }

    /// The term's value and its derivative with respect to `d2`, in `f64` (for the terms
    /// added outside the graph).
    pub fn term_f64(self, w: f64, d2: f64) -> (f64, f64) {
        match self {
            Combination::Squared => (d2 * (w * w), w * w),
            Combination::Smoothed => {
                let s = (d2 + DISTANCE_SMOOTHING * DISTANCE_SMOOTHING).sqrt();
                (s * w, 0.5 * w / s)
            }
        }
    }
}
