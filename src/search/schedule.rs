//! The units of a search evaluated on a rayon pool: the records an earlier run left kept
//! (`--resume`), each unit with work left compiled when a worker takes it up, its
//! alternatives evaluated in classes that share their starts, every record streamed to
//! `OUT/alternatives.jsonl` as it finishes, the model dropped after its last alternative.

use super::evaluate::{Prepared, evaluate, prepare};
use super::options::{Evaluation, FailedModel, SearchError, SearchOptions};
use super::output::{self, OutputDir, RECORDS, ResumeReport};
use super::plan::{Done, Plan};
use super::progress::Progress;
use super::record::AlternativeRecord;
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
    let (records_file, report, done) = keep_records(plan, units, out, resume)?;
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
        task,
        plan,
        opts,
        progress,
        writer: Mutex::new(records_file),
        write_error: Mutex::new(None),
        compile_s: Mutex::new(0.0f64),
        failed: Mutex::new(Vec::new()),
        robust_spec: (!opts.post_check_only).then(|| RobustSpec::from_task(task, opts.sweep)),
    };
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
    pool.install(|| {
        todo.par_iter().for_each(|&u| {
            let modes: Vec<u32> = undone(u).collect();
            work.unit(u, &modes);
        });
    });
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
) -> Result<(File, Option<ResumeReport>, Done), SearchError> {
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
    Ok((records_file, report, done))
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
            if self.progress.cancelled() {
                return;
            }
            let alt = self.plan.alternative(u, m);
            match evaluate(self.task, prepared, &alt, graph, self.opts, &shared) {
                Ok(rec) => self.write(&rec),
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
