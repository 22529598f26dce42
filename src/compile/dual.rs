//! Forward-mode dual numbers: an independent gradient oracle for the symbolic
//! differentiator (and the "dual" row of `foldsynth bench`).
//!
//! The derivative conventions are the ones [`diff`](super::diff) uses: `sgn` has
//! derivative 0; the clamped `acos` has derivative `-1/sqrt(1-x²)` inside `(-1, 1)` and 0
//! elsewhere; `sqrt` has derivative 0 at 0; `atan2` has gradient 0 at the origin. No rule
//! produces NaN or an infinity from finite inputs.

use crate::expr::clamp_unit;
use crate::kinematics::{Scalar, acos_clamped, sgn_f64};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A value with its gradient with respect to `n` variables.
///
/// An empty gradient means "all zero", which keeps constants context-free
/// ([`Scalar::from_f64`] does not know `n`).
#[derive(Clone, Debug, PartialEq)]
pub struct Dual {
    /// The value.
    pub v: f64,
    /// The gradient (empty = zero).
    pub g: Vec<f64>,
}

impl Dual {
    /// A constant.
    pub fn constant(v: f64) -> Dual {
        Dual { v, g: Vec::new() }
    }

    /// Variable `i` of `n` with value `v` (unit gradient).
    pub fn var(v: f64, i: usize, n: usize) -> Dual {
        let mut g = vec![0.0; n];
        g[i] = 1.0;
        Dual { v, g }
    }

    /// The gradient padded to `n` entries.
    pub fn grad(&self, n: usize) -> Vec<f64> {
        let mut g = self.g.clone();
        g.resize(n, 0.0);
        g
    }

    /// `ka * a.g + kb * b.g`, treating an empty gradient as zero.
    fn lin(ka: f64, a: &[f64], kb: f64, b: &[f64]) -> Vec<f64> {
        match (a.is_empty(), b.is_empty()) {
            (true, true) => Vec::new(),
            (false, true) => a.iter().map(|x| ka * x).collect(),
            (true, false) => b.iter().map(|y| kb * y).collect(),
            (false, false) => {
                let n = a.len().max(b.len());
                (0..n)
                    .map(|i| {
                        ka * a.get(i).copied().unwrap_or(0.0)
                            + kb * b.get(i).copied().unwrap_or(0.0)
                    })
                    .collect()
            }
        }
    }

    fn chain(&self, v: f64, d: f64) -> Dual {
        Dual {
            v,
            g: self.g.iter().map(|x| d * x).collect(),
        }
    }

    /// `clamp(self, -1, 1)`, derivative 1 inside the open interval and 0 elsewhere.
    pub fn clamp_unit(&self) -> Dual {
        let d = if self.v > -1.0 && self.v < 1.0 {
            1.0
        } else {
            0.0
        };
        self.chain(clamp_unit(self.v), d)
    }
}

impl Add for Dual {
    type Output = Dual;
    fn add(self, b: Dual) -> Dual {
        Dual {
            v: self.v + b.v,
            g: Dual::lin(1.0, &self.g, 1.0, &b.g),
        }
    }
}

impl Sub for Dual {
    type Output = Dual;
    fn sub(self, b: Dual) -> Dual {
        Dual {
            v: self.v - b.v,
            g: Dual::lin(1.0, &self.g, -1.0, &b.g),
        }
    }
}

impl Mul for Dual {
    type Output = Dual;
    fn mul(self, b: Dual) -> Dual {
        Dual {
            v: self.v * b.v,
            g: Dual::lin(b.v, &self.g, self.v, &b.g),
        }
    }
}

impl Div for Dual {
    type Output = Dual;
    fn div(self, b: Dual) -> Dual {
        let q = self.v / b.v;
        Dual {
            v: q,
            g: Dual::lin(1.0 / b.v, &self.g, -q / b.v, &b.g),
        }
    }
}

impl Neg for Dual {
    type Output = Dual;
    fn neg(self) -> Dual {
        self.chain(-self.v, -1.0)
    }
}

impl Add<f64> for Dual {
    type Output = Dual;
    fn add(self, b: f64) -> Dual {
        Dual {
            v: self.v + b,
            g: self.g,
        }
    }
}

impl Sub<f64> for Dual {
    type Output = Dual;
    fn sub(self, b: f64) -> Dual {
        Dual {
            v: self.v - b,
            g: self.g,
        }
    }
}

impl Mul<f64> for Dual {
    type Output = Dual;
    fn mul(self, b: f64) -> Dual {
        self.chain(self.v * b, b)
    }
}

impl Div<f64> for Dual {
    type Output = Dual;
    fn div(self, b: f64) -> Dual {
        self.chain(self.v / b, 1.0 / b)
    }
}

impl Scalar for Dual {
    fn from_f64(v: f64) -> Self {
        Dual::constant(v)
    }
    fn sin(&self) -> Self {
        self.chain(self.v.sin(), self.v.cos())
    }
    fn cos(&self) -> Self {
        self.chain(self.v.cos(), -self.v.sin())
    }
    fn acos(&self) -> Self {
        let x = self.v;
        let d = if x > -1.0 && x < 1.0 {
            -1.0 / ((1.0 - x) * (1.0 + x)).sqrt()
        } else {
            0.0
        };
        self.chain(acos_clamped(x), d)
    }
    fn sqrt(&self) -> Self {
        let s = self.v.sqrt();
        let d = if s > 0.0 { 0.5 / s } else { 0.0 };
        self.chain(s, d)
    }
    fn atan2(&self, x: &Self) -> Self {
        let (yv, xv) = (self.v, x.v);
        let r = xv * xv + yv * yv;
        let (dy, dx) = if r > 0.0 {
            (xv / r, -yv / r)
        } else {
            (0.0, 0.0)
        };
        Dual {
            v: yv.atan2(xv),
            g: Dual::lin(dy, &self.g, dx, &x.g),
        }
    }
    fn sgn(&self) -> Self {
        Dual::constant(sgn_f64(self.v))
    }
    fn to_f64(&self) -> Option<f64> {
        Some(self.v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn product_rule_and_guards() {
        let x = Dual::var(0.3, 0, 2);
        let y = Dual::var(0.7, 1, 2);
        let f = x.clone() * y.sin();
        assert_eq!(f.g, vec![0.7f64.sin(), 0.3 * 0.7f64.cos()]);
        let outside = Dual::var(1.5, 0, 1).acos();
        assert_eq!(outside.g, vec![0.0]);
        let at_zero = Dual::var(0.0, 0, 1).sqrt();
        assert_eq!(at_zero.g, vec![0.0]);
        let origin = Dual::var(0.0, 0, 2).atan2(&Dual::var(0.0, 1, 2));
        assert_eq!(origin.g, vec![0.0, 0.0]);
        assert_eq!(Dual::var(-2.0, 0, 1).sgn().grad(1), vec![0.0]);
    }
}
