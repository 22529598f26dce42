//! The units of a search evaluated on a rayon pool: the records an earlier run left kept
//! (`--resume`), each unit with work left compiled when a worker takes it up, its
//! alternatives evaluated in classes that share their starts, every record streamed to
//! `OUT/alternatives.jsonl` as it finishes, the model dropped after its last alternative.

use super::evaluate::{Prepared, evaluate, prepare};
use super::guide;
use super::options::{Evaluation, FailedModel, SearchError, SearchOptions};
use super::output::{self, OutputDir, RECORDS, ResumeReport};
use super::plan::{Done, Plan};
use super::progress::Progress;
use super::record::AlternativeRecord;
use super::strategy::Strategy;
use super::warm::Optima;
use crate::cpu_time::Stopwatch;
use crate::grammar::CreaseGraph;
use crate::model::compiled::CompiledModel;
use crate::model::robust::RobustSpec;
use crate::optimize::SharedStarts;
use crate::task::Task;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::Write;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

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
    // A guided run keeps any record of the plan: an earlier run of a larger budget, or an
    // exhaustive one, holds records outside this budget's models that are still its own.
    let all: Vec<usize>;
    let kept_units = if opts.strategy == Strategy::Guided {
        all = (0..plan.units.len()).collect();
        &all
    } else {
        units
    };
    let optima = (opts.strategy == Strategy::Guided && opts.warm_starts).then(|| Optima::new(plan));
    let (records_file, report, done, kept_cpu_s) =
        keep_records(plan, kept_units, out, resume, optima.as_ref())?;
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
    let work = Work {
        spent: Spent::new(opts.budget.cpu_s, kept_cpu_s),
        task,
        plan,
        opts,
        progress,
        writer: Mutex::new(records_file),
        write_error: Mutex::new(None),
        compile_s: Mutex::new(0.0f64),
        failed: Mutex::new(Vec::new()),
        robust_spec: (!opts.post_check_only).then(|| RobustSpec::from_task(task, opts.sweep)),
        optima,
    };
    // A CPU budget ends the run before its list: no total to show, or an ETA in days.
    let total = opts.budget.cpu_s.is_none().then_some(remaining as u64);
    progress.phase("compile + optimize + check", "alternatives", total);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()
        .map_err(|e| SearchError::Task {
            task: task.name.clone(),
            message: e.to_string(),
        })?;
    match opts.strategy {
        Strategy::Exhaustive => pool.install(|| {
            todo.par_iter().for_each(|&u| {
                let modes: Vec<u32> = undone(u).collect();
                work.unit(u, &modes);
            });
        }),
        Strategy::Guided => {
            let mut todo = todo.clone();
            todo.sort_by_key(|&u| guide::rank(plan, u));
            // One score at a time: a parent's optimum is on record before its r1
            // children (one score lower) start, on any number of workers.
            for tier in todo.chunk_by(|&a, &b| unit_score(plan, a) == unit_score(plan, b)) {
                in_order(&pool, tier, &work.spent, progress, |u| {
                    let modes: Vec<u32> = undone(u).collect();
                    work.unit(u, &modes);
                });
            }
        }
    }
    progress.finish_phase();
    if progress.cancelled() {
        return Err(SearchError::Interrupted {
            out: out.root().display().to_string(),
        });
    }
    if let Some(e) = work.write_error.into_inner().ok().flatten() {
        // A record that is not on disk would be lost to --resume: stop here.
        return Err(SearchError::Io {
            path: out.path(RECORDS).display().to_string(),
            source: e,
        });
    }
    let mut failed = work.failed.into_inner().unwrap_or_else(|e| e.into_inner());
    failed.sort_by(|a, b| (&a.sequence, a.candidate).cmp(&(&b.sequence, b.candidate)));
    Ok(Evaluation {
        compile_s: work
            .compile_s
            .into_inner()
            .unwrap_or_else(|e| e.into_inner())
            + 0.0,
        jobs: pool.current_num_threads(),
        resumed: report.as_ref().map_or(0, |r| r.reused),
        resume: report,
        failed,
    })
}

/// Open the records file for this run's records: with `resume`, the earlier run's records
/// of `units` kept (each once) and reported; the alternatives they hold marked done.
fn keep_records(
    plan: &Plan,
    units: &[usize],
    out: &OutputDir,
    resume: bool,
    optima: Option<&Optima>,
) -> Result<(File, Option<ResumeReport>, Done, f64), SearchError> {
    let mut kept_ms = 0.0;
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
            kept_ms += r.optimize_ms + r.check_ms;
            if let Some(o) = optima {
                o.keep(plan, place.unit, place.index, r);
            }
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
    Ok((records_file, report, done, kept_ms / 1e3))
}

/// The CPU budget of a guided search: seconds this process has spent since the
/// evaluation began, plus those of the records a resumed run keeps.
struct Spent {
    budget_s: Option<f64>,
    start_s: f64,
    kept_s: f64,
}

impl Spent {
    fn new(budget_s: Option<f64>, kept_s: f64) -> Spent {
        Spent {
            budget_s,
            start_s: crate::cpu_time::process_seconds(),
            kept_s,
        }
    }
    /// Whether the budget is spent (never without one).
    fn exhausted(&self) -> bool {
        self.budget_s
            .is_some_and(|b| crate::cpu_time::process_seconds() - self.start_s + self.kept_s >= b)
    }
}

/// Run `each` on `units` in their order on `pool`: each worker takes the next unit not
/// yet taken (a parallel iterator would split the list and start its second half at
/// once), until the units or the CPU budget run out.
fn in_order(
    pool: &rayon::ThreadPool,
    units: &[usize],
    spent: &Spent,
    progress: &Progress,
    each: impl Fn(usize) + Sync,
) {
    let next = AtomicUsize::new(0);
    pool.scope(|s| {
        for _ in 0..pool.current_num_threads() {
            s.spawn(|_| {
                while let Some(&u) = units.get(next.fetch_add(1, Ordering::Relaxed)) {
                    if spent.exhausted() || progress.cancelled() {
                        break;
                    }
                    each(u);
                }
            });
        }
    });
}

/// What the workers share: the search, the records file, and what they report.
struct Work<'a> {
    task: &'a Task,
    plan: &'a Plan,
    opts: &'a SearchOptions,
    progress: &'a Progress,
    /// The records file.
    writer: Mutex<File>,
    /// The first error writing it.
    write_error: Mutex<Option<std::io::Error>>,
    /// CPU seconds compiling, summed over the workers.
    compile_s: Mutex<f64>,
    failed: Mutex<Vec<FailedModel>>,
    /// The robustness block every model gets (absent with `--post-check-only`).
    robust_spec: Option<RobustSpec>,
    /// The optima warm starts come from (a guided search with warm starts).
    optima: Option<Optima>,
    /// The CPU budget (a guided search's `--budget-cpu`): checked before each alternative,
    /// not only before each model, so a run overshoots it by at most one alternative per
    /// worker rather than by the models in flight.
    spent: Spent,
}

impl Work<'_> {
    /// Compile unit `u`'s model, evaluate its alternatives `modes` (their classes in
    /// parallel) and drop the model.
    fn unit(&self, u: usize, modes: &[u32]) {
        if self.progress.cancelled() {
            return;
        }
        let (task, plan) = (self.task, self.plan);
        let unit = &plan.units[u];
        let graph = plan.graph(task, unit.graph);
        let t = Stopwatch::start();
        let prepared = prepare(&graph, task, unit.candidate, self.robust_spec.as_ref());
        *self.compile_s.lock().unwrap_or_else(|e| e.into_inner()) += t.cpu_ms() / 1e3;
        let prepared = match prepared {
            Ok(p) => p,
            Err(error) => {
                let sequence = plan.graphs[unit.graph].sequence.clone();
                eprintln!(
                    "error: {sequence} (candidate {}): {error}",
                    unit.candidate + 1
                );
                self.failed
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push(FailedModel {
                        sequence,
                        candidate: unit.candidate + 1,
                        error,
                    });
                self.progress.inc(modes.len() as u64);
                return;
            }
        };
        classes(&prepared.compiled, modes)
            .par_iter()
            .for_each(|(&canonical, members)| {
                self.class(u, &graph, &prepared, canonical, members);
            });
        if let Some(block) = &prepared.robust {
            *self.compile_s.lock().unwrap_or_else(|e| e.into_inner()) += block.compile_s();
        }
        // `prepared` (the native code) is dropped here, with its last alternative.
    }

    /// Evaluate the alternatives `members` of unit `u` in turn, with the starts of their
    /// class (canonical modes `canonical`), and write their records.
    fn class(
        &self,
        u: usize,
        graph: &CreaseGraph,
        prepared: &Prepared,
        canonical: u32,
        members: &[u32],
    ) {
        let key = self.plan.alternative(u, canonical).key();
        let shared = SharedStarts::new(alternative_seed(self.opts.seed, &key));
        for &m in members {
            if self.progress.cancelled() || self.spent.exhausted() {
                return;
            }
            let alt = self.plan.alternative(u, m);
            let warm = self
                .optima
                .as_ref()
                .map_or_else(Vec::new, |o| o.starts(self.plan, u, m, &prepared.model));
            match evaluate(self.task, prepared, &alt, graph, self.opts, &shared, warm) {
                Ok(rec) => {
                    self.write(&rec);
                    if let Some(o) = &self.optima {
                        let index = self.plan.units[u].first + u64::from(m);
                        o.keep(self.plan, u, index, &rec);
                    }
                }
                Err(error) => self.block_failed(u, error),
            }
            self.progress.inc(1);
        }
    }

    /// Unit `u`'s robustness block could not be compiled (`error`). Every alternative
    /// that needs the block gets the same error: the model is reported once.
    fn block_failed(&self, u: usize, error: String) {
        let unit = &self.plan.units[u];
        let mut failed = self.failed.lock().unwrap_or_else(|e| e.into_inner());
        let sequence = &self.plan.graphs[unit.graph].sequence;
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
    }

    /// Append one record to the records file.
    fn write(&self, rec: &AlternativeRecord) {
        let mut line = serde_json::to_string(rec).unwrap_or_default();
        line.push('\n');
        if let Ok(mut w) = self.writer.lock() {
            // One write per line, flushed: a kill loses at most this one.
            if let Err(e) = w.write_all(line.as_bytes()).and_then(|_| w.flush())
                && let Ok(mut first) = self.write_error.lock()
            {
                first.get_or_insert(e);
            }
        }
    }
}

/// The alternatives `modes` of a model grouped by class: those whose modes differ only
/// where no output depends on them are one optimization problem, so a class shares its
/// starts' phase A, with the seed of its member whose unused modes are all up (issue 14).
/// Keyed by that member's modes.
fn classes(compiled: &CompiledModel, modes: &[u32]) -> BTreeMap<u32, Vec<u32>> {
    let unused: u32 = compiled
        .modes_used
        .iter()
        .enumerate()
        .filter(|(_, used)| !**used)
        .fold(0, |acc, (i, _)| acc | 1 << i);
    let mut classes: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for &m in modes {
        classes.entry(m & !unused).or_default().push(m);
    }
    classes
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

/// The guided score of unit `u`'s graph.
fn unit_score(plan: &Plan, u: usize) -> i64 {
    guide::score(&plan.graphs[plan.units[u].graph])
}
