//! The Principle of Three Units for one degree-n vertex (thesis Sec. 4.1–4.2).

mod scalar;

pub use scalar::{Scalar, acos_clamped, sgn_f64};
