//! One rule application as the thesis's notation names it (`4`, `(4, 8)`, `(9, 14)'`): what
//! the rules match and apply, and what [`super::notation`] reads and writes.

use std::fmt;

/// One rule application in the notation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Step {
    /// r1 on the vertex with this name.
    Extend(usize),
    /// r2 on the two vertices with these names, written sorted (the larger first only in
    /// the rare case where both roles match and the second one is meant).
    Combine(usize, usize),
    /// r2′ on the two vertices with these names (written as r2's pairs, with a prime).
    Straight(usize, usize),
}

impl fmt::Display for Step {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Step::Extend(n) => write!(f, "{n}"),
            Step::Combine(a, b) => write!(f, "({a}, {b})"),
            Step::Straight(a, b) => write!(f, "({a}, {b})'"),
        }
    }
}
