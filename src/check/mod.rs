//! Geometric checks on evaluated designs: self-intersection, obstacles, verification.
//!
//! * [`triangulate`] — ear clipping of facets in the flat layout (once per pattern);
//! * [`tri_tri`] — Möller's triangle–triangle test with a contact tolerance;
//! * [`self_intersection`] — facet pairs at one state: crossings and the flip test of
//!   thesis Sec. 3.2.4;
//! * [`features`] — feature size of the flat layout (vertex–vertex, vertex–edge, edge
//!   lengths): what fabrication and importers that snap geometry need;
//! * [`cylinder`] — the finite-cylinder obstacle of the gripper task (Sec. 5.5);
//! * [`motion`] — the flat layout and evenly spaced states of a motion (16 in the thesis);
//! * [`rotated_copy`] — the two-armed gripper built from one arm;
//! * [`cycle`] — cyclic designs (r2′): compatibility and position agreement over a sweep.
//! * [`robustness`] — margins of a motion (rigid margin, clearances) measured exactly,
//!   independently of the optimizer's clearance constraints.
//!
//! ```
//! use foldsynth::check::{Checker, MotionSettings, check_motion};
//! // Two unit squares hinged along x = 0; the left one folds up (valley) by t.
//! let layout = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [-1.0, 1.0], [-1.0, 0.0]];
//! let faces = vec![vec![0, 1, 2, 3], vec![0, 3, 4, 5]];
//! let checker = Checker::new(&layout, &faces).unwrap();
//! let state = |t: f64| {
//!     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0],
//!          [-t.cos(), 1.0, t.sin()], [-t.cos(), 0.0, t.sin()]]
//! };
//! // Folding to 3 rad (short of π) is fine; folding to 3.5 rad flips one through the other.
//! let ok = check_motion(&checker, &layout, state, 0.0, 3.0, &MotionSettings::default()).unwrap();
//! assert!(ok.clear());
//! let bad = check_motion(&checker, &layout, state, 0.0, 3.5, &MotionSettings::default()).unwrap();
//! assert!(!bad.self_intersection_free());
//! ```

pub mod copies;
pub mod cycle;
pub mod cylinder;
pub mod distance;
pub mod features;
pub mod motion;
pub mod requirements;
pub mod robustness;
pub mod rotated_copy;
pub mod self_intersection;
pub mod shapes;
pub mod thick;
pub mod tri_tri;
pub mod triangulate;

pub use cylinder::Cylinder;
pub use motion::{MotionReport, MotionSettings, check_frames, check_motion, check_states};
pub use rotated_copy::{RotatedCopyError, two_armed, with_rotated_copy};
pub use self_intersection::{
    CheckError, Checker, Hinge, Intersection, IntersectionKind, ObstacleHit, StateTracker,
};
pub use tri_tri::{DEFAULT_TOL, triangles_intersect};
pub use triangulate::{TriangulateError, triangulate_faces, triangulate_polygon};
pub mod verify;
