//! The numeric bar-and-hinge simulator of thesis Sec. 3 (the baseline).
