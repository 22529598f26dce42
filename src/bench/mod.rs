//! Benchmarks measured in one run and reported as ratios: the measuring side of
//! `foldsynth bench …` (`cli/bench*.rs` parse the arguments and print).
//!
//! One file per benchmark: [`vertex`] (one vertex, with the CasADi peer in [`casadi`]),
//! [`model`] (one design model), [`numeric`] (one motion: compiled PTU against the
//! bar-and-hinge simulation), [`export`] (one design's files), [`optimize`] (our optimizer
//! against IPOPT on a task's alternatives); [`symbolica`] is the
//! Symbolica peer of `vertex` and `model`. This file holds what they share and imports
//! none of them.

use crate::cpu_time::Stopwatch;
use anyhow::{Result, bail};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub mod casadi;
pub mod export;
pub mod model;
pub mod numeric;
pub mod optimize;
pub mod symbolica;
pub mod vertex;

/// A peer implementation to measure in the same run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Peer {
    /// CasADi SX, reverse-mode gradient, generated C compiled with `gcc -O3`.
    Casadi,
    /// Symbolica: its canonical form, its derivatives, its optimized evaluator, SymJIT
    /// (needs the `symbolica` cargo feature).
    Symbolica,
}

/// A peer's Python script: `given`, or the crate's `benches/peers/<name>`; an error naming
/// the path when it does not exist.
pub fn peer_script(given: Option<&Path>, name: &str) -> Result<PathBuf> {
    let script = given.map(Path::to_path_buf).unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("benches/peers")
            .join(name)
    });
    if !script.exists() {
        bail!(
            "peer script {} not found (use --peer-script)",
            script.display()
        );
    }
    Ok(script)
}

/// A fresh path in the system's temporary folder for one peer run's files (not created):
/// `foldsynth-<what>-<process id>-<nanoseconds>`.
pub fn scratch_dir(what: &str) -> PathBuf {
    let stamp = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    std::env::temp_dir().join(format!("foldsynth-{what}-{}-{stamp}", std::process::id()))
}

/// Median nanoseconds per call of `f`, over batches filling about `budget`: CPU time of
/// this thread per batch (where the platform has a thread clock), so time the process
/// spends waiting for a core on a busy machine does not count.
pub fn time_ns(budget: Duration, mut f: impl FnMut()) -> f64 {
    let batch = |f: &mut dyn FnMut(), n: usize| {
        let t = Stopwatch::start();
        for _ in 0..n {
            f();
        }
        t.cpu_ms() * 1e6
    };
    // Calibrate: how many calls take ~1/20 of the budget.
    let target_ns = budget.as_secs_f64() * 1e9 / 20.0;
    let mut n = 1usize;
    loop {
        let e = batch(&mut f, n);
        if e >= target_ns / 4.0 || n >= 1 << 30 {
            let per = e / n as f64;
            n = ((target_ns / per.max(1e-1)) as usize).max(1);
            break;
        }
        n *= 4;
    }
    let mut samples = Vec::new();
    let start = Instant::now();
    while samples.len() < 5 || (start.elapsed() < budget && samples.len() < 41) {
        samples.push(batch(&mut f, n) / n as f64);
    }
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

/// Median of `reps` runs of `f` in milliseconds (wall clock), with the last run's result.
pub fn time_ms<T>(reps: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..reps {
        let t = Instant::now();
        let r = f();
        times.push(t.elapsed().as_secs_f64() * 1e3);
        last = Some(r);
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], last.expect("reps >= 1"))
}

/// The fastest of several rounds' times (interference only ever adds time); infinity for
/// none.
pub fn fastest(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::INFINITY, f64::min)
}

/// Relative deviation of `a` from `b`, absolute below 1.
pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1.0)
}
