//! foldsynth: synthesis of rigidly foldable origami crease patterns.
//!
//! The data flows one way (see `ARCHITECTURE.md`):
//! task → grammar → model → compile → optimize → check → search → export, with
//! [`distribute`] (shards, merge, Slurm) above `search`, [`kinematics`] (the Principle of Three Units, generic over [`kinematics::Scalar`])
//! and [`expr`] (the expression graph) underneath, and [`simulate`] as the numeric
//! bar-and-hinge baseline of thesis Sec. 3.

#![warn(missing_docs)]

pub mod bench;
pub mod check;
pub mod cli;
pub mod compile;
pub mod cpu_time;
pub mod distribute;
pub mod export;
pub mod expr;
pub mod fabricate;
pub mod fuzz;
pub mod geom;
pub mod grammar;
pub mod kinematics;
pub mod limits;
pub mod model;
pub mod optimize;
pub mod pattern;
pub mod scene;
pub mod search;
pub mod simulate;
pub mod task;
mod task_load;
pub mod text;
pub mod trig;
