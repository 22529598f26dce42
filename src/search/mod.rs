//! The search over design alternatives (thesis Fig. 39, Sec. 5.3–5.6): every meaningful
//! graph × every gripping candidate × every assignment of rigid body modes.
//!
//! Per (graph, candidate) the model is compiled once, lazily, by whichever worker needs it
//! first; the 2^N mode assignments are parameters of that one native function. Each
//! alternative is optimized; when it meets the target it is checked for self-intersection
//! (both arms for a two-armed task) and against the obstacles, and verified independently
//! (a verification failure is a bug and is reported loudly). Results stream to
//! `OUT/alternatives.jsonl` one line per alternative as it finishes, so a killed run
//! loses nothing and `--resume` skips what is done. [`output`] decides where a run may
//! write, what it may delete (only what an earlier run listed in its manifest) and when
//! its records may be reused.

pub mod output;
pub mod plan;
mod record;
mod run;

pub use plan::Plan;
pub use record::{AlternativeRecord, Summary, Tally, Timings, level_distribution};
pub use run::{
    Alternative, Evaluation, FailedModel, SHARD_REPORT, SHARD_TASK, SearchError, SearchOptions,
    ShardReport, Share, check_search, evaluate_units, finish, open_output, plan, prepare, run,
    run_shard, settings, tally_records,
};
