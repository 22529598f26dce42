//! `foldsynth bench optimize TASK`: our optimizer against IPOPT on the task's alternatives
//! (measured by [`crate::bench::optimize`]).

use super::formulas::{ModelFormulaOptions, model_formulas};
use crate::bench::optimize::{OptimizeBench, OptimizeBenchOptions, Side, run as measure};
use crate::expr::Format;
use crate::limits;
use crate::task::Task;
use anyhow::Result;
use std::path::PathBuf;

/// Arguments of `foldsynth bench optimize`.
#[derive(Debug, clap::Args)]
pub struct OptimizeBenchArgs {
    /// The task file (e.g. grammar/gripper.toml).
    pub task: PathBuf,
    /// N_max of the enumeration (default: the task's).
    #[arg(long, value_parser = limits::count::<1, { limits::N_MAX as u64 }>)]
    pub n_max: Option<usize>,
    /// At most this many alternatives, spread evenly over the enumeration.
    #[arg(long, default_value_t = 60, value_parser = limits::count::<1, 100000>)]
    pub alternatives: usize,
    /// Starting points per alternative (the search's default).
    #[arg(long, default_value_t = 16, value_parser = limits::count::<1, { limits::STARTS_MAX as u64 }>)]
    pub starts: usize,
    /// Seed of the starting points.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// The Python interpreter with CasADi (`pip install casadi`).
    #[arg(long, default_value = "python3")]
    pub python: String,
    /// The peer script (default: the crate's benches/peers/ipopt_optimize.py).
    #[arg(long)]
    pub peer_script: Option<PathBuf>,
    /// Print one JSON object with every alternative.
    #[arg(long)]
    pub json: bool,
}

/// Run `foldsynth bench optimize`.
pub fn run(args: OptimizeBenchArgs) -> Result<()> {
    let task = Task::load(&args.task)?;
    let formulas = |m: &crate::model::Model| {
        model_formulas(
            m,
            &task.name,
            ModelFormulaOptions {
                format: Format::Python,
                simplify: true,
                gradient: false,
            },
        )
    };
    let b = measure(
        &task,
        &OptimizeBenchOptions {
            n_max: args.n_max,
            alternatives: args.alternatives,
            starts: args.starts,
            seed: args.seed,
            python: &args.python,
            script: args.peer_script.as_deref(),
            formulas: &formulas,
        },
    )?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&b)?);
    } else {
        print_table(&b);
    }
    Ok(())
}

/// The comparison as a table: shares, and per alternative the means.
fn print_table(b: &OptimizeBench) {
    let n = b.alternatives.len().max(1) as f64;
    let col = |f: &dyn Fn(&Side) -> f64| -> (f64, f64) {
        let ours: f64 = b.alternatives.iter().map(|a| f(&a.ours)).sum();
        let theirs: f64 = b.alternatives.iter().map(|a| f(&a.ipopt)).sum();
        (ours / n, theirs / n)
    };
    let pct = |x: f64| format!("{:.1} %", 100.0 * x);
    println!(
        "{} alternatives of task '{}' (N_max = {}: one in {} of {}), up to {} starts each from the same points; {}",
        b.alternatives.len(),
        b.task,
        b.n_max,
        (b.enumerated as usize).div_ceil(b.alternatives.len().max(1)),
        b.enumerated,
        b.starts,
        b.peer
    );
    println!("{:<44} {:>16} {:>16}", "", "foldsynth", "IPOPT");
    let (o, t) = col(&|s| f64::from(u8::from(s.reached)));
    println!(
        "{:<44} {:>16} {:>16}",
        "reach the target (Ω ≤ threshold)",
        pct(o),
        pct(t)
    );
    let (o, t) = col(&|s| f64::from(u8::from(s.met)));
    println!(
        "{:<44} {:>16} {:>16}",
        "… feasibly (meet it, as the search counts)",
        pct(o),
        pct(t)
    );
    let (o, t) = col(&|s| s.starts_run as f64);
    println!(
        "{:<44} {:>16.2} {:>16.2}",
        "starts run per alternative", o, t
    );
    let (o, t) = col(&|s| s.evaluations as f64);
    println!(
        "{:<44} {:>16.0} {:>16.0}",
        "evaluations per alternative", o, t
    );
    let (o, t) = col(&|s| s.cpu_ms);
    println!("{:<44} {:>16.3} {:>16.3}", "CPU ms per alternative", o, t);
    println!(
        "{:<44} {:>16} {:>16.1}",
        "time relative to foldsynth",
        "1",
        if o > 0.0 { t / o } else { f64::NAN }
    );
    let iters: usize = b.alternatives.iter().map(|a| a.ipopt_iterations).sum();
    let hess: usize = b.alternatives.iter().map(|a| a.ipopt_hessians).sum();
    let dev = b
        .alternatives
        .iter()
        .map(|a| a.formula_deviation)
        .fold(0.0, f64::max);
    let branch: usize = b.alternatives.iter().map(|a| a.formula_branch_starts).sum();
    let points: usize = b.alternatives.len() * b.starts;
    let both = b
        .alternatives
        .iter()
        .filter(|a| a.ours.met && a.ipopt.met)
        .count();
    let only_ours = b
        .alternatives
        .iter()
        .filter(|a| a.ours.met && !a.ipopt.met)
        .count();
    let only_theirs = b
        .alternatives
        .iter()
        .filter(|a| !a.ours.met && a.ipopt.met)
        .count();
    println!(
        "met by both {both}, by foldsynth only {only_ours}, by IPOPT only {only_theirs}; IPOPT: {:.1} iterations and {:.1} Hessians per alternative",
        iters as f64 / n,
        hess as f64 / n
    );
    println!(
        "the printed formulas (CasADi) and the compiled model agree to {dev:.1e} (relative; the largest median over an alternative's starts); {branch} of {points} starts lie on a branch decided by rounding (deviation > {:.0e}); IPOPT options {}",
        crate::bench::optimize::BRANCH_DEVIATION,
        b.ipopt_options
    );
}
