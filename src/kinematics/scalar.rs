//! The number type the kinematics is written over.
//!
//! The PTU code is written once, generic over [`Scalar`]: `f64` gives the numeric
//! reference, the expression-graph handle (`expr`) builds symbolic models from the very
//! same code, and the dual number (`compile::dual`) is an independent gradient oracle.
//! `f64`'s `sin`, `cos`, `atan2` and `acos` are [`crate::trig`]'s, the functions the
//! interpreter and the compiled code use, so all of them compute the same bits.

use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A real number as the kinematics needs it.
///
/// Implementations must agree with `f64` to rounding on every operation, including the
/// conventions that matter for the PTU:
/// - [`Scalar::acos`] clamps its argument to `[-1, 1]` (rounding pushes dot products of
///   unit vectors slightly outside) and its derivative is 0 outside the open interval;
/// - [`Scalar::sgn`] is `-1`, `0` or `+1` with derivative 0 everywhere.
pub trait Scalar:
    Clone
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
{
    /// A constant. Symbolic implementations keep it context-free until it meets a node.
    fn from_f64(v: f64) -> Self;
    /// Sine.
    fn sin(&self) -> Self;
    /// Cosine.
    fn cos(&self) -> Self;
    /// Arccosine of the argument clamped to `[-1, 1]`.
    fn acos(&self) -> Self;
    /// Square root (of a non-negative argument; callers clamp where rounding matters).
    fn sqrt(&self) -> Self;
    /// `atan2(self, x)`: the angle of the vector `(x, self)` in `(-π, π]`.
    fn atan2(&self, x: &Self) -> Self;
    /// Sign: `-1`, `0` or `+1`.
    fn sgn(&self) -> Self;
    /// The numeric value when it is known without evaluation (always for `f64`,
    /// for constant-folded symbolic nodes).
    fn to_f64(&self) -> Option<f64>;

    /// `max(0, x)`, written as `(x + x·sgn(x)) / 2` so that every implementation gets it
    /// from the primitives (derivative: 1 for x > 0, 0 for x < 0).
    fn max0(&self) -> Self {
        (self.clone() + self.clone() * self.sgn()) * 0.5
    }
}

/// Sign with `sgn(0) = 0` (and NaN mapped to 0), shared by every implementation.
#[inline]
pub fn sgn_f64(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Arccosine with the argument clamped to `[-1, 1]`, shared by every implementation.
#[inline]
pub fn acos_clamped(x: f64) -> f64 {
    crate::trig::acos(x)
}

impl Scalar for f64 {
    #[inline]
    fn from_f64(v: f64) -> Self {
        v
    }
    #[inline]
    fn sin(&self) -> Self {
        crate::trig::sin(*self)
    }
    #[inline]
    fn cos(&self) -> Self {
        crate::trig::cos(*self)
    }
    #[inline]
    fn acos(&self) -> Self {
        acos_clamped(*self)
    }
    #[inline]
    fn sqrt(&self) -> Self {
        f64::sqrt(*self)
    }
    #[inline]
    fn atan2(&self, x: &Self) -> Self {
        crate::trig::atan2(*self, *x)
    }
    #[inline]
    fn sgn(&self) -> Self {
        sgn_f64(*self)
    }
    #[inline]
    fn to_f64(&self) -> Option<f64> {
        Some(*self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f64_conventions() {
        assert_eq!(Scalar::acos(&1.0000000000000002_f64), 0.0);
        assert_eq!(Scalar::acos(&-1.5_f64), std::f64::consts::PI);
        assert_eq!(Scalar::sgn(&0.0_f64), 0.0);
        assert_eq!(Scalar::sgn(&-0.0_f64), 0.0);
        assert_eq!(Scalar::sgn(&-3.0_f64), -1.0);
        assert_eq!(Scalar::atan2(&1.0_f64, &0.0), std::f64::consts::FRAC_PI_2);
    }
}
