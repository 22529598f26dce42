//! `foldsynth bench model TASK --graph SEQ`: value+gradient of a whole design model
//! (objective and every constraint with their gradients) by the JIT, the expression-graph
//! interpreter and the plain f64 model with central differences, plus the compile latency,
//! measured in one run. Every figure is CPU time of this thread; the compile stages and
//! their total come from the same compile (the median of five by total).

use super::bench::time_ns;
use super::model::{middle, parse_modes};
use crate::compile::Options;
use crate::expr::Tape;
use crate::grammar::CreaseGraph;
use crate::model::Model;
use crate::model::compiled::{
    CompiledModel, ModelProblem, objective_target, outputs_f64, symbolic,
};
use crate::optimize;
use crate::task::Task;
use anyhow::{Context, Result, bail};
use serde_json::json;
use std::hint::black_box;
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
    pub peer: Vec<super::bench::Peer>,
}

/// Run `foldsynth bench model`.
pub fn run(args: ModelBenchArgs) -> Result<()> {
    let task = Task::load(&args.task)?;
    let graph = CreaseGraph::from_sequence(&task, &args.graph)
        .with_context(|| format!("--graph '{}'", args.graph))?;
    if !(1..=3).contains(&args.candidate) {
        bail!("--candidate must be 1, 2 or 3");
    }
    if args.peer.contains(&super::bench::Peer::Casadi) {
        bail!("--peer casadi: the CasADi peer covers `bench vertex` only; use --peer symbolica");
    }
    let model = Model::new(&graph, &task, args.candidate - 1)?;
    let modes = parse_modes(args.modes.as_deref(), model.plan.internal.len())?;
    let budget = Duration::from_millis(args.millis.max(10));

    // Compile latency: build → simplify → differentiate → JIT, five compiles; the median
    // one by total gives the total and its stages.
    let mut runs = (0..5)
        .map(|_| CompiledModel::new(&model, &Options::default()))
        .collect::<Result<Vec<_>, _>>()?;
    runs.sort_by(|a, b| a.total_ms.total_cmp(&b.total_ms));
    let compiled = runs.swap_remove(2);
    let compile_ms = compiled.total_ms;
    let value_only = CompiledModel::new(
        &model,
        &Options {
            gradients: false,
            ..Options::default()
        },
    )?;
    let rep = &compiled.compiled.report;

    // Evaluate at an optimized design (a representative point), else the middle.
    let problem = ModelProblem::new(&model, &compiled, &modes);
    let sol = optimize::minimize(
        &problem,
        &optimize::Options {
            starts: 8,
            target: Some(objective_target(&model)),
            ..Default::default()
        },
    );
    let x = if sol.feasible { sol.x } else { middle(&model) };
    let params = compiled.params(&model, &modes);
    let n = x.len();

    let mut buf = vec![0.0; compiled.buffer_len()];
    let jit_vg = time_ns(budget, || compiled.call(black_box(&x), &params, &mut buf));
    let mut vbuf = vec![0.0; value_only.buffer_len()];
    let jit_v = time_ns(budget, || {
        value_only.call(black_box(&x), &params, &mut vbuf)
    });
    let tape = Tape::new(
        &compiled.compiled.graph,
        &compiled.compiled.outputs,
        n,
        params.len(),
    )?;
    let mut tbuf = vec![0.0; compiled.buffer_len()];
    let interp = time_ns(budget, || {
        tape.eval(black_box(&x), &params, &mut tbuf)
            .expect("sizes match");
    });
    let h = 1e-6;
    let f64_fd = time_ns(budget, || {
        black_box(outputs_f64(&model, black_box(&x), &modes));
        for j in 0..n {
            let mut xp = x.clone();
            xp[j] += h;
            let mut xm = x.clone();
            xm[j] -= h;
            black_box((
                outputs_f64(&model, &xp, &modes),
                outputs_f64(&model, &xm, &modes),
            ));
        }
    });
    // The three agree (the numbers measured are of the same function).
    compiled.call(&x, &params, &mut buf);
    tape.eval(&x, &params, &mut tbuf)?;
    let (f, g) = outputs_f64(&model, &x, &modes);
    let agree = std::iter::once(f).chain(g).enumerate().all(|(k, v)| {
        let (a, b) = (buf[k], tbuf[k]);
        (a - v).abs() <= 1e-12 * v.abs().max(1.0) && (b - v).abs() <= 1e-12 * v.abs().max(1.0)
    });
    let symbolica = if args.peer.contains(&super::bench::Peer::Symbolica) {
        let (ctx, outputs) = symbolic(&model);
        let mut named = vec![("objective".to_string(), ctx.node_id(&outputs[0]))];
        for (k, o) in outputs[1..].iter().enumerate() {
            named.push((format!("g{}", k + 1), ctx.node_id(o)));
        }
        let job = super::bench_symbolica::PeerJob {
            graph: ctx.to_graph(),
            outputs: named,
            names: super::formulas::model_names(&model),
            n_vars: n,
            n_params: params.len(),
        };
        let inputs: Vec<f64> = x.iter().chain(&params).copied().collect();
        let mut s = super::bench_symbolica::SymbolicaPeer::new(job, inputs, &buf, 3)?;
        // Rounds of a fifth of the budget per row, like the rows above in total.
        for _ in 0..5 {
            s.round(budget / 5)?;
        }
        Some(s)
    } else {
        None
    };

    let mut out = json!({
        "task": task.name, "graph": model.plan.sequence, "variables": n,
        "constraints": compiled.n_constraints,
        "jit_value_ns": jit_v, "jit_value_grad_ns": jit_vg,
        "interpreter_value_grad_ns": interp, "f64_central_diff_ns": f64_fd,
        "compile_ms": compile_ms, "build_ms": compiled.build_ms, "value_grad_over_value": jit_vg / jit_v,
        "simplify_ms": rep.simplify_ms, "diff_ms": rep.diff_ms, "jit_ms": rep.jit_ms,
        "ops_before": rep.input.ops, "ops_after": rep.simplified.ops, "ops_gradient": rep.with_gradients.ops,
        "values_agree": agree, "at_optimum": sol.feasible,
    });
    if let Some(s) = &symbolica {
        out["symbolica"] = s.json();
        out["symbolica_value_grad_ratio"] = json!(jit_vg / s.value_grad_ns());
        out["symbolica_compile_ratio"] = json!(compile_ms / s.compile_ms());
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!(
        "model {} of task '{}': {n} variables, {} constraints (evaluated at {})",
        model.plan.sequence,
        task.name,
        compiled.n_constraints,
        if sol.feasible {
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
        "compile: {compile_ms:.1} ms CPU (build {:.1}, simplify {:.1}, differentiate {:.1}, JIT {:.1}: the median of 5 compiles); operations {} → {} after egg → {} with gradients",
        compiled.build_ms,
        rep.simplify_ms,
        rep.diff_ms,
        rep.jit_ms,
        rep.input.ops,
        rep.simplified.ops,
        rep.with_gradients.ops
    );
    println!("JIT, interpreter and f64 agree to 1e-12: {agree}");
    if let Some(s) = &symbolica {
        for l in s.lines(jit_vg, compile_ms) {
            println!("{l}");
        }
    }
    Ok(())
}
