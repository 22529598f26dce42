//! Running a search: scheduling, streaming, resuming, summarizing, exporting.

use super::output::{self, OutputDir, RECORDS, RunSettings, SETTINGS, ShardSpec};
use super::plan::{Done, Plan};
use super::progress::Progress;
use super::record::{AlternativeRecord, RankEntry, Summary, Tally, Timings};
use super::report::{report_design, report_input, task_facts};
use crate::check::robustness::{self, RobustnessInput, UnitCreases};
use crate::check::verify::{Tolerances, verify_folded};
use crate::check::{CheckError, Checker, Cylinder, MotionSettings, check_states, two_armed};
use crate::compile::Options as CompileOptions;
use crate::cpu_time::Stopwatch;
use crate::export::{self, DesignMeta, ExportOptions};
use crate::grammar::{CreaseGraph, Rules};
use crate::limits;
use crate::model::compiled::{CompiledModel, ModelProblem, objective_target};
use crate::model::numeric::{Evaluated, sample_times};
use crate::model::robust::{Deferred, LazyBlock, RobustSpec};
use crate::model::{Model, ModelError};
use crate::optimize::{self, SharedStarts, minimize_shared};
use crate::pattern::Pattern;
use crate::task::Task;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufRead, BufReader, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

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
    /// Write FOLD/SVG/OBJ/STL/pictures/GIF for every feasible design (the design JSONs and
    /// the report are written either way).
    pub export: bool,
    /// Show progress on stderr: a bar on a terminal, a status line every few seconds
    /// otherwise (see [`Progress`]).
    pub progress: bool,
    /// The grammar's rules (default r1, r2; r2′ adds cyclic patterns).
    pub rules: Rules,
    /// Today's behaviour before issue 12: optimize without the robustness block and only
    /// check afterwards (for side-by-side comparisons).
    pub post_check_only: bool,
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
            progress: true,
            rules: Rules::default(),
            post_check_only: false,
        }
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

/// A compiled model ready for its 2^N alternatives.
pub struct Prepared {
    /// The model.
    pub model: Model,
    /// Its native code.
    pub compiled: CompiledModel,
    /// Its robustness block (absent with `--post-check-only`), compiled when an
    /// alternative first needs it.
    pub robust: Option<LazyBlock>,
}

/// Build and compile the model of one graph and candidate, with its robustness block
/// (compiled on first use) when `robust` is given.
pub fn prepare(
    graph: &CreaseGraph,
    task: &Task,
    candidate: usize,
    robust: Option<&RobustSpec>,
) -> Result<Prepared, String> {
    let model = Model::new(graph, task, candidate).map_err(|e| e.to_string())?;
    let compiled =
        CompiledModel::new(&model, &CompileOptions::default()).map_err(|e| e.to_string())?;
    let robust = robust.map(|spec| LazyBlock::new(spec.clone()));
    Ok(Prepared {
        model,
        compiled,
        robust,
    })
}

/// A 64-bit mix (splitmix64) of the run's seed and an alternative's key: every alternative
/// gets its own reproducible starting points, whatever the scheduling.
fn alternative_seed(seed: u64, key: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in key.bytes() {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    let mut z = seed ^ h;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The obstacles of the task as the checks take them.
fn obstacles(task: &Task) -> Vec<Cylinder> {
    task.check
        .as_ref()
        .map(|c| c.cylinders.clone())
        .unwrap_or_default()
}

/// The pattern checks and exports work on: the arm, with its rotated copy for two-armed
/// tasks.
fn checked_pattern(task: &Task, arm: &Pattern) -> Result<Pattern, String> {
    if task.check.as_ref().is_some_and(|c| c.second_arm) {
        two_armed(arm).map_err(|e| e.to_string())
    } else {
        Ok(arm.clone())
    }
}

/// Why an intersection check could not run.
enum CheckFailure {
    /// The flat layout is invalid (counts as a self-intersection).
    Layout(String),
    /// Anything else (reported).
    Other(String),
}

/// Optimize, check and verify one alternative; `shared`: the phase-A starts of its class
/// (the alternatives of its model whose modes differ only where no output depends on
/// them), whose seed it optimizes with. An error when the model's robustness block was
/// needed and could not be compiled.
fn evaluate(
    task: &Task,
    p: &Prepared,
    alt: &Alternative,
    graph: &CreaseGraph,
    opts: &SearchOptions,
    shared: &SharedStarts,
) -> Result<AlternativeRecord, String> {
    let model = &p.model;
    let modes = alt.mode_signs();
    let key = alt.key();
    let t0 = Stopwatch::start();
    let problem = ModelProblem::new(model, &p.compiled, &modes);
    let optimize_opts = optimize::Options {
        starts: opts.starts,
        seed: shared.seed(),
        target: Some(objective_target(model)),
        max_outer: if model.plan.sinks.is_empty() {
            optimize::Options::default().max_outer
        } else {
            crate::model::cycle::MAX_OUTER
        },
        ..Default::default()
    };
    // CPU seconds this alternative spent compiling the model's robustness block: compile
    // time, not optimization.
    let mut block_compile_s = 0.0;
    let mut sol = match &p.robust {
        None => minimize_shared(&problem, None, &optimize_opts, Some(shared)),
        Some(lazy) => {
            let rp = Deferred::new(model, lazy, &modes);
            let sol = minimize_shared(&problem, Some(&rp), &optimize_opts, Some(shared));
            if let Some(e) = rp.error() {
                return Err(e.to_string());
            }
            block_compile_s = rp.compile_s();
            sol
        }
    };
    // Cyclic patterns: Newton on the compatibility equations, to rounding.
    crate::model::cycle::polish_solution(
        &problem,
        model,
        &modes,
        &mut sol,
        optimize_opts.feasibility_tol,
        optimize_opts.target,
    );
    let optimize_ms = t0.cpu_ms() - block_compile_s * 1e3;
    let full = model.full_vars(&sol.x);
    let omega = model.omega(&full, &modes);
    let meets = sol.feasible && omega <= model.threshold;
    let variables: BTreeMap<String, f64> = model
        .free
        .iter()
        .zip(&sol.x)
        .map(|(&i, x)| (model.plan.variables[i].name.clone(), *x))
        .collect();
    let mut rec = AlternativeRecord {
        key,
        graph: alt.graph,
        sequence: alt.sequence.clone(),
        level: graph.level(),
        internal_vertices: alt.n,
        candidate: alt.candidate + 1,
        gripping_vertex: model.plan.vertices[model.gripping].name,
        modes: alt.mode_names(),
        objective: omega,
        feasible: sol.feasible,
        max_violation: sol.violation,
        min_slack: sol.g.iter().copied().fold(f64::INFINITY, f64::min),
        meets_target: meets,
        self_intersection_free: None,
        self_intersection: None,
        layout_defect: None,
        obstacle_free: None,
        obstacle_hit: None,
        verification: None,
        verification_failed: None,
        robust_accepted: sol.robust,
        robust_attempts: sol.robust_attempts,
        robustness: None,
        short_of_margins: Vec::new(),
        variables,
        starts_run: sol.starts_run,
        evaluations: sol.evaluations,
        optimize_ms,
        check_ms: 0.0,
        cycle: None,
    };
    if !meets {
        return Ok(rec);
    }
    let t1 = Stopwatch::start();
    let design = Evaluated::new(&model.plan, full, modes);
    // The judges run on the dense verification sweep, not only on the states the optimizer
    // saw, so an intersection between sampled states cannot hide.
    // Each state folded once, for the pattern the checks judge and for `verify`.
    let sweep = sample_times(model.t_max, opts.sweep);
    let folds = design.fold_all(&sweep);
    let arm = design.pattern_of(&sweep, &folds);
    let checked = checked_pattern(task, &arm)
        .map_err(CheckFailure::Other)
        .and_then(|pat| {
            let mut checker = Checker::from_pattern(&pat).map_err(|e| match e {
                // A facet that cannot be triangulated is inverted or overlaps itself in the
                // flat layout: the paper crosses itself before it folds.
                CheckError::Triangulate(t) => CheckFailure::Layout(t.to_string()),
                e => CheckFailure::Other(e.to_string()),
            })?;
            if pat.faces.len() > arm.faces.len() {
                // `two_armed`: the second arm is the first turned by exactly 180°.
                checker = checker.with_half_turn_copy(arm.faces.len());
            }
            let s = check_states(
                &checker,
                Some(&pat.vertices),
                pat.frames.iter().map(|f| (f.t, f.coords.clone())),
                &MotionSettings {
                    n_states: opts.sweep,
                    stop_at_first: true,
                    obstacles: Vec::new(),
                },
            )
            .map_err(|e| CheckFailure::Other(e.to_string()))?;
            let cyl = obstacles(task);
            let hit = pat.frames.iter().find_map(|f| {
                cyl.iter().enumerate().find_map(|(k, c)| {
                    checker
                        .obstacle_hits(&f.coords, c, k, f.t, true)
                        .first()
                        .copied()
                })
            });
            Ok((s, hit, pat))
        });
    let mut checked_pattern = None;
    match checked {
        Ok((s, hit, pat)) => {
            rec.self_intersection_free = Some(s.self_intersection_free());
            rec.self_intersection = s.first_intersection().cloned();
            rec.obstacle_free = Some(hit.is_none());
            rec.obstacle_hit = hit;
            checked_pattern = Some(pat);
        }
        Err(CheckFailure::Layout(why)) => {
            rec.self_intersection_free = Some(false);
            rec.layout_defect = Some(why);
        }
        Err(CheckFailure::Other(e)) => {
            eprintln!("warning: {}: the intersection check failed: {e}", rec.key);
        }
    }
    let tol = Tolerances::default();
    let report = verify_folded(&design, &sweep, &folds, &tol);
    let failed = !report.geometry_passes(&tol);
    if failed && model.plan.sinks.is_empty() {
        eprintln!(
            "BUG: verification failed for {} (graph {}): {}",
            rec.key,
            rec.sequence,
            report.failures(&tol).join("; ")
        );
    }
    if !model.plan.sinks.is_empty() {
        // A cyclic design (r2′): the PTU's frames are only right where the cycle closes, so
        // the sweep and the simulation decide; a geometric failure is a bug only then.
        let verdict = crate::simulate::crossval::verify_cyclic(
            model,
            &design.vars,
            &design.modes,
            opts.sweep,
            tol.geometry_margin,
        );
        let failed = failed && verdict.sweep.passes(crate::check::cycle::CYCLE_TOL);
        rec.verification_failed = Some(failed);
        rec.cycle = Some(verdict);
    } else {
        rec.verification_failed = Some(failed);
    }
    rec.verification = Some(report);
    // Margins are a design's: measured only where every check passed (with
    // `--post-check-only` most target-meeting alternatives fail one, and measuring them was
    // half of that run's check time; issue 14).
    if let Some(pat) = checked_pattern.filter(|_| rec.passes_checks()) {
        rec.robustness = match measure_robustness(task, model, &arm, &pat) {
            Ok(r) => Some(r),
            Err(e) => {
                eprintln!(
                    "warning: {}: the robustness measurement failed: {e}",
                    rec.key
                );
                None
            }
        };
        rec.short_of_margins = rec.margins_short();
    }
    rec.check_ms = t1.cpu_ms();
    Ok(rec)
}

/// The robustness of a design measured by `check::robustness` on the checked pattern
/// (`pat`: the arm, or both arms) at the sweep's frames.
fn measure_robustness(
    task: &Task,
    model: &Model,
    arm: &Pattern,
    pat: &Pattern,
) -> Result<robustness::RobustnessReport, String> {
    let plan = &model.plan;
    let face_names: Vec<String> = plan
        .polygons
        .iter()
        .enumerate()
        .filter(|(_, (p, _))| p.len() >= 3)
        .map(|(f, _)| plan.facet_names[f].clone())
        .collect();
    let n = arm.vertices.len();
    let vertex_names = (0..pat.vertices.len())
        .map(|v| {
            if v < n {
                format!("v{}", plan.vertices[v].name)
            } else {
                format!("copy #{}", v - n + 1)
            }
        })
        .collect();
    let units = plan
        .internal
        .iter()
        .map(|&a| {
            let v = &plan.vertices[a];
            let m = v.preds;
            UnitCreases {
                vertex: a,
                ends: [0, 1, 2].map(|k| v.rays[m + k].other),
                label: format!("v{}", v.name),
            }
        })
        .collect();
    let cylinders = obstacles(task);
    // The arms of a two-armed gripper meet at a target on the rotation axis: their tips
    // touch there by design (the copy of the gripping vertex is found by its flat position).
    let tip = (pat.vertices.len() > n
        && model
            .targets
            .iter()
            .any(|t| t.point[0].abs() < 1e-9 && t.point[1].abs() < 1e-9))
    .then(|| {
        let g = model.gripping;
        let q = [-arm.vertices[g][0], -arm.vertices[g][1]];
        (n..pat.vertices.len())
            .find(|&j| (pat.vertices[j][0] - q[0]).hypot(pat.vertices[j][1] - q[1]) <= 1e-9)
            .map(|c| (g, c))
    })
    .flatten();
    let input = RobustnessInput {
        pattern: pat,
        arm_faces: arm.faces.len(),
        face_names,
        vertex_names,
        cylinders: &cylinders,
        units,
        tip,
        t_max: model.t_max,
        settings: task.robustness,
        arm,
    };
    robustness::measure(&input).map_err(|e| e.to_string())
}

/// The model of a record's graph and candidate, and the record's free variables, all
/// variables and mode signs.
type Design = (Model, Vec<f64>, Vec<f64>, Vec<f64>);

/// Rebuild a recorded design ([`Design`]).
fn design_of(
    task: &Task,
    graph: &CreaseGraph,
    rec: &AlternativeRecord,
) -> Result<Design, SearchError> {
    let model = Model::new(graph, task, rec.candidate - 1)?;
    let free: Vec<f64> = model
        .free
        .iter()
        .map(|&i| {
            rec.variables
                .get(&model.plan.variables[i].name)
                .copied()
                .unwrap_or(model.var_bounds(i).0)
        })
        .collect();
    let full = model.full_vars(&free);
    let modes: Vec<f64> = rec
        .modes
        .iter()
        .map(|m| if m == "up" { 1.0 } else { -1.0 })
        .collect();
    Ok((model, free, full, modes))
}

/// The robustness of a recorded design measured again by `check::robustness` on a sweep of
/// `states` states (e.g. denser than the search's): `graph` is the record's graph (the
/// enumeration's meaningful graphs, in order, indexed by `rec.graph`).
pub fn remeasure(
    task: &Task,
    graph: &CreaseGraph,
    rec: &AlternativeRecord,
    states: usize,
) -> Result<robustness::RobustnessReport, String> {
    let (model, _, full, modes) = design_of(task, graph, rec).map_err(|e| e.to_string())?;
    let design = Evaluated::new(&model.plan, full, modes);
    let arm = design.pattern(&sample_times(model.t_max, states.max(2)));
    let pat = checked_pattern(task, &arm)?;
    measure_robustness(task, &model, &arm, &pat)
}

/// Which part of the search a run evaluates: a shard's units (see `distribute`).
#[derive(Clone, Copy, Debug)]
pub struct Share<'a> {
    /// The shard, as its settings record it.
    pub spec: ShardSpec,
    /// Its units (indices into [`Plan::units`]).
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
    Ok(n_max)
}

/// The plan of `task`'s search at `n_max`; an error when there is nothing to search.
pub fn plan(task: &Task, n_max: usize, rules: Rules) -> Result<Plan, SearchError> {
    let plan = Plan::with_rules(task, n_max, rules);
    if plan.graphs.is_empty() {
        return Err(SearchError::Task {
            task: task.name.clone(),
            message: format!(
                "G0 generates no meaningful graph up to N_max = {n_max} (see `foldsynth enumerate`): there is nothing to optimize"
            ),
        });
    }
    Ok(plan)
}

/// The settings of a search of `task` at `n_max` with `opts` (and of shard `shard`).
pub fn settings(
    task: &Task,
    n_max: usize,
    opts: &SearchOptions,
    shard: Option<ShardSpec>,
) -> RunSettings {
    RunSettings {
        task: task.name.clone(),
        task_digest: task.digest.clone(),
        n_max,
        starts: opts.starts,
        seed: opts.seed,
        sweep: opts.sweep,
        foldsynth: env!("CARGO_PKG_VERSION").into(),
        rules: (opts.rules != Rules::default()).then(|| opts.rules.names()),
        post_check_only: opts.post_check_only,
        shard,
    }
}

/// Open the output directory for a run of `settings` and write its settings file.
pub fn open_output(
    settings: &RunSettings,
    opts: &SearchOptions,
) -> Result<(OutputDir, bool), SearchError> {
    let opened = OutputDir::open(&opts.out, settings, opts.resume, opts.force)?;
    for note in &opened.notes {
        eprintln!("note: {note}");
    }
    let out = opened.dir;
    out.write(
        SETTINGS,
        serde_json::to_string_pretty(settings).unwrap_or_default() + "\n",
    )?;
    Ok((out, opened.resume))
}

/// Run the search of `task` and write everything under `opts.out`.
pub fn run(task: &Task, opts: &SearchOptions) -> Result<Summary, SearchError> {
    let start = Instant::now();
    let n_max = check_search(task, opts)?;
    let progress = Progress::new(opts.progress);
    progress.phase("enumerate graphs", "graphs", None);
    let plan = plan(task, n_max, opts.rules)?;
    progress.inc(plan.graphs.len() as u64);
    progress.finish_phase_with(&format!(
        "{} generated, {} meaningful",
        plan.generated,
        plan.graphs.len()
    ));
    let (out, resume) = open_output(&settings(task, n_max, opts, None), opts)?;
    let all: Vec<usize> = (0..plan.units.len()).collect();
    let ev = evaluate_units(task, &plan, &all, &out, resume, opts, &progress)?;
    finish(task, &plan, &out, opts, &ev, start, &progress)
}

/// Run shard `share` of the search of `task` (planned as `plan`) into `opts.out`: its
/// records, the task file and `shard.json`; `merge` makes the whole run of the shards.
pub fn run_shard(
    task: &Task,
    plan: &Plan,
    share: Share<'_>,
    opts: &SearchOptions,
) -> Result<ShardReport, SearchError> {
    let start = Instant::now();
    let n_max = check_search(task, opts)?;
    let (out, resume) = open_output(&settings(task, n_max, opts, Some(share.spec)), opts)?;
    out.write(SHARD_TASK, share.task_text)?;
    let progress = Progress::new(opts.progress);
    let ev = evaluate_units(task, plan, share.units, &out, resume, opts, &progress)?;
    drop(progress);
    let tally = tally_records(plan, &out.path(RECORDS))?.0;
    let report = ShardReport {
        shard: share.spec,
        units: share.units.len(),
        alternatives: share.units.iter().map(|&u| plan.units[u].count).sum(),
        records: tally.records,
        cost: plan.cost(share.units),
        total_cost: plan.units.iter().map(|u| u.cost).sum(),
        failed_models: ev.failed,
        timings: Timings {
            enumerate_s: plan.enumerate_s,
            compile_s: ev.compile_s,
            optimize_s: tally.optimize_ms / 1e3 + 0.0,
            check_s: tally.check_ms / 1e3 + 0.0,
            export_s: 0.0,
            total_s: start.elapsed().as_secs_f64(),
            cpu_s: crate::cpu_time::process_seconds(),
        },
    };
    out.write(
        SHARD_REPORT,
        serde_json::to_string_pretty(&report).unwrap_or_default() + "\n",
    )?;
    Ok(report)
}

/// Evaluate every alternative of `units` not yet in `OUT/alternatives.jsonl` (with
/// `resume`, the records of an earlier run of the same settings are kept), streaming
/// each record to the file as it finishes.
///
/// Work goes by unit: a worker builds and compiles a unit's model, its alternatives are
/// evaluated (in parallel), and the model is dropped when they are done. Memory holds
/// the models in flight (about one per worker), not one per unit.
pub fn evaluate_units(
    task: &Task,
    plan: &Plan,
    units: &[usize],
    out: &OutputDir,
    resume: bool,
    opts: &SearchOptions,
    progress: &Progress,
) -> Result<Evaluation, SearchError> {
    let mut mine = vec![false; plan.units.len()];
    for &u in units {
        mine[u] = true;
    }
    let mut done = Done::new(plan.alternatives);
    let (records_file, report) = output::keep_records(out, resume, &mut |r| {
        let place = plan
            .locate(&r.key)
            .filter(|p| mine[p.unit])
            .ok_or_else(|| {
                format!(
                    "alternative {} is not part of this search",
                    crate::text::excerpt(&r.key, 200)
                )
            })?;
        if done.insert(place.index) {
            Ok(())
        } else {
            Err(format!(
                "alternative {} appears again",
                crate::text::excerpt(&r.key, 200)
            ))
        }
    })?;
    if let Some(report) = &report {
        eprintln!("{}", report.text(&out.path(RECORDS)));
    }
    // The units with work left; their modes are listed when a worker takes them up.
    let done = &done;
    let undone = move |u: usize| {
        let unit = &plan.units[u];
        (0..unit.count as u32).filter(move |&m| !done.contains(unit.first + u64::from(m)))
    };
    let todo: Vec<usize> = units
        .iter()
        .copied()
        .filter(|&u| undone(u).next().is_some())
        .collect();
    let remaining: usize = todo.iter().map(|&u| undone(u).count()).sum();
    let writer = Mutex::new(records_file);
    let write_error: Mutex<Option<std::io::Error>> = Mutex::new(None);
    let compile_s = Mutex::new(0.0f64);
    let failed: Mutex<Vec<FailedModel>> = Mutex::new(Vec::new());
    let robust_spec = (!opts.post_check_only).then(|| RobustSpec::from_task(task, opts.sweep));
    progress.phase(
        "compile + optimize + check",
        "alternatives",
        Some(remaining as u64),
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()
        .map_err(|e| SearchError::Task {
            task: task.name.clone(),
            message: e.to_string(),
        })?;
    let lock = |m: &Mutex<f64>| *m.lock().unwrap_or_else(|e| e.into_inner());
    pool.install(|| {
        todo.par_iter().for_each(|&u| {
            let unit = &plan.units[u];
            let modes: Vec<u32> = undone(u).collect();
            let graph = plan.graph(task, unit.graph);
            let t = Stopwatch::start();
            let prepared = prepare(&graph, task, unit.candidate, robust_spec.as_ref());
            *compile_s.lock().unwrap_or_else(|e| e.into_inner()) += t.cpu_ms() / 1e3;
            let prepared = match prepared {
                Ok(p) => p,
                Err(error) => {
                    let sequence = plan.graphs[unit.graph].sequence.clone();
                    eprintln!(
                        "error: {sequence} (candidate {}): {error}",
                        unit.candidate + 1
                    );
                    failed
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .push(FailedModel {
                            sequence,
                            candidate: unit.candidate + 1,
                            error,
                        });
                    progress.inc(modes.len() as u64);
                    return;
                }
            };
            // The alternatives whose modes differ only where no output depends on them
            // are one optimization problem: a class shares its starts' phase A, with the
            // seed of its member whose unused modes are all up (issue 14).
            let unused: u32 = prepared
                .compiled
                .modes_used
                .iter()
                .enumerate()
                .filter(|(_, used)| !**used)
                .fold(0, |acc, (i, _)| acc | 1 << i);
            let mut classes: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
            for &m in &modes {
                classes.entry(m & !unused).or_default().push(m);
            }
            classes.par_iter().for_each(|(&canonical, members)| {
                let key = plan.alternative(u, canonical).key();
                let shared = SharedStarts::new(alternative_seed(opts.seed, &key));
                for &m in members {
                    let alt = plan.alternative(u, m);
                    let rec = match evaluate(task, &prepared, &alt, &graph, opts, &shared) {
                        Ok(rec) => rec,
                        Err(error) => {
                            // Every alternative that needs the block gets the same error:
                            // the model is reported once.
                            let mut failed = failed.lock().unwrap_or_else(|e| e.into_inner());
                            let sequence = &plan.graphs[unit.graph].sequence;
                            let candidate = unit.candidate + 1;
                            if !failed
                                .iter()
                                .any(|f| &f.sequence == sequence && f.candidate == candidate)
                            {
                                eprintln!("error: {sequence} (candidate {candidate}): {error}");
                                failed.push(FailedModel {
                                    sequence: sequence.clone(),
                                    candidate,
                                    error,
                                });
                            }
                            progress.inc(1);
                            continue;
                        }
                    };
                    let mut line = serde_json::to_string(&rec).unwrap_or_default();
                    line.push('\n');
                    if let Ok(mut w) = writer.lock() {
                        // One write per line, flushed: a kill loses at most this one.
                        if let Err(e) = w.write_all(line.as_bytes()).and_then(|_| w.flush())
                            && let Ok(mut first) = write_error.lock()
                        {
                            first.get_or_insert(e);
                        }
                    }
                    progress.inc(1);
                }
            });
            if let Some(block) = &prepared.robust {
                *compile_s.lock().unwrap_or_else(|e| e.into_inner()) += block.compile_s();
            }
            // `prepared` (the native code) is dropped here, with its last alternative.
        });
    });
    progress.finish_phase();
    if let Some(e) = write_error.into_inner().ok().flatten() {
        // A record that is not on disk would be lost to --resume: stop here.
        return Err(SearchError::Io {
            path: out.path(RECORDS).display().to_string(),
            source: e,
        });
    }
    let mut failed = failed.into_inner().unwrap_or_else(|e| e.into_inner());
    failed.sort_by(|a, b| (&a.sequence, a.candidate).cmp(&(&b.sequence, b.candidate)));
    Ok(Evaluation {
        compile_s: lock(&compile_s) + 0.0,
        jobs: pool.current_num_threads(),
        resumed: report.as_ref().map_or(0, |r| r.reused),
        resume: report,
        failed,
    })
}

/// Read a records file line by line: the summary's counts, and where each feasible
/// design's record is (its alternative number and the byte offset of its line), most
/// robust first (ties: enumeration order).
pub fn tally_records(plan: &Plan, path: &Path) -> Result<(Tally, Vec<(u64, u64)>), SearchError> {
    let io = |source| SearchError::Io {
        path: path.display().to_string(),
        source,
    };
    let mut reader = BufReader::new(File::open(path).map_err(io)?);
    let mut tally = Tally::default();
    let mut designs = Vec::new();
    let mut buf = String::new();
    let mut offset = 0u64;
    let mut line = 0usize;
    loop {
        buf.clear();
        let n = reader.read_line(&mut buf).map_err(io)?;
        if n == 0 {
            break;
        }
        line += 1;
        let bad = |why: String| SearchError::Records {
            path: path.display().to_string(),
            line,
            message: why,
        };
        let rec: AlternativeRecord =
            serde_json::from_str(&buf).map_err(|e| bad(format!("not a record ({e})")))?;
        tally.add(&rec);
        if rec.feasible_design() {
            let place = plan
                .locate(&rec.key)
                .ok_or_else(|| bad(format!("{} is not an alternative of this search", rec.key)))?;
            designs.push((rec.score(), place.index, offset));
        }
        offset += n as u64;
    }
    // Most robust first (ties: enumeration order).
    designs.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    Ok((tally, designs.into_iter().map(|(_, i, o)| (i, o)).collect()))
}

/// Summarize the records in `OUT/alternatives.jsonl` and write `summary.json`, the
/// designs and (with export) their files and the report. `start` is when the run began.
pub fn finish(
    task: &Task,
    plan: &Plan,
    out: &OutputDir,
    opts: &SearchOptions,
    ev: &Evaluation,
    start: Instant,
    progress: &Progress,
) -> Result<Summary, SearchError> {
    let records = out.path(RECORDS);
    let (tally, designs) = tally_records(plan, &records)?;
    let mut timings = Timings {
        enumerate_s: plan.enumerate_s,
        compile_s: ev.compile_s,
        optimize_s: tally.optimize_ms / 1e3 + 0.0,
        check_s: tally.check_ms / 1e3 + 0.0,
        export_s: 0.0,
        total_s: 0.0,
        cpu_s: 0.0,
    };
    let mut ids = Vec::with_capacity(designs.len());
    let mut summary = Summary {
        task: task.name.clone(),
        n_max: plan.n_max,
        graphs: plan.graphs.len(),
        alternatives: tally.records,
        meets_target: tally.meets_target,
        no_self_intersection: tally.no_self_intersection,
        no_intersection: tally.no_intersection,
        feasible: tally.feasible,
        rigid_at_tmax_only: tally.rigid_at_tmax_only,
        verification_failures: tally.verification_failures,
        thesis: if plan.n_max == 3 {
            Summary::thesis_counts(&task.name)
        } else {
            None
        },
        timings: timings.clone(),
        levels: tally.levels,
        settings: json!({
            "starts": opts.starts, "seed": opts.seed, "jobs": ev.jobs,
            "sweep": opts.sweep, "resumed": ev.resumed, "resume": ev.resume,
            "post_check_only": opts.post_check_only,
            "optimize_states": (!opts.post_check_only)
                .then(|| RobustSpec::from_task(task, opts.sweep).states),
            "robustness": {
                "rigid_margin": task.robustness.rigid_margin,
                "clearance": task.robustness.clearance,
                "obstacle_clearance": task.robustness.obstacle_clearance,
                "min_feature": task.robustness.min_feature,
            },
        }),
        meets_margins: tally.meets_margins,
        near_rigid_limit: tally.near_rigid_limit,
        short_of_margins: tally.short_of_margins,
        ranking: Vec::new(),
        designs: Vec::new(),
        cyclic: opts.rules.r2p.then(|| {
            let mut c = tally.cyclic.clone();
            c.graphs = plan.cyclic_graphs;
            c
        }),
    };
    // The ids and scores, most robust first (the order of `designs`), from the records.
    let mut ranking = Vec::with_capacity(designs.len());
    for chunk in designs.chunks(1024) {
        for rec in read_at(&records, chunk)? {
            ids.push(rec.id());
            ranking.push(RankEntry {
                id: rec.id(),
                score: rec.robustness.as_ref().map(|x| x.score),
            });
        }
    }
    summary.designs = ids;
    summary.ranking = ranking;

    let t2 = Instant::now();
    summary.timings.total_s = start.elapsed().as_secs_f64();
    write_designs(
        task, plan, &records, &designs, &summary, opts, out, progress,
    )?;
    timings.export_s = t2.elapsed().as_secs_f64();
    timings.total_s = start.elapsed().as_secs_f64();
    // A run (or a merge) is one process: its CPU time so far.
    timings.cpu_s = crate::cpu_time::process_seconds();
    summary.timings = timings;
    out.write(
        "summary.json",
        serde_json::to_string_pretty(&summary).unwrap_or_default(),
    )?;
    Ok(summary)
}

/// The records at `places` (alternative number, byte offset) of the records file.
fn read_at(path: &Path, places: &[(u64, u64)]) -> Result<Vec<AlternativeRecord>, SearchError> {
    let io = |source| SearchError::Io {
        path: path.display().to_string(),
        source,
    };
    let mut reader = BufReader::new(File::open(path).map_err(io)?);
    let mut buf = String::new();
    places
        .iter()
        .map(|&(_, offset)| {
            reader.seek(SeekFrom::Start(offset)).map_err(io)?;
            buf.clear();
            reader.read_line(&mut buf).map_err(io)?;
            serde_json::from_str(&buf).map_err(|e| SearchError::Records {
                path: path.display().to_string(),
                line: 0,
                message: format!("the record at byte {offset} is not readable any more ({e})"),
            })
        })
        .collect()
}

/// The export metadata of a design.
fn design_meta(task: &Task, model: &Model, rec: &AlternativeRecord) -> DesignMeta {
    let mut meta = model_meta(task, model, &rec.modes, rec.objective);
    meta.extra
        .insert("candidate".to_string(), json!(rec.candidate));
    meta.extra.insert("key".to_string(), json!(rec.key));
    meta
}

/// The export metadata of a design of `model` with `modes` ("up"/"down") and objective
/// Ω* (also for designs outside a search, e.g. `foldsynth model --save`).
pub fn model_meta(task: &Task, model: &Model, modes: &[String], objective: f64) -> DesignMeta {
    let multi = model.targets.len() > 1;
    DesignMeta {
        task: task.name.clone(),
        rule_sequence: model.plan.sequence.clone(),
        modes: modes
            .iter()
            .map(|m| {
                if m == "up" {
                    export::Mode::Up
                } else {
                    export::Mode::Down
                }
            })
            .collect(),
        // The vertex name (1-based), as in the rule sequence and the record.
        gripping_vertex: Some(model.plan.vertices[model.gripping].name),
        objective: Some(objective),
        targets: model
            .targets
            .iter()
            .map(|t| export::TargetPoint {
                p: t.point,
                t: Some(t.t),
            })
            .collect(),
        trajectory: if multi {
            model.targets.iter().map(|t| t.point).collect()
        } else {
            Vec::new()
        },
        obstacle: task
            .check
            .as_ref()
            .and_then(|c| c.cylinders.first().copied()),
        second_arm: task.check.as_ref().is_some_and(|c| c.second_arm),
        extra: BTreeMap::new(),
    }
}

/// Write `designs/<id>.json` for every feasible design, with export its files, and the
/// report (always: its 3D views need only the geometry).
// The run's parts, each borrowed once; a struct of them would only rename the call.
#[allow(clippy::too_many_arguments)]
fn write_designs(
    task: &Task,
    plan: &Plan,
    records: &Path,
    feasible: &[(u64, u64)],
    summary: &Summary,
    opts: &SearchOptions,
    out_dir: &OutputDir,
    progress: &Progress,
) -> Result<(), SearchError> {
    // The earlier run's designs were deleted when the directory was opened (only the
    // files its manifest lists).
    out_dir.create_dir("designs")?;
    // Designs are independent: built and written in parallel, a chunk at a time (memory
    // holds one chunk); each chunk's files are listed in the manifest in one step before
    // any is written. The cards stay in the order of `feasible`: most robust first, `rank`
    // 1.
    let build = |(rank, rec): (usize, &AlternativeRecord)| -> Result<DesignWork, SearchError> {
        let (model, free, full, modes) = design_of(task, &plan.graph(task, rec.graph), rec)?;
        let design = Evaluated::new(&model.plan, full.clone(), modes);
        let pattern = design.pattern(&sample_times(model.t_max, 33));
        let meta = design_meta(task, &model, rec);
        let all_vars: BTreeMap<String, f64> = model
            .plan
            .variables
            .iter()
            .zip(&full)
            .map(|(v, x)| (v.name.clone(), *x))
            .collect();
        let constraints: Vec<_> = {
            let (_, g) = crate::model::compiled::outputs_f64(&model, &free, &design.modes);
            g.iter()
                .enumerate()
                .map(|(k, v)| json!({"label": model.constraint_label(k), "value": v}))
                .collect()
        };
        let id = rec.id();
        let doc = json!({
            "id": id,
            "task": task.name,
            "sequence": rec.sequence,
            "level": rec.level,
            "candidate": rec.candidate,
            "gripping_vertex": rec.gripping_vertex,
            "modes": rec.modes,
            "objective": rec.objective,
            "threshold": model.threshold,
            "variables": rec.variables,
            "all_variables": all_vars,
            "constraint_slack": rec.min_slack,
            "constraints": constraints,
            "verification": rec.verification,
            "self_intersection_free": rec.self_intersection_free,
            "obstacle_free": rec.obstacle_free,
            "robustness": rec.robustness,
            "rank": rank,
            "pattern": pattern,
            "meta": meta,
            "svg": export::svg::svg_scale(&pattern, &Default::default()).ok(),
        });
        Ok(DesignWork {
            rec: rec.clone(),
            threshold: model.threshold,
            doc: serde_json::to_string_pretty(&doc).unwrap_or_default(),
            options: ExportOptions {
                name: id.clone(),
                ..Default::default()
            },
            id,
            pattern,
            meta,
        })
    };
    let write_one = |w: DesignWork| -> Result<export::report::ReportDesign, SearchError> {
        let id = &w.id;
        let path = out_dir.path(&format!("designs/{id}.json"));
        std::fs::write(&path, &w.doc).map_err(|source| SearchError::Io {
            path: path.display().to_string(),
            source,
        })?;
        if !opts.export {
            progress.inc(1);
            return Ok(report_design(
                &w.rec,
                w.threshold,
                w.pattern,
                w.meta,
                path,
                None,
                None,
            ));
        }
        let out = out_dir.path(&format!("designs/{id}"));
        let files = export::write_all(&out, &w.pattern, &w.meta, &w.options)
            .map_err(|e| SearchError::Export(e.to_string()))?;
        let check = export::verify::verify_file(&files.fold, &Default::default())
            .map_err(|e| SearchError::Export(e.to_string()))?;
        if !check.ok {
            eprintln!("BUG: the exported FOLD file of {id} fails verification");
        }
        progress.inc(1);
        Ok(report_design(
            &w.rec,
            w.threshold,
            w.pattern,
            w.meta,
            path,
            Some(files),
            Some(check),
        ))
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()
        .map_err(|e| SearchError::Export(e.to_string()))?;
    progress.phase(
        if opts.export {
            "write designs and their files"
        } else {
            "write design JSONs"
        },
        "designs",
        Some(feasible.len() as u64),
    );
    let mut cards: Vec<export::report::ReportDesign> = Vec::new();
    for (c, chunk) in feasible.chunks(256).enumerate() {
        let recs = read_at(records, chunk)?;
        let work = pool.install(|| {
            recs.par_iter()
                .enumerate()
                .map(|(k, rec)| build((c * 256 + k + 1, rec)))
                .collect::<Result<Vec<_>, _>>()
        })?;
        // Listed before they are written, so a kill leaves nothing unlisted.
        let mut files: Vec<PathBuf> = work
            .iter()
            .map(|w| out_dir.path(&format!("designs/{}.json", w.id)))
            .collect();
        if opts.export {
            let dirs: Vec<String> = work.iter().map(|w| format!("designs/{}", w.id)).collect();
            for (w, dir) in work.iter().zip(out_dir.create_dirs(&dirs)?) {
                files.extend(export::planned_files(&dir, &w.pattern, &w.options).all());
            }
        }
        out_dir.register(&files)?;
        let written = pool.install(|| {
            work.into_par_iter()
                .map(write_one)
                .collect::<Result<Vec<_>, _>>()
        })?;
        cards.extend(written);
    }
    progress.phase("write report", "", None);
    let input = report_input(
        task,
        plan.tree.clone(),
        summary,
        task_facts(task, opts, summary),
        cards,
    );
    out_dir.register([out_dir.path("report.html")])?;
    let path = export::report::write_report(out_dir.root(), &input)
        .map_err(|e| SearchError::Export(e.to_string()))?;
    let bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
    progress.finish_phase_with(&format!("{} ({bytes} bytes)", path.display()));
    Ok(())
}

/// One design, built and ready to write.
struct DesignWork {
    id: String,
    rec: AlternativeRecord,
    threshold: f64,
    /// `designs/<id>.json`.
    doc: String,
    pattern: Pattern,
    meta: DesignMeta,
    options: ExportOptions,
}
