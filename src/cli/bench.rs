//! `foldsynth bench …`: speed measured in one run and reported as ratios.
//!
//! One sub-subcommand per benchmark; add a variant to [`BenchCommand`] and a match arm
//! in [`run`] to add one. The measuring is the library's ([`crate::bench`]); these files
//! read the arguments and print.

use crate::bench::Peer;
use crate::bench::vertex::{VertexBench, VertexBenchOptions, measure};
use crate::compile::vertex::most_rigid_t;
use crate::kinematics::VertexSpec;
use anyhow::{Context, Result, bail};
use std::path::PathBuf;

/// Arguments of `foldsynth bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// What to measure.
    #[command(subcommand)]
    pub what: BenchCommand,
}

/// The benchmarks.
#[derive(Debug, clap::Subcommand)]
pub enum BenchCommand {
    /// One vertex: value+gradient of φ1+φ2+φ3 by JIT, interpreter, f64 + central
    /// differences and dual numbers, and the compile latency.
    Vertex(VertexBenchArgs),
    /// One design model: objective and constraints with gradients by JIT, interpreter and
    /// f64 + central differences, and the compile latency.
    Model(super::bench_model::ModelBenchArgs),
    /// One folding motion of one design: the compiled PTU model against the bar-and-hinge
    /// simulation (thesis Sec. 3), same states.
    Numeric(super::bench_numeric::NumericBenchArgs),
    /// One design's files, part by part (FOLD, SVG, meshes, pictures, GIF frames and their
    /// LZW against the gif crate's), on one thread.
    Export(super::bench_export::ExportBenchArgs),
    /// Our optimizer against IPOPT (the CasADi wheel's) on a task's alternatives from the
    /// same starting points: the share that meets the target, and that meets it feasibly,
    /// starts, evaluations and CPU time per alternative.
    Optimize(super::bench_optimize::OptimizeBenchArgs),
}

/// Run `foldsynth bench`.
pub fn run(args: BenchArgs) -> Result<()> {
    match args.what {
        BenchCommand::Vertex(a) => run_vertex(a),
        BenchCommand::Model(a) => super::bench_model::run(a),
        BenchCommand::Numeric(a) => super::bench_numeric::run(a),
        BenchCommand::Export(a) => super::bench_export::run(a),
        BenchCommand::Optimize(a) => super::bench_optimize::run(a),
    }
}

/// Arguments of `foldsynth bench vertex`.
#[derive(Debug, clap::Args)]
pub struct VertexBenchArgs {
    /// The vertex in the thesis's notation, e.g.
    /// "v(up, ((40,50,45,35,40),(t,-t,t,-t)), (55), (95))".
    pub spec: String,
    /// Make the sector angles variables (gradient with respect to all of them); otherwise
    /// the gradient is with respect to t.
    #[arg(long)]
    pub symbolic_sectors: bool,
    /// Print one JSON object (times in nanoseconds, compile times in milliseconds).
    #[arg(long)]
    pub json: bool,
    /// Also run peer implementations in this invocation (repeat or separate by commas:
    /// `--peer casadi,symbolica`).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub peer: Vec<Peer>,
    /// The driving parameter at which to evaluate (default: the most rigid sample of
    /// (0, π), away from singular states).
    #[arg(long, allow_hyphen_values = true)]
    pub t: Option<f64>,
    /// Milliseconds of measurement per row (split into rounds of batches; the fastest
    /// round's median batch is reported).
    #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u64).range(1..=crate::limits::BENCH_MILLIS_MAX))]
    pub millis: u64,
    /// The peer script (default: the crate's benches/peers/casadi_vertex.py).
    #[arg(long)]
    pub peer_script: Option<PathBuf>,
}

/// Run `foldsynth bench vertex`.
pub fn run_vertex(args: VertexBenchArgs) -> Result<()> {
    let spec = VertexSpec::parse(&args.spec).context("invalid vertex")?;
    let t = args.t.unwrap_or_else(|| most_rigid_t(&spec));
    if !(t.is_finite() && t.abs() <= crate::limits::COORD_MAX) {
        bail!("--t must be a finite number within ±1e6");
    }
    let b = measure(&VertexBenchOptions {
        spec: &spec,
        symbolic_sectors: args.symbolic_sectors,
        t,
        millis: args.millis,
        peers: &args.peer,
        peer_script: args.peer_script.as_deref(),
    })?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&b.json())?);
    } else {
        print_vertex(&b);
    }
    verdict(&b)
}

/// A NaN or a deviation of the CasADi peer where the vertex is rigid is a failed check
/// (exit 1).
fn verdict(b: &VertexBench) -> Result<()> {
    match b.casadi.as_ref().and_then(|p| p.dev) {
        Some(d) if b.rigid_at_t && (d.is_nan() || d > 1e-6) => Err(super::CheckFailed(format!(
            "CasADi and foldsynth disagree at t = {}, where the vertex is rigid: relative deviation {}",
            b.t,
            if d.is_nan() {
                "NaN".to_string()
            } else {
                format!("{d:.1e}")
            }
        ))
        .into()),
        _ => Ok(()),
    }
}

/// The text report of `bench vertex`.
fn print_vertex(b: &VertexBench) {
    let (n, t, rep) = (b.n_vars, b.t, &b.report);
    println!(
        "vertex {}  (degree {}, {})",
        b.vertex,
        b.degree,
        if b.symbolic_sectors {
            format!("symbolic sectors: gradient w.r.t. {n} sector angles")
        } else {
            "numeric sectors: gradient w.r.t. t".to_string()
        }
    );
    println!("value φ1+φ2+φ3 = {:.15} at t = {t}", b.value);
    let (ops_before, ops_after) = (rep.input.ops, rep.simplified.ops);
    let shrink = 100.0 * (ops_before as f64 - ops_after as f64) / ops_before.max(1) as f64;
    println!(
        "operations: built {ops_before}, simplified {ops_after} ({shrink:.1}% fewer), with gradient {}; transcendental nodes {} -> {}; libm calls in the native code: value {}, value+gradient {} (sin+cos of one argument = one sincos)",
        rep.with_gradients.ops,
        rep.input.calls,
        rep.simplified.calls,
        b.native_calls_value,
        b.native_calls_value_grad
    );
    println!();
    print_vertex_times(b);
    println!();
    println!(
        "compile latency {:.2} ms = build {:.2} + simplify {:.2} + differentiate {:.2} + JIT {:.2} (+ overhead)",
        b.compile_ms, b.build_ms, rep.simplify_ms, rep.diff_ms, rep.jit_ms
    );
    print_vertex_checks(b);
    if let Some(s) = &b.symbolica {
        println!();
        for l in s.lines(b.times.jit_value_grad_ns, b.compile_ms) {
            println!("{l}");
        }
    }
}

/// The table of times, relative to the JIT.
fn print_vertex_times(b: &VertexBench) {
    let tm = &b.times;
    let jit = tm.jit_value_grad_ns;
    println!(
        "{:<44} {:>12} {:>12}",
        "value + gradient", "ns/eval", "vs JIT"
    );
    let row = |name: &str, ns: f64| {
        println!("{name:<44} {ns:>12.1} {:>11.2}x", ns / jit);
    };
    row("JIT (Cranelift)", jit);
    row("DAG interpreter", tm.interpreter_value_grad_ns);
    row(
        &format!(
            "f64 kinematics + central differences ({} evals)",
            1 + 2 * b.n_vars
        ),
        tm.f64_central_diff_ns,
    );
    row("dual numbers (forward mode)", tm.dual_ns);
    if let Some(p) = &b.casadi {
        if let Some(ns) = p.info.get("value_grad_ns").and_then(|v| v.as_f64()) {
            row("CasADi SX reverse mode, gcc -O3 (peer)", ns);
        } else if let Some(msg) = p.info.get("skipped").and_then(|v| v.as_str()) {
            println!("CasADi peer skipped: {msg}");
        }
    }
    if let Some(s) = &b.symbolica {
        row("Symbolica SymJIT (peer)", s.value_grad_ns());
    }
    println!();
    println!("{:<44} {:>12.1}", "JIT value only (ns)", tm.jit_value_ns);
    println!(
        "{:<44} {:>12.1}",
        "f64 kinematics value only (ns)", tm.f64_value_ns
    );
    println!(
        "{:<44} {:>12.2}",
        "JIT gradient/value cost ratio",
        b.grad_value_ratio()
    );
    println!(
        "{:<44} {:>12.1}",
        "JIT speedup over central differences",
        tm.f64_central_diff_ns / jit
    );
}

/// The peer's compile time and how the implementations' numbers agree.
fn print_vertex_checks(b: &VertexBench) {
    if let Some(p) = &b.casadi
        && let Some(ms) = p.info.get("total_compile_ms").and_then(|v| v.as_f64())
    {
        println!(
            "CasADi build + codegen + gcc -O3: {ms:.1} ms (ours is {:.3} of it)",
            b.compile_ms / ms
        );
    }
    let c = &b.checks;
    println!(
        "checks: value vs f64/interpreter {:.1e}, gradient vs dual {:.1e}, vs central differences {:.1e}",
        c.max_dev_value, c.max_dev_dual, c.max_dev_fd
    );
    let Some(p) = &b.casadi else { return };
    match p.dev {
        Some(d) if d.is_finite() => println!("CasADi's value and gradient vs ours: {d:.1e}"),
        Some(_) => println!(
            "CasADi's value and gradient vs ours: not comparable, CasADi gives NaN for {} at t = {}{}",
            p.nans.join(", "),
            b.t,
            if b.rigid_at_t {
                ""
            } else {
                " (outside the vertex's rigid interval: its sqrt of a negative number is NaN; ours is guarded)"
            }
        ),
        None => {}
    }
}
