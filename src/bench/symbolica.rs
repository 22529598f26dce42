//! The Symbolica peer of `foldsynth bench vertex|model --peer symbolica`: Symbolica's
//! pipeline (canonical form → its derivatives → its optimized evaluator → SymJIT) built
//! from the same expression graph as ours, timed in rounds in the same run, its values
//! and gradients checked against ours. Everything Symbolica runs on its own thread
//! (`compile::symbolica`); the timing loops run there too.

use super::fastest;
#[cfg(feature = "symbolica")]
use super::{rel, time_ns};
#[cfg(feature = "symbolica")]
use crate::compile::symbolica::{BuildReport, Job, Peer};
use crate::expr::{ExprGraph, Names, NodeId};
use anyhow::Result;
use serde_json::json;
use std::time::Duration;

/// What a benchmark hands the peer: named outputs of our graph as built.
pub struct PeerJob {
    /// The graph.
    pub graph: ExprGraph,
    /// The outputs, named.
    pub outputs: Vec<(String, NodeId)>,
    /// Variable and parameter names.
    pub names: Names,
    /// Number of variables.
    pub n_vars: usize,
    /// Number of parameters.
    pub n_params: usize,
}

/// The Symbolica peer: built once, timed round by round.
pub struct SymbolicaPeer {
    #[cfg(feature = "symbolica")]
    peer: Peer,
    #[cfg(feature = "symbolica")]
    report: BuildReport,
    #[cfg(feature = "symbolica")]
    inputs: Vec<f64>,
    compile_ms: f64,
    max_rel_dev: f64,
    /// Deviations from ours: JIT values (both JITs), JIT gradients, evaluator values,
    /// evaluator gradients.
    devs: [f64; 4],
    value_ns: Vec<f64>,
    value_grad_ns: Vec<f64>,
    interpreted_ns: Vec<f64>,
}

/// The error of every Symbolica option in a build without the feature.
pub const NO_SYMBOLICA: &str = "this foldsynth was built without Symbolica; rebuild with `cargo build --release --features symbolica`";

impl SymbolicaPeer {
    /// Build Symbolica's pipeline for `job` (`reps` times, the median build time is the
    /// compile latency) and compare its values and gradients at `inputs` (variables, then
    /// parameters) with `ours` (our output buffer: values, then gradients).
    #[cfg(feature = "symbolica")]
    pub fn new(job: PeerJob, inputs: Vec<f64>, ours: &[f64], reps: usize) -> Result<SymbolicaPeer> {
        let job = Job {
            graph: job.graph,
            outputs: job.outputs,
            names: job.names,
            n_vars: job.n_vars,
            n_params: job.n_params,
        };
        let mut times = Vec::new();
        let mut built = None;
        for _ in 0..reps.max(1) {
            let p = Peer::build(job.clone())?;
            times.push(p.report.total_ms);
            built = Some(p);
        }
        times.sort_by(f64::total_cmp);
        let peer = built.ok_or_else(|| anyhow::anyhow!("no build"))?;
        let dev = |theirs: &[f64], range: std::ops::Range<usize>| {
            theirs[range.clone()]
                .iter()
                .zip(&ours[range])
                .map(|(a, b)| rel(*a, *b))
                .fold(0.0, f64::max)
        };
        let n_values = peer.n_outputs;
        let jit = peer.eval(&inputs)?;
        let jit_values = peer.eval_values(&inputs)?;
        let interpreted = peer.eval_interpreted(&inputs)?;
        let devs = [
            // Both JITs' values: value+gradient's and value-only's.
            dev(&jit, 0..n_values).max(dev(&jit_values, 0..n_values)),
            dev(&jit, n_values..ours.len()),
            dev(&interpreted, 0..n_values),
            dev(&interpreted, n_values..ours.len()),
        ];
        let max_rel_dev = devs.iter().copied().fold(0.0, f64::max);
        Ok(SymbolicaPeer {
            report: peer.report.clone(),
            peer,
            inputs,
            compile_ms: times[times.len() / 2],
            max_rel_dev,
            devs,
            value_ns: Vec::new(),
            value_grad_ns: Vec::new(),
            interpreted_ns: Vec::new(),
        })
    }

    /// Without the `symbolica` feature there is no peer.
    #[cfg(not(feature = "symbolica"))]
    pub fn new(_: PeerJob, _: Vec<f64>, _: &[f64], _: usize) -> Result<SymbolicaPeer> {
        anyhow::bail!("--peer symbolica: {}", NO_SYMBOLICA)
    }

    /// One round of timings (`slice` per row), on the Symbolica thread.
    #[cfg(feature = "symbolica")]
    pub fn round(&mut self, slice: Duration) -> Result<()> {
        use std::hint::black_box;
        let x = self.inputs.clone();
        let (nv, nvg) = (
            self.peer.n_outputs,
            self.peer.n_outputs * (1 + self.peer.n_vars),
        );
        let (v, vg, it) = self.peer.with(move |e| {
            let mut out = vec![0.0; nv];
            let v = time_ns(slice, || {
                e.value(black_box(&x), &mut out);
                black_box(&out);
            });
            let mut out = vec![0.0; nvg];
            let vg = time_ns(slice, || {
                e.value_grad(black_box(&x), &mut out);
                black_box(&out);
            });
            let it = time_ns(slice, || {
                e.value_grad_interpreted(black_box(&x), &mut out);
                black_box(&out);
            });
            (v, vg, it)
        })?;
        self.value_ns.push(v);
        self.value_grad_ns.push(vg);
        self.interpreted_ns.push(it);
        Ok(())
    }

    /// Without the feature: unreachable, [`SymbolicaPeer::new`] fails first.
    #[cfg(not(feature = "symbolica"))]
    pub fn round(&mut self, _: Duration) -> Result<()> {
        anyhow::bail!("--peer symbolica: {}", NO_SYMBOLICA)
    }

    /// Fastest value+gradient time over the rounds (JIT), ns.
    pub fn value_grad_ns(&self) -> f64 {
        fastest(&self.value_grad_ns)
    }

    /// Fastest value-only time (JIT), ns.
    pub fn value_ns(&self) -> f64 {
        fastest(&self.value_ns)
    }

    /// Median build time, graph to native value+gradient code, ms.
    pub fn compile_ms(&self) -> f64 {
        self.compile_ms
    }

    /// Largest relative deviation of Symbolica's values and gradients from ours.
    pub fn max_rel_dev(&self) -> f64 {
        self.max_rel_dev
    }

    /// The figures as JSON (times in ns, builds in ms).
    pub fn json(&self) -> serde_json::Value {
        #[allow(unused_mut)]
        let mut o = json!({
            "jit_value_ns": self.value_ns(),
            "jit_value_grad_ns": self.value_grad_ns(),
            "evaluator_value_grad_ns": fastest(&self.interpreted_ns),
            "compile_ms": self.compile_ms,
            "max_rel_dev": self.max_rel_dev,
            "max_rel_dev_jit_value": self.devs[0],
            "max_rel_dev_jit_grad": self.devs[1],
            "max_rel_dev_evaluator_value": self.devs[2],
            "max_rel_dev_evaluator_grad": self.devs[3],
            "agrees_1e-12": self.max_rel_dev <= 1e-12,
            "rounds": self.value_grad_ns.len(),
        });
        #[cfg(feature = "symbolica")]
        {
            o["build"] = json!(self.report);
            o["version"] = json!(::symbolica::license::LicenseManager::get_version());
        }
        o
    }

    /// Lines for the text report: `ours_vg_ns` and `ours_compile_ms` are our JIT's
    /// value+gradient time and compile latency.
    pub fn lines(&self, ours_vg_ns: f64, ours_compile_ms: f64) -> Vec<String> {
        let vg = self.value_grad_ns();
        #[allow(unused_mut)]
        let mut l = vec![
            format!(
                "Symbolica (peer): value {:.1} ns, value+gradient {vg:.1} ns by SymJIT ({:.2}x our JIT), {:.1} ns by its evaluator without JIT",
                self.value_ns(),
                vg / ours_vg_ns,
                fastest(&self.interpreted_ns)
            ),
            format!(
                "Symbolica compile: {:.2} ms, graph to native value+gradient code (ours is {:.3} of it)",
                self.compile_ms,
                ours_compile_ms / self.compile_ms
            ),
        ];
        #[cfg(feature = "symbolica")]
        {
            let r = &self.report;
            l.push(format!(
                "  convert {:.2} + differentiate {:.2} + optimize {:.2} + SymJIT {:.2} ms; {} aliases, {} derivative aliases",
                r.convert_ms, r.diff_ms, r.optimize_ms, r.jit_ms, r.aliases, r.derivative_aliases
            ));
            l.push(format!(
                "  Symbolica operations, value+gradient: {} before, {} after its optimization; value only {}",
                r.ops_before.total(),
                r.ops_after.total(),
                r.ops_value.total()
            ));
        }
        l.push(format!(
            "Symbolica's values and gradients vs ours: {:.1e} (SymJIT values {:.1e}, gradients {:.1e}; evaluator values {:.1e}, gradients {:.1e}) ({})",
            self.max_rel_dev,
            self.devs[0],
            self.devs[1],
            self.devs[2],
            self.devs[3],
            if self.max_rel_dev <= 1e-12 {
                "agree to 1e-12"
            } else {
                "DO NOT agree to 1e-12"
            }
        ));
        l
    }
}
