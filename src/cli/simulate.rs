//! `foldsynth simulate FILE [--steps J] [--json]`: the bar-and-hinge simulation of a
//! pattern file, with a table of δ(j), Γ, θ and the verdict.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

use crate::simulate::{PatternFile, RIGID_DELTA, SimReport, simulate};

/// Arguments of `foldsynth simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// A pattern file (TOML, see `grammar/flasher_adapted.toml`).
    pub file: PathBuf,
    /// Number of folding steps J (overrides the file's `motion.steps`).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub steps: Option<u64>,
    /// Print the full report as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Run `foldsynth simulate`.
pub fn run(args: SimulateArgs) -> anyhow::Result<()> {
    let mut file = PatternFile::load(&args.file)?;
    if let Some(j) = args.steps {
        file.input.steps = j as usize;
    }
    let start = std::time::Instant::now();
    let report = simulate(&file.input).with_context(|| {
        let legend: Vec<String> = file
            .vertex_names
            .iter()
            .enumerate()
            .map(|(i, n)| format!("{i}={n}"))
            .collect();
        format!(
            "simulating {} (vertex numbers: {})",
            args.file.display(),
            legend.join(", ")
        )
    })?;
    let seconds = start.elapsed().as_secs_f64();
    if args.json {
        let out = serde_json::json!({
            "name": file.name,
            "vertex_names": file.vertex_names,
            "steps": report.steps,
            "gamma": report.gamma,
            "theta": report.theta,
            "rigid": report.rigid,
            "max_delta": report.max_delta(),
            "rigid_delta_bound": RIGID_DELTA,
            "initial_intersections": report.initial_intersections,
            "final_positions": report.final_positions(),
            "states": report.states,
            "bars": report.bars,
            "free_vertices": report.free_vertices,
            "seconds": seconds,
        });
        emit(&(serde_json::to_string_pretty(&out)? + "\n"))
    } else {
        emit(&table(&file, &report, seconds))
    }
}

/// Write to stdout; a closed pipe (`| head`) ends the output quietly instead of failing.
pub(crate) fn emit(text: &str) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        r => Ok(r?),
    }
}

fn table(file: &PatternFile, r: &SimReport, seconds: f64) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "{}", file.name);
    let _ = writeln!(
        o,
        "{} vertices ({} free), {} facets, {} bars, J = {}",
        file.vertex_names.len(),
        r.free_vertices,
        file.input.faces.len(),
        r.bars,
        r.steps.len()
    );
    let _ = writeln!(
        o,
        "{:>4} {:>12} {:>12} {:>12} {:>5}  intersection",
        "j", "t", "delta(j)", "sum|l-lt|", "iter"
    );
    for s in &r.steps {
        let x = match &s.intersection {
            Some(i) => format!("{:?} f{}-f{}", i.kind, i.face_a, i.face_b),
            None => String::new(),
        };
        let _ = writeln!(
            o,
            "{:>4} {:>12.6} {:>12.3e} {:>12.3e} {:>5}  {}",
            s.j, s.t, s.delta, s.delta_length, s.iterations, x
        );
    }
    if !r.initial_intersections.is_empty() {
        let _ = writeln!(
            o,
            "initial state already intersects: {} facet pairs",
            r.initial_intersections.len()
        );
    }
    let _ = writeln!(o, "Gamma (mean delta)  {:.3e}", r.gamma);
    let _ = writeln!(o, "max delta(j)        {:.3e}", r.max_delta());
    let _ = writeln!(o, "theta               {:.4}", r.theta);
    let _ = writeln!(
        o,
        "verdict             {}",
        if r.rigid {
            format!("rigid (every delta(j) <= {RIGID_DELTA:e})")
        } else {
            format!("not rigid (some delta(j) > {RIGID_DELTA:e})")
        }
    );
    let _ = writeln!(o, "final positions:");
    for (name, p) in file.vertex_names.iter().zip(r.final_positions()) {
        let _ = writeln!(
            o,
            "  {name:>8}  ({:>10.6}, {:>10.6}, {:>10.6})",
            p[0], p[1], p[2]
        );
    }
    let _ = writeln!(o, "time                {:.3} s", seconds);
    o
}
