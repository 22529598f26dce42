//! The compiler: egg simplification, reverse-mode differentiation, Cranelift JIT.

pub mod diff;
pub mod dual;
pub mod jit;

pub use diff::{gradient, gradients};
pub use dual::Dual;
pub use jit::{CompileError, CompiledFn};
pub mod simplify;
