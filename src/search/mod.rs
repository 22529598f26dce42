//! The search over design alternatives (thesis Fig. 39, Sec. 5.3–5.6): every meaningful
//! graph × every gripping candidate × every assignment of rigid body modes.
//!
//! The work goes by unit ([`mod@plan`]): one (graph, candidate) is one model, compiled once
//! when a worker takes the unit up and dropped after its last alternative; the 2^N mode
//! assignments are parameters of that one native function. Each alternative is
//! optimized; when it meets the target it is checked for self-intersection (both arms for
//! a two-armed task) and against the obstacles, and verified independently (a
//! verification failure is a bug and is reported loudly). Results stream to
//! `OUT/alternatives.jsonl` one line per alternative as it finishes, so a killed run
//! loses nothing and `--resume` skips what is done; the summary, designs and report are
//! made by reading that file back line by line. Nothing is kept per alternative but one
//! bit, so memory does not grow with N_max. [`output`] decides where a run may write,
//! what it may delete (only what an earlier run listed in its manifest) and when its
//! records may be reused. A run can be one shard of the search ([`run_shard`]; see
//! `distribute`).

pub mod output;
pub mod plan;
mod progress;
mod record;
mod report;
mod run;

pub use plan::Plan;
pub use progress::{LINE_INTERVAL, Progress, human_duration, status_line};
pub use record::{AlternativeRecord, RankEntry, Summary, Tally, Timings, level_distribution};
pub use run::{
    Alternative, Evaluation, FailedModel, SHARD_REPORT, SHARD_TASK, SearchError, SearchOptions,
    ShardReport, Share, check_search, evaluate_units, finish, model_meta, open_output, plan,
    prepare, remeasure, run, run_shard, settings, tally_records,
};
