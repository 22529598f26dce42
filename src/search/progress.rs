//! Progress of a run on stderr, in every phase (enumerate, compile + optimize, write
//! designs, write the report).
//!
//! On a terminal an indicatif bar (a spinner where the total is unknown) is redrawn in
//! place, and every finished phase leaves one line above it. Off a terminal (a file, a CI
//! log, a pipe) nothing is redrawn: a plain status line is written every few seconds by a
//! ticker thread (done/total, rate, ETA), plus one line when a phase starts and one when it
//! ends, so a long run shows signs of life in any log.
//!
//! ```
//! use foldsynth::search::Progress;
//! use std::time::Duration;
//! let dir = tempfile::tempdir().unwrap();
//! let log = dir.path().join("progress.log");
//! let p = Progress::lines(std::fs::File::create(&log).unwrap(), Duration::from_secs(5));
//! p.phase("optimize", "alternatives", Some(4));
//! p.inc(4);
//! drop(p);
//! let text = std::fs::read_to_string(&log).unwrap();
//! assert!(text.contains("optimize: 4/4 alternatives in"));
//! ```

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::{IsTerminal, Write};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex, OnceLock};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How often the plain (off-terminal) status line is written.
pub const LINE_INTERVAL: Duration = Duration::from_secs(5);

/// One step of a run's progress, as a [`ProgressHook`] is told it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProgressEvent<'a> {
    /// The phase, e.g. `compile + optimize + check`.
    pub phase: &'a str,
    /// What it counts, e.g. `alternatives` (empty when it counts nothing).
    pub unit: &'a str,
    /// Items done so far in this phase.
    pub done: u64,
    /// Items in the phase, when known.
    pub total: Option<u64>,
    /// The phase has just ended (`done` is final).
    pub finished: bool,
}

/// A function told of every step of a run's progress (a phase started, items done, a phase
/// ended), called on whichever thread made the step, so it must be cheap and must not
/// block; and a flag that stops the run (see [`ProgressHook::cancel`]). Library users (the
/// Python package) watch a run through it without parsing stderr.
#[derive(Clone)]
pub struct ProgressHook {
    callback: Arc<dyn Fn(&ProgressEvent<'_>) + Send + Sync>,
    cancel: Arc<AtomicBool>,
}

impl ProgressHook {
    /// A hook calling `callback` at every step.
    pub fn new(callback: impl Fn(&ProgressEvent<'_>) + Send + Sync + 'static) -> ProgressHook {
        ProgressHook {
            callback: Arc::new(callback),
            cancel: Arc::new(AtomicBool::new(false)),
        }
    }

    /// Ask the run to stop: no alternative is started after this, and the search returns
    /// [`SearchError::Interrupted`](super::SearchError::Interrupted) once those in
    /// flight are written (so `--resume` continues from them).
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    /// Whether [`cancel`](Self::cancel) was called.
    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

impl std::fmt::Debug for ProgressHook {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ProgressHook")
            .field("cancelled", &self.cancelled())
            .finish_non_exhaustive()
    }
}

/// Where progress goes.
enum Output {
    /// An indicatif bar on a terminal.
    Bar(ProgressBar),
    /// Plain lines to a writer (stderr off a terminal).
    Lines(Mutex<Box<dyn Write + Send>>),
    /// Nothing.
    Hidden,
}

/// The phase being run.
struct Phase {
    name: String,
    unit: String,
    total: Option<u64>,
    started: Instant,
}

struct Shared {
    out: Output,
    phase: Mutex<Option<Phase>>,
    done: AtomicU64,
    hook: OnceLock<ProgressHook>,
}

impl Shared {
    /// Tell the hook (if any) where phase `p` stands.
    fn tell(&self, p: &Phase, done: u64, finished: bool) {
        if let Some(h) = self.hook.get() {
            (h.callback)(&ProgressEvent {
                phase: &p.name,
                unit: &p.unit,
                done,
                total: p.total,
                finished,
            });
        }
    }

    fn line(&self, text: &str) {
        match &self.out {
            Output::Bar(b) => b.println(text),
            Output::Lines(w) => {
                if let Ok(mut w) = w.lock() {
                    // Progress is best effort: a closed stderr must not stop the run.
                    let _ = writeln!(w, "progress: {text}").and_then(|_| w.flush());
                }
            }
            Output::Hidden => {}
        }
    }

    /// The status line of the running phase, if any.
    fn status(&self) -> Option<String> {
        let phase = self.phase.lock().ok()?;
        let p = phase.as_ref()?;
        Some(status_line(
            &p.name,
            &p.unit,
            self.done.load(Ordering::Relaxed),
            p.total,
            p.started.elapsed(),
        ))
    }
}

/// Progress of a run: phases with an optional total, counted from any thread.
///
/// Cheap to share by reference across a rayon pool (`inc` is one atomic add, plus the bar's
/// own rate-limited redraw on a terminal).
pub struct Progress {
    shared: Arc<Shared>,
    ticker: Option<(Sender<()>, JoinHandle<()>)>,
}

impl Progress {
    /// Progress on stderr: a bar on a terminal, plain lines every [`LINE_INTERVAL`]
    /// otherwise; nothing when `enabled` is false.
    pub fn new(enabled: bool) -> Progress {
        if !enabled {
            Progress::hidden()
        } else if std::io::stderr().is_terminal() {
            let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            Progress::with_output(Output::Bar(bar), None)
        } else {
            Progress::lines(std::io::stderr(), LINE_INTERVAL)
        }
    }

    /// Plain status lines to `out` every `interval` while a phase runs (and when a phase
    /// starts and ends).
    pub fn lines(out: impl Write + Send + 'static, interval: Duration) -> Progress {
        Progress::with_output(Output::Lines(Mutex::new(Box::new(out))), Some(interval))
    }

    /// No output at all.
    pub fn hidden() -> Progress {
        Progress::with_output(Output::Hidden, None)
    }

    fn with_output(out: Output, interval: Option<Duration>) -> Progress {
        let shared = Arc::new(Shared {
            out,
            phase: Mutex::new(None),
            done: AtomicU64::new(0),
            hook: OnceLock::new(),
        });
        let ticker = interval.map(|every| {
            let (stop, rx) = mpsc::channel::<()>();
            let s = Arc::clone(&shared);
            let handle = std::thread::spawn(move || {
                while let Err(RecvTimeoutError::Timeout) = rx.recv_timeout(every) {
                    if let Some(text) = s.status() {
                        s.line(&text);
                    }
                }
            });
            (stop, handle)
        });
        Progress { shared, ticker }
    }

    /// The same progress, also told to `hook` (when given) at every step.
    pub fn with_hook(self, hook: Option<ProgressHook>) -> Progress {
        if let Some(h) = hook {
            // A new Progress has no hook yet: `set` cannot fail here.
            let _ = self.shared.hook.set(h);
        }
        self
    }

    /// Whether the hook asked the run to stop ([`ProgressHook::cancel`]).
    pub fn cancelled(&self) -> bool {
        self.shared.hook.get().is_some_and(ProgressHook::cancelled)
    }

    /// Start a phase (ending the one before): `total` items of `unit`, or unknown.
    pub fn phase(&self, name: &str, unit: &str, total: Option<u64>) {
        self.finish_phase();
        self.shared.done.store(0, Ordering::Relaxed);
        if let Ok(mut p) = self.shared.phase.lock() {
            let phase = Phase {
                name: name.to_string(),
                unit: unit.to_string(),
                total,
                started: Instant::now(),
            };
            self.shared.tell(&phase, 0, false);
            *p = Some(phase);
        }
        match &self.shared.out {
            Output::Bar(b) => {
                b.set_message(if unit.is_empty() {
                    name.to_string()
                } else {
                    format!("{name} ({unit})")
                });
                match total {
                    Some(n) => {
                        b.disable_steady_tick();
                        b.set_style(
                            ProgressStyle::with_template(
                                "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} {msg}, ETA {eta}",
                            )
                            .expect("valid template"),
                        );
                        b.set_length(n);
                    }
                    None => {
                        b.set_style(
                            ProgressStyle::with_template("{spinner} [{elapsed_precise}] {msg}")
                                .expect("valid template"),
                        );
                        b.enable_steady_tick(Duration::from_millis(120));
                    }
                }
                // Position, elapsed time and ETA start afresh with the phase.
                b.reset();
            }
            Output::Lines(_) => self.shared.line(&match total {
                Some(n) => format!("{name}: {n} {unit} to do"),
                None => format!("{name}: started"),
            }),
            Output::Hidden => {}
        }
    }

    /// Count `n` more items of the running phase done.
    pub fn inc(&self, n: u64) {
        let done = self.shared.done.fetch_add(n, Ordering::Relaxed) + n;
        if let Output::Bar(b) = &self.shared.out {
            b.inc(n);
        }
        if self.shared.hook.get().is_some()
            && let Ok(p) = self.shared.phase.lock()
            && let Some(p) = p.as_ref()
        {
            self.shared.tell(p, done, false);
        }
    }

    /// Print a line without disturbing the bar.
    pub fn note(&self, text: &str) {
        self.shared.line(text);
    }

    /// End the running phase (if any) with its summary line.
    pub fn finish_phase(&self) {
        self.finish_phase_with("");
    }

    /// End the running phase (if any) with its summary line and `detail` appended.
    pub fn finish_phase_with(&self, detail: &str) {
        let Some(p) = self.shared.phase.lock().ok().and_then(|mut p| p.take()) else {
            return;
        };
        let done = self.shared.done.load(Ordering::Relaxed);
        self.shared.tell(&p, done, true);
        let mut text = done_line(&p.name, &p.unit, done, p.total, p.started.elapsed());
        if !detail.is_empty() {
            text += &format!("; {detail}");
        }
        if let Output::Bar(b) = &self.shared.out {
            b.disable_steady_tick();
        }
        self.shared.line(&text);
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish_phase();
        if let Some((stop, handle)) = self.ticker.take() {
            drop(stop);
            let _ = handle.join();
        }
        if let Output::Bar(b) = &self.shared.out {
            b.finish_and_clear();
        }
    }
}

/// Seconds as people read them: `42 s`, `3 min 05 s`, `2 h 07 min`.
pub fn human_duration(d: Duration) -> String {
    let s = d.as_secs_f64();
    if s < 10.0 {
        format!("{s:.1} s")
    } else if s < 60.0 {
        format!("{s:.0} s")
    } else if s < 3600.0 {
        let m = (s / 60.0).floor();
        format!("{m:.0} min {:02.0} s", (s - 60.0 * m).floor())
    } else {
        let h = (s / 3600.0).floor();
        format!("{h:.0} h {:02.0} min", ((s - 3600.0 * h) / 60.0).floor())
    }
}

/// Items per second so far (`None` before the first item or the first instant).
fn rate(done: u64, elapsed: Duration) -> Option<f64> {
    let s = elapsed.as_secs_f64();
    (done > 0 && s > 0.0).then(|| done as f64 / s)
}

/// The status line of a running phase: done/total, percentage, rate and the ETA at that
/// rate (remaining ÷ rate); only the elapsed time when the total is unknown.
pub fn status_line(
    name: &str,
    unit: &str,
    done: u64,
    total: Option<u64>,
    elapsed: Duration,
) -> String {
    let Some(total) = total else {
        if done > 0 {
            // An open-ended count (a guided search's CPU budget): what is done, and how fast.
            return format!(
                "{name}: {done} {unit}, {:.1}/s, elapsed {}",
                rate(done, elapsed).unwrap_or(0.0),
                human_duration(elapsed)
            );
        }
        return format!("{name}: running for {}", human_duration(elapsed));
    };
    let pct = if total == 0 {
        100.0
    } else {
        100.0 * done as f64 / total as f64
    };
    let (speed, eta) = match rate(done, elapsed) {
        Some(r) => (
            format!("{r:.1}/s"),
            human_duration(Duration::from_secs_f64(
                total.saturating_sub(done) as f64 / r,
            )),
        ),
        None => ("–/s".to_string(), "unknown".to_string()),
    };
    format!(
        "{name}: {done}/{total} {unit} ({pct:.0}%), {speed}, ETA {eta}, elapsed {}",
        human_duration(elapsed)
    )
}

/// The line that ends a phase.
fn done_line(name: &str, unit: &str, done: u64, total: Option<u64>, elapsed: Duration) -> String {
    let count = match total {
        Some(t) => format!("{done}/{t} {unit}"),
        None if done > 0 => format!("{done} {unit}"),
        None => "done".to_string(),
    };
    let speed = match (total, rate(done, elapsed)) {
        (Some(_), Some(r)) => format!(" ({r:.1}/s)"),
        _ => String::new(),
    };
    format!("{name}: {count} in {}{speed}", human_duration(elapsed))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eta_is_remaining_over_rate() {
        // 25 of 100 in 10 s: 2.5 per second, 75 left → 30 s.
        let l = status_line(
            "optimize",
            "alternatives",
            25,
            Some(100),
            Duration::from_secs(10),
        );
        assert_eq!(
            l,
            "optimize: 25/100 alternatives (25%), 2.5/s, ETA 30 s, elapsed 10 s"
        );
        let l = status_line("x", "items", 0, Some(7), Duration::from_secs(3));
        assert!(l.contains("0/7 items (0%), –/s, ETA unknown"), "{l}");
        let l = status_line("enumerate", "graphs", 0, None, Duration::from_secs(75));
        assert_eq!(l, "enumerate: running for 1 min 15 s");
        let l = status_line(
            "optimize",
            "alternatives",
            50,
            None,
            Duration::from_secs(20),
        );
        assert_eq!(l, "optimize: 50 alternatives, 2.5/s, elapsed 20 s");
    }

    #[test]
    fn durations_read_naturally() {
        assert_eq!(human_duration(Duration::from_millis(2500)), "2.5 s");
        assert_eq!(human_duration(Duration::from_secs(42)), "42 s");
        assert_eq!(human_duration(Duration::from_secs(185)), "3 min 05 s");
        assert_eq!(human_duration(Duration::from_secs(7620)), "2 h 07 min");
    }

    #[derive(Clone, Default)]
    struct Log(Arc<Mutex<Vec<u8>>>);
    impl Write for Log {
        fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(b);
            Ok(b.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn plain_lines_tick_while_a_phase_runs_and_close_every_phase() {
        let log = Log::default();
        let p = Progress::lines(log.clone(), Duration::from_millis(10));
        p.phase("compile + optimize", "alternatives", Some(10));
        p.inc(3);
        std::thread::sleep(Duration::from_millis(80));
        p.phase("write designs", "designs", Some(2));
        p.inc(2);
        drop(p);
        let text = String::from_utf8(log.0.lock().unwrap().clone()).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert!(lines.iter().all(|l| l.starts_with("progress: ")), "{text}");
        assert_eq!(
            lines[0],
            "progress: compile + optimize: 10 alternatives to do"
        );
        // At least one tick while 3 of 10 were done, with a rate and an ETA.
        assert!(
            lines.iter().any(
                |l| l.contains("compile + optimize: 3/10 alternatives (30%)") && l.contains("ETA")
            ),
            "{text}"
        );
        assert!(
            lines
                .iter()
                .any(|l| l.starts_with("progress: compile + optimize: 3/10 alternatives in ")),
            "{text}"
        );
        assert!(
            lines
                .last()
                .unwrap()
                .starts_with("progress: write designs: 2/2 designs in "),
            "{text}"
        );
    }

    #[test]
    fn a_hook_hears_every_step_and_can_stop_the_run() {
        type Heard = (String, u64, Option<u64>, bool);
        let heard: Arc<Mutex<Vec<Heard>>> = Arc::default();
        let h = Arc::clone(&heard);
        let hook = ProgressHook::new(move |e| {
            h.lock()
                .unwrap()
                .push((e.phase.to_string(), e.done, e.total, e.finished));
        });
        let p = Progress::hidden().with_hook(Some(hook.clone()));
        p.phase("optimize", "alternatives", Some(3));
        p.inc(1);
        p.inc(2);
        assert!(!p.cancelled());
        hook.cancel();
        assert!(p.cancelled());
        p.phase("write", "", None);
        drop(p);
        let s = |t: &str| t.to_string();
        assert_eq!(
            *heard.lock().unwrap(),
            vec![
                (s("optimize"), 0, Some(3), false),
                (s("optimize"), 1, Some(3), false),
                (s("optimize"), 3, Some(3), false),
                (s("optimize"), 3, Some(3), true),
                (s("write"), 0, None, false),
                (s("write"), 0, None, true),
            ]
        );
        // Without a hook nothing can cancel.
        assert!(!Progress::hidden().cancelled());
    }
}
