//! The Principle of Three Units for one degree-n vertex (thesis Sec. 4.1–4.2).
//!
//! Everything in [`ptu`](self) is generic over [`Scalar`], so the same code evaluates in
//! `f64`, builds expression graphs and propagates dual numbers. The vertex notation of
//! Eq. 24 is parsed by [`VertexSpec::parse`]; numeric foldability analysis (rigid
//! intervals, degree-4 results) lives in [`foldability`].

pub mod foldability;
mod notation;
mod ptu;
mod scalar;

pub use notation::{DriveExpr, Mode, NotationError, UnitSpec, VertexSpec};
pub use ptu::{
    Unit, UnitAngles, VertexState, ccw_sequence, closure_residual, flat_foldable,
    folded_unit_angle, internal_angles, rigid_margins, solve_vertex, unit_angles, wrap_angle,
};
pub use scalar::{Scalar, acos_clamped, sgn_f64};
