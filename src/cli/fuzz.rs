//! `foldsynth fuzz [--inputs N] [--seed S] [--targets LIST] [--jobs J]`: fuzz every parser
//! (see [`crate::fuzz`]).
//!
//! The inputs run in batches in child processes (`foldsynth fuzz --worker …`), so an
//! abort (a stack overflow, a failed allocation) or a hang ends one child, not the run:
//! the batch is then run again with a trace of input indices to find the input, which is
//! saved with the panics to `--findings DIR` (default `out/fuzz`, written only when there
//! is a finding), and the run continues after it. Exit status 1 when any input panicked,
//! aborted or hung.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use serde_json::json;

use crate::fuzz::{self, BatchReport, Counts, Finding, Target};

/// Arguments of `foldsynth fuzz`.
#[derive(Debug, clap::Args)]
pub struct FuzzArgs {
    /// Inputs in all, spread over the targets in turn (1 to 100000000).
    #[arg(long, default_value_t = 10_000, value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
    pub inputs: u64,
    /// Seed: the same seed gives the same inputs.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Targets, comma-separated: task, vertex, expr, fold, design, pattern, records, mesh
    /// (default: all).
    #[arg(long, value_delimiter = ',')]
    pub targets: Vec<String>,
    /// Child processes at once, 0 (one per core) to 256.
    #[arg(long, default_value_t = 0, value_parser = crate::limits::count::<0, { crate::limits::JOBS_MAX as u64 }>)]
    pub jobs: usize,
    /// Inputs per child process.
    #[arg(long, default_value_t = 20_000, value_parser = clap::value_parser!(u64).range(1..=10_000_000))]
    pub batch: u64,
    /// Seconds one batch may run before it counts as a hang.
    #[arg(long, default_value_t = 900, value_parser = clap::value_parser!(u64).range(1..=86_400))]
    pub timeout: u64,
    /// Where to save the inputs of findings (default: out/fuzz; created only for a finding).
    #[arg(long)]
    pub findings: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Internal: run inputs START.. of one batch in this process, print its report as JSON.
    #[arg(long, hide = true)]
    pub worker: bool,
    /// Internal: the first input of the batch.
    #[arg(long, hide = true, default_value_t = 0)]
    pub start: u64,
    /// Internal: write each input's index to stderr before running it.
    #[arg(long, hide = true)]
    pub trace: bool,
    /// Write input INDEX of the run with --seed (and --targets) to stdout and stop: to
    /// reproduce a finding.
    #[arg(long, value_name = "INDEX")]
    pub dump: Option<u64>,
}

fn targets(names: &[String]) -> Result<Vec<Target>> {
    if names.is_empty() {
        return Ok(Target::ALL.to_vec());
    }
    names
        .iter()
        .map(|n| {
            Target::from_name(n.trim()).with_context(|| {
                format!(
                    "--targets: '{}' is not a target; allowed: {}",
                    crate::text::excerpt(n, 40),
                    Target::ALL.map(Target::name).join(", ")
                )
            })
        })
        .collect()
}

/// Run `foldsynth fuzz`.
pub fn run(args: FuzzArgs) -> Result<()> {
    let targets = targets(&args.targets)?;
    if let Some(i) = args.dump {
        use std::io::Write as _;
        let bytes = fuzz::input(fuzz::target_of(&targets, i), args.seed, i);
        std::io::stdout().write_all(&bytes)?;
        return Ok(());
    }
    if args.worker {
        fuzz::quiet_panics();
        let mut stderr = std::io::stderr();
        let trace: Option<&mut dyn std::io::Write> =
            if args.trace { Some(&mut stderr) } else { None };
        let report = fuzz::run_batch(&targets, args.seed, args.start, args.batch, trace);
        println!("{}", serde_json::to_string(&report)?);
        return Ok(());
    }
    parent(&args, &targets)
}

/// One batch: inputs `start..end`.
#[derive(Clone, Copy, Debug)]
struct Batch {
    start: u64,
    end: u64,
}

struct Running {
    batch: Batch,
    child: Child,
    out: PathBuf,
    started: Instant,
}

fn spawn(
    exe: &Path,
    args: &FuzzArgs,
    targets: &[Target],
    b: Batch,
    scratch: &Path,
    trace: bool,
) -> Result<(Child, PathBuf, PathBuf)> {
    let out = scratch.join(format!("{}.out", b.start));
    let err = scratch.join(format!("{}.err", b.start));
    let names: Vec<&str> = targets.iter().map(|t| t.name()).collect();
    let mut cmd = Command::new(exe);
    cmd.arg("fuzz")
        .arg("--worker")
        .arg("--seed")
        .arg(args.seed.to_string())
        .arg("--start")
        .arg(b.start.to_string())
        .arg("--batch")
        .arg((b.end - b.start).to_string())
        .arg("--targets")
        .arg(names.join(","))
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out)?)
        .stderr(std::fs::File::create(&err)?);
    if trace {
        cmd.arg("--trace");
    }
    let child = cmd
        .spawn()
        .with_context(|| format!("cannot start {}", exe.display()))?;
    Ok((child, out, err))
}

/// What ended a child that did not report.
fn describe(status: Option<std::process::ExitStatus>) -> (String, String) {
    match status {
        None => ("hang".into(), "did not finish in time".into()),
        Some(s) => {
            #[cfg(unix)]
            {
                use std::os::unix::process::ExitStatusExt;
                if let Some(sig) = s.signal() {
                    return ("abort".into(), format!("killed by signal {sig}"));
                }
            }
            ("abort".into(), format!("exited with {s}"))
        }
    }
}

/// Wait for `child` at most until `deadline`; kill it then.
fn wait_until(child: &mut Child, deadline: Instant) -> Option<std::process::ExitStatus> {
    loop {
        match child.try_wait() {
            Ok(Some(s)) => return Some(s),
            Ok(None) if Instant::now() >= deadline => {
                let _ = child.kill();
                let _ = child.wait();
                return None;
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(20)),
            Err(_) => return None,
        }
    }
}

/// Write every finding's input into the findings folder (`--findings`, else
/// `out/fuzz`); the folder and the files written.
fn save_findings(args: &FuzzArgs, findings: &[Finding]) -> Result<(PathBuf, Vec<PathBuf>)> {
    let dir = args
        .findings
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join("fuzz"));
    let mut saved = Vec::new();
    if !findings.is_empty() {
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("cannot create {}", dir.display()))?;
        for f in findings {
            let path = dir.join(format!(
                "{}-{}-{}-{}.{}",
                f.target.name(),
                f.kind,
                args.seed,
                f.index,
                f.target.extension()
            ));
            std::fs::write(&path, fuzz::input(f.target, args.seed, f.index))
                .with_context(|| format!("cannot write {}", path.display()))?;
            saved.push(path);
        }
    }
    Ok((dir, saved))
}

/// The parent: batches in child processes, findings collected and saved.
fn parent(args: &FuzzArgs, targets: &[Target]) -> Result<()> {
    let t0 = Instant::now();
    let exe = std::env::current_exe().context("cannot find the foldsynth executable")?;
    let scratch = std::env::temp_dir().join(format!(
        "foldsynth-fuzz-{}-{}",
        std::process::id(),
        t0.elapsed().as_nanos()
    ));
    std::fs::create_dir_all(&scratch)
        .with_context(|| format!("cannot create {}", scratch.display()))?;
    let result = run_batches(args, targets, &exe, &scratch);
    let _ = std::fs::remove_dir_all(&scratch);
    let (counts, findings) = result?;
    let seconds = t0.elapsed().as_secs_f64();

    let total: u64 = counts.values().map(|c| c.inputs).sum();
    let failing: Vec<&Finding> = findings.iter().filter(|f| f.kind != "slow").collect();
    let (dir, saved) = save_findings(args, &findings)?;
    let by_kind = |k: &str| findings.iter().filter(|f| f.kind == k).count();
    let report = json!({
        "seed": args.seed,
        "inputs": total,
        "seconds": seconds,
        "inputs_per_second": total as f64 / seconds.max(1e-9),
        "targets": counts,
        "panics": by_kind("panic"),
        "aborts": by_kind("abort"),
        "hangs": by_kind("hang"),
        "slow": by_kind("slow"),
        "findings": findings,
        "saved": saved,
    });
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!(
            "fuzz: {total} inputs in {seconds:.1} s ({:.0}/s), seed {}",
            total as f64 / seconds.max(1e-9),
            args.seed
        );
        println!(
            "{:<8} {:>10} {:>10} {:>10} {:>12}",
            "target", "inputs", "accepted", "mean ms", "slowest ms"
        );
        for (name, c) in &counts {
            println!(
                "{name:<8} {:>10} {:>10} {:>10.3} {:>12.1}",
                c.inputs,
                c.accepted,
                c.total_ms / c.inputs.max(1) as f64,
                c.max_ms
            );
        }
        println!(
            "panics {}, aborts {}, hangs {}, slower than {} s: {}",
            by_kind("panic"),
            by_kind("abort"),
            by_kind("hang"),
            fuzz::SLOW_MS / 1e3,
            by_kind("slow")
        );
        for f in &findings {
            println!(
                "  {} {} #{}: {}",
                f.kind,
                f.target.name(),
                f.index,
                crate::text::excerpt(&f.message, 300)
            );
        }
        if !saved.is_empty() {
            println!("inputs saved in {}", dir.display());
        }
    }
    if !failing.is_empty() {
        return Err(super::CheckFailed(format!(
            "{} input(s) panicked, aborted or hung (see above)",
            failing.len()
        ))
        .into());
    }
    Ok(())
}

type Merged = (BTreeMap<String, Counts>, Vec<Finding>);

fn merge(into: &mut Merged, r: BatchReport) {
    for (k, c) in r.targets {
        let e = into.0.entry(k).or_default();
        e.inputs += c.inputs;
        e.accepted += c.accepted;
        e.max_ms = e.max_ms.max(c.max_ms);
        e.total_ms += c.total_ms;
    }
    into.1.extend(r.findings);
}

fn run_batches(args: &FuzzArgs, targets: &[Target], exe: &Path, scratch: &Path) -> Result<Merged> {
    let jobs = if args.jobs == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        args.jobs
    };
    let timeout = Duration::from_secs(args.timeout);
    let mut queue: std::collections::VecDeque<Batch> = (0..args.inputs)
        .step_by(args.batch as usize)
        .map(|s| Batch {
            start: s,
            end: (s + args.batch).min(args.inputs),
        })
        .collect();
    let mut merged: Merged = (BTreeMap::new(), Vec::new());
    let mut running: Vec<Running> = Vec::new();
    while !queue.is_empty() || !running.is_empty() {
        while running.len() < jobs
            && let Some(b) = queue.pop_front()
        {
            let (child, out, _) = spawn(exe, args, targets, b, scratch, false)?;
            running.push(Running {
                batch: b,
                child,
                out,
                started: Instant::now(),
            });
        }
        std::thread::sleep(Duration::from_millis(20));
        let mut i = 0;
        while i < running.len() {
            let r = &mut running[i];
            let status = match r.child.try_wait() {
                Ok(Some(s)) => Some(Some(s)),
                Ok(None) if r.started.elapsed() > timeout => {
                    let _ = r.child.kill();
                    let _ = r.child.wait();
                    Some(None)
                }
                Ok(None) => None,
                Err(_) => Some(None),
            };
            let Some(status) = status else {
                i += 1;
                continue;
            };
            let done = running.swap_remove(i);
            let report = status
                .filter(|s| s.success())
                .and_then(|_| std::fs::read_to_string(&done.out).ok())
                .and_then(|t| {
                    let last = t.lines().last().unwrap_or("").to_string();
                    serde_json::from_str::<serde_json::Value>(&last).ok()
                });
            match report {
                Some(v) => merge(&mut merged, batch_report(&v)),
                None => {
                    // Find the input: the batch again, tracing every index.
                    let (kind, message) = describe(status);
                    let index = locate(args, targets, exe, scratch, done.batch)?;
                    if index > done.batch.start {
                        // The inputs before it ran fine in the traced run: count them anew.
                        queue.push_back(Batch {
                            start: done.batch.start,
                            end: index,
                        });
                    }
                    let target = fuzz::target_of(targets, index);
                    let e = merged.0.entry(target.name().to_string()).or_default();
                    e.inputs += 1;
                    merged.1.push(Finding {
                        target,
                        index,
                        kind,
                        message,
                        ms: 0.0,
                    });
                    if index + 1 < done.batch.end {
                        queue.push_back(Batch {
                            start: index + 1,
                            end: done.batch.end,
                        });
                    }
                }
            }
        }
    }
    Ok(merged)
}

/// A worker's JSON report back into a [`BatchReport`] (counts and findings).
fn batch_report(v: &serde_json::Value) -> BatchReport {
    let mut r = BatchReport::default();
    if let Some(t) = v.get("targets").and_then(|t| t.as_object()) {
        for (k, c) in t {
            if let Ok(c) = serde_json::from_value::<Counts>(c.clone()) {
                r.targets.insert(k.clone(), c);
            }
        }
    }
    if let Some(fs) = v.get("findings").and_then(|f| f.as_array()) {
        for f in fs {
            let target = f
                .get("target")
                .and_then(|t| t.as_str())
                .and_then(Target::from_name);
            let index = f.get("index").and_then(|i| i.as_u64());
            if let (Some(target), Some(index)) = (target, index) {
                r.findings.push(Finding {
                    target,
                    index,
                    kind: f["kind"].as_str().unwrap_or("panic").to_string(),
                    message: f["message"].as_str().unwrap_or("").to_string(),
                    ms: f["ms"].as_f64().unwrap_or(0.0),
                });
            }
        }
    }
    r
}

/// Run a failed batch again with a trace: the index of the input that ended it.
fn locate(
    args: &FuzzArgs,
    targets: &[Target],
    exe: &Path,
    scratch: &Path,
    b: Batch,
) -> Result<u64> {
    let (mut child, _, err) = spawn(exe, args, targets, b, scratch, true)?;
    let _ = wait_until(
        &mut child,
        Instant::now() + Duration::from_secs(args.timeout),
    );
    let text = std::fs::read_to_string(&err).unwrap_or_default();
    let culprit = text
        .lines()
        .rev()
        .find_map(|l| l.trim().parse::<u64>().ok())
        .filter(|i| (b.start..b.end).contains(i));
    match culprit {
        Some(c) => Ok(c),
        None => bail!(
            "a fuzz worker for inputs {}..{} failed and the rerun did not show where: {}",
            b.start,
            b.end,
            crate::text::excerpt(text.trim(), 400)
        ),
    }
}
