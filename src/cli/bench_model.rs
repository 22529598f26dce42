//! `foldsynth bench model TASK --graph SEQ`: value+gradient of a whole design model by the
//! JIT, the interpreter and f64 with central differences, and the compile latency
//! (measured by [`crate::bench::model`]).

use super::model::{middle, parse_modes};
use crate::bench::Peer;
use crate::bench::model::{ModelBench, ModelBenchOptions, measure};
use crate::grammar::CreaseGraph;
use crate::model::Model;
use crate::task::Task;
use anyhow::{Context, Result, bail};
use std::path::PathBuf;
use std::time::Duration;

/// Arguments of `foldsynth bench model`.
#[derive(Debug, clap::Args)]
pub struct ModelBenchArgs {
    /// The task file (e.g. grammar/gripper.toml).
    pub task: PathBuf,
    /// The graph as a rule sequence.
    #[arg(long, default_value = "2, 3, (4, 8), 4, (7, 8)")]
    pub graph: String,
    /// Rigid body modes, e.g. "up,down,up" (default: all up).
    #[arg(long)]
    pub modes: Option<String>,
    /// Gripping candidate 1, 2 or 3.
    #[arg(long, default_value_t = 1)]
    pub candidate: usize,
    /// Milliseconds of measurement per row.
    #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u64).range(1..=crate::limits::BENCH_MILLIS_MAX))]
    pub millis: u64,
    /// Print one JSON object (times in nanoseconds, compile times in milliseconds).
    #[arg(long)]
    pub json: bool,
    /// Also run peer implementations in this invocation (only `symbolica` covers whole
    /// models; the CasADi peer covers `bench vertex`).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub peer: Vec<Peer>,
}

/// Run `foldsynth bench model`.
pub fn run(args: ModelBenchArgs) -> Result<()> {
    let task = Task::load(&args.task)?;
    let graph = CreaseGraph::from_sequence(&task, &args.graph)
        .with_context(|| format!("--graph '{}'", args.graph))?;
    if !(1..=3).contains(&args.candidate) {
        bail!("--candidate must be 1, 2 or 3");
    }
    if args.peer.contains(&Peer::Casadi) {
        bail!("--peer casadi: the CasADi peer covers `bench vertex` only; use --peer symbolica");
    }
    let model = Model::new(&graph, &task, args.candidate - 1)?;
    let modes = parse_modes(args.modes.as_deref(), model.plan.n_modes)?;
    let b = measure(ModelBenchOptions {
        model: &model,
        modes: &modes,
        budget: Duration::from_millis(args.millis.max(10)),
        fallback: middle(&model),
        symbolica: args
            .peer
            .contains(&Peer::Symbolica)
            .then(|| super::formulas::model_names(&model)),
    })?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&b.json(&task.name))?);
        return Ok(());
    }
    print_text(&b, &task.name);
    Ok(())
}

/// The text report of `bench model`.
fn print_text(b: &ModelBench, task: &str) {
    let (tm, rep) = (&b.times, &b.report);
    let (jit_v, jit_vg) = (tm.jit_value_ns, tm.jit_value_grad_ns);
    let (interp, f64_fd) = (tm.interpreter_value_grad_ns, tm.f64_central_diff_ns);
    println!(
        "model {} of task '{task}': {} variables, {} constraints (evaluated at {})",
        b.sequence,
        b.variables,
        b.constraints,
        if b.at_optimum {
            "an optimized design"
        } else {
            "the middle of the bounds"
        }
    );
    println!(
        "value + gradient of the objective and every constraint, one run (CPU time per call):"
    );
    println!("  JIT value only                    {jit_v:>10.0} ns");
    println!(
        "  JIT value + all gradients         {jit_vg:>10.0} ns   ({:.2}× the value)",
        jit_vg / jit_v
    );
    println!(
        "  interpreter value + gradients     {interp:>10.0} ns   ({:.1}× the JIT)",
        interp / jit_vg
    );
    println!(
        "  f64 + central differences         {f64_fd:>10.0} ns   ({:.1}× the JIT)",
        f64_fd / jit_vg
    );
    println!(
        "compile: {:.1} ms CPU (build {:.1}, simplify {:.1}, differentiate {:.1}, JIT {:.1}: the median of 5 compiles); operations {} → {} after egg → {} with gradients",
        b.compile_ms,
        b.build_ms,
        rep.simplify_ms,
        rep.diff_ms,
        rep.jit_ms,
        rep.input.ops,
        rep.simplified.ops,
        rep.with_gradients.ops
    );
    println!(
        "JIT, interpreter and f64 agree to 1e-12: {}",
        b.values_agree
    );
    if let Some(s) = &b.symbolica {
        for l in s.lines(jit_vg, b.compile_ms) {
            println!("{l}");
        }
    }
}
