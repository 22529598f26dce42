//! The hash-consed expression DAG that implements `Scalar` symbolically.
