//! The optimization model of one crease-pattern graph for a design task (thesis Sec.
//! 5.2.1.3–5.2.2.4, 5.4.1, 5.5.3).
//!
//! A [`Plan`] (built once per graph) says how every position, sector and dihedral angle
//! follows from the design variables; [`geometry`] evaluates it generically over
//! [`Scalar`]; [`Model`] adds the task: bounds, the objective at the target states, the
//! constraints ψ, and the choice of gripping vertex. The same code runs in `f64` (the
//! numeric path that verification and export read) and on symbols (the compiled model).

pub mod area;
pub mod clearance;
pub mod compiled;
pub mod cycle;
pub mod geometry;
pub mod interface;
pub mod linalg;
pub mod numeric;
pub mod orientation;
pub mod plan;
pub mod robust;
pub mod select;
pub mod surface;
pub mod targets;
pub mod terms;

pub use plan::{Constraint, Plan, PlanError};

use crate::grammar::{CreaseGraph, VarKind};
use crate::kinematics::Scalar;
use crate::task::Task;
use geometry::{Flat, Folded};

pub use crate::task::Bounds;
pub use targets::{Combination, DISTANCE_SMOOTHING, Target};

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
    /// The targets of Ω (Eq. 37: one; Eq. 38: a trajectory), generalized to any vertex and
    /// any goal (issue 31), in the task's order.
    pub targets: Vec<Target>,
    /// How the targets' terms are combined (one target and no area term: squared).
    pub combination: Combination,
    /// The meshes of surface goals, prepared for nearest-point queries (index =
    /// [`crate::task::terms::Goal::Surface`]'s `index`).
    pub surfaces: Vec<surface::Surface>,
    /// The orientation requirements, resolved on this graph (constraints at their states).
    pub orientations: Vec<orientation::Orientation>,
    /// The area term to maximize, if the task has one.
    pub area: Option<crate::task::terms::AreaTerm>,
    /// The task's copies (the flat area counts each; the packing footprint covers all).
    pub copies: crate::scene::Copies,
    /// The containment boxes that apply at one state (`[[constraints.inside]]` with a `t`):
    /// every vertex of every copy inside, as smooth constraints of the model itself, so the
    /// optimum an area term drives outwards already lies in the box (the robustness block
    /// then only adds the wall gap; from outside it rarely got back in).
    pub boxes: Vec<crate::scene::Containment>,
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
        if objective.targets.is_empty() && objective.area.is_none() {
            return Err(err("the objective has no targets and no area term"));
        }
        let candidates = plan
            .candidates
            .ok_or_else(|| err("the graph has no extended vertex to grip with"))?;
        if candidate > 2 {
            return Err(err("the gripping candidate must be 1, 2 or 3"));
        }
        let gripping = candidates[candidate];
        let resolved = terms::resolve(&plan, task, objective, gripping)?;
        let targets = resolved.targets;
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
        let combination = if targets.len() == 1 && objective.area.is_none() {
            Combination::Squared
        } else {
            Combination::Smoothed
        };
        let mut model = Model {
            plan,
            bounds,
            t_max,
            targets,
            combination,
            surfaces: resolved.surfaces,
            orientations: resolved.orientations,
            area: objective.area,
            copies: task.scene.copies,
            boxes: (task.scene.containment.iter())
                .filter(|b| b.t.is_some())
                .cloned()
                .collect(),
            threshold: objective.threshold,
            candidate,
            gripping,
            free: Vec::new(),
            times,
            kawasaki: task.kawasaki,
        };
        // The new terms' states go last: the thesis's and the cyclic ones keep their places.
        for t in terms::extra_times(&model) {
            if !model.times.contains(&t) {
                model.times.push(t);
            }
        }
        model.free = model.dependencies();
        Ok(model)
    }

    /// The variables the objective and the constraints depend on (Φ_opt, Sec. 5.4.1),
    /// found by building the model once on symbols and following the expression graph.
    fn dependencies(&self) -> Vec<usize> {
        let ctx = crate::expr::Ctx::new();
        let all: Vec<usize> = (0..self.plan.variables.len()).collect();
        let vars: Vec<crate::expr::Sym> = all.iter().map(|&i| ctx.var(i)).collect();
        let modes: Vec<crate::expr::Sym> = (0..self.plan.n_modes).map(|i| ctx.param(i)).collect();
        let times: Vec<crate::expr::Sym> = (0..self.times.len())
            .map(|i| ctx.param(self.plan.n_modes + i))
            .collect();
        let out = self.outputs(&vars, &modes, &times);
        let mut ids = vec![ctx.node_id(&out.objective)];
        ids.extend(out.constraints.iter().map(|c| ctx.node_id(c)));
        ids.extend(out.aux.iter().map(|c| ctx.node_id(c)));
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
        let omega = terms::omega(self, &flat, &folded);
        let mut constraints = self.constraints(&flat, &folded[0]);
        constraints.extend(cycle::constraints(self, &flat, &folded));
        constraints.extend(self.kawasaki_constraints(&flat));
        constraints.extend(terms::constraints(self, &flat, &folded, &omega));
        // With an area term Ω is a constraint and the objective is −weight·A.
        let objective = match (self.area, terms::area_value(self, &flat, &folded)) {
            (Some(term), Some(a)) => a * (-term.weight),
            _ => omega,
        };
        Outputs {
            objective,
            constraints,
            aux: terms::aux(self, &flat, &folded),
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

    /// Ω as the thesis states it (Eq. 37/38), generalized: `Σ w d` over every target, `d`
    /// the distance of its vertex at its state from its goal (point, line, plane or the
    /// nearest triangle of a surface), from the f64 path. Point targets keep the thesis's
    /// arithmetic.
    pub fn omega(&self, full_vars: &[f64], modes: &[f64]) -> f64 {
        let flat = geometry::flat(&self.plan, full_vars);
        self.targets
            .iter()
            .map(|target| {
                let folded = geometry::fold(&self.plan, &flat, modes, &target.t);
                let x = geometry::position(&self.plan, &flat, &folded, target.vertex);
                let d: f64 = match &target.goal {
                    crate::task::terms::Goal::Point { point } => (0..3)
                        .map(|i| (x[i] - point[i]).powi(2))
                        .sum::<f64>()
                        .sqrt(),
                    crate::task::terms::Goal::Surface { index } => self.surfaces[*index]
                        .nearest(x)
                        .map_or(f64::INFINITY, |n| n.d2.sqrt()),
                    goal => targets::squared_distance(&x, goal)
                        .expect("line and plane distances are expressions")
                        .sqrt(),
                };
                target.weight * d
            })
            .sum()
    }

    /// The area term `A` of a design (flat area × copies, or the packing ratio), from the
    /// f64 path; `None` without an area term.
    pub fn area(&self, full_vars: &[f64], modes: &[f64]) -> Option<f64> {
        self.area?;
        let flat = geometry::flat(&self.plan, full_vars);
        let folded: Vec<Folded<f64>> = self
            .times
            .iter()
            .map(|t| geometry::fold(&self.plan, &flat, modes, t))
            .collect();
        terms::area_value(self, &flat, &folded)
    }

    /// The surface targets' terms from the auxiliary outputs `aux` ([`Outputs::aux`]): per
    /// surface target, in order, its term (`w² d²` or `w √(d² + ε²)` as
    /// [`Model::combination`] says, `d` the distance to the nearest triangle) and the
    /// term's gradient with respect to the vertex's position (Danskin: through the nearest
    /// point `q`, `∂d²/∂x = 2 (x − q)`).
    pub fn surface_terms(&self, aux: &[f64]) -> Vec<(f64, [f64; 3])> {
        self.targets
            .iter()
            .filter_map(|t| t.surface().map(|s| (t, s)))
            .enumerate()
            .map(|(j, (t, s))| {
                let x = [aux[3 * j], aux[3 * j + 1], aux[3 * j + 2]];
                let near = self.surfaces[s]
                    .nearest(x)
                    .expect("surface goals have triangles (checked when the model is built)");
                let (v, dv) = self.combination.term_f64(t.weight, near.d2);
                (
                    v,
                    std::array::from_fn(|i| dv * 2.0 * (x[i] - near.point[i])),
                )
            })
            .collect()
    }

    /// Where the surface terms go: `None` into the objective, `Some(k)` subtracted from
    /// constraint `k` (`threshold − Ω ≥ 0`, when an area term makes Ω a constraint).
    pub fn surface_destination(&self) -> Option<usize> {
        terms::omega_constraint(self).map(|j| self.new_terms_offset() + j)
    }

    /// Number of auxiliary outputs ([`Outputs::aux`]): 3 per surface target.
    pub fn surface_aux_len(&self) -> usize {
        3 * self
            .targets
            .iter()
            .filter(|t| t.surface().is_some())
            .count()
    }

    /// Index of the first constraint of the task language's terms (orientation, area).
    fn new_terms_offset(&self) -> usize {
        self.plan.constraints.len() + cycle::count(self) + 2 * self.kawasaki_vertices().len()
    }

    /// A readable label of constraint `i`.
    pub fn constraint_label(&self, i: usize) -> String {
        let p = &self.plan;
        if let Some(j) = i.checked_sub(self.new_terms_offset()) {
            return terms::label(self, j);
        }
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
    /// The objective minimized (squared distance for one target; Eq. 38 otherwise; `−weight·A`
    /// with an area term). Surface targets are not in it: see [`Outputs::aux`].
    pub objective: S,
    /// Constraints `g ≥ 0`.
    pub constraints: Vec<S>,
    /// Auxiliary outputs the graph cannot finish: the position (x, y, z) of every surface
    /// target's vertex at its state, in target order; [`Model::surface_terms`] adds their
    /// distances numerically.
    pub aux: Vec<S>,
}
