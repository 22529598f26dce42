//! Running one search on many machines: shards, their merge, and Slurm batch scripts.
//!
//! A shard is a plain `synthesize` run of a deterministic share of the search's units
//! ([`shard`]: one unit is one compiled model and its 2^N mode assignments; shares are
//! balanced by estimated cost). [`merge`] checks that a set of shard directories is one
//! complete search and writes the run a single machine would have written: the same
//! records, summary, designs, exports and report. [`slurm`] writes a job array (one task
//! per shard) and a merge job that runs after it; Slurm does the scheduling.
//!
//! Data flows one way: this module uses `search` (its plan, its runs, its output
//! directory), never the reverse.

pub mod merge;
pub mod shard;
pub mod slurm;

use std::path::Path;

/// An error of sharding, merging or writing batch scripts.
#[derive(Debug, thiserror::Error)]
pub enum DistributeError {
    /// A directory, file or option that cannot be used as given.
    #[error("{path}: {message}")]
    Input {
        /// The directory, file or option.
        path: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// The search itself failed.
    #[error(transparent)]
    Search(#[from] crate::search::SearchError),
    /// The output directory cannot be used.
    #[error(transparent)]
    Output(#[from] crate::search::output::OutputError),
}

impl DistributeError {
    fn input(path: impl AsRef<Path>, message: impl Into<String>) -> DistributeError {
        DistributeError::Input {
            path: path.as_ref().display().to_string(),
            message: message.into(),
        }
    }
}
