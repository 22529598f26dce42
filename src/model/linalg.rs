//! Small 3×3 linear algebra over any [`Scalar`] (the model's rigid facet maps).

use crate::kinematics::Scalar;

/// A 3×3 matrix as rows.
pub type Mat3<S> = [[S; 3]; 3];
/// A 3-vector.
pub type Vec3<S> = [S; 3];

/// The identity.
pub fn identity<S: Scalar>() -> Mat3<S> {
    let (o, z) = (S::from_f64(1.0), S::from_f64(0.0));
    [[o.clone(), z.clone(), z.clone()], [z.clone(), o.clone(), z.clone()], [z.clone(), z, o]]
}

/// `a · b`.
pub fn mul<S: Scalar>(a: &Mat3<S>, b: &Mat3<S>) -> Mat3<S> {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            a[i][0].clone() * b[0][j].clone()
                + a[i][1].clone() * b[1][j].clone()
                + a[i][2].clone() * b[2][j].clone()
        })
    })
}

/// `a · v`.
pub fn apply<S: Scalar>(a: &Mat3<S>, v: &Vec3<S>) -> Vec3<S> {
    std::array::from_fn(|i| {
        a[i][0].clone() * v[0].clone() + a[i][1].clone() * v[1].clone() + a[i][2].clone() * v[2].clone()
    })
}

/// `a + b`.
pub fn add<S: Scalar>(a: &Vec3<S>, b: &Vec3<S>) -> Vec3<S> {
    std::array::from_fn(|i| a[i].clone() + b[i].clone())
}

/// `a − b`.
pub fn sub<S: Scalar>(a: &Vec3<S>, b: &Vec3<S>) -> Vec3<S> {
    std::array::from_fn(|i| a[i].clone() - b[i].clone())
}

/// Rotation by `angle` about the in-plane unit axis `(dx, dy, 0)` (Rodrigues' formula).
pub fn rot_in_plane_axis<S: Scalar>(dx: &S, dy: &S, angle: &S) -> Mat3<S> {
    let (c, s) = (angle.cos(), angle.sin());
    let k = S::from_f64(1.0) - c.clone();
    let z = S::from_f64(0.0);
    // R = c I + s [d]× + (1 − c) d dᵀ with d = (dx, dy, 0).
    [
        [c.clone() + k.clone() * dx.clone() * dx.clone(), k.clone() * dx.clone() * dy.clone(), s.clone() * dy.clone()],
        [k.clone() * dx.clone() * dy.clone(), c.clone() + k * dy.clone() * dy.clone(), -(s.clone() * dx.clone())],
        [-(s.clone() * dy.clone()), s * dx.clone(), c + z],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rodrigues_matches_nalgebra() {
        let (a, ang) = (0.7_f64, 1.3_f64);
        let (dx, dy) = (a.cos(), a.sin());
        let r = rot_in_plane_axis(&dx, &dy, &ang);
        let axis = nalgebra::Unit::new_normalize(nalgebra::Vector3::new(dx, dy, 0.0));
        let n = nalgebra::Rotation3::from_axis_angle(&axis, ang);
        for i in 0..3 {
            for j in 0..3 {
                assert!((r[i][j] - n[(i, j)]).abs() < 1e-15);
            }
        }
    }
}
