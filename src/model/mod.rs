//! The optimization model of one crease-pattern graph for a design task (thesis Sec.
//! 5.2.1.3–5.2.2.4, 5.4.1, 5.5.3).
//!
//! A [`Plan`] (built once per graph) says how every position, sector and dihedral angle
//! follows from the design variables; [`geometry`] evaluates it generically over
//! [`Scalar`]; [`Model`] adds the task: bounds, the objective at the target states, the
//! constraints ψ, and the choice of gripping vertex. The same code runs in `f64` (the
//! numeric path that verification and export read) and on symbols (the compiled model).

pub mod clearance;
pub mod compiled;
pub mod cycle;
pub mod geometry;
pub mod interface;
pub mod linalg;
pub mod numeric;
pub mod plan;
pub mod robust;
pub mod select;

pub use plan::{Constraint, Plan, PlanError};

use crate::grammar::{CreaseGraph, VarKind};
use crate::kinematics::Scalar;
use crate::task::Task;
use geometry::{Flat, Folded};

pub use crate::task::Bounds;

/// A point the gripping vertex should reach at parameter `t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// The driving parameter.
    pub t: f64,
    /// The point.
    pub point: [f64; 3],
    /// Its weight in the objective.
    pub weight: f64,
}

/// Smoothing of `‖d‖` in multi-target objectives: `√(‖d‖² + ε²)`, so the gradient exists
/// where a target is hit exactly. Far below any threshold a task can state.
pub const DISTANCE_SMOOTHING: f64 = 1e-9;

/// Eq. 33 is imposed with this margin (radians): `U_j + U_k − U_i ≥ RIGID_MARGIN` at
/// t_max. At a margin of exactly 0 the vertex triangle is degenerate and its angles move
/// with the square root of the margin, so rounding (1e-16) would become closure errors of
/// 1e-8; a margin of 1e-8 keeps the optimized state strictly rigid and the computed
/// geometry exact to ~1e-12, and changes no design measurably.
pub const RIGID_MARGIN: f64 = 1e-8;

/// An error building a model.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// The graph could not be turned into a plan.
    #[error("{0}")]
    Plan(#[from] PlanError),
    /// The task lacks something the model needs.
    #[error("task '{task}': {message}")]
    Task {
        /// Task name.
        task: String,
        /// What is missing and what is allowed.
        message: String,
    },
}

/// The model of one graph, one gripping candidate, one task.
#[derive(Clone, Debug)]
pub struct Model {
    /// The graph's plan.
    pub plan: Plan,
    /// Variable bounds.
    pub bounds: Bounds,
    /// End of the motion.
    pub t_max: f64,
    /// Targets of the gripping vertex (Eq. 37: one; Eq. 38: a trajectory).
    pub targets: Vec<Target>,
    /// Success threshold on Ω.
    pub threshold: f64,
    /// Which of the three successors of the vertex extended last grips (0, 1, 2).
    pub candidate: usize,
    /// The gripping vertex (dense index into the plan's vertices).
    pub gripping: usize,
    /// Variables of the optimization (Φ_opt): indices into `plan.variables` that the
    /// objective or a constraint depends on. The others are drawn at their lower bound.
    pub free: Vec<usize>,
    /// The distinct values of t the model evaluates: `t_max` first, then the targets', then
    /// (for cyclic patterns) the compatibility states of [`cycle::states`].
    pub times: Vec<f64>,
    /// The task's `[constraints] kawasaki`: every internal vertex of even degree folds flat.
    pub kawasaki: bool,
}

impl Model {
    /// The model of `graph` for `task` with gripping candidate `candidate` (0, 1 or 2).
    pub fn new(graph: &CreaseGraph, task: &Task, candidate: usize) -> Result<Model, ModelError> {
        let plan = Plan::new(graph)?;
        Model::from_plan(plan, task, candidate)
    }

    /// The model of an already built plan.
    pub fn from_plan(plan: Plan, task: &Task, candidate: usize) -> Result<Model, ModelError> {
        let err = |message: &str| ModelError::Task {
            task: task.name.clone(),
            message: message.to_string(),
        };
        let bounds = task
            .bounds
            .ok_or_else(|| err("the task has no [bounds] (l_min, l_max, alpha_min, alpha_max)"))?;
        let t_max = task
            .motion
            .as_ref()
            .ok_or_else(|| err("the task has no [motion] t_max"))?
            .t_max;
        let objective = task
            .objective
            .as_ref()
            .ok_or_else(|| err("the task has no [objective] with targets"))?;
        if objective.targets.is_empty() {
            return Err(err("the objective has no targets"));
        }
        // Point targets of the gripping vertex: the thesis's objective (Eq. 37–38).
        let targets: Vec<Target> = objective
            .targets
            .iter()
            .map(|t| match (&t.vertex, t.point()) {
                (crate::task::terms::VertexRef::Tip, Some(point)) => Ok(Target {
                    t: t.t,
                    point,
                    weight: t.weight,
                }),
                _ => Err(err(&format!(
                    "objective.targets[{}]: only point targets of the tip are modelled",
                    t.entry
                ))),
            })
            .collect::<Result<_, _>>()?;
        let candidates = plan
            .candidates
            .ok_or_else(|| err("the graph has no extended vertex to grip with"))?;
        if candidate > 2 {
            return Err(err("the gripping candidate must be 1, 2 or 3"));
        }
        let gripping = candidates[candidate];
        let mut times = vec![t_max];
        for t in &targets {
            if !times.contains(&t.t) {
                times.push(t.t);
            }
        }
        if !plan.sinks.is_empty() {
            for t in cycle::states(t_max) {
                if !times.contains(&t) {
                    times.push(t);
                }
            }
        }
        let mut model = Model {
            plan,
            bounds,
            t_max,
            targets,
            threshold: objective.threshold,
            candidate,
            gripping,
            free: Vec::new(),
            times,
            kawasaki: task.kawasaki,
        };
        model.free = model.dependencies();
        Ok(model)
    }

    /// The variables the objective and the constraints depend on (Φ_opt, Sec. 5.4.1),
    /// found by building the model once on symbols and following the expression graph.
    fn dependencies(&self) -> Vec<usize> {
        let ctx = crate::expr::Ctx::new();
        let all: Vec<usize> = (0..self.plan.variables.len()).collect();
        let vars: Vec<crate::expr::Sym> = all.iter().map(|&i| ctx.var(i)).collect();
        let modes: Vec<crate::expr::Sym> = (0..self.plan.internal.len())
            .map(|i| ctx.param(i))
            .collect();
        let times: Vec<crate::expr::Sym> = (0..self.times.len())
            .map(|i| ctx.param(self.plan.internal.len() + i))
            .collect();
        let out = self.outputs(&vars, &modes, &times);
        let mut ids = vec![ctx.node_id(&out.objective)];
        ids.extend(out.constraints.iter().map(|c| ctx.node_id(c)));
        let graph = ctx.graph();
        let reach = graph.reachable(&ids);
        let mut used = vec![false; all.len()];
        for (node, r) in graph.nodes().iter().zip(&reach) {
            if let (true, crate::expr::Node::Var(i)) = (r, node) {
                used[*i as usize] = true;
            }
        }
        all.into_iter().filter(|i| used[*i]).collect()
    }

    /// Lower and upper bound of variable `i` (of `plan.variables`).
    pub fn var_bounds(&self, i: usize) -> (f64, f64) {
        match self.plan.variables[i].kind {
            VarKind::Sector => (self.bounds.alpha_min, self.bounds.alpha_max),
            VarKind::Length => (self.bounds.l_min, self.bounds.l_max),
        }
    }

    /// The full variable vector from the free ones (the others at their lower bound).
    pub fn full_vars<S: Scalar>(&self, free: &[S]) -> Vec<S> {
        let mut full: Vec<S> = (0..self.plan.variables.len())
            .map(|i| S::from_f64(self.var_bounds(i).0))
            .collect();
        for (k, &i) in self.free.iter().enumerate() {
            full[i] = free[k].clone();
        }
        full
    }

    /// Objective and constraints for the full variable vector, the modes (±1 per internal
    /// vertex) and the values of [`Model::times`] (as scalars, so they can be parameters).
    pub fn outputs<S: Scalar>(&self, vars: &[S], modes: &[S], times: &[S]) -> Outputs<S> {
        let flat = geometry::flat(&self.plan, vars);
        let folded: Vec<Folded<S>> = times
            .iter()
            .map(|t| geometry::fold(&self.plan, &flat, modes, t))
            .collect();
        let mut terms = Vec::with_capacity(self.targets.len());
        for target in &self.targets {
            let k = self
                .times
                .iter()
                .position(|s| *s == target.t)
                .expect("every target time is in times");
            let x = geometry::position(&self.plan, &flat, &folded[k], self.gripping);
            let d2 = (0..3).fold(S::from_f64(0.0), |acc, i| {
                let d = x[i].clone() - target.point[i];
                acc + d.clone() * d
            });
            terms.push((target.weight, d2));
        }
        // One target: the squared distance (smooth at the optimum, same minimizer as
        // Eq. 37). Several: Eq. 38's weighted sum of distances, smoothed at 1e-9.
        let objective = if terms.len() == 1 {
            terms[0].1.clone() * (terms[0].0 * terms[0].0)
        } else {
            terms.iter().fold(S::from_f64(0.0), |acc, (w, d2)| {
                acc + (d2.clone() + DISTANCE_SMOOTHING * DISTANCE_SMOOTHING).sqrt() * *w
            })
        };
        let mut constraints = self.constraints(&flat, &folded[0]);
        constraints.extend(cycle::constraints(self, &flat, &folded));
        constraints.extend(self.kawasaki_constraints(&flat));
        Outputs {
            objective,
            constraints,
        }
    }

    /// The constraints ψ as `g ≥ 0`, in the order of `plan.constraints`; rigid foldability
    /// is read from `at_tmax`, the folded state at t_max.
    pub fn constraints<S: Scalar>(&self, flat: &Flat<S>, at_tmax: &Folded<S>) -> Vec<S> {
        let b = &self.bounds;
        self.plan
            .constraints
            .iter()
            .map(|c| match c {
                Constraint::Sector {
                    vertex, k, lower, ..
                } => {
                    let s = flat.sectors[*vertex][*k].clone();
                    if *lower {
                        s - b.alpha_min
                    } else {
                        S::from_f64(b.alpha_max) - s
                    }
                }
                Constraint::Length { crease, lower } => {
                    let c = &self.plan.creases[*crease];
                    let (p, q) = (&flat.pos[c.tail], &flat.pos[c.head]);
                    let (dx, dy) = (q[0].clone() - p[0].clone(), q[1].clone() - p[1].clone());
                    let l = (dx.clone() * dx + dy.clone() * dy).sqrt();
                    if *lower {
                        l - b.l_min
                    } else {
                        S::from_f64(b.l_max) - l
                    }
                }
                Constraint::Rigid { vertex, i } => {
                    at_tmax.states[*vertex]
                        .as_ref()
                        .expect("rigid constraints are on internal vertices")
                        .margins[*i]
                        .clone()
                        - RIGID_MARGIN
                }
            })
            .collect()
    }

    /// The internal vertices Kawasaki's condition applies to: all of even degree when the
    /// task asks for it (an odd-degree vertex, r2's, cannot fold flat at all).
    pub fn kawasaki_vertices(&self) -> Vec<usize> {
        if !self.kawasaki {
            return Vec::new();
        }
        let p = &self.plan;
        p.internal
            .iter()
            .copied()
            .filter(|&v| p.vertices[v].rays.len().is_multiple_of(2))
            .collect()
    }

    /// Kawasaki's condition as constraints `g ≥ 0`: at each of [`Model::kawasaki_vertices`]
    /// the alternating sum of the flat sectors, `Σ (−1)^k α_k = 0`, as the pair `±`. With
    /// the sum 2π it says every other sector sums to π: the vertex folds flat. On a cyclic
    /// pattern of degree-4 vertices this turns the compatibility of the whole motion into
    /// one condition: a flat-foldable vertex's fold angles obey `tan(ρ_i/2) = k_i
    /// tan(ρ_j/2)` with constant k_i, so around a cycle the products either agree for
    /// every t or for none.
    pub fn kawasaki_constraints<S: Scalar>(&self, flat: &Flat<S>) -> Vec<S> {
        let mut out = Vec::new();
        for v in self.kawasaki_vertices() {
            let sum = flat.sectors[v]
                .iter()
                .enumerate()
                .fold(S::from_f64(0.0), |acc, (k, a)| {
                    if k.is_multiple_of(2) {
                        acc + a.clone()
                    } else {
                        acc - a.clone()
                    }
                });
            out.push(sum.clone());
            out.push(-sum);
        }
        out
    }

    /// Ω as the thesis states it (Eq. 37/38): `Σ w ‖P − X_g(t)‖`, from the f64 path.
    pub fn omega(&self, full_vars: &[f64], modes: &[f64]) -> f64 {
        let flat = geometry::flat(&self.plan, full_vars);
        self.targets
            .iter()
            .map(|target| {
                let folded = geometry::fold(&self.plan, &flat, modes, &target.t);
                let x = geometry::position(&self.plan, &flat, &folded, self.gripping);
                let d: f64 = (0..3)
                    .map(|i| (x[i] - target.point[i]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                target.weight * d
            })
            .sum()
    }

    /// A readable label of constraint `i`.
    pub fn constraint_label(&self, i: usize) -> String {
        let p = &self.plan;
        if let Some(j) = i.checked_sub(p.constraints.len())
            && j < cycle::count(self)
        {
            return cycle::label(self, j);
        }
        if let Some(j) = i.checked_sub(p.constraints.len() + cycle::count(self)) {
            let v = self.kawasaki_vertices()[j / 2];
            return format!(
                "Kawasaki: v{} folds flat, alternating sector sum {} 0",
                p.vertices[v].name,
                if j % 2 == 0 { "≥" } else { "≤" }
            );
        }
        match &p.constraints[i] {
            Constraint::Sector {
                vertex,
                k,
                lower,
                source,
            } => {
                let v = &p.vertices[*vertex];
                let n = v.rays.len();
                let (a, b) = (v.rays[*k].other, v.rays[(*k + 1) % n].other);
                format!(
                    "{source}: sector at v{} between v{} and v{} {} α_{}",
                    v.name,
                    p.vertices[a].name,
                    p.vertices[b].name,
                    if *lower { "≥" } else { "≤" },
                    if *lower { "min" } else { "max" }
                )
            }
            Constraint::Length { crease, lower } => {
                let c = &p.creases[*crease];
                format!(
                    "Eq. 35: length v{}→v{} {} l_{}",
                    p.vertices[c.tail].name,
                    p.vertices[c.head].name,
                    if *lower { "≥" } else { "≤" },
                    if *lower { "min" } else { "max" }
                )
            }
            Constraint::Rigid { vertex, i } => {
                let j = [(1, 2, 0), (0, 2, 1), (0, 1, 2)][*i];
                format!(
                    "Eq. 33: v{} rigid at t_max: U{} + U{} − U{} ≥ 1e-8",
                    p.vertices[*vertex].name,
                    j.0 + 1,
                    j.1 + 1,
                    j.2 + 1
                )
            }
        }
    }
}

/// Objective and constraints of a model.
#[derive(Clone, Debug)]
pub struct Outputs<S> {
    /// The objective minimized (squared distance for one target; Eq. 38 otherwise).
    pub objective: S,
    /// Constraints `g ≥ 0`.
    pub constraints: Vec<S>,
}
