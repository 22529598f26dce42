//! Bounded, constrained, multi-start gradient optimization (augmented Lagrangian + L-BFGS).
