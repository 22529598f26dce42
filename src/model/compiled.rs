//! A model compiled to native code: objective, constraints and all their gradients with
//! respect to the free variables in one call, with the modes and the times as parameters
//! (one compiled function serves all 2^N mode assignments).

use super::{Model, geometry};
use crate::compile::{self, Compiled, Options};
use crate::cpu_time::Stopwatch;
use crate::expr::{Ctx, Node, Sym};
use crate::optimize::{Evaluation, Problem};
use std::cell::RefCell;

/// A compiled [`Model`].
#[derive(Debug)]
pub struct CompiledModel {
    /// The compiled function with its layout and report.
    pub compiled: Compiled,
    /// Number of free variables (the model's `free`).
    pub n_vars: usize,
    /// Number of constraints.
    pub n_constraints: usize,
    /// Number of internal vertices (mode parameters come first).
    pub n_modes: usize,
    /// Milliseconds to build the expression graph (CPU time of the compiling thread, as
    /// the compile report's stages).
    pub build_ms: f64,
    /// Milliseconds from the start of the build to native code (build, simplify,
    /// differentiate, compile; CPU time).
    pub total_ms: f64,
    /// Per internal vertex: whether its mode reaches any output. Modes that do not (a
    /// vertex outside the gripping vertex's chain that no constraint sees) leave the
    /// compiled function unchanged bit for bit, so the alternatives that differ only there
    /// are one optimization problem.
    pub modes_used: Vec<bool>,
}

/// The symbolic outputs of `model`: free variable `k` is `Var(k)`, the others are the
/// constants they are drawn at; parameters are the modes, then `model.times`.
pub fn symbolic(model: &Model) -> (Ctx, Vec<Sym>) {
    let ctx = Ctx::new();
    let free: Vec<Sym> = (0..model.free.len()).map(|k| ctx.var(k)).collect();
    let vars = model.full_vars(&free);
    let n = model.plan.internal.len();
    let modes: Vec<Sym> = (0..n).map(|i| ctx.param(i)).collect();
    let times: Vec<Sym> = (0..model.times.len()).map(|i| ctx.param(n + i)).collect();
    let out = model.outputs(&vars, &modes, &times);
    let mut outputs = vec![out.objective];
    outputs.extend(out.constraints);
    (ctx, outputs)
}

impl CompiledModel {
    /// Build, simplify, differentiate and compile `model`.
    pub fn new(model: &Model, opts: &Options) -> Result<CompiledModel, compile::CompileError> {
        let start = Stopwatch::start();
        let (ctx, outputs) = symbolic(model);
        let ids: Vec<_> = outputs.iter().map(|s| ctx.node_id(s)).collect();
        let graph = ctx.to_graph();
        let build_ms = start.cpu_ms();
        let n_params = model.plan.internal.len() + model.times.len();
        let compiled = compile::compile(&graph, &ids, model.free.len(), n_params, opts)?;
        let n_modes = model.plan.internal.len();
        let mut modes_used = vec![false; n_modes];
        let reachable = compiled.graph.reachable(&compiled.outputs);
        for (node, _) in compiled
            .graph
            .nodes()
            .iter()
            .zip(&reachable)
            .filter(|(_, r)| **r)
        {
            if let Node::Param(k) = node
                && let Some(used) = modes_used.get_mut(*k as usize)
            {
                *used = true;
            }
        }
        Ok(CompiledModel {
            modes_used,
            n_vars: model.free.len(),
            n_constraints: ids.len() - 1,
            n_modes: model.plan.internal.len(),
            compiled,
            build_ms,
            total_ms: start.cpu_ms(),
        })
    }

    /// The parameter vector for the given modes (±1) and the model's times.
    pub fn params(&self, model: &Model, modes: &[f64]) -> Vec<f64> {
        let mut p = modes.to_vec();
        p.extend_from_slice(&model.times);
        p
    }

    /// Evaluate into `out` (sized [`CompiledModel::buffer_len`]).
    pub fn call(&self, free: &[f64], params: &[f64], out: &mut [f64]) {
        self.compiled
            .function
            .call(free, params, out)
            .expect("buffer sizes match the compiled layout");
    }

    /// Length of the output buffer.
    pub fn buffer_len(&self) -> usize {
        self.compiled.layout.len()
    }

    /// Copy one evaluation from the output buffer into an optimizer [`Evaluation`].
    pub fn unpack(&self, buf: &[f64], e: &mut Evaluation) {
        let l = &self.compiled.layout;
        let m = self.n_constraints;
        e.f = buf[l.value(0)];
        e.g.copy_from_slice(&buf[l.value(1)..l.value(1) + m]);
        if l.gradients {
            e.df.copy_from_slice(&buf[l.gradient(0)]);
            // The constraints' gradients are consecutive rows: the Jacobian in one copy.
            let rows = l.gradient(1).start..l.gradient(1).start + m * self.n_vars;
            e.dg.copy_from_slice(&buf[rows]);
        }
    }
}

/// A design's motion compiled to native code: the position of every vertex at `t`. `t` is
/// the one variable; the free variables, then the modes, are parameters, so one compiled
/// function serves every design of the graph. No gradients: this is the PTU's forward
/// kinematics, the counterpart of one bar-and-hinge simulation step
/// (`foldsynth bench numeric`).
#[derive(Debug)]
pub struct CompiledMotion {
    /// The compiled function (outputs: x, y, z of vertex 0, then vertex 1, …).
    pub compiled: Compiled,
    /// Number of vertices.
    pub n_vertices: usize,
    /// Milliseconds from the start of the build to native code (CPU time).
    pub total_ms: f64,
}

impl CompiledMotion {
    /// Build, simplify and compile the motion of `model`'s graph.
    pub fn new(model: &Model, opts: &Options) -> Result<CompiledMotion, compile::CompileError> {
        let start = Stopwatch::start();
        let ctx = Ctx::new();
        let t = ctx.var(0);
        let nf = model.free.len();
        let free: Vec<Sym> = (0..nf).map(|k| ctx.param(k)).collect();
        let vars = model.full_vars(&free);
        let modes: Vec<Sym> = (0..model.plan.internal.len())
            .map(|i| ctx.param(nf + i))
            .collect();
        let flat = geometry::flat(&model.plan, &vars);
        let folded = geometry::fold(&model.plan, &flat, &modes, &t);
        let n_vertices = model.plan.vertices.len();
        let ids: Vec<_> = (0..n_vertices)
            .flat_map(|v| geometry::position(&model.plan, &flat, &folded, v))
            .map(|c| ctx.node_id(&c))
            .collect();
        let graph = ctx.to_graph();
        let n_params = nf + model.plan.internal.len();
        let opts = Options {
            gradients: false,
            ..opts.clone()
        };
        let compiled = compile::compile(&graph, &ids, 1, n_params, &opts)?;
        Ok(CompiledMotion {
            compiled,
            n_vertices,
            total_ms: start.cpu_ms(),
        })
    }

    /// The parameter vector of a design: its free variables, then its modes (±1).
    pub fn params(free: &[f64], modes: &[f64]) -> Vec<f64> {
        free.iter().chain(modes).copied().collect()
    }

    /// Every vertex's position at `t` into `out` (3 per vertex, sized
    /// [`CompiledMotion::buffer_len`]).
    pub fn positions(&self, t: f64, params: &[f64], out: &mut [f64]) {
        self.compiled
            .function
            .call(&[t], params, out)
            .expect("buffer sizes match the compiled layout");
    }

    /// Length of the output buffer.
    pub fn buffer_len(&self) -> usize {
        self.compiled.layout.len()
    }
}

/// A compiled model with its modes fixed: an optimization [`Problem`].
pub struct ModelProblem<'a> {
    model: &'a Model,
    compiled: &'a CompiledModel,
    params: Vec<f64>,
    buf: RefCell<Vec<f64>>,
}

impl<'a> ModelProblem<'a> {
    /// The problem of `model` with the given modes.
    pub fn new(model: &'a Model, compiled: &'a CompiledModel, modes: &[f64]) -> ModelProblem<'a> {
        ModelProblem {
            model,
            compiled,
            params: compiled.params(model, modes),
            buf: RefCell::new(vec![0.0; compiled.buffer_len()]),
        }
    }
}

impl Problem for ModelProblem<'_> {
    fn n_vars(&self) -> usize {
        self.compiled.n_vars
    }
    fn n_constraints(&self) -> usize {
        self.compiled.n_constraints
    }
    fn bounds(&self, i: usize) -> (f64, f64) {
        self.model.var_bounds(self.model.free[i])
    }
    fn eval(&self, x: &[f64], out: &mut Evaluation) {
        let mut buf = self.buf.borrow_mut();
        self.compiled.call(x, &self.params, &mut buf);
        self.compiled.unpack(&buf, out);
    }
}

/// The objective value that means "target met" for the compiled objective (squared
/// distance for one target, Eq. 38 otherwise).
pub fn objective_target(model: &Model) -> f64 {
    if model.targets.len() == 1 {
        let w = model.targets[0].weight;
        (model.threshold / w).powi(2) * w * w
    } else {
        model.threshold
    }
}

/// f64 evaluation of the same outputs (the plain kinematics, no symbols).
pub fn outputs_f64(model: &Model, free: &[f64], modes: &[f64]) -> (f64, Vec<f64>) {
    let vars = model.full_vars(free);
    let times: Vec<f64> = model.times.clone();
    let out = model.outputs(&vars, modes, &times);
    (out.objective, out.constraints)
}
