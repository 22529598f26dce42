//! The compiler: egg simplification, reverse-mode differentiation, Cranelift JIT.
