//! Rotational copies of the designed arm: the device is `n` arms, copy `k` the arm turned by
//! `2πk/n` about an axis (the thesis's gripper is n = 2 about the z-axis; a four-sided
//! flasher n = 4).

use serde::{Deserialize, Serialize};

use crate::geom::{V3, add, dot, sub};

/// A 3×3 rotation matrix, rows.
pub type Mat3 = [V3; 3];

/// `n` copies of the arm about the axis through `point` along the unit `direction`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Copies {
    /// Number of arms in the device (1: the arm alone).
    pub n: usize,
    /// A point on the axis.
    pub point: V3,
    /// Unit direction of the axis.
    pub direction: V3,
}

impl Default for Copies {
    fn default() -> Self {
        Copies {
            n: 1,
            point: [0.0; 3],
            direction: [0.0, 0.0, 1.0],
        }
    }
}

impl Copies {
    /// `n` copies about the z-axis through the origin.
    pub fn about_z(n: usize) -> Copies {
        Copies {
            n,
            ..Copies::default()
        }
    }

    /// Whether the axis is the z-axis through the origin, where quarter and half turns are
    /// exact (no rounding of cos and sin: the thesis's gripper copy is `(−x, −y, z)` bit
    /// for bit).
    fn is_z(&self) -> bool {
        self.point == [0.0; 3] && self.direction == [0.0, 0.0, 1.0]
    }

    /// The rotation of copy `k` (0 ≤ k < n; copy 0 is the arm itself).
    pub fn rotation(&self, k: usize) -> Mat3 {
        let k = k % self.n.max(1);
        if self.is_z() && (4 * k).is_multiple_of(self.n.max(1)) {
            // A multiple of a quarter turn about z: exact.
            let (c, s) = match (4 * k / self.n.max(1)) % 4 {
                0 => (1.0, 0.0),
                1 => (0.0, 1.0),
                2 => (-1.0, 0.0),
                _ => (0.0, -1.0),
            };
            return [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        }
        let angle = std::f64::consts::TAU * k as f64 / self.n as f64;
        rodrigues(self.direction, angle)
    }

    /// Point `p` of the arm, moved to copy `k`.
    pub fn apply(&self, k: usize, p: V3) -> V3 {
        if k.is_multiple_of(self.n.max(1)) {
            return p;
        }
        let r = self.rotation(k);
        let d = sub(p, self.point);
        add(self.point, mul(&r, d))
    }

    /// A direction (or a gradient) of the arm, turned to copy `k` (no translation).
    pub fn turn(&self, k: usize, v: V3) -> V3 {
        if k.is_multiple_of(self.n.max(1)) {
            return v;
        }
        mul(&self.rotation(k), v)
    }

    /// A direction of copy `k` turned back to the arm: `Rᵀ v` (a gradient with respect to
    /// copy k's point is `Rᵀ` times the gradient with respect to the arm's point).
    pub fn turn_back(&self, k: usize, v: V3) -> V3 {
        if k.is_multiple_of(self.n.max(1)) {
            return v;
        }
        let r = self.rotation(k);
        [
            r[0][0] * v[0] + r[1][0] * v[1] + r[2][0] * v[2],
            r[0][1] * v[0] + r[1][1] * v[1] + r[2][1] * v[2],
            r[0][2] * v[0] + r[1][2] * v[1] + r[2][2] * v[2],
        ]
    }
}

/// `r · v`.
pub fn mul(r: &Mat3, v: V3) -> V3 {
    [dot(r[0], v), dot(r[1], v), dot(r[2], v)]
}

/// The rotation by `angle` about the unit axis `u` (Rodrigues' formula).
pub fn rodrigues(u: V3, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    let [x, y, z] = u;
    [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::scale;

    #[test]
    fn half_turn_about_z_is_exact() {
        let c = Copies::about_z(2);
        let p = [0.3, -1.7, 0.25];
        assert_eq!(c.apply(1, p), [-0.3, 1.7, 0.25]);
        assert_eq!(c.turn_back(1, p), [-0.3, 1.7, 0.25]);
    }

    #[test]
    fn n_turns_compose_to_the_identity_and_keep_lengths() {
        let c = Copies {
            n: 5,
            point: [1.0, 2.0, -0.5],
            direction: {
                let v = [0.3, -0.4, 0.866];
                let l = dot(v, v).sqrt();
                scale(v, 1.0 / l)
            },
        };
        let p = [0.7, -0.2, 1.3];
        let mut q = p;
        for _ in 0..5 {
            q = c.apply(1, q);
        }
        for i in 0..3 {
            assert!((q[i] - p[i]).abs() < 1e-12, "{q:?} vs {p:?}");
        }
        let d = |a: V3, b: V3| dot(sub(a, b), sub(a, b)).sqrt();
        let o = [0.1, 0.1, 0.1];
        for k in 0..5 {
            assert!((d(c.apply(k, p), c.apply(k, o)) - d(p, o)).abs() < 1e-12);
            // Rᵀ R = I.
            let v = c.turn_back(k, c.turn(k, p));
            for i in 0..3 {
                assert!((v[i] - p[i]).abs() < 1e-12);
            }
        }
    }
}
