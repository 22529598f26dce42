//! The arm's rotational copies as the robustness block moves points and gradients between
//! them (issue 31).
//!
//! Copy `k` of a point is [`Copies::apply`]; a gradient with respect to copy `k`'s point is
//! pulled back to the arm's by [`Copies::turn_back`]. The thesis's two-armed gripper (two
//! copies about the z-axis through the origin) keeps its own arithmetic, `(−x, −y, z)`,
//! so that its records stay the same bit for bit (a rotation matrix would turn `−0.0` into
//! `+0.0` on the way).

use crate::geom::V3;
use crate::scene::Copies;

/// The rotated copy of a two-armed task: 180° about the z-axis.
pub fn copy_point(p: V3) -> V3 {
    [-p[0], -p[1], p[2]]
}

/// The copies of the arm: copy 0 is the arm itself, copies `1..n` the arm turned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CopyMap {
    /// The task's copies.
    pub copies: Copies,
    /// Two copies about the z-axis through the origin: the half turn `(−x, −y, z)`.
    half_turn: bool,
}

impl CopyMap {
    /// The copies of a task's scene.
    pub fn new(copies: Copies) -> CopyMap {
        let half_turn =
            copies.n == 2 && copies.point == [0.0; 3] && copies.direction == [0.0, 0.0, 1.0];
        CopyMap { copies, half_turn }
    }

    /// Number of arms (1: the arm alone).
    pub fn n(&self) -> usize {
        self.copies.n.max(1)
    }

    /// Point `p` of the arm on copy `k`.
    pub fn point(&self, k: usize, p: V3) -> V3 {
        if k == 0 {
            p
        } else if self.half_turn {
            copy_point(p)
        } else {
            self.copies.apply(k, p)
        }
    }

    /// A gradient with respect to copy `k`'s point, as one with respect to the arm's
    /// (`Rᵀ g`).
    pub fn grad_back(&self, k: usize, g: V3) -> V3 {
        if k == 0 {
            g
        } else if self.half_turn {
            // R = Rᵀ for the half turn.
            copy_point(g)
        } else {
            self.copies.turn_back(k, g)
        }
    }

    /// How far a turned point may land from a point to count as that point: 0 for the
    /// exact half turn, rounding (1e-12) for the others.
    pub fn tolerance(&self) -> f64 {
        if self.half_turn { 0.0 } else { 1e-12 }
    }

    /// Whether a target point lies on the copies' axis (where the tips of all copies meet
    /// by design).
    pub fn on_axis(&self, p: V3) -> bool {
        if self.half_turn {
            return p[0].abs() < 1e-9 && p[1].abs() < 1e-9;
        }
        let c = &self.copies;
        let d = crate::geom::sub(p, c.point);
        let along = crate::geom::dot(d, c.direction);
        crate::geom::norm(crate::geom::sub(d, crate::geom::scale(c.direction, along))) < 1e-9
    }

    /// Whether the fixed flat position `q` of a vertex, on copy `k`, coincides with the
    /// arm's fixed flat position `p` (a vertex on the axis, shared by the copies).
    pub fn merges(&self, k: usize, q: [f64; 2], p: [f64; 2]) -> bool {
        if self.half_turn {
            return (-q[0] - p[0]).hypot(-q[1] - p[1]) <= 1e-9;
        }
        let m = self.point(k, [q[0], q[1], 0.0]);
        crate::geom::norm(crate::geom::sub(m, [p[0], p[1], 0.0])) <= 1e-9
    }
}
