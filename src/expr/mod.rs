//! The hash-consed expression DAG that implements `Scalar` symbolically.
//!
//! ```
//! use foldsynth::expr::{Ctx, Tape};
//! use foldsynth::kinematics::Scalar;
//!
//! // The same generic code runs on f64 and builds graphs.
//! fn f<S: Scalar>(a: S, t: S) -> S {
//!     (a.cos() * t.sin()).acos()
//! }
//! let ctx = Ctx::new();
//! let y = f(ctx.var(0), ctx.param(0));
//! let id = ctx.node_id(&y);
//! let g = ctx.to_graph();
//! let tape = Tape::new(&g, &[id], 1, 1).unwrap();
//! let mut out = [0.0];
//! tape.eval(&[0.4], &[1.1], &mut out).unwrap();
//! assert_eq!(out[0], f(0.4, 1.1));
//! ```
//!
//! - [`ExprGraph`]: the arena; [`ExprGraph::add`] hash-conses and folds.
//! - [`Ctx`] / [`Sym`]: a shared graph and the handle implementing `Scalar`.
//! - [`Tape`]: the interpreter.
//! - [`print`](mod@print): printers (plain, LaTeX, Mathematica, Python, DOT).

mod eval;
mod graph;
mod node;
pub mod print;
mod sym;

pub(crate) use eval::check_indices;
pub use eval::{ShapeError, Tape};
pub(crate) use graph::FxHashMap;
pub use graph::{Counts, ExprGraph};
pub use node::{Children, INPUT_BOUND, Node, NodeId, Range, clamp_unit, select};
pub use print::{Format, Names};
pub use sym::{Ctx, Sym};
