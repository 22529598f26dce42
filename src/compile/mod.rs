//! The compiler: egg simplification, reverse-mode differentiation, Cranelift JIT.
//!
//! A *model* is a set of outputs (objective, constraints, …) over variables and
//! parameters in an [`ExprGraph`]. [`compile`] simplifies it, appends the gradient of
//! every output with respect to all variables, and JIT-compiles values and gradients into
//! one native call:
//!
//! ```
//! use foldsynth::compile::{Options, compile};
//! use foldsynth::expr::Ctx;
//! use foldsynth::kinematics::Scalar;
//!
//! let ctx = Ctx::new();
//! let (x, t) = (ctx.var(0), ctx.param(0));
//! let f = (x.clone() * t).sin() + x.cos();
//! let out = [ctx.node_id(&f)];
//! let c = compile(&ctx.to_graph(), &out, 1, 1, &Options::default()).unwrap();
//! let mut buf = vec![0.0; c.layout.len()];
//! c.function.call(&[0.5], &[2.0], &mut buf).unwrap();
//! assert!((buf[c.layout.value(0)] - (1.0f64.sin() + 0.5f64.cos())).abs() < 1e-15);
//! let d = 2.0 * 1.0f64.cos() - 0.5f64.sin();
//! assert!((buf[c.layout.gradient(0).start] - d).abs() < 1e-15);
//! ```
//!
//! Stages: [`simplify`] (egg), [`diff`] (reverse mode) and [`mod@jacobian`] (reverse sweeps
//! or vertex elimination; both take their local partials from `partials`), [`codegen`] (the
//! Cranelift function builder) behind [`jit`] (in process) and [`aot`] (object, shared
//! library, C header); [`dual`] is the forward-mode oracle the tests hold the differentiator
//! to; [`vertex`] builds the symbolic PTU of one vertex (for `foldsynth formulas` and
//! `foldsynth bench vertex`).
//! With the cargo feature `symbolica`, `symbolica` is the second pipeline and printer
//! built on Symbolica (on its own thread).

pub mod aot;
pub mod codegen;
pub mod diff;
pub mod dual;
pub mod jacobian;
pub mod jit;
mod partials;
pub mod simplify;
#[cfg(feature = "symbolica")]
pub mod symbolica;
pub mod tape;
pub mod vanish;
pub mod vertex;

pub use codegen::{CompileError, Math, OptLevel};
pub use diff::{gradient, gradients};
pub use dual::Dual;
pub use jacobian::{Jacobian, jacobian};
pub use jit::CompiledFn;

use crate::cpu_time::Stopwatch;
use crate::expr::{Counts, ExprGraph, NodeId, check_indices};

/// What [`compile`] does.
#[derive(Clone, Debug)]
pub struct Options {
    /// Simplify with egg first (`None`: only the construction-time folding).
    pub simplify: Option<simplify::Limits>,
    /// Append the gradient of every output with respect to all variables.
    pub gradients: bool,
    /// How those gradients are computed.
    pub jacobian: Jacobian,
    /// Cranelift's optimization level.
    pub opt_level: OptLevel,
    /// How the generated code computes `sin`, `cos`, `atan2` and `acos` (the same bits
    /// either way).
    pub math: Math,
    /// Fuse a product into the sum or difference that is its only use (one `fma`, one
    /// rounding) in the gradients, where this CPU has FMA. The values keep the
    /// interpreter's bits; the gradients are as accurate or more, and differ from the
    /// interpreter's in the last bits. Gradients are mostly sums of products: on the
    /// gripper's design model about 250 of their 1,200 operations fuse.
    pub fma: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            simplify: Some(simplify::Limits::default()),
            gradients: true,
            jacobian: Jacobian::default(),
            opt_level: OptLevel::Auto,
            math: Math::default(),
            fma: true,
        }
    }
}

/// Where things are in the output buffer of a compiled model: the values of the
/// outputs first, then (with gradients) `n_vars` partial derivatives per output.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Number of model outputs.
    pub n_outputs: usize,
    /// Number of variables.
    pub n_vars: usize,
    /// Whether gradients follow the values.
    pub gradients: bool,
}

impl Layout {
    /// Length of the output buffer.
    pub fn len(&self) -> usize {
        self.n_outputs * if self.gradients { 1 + self.n_vars } else { 1 }
    }
    /// Whether the buffer is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Index of the value of output `i`.
    pub fn value(&self, i: usize) -> usize {
        i
    }
    /// Indices of the gradient of output `i` (empty without gradients).
    pub fn gradient(&self, i: usize) -> std::ops::Range<usize> {
        if self.gradients {
            let s = self.n_outputs + i * self.n_vars;
            s..s + self.n_vars
        } else {
            0..0
        }
    }
}

/// Sizes and times of the compiler stages.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CompileReport {
    /// Counts of the model outputs as given.
    pub input: Counts,
    /// Counts after simplification (equal to `input` without it).
    pub simplified: Counts,
    /// Counts of values and gradients together (what is compiled).
    pub with_gradients: Counts,
    /// The simplifier's own report.
    pub simplify: Option<simplify::Report>,
    /// Milliseconds in simplification (CPU time of the compiling thread, as the others).
    pub simplify_ms: f64,
    /// Milliseconds in differentiation.
    pub diff_ms: f64,
    /// Milliseconds in code generation.
    pub jit_ms: f64,
}

/// A compiled model.
#[derive(Debug)]
pub struct Compiled {
    /// The native function.
    pub function: CompiledFn,
    /// Where values and gradients are in its output buffer.
    pub layout: Layout,
    /// The graph that was compiled.
    pub graph: ExprGraph,
    /// The compiled nodes, in the order of the output buffer.
    pub outputs: Vec<NodeId>,
    /// Sizes and times.
    pub report: CompileReport,
}

/// Simplify, differentiate and compile `outputs` over `n_vars` variables and `n_params`
/// parameters (see the module example).
pub fn compile(
    graph: &ExprGraph,
    outputs: &[NodeId],
    n_vars: usize,
    n_params: usize,
    opts: &Options,
) -> Result<Compiled, CompileError> {
    check_indices(graph, outputs, n_vars, n_params)?;
    let input = graph.counts(outputs);
    let t0 = Stopwatch::start();
    let (mut g, outs, srep) = match &opts.simplify {
        Some(limits) => {
            let (g, o, r) = simplify::simplify(graph, outputs, limits);
            (g, o, Some(r))
        }
        None => {
            let (g, o) = graph.extract(outputs);
            (g, o, None)
        }
    };
    let simplify_ms = t0.cpu_ms();
    let simplified = g.counts(&outs);
    let t1 = Stopwatch::start();
    // Nodes from here on are the gradients' (differentiation appends).
    let fma_from = if opts.fma { g.len() } else { usize::MAX };
    let mut all = outs.clone();
    if opts.gradients {
        for grad in jacobian(&mut g, &outs, n_vars, opts.jacobian)? {
            all.extend(grad);
        }
    }
    let diff_ms = t1.cpu_ms();
    let with_gradients = g.counts(&all);
    let t2 = Stopwatch::start();
    let function = CompiledFn::with_fma_from(
        &g,
        &all,
        n_vars,
        n_params,
        opts.opt_level,
        opts.math,
        fma_from,
    )?;
    let jit_ms = t2.cpu_ms();
    Ok(Compiled {
        function,
        layout: Layout {
            n_outputs: outputs.len(),
            n_vars,
            gradients: opts.gradients,
        },
        graph: g,
        outputs: all,
        report: CompileReport {
            input,
            simplified,
            with_gradients,
            simplify: srep,
            simplify_ms,
            diff_ms,
            jit_ms,
        },
    })
}
