//! `foldsynth bench vertex`: value+gradient of φ1+φ2+φ3 of one vertex by the JIT, the
//! expression-graph interpreter, the f64 kinematics with central differences and dual
//! numbers, the compile latency stage by stage, and the peers (CasADi, Symbolica) in the
//! same run. Every implementation's numbers are checked against the others' first.

use super::casadi::{CasadiJob, CasadiPeer};
use super::symbolica::{PeerJob, SymbolicaPeer};
use super::{Peer, fastest, rel, time_ms, time_ns};
use crate::compile::vertex::{self, VertexModel};
use crate::compile::{CompileReport, Compiled, Dual, Options, compile};
use crate::expr::{ExprGraph, NodeId, Tape};
use crate::geom::max_or_nan;
use crate::kinematics::VertexSpec;
use crate::kinematics::foldability::{self, RIGID_TOL};
use anyhow::Result;
use serde_json::json;
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

/// Rounds of timings: every row is measured once per round (the peer's harness too) and
/// the fastest round is reported.
pub const ROUNDS: u32 = 7;

/// Step of the central differences.
const H: f64 = 1e-6;

/// What to measure.
pub struct VertexBenchOptions<'a> {
    /// The vertex.
    pub spec: &'a VertexSpec,
    /// Sector angles as variables (gradient with respect to all of them); otherwise the
    /// gradient is with respect to t.
    pub symbolic_sectors: bool,
    /// The driving parameter at which to evaluate.
    pub t: f64,
    /// Milliseconds of measurement per row (at least 10 are used), split into rounds.
    pub millis: u64,
    /// The peers to run in the same run.
    pub peers: &'a [Peer],
    /// The CasADi peer's script (default: the crate's `benches/peers/casadi_vertex.py`).
    pub peer_script: Option<&'a Path>,
}

/// Nanoseconds per evaluation, the fastest round of each row.
#[derive(Clone, Copy, Debug)]
pub struct VertexTimes {
    /// JIT, value only.
    pub jit_value_ns: f64,
    /// JIT, value and gradient.
    pub jit_value_grad_ns: f64,
    /// The DAG interpreter, value and gradient.
    pub interpreter_value_grad_ns: f64,
    /// The f64 kinematics, value only.
    pub f64_value_ns: f64,
    /// The f64 kinematics, value and central differences (1 + 2n evaluations).
    pub f64_central_diff_ns: f64,
    /// Dual numbers (forward mode).
    pub dual_ns: f64,
}

/// Largest relative deviations between the implementations at the point measured.
#[derive(Clone, Copy, Debug)]
pub struct VertexChecks {
    /// JIT value against the f64 kinematics and the interpreter.
    pub max_dev_value: f64,
    /// JIT gradient against dual numbers.
    pub max_dev_dual: f64,
    /// JIT gradient against central differences.
    pub max_dev_fd: f64,
}

/// The CasADi peer's figures and how its numbers compare with ours.
pub struct CasadiFigures {
    /// The peer's JSON (its times, compile timings, value and gradient), or why it was
    /// skipped (`"skipped"`).
    pub info: serde_json::Value,
    /// Largest relative deviation of its value and gradient from ours (NaN where it gives
    /// NaN); `None` when it gave no numbers.
    pub dev: Option<f64>,
    /// What the peer gives as NaN (`value`, `grad[i]`).
    pub nans: Vec<String>,
}

/// The figures of one `bench vertex` run.
pub struct VertexBench {
    /// The vertex in the thesis's notation.
    pub vertex: String,
    /// Its degree.
    pub degree: usize,
    /// Whether the gradient is with respect to the sector angles.
    pub symbolic_sectors: bool,
    /// Number of variables of the gradient.
    pub n_vars: usize,
    /// The driving parameter.
    pub t: f64,
    /// φ1+φ2+φ3 by the JIT.
    pub value: f64,
    /// Whether the vertex is rigid at `t`.
    pub rigid_at_t: bool,
    /// The times.
    pub times: VertexTimes,
    /// Milliseconds to build the graph (median of several builds).
    pub build_ms: f64,
    /// Build plus simplify, differentiate, JIT (medians).
    pub compile_ms: f64,
    /// The compiler's report of value+gradient.
    pub report: CompileReport,
    /// libm calls in the native code of the value only.
    pub native_calls_value: usize,
    /// libm calls in the native code of value+gradient.
    pub native_calls_value_grad: usize,
    /// The implementations against each other.
    pub checks: VertexChecks,
    /// The CasADi peer, when asked for.
    pub casadi: Option<CasadiFigures>,
    /// The Symbolica peer, when asked for.
    pub symbolica: Option<SymbolicaPeer>,
}

/// The vertex's graph and its two compiles, with the compile latency.
struct CompiledVertex {
    model: VertexModel,
    graph: ExprGraph,
    out: [NodeId; 1],
    compiled: Compiled,
    value_only: Compiled,
    build_ms: f64,
    pipeline_ms: f64,
}

impl CompiledVertex {
    /// Compile latency, stage by stage (median of several runs; the first warms caches).
    fn new(spec: &VertexSpec, sym: bool) -> Result<CompiledVertex> {
        let reps = 7;
        let (build_ms, model) = time_ms(reps, || VertexModel::build(spec, sym));
        let graph = model.ctx.to_graph();
        let out = [model.phi_sum_id()];
        let opts = Options::default();
        let (pipeline_ms, compiled) = time_ms(reps, || {
            compile(&graph, &out, model.n_vars, model.n_params, &opts)
        });
        let compiled = compiled?;
        let value_only = compile(
            &graph,
            &out,
            model.n_vars,
            model.n_params,
            &Options {
                gradients: false,
                ..Options::default()
            },
        )?;
        Ok(CompiledVertex {
            model,
            graph,
            out,
            compiled,
            value_only,
            build_ms,
            pipeline_ms,
        })
    }
}

/// The point, the implementations and their buffers: what every timing row runs.
struct Rows<'a> {
    spec: &'a VertexSpec,
    sym: bool,
    vars: &'a [f64],
    params: &'a [f64],
    dparams: Vec<Dual>,
    c: &'a CompiledVertex,
    tape: Tape,
    buf: Vec<f64>,
    tbuf: Vec<f64>,
    vbuf: [f64; 1],
    scratch: Vec<f64>,
}

/// Central differences of φ1+φ2+φ3 at `v`.
fn central(spec: &VertexSpec, sym: bool, v: &[f64], params: &[f64]) -> Vec<f64> {
    let n = v.len();
    let mut g = vec![0.0; n];
    let mut x = v.to_vec();
    for i in 0..n {
        let xi = x[i];
        x[i] = xi + H;
        let fp = vertex::phi_sum(spec, sym, &x, params);
        x[i] = xi - H;
        let fm = vertex::phi_sum(spec, sym, &x, params);
        x[i] = xi;
        g[i] = (fp - fm) / (2.0 * H);
    }
    g
}

impl<'a> Rows<'a> {
    /// Evaluate every implementation once; their deviations from the JIT's numbers.
    fn new(
        spec: &'a VertexSpec,
        sym: bool,
        (vars, params): (&'a [f64], &'a [f64]),
        c: &'a CompiledVertex,
    ) -> Result<(Rows<'a>, VertexChecks)> {
        let n = vars.len();
        let mut buf = vec![0.0; c.compiled.layout.len()];
        c.compiled.function.call(vars, params, &mut buf)?;
        let tape = Tape::new(&c.compiled.graph, &c.compiled.outputs, n, params.len())?;
        let mut tbuf = vec![0.0; c.compiled.layout.len()];
        let mut scratch = Vec::new();
        tape.eval_with(&mut scratch, vars, params, &mut tbuf)?;
        let dvars: Vec<Dual> = (0..n).map(|i| Dual::var(vars[i], i, n)).collect();
        let dparams: Vec<Dual> = params.iter().map(|&p| Dual::constant(p)).collect();
        let dual = vertex::phi_sum(spec, sym, &dvars, &dparams);
        let f64_value = vertex::phi_sum(spec, sym, vars, params);
        let fd = central(spec, sym, vars, params);
        let grad = &buf[c.compiled.layout.gradient(0)];
        let checks = VertexChecks {
            max_dev_value: rel(buf[0], f64_value).max(rel(buf[0], tbuf[0])),
            max_dev_dual: max_or_nan(
                (0..n).map(|i| rel(grad[i], dual.g.get(i).copied().unwrap_or(0.0))),
            ),
            max_dev_fd: max_or_nan((0..n).map(|i| rel(grad[i], fd[i]))),
        };
        let rows = Rows {
            spec,
            sym,
            vars,
            params,
            dparams,
            c,
            tape,
            buf,
            tbuf,
            vbuf: [0.0],
            scratch,
        };
        Ok((rows, checks))
    }

    /// One round: every row measured for `slice`, pushed onto `times`.
    fn round(&mut self, slice: Duration, times: &mut [Vec<f64>; 6]) {
        let (spec, sym, vars, params) = (self.spec, self.sym, self.vars, self.params);
        let n = vars.len();
        let c = self.c;
        let vbuf = &mut self.vbuf;
        times[0].push(time_ns(slice, || {
            c.value_only
                .function
                .call(black_box(vars), black_box(params), vbuf)
                .expect("lengths checked above");
            black_box(&*vbuf);
        }));
        let buf = &mut self.buf;
        times[1].push(time_ns(slice, || {
            c.compiled
                .function
                .call(black_box(vars), black_box(params), buf)
                .expect("lengths checked above");
            black_box(&*buf);
        }));
        let (tape, scratch, tbuf) = (&self.tape, &mut self.scratch, &mut self.tbuf);
        times[2].push(time_ns(slice, || {
            tape.eval_with(scratch, black_box(vars), black_box(params), tbuf)
                .expect("lengths checked above");
            black_box(&*tbuf);
        }));
        times[3].push(time_ns(slice, || {
            black_box(vertex::phi_sum(
                spec,
                sym,
                black_box(vars),
                black_box(params),
            ));
        }));
        times[4].push(time_ns(slice, || {
            black_box(vertex::phi_sum(
                spec,
                sym,
                black_box(vars),
                black_box(params),
            ));
            black_box(central(spec, sym, black_box(vars), params));
        }));
        let dparams = &self.dparams;
        times[5].push(time_ns(slice, || {
            let dv: Vec<Dual> = (0..n).map(|i| Dual::var(vars[i], i, n)).collect();
            black_box(vertex::phi_sum(
                spec,
                sym,
                black_box(&dv),
                black_box(dparams),
            ));
        }));
    }
}

/// The peers asked for, set up before the timings.
struct Peers {
    casadi: Option<CasadiPeer>,
    symbolica: Option<SymbolicaPeer>,
}

impl Peers {
    fn new(
        opts: &VertexBenchOptions<'_>,
        c: &CompiledVertex,
        (vars, params): (&[f64], &[f64]),
        ours: &[f64],
    ) -> Result<Peers> {
        let casadi = if opts.peers.contains(&Peer::Casadi) {
            Some(CasadiPeer::new(&CasadiJob {
                script: opts.peer_script,
                spec: opts.spec,
                symbolic_sectors: opts.symbolic_sectors,
                t: opts.t,
                millis: (opts.millis / u64::from(ROUNDS)).max(10),
            })?)
        } else {
            None
        };
        let symbolica = if opts.peers.contains(&Peer::Symbolica) {
            let job = PeerJob {
                graph: c.graph.clone(),
                outputs: vec![("phi_sum".to_string(), c.out[0])],
                names: c.model.names.clone(),
                n_vars: c.model.n_vars,
                n_params: c.model.n_params,
            };
            let inputs: Vec<f64> = vars.iter().chain(params).copied().collect();
            Some(SymbolicaPeer::new(job, inputs, ours, 3)?)
        } else {
            None
        };
        Ok(Peers { casadi, symbolica })
    }
}

/// CasADi's value and gradient against ours (the same function at the same point).
/// `null` is the harness's NaN (JSON has none): CasADi's gradient is NaN outside the
/// rigid interval, where ours is guarded (sqrt at 0). NaN stays NaN in the maximum.
fn casadi_figures(info: serde_json::Value, value: f64, grad: &[f64]) -> CasadiFigures {
    let mut nans = Vec::new();
    if info.get("value").is_some_and(|v| v.is_null()) {
        nans.push("value".to_string());
    }
    if let Some(g) = info.get("grad").and_then(|g| g.as_array()) {
        nans.extend(
            g.iter()
                .enumerate()
                .filter(|(_, x)| x.is_null())
                .map(|(i, _)| format!("grad[{i}]")),
        );
    }
    let dev = (|| {
        let v = info.get("value")?;
        let g = info.get("grad")?.as_array()?;
        let num = |x: &serde_json::Value| x.as_f64().unwrap_or(f64::NAN);
        Some(max_or_nan(std::iter::once(rel(num(v), value)).chain(
            g.iter().enumerate().map(|(i, gi)| rel(num(gi), grad[i])),
        )))
    })();
    CasadiFigures { info, dev, nans }
}

/// Measure `bench vertex`.
pub fn measure(opts: &VertexBenchOptions<'_>) -> Result<VertexBench> {
    let (spec, sym, t) = (opts.spec, opts.symbolic_sectors, opts.t);
    let (vars, params) = vertex::point(spec, sym, t);
    let budget = Duration::from_millis(opts.millis.max(10));
    let c = CompiledVertex::new(spec, sym)?;
    let (mut rows, checks) = Rows::new(spec, sym, (&vars, &params), &c)?;
    let grad: Vec<f64> = rows.buf[c.compiled.layout.gradient(0)].to_vec();
    let value = rows.buf[0];

    // Timings. Every row is measured in each of several rounds (the peer's harness too)
    // and the fastest round is reported: interference from other processes only ever
    // adds time, so the minimum is the most repeatable estimate on a busy machine, and
    // all rows are treated alike.
    let mut peers = Peers::new(opts, &c, (&vars, &params), &rows.buf)?;
    let slice = budget / ROUNDS;
    let mut times: [Vec<f64>; 6] = Default::default();
    for _ in 0..ROUNDS {
        rows.round(slice, &mut times);
        if let Some(s) = &mut peers.symbolica {
            s.round(slice)?;
        }
        if let Some(p) = &mut peers.casadi {
            p.round();
        }
    }
    let times = VertexTimes {
        jit_value_ns: fastest(&times[0]),
        jit_value_grad_ns: fastest(&times[1]),
        interpreter_value_grad_ns: fastest(&times[2]),
        f64_value_ns: fastest(&times[3]),
        f64_central_diff_ns: fastest(&times[4]),
        dual_ns: fastest(&times[5]),
    };
    let casadi = match peers.casadi {
        Some(p) => Some(casadi_figures(p.finish(ROUNDS)?, value, &grad)),
        None => None,
    };
    Ok(VertexBench {
        vertex: spec.to_string(),
        degree: spec.degree(),
        symbolic_sectors: sym,
        n_vars: vars.len(),
        t,
        value,
        rigid_at_t: foldability::min_margin(spec, t) >= -RIGID_TOL,
        times,
        build_ms: c.build_ms,
        compile_ms: c.build_ms + c.pipeline_ms,
        report: c.compiled.report.clone(),
        native_calls_value: c.value_only.function.n_calls(),
        native_calls_value_grad: c.compiled.function.n_calls(),
        checks,
        casadi,
        symbolica: peers.symbolica,
    })
}

impl VertexBench {
    /// The JIT's cost of value+gradient over the value alone.
    pub fn grad_value_ratio(&self) -> f64 {
        self.times.jit_value_grad_ns / self.times.jit_value_ns
    }

    /// The figures as one JSON object (times in nanoseconds, compile times in
    /// milliseconds).
    pub fn json(&self) -> serde_json::Value {
        let (tm, rep) = (&self.times, &self.report);
        let mut o = json!({
            "vertex": self.vertex,
            "degree": self.degree,
            "symbolic_sectors": self.symbolic_sectors,
            "n_vars": self.n_vars,
            "t": self.t,
            "jit_value_ns": tm.jit_value_ns,
            "jit_value_grad_ns": tm.jit_value_grad_ns,
            "interpreter_value_grad_ns": tm.interpreter_value_grad_ns,
            "f64_value_ns": tm.f64_value_ns,
            "f64_central_diff_ns": tm.f64_central_diff_ns,
            "dual_ns": tm.dual_ns,
            "jit_grad_value_ratio": self.grad_value_ratio(),
            "compile_ms": self.compile_ms,
            "build_ms": self.build_ms,
            "simplify_ms": rep.simplify_ms,
            "diff_ms": rep.diff_ms,
            "jit_ms": rep.jit_ms,
            "ops_before": rep.input.ops,
            "ops_after": rep.simplified.ops,
            "ops_gradient": rep.with_gradients.ops,
            "calls_before": rep.input.calls,
            "calls_after": rep.simplified.calls,
            "native_calls_value": self.native_calls_value,
            "native_calls_value_grad": self.native_calls_value_grad,
            "simplify": rep.simplify,
            "max_rel_dev_value": self.checks.max_dev_value,
            "max_rel_dev_grad_vs_dual": self.checks.max_dev_dual,
            "max_rel_dev_grad_vs_central_diff": self.checks.max_dev_fd,
        });
        if let Some(p) = &self.casadi {
            o["peer"] = p.info.clone();
            if let Some(ns) = p.info.get("value_grad_ns").and_then(|v| v.as_f64()) {
                o["peer_value_grad_ratio"] = json!(tm.jit_value_grad_ns / ns);
            }
            if let Some(ms) = p.info.get("total_compile_ms").and_then(|v| v.as_f64()) {
                o["peer_compile_ratio"] = json!(self.compile_ms / ms);
            }
            o["peer_max_rel_dev"] = json!(p.dev.filter(|d| d.is_finite()));
            o["peer_nan"] = json!(p.nans);
            o["rigid_at_t"] = json!(self.rigid_at_t);
        }
        if let Some(s) = &self.symbolica {
            o["symbolica"] = s.json();
            o["symbolica_value_grad_ratio"] = json!(tm.jit_value_grad_ns / s.value_grad_ns());
            o["symbolica_compile_ratio"] = json!(self.compile_ms / s.compile_ms());
        }
        o
    }
}
