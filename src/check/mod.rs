//! Geometric checks on evaluated designs: self-intersection, obstacles, verification.

pub mod verify;
