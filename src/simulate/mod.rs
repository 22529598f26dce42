//! The numeric bar-and-hinge simulator of thesis Sec. 3 (the baseline).
//!
//! Bars join every pair of vertices of each facet (sides and diagonals, Eq. 2). The motion
//! is driven by vertex trajectories or crease angles, with fixed vertices or facets; each
//! of J steps finds the positions that minimise the bar-length errors from the previous
//! step's solution ([`solver`] says exactly what is minimised), and reports the distortion
//! δ(j) (Eq. 3), the rigidity error Γ (Eq. 4), the self-intersection measure θ (using
//! [`crate::check`]) and the final positions.
//!
//! * [`input`] — the plain input any source can build ([`SimInput`]);
//! * [`formula`] — formulas in `t` for trajectories and crease angles;
//! * [`pattern_file`] — the `grammar/*.toml` pattern format;
//! * [`solver`] — the per-step Levenberg–Marquardt solve;
//! * [`run`] — the simulation loop and its report;
//! * [`crossval`] — the simulator against the PTU's designs (same drive, same states);
//! * [`flasher`] — the adapted four-sided flasher task of Sec. 3.3–3.7 and its simulated
//!   annealing.
//!
//! ```
//! use std::sync::Arc;
//! use foldsynth::simulate::{Drive, SimInput, SolverSettings, simulate};
//! // One square facet turning about the crease x = 0 against a fixed square: rigid.
//! let input = SimInput {
//!     initial: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0],
//!                   [-1.0, 1.0, 0.0], [-1.0, 0.0, 0.0]],
//!     faces: vec![vec![0, 1, 2, 3], vec![0, 3, 4, 5]],
//!     extra_bars: vec![],
//!     fixed: vec![],
//!     drives: vec![Drive::Crease { p: 0, q: 3, fixed_face: 0, moving_face: 1,
//!                                  angle: Arc::new(|t| t) }],
//!     t_start: 0.0,
//!     t_end: 1.5,
//!     steps: 10,
//!     first_step_offsets: vec![],
//!     check_intersections: true,
//!     solver: SolverSettings::default(),
//! };
//! let report = simulate(&input).unwrap();
//! assert!(report.rigid && report.gamma < 1e-12 && report.theta == 0.0);
//! ```

pub mod crossval;
pub mod flasher;
pub mod formula;
pub mod input;
pub mod pattern_file;
pub mod run;
pub mod solver;

pub use formula::{Formula, FormulaError};
pub use input::{AngleFn, Drive, InputError, PathFn, SimInput, SolverSettings};
pub use pattern_file::{PatternFile, PatternFileError};
pub use run::{
    RIGID_DELTA, SimError, SimReport, StepReport, checker_for, simulate, simulate_with_checker,
};
pub use solver::{Bars, SolveStats};
