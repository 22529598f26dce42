//! `foldsynth bench model`: value+gradient of a whole design model (objective and every
//! constraint with their gradients) by the JIT, the expression-graph interpreter and the
//! plain f64 model with central differences, plus the compile latency, measured in one
//! run. Every figure is CPU time of this thread; the compile stages and their total come
//! from the same compile (the median of five by total).

use super::symbolica::{PeerJob, SymbolicaPeer};
use super::time_ns;
use crate::compile::{CompileReport, Options};
use crate::expr::{Names, Tape};
use crate::model::Model;
use crate::model::compiled::{
    CompiledModel, ModelProblem, objective_target, outputs_f64, symbolic,
};
use crate::optimize;
use anyhow::Result;
use serde_json::json;
use std::hint::black_box;
use std::time::Duration;

/// What to measure.
pub struct ModelBenchOptions<'a> {
    /// The model.
    pub model: &'a Model,
    /// Its modes (±1 per internal vertex).
    pub modes: &'a [f64],
    /// Measurement per row.
    pub budget: Duration,
    /// Where to evaluate when the optimizer finds no feasible design (the middle of the
    /// bounds).
    pub fallback: Vec<f64>,
    /// The model's variable and parameter names, to run the Symbolica peer; `None`: no
    /// peer.
    pub symbolica: Option<Names>,
}

/// Nanoseconds per call of value (+ gradients) of the objective and every constraint.
#[derive(Clone, Copy, Debug)]
pub struct ModelTimes {
    /// JIT, values only.
    pub jit_value_ns: f64,
    /// JIT, values and all gradients.
    pub jit_value_grad_ns: f64,
    /// The DAG interpreter, values and gradients.
    pub interpreter_value_grad_ns: f64,
    /// The f64 model with central differences.
    pub f64_central_diff_ns: f64,
}

/// The figures of one `bench model` run.
pub struct ModelBench {
    /// The graph's rule sequence.
    pub sequence: String,
    /// Number of free variables.
    pub variables: usize,
    /// Number of constraints.
    pub constraints: usize,
    /// The times.
    pub times: ModelTimes,
    /// Milliseconds of the median compile (build to native code).
    pub compile_ms: f64,
    /// Milliseconds of its build.
    pub build_ms: f64,
    /// Its compiler report.
    pub report: CompileReport,
    /// Whether JIT, interpreter and f64 agree to 1e-12.
    pub values_agree: bool,
    /// Whether the point is an optimized design (else the fallback).
    pub at_optimum: bool,
    /// The Symbolica peer, when asked for.
    pub symbolica: Option<SymbolicaPeer>,
}

/// Compile latency: build → simplify → differentiate → JIT, five compiles; the median
/// one by total gives the total and its stages. Then the value-only compile.
fn compile_median(model: &Model) -> Result<(CompiledModel, CompiledModel)> {
    let mut runs = (0..5)
        .map(|_| CompiledModel::new(model, &Options::default()))
        .collect::<Result<Vec<_>, _>>()?;
    runs.sort_by(|a, b| a.total_ms.total_cmp(&b.total_ms));
    let compiled = runs.swap_remove(2);
    let value_only = CompiledModel::new(
        model,
        &Options {
            gradients: false,
            ..Options::default()
        },
    )?;
    Ok((compiled, value_only))
}

/// The times of the four rows at `x`, and whether the three implementations agree there
/// (the numbers measured are of the same function). `buf` is left holding the JIT's
/// values and gradients.
fn time_rows(
    opts: &ModelBenchOptions<'_>,
    (compiled, value_only): (&CompiledModel, &CompiledModel),
    (x, params): (&[f64], &[f64]),
    buf: &mut [f64],
) -> Result<(ModelTimes, bool)> {
    let (model, modes, budget, n) = (opts.model, opts.modes, opts.budget, x.len());
    let jit_vg = time_ns(budget, || compiled.call(black_box(x), params, buf));
    let mut vbuf = vec![0.0; value_only.buffer_len()];
    let jit_v = time_ns(budget, || value_only.call(black_box(x), params, &mut vbuf));
    let tape = Tape::new(
        &compiled.compiled.graph,
        &compiled.compiled.outputs,
        n,
        params.len(),
    )?;
    let mut tbuf = vec![0.0; compiled.buffer_len()];
    let interp = time_ns(budget, || {
        tape.eval(black_box(x), params, &mut tbuf)
            .expect("sizes match");
    });
    let h = 1e-6;
    let f64_fd = time_ns(budget, || {
        black_box(outputs_f64(model, black_box(x), modes));
        for j in 0..n {
            let mut xp = x.to_vec();
            xp[j] += h;
            let mut xm = x.to_vec();
            xm[j] -= h;
            black_box((
                outputs_f64(model, &xp, modes),
                outputs_f64(model, &xm, modes),
            ));
        }
    });
    compiled.call(x, params, buf);
    tape.eval(x, params, &mut tbuf)?;
    let (f, g) = outputs_f64(model, x, modes);
    let agree = std::iter::once(f).chain(g).enumerate().all(|(k, v)| {
        let (a, b) = (buf[k], tbuf[k]);
        (a - v).abs() <= 1e-12 * v.abs().max(1.0) && (b - v).abs() <= 1e-12 * v.abs().max(1.0)
    });
    let times = ModelTimes {
        jit_value_ns: jit_v,
        jit_value_grad_ns: jit_vg,
        interpreter_value_grad_ns: interp,
        f64_central_diff_ns: f64_fd,
    };
    Ok((times, agree))
}

/// The Symbolica peer of the same model at the same point, timed in rounds of a fifth of
/// the budget per row (like the rows above in total).
fn symbolica_peer(
    model: &Model,
    names: Names,
    (x, params): (&[f64], &[f64]),
    ours: &[f64],
    budget: Duration,
) -> Result<SymbolicaPeer> {
    let (ctx, outputs) = symbolic(model);
    let mut named = vec![("objective".to_string(), ctx.node_id(&outputs[0]))];
    for (k, o) in outputs[1..].iter().enumerate() {
        named.push((format!("g{}", k + 1), ctx.node_id(o)));
    }
    let job = PeerJob {
        graph: ctx.to_graph(),
        outputs: named,
        names,
        n_vars: x.len(),
        n_params: params.len(),
    };
    let inputs: Vec<f64> = x.iter().chain(params).copied().collect();
    let mut s = SymbolicaPeer::new(job, inputs, ours, 3)?;
    for _ in 0..5 {
        s.round(budget / 5)?;
    }
    Ok(s)
}

/// Measure `bench model`.
pub fn measure(opts: ModelBenchOptions<'_>) -> Result<ModelBench> {
    let (model, modes) = (opts.model, opts.modes);
    let (compiled, value_only) = compile_median(model)?;

    // Evaluate at an optimized design (a representative point), else the fallback.
    let problem = ModelProblem::new(model, &compiled, modes);
    let sol = optimize::minimize(
        &problem,
        &optimize::Options {
            starts: 8,
            target: Some(objective_target(model)),
            ..Default::default()
        },
    );
    let x = if sol.feasible {
        sol.x
    } else {
        opts.fallback.clone()
    };
    let params = compiled.params(model, modes);
    let mut buf = vec![0.0; compiled.buffer_len()];
    let (times, agree) = time_rows(&opts, (&compiled, &value_only), (&x, &params), &mut buf)?;
    let symbolica = match opts.symbolica {
        Some(names) => Some(symbolica_peer(
            model,
            names,
            (&x, &params),
            &buf,
            opts.budget,
        )?),
        None => None,
    };
    Ok(ModelBench {
        sequence: model.plan.sequence.clone(),
        variables: x.len(),
        constraints: compiled.n_constraints,
        times,
        compile_ms: compiled.total_ms,
        build_ms: compiled.build_ms,
        report: compiled.compiled.report.clone(),
        values_agree: agree,
        at_optimum: sol.feasible,
        symbolica,
    })
}

impl ModelBench {
    /// The figures as one JSON object (times in nanoseconds, compile times in
    /// milliseconds) for task `task`.
    pub fn json(&self, task: &str) -> serde_json::Value {
        let (tm, rep) = (&self.times, &self.report);
        let (jit_v, jit_vg) = (tm.jit_value_ns, tm.jit_value_grad_ns);
        let mut out = json!({
            "task": task, "graph": self.sequence, "variables": self.variables,
            "constraints": self.constraints,
            "jit_value_ns": jit_v, "jit_value_grad_ns": jit_vg,
            "interpreter_value_grad_ns": tm.interpreter_value_grad_ns, "f64_central_diff_ns": tm.f64_central_diff_ns,
            "compile_ms": self.compile_ms, "build_ms": self.build_ms, "value_grad_over_value": jit_vg / jit_v,
            "simplify_ms": rep.simplify_ms, "diff_ms": rep.diff_ms, "jit_ms": rep.jit_ms,
            "ops_before": rep.input.ops, "ops_after": rep.simplified.ops, "ops_gradient": rep.with_gradients.ops,
            "values_agree": self.values_agree, "at_optimum": self.at_optimum,
        });
        if let Some(s) = &self.symbolica {
            out["symbolica"] = s.json();
            out["symbolica_value_grad_ratio"] = json!(jit_vg / s.value_grad_ns());
            out["symbolica_compile_ratio"] = json!(self.compile_ms / s.compile_ms());
        }
        out
    }
}
