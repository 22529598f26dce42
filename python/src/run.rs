//! The search from Python: `foldsynth.synthesize` (native half) runs `search::run` on its
//! own thread while the calling thread, without the GIL, waits for it and wakes every
//! 100 ms to hand the progress so far to the Python callback and to notice Ctrl-C; and
//! the FOLD document of a design file.

use super::{FoldsynthError, Task, fs_err};
use foldsynth::distribute;
use foldsynth::export::{DesignFile, FoldSpec, fold};
use foldsynth::grammar::Rules;
use foldsynth::search::output::ShardSpec;
use foldsynth::search::{self, ProgressHook, SearchOptions, ShardReport, Summary};
use foldsynth::task::Task as FsTask;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// How often the waiting thread hands progress to Python and checks for Ctrl-C.
const POLL: Duration = Duration::from_millis(100);

/// One step of progress, owned, queued for the calling thread.
#[derive(Clone, Debug)]
struct Step {
    phase: String,
    unit: String,
    done: u64,
    total: Option<u64>,
    finished: bool,
}

/// The steps not yet handed to Python. Within a phase only the latest count is kept: the
/// workers may finish thousands of alternatives between two polls.
type Steps = Arc<Mutex<Vec<Step>>>;

fn hook(steps: &Steps) -> ProgressHook {
    let steps = Arc::clone(steps);
    ProgressHook::new(move |e| {
        let mut q = steps.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(last) = q.last_mut()
            && last.phase == e.phase
            && !last.finished
        {
            last.done = e.done;
            last.total = e.total;
            last.finished = e.finished;
            return;
        }
        q.push(Step {
            phase: e.phase.to_string(),
            unit: e.unit.to_string(),
            done: e.done,
            total: e.total,
            finished: e.finished,
        });
    })
}

/// What the search thread ran: the whole search, or one shard of it (`shard="K/N"`).
enum Outcome {
    Whole(Box<Summary>),
    Shard(ShardReport),
}

/// Run the search of `task` with `opts` off the GIL (only `shard` of it, if given, with
/// the task file's text for the merge); progress goes to `callback`
/// (`callback(phase, unit, done, total, finished)`) on the calling thread. An exception
/// from the callback or a signal (Ctrl-C: KeyboardInterrupt) stops the search — no new
/// alternative is started, those in flight are written — and is raised once it has
/// stopped, so the directory holds a run that `resume=True` continues. Returns the
/// summary as a Python object (summary.json's content; a shard's: shard.json's).
pub fn search<'py>(
    py: Python<'py>,
    task: &Arc<FsTask>,
    mut opts: SearchOptions,
    shard: Option<(ShardSpec, String)>,
    callback: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    if opts.starts == 0 {
        return Err(PyValueError::new_err("starts must be at least 1"));
    }
    if opts.n_max == Some(0) {
        return Err(PyValueError::new_err("n_max must be at least 1"));
    }
    let steps: Steps = Arc::default();
    let hook = hook(&steps);
    opts.on_progress = Some(hook.clone());
    let (tx, rx) = mpsc::channel::<()>();
    let task = Arc::clone(task);
    let worker = std::thread::Builder::new()
        .name("foldsynth-search".into())
        .spawn(move || {
            let result = match &shard {
                None => search::run(&task, &opts)
                    .map(|s| Outcome::Whole(Box::new(s)))
                    .map_err(anyhow::Error::from),
                Some((spec, text)) => distribute::shard::run(&task, text, &opts, *spec)
                    .map(Outcome::Shard)
                    .map_err(anyhow::Error::from),
            };
            // The receiver may be gone only if the caller panicked: nothing to tell.
            let _ = tx.send(());
            result
        })
        .map_err(|e| FoldsynthError::new_err(format!("cannot start the search thread: {e}")))?;
    // A Receiver is Send but not Sync; the closure below borrows it across threads.
    let rx = Mutex::new(rx);
    loop {
        let finished = py.detach(|| {
            let rx = rx.lock().unwrap_or_else(|p| p.into_inner());
            !matches!(rx.recv_timeout(POLL), Err(RecvTimeoutError::Timeout))
        });
        let pending = std::mem::take(&mut *steps.lock().unwrap_or_else(|p| p.into_inner()));
        let mut stop = None;
        if let Some(cb) = &callback {
            for s in pending {
                if let Err(e) = cb.call1(py, (s.phase, s.unit, s.done, s.total, s.finished)) {
                    stop = Some(e);
                    break;
                }
            }
        }
        if stop.is_none() {
            stop = py.check_signals().err();
        }
        if let Some(e) = stop {
            hook.cancel();
            // The search stops at its next alternative; its error (Interrupted) is
            // replaced by the exception that stopped it.
            let _ = py.detach(|| worker.join());
            return Err(e);
        }
        if finished {
            break;
        }
    }
    let outcome = py
        .detach(|| worker.join())
        .map_err(|_| FoldsynthError::new_err("the search thread panicked (a bug in foldsynth)"))?
        .map_err(fs_err)?;
    let text = match outcome {
        Outcome::Whole(summary) => {
            if summary.verification_failures > 0 {
                return Err(FoldsynthError::new_err(format!(
                    "{} designs failed verification (a bug; see the messages on stderr)",
                    summary.verification_failures
                )));
            }
            serde_json::to_string(&summary)
        }
        Outcome::Shard(report) => serde_json::to_string(&report),
    }
    .map_err(fs_err)?;
    py.import("json")?.call_method1("loads", (text,))
}

/// Run the whole method of `task` into `out` (as `foldsynth synthesize`), calling
/// `callback(phase, unit, done, total, finished)` with its progress; returns the summary.
/// `foldsynth.synthesize` wraps it and returns a `Run`.
#[pyfunction]
#[pyo3(signature = (task, out, *, jobs = 0, starts = 16, seed = 0, resume = false, force = false, n_max = None, sweep = 181, export = true, export_top = None, export_all = false, report_motions = None, report_motions_all = false, report_designs = None, report_designs_all = false, shard = None, rules = "r1,r2", post_check_only = false, strategy = "exhaustive", budget_alternatives = None, budget_cpu = None, warm_starts = true, callback = None))]
#[allow(clippy::too_many_arguments)]
pub fn synthesize<'py>(
    py: Python<'py>,
    task: &Task,
    out: PathBuf,
    jobs: usize,
    starts: usize,
    seed: u64,
    resume: bool,
    force: bool,
    n_max: Option<usize>,
    sweep: usize,
    export: bool,
    export_top: Option<usize>,
    export_all: bool,
    report_motions: Option<usize>,
    report_motions_all: bool,
    report_designs: Option<usize>,
    report_designs_all: bool,
    shard: Option<&str>,
    rules: &str,
    post_check_only: bool,
    strategy: &str,
    budget_alternatives: Option<u64>,
    budget_cpu: Option<f64>,
    warm_starts: bool,
    callback: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let rules =
        Rules::parse(rules).map_err(|e| PyValueError::new_err(format!("rules {rules:?}: {e}")))?;
    let strategy: search::Strategy = strategy
        .parse()
        .map_err(|e| PyValueError::new_err(format!("strategy: {e}")))?;
    let shard = match shard {
        None => None,
        Some(text) => {
            let spec: ShardSpec = text
                .parse()
                .map_err(|e| PyValueError::new_err(format!("shard: {e}")))?;
            // The merge rebuilds the designs from the task's text, kept with the shard.
            let Some(source) = task.task.source.as_deref() else {
                return Err(PyValueError::new_err(
                    "shard: a shard keeps its task file for the merge; give the task as a file (or a Task loaded from one)",
                ));
            };
            let text = std::fs::read_to_string(source)
                .map_err(|e| FoldsynthError::new_err(format!("{}: {e}", source.display())))?;
            Some((spec, text))
        }
    };
    let opts = SearchOptions {
        out,
        jobs,
        starts,
        seed,
        resume,
        force,
        n_max,
        sweep,
        export,
        // `export=N`: the N most robust; `"all"`: every design; `True`: the CLI's default.
        export_top: if export_all {
            None
        } else {
            Some(export_top.unwrap_or(search::EXPORT_TOP))
        },
        progress: false,
        rules,
        post_check_only,
        // As `export`: a number, every design, or the CLI's default.
        report_motions: if report_motions_all {
            None
        } else {
            Some(report_motions.unwrap_or(search::REPORT_MOTIONS))
        },
        report_designs: if report_designs_all {
            None
        } else {
            Some(report_designs.unwrap_or(search::REPORT_DESIGNS))
        },
        strategy,
        budget: search::Budget {
            alternatives: budget_alternatives,
            cpu_s: budget_cpu,
        },
        warm_starts,
        ..SearchOptions::default()
    };
    search(py, &task.task, opts, shard, callback)
}

/// The FOLD 1.2 document (JSON text) of the design file `path` (`designs/<id>.json`), as
/// `foldsynth export --format fold` writes it.
#[pyfunction]
pub fn design_fold(py: Python<'_>, path: PathBuf) -> PyResult<String> {
    py.detach(|| -> anyhow::Result<String> {
        let d = DesignFile::read(&path)?;
        Ok(fold::to_fold_string(&d.pattern, &d.meta, FoldSpec::V1_2)?)
    })
    .map_err(fs_err)
}

/// A design file's frames as `(t, coords, fold_angles)`: the fold angles the file leaves
/// out read from the positions, as every reader of design files does.
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn design_frames(
    py: Python<'_>,
    path: PathBuf,
) -> PyResult<(Vec<f64>, Vec<Vec<[f64; 3]>>, Vec<Vec<f64>>)> {
    py.detach(|| -> anyhow::Result<_> {
        let d = DesignFile::read(&path)?;
        let frames = d.pattern.frames;
        Ok((
            frames.iter().map(|f| f.t).collect(),
            frames.iter().map(|f| f.coords.clone()).collect(),
            frames.into_iter().map(|f| f.fold_angles).collect(),
        ))
    })
    .map_err(fs_err)
}
