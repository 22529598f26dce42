//! What every phase of a search shares: its settings, its errors, one alternative, the
//! share of the search a run evaluates and what evaluating it reports, and the check that
//! a task can be searched at all. It imports none of the phases.

use super::output::{self, ShardSpec};
use super::progress::ProgressHook;
use super::record::Timings;
use super::strategy::{Budget, Strategy};
use crate::grammar::Rules;
use crate::limits;
use crate::model::ModelError;
use crate::task::Task;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Settings of a search.
#[derive(Clone, Debug)]
pub struct SearchOptions {
    /// Output directory.
    pub out: PathBuf,
    /// Worker threads (0: one per core).
    pub jobs: usize,
    /// Starting points per alternative.
    pub starts: usize,
    /// Seed of the starting points.
    pub seed: u64,
    /// Skip alternatives already in `OUT/alternatives.jsonl` (only of a run of the same
    /// settings).
    pub resume: bool,
    /// Use a directory that is not an earlier run of the same settings: replace a
    /// foldsynth run of other settings (deleting only its listed files), or write into a
    /// foreign directory (deleting nothing).
    pub force: bool,
    /// Override the task's N_max.
    pub n_max: Option<usize>,
    /// States of the verification sweep over [0, t_max].
    pub sweep: usize,
    /// Write FOLD/SVG/OBJ/STL/pictures/GIF for feasible designs (the design JSONs and the
    /// report are written either way); how many: [`SearchOptions::export_top`].
    pub export: bool,
    /// With `export`, the files of only the this many most robust designs (the report's
    /// ranking); `None`: of every design. The report gives the others' command.
    pub export_top: Option<usize>,
    /// How many of the most robust designs `report.html` draws with their whole motion
    /// (the others with their folded form); `None`: every design.
    pub report_motions: Option<usize>,
    /// `report.html` carries the card, 3D view and crease pattern of this many of the most
    /// robust designs, and every other design as a row of its table; `None`: every design
    /// in full (`--report-designs N|all`, default [`REPORT_DESIGNS`]).
    pub report_designs: Option<usize>,
    /// Show progress on stderr: a bar on a terminal, a status line every few seconds
    /// otherwise (see [`Progress`](super::Progress)).
    pub progress: bool,
    /// The grammar's rules (default r1, r2; r2′ adds cyclic patterns).
    pub rules: Rules,
    /// Today's behaviour before issue 12: optimize without the robustness block and only
    /// check afterwards (for side-by-side comparisons).
    pub post_check_only: bool,
    /// Exhaustive (every alternative) or guided (the most promising models first, up to
    /// `budget`; see [`guide`](super::guide)).
    pub strategy: Strategy,
    /// What a guided search may spend.
    pub budget: Budget,
    /// A guided search also starts an alternative whose quasi-random starts failed from
    /// its parent's optimum, where the parent was optimized earlier in the run (off:
    /// exactly the exhaustive search's records).
    pub warm_starts: bool,
    /// Told of every step of the run's progress, and able to stop it (the Python
    /// package's progress callback and Ctrl-C); `None` for the CLI.
    pub on_progress: Option<ProgressHook>,
    /// Search only these graphs (rule sequences, as `foldsynth enumerate` names the
    /// meaningful graphs; `synthesize --graph`): every alternative of each; empty: every
    /// meaningful graph up to N_max.
    pub graphs: Vec<String>,
}

impl Default for SearchOptions {
    fn default() -> Self {
        SearchOptions {
            out: PathBuf::from("out"),
            jobs: 0,
            starts: 16,
            seed: 0,
            resume: false,
            force: false,
            n_max: None,
            sweep: 181,
            export: true,
            export_top: Some(EXPORT_TOP),
            report_motions: Some(REPORT_MOTIONS),
            report_designs: Some(REPORT_DESIGNS),
            progress: true,
            rules: Rules::default(),
            post_check_only: false,
            strategy: Strategy::Exhaustive,
            budget: Budget::default(),
            warm_starts: true,
            on_progress: None,
            graphs: Vec::new(),
        }
    }
}

/// How many of the most robust designs a run exports by default (`--export N`).
pub const EXPORT_TOP: usize = 20;

/// How many of the most robust designs `report.html` draws with their whole motion by
/// default (`--report-motions N|all`); the others with their folded form alone (a design's motion is 5–8 KB of the page: a run's
/// page stays a few MB however many designs it keeps, issue 35).
pub const REPORT_MOTIONS: usize = 100;

/// How many of the most robust designs `report.html` carries in full by default
/// (`--report-designs N|all`): a design in full is about 3 KB of the page with its folded
/// form, a row of the table about 100 bytes, so a run of 100,000 designs makes a page of
/// about 13 MB (issue 34).
pub const REPORT_DESIGNS: usize = 1000;

/// `--export N|all` (the files of the N most robust designs, or of all), also
/// `--report-motions N|all` and `--report-designs N|all`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExportCount(pub Option<usize>);

impl std::fmt::Display for ExportCount {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            Some(n) => write!(f, "{n}"),
            None => write!(f, "all"),
        }
    }
}

impl std::str::FromStr for ExportCount {
    type Err = String;
    fn from_str(s: &str) -> Result<ExportCount, String> {
        if s.trim().eq_ignore_ascii_case("all") {
            return Ok(ExportCount(None));
        }
        s.trim()
            .parse::<usize>()
            .map(|n| ExportCount(Some(n)))
            .map_err(|_| {
                format!(
                    "'{}' is neither a number of designs nor 'all' (e.g. 50 or all)",
                    crate::text::excerpt(s, 40)
                )
            })
    }
}

/// An error of the search.
#[derive(Debug, thiserror::Error)]
pub enum SearchError {
    /// The task cannot be searched.
    #[error("task '{task}': {message}")]
    Task {
        /// Task name.
        task: String,
        /// What is missing.
        message: String,
    },
    /// Reading or writing files.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The error.
        source: std::io::Error,
    },
    /// A records file holds a line that is not a record of this search.
    #[error("{path}, line {line}: {message}")]
    Records {
        /// The file.
        path: String,
        /// 1-based line number (0: unknown).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The output directory cannot be used (see [`super::output`]).
    #[error(transparent)]
    Output(#[from] output::OutputError),
    /// A model could not be built.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// Export failed.
    #[error("export: {0}")]
    Export(String),
    /// The run was stopped through its [`ProgressHook`] before every alternative was
    /// evaluated; the records written so far stay for `--resume`.
    #[error(
        "{out}: the search was interrupted; the records written so far are kept: run it again with resume (--resume) to continue"
    )]
    Interrupted {
        /// The output directory.
        out: String,
    },
}

/// One design alternative: a graph, a gripping candidate and a mode assignment.
#[derive(Clone, Debug)]
pub struct Alternative {
    /// Index among the meaningful graphs.
    pub graph: usize,
    /// Gripping candidate 0, 1, 2.
    pub candidate: usize,
    /// Bit i set: internal vertex i (extension order) in mode down.
    pub modes: u32,
    /// Number of internal vertices.
    pub n: usize,
    /// The graph's rule sequence.
    pub sequence: String,
}

impl Alternative {
    /// ±1 per internal vertex.
    pub fn mode_signs(&self) -> Vec<f64> {
        (0..self.n)
            .map(|i| if self.modes >> i & 1 == 1 { -1.0 } else { 1.0 })
            .collect()
    }
    /// "up"/"down" per internal vertex.
    pub fn mode_names(&self) -> Vec<String> {
        self.mode_signs()
            .iter()
            .map(|m| if *m > 0.0 { "up".into() } else { "down".into() })
            .collect()
    }
    /// The record key.
    pub fn key(&self) -> String {
        format!(
            "{}|{}|{}",
            self.sequence,
            self.candidate + 1,
            self.mode_names().join(",")
        )
    }
}

/// Which part of the search a run evaluates: a shard's units (see `distribute`).
#[derive(Clone, Copy, Debug)]
pub struct Share<'a> {
    /// The shard, as its settings record it.
    pub spec: ShardSpec,
    /// Its units (indices into [`Plan::units`](super::Plan::units)).
    pub units: &'a [usize],
    /// The task file's text: kept in the shard's directory (`task.toml`) so that
    /// `merge` rebuilds the designs from exactly the task the shard ran.
    pub task_text: &'a str,
}

/// A model that could not be built or compiled: its alternatives have no records (when
/// only its robustness block fails, which shows when an alternative first needs it, those
/// that never needed it keep theirs).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FailedModel {
    /// The graph's rule sequence.
    pub sequence: String,
    /// Gripping candidate 1, 2, 3.
    pub candidate: usize,
    /// Why.
    pub error: String,
}

/// What evaluating (part of) a search did, besides writing its records.
#[derive(Clone, Debug, Default)]
pub struct Evaluation {
    /// Seconds spent compiling (summed over the workers).
    pub compile_s: f64,
    /// Worker threads.
    pub jobs: usize,
    /// Records reused from an earlier run (`--resume`).
    pub resumed: usize,
    /// What `--resume` kept and dropped.
    pub resume: Option<output::ResumeReport>,
    /// Models that failed.
    pub failed: Vec<FailedModel>,
}

/// What a shard's run leaves in `OUT/shard.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ShardReport {
    /// The shard.
    pub shard: ShardSpec,
    /// Units (compiled models) in the shard.
    pub units: usize,
    /// Alternatives in the shard.
    pub alternatives: u64,
    /// Records in `alternatives.jsonl` (all of the shard's alternatives but those of
    /// failed models once it is complete).
    pub records: usize,
    /// Estimated cost of the shard (see `plan::Unit::cost`).
    pub cost: u64,
    /// Estimated cost of the whole search.
    pub total_cost: u64,
    /// Models that failed (see [`FailedModel`] for which alternatives have no records).
    pub failed_models: Vec<FailedModel>,
    /// Time per stage; `total_s` is this run's wall time.
    pub timings: Timings,
}

/// The shard's report file.
pub const SHARD_REPORT: &str = "shard.json";
/// The task file a shard keeps.
pub const SHARD_TASK: &str = "task.toml";

/// Check that `task` can be searched with `opts`; the N_max to use.
pub fn check_search(task: &Task, opts: &SearchOptions) -> Result<usize, SearchError> {
    let terr = |m: &str| SearchError::Task {
        task: task.name.clone(),
        message: m.to_string(),
    };
    if task.objective.is_none() {
        return Err(terr(
            "no [objective]: a search needs targets for the gripping vertex",
        ));
    }
    if task.bounds.is_none() {
        return Err(terr(
            "no [bounds]: a search needs l_min, l_max, alpha_min, alpha_max",
        ));
    }
    if task.motion.is_none() {
        return Err(terr("no [motion]: a search needs t_max"));
    }
    let n_max = opts.n_max.unwrap_or(task.n_max);
    // Every count is checked before anything is allocated.
    let counts = [
        ("N_max", n_max as u64, 1, limits::N_MAX as u64),
        ("starts", opts.starts as u64, 1, limits::STARTS_MAX as u64),
        ("sweep", opts.sweep as u64, 2, limits::SWEEP_MAX as u64),
        ("jobs", opts.jobs as u64, 0, limits::JOBS_MAX as u64),
    ];
    for (what, value, min, max) in counts {
        limits::check_count(what, value, min, max).map_err(|m| terr(&m))?;
    }
    check_budget(opts).map_err(|m| terr(&m))?;
    Ok(n_max)
}

/// A budget belongs to a guided search and must be something to spend.
fn check_budget(opts: &SearchOptions) -> Result<(), String> {
    let b = opts.budget;
    if opts.strategy == Strategy::Exhaustive && (b.alternatives.is_some() || b.cpu_s.is_some()) {
        return Err(
            "a budget (alternatives or CPU seconds) is for the guided search: add --strategy guided, or drop the budget to evaluate every alternative".into(),
        );
    }
    if b.alternatives == Some(0) {
        return Err("the budget of alternatives is 0; give at least 1".into());
    }
    if let Some(s) = b.cpu_s
        && !(s.is_finite() && s > 0.0 && s <= limits::BUDGET_CPU_MAX)
    {
        return Err(format!(
            "the CPU budget {s} s is not a number of seconds in (0, {}]",
            limits::BUDGET_CPU_MAX
        ));
    }
    Ok(())
}
