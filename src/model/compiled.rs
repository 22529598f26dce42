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
    /// Number of auxiliary outputs after the constraints ([`super::Outputs::aux`]: 3 per
    /// surface target), whose values and gradient rows [`ModelProblem::eval`] turns into
    /// the surface terms.
    pub n_aux: usize,
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
/// constants they are drawn at; parameters are the modes, then `model.times`. Outputs: the
/// objective, the constraints, then the auxiliary outputs (surface targets' positions).
pub fn symbolic(model: &Model) -> (Ctx, Vec<Sym>) {
    let ctx = Ctx::new();
    let free: Vec<Sym> = (0..model.free.len()).map(|k| ctx.var(k)).collect();
    let vars = model.full_vars(&free);
    let n = model.plan.n_modes;
    let modes: Vec<Sym> = (0..n).map(|i| ctx.param(i)).collect();
    let times: Vec<Sym> = (0..model.times.len()).map(|i| ctx.param(n + i)).collect();
    let out = model.outputs(&vars, &modes, &times);
    let mut outputs = vec![out.objective];
    outputs.extend(out.constraints);
    outputs.extend(out.aux);
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
        let n_params = model.plan.n_modes + model.times.len();
        let compiled = compile::compile(&graph, &ids, model.free.len(), n_params, opts)?;
        let n_modes = model.plan.n_modes;
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
            n_constraints: ids.len() - 1 - model.surface_aux_len(),
            n_aux: model.surface_aux_len(),
            n_modes: model.plan.n_modes,
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

    /// Add the surface targets' terms to an unpacked evaluation: their values from the
    /// auxiliary outputs in `buf`, their gradients by the chain rule through the aux
    /// outputs' gradient rows; into the objective, or subtracted from the constraint
    /// [`Model::surface_destination`] names.
    pub fn add_surfaces(&self, model: &Model, buf: &[f64], e: &mut Evaluation) {
        if self.n_aux == 0 {
            return;
        }
        let l = &self.compiled.layout;
        let base = 1 + self.n_constraints;
        let aux = &buf[l.value(base)..l.value(base) + self.n_aux];
        let dest = model.surface_destination();
        for (j, (v, dx)) in model.surface_terms(aux).into_iter().enumerate() {
            match dest {
                None => e.f += v,
                Some(k) => e.g[k] -= v,
            }
            if !l.gradients {
                continue;
            }
            for (i, dxi) in dx.iter().enumerate() {
                let row = &buf[l.gradient(base + 3 * j + i)];
                let target = match dest {
                    None => &mut e.df[..],
                    Some(k) => &mut e.dg[k * self.n_vars..(k + 1) * self.n_vars],
                };
                let sign = if dest.is_none() { 1.0 } else { -1.0 };
                for (t, r) in target.iter_mut().zip(row) {
                    *t += sign * dxi * r;
                }
            }
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
        let modes: Vec<Sym> = (0..model.plan.n_modes).map(|i| ctx.param(nf + i)).collect();
        let flat = geometry::flat(&model.plan, &vars);
        let folded = geometry::fold(&model.plan, &flat, &modes, &t);
        let n_vertices = model.plan.vertices.len();
        let ids: Vec<_> = (0..n_vertices)
            .flat_map(|v| geometry::position(&model.plan, &flat, &folded, v))
            .map(|c| ctx.node_id(&c))
            .collect();
        let graph = ctx.to_graph();
        let n_params = nf + model.plan.n_modes;
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
        self.compiled.add_surfaces(self.model, &buf, out);
    }
}

/// The value of the compiled objective at or below which a feasible point meets the
/// target: what the search gives the optimizer as [`crate::optimize::Options::target`].
/// Without an area term: `w² (threshold / w)²` for one target (the compiled objective is
/// `w² d²`), `threshold` for several (`Σ w √(d² + ε²)`). With an area term: `+∞`, because
/// the target is written as constraints (`threshold − Ω ≥ 0` when there are targets, and
/// `A − at_least ≥ 0`), so every feasible point meets it, and the optimizer runs every
/// start ([`crate::optimize::Options::all_starts`], see [`all_starts`]) keeping the least
/// `−weight·A`.
pub fn objective_target(model: &Model) -> f64 {
    if model.area.is_some() {
        return f64::INFINITY;
    }
    if model.targets.len() == 1 {
        let w = model.targets[0].weight;
        (model.threshold / w).powi(2) * w * w
    } else {
        model.threshold
    }
}

/// Whether the optimizer should run every start for `model` (it has an area term: no
/// natural zero, so the first start meeting the target is no reason to stop).
pub fn all_starts(model: &Model) -> bool {
    model.area.is_some()
}

/// How many times a search's `--starts` an area model runs: it has no target to stop
/// at and many local optima (on `grammar/cuboid_area.toml` 16 starts found a best area of
/// 5.4, 48 starts 19.7), so it gets the effort that three gripping candidates of one
/// graph spent before an area task stopped writing three identical problems.
pub const AREA_STARTS_FACTOR: usize = 3;

/// The starts a search runs on `model` when the user asked for `starts` per alternative.
pub fn search_starts(model: &Model, starts: usize) -> usize {
    if all_starts(model) {
        starts * AREA_STARTS_FACTOR
    } else {
        starts
    }
}

/// The record's `meets_target`: the optimized point is feasible (every constraint of the
/// model holds within the optimizer's feasibility tolerance — with an area term these
/// include `threshold − Ω_smooth ≥ 0` and `A − at_least ≥ 0`) and the reported Ω
/// ([`Model::omega`], `Σ w d` over the targets, 0 without targets) is at most the
/// threshold. With an area term the second condition follows from the first up to the
/// smoothing (Ω ≤ Ω_smooth); it is what the search decided before issue 31, unchanged.
pub fn meets_target(model: &Model, feasible: bool, omega: f64) -> bool {
    feasible && omega <= model.threshold
}

/// f64 evaluation of the same outputs (the plain kinematics, no symbols): the objective
/// and the constraints, surface terms included (as [`ModelProblem::eval`] adds them).
pub fn outputs_f64(model: &Model, free: &[f64], modes: &[f64]) -> (f64, Vec<f64>) {
    let vars = model.full_vars(free);
    let times: Vec<f64> = model.times.clone();
    let out = model.outputs(&vars, modes, &times);
    let (mut f, mut g) = (out.objective, out.constraints);
    let dest = model.surface_destination();
    for (v, _) in model.surface_terms(&out.aux) {
        match dest {
            None => f += v,
            Some(k) => g[k] -= v,
        }
    }
    (f, g)
}
