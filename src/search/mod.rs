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
//! records may be reused, and locks the directory ([`lock`]: one run at a time); at the
//! end [`mod@parquet`] writes the records again as `alternatives.parquet`. A run can be one shard of the search ([`run_shard`]; see
//! `distribute`).
//!
//! Each phase has its own file, in the order a run takes them: `options` (what they all
//! share: settings, errors, an alternative, what an evaluation reports) → `plan` →
//! `open` (the output directory) → `schedule` (the units on a pool, records streamed) →
//! `evaluate` (one alternative; `measure`: what its judges look at) → `finish`
//! (`readback` of the records, the summary) → `designs` → `report`; `run` calls them in
//! that order.

mod designs;
mod evaluate;
mod finish;
pub mod guide;
pub mod lock;
mod measure;
pub mod modes;
mod open;
mod options;
pub mod output;
pub mod parquet;
pub mod plan;
mod progress;
mod readback;
mod record;
mod report;
mod run;
mod schedule;
pub mod strategy;
mod warm;

pub use designs::{model_meta, remeasure};
pub use evaluate::prepare;
pub use finish::finish;
pub use open::{open_output, settings};
pub use options::{
    Alternative, EXPORT_TOP, Evaluation, ExportCount, FailedModel, REPORT_DESIGNS, REPORT_MOTIONS,
    SHARD_REPORT, SHARD_TASK, SearchError, SearchOptions, ShardReport, Share, check_search,
};
pub use plan::{Plan, plan};
pub use progress::{
    LINE_INTERVAL, Progress, ProgressEvent, ProgressHook, human_duration, status_line,
};
pub use readback::tally_records;
pub use record::{AlternativeRecord, RankEntry, Summary, Tally, Timings, level_distribution};
pub use run::{run, run_shard};
pub use schedule::evaluate_units;
pub use strategy::{Budget, Coverage, Selection, Strategy, VertexCoverage};
