//! Running a search: scheduling, streaming, resuming, summarizing, exporting.

use super::output::{self, OutputDir, RECORDS, RunSettings, SETTINGS};
use super::progress::Progress;
use super::record::{
    AlternativeRecord, CyclicCounts, RankEntry, Summary, Timings, level_distribution,
};
use super::report::{report_design, report_input, task_facts};
use crate::check::robustness::{self, RobustnessInput, UnitCreases};
use crate::check::verify::{Tolerances, verify};
use crate::check::{CheckError, Checker, Cylinder, MotionSettings, check_states, two_armed};
use crate::compile::Options as CompileOptions;
use crate::cpu_time::Stopwatch;
use crate::export::{self, DesignMeta, ExportOptions};
use crate::grammar::{CreaseGraph, Enumeration, Filters, Rules};
use crate::limits;
use crate::model::compiled::{CompiledModel, ModelProblem, objective_target};
use crate::model::numeric::{Evaluated, sample_times};
use crate::model::robust::{RobustModel, RobustProblem, RobustSpec};
use crate::model::{Model, ModelError};
use crate::optimize::{self, minimize, minimize_robust};
use crate::pattern::Pattern;
use crate::task::Task;
use rayon::prelude::*;
use serde_json::json;
use std::collections::{BTreeMap, HashMap};
use std::io::Write;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
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
    /// Its robustness block (absent with `--post-check-only`).
    pub robust: Option<RobustModel>,
}

/// The compiled model of one (graph, candidate) while its alternatives are evaluated.
struct Slot {
    /// The model, or why it failed; `None` before the first alternative and after the last.
    model: Option<Result<Arc<Prepared>, String>>,
    /// CPU seconds spent compiling (the compiling thread's clock).
    seconds: f64,
    /// Alternatives of this slot still to evaluate.
    remaining: usize,
    /// Whether a failure was reported (once per slot).
    reported: bool,
}

/// Build and compile the model of one graph and candidate, with its robustness block
/// when `robust` is given.
pub fn prepare(
    graph: &CreaseGraph,
    task: &Task,
    candidate: usize,
    robust: Option<&RobustSpec>,
) -> Result<Prepared, String> {
    let model = Model::new(graph, task, candidate).map_err(|e| e.to_string())?;
    let compiled =
        CompiledModel::new(&model, &CompileOptions::default()).map_err(|e| e.to_string())?;
    let robust = robust
        .map(|spec| RobustModel::new(&model, spec.clone()))
        .transpose()
        .map_err(|e| e.to_string())?;
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

/// Optimize, check and verify one alternative.
fn evaluate(
    task: &Task,
    p: &Prepared,
    alt: &Alternative,
    graph: &CreaseGraph,
    opts: &SearchOptions,
) -> AlternativeRecord {
    let model = &p.model;
    let modes = alt.mode_signs();
    let key = alt.key();
    let t0 = Stopwatch::start();
    let problem = ModelProblem::new(model, &p.compiled, &modes);
    let optimize_opts = optimize::Options {
        starts: opts.starts,
        seed: alternative_seed(opts.seed, &key),
        target: Some(objective_target(model)),
        ..Default::default()
    };
    let mut sol = match &p.robust {
        None => minimize(&problem, &optimize_opts),
        Some(block) => {
            let rp = RobustProblem::new(model, block, &modes);
            minimize_robust(&problem, Some(&rp), &optimize_opts)
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
    let optimize_ms = t0.cpu_ms();
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
        variables,
        starts_run: sol.starts_run,
        evaluations: sol.evaluations,
        optimize_ms,
        check_ms: 0.0,
        cycle: None,
    };
    if !meets {
        return rec;
    }
    let t1 = Stopwatch::start();
    let design = Evaluated::new(&model.plan, full, modes);
    // The judges run on the dense verification sweep, not only on the states the optimizer
    // saw, so an intersection between sampled states cannot hide.
    let arm = design.pattern(&sample_times(model.t_max, opts.sweep));
    let checked = checked_pattern(task, &arm)
        .map_err(CheckFailure::Other)
        .and_then(|pat| {
            let checker = Checker::from_pattern(&pat).map_err(|e| match e {
                // A facet that cannot be triangulated is inverted or overlaps itself in the
                // flat layout: the paper crosses itself before it folds.
                CheckError::Triangulate(t) => CheckFailure::Layout(t.to_string()),
                e => CheckFailure::Other(e.to_string()),
            })?;
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
    match checked {
        Ok((s, hit, pat)) => {
            rec.self_intersection_free = Some(s.self_intersection_free());
            rec.self_intersection = s.first_intersection().cloned();
            rec.obstacle_free = Some(hit.is_none());
            rec.obstacle_hit = hit;
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
    let report = verify(&design, &sample_times(model.t_max, opts.sweep), &tol);
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
    rec.check_ms = t1.cpu_ms();
    rec
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

/// Run the search of `task` and write everything under `opts.out`.
pub fn run(task: &Task, opts: &SearchOptions) -> Result<Summary, SearchError> {
    let start = Instant::now();
    let cpu0 = crate::cpu_time::process_seconds();
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

    let progress = Progress::new(opts.progress);
    progress.phase("enumerate graphs", "graphs", None);
    let t0 = Instant::now();
    let enumeration =
        Enumeration::run_within_with(task, n_max, Filters::all(), opts.rules, limits::GRAPHS_MAX)
            .map_err(|est| terr(&est.refusal(&task.name, n_max, Filters::all())))?;
    let graphs: Vec<&CreaseGraph> = enumeration.meaningful().map(|n| &n.graph).collect();
    let enumerate_s = t0.elapsed().as_secs_f64();
    progress.inc(graphs.len() as u64);
    progress.finish_phase_with(&format!(
        "{} generated, {} meaningful",
        enumeration.nodes.len(),
        graphs.len()
    ));
    if graphs.is_empty() {
        return Err(terr(&format!(
            "G0 generates no meaningful graph up to N_max = {n_max} (see `foldsynth enumerate`): there is nothing to optimize"
        )));
    }
    let count = enumeration.alternatives();
    if count > limits::ALTERNATIVES_MAX {
        return Err(terr(&format!(
            "N_max = {n_max} gives {count} design alternatives ({} graphs); one search evaluates at most {} (each takes tens of milliseconds and keeps a record in memory). Lower N_max.",
            graphs.len(),
            limits::ALTERNATIVES_MAX
        )));
    }

    let mut alternatives = Vec::new();
    for (g, graph) in graphs.iter().enumerate() {
        let n = graph.internal_count();
        for candidate in 0..3 {
            for modes in 0..(1u32 << n) {
                alternatives.push(Alternative {
                    graph: g,
                    candidate,
                    modes,
                    n,
                    sequence: graph.sequence(),
                });
            }
        }
    }

    // The settings that decide the results: the output directory holds only runs of
    // these settings (see `output`).
    let settings = RunSettings {
        task: task.name.clone(),
        task_digest: task.digest.clone(),
        n_max,
        starts: opts.starts,
        seed: opts.seed,
        sweep: opts.sweep,
        foldsynth: env!("CARGO_PKG_VERSION").into(),
        rules: (opts.rules != Rules::default()).then(|| opts.rules.names()),
        post_check_only: opts.post_check_only,
    };
    let opened = OutputDir::open(&opts.out, &settings, opts.resume, opts.force)?;
    for note in &opened.notes {
        eprintln!("note: {note}");
    }
    let out = opened.dir;
    out.write(
        SETTINGS,
        serde_json::to_string_pretty(&settings).unwrap_or_default() + "\n",
    )?;
    let wanted: HashMap<String, usize> = alternatives
        .iter()
        .enumerate()
        .map(|(i, a)| (a.key(), i))
        .collect();
    let (done, resume) = if opened.resume {
        let path = out.path(RECORDS);
        let (done, report) = output::read_records(&path, &|k| wanted.contains_key(k))?;
        eprintln!("{}", report.text(&path));
        (done, Some(report))
    } else {
        (Vec::new(), None)
    };
    let finished: std::collections::HashSet<String> = done.iter().map(|r| r.key.clone()).collect();
    let todo: Vec<&Alternative> = alternatives
        .iter()
        .filter(|a| !finished.contains(&a.key()))
        .collect();
    // Rewrite the file with the kept records, then append as alternatives finish.
    let (_, records_file) = output::write_records(&out, &done)?;
    let writer = Mutex::new(records_file);
    let write_error: Mutex<Option<std::io::Error>> = Mutex::new(None);

    // One model per (graph, candidate), compiled by the first worker that needs it and
    // dropped after its last alternative: memory stays bounded by the models in flight.
    let mut pending = vec![0usize; graphs.len() * 3];
    for a in &todo {
        pending[a.graph * 3 + a.candidate] += 1;
    }
    let cache: Vec<Mutex<Slot>> = pending
        .into_iter()
        .map(|remaining| {
            Mutex::new(Slot {
                model: None,
                seconds: 0.0,
                remaining,
                reported: false,
            })
        })
        .collect();
    let robust_spec = (!opts.post_check_only).then(|| RobustSpec::from_task(task, opts.sweep));
    progress.phase(
        "compile + optimize + check",
        "alternatives",
        Some(todo.len() as u64),
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()
        .map_err(|e| terr(&e.to_string()))?;
    let new: Vec<AlternativeRecord> = pool.install(|| {
        todo.par_iter()
            .filter_map(|alt| {
                let slot = &cache[alt.graph * 3 + alt.candidate];
                let (prepared, first_failure) = {
                    // Held while compiling: the other workers of this slot wait for it.
                    let mut s = slot.lock().unwrap_or_else(|e| e.into_inner());
                    if s.model.is_none() {
                        let t = Stopwatch::start();
                        s.model = Some(
                            prepare(graphs[alt.graph], task, alt.candidate, robust_spec.as_ref())
                                .map(Arc::new),
                        );
                        s.seconds += t.cpu_ms() / 1e3;
                    }
                    let m = s
                        .model
                        .clone()
                        .unwrap_or_else(|| Err("not compiled".into()));
                    let first = m.is_err() && !std::mem::replace(&mut s.reported, true);
                    (m, first)
                };
                let release = || {
                    let mut s = slot.lock().unwrap_or_else(|e| e.into_inner());
                    s.remaining = s.remaining.saturating_sub(1);
                    if s.remaining == 0 {
                        // Keep a failure (cheap, and said once); drop the native code.
                        if matches!(s.model, Some(Ok(_))) {
                            s.model = None;
                        }
                    }
                };
                let prepared = match prepared {
                    Ok(p) => p,
                    Err(e) => {
                        if first_failure {
                            eprintln!(
                                "error: {} (candidate {}): {e}",
                                alt.sequence,
                                alt.candidate + 1
                            );
                        }
                        release();
                        progress.inc(1);
                        return None;
                    }
                };
                let rec = evaluate(task, &prepared, alt, graphs[alt.graph], opts);
                release();
                let line = serde_json::to_string(&rec).unwrap_or_default();
                if let Ok(mut w) = writer.lock() {
                    // Each line is flushed as it is written: a kill loses at most this one.
                    if let Err(e) = writeln!(w, "{line}").and_then(|_| w.flush())
                        && let Ok(mut first) = write_error.lock()
                    {
                        first.get_or_insert(e);
                    }
                }
                progress.inc(1);
                Some(rec)
            })
            .collect()
    });
    progress.finish_phase();
    if let Some(e) = write_error.into_inner().ok().flatten() {
        // A record that is not on disk would be lost to --resume: stop here.
        return Err(SearchError::Io {
            path: out.path(RECORDS).display().to_string(),
            source: e,
        });
    }

    let mut records = done;
    records.extend(new);
    let order: HashMap<String, usize> = wanted;
    records.sort_by_key(|r| order.get(&r.key).copied().unwrap_or(usize::MAX));

    // `+ 0.0`: an empty f64 sum is −0.0, which would print as "-0.00 s".
    let compile_s: f64 = cache
        .iter()
        .map(|c| c.lock().map_or(0.0, |s| s.seconds))
        .sum::<f64>()
        + 0.0;
    let mut timings = Timings {
        enumerate_s,
        compile_s,
        optimize_s: records.iter().map(|r| r.optimize_ms).sum::<f64>() / 1e3 + 0.0,
        check_s: records.iter().map(|r| r.check_ms).sum::<f64>() / 1e3 + 0.0,
        export_s: 0.0,
        total_s: 0.0,
        cpu_s: 0.0,
    };
    let mut feasible: Vec<&AlternativeRecord> =
        records.iter().filter(|r| r.feasible_design()).collect();
    // Most robust first (ties: enumeration order).
    feasible.sort_by(|a, b| b.score().total_cmp(&a.score()));
    let mut summary = Summary {
        task: task.name.clone(),
        n_max,
        graphs: graphs.len(),
        alternatives: records.len(),
        meets_target: records.iter().filter(|r| r.meets_target).count(),
        no_self_intersection: records
            .iter()
            .filter(|r| r.meets_target && r.self_intersection_free == Some(true))
            .count(),
        no_intersection: records.iter().filter(|r| r.thesis_feasible()).count(),
        feasible: feasible.len(),
        rigid_at_tmax_only: records
            .iter()
            .filter(|r| {
                r.meets_target
                    && r.verification
                        .as_ref()
                        .is_some_and(|v| v.rigid_at_tmax && !v.rigid_over_motion)
            })
            .count(),
        verification_failures: records
            .iter()
            .filter(|r| r.verification_failed == Some(true))
            .count(),
        thesis: if n_max == 3 {
            Summary::thesis_counts(&task.name)
        } else {
            None
        },
        timings: timings.clone(),
        levels: level_distribution(&records),
        settings: json!({
            "starts": opts.starts, "seed": opts.seed, "jobs": pool.current_num_threads(),
            "sweep": opts.sweep, "resumed": finished.len(), "resume": resume,
            "post_check_only": opts.post_check_only,
            "optimize_states": robust_spec.as_ref().map(|s| s.states),
            "robustness": {
                "rigid_margin": task.robustness.rigid_margin,
                "clearance": task.robustness.clearance,
                "obstacle_clearance": task.robustness.obstacle_clearance,
            },
        }),
        meets_margins: feasible
            .iter()
            .filter(|r| r.robustness.as_ref().is_some_and(|x| x.meets_settings()))
            .count(),
        near_rigid_limit: feasible
            .iter()
            .filter(|r| {
                r.robustness
                    .as_ref()
                    .is_some_and(|x| x.rigid_margin.value < 1e-3)
            })
            .count(),
        ranking: feasible
            .iter()
            .map(|r| RankEntry {
                id: r.id(),
                score: r.robustness.as_ref().map(|x| x.score),
            })
            .collect(),
        designs: feasible.iter().map(|r| r.id()).collect(),
        cyclic: opts.rules.r2p.then(|| {
            CyclicCounts::count(
                graphs.iter().filter(|g| g.is_cyclic_pattern()).count(),
                &records,
            )
        }),
    };

    let t2 = Instant::now();
    summary.timings.total_s = start.elapsed().as_secs_f64();
    write_designs(
        task,
        &graphs,
        &enumeration,
        &feasible,
        &summary,
        opts,
        &progress,
        &out,
    )?;
    timings.export_s = t2.elapsed().as_secs_f64();
    timings.total_s = start.elapsed().as_secs_f64();
    timings.cpu_s = crate::cpu_time::process_seconds() - cpu0;
    summary.timings = timings;
    out.write(
        "summary.json",
        serde_json::to_string_pretty(&summary).unwrap_or_default(),
    )?;
    Ok(summary)
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
    graphs: &[&CreaseGraph],
    enumeration: &Enumeration,
    feasible: &[&AlternativeRecord],
    summary: &Summary,
    opts: &SearchOptions,
    progress: &Progress,
    out_dir: &OutputDir,
) -> Result<(), SearchError> {
    // The earlier run's designs were deleted when the directory was opened (only the
    // files its manifest lists).
    out_dir.create_dir("designs")?;
    // Designs are independent: write them in parallel, keep the cards in order.
    progress.phase(
        if opts.export {
            "write designs and their files"
        } else {
            "write design JSONs"
        },
        "designs",
        Some(feasible.len() as u64),
    );
    let write_one = |(rank, rec): (usize, &&AlternativeRecord)| -> Result<export::report::ReportDesign, SearchError> {
            let rank = rank + 1;
            let (model, free, full, modes) = design_of(task, graphs[rec.graph], rec)?;
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
            let path = out_dir.write(
                &format!("designs/{id}.json"),
                serde_json::to_string_pretty(&doc).unwrap_or_default(),
            )?;
            if !opts.export {
                progress.inc(1);
                return Ok(report_design(
                    rec,
                    model.threshold,
                    pattern,
                    meta,
                    path,
                    None,
                    None,
                ));
            }
            let out = out_dir.create_dir(&format!("designs/{id}"))?;
            let eo = ExportOptions {
                name: id.clone(),
                ..Default::default()
            };
            // Listed before they are written, so a kill leaves nothing unlisted.
            out_dir.register(export::planned_files(&out, &pattern, &eo).all())?;
            let files = export::write_all(&out, &pattern, &meta, &eo)
                .map_err(|e| SearchError::Export(e.to_string()))?;
            let check = export::verify::verify_file(&files.fold, &Default::default())
                .map_err(|e| SearchError::Export(e.to_string()))?;
            if !check.ok {
                eprintln!("BUG: the exported FOLD file of {id} fails verification");
            }
            progress.inc(1);
            Ok(report_design(
                rec,
                model.threshold,
                pattern,
                meta,
                path,
                Some(files),
                Some(check),
            ))
        };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()
        .map_err(|e| SearchError::Export(e.to_string()))?;
    let cards: Vec<export::report::ReportDesign> = pool.install(|| {
        feasible
            .par_iter()
            .enumerate()
            .map(write_one)
            .collect::<Result<Vec<_>, _>>()
    })?;
    progress.phase("write report", "", None);
    let input = report_input(
        task,
        enumeration,
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
