//! Geometric checks on evaluated designs: self-intersection, obstacles, verification.
