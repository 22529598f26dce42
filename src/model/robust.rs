//! The robustness block of a model (issue 12): clearance and rigid-margin constraints at
//! the states of the motion the optimizer samples, compiled with the rest of the model.
//!
//! ## What is compiled
//!
//! Per graph and gripping candidate, two native functions built from the same generic
//! kinematics as the model ([`super::geometry`] on symbols, then egg → reverse mode →
//! Cranelift), with the modes and `t` as parameters:
//! - **values**: every vertex position, every Eq. 25 margin `U_j + U_k − U_i` and every
//!   crease's fold angle at `t`;
//! - **pullback**: the gradient of `S = Σ w_i·X_i + Σ u_k m_k + Σ r_c ρ_c` with respect
//!   to the design variables, with the weights as parameters. It reads the forward
//!   quantities the values function left on a tape ([`crate::compile::tape`]) instead of
//!   sweeping forward again.
//!
//! Every constraint of the block is a smooth function `h(X, m, ρ)` of those values (the
//! separating-plane constraints of [`super::clearance`] are linear in `X` for a given
//! plane), so the gradient of the block's augmented-Lagrangian term,
//! `Σ_k ∂φ/∂h_k ∇h_k`, is the gradient of `S` with `w = Σ_k ∂φ/∂h_k ∂h_k/∂X`, etc.: one
//! reverse sweep, exact (no finite differences), whatever the number of constraints. The
//! compile cost does not grow with the number of facet pairs; each sampled state costs
//! one call of the values and, where a constraint is active, one of the pullback per
//! evaluation, and states with no constraint near its bound are skipped.
//!
//! ## The constraints, at each sampled state t
//!
//! - clearance between facets, to the rotated copies and to the obstacles' convex pieces
//!   ([`super::clearance`]);
//! - every vertex of every copy above each half-space obstacle and inside each containment
//!   box (at its one t, a sampled state of every start, or at every state), with
//!   `obstacle_clearance` to the walls: linear in the positions, no plane;
//! - creases stay `2 asin(clearance/2)` short of folding flat (|ρ| ≤ π − that), and
//!   within the task's fold limits (`max_fold`, `fold_limits`) where those are lower;
//! - rigid foldability with margin: `U_j + U_k − U_i ≥ rigid_margin · (t/t_max)²` for
//!   t > 0. At the flat state every vertex whose first unit spans more than π has a
//!   degenerate vertex triangle (`U_1 = 2π − Σα = U_2 + U_3` by developability, for any
//!   sector angles), and its margin — and the effect of a sector error on it — grows as t²
//!   from there; at t_max the full margin applies, over the motion its t² share.
//!
//! ## Feature size of the flat layout (issue 20)
//!
//! Independent of t: every two vertices, every vertex and edge (crease or the paper's edge)
//! it does not end on, are at least `min_feature` apart in the flat layout — so every edge
//! is at least that long. The in-plane positions are a third compiled function of the
//! design variables (values and their Jacobian, from the same [`geometry::flat`]); the
//! distances and their gradients are closed form on top of it. The distance from a vertex
//! `p` to the segment `a + s(b − a)`, `s ∈ [0, 1]`, is continuously differentiable in all
//! three points away from 0 (the nearest point is unique, so by Danskin's theorem the
//! gradient is that of `|p − a − s(b − a)|` at the minimizing `s`, held fixed): one
//! constraint per vertex–edge pair whose gradient is continuous where the nearest point
//! passes an end. There it equals that end's vertex-pair constraint, which changes no
//! feasible set. Every pair is evaluated at every merit evaluation (a few hundred closed-form
//! distances and one small compiled call: no planes to fit, no state to sample); a pair
//! adds to the merit and its gradient only while violated or with a multiplier.
//!
//! Each requirement is imposed with a 1% safety over its setting (plus a floor that keeps
//! zero settings strictly clear of contact), so states between the ones sampled keep the
//! setting; a design is accepted only when a finer sweep (the search's verification
//! sweep) holds with half that safety, and states where it does not are added.

use super::clearance::{
    self, Buffers, CopyMap, Effort, Group, Pair, PairKind, Pairs, Plane, Scene, VRef, obstacle,
};
use super::select::{self, SelectError};
use super::{Model, RIGID_MARGIN, geometry};
use crate::compile::tape::Taped;
use crate::compile::{self, Compiled, Options};
use crate::expr::{Ctx, Sym};
use crate::geom::V3;
use crate::kinematics::wrap_angle;
use crate::optimize::{Acceptance, Robust};
use crate::scene::{Containment, HalfSpace};
use crate::task::fabrication::Fabrication;
use crate::task::terms::Requirements;
use crate::task::{Robustness, Task};
use std::cell::{Cell, OnceCell, RefCell};
use std::f64::consts::PI;
use std::sync::OnceLock;
use std::time::Instant;

/// Relative safety over each setting at the sampled states (half of it on the sweep).
pub const SAFETY: f64 = 1e-2;
/// Smallest clearance imposed (paper units), so that a setting of 0 still keeps facets off
/// contact (the Möller check's tolerance is 1e-9).
pub const CLEARANCE_FLOOR: f64 = 1e-6;
/// Pairs whose bounding spheres are farther apart than the required gap plus this (paper
/// units; radians for cones) get no plane.
pub const ACTIVATE: f64 = 0.05;
/// A sampled state joins the merit while one of its constraints is within this of its
/// bound (or carries a multiplier).
const LIVE: f64 = 0.05;

/// Plane fits between outer iterations: the optimizer's planes.
const FIT: Effort = Effort {
    enough: LIVE,
    iters: 32,
    tol: 1e-10,
    axes: true,
};
/// Plane fits on the acceptance sweep: any plane that shows the gap will do.
const SWEEP_FIT: Effort = Effort {
    enough: 0.0,
    iters: 32,
    tol: 1e-9,
    axes: false,
};
/// At most this many states are added to the sampled ones per start.
const MAX_ADDED_STATES: usize = 24;

/// The block's settings for one task.
#[derive(Clone, Debug)]
pub struct RobustSpec {
    /// The task's `[robustness]`.
    pub settings: Robustness,
    /// Evenly spaced states over [0, t_max] where the constraints are imposed.
    pub states: usize,
    /// States of the finer sweep a design must also pass.
    pub sweep: usize,
    /// The world: obstacles of every shape (kept clear by every copy), the copies (kept
    /// clear of each other), the containment boxes.
    pub scene: crate::scene::Scene,
    /// The task's requirements; the block reads the fold-angle limits (`max_fold`,
    /// `fold_limits`).
    pub requirements: Requirements,
    /// The task's `[fabrication]` (issue 32): with it, every gap grows by the panels' reach
    /// (see [`RobustModel::thick_inflation`]) and every crease's fold is bounded by
    /// [`thick_fold_limit`]; `None`: zero-thickness facets, as before.
    pub fabrication: Option<Fabrication>,
}

/// The largest setback (paper units, G0's crease = 1) the optimizer lets a tapered panel's
/// trimming take off its facet at a crease: a tenth of G0's crease (1 cm on a 10 cm
/// gripper). The setback at fold angle ρ is `reach · tan(|ρ|/2)`, so it bounds the fold.
pub const MAX_SETBACK: f64 = 0.1;

/// The largest `|ρ|` (rad) at which the tapered setback `reach · tan(|ρ|/2)` of `spec`'s
/// panels stays within [`MAX_SETBACK`]: `2 atan(MAX_SETBACK / reach)`, below π for every
/// thickness (a crease of thick panels never folds flat).
pub fn thick_fold_limit(spec: &Fabrication) -> f64 {
    2.0 * (MAX_SETBACK / spec.reach_units()).atan()
}

impl RobustSpec {
    /// The settings of `task`, with the verification sweep of `sweep` states.
    pub fn from_task(task: &Task, sweep: usize) -> RobustSpec {
        let check = task.check.as_ref();
        RobustSpec {
            settings: task.robustness,
            states: check.map_or(crate::task::DEFAULT_OPTIMIZE_STATES, |c| c.optimize_states),
            sweep: sweep.max(2),
            scene: task.scene.clone(),
            requirements: task.requirements.clone(),
            fabrication: task.fabrication,
        }
    }
}

/// Why a block could not be built.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// Code generation failed.
    #[error(transparent)]
    Compile(#[from] compile::CompileError),
    /// A fold limit names a crease this graph does not have.
    #[error("fold limit: {0}")]
    Select(#[from] SelectError),
}

/// How strictly a requirement is read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// What the optimizer imposes at the sampled states (setting + safety).
    Imposed,
    /// What a design must keep on the finer sweep (setting + half the safety).
    Accept,
    /// The setting itself.
    Setting,
}

impl Level {
    fn factor(self) -> f64 {
        match self {
            Level::Imposed => 1.0 + SAFETY,
            Level::Accept => 1.0 + 0.5 * SAFETY,
            Level::Setting => 1.0,
        }
    }
}

/// What a constraint depends on: vertex positions (with `∂h/∂x`), a margin or a fold angle
/// (with `∂h/∂·`).
#[derive(Clone, Copy, Debug)]
pub enum Dep<'a> {
    /// Positions of the vertices involved and the gradient of `h` with respect to each.
    X(&'a [(VRef, V3)]),
    /// Margin `k` (vertex `k / 3`, margin `k % 3`), `∂h/∂m = 1`.
    Margin(usize),
    /// Fold angle of crease `creases[c]` with `∂h/∂ρ`.
    Rho(usize, f64),
}

/// What a constraint slot of [`RobustModel::slots`] belongs to (for messages and records).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SlotOwner {
    /// A clearance pair (index into the pairs).
    Pair(usize),
    /// The fold angle of `creases[c]`.
    Crease(usize),
    /// Margin `k` of the Eq. 25 margins (vertex `k / 3`).
    Margin(usize),
    /// Vertex `vertex` of copy `copy` above half-space `k` (index into
    /// [`RobustModel::halfspaces`]).
    HalfSpace {
        /// Which half-space.
        k: usize,
        /// Which copy.
        copy: usize,
        /// Which vertex.
        vertex: usize,
    },
    /// Vertex `vertex` of copy `copy` inside box `k` (index into [`RobustModel::boxes`]),
    /// against wall `wall`: `2i` the `+` wall of the box's axis `i`, `2i + 1` the `−` wall.
    Box {
        /// Which box.
        k: usize,
        /// Which copy.
        copy: usize,
        /// Which vertex.
        vertex: usize,
        /// Which wall.
        wall: usize,
    },
}

/// The values the block reads at one state.
#[derive(Clone, Debug, Default)]
pub struct StateValues {
    /// Vertex positions, their copies and the facets' bounding spheres.
    pub scene: Scene,
    /// Margins, three per internal vertex (extension order).
    pub margins: Vec<f64>,
    /// Fold angles of the constrained creases.
    pub rho: Vec<f64>,
}

/// Buffers for evaluating the block (one per alternative: no allocation per evaluation).
#[derive(Clone, Debug, Default)]
pub struct Work {
    params: Vec<f64>,
    out: Vec<f64>,
    /// The pullback's gradient.
    grad: Vec<f64>,
    /// Where the tape in `out` was computed: the free variables, the modes and t.
    tape_at: Vec<f64>,
    x: Vec<V3>,
    /// The values of the last state evaluated.
    pub values: StateValues,
    buffers: Buffers,
    weights: Vec<f64>,
    /// The flat layout of the last [`RobustModel::eval_flat`] (issue 20).
    pub flat: Vec<[f64; 2]>,
    flat_out: Vec<f64>,
    flat_weights: Vec<f64>,
}

/// The compiled robustness block of one model.
#[derive(Debug)]
pub struct RobustModel {
    /// Pairs of pieces and their slots.
    pub pairs: Pairs,
    /// Creases with a fold-angle constraint (the driven ones are set by the task).
    pub creases: Vec<usize>,
    /// The task's fold-angle limit of each of [`RobustModel::creases`] (rad; `None`: only
    /// the clearance's distance from ±π).
    pub fold_limits: Vec<Option<f64>>,
    /// The half-space obstacles: (index in the scene, the half-space).
    pub halfspaces: Vec<(usize, HalfSpace)>,
    /// The containment boxes.
    pub boxes: Vec<Containment>,
    /// Settings.
    pub spec: RobustSpec,
    /// The flat layout's edges: every crease (tail, head), then the paper's edges that
    /// close open facets (as in the exported pattern).
    pub edges: Vec<[usize; 2]>,
    /// Values and their weighted pullback, sharing a tape.
    taped: Taped,
    /// In-plane positions of the flat layout and their Jacobian (issue 20).
    flat_fn: Compiled,
    n_vertices: usize,
    /// Internal vertices (three margins each).
    n_internal: usize,
    /// Mode parameters (before t in the compiled functions' parameters).
    n_modes: usize,
    t_max: f64,
    /// Milliseconds from the start of the build to native code.
    pub total_ms: f64,
}

impl RobustModel {
    /// Build and compile the block of `model`.
    pub fn new(model: &Model, spec: RobustSpec) -> Result<RobustModel, BuildError> {
        let start = Instant::now();
        let plan = &model.plan;
        let map = CopyMap::new(spec.scene.copies);
        // The arms of a gripper meet at its target on the axis: their tips touch there by
        // design.
        let tip = (map.n() >= 2 && model.targets.iter().any(|t| map.on_axis(t.point)))
            .then_some(model.gripping);
        let (convex, halfspaces) = obstacle::pieces(&spec.scene);
        let pairs = Pairs::new(plan, map, tip, convex);
        let creases: Vec<usize> = (0..plan.creases.len())
            .filter(|&c| plan.creases[c].drive.is_none())
            .collect();
        let mut fold_limits = resolve_fold_limits(model, &creases, &spec.requirements)?;
        if let Some(fab) = &spec.fabrication {
            let thick = thick_fold_limit(fab);
            for l in &mut fold_limits {
                *l = Some(l.map_or(thick, |m| m.min(thick)));
            }
        }
        let nm = plan.n_modes;
        let (nv, ni, nf, nc) = (
            plan.vertices.len(),
            plan.internal.len(),
            model.free.len(),
            creases.len(),
        );
        let ctx = Ctx::new();
        let free: Vec<Sym> = (0..nf).map(|k| ctx.var(k)).collect();
        let vars = model.full_vars(&free);
        let modes: Vec<Sym> = (0..nm).map(|i| ctx.param(i)).collect();
        let t = ctx.param(nm);
        let flat = geometry::flat(plan, &vars);
        let flat_ids: Vec<_> = flat.pos.iter().flatten().map(|s| ctx.node_id(s)).collect();
        let folded = geometry::fold(plan, &flat, &modes, &t);
        let x: Vec<[Sym; 3]> = (0..nv)
            .map(|v| geometry::position(plan, &flat, &folded, v))
            .collect();
        let m: Vec<Sym> = plan
            .internal
            .iter()
            .flat_map(|&a| {
                folded.states[a]
                    .as_ref()
                    .expect("internal vertices are solved")
                    .margins
                    .clone()
            })
            .collect();
        let rho: Vec<Sym> = creases.iter().map(|&c| folded.rho[c].clone()).collect();
        let mut value_ids = Vec::with_capacity(3 * nv + 3 * ni + nc);
        for p in &x {
            value_ids.extend(p.iter().map(|s| ctx.node_id(s)));
        }
        value_ids.extend(m.iter().chain(&rho).map(|s| ctx.node_id(s)));
        let graph = ctx.to_graph();
        let base = Options::default();
        let taped = compile::tape::taped(&graph, &value_ids, nf, nm + 1, base.simplify.as_ref())?;
        let flat_fn = compile::compile(&graph, &flat_ids, nf, nm + 1, &base)?;
        Ok(RobustModel {
            pairs,
            creases,
            fold_limits,
            halfspaces,
            boxes: spec.scene.containment.clone(),
            spec,
            edges: layout_edges(plan),
            taped,
            flat_fn,
            n_vertices: nv,
            n_internal: ni,
            n_modes: nm,
            t_max: model.t_max,
            total_ms: start.elapsed().as_secs_f64() * 1e3,
        })
    }

    /// Number of constraint slots per state: the pairs', then one per crease, then three
    /// margins per internal vertex, then one per half-space, copy and vertex, then six per
    /// box, copy and vertex.
    pub fn slots(&self) -> usize {
        self.scene_base() + self.scene_slots()
    }

    /// The first half-space slot.
    fn scene_base(&self) -> usize {
        self.pairs.slots + self.creases.len() + 3 * self.n_internal
    }

    /// Number of half-space and box slots.
    fn scene_slots(&self) -> usize {
        let per = self.pairs.copies.n() * self.n_vertices;
        per * (self.halfspaces.len() + 6 * self.boxes.len())
    }

    /// What slot `slot` (< [`RobustModel::slots`]) constrains.
    pub fn slot_owner(&self, slot: usize) -> SlotOwner {
        let pairs = &self.pairs.pairs;
        if slot < self.pairs.slots {
            // Pairs' slots are consecutive, in order.
            let p = pairs.partition_point(|q| q.slot + q.slots() <= slot);
            return SlotOwner::Pair(p);
        }
        let mut s = slot - self.pairs.slots;
        if s < self.creases.len() {
            return SlotOwner::Crease(s);
        }
        s -= self.creases.len();
        if s < 3 * self.n_internal {
            return SlotOwner::Margin(s);
        }
        s -= 3 * self.n_internal;
        let nv = self.n_vertices;
        let per = self.pairs.copies.n() * nv;
        if s < per * self.halfspaces.len() {
            let (k, r) = (s / per, s % per);
            return SlotOwner::HalfSpace {
                k,
                copy: r / nv,
                vertex: r % nv,
            };
        }
        s -= per * self.halfspaces.len();
        let (k, r) = (s / (6 * per), s % (6 * per));
        SlotOwner::Box {
            k,
            copy: r / (6 * nv),
            vertex: (r / 6) % nv,
            wall: r % 6,
        }
    }

    /// A label for slot `slot`: the obstacle's or box's name, the copy and the vertex, or
    /// the crease, margin or pair.
    pub fn slot_label(&self, slot: usize) -> String {
        let scene = &self.spec.scene;
        match self.slot_owner(slot) {
            SlotOwner::Pair(p) => {
                let pair = &self.pairs.pairs[p];
                match pair.kind {
                    PairKind::Obstacle { k, .. } => {
                        let o = self.pairs.obstacles[k].obstacle;
                        format!(
                            "{} (copy {}, facet {})",
                            scene.obstacles[o].name, pair.a.1, pair.a.0
                        )
                    }
                    _ => format!("{:?} pair {p}", pair.group),
                }
            }
            SlotOwner::Crease(c) => format!("fold angle of crease {}", self.creases[c]),
            SlotOwner::Margin(k) => format!("margin {} of internal vertex {}", k % 3, k / 3),
            SlotOwner::HalfSpace { k, copy, vertex } => format!(
                "{} (copy {copy}, vertex {vertex})",
                scene.obstacles[self.halfspaces[k].0].name
            ),
            SlotOwner::Box {
                k,
                copy,
                vertex,
                wall,
            } => format!(
                "{} (copy {copy}, vertex {vertex}, {}{} wall)",
                self.boxes[k].name,
                if wall % 2 == 0 { "+" } else { "-" },
                ["x", "y", "z"][wall / 2]
            ),
        }
    }

    /// The states every start samples: `states` evenly spaced over [0, t_max], then the
    /// t of every box that applies at one state (unless already sampled).
    pub fn base_times(&self) -> Vec<f64> {
        let n = self.spec.states.max(2);
        let mut ts: Vec<f64> = (0..n)
            .map(|i| self.t_max * i as f64 / (n - 1) as f64)
            .collect();
        for b in &self.boxes {
            if let Some(t) = b.t
                && !ts.contains(&t)
            {
                ts.push(t);
            }
        }
        ts
    }

    /// Number of pullback weights (3 per vertex, 3 per internal vertex, 1 per crease).
    pub fn n_weights(&self) -> usize {
        3 * self.n_vertices + 3 * self.n_internal + self.creases.len()
    }

    /// Buffers sized for this block.
    pub fn work(&self) -> Work {
        Work {
            params: vec![0.0; self.n_modes + 1 + self.n_weights() + self.taped.n_tape],
            out: vec![0.0; self.taped.n_values + self.taped.n_tape],
            grad: vec![0.0; self.taped.reverse.n_outputs()],
            weights: vec![0.0; self.n_weights()],
            flat: vec![[0.0; 2]; self.n_vertices],
            flat_out: vec![0.0; self.flat_fn.layout.len()],
            flat_weights: vec![0.0; 2 * self.n_vertices],
            ..Work::default()
        }
    }

    /// Evaluate the values at `t` (compiled) into `work.values`.
    pub fn eval(&self, free: &[f64], modes: &[f64], t: f64, work: &mut Work) {
        let nm = self.n_modes;
        let ni = self.n_internal;
        work.params[..nm].copy_from_slice(modes);
        work.params[nm] = t;
        self.taped
            .forward
            .call(free, &work.params[..nm + 1], &mut work.out)
            .expect("buffer sizes match the compiled layout");
        work.tape_at.clear();
        work.tape_at.extend_from_slice(free);
        work.tape_at.extend_from_slice(&work.params[..nm + 1]);
        let nv = self.n_vertices;
        work.x.clear();
        work.x
            .extend((0..nv).map(|v| [work.out[3 * v], work.out[3 * v + 1], work.out[3 * v + 2]]));
        work.values.scene.set(&work.x, &self.pairs);
        let (m0, r0) = (3 * nv, 3 * nv + 3 * ni);
        work.values.margins.clear();
        work.values.margins.extend_from_slice(&work.out[m0..r0]);
        work.values.rho.clear();
        work.values
            .rho
            .extend_from_slice(&work.out[r0..r0 + self.creases.len()]);
    }

    /// The same values from the plain f64 kinematics (no compiled code).
    pub fn eval_f64(&self, model: &Model, free: &[f64], modes: &[f64], t: f64) -> StateValues {
        let plan = &model.plan;
        let vars = model.full_vars(free);
        let flat = geometry::flat(plan, &vars);
        let folded = geometry::fold(plan, &flat, modes, &t);
        let x: Vec<V3> = (0..plan.vertices.len())
            .map(|v| geometry::position(plan, &flat, &folded, v))
            .collect();
        let mut scene = Scene::default();
        scene.set(&x, &self.pairs);
        StateValues {
            scene,
            margins: plan
                .internal
                .iter()
                .flat_map(|&a| folded.states[a].as_ref().expect("solved").margins)
                .collect(),
            rho: self.creases.iter().map(|&c| folded.rho[c]).collect(),
        }
    }

    /// Add `∇_free S` for `weights` (on positions, margins, fold angles; see
    /// [`RobustModel::add_weights`]) at `t` into `grad`: the pullback of those weights
    /// through the compiled kinematics.
    pub fn pullback(
        &self,
        free: &[f64],
        modes: &[f64],
        t: f64,
        weights: &[f64],
        work: &mut Work,
        grad: &mut [f64],
    ) {
        let nm = self.n_modes;
        // The tape is the last `eval`'s: evaluate first unless it was at this point.
        let (nf, at) = (free.len(), &work.tape_at);
        let same = at.len() == nf + nm + 1
            && at[..nf] == *free
            && at[nf..nf + nm] == *modes
            && at[nf + nm] == t;
        if !same {
            self.eval(free, modes, t, work);
        }
        let (nv, nt) = (self.taped.n_values, self.taped.n_tape);
        work.params[nm + 1..nm + 1 + nv].copy_from_slice(weights);
        work.params[nm + 1 + nv..].copy_from_slice(&work.out[nv..nv + nt]);
        self.taped
            .reverse
            .call(free, &work.params, &mut work.grad)
            .expect("buffer sizes match the compiled layout");
        for (g, d) in grad.iter_mut().zip(&work.grad) {
            *g += d;
        }
    }

    /// The gap each pair must keep at `level` (paper units).
    pub fn gap(&self, pair: &Pair, level: Level) -> f64 {
        let s = &self.spec.settings;
        let k = level.factor();
        let floor = match level {
            Level::Setting => 0.0,
            _ => CLEARANCE_FLOOR,
        };
        let base = match pair.kind {
            PairKind::Obstacle { k: c, .. } => {
                self.pairs.obstacles[c].radius + s.obstacle_clearance * k + floor
            }
            _ => s.clearance * k + floor,
        };
        match self.spec.fabrication {
            None => base,
            Some(_) => base + self.thick_inflation(pair.kind),
        }
    }

    /// What `[fabrication]` adds to a pair's gap (paper units): every point of a thick panel
    /// lies within `reach` of its facet, so facets `clearance + 2·reach` apart (a facet and
    /// an obstacle `obstacle_clearance + reach`) keep their panels `clearance` apart. For
    /// facets meeting at a point the gap is the chord at unit distance from it: the panels
    /// keep the clearance there, and nearer the point the tapered trimming (checked by
    /// `check::thick`) keeps them apart. 0 without `[fabrication]`.
    pub fn thick_inflation(&self, kind: PairKind) -> f64 {
        let Some(fab) = &self.spec.fabrication else {
            return 0.0;
        };
        match kind {
            PairKind::Obstacle { .. } => fab.reach_units(),
            _ => 2.0 * fab.reach_units(),
        }
    }

    /// The fold-angle distance from ±π every crease keeps at `level` (rad).
    pub fn crease_gap(&self, level: Level) -> f64 {
        let s = &self.spec.settings;
        let floor = match level {
            Level::Setting => 0.0,
            _ => CLEARANCE_FLOOR,
        };
        2.0 * ((s.clearance * level.factor()).min(2.0) / 2.0).asin() + floor
    }

    /// The largest `|ρ|` crease `creases[c]` may reach at `level` (rad): `π −`
    /// [`RobustModel::crease_gap`], lowered to the task's fold limit (with the safety).
    pub fn crease_limit(&self, c: usize, level: Level) -> f64 {
        let lim = PI - self.crease_gap(level);
        match self.fold_limits[c] {
            None => lim,
            Some(m) => {
                let floor = match level {
                    Level::Setting => 0.0,
                    _ => CLEARANCE_FLOOR,
                };
                lim.min(m / level.factor() - floor)
            }
        }
    }

    /// The distance every vertex keeps from a half-space's boundary and a box's walls at
    /// `level` (paper units).
    pub fn wall_gap(&self, level: Level) -> f64 {
        let floor = match level {
            Level::Setting => 0.0,
            _ => CLEARANCE_FLOOR,
        };
        let base = self.spec.settings.obstacle_clearance * level.factor() + floor;
        match &self.spec.fabrication {
            None => base,
            Some(fab) => base + fab.reach_units(),
        }
    }

    /// The margin every vertex keeps at `t` (rad), `None` at the flat state.
    pub fn margin_required(&self, t: f64, level: Level) -> Option<f64> {
        if t == 0.0 {
            return None;
        }
        let base = match level {
            Level::Setting => self.spec.settings.rigid_margin,
            _ => self.spec.settings.rigid_margin.max(RIGID_MARGIN) * level.factor(),
        };
        Some(base * (t / self.t_max).powi(2))
    }

    /// Visit every constraint at one state: the pairs with a plane (`planes[p]`), then
    /// every crease and margin constraint: `visit(slot, group, h, dep)`.
    pub fn visit(
        &self,
        t: f64,
        v: &StateValues,
        planes: &[Option<Plane>],
        level: Level,
        mut visit: impl FnMut(usize, Option<Group>, f64, Dep<'_>),
    ) {
        for (p, pair) in self.pairs.pairs.iter().enumerate() {
            if let Some(plane) = &planes[p] {
                self.visit_pair(p, plane, v, level, |c| {
                    visit(c.slot, Some(pair.group), c.h, Dep::X(c.dx))
                });
            }
        }
        self.visit_rest(t, v, level, |slot, h, dep| visit(slot, None, h, dep));
    }

    /// Visit the constraints of pair `p` with `plane`.
    pub fn visit_pair(
        &self,
        p: usize,
        plane: &Plane,
        v: &StateValues,
        level: Level,
        visit: impl FnMut(clearance::Slot<'_>),
    ) {
        let pair = &self.pairs.pairs[p];
        let gap = self.gap(pair, level);
        clearance::constraints(pair, plane, gap, &v.scene, &self.pairs.obstacles, visit);
    }

    /// Visit the crease and margin constraints: `visit(slot, h, dep)`.
    pub fn visit_rest(
        &self,
        t: f64,
        v: &StateValues,
        level: Level,
        mut visit: impl FnMut(usize, f64, Dep<'_>),
    ) {
        let base = self.pairs.slots;
        let lim = PI - self.crease_gap(level);
        for (c, rho) in v.rho.iter().enumerate() {
            let w = wrap_angle(*rho);
            let lim = match self.fold_limits[c] {
                None => lim,
                Some(_) => self.crease_limit(c, level),
            };
            visit(base + c, lim - w.abs(), Dep::Rho(c, -w.signum()));
        }
        if let Some(req) = self.margin_required(t, level) {
            let base = base + self.creases.len();
            for (k, m) in v.margins.iter().enumerate() {
                visit(base + k, m - req, Dep::Margin(k));
            }
        }
        self.visit_walls(t, v, level, visit);
    }

    /// Visit the half-space and box constraints at `t` (a box with its own t only there):
    /// every vertex of every copy keeps `n·(x − p) ≥ g` above each half-space and
    /// `half_i − g ∓ a_i·(x − c) ≥ 0` inside each box, `g` = [`RobustModel::wall_gap`].
    pub fn visit_walls(
        &self,
        t: f64,
        v: &StateValues,
        level: Level,
        mut visit: impl FnMut(usize, f64, Dep<'_>),
    ) {
        if self.halfspaces.is_empty() && self.boxes.is_empty() {
            return;
        }
        let g = self.wall_gap(level);
        let (n, nv) = (self.pairs.copies.n(), self.n_vertices);
        let mut slot = self.scene_base();
        for (_, hs) in &self.halfspaces {
            for copy in 0..n {
                for vertex in 0..nv {
                    let r = VRef { vertex, copy };
                    let h = hs.height(v.scene.at(r)) - g;
                    visit(slot, h, Dep::X(&[(r, hs.normal)]));
                    slot += 1;
                }
            }
        }
        for b in &self.boxes {
            if b.t.is_some_and(|tb| tb != t) {
                slot += 6 * n * nv;
                continue;
            }
            let bounds = &b.bounds;
            for copy in 0..n {
                for vertex in 0..nv {
                    let r = VRef { vertex, copy };
                    let q = bounds.local(v.scene.at(r));
                    for (i, qi) in q.into_iter().enumerate() {
                        let room = bounds.half[i] - g;
                        let a = bounds.axes[i];
                        visit(slot, room - qi, Dep::X(&[(r, crate::geom::scale(a, -1.0))]));
                        visit(slot + 1, room + qi, Dep::X(&[(r, a)]));
                        slot += 2;
                    }
                }
            }
        }
    }

    /// Fit the planes of one state into `planes`: pairs within reach get a plane (refitted
    /// from the previous one), far ones none unless `keep(p)` (they carry a multiplier).
    pub fn fit(
        &self,
        v: &StateValues,
        planes: &mut [Option<Plane>],
        keep: impl Fn(usize) -> bool,
        level: Level,
        effort: Effort,
        buffers: &mut Buffers,
    ) {
        for (p, pair) in self.pairs.pairs.iter().enumerate() {
            let need = match pair.kind {
                PairKind::Cone { .. } => 2.0 * (self.gap(pair, level).min(2.0) / 2.0).asin(),
                _ => self.gap(pair, level),
            };
            if !keep(p)
                && self
                    .pairs
                    .lower_bound(pair, &v.scene, need + ACTIVATE, buffers)
                    > need + ACTIVATE
            {
                planes[p] = None;
                continue;
            }
            // A previous plane that still shows the gap with room to spare is kept: the
            // pair is inactive and where its plane sits does not matter.
            let enough = match pair.kind {
                PairKind::Cone { .. } => (self.gap(pair, level).min(2.0) / 2.0) + effort.enough,
                PairKind::Obstacle { .. } => need + effort.enough,
                PairKind::Apart => need + effort.enough,
            };
            let (plane, _) = clearance::fit_plane(
                pair,
                &v.scene,
                &self.pairs.obstacles,
                planes[p],
                self.gap(pair, level),
                Effort { enough, ..effort },
                buffers,
            );
            planes[p] = Some(plane);
        }
    }

    /// The smallest feature the flat layout keeps at `level` (paper units), `None` when the
    /// setting is 0 (off).
    pub fn feature_required(&self, level: Level) -> Option<f64> {
        let s = self.spec.settings.min_feature;
        (s > 0.0).then(|| s * level.factor())
    }

    /// Number of feature slots: one per vertex pair, then one per vertex and edge (those
    /// where the vertex is an end of the edge stay unused).
    pub fn feature_slots(&self) -> usize {
        let n = self.n_vertices;
        n * (n - 1) / 2 + n * self.edges.len()
    }

    /// Evaluate the flat layout (compiled: positions and their Jacobian) into `work.flat`.
    pub fn eval_flat(&self, free: &[f64], work: &mut Work) {
        let n = self.n_vertices;
        self.flat_fn
            .function
            .call(free, &work.params[..self.n_modes + 1], &mut work.flat_out)
            .expect("buffer sizes match the compiled layout");
        work.flat.clear();
        work.flat
            .extend((0..n).map(|v| [work.flat_out[2 * v], work.flat_out[2 * v + 1]]));
    }

    /// Visit the feature constraints of the flat layout `pos` at `level` (none when the
    /// setting is 0): `visit(slot, h, ∂h/∂pos)` with `h = distance − required` and the
    /// gradient on the two or three vertices involved.
    pub fn visit_features(
        &self,
        pos: &[[f64; 2]],
        level: Level,
        visit: impl FnMut(usize, f64, &[(usize, [f64; 2])]),
    ) {
        self.visit_features_where(pos, level, |_| false, visit);
    }

    /// [`RobustModel::visit_features`] without the slots `skip_if_clear` allows to skip
    /// when they hold (`h ≥ 0`, found from squared distances without a square root): a
    /// slot with multiplier 0 that holds adds exactly nothing to the merit, to the
    /// multiplier update or to the largest violation, and most slots are such (issue 14).
    fn visit_features_where(
        &self,
        pos: &[[f64; 2]],
        level: Level,
        skip_if_clear: impl Fn(usize) -> bool,
        mut visit: impl FnMut(usize, f64, &[(usize, [f64; 2])]),
    ) {
        let Some(req) = self.feature_required(level) else {
            return;
        };
        let req2 = req * req;
        let n = pos.len();
        let unit = |r: [f64; 2], d: f64| {
            if d > 0.0 {
                [r[0] / d, r[1] / d]
            } else {
                [0.0; 2]
            }
        };
        let mut slot = 0;
        for a in 0..n {
            for b in a + 1..n {
                let r = [pos[a][0] - pos[b][0], pos[a][1] - pos[b][1]];
                let d2 = r[0] * r[0] + r[1] * r[1];
                if d2 >= req2 && skip_if_clear(slot) {
                    slot += 1;
                    continue;
                }
                // Paper coordinates are O(1): no overflow for hypot to guard against.
                let d = d2.sqrt();
                let u = unit(r, d);
                visit(slot, d - req, &[(a, u), (b, [-u[0], -u[1]])]);
                slot += 1;
            }
        }
        for (v, p) in pos.iter().enumerate() {
            for &[ia, ib] in &self.edges {
                if v != ia && v != ib {
                    let (a, b) = (pos[ia], pos[ib]);
                    let e = [b[0] - a[0], b[1] - a[1]];
                    let len2 = e[0] * e[0] + e[1] * e[1];
                    // The nearest point a + s e; with s held there the gradient is exact.
                    let s = if len2 > 0.0 {
                        (((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / len2).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    let r = [p[0] - a[0] - s * e[0], p[1] - a[1] - s * e[1]];
                    let d2 = r[0] * r[0] + r[1] * r[1];
                    if d2 >= req2 && skip_if_clear(slot) {
                        slot += 1;
                        continue;
                    }
                    let d = d2.sqrt();
                    let u = unit(r, d);
                    let ga = [-(1.0 - s) * u[0], -(1.0 - s) * u[1]];
                    let gb = [-s * u[0], -s * u[1]];
                    visit(slot, d - req, &[(v, u), (ia, ga), (ib, gb)]);
                }
                slot += 1;
            }
        }
    }

    /// The feature constraints' augmented-Lagrangian term at `free` with multipliers
    /// `lambda` (one per feature slot) and penalty `mu`: adds its exact gradient (the
    /// distances' gradients pulled back through the layout's compiled Jacobian) into `grad`
    /// and returns its value. 0 when the setting is 0.
    pub fn feature_merit(
        &self,
        free: &[f64],
        lambda: &[f64],
        mu: f64,
        work: &mut Work,
        grad: &mut [f64],
    ) -> f64 {
        if self.feature_required(Level::Imposed).is_none() {
            return 0.0;
        }
        self.eval_flat(free, work);
        let Work {
            flat,
            flat_out,
            flat_weights: w,
            ..
        } = work;
        w.iter_mut().for_each(|w| *w = 0.0);
        let mut value = 0.0;
        self.visit_features_where(
            flat,
            Level::Imposed,
            |k| lambda[k] == 0.0,
            |slot, h, dx| {
                let l = lambda[slot];
                let a = (l - mu * h).max(0.0);
                value += (a * a - l * l) / (2.0 * mu);
                if a > 0.0 {
                    for (v, g) in dx {
                        w[2 * v] -= a * g[0];
                        w[2 * v + 1] -= a * g[1];
                    }
                }
            },
        );
        for (k, wk) in w.iter().enumerate().filter(|(_, wk)| **wk != 0.0) {
            for (g, d) in grad
                .iter_mut()
                .zip(&flat_out[self.flat_fn.layout.gradient(k)])
            {
                *g += wk * d;
            }
        }
        value
    }

    /// Add `coeff · ∂h/∂(values)` of one constraint into the pullback weights.
    pub fn add_weights(&self, dep: Dep<'_>, coeff: f64, w: &mut [f64]) {
        match dep {
            Dep::X(gs) => {
                for (r, g) in gs {
                    // Copy k is the arm turned by R: ∂/∂X = Rᵀ ∂/∂(R X).
                    let g = self.pairs.copies.grad_back(r.copy, *g);
                    for i in 0..3 {
                        w[3 * r.vertex + i] += coeff * g[i];
                    }
                }
            }
            Dep::Margin(k) => w[3 * self.n_vertices + k] += coeff,
            Dep::Rho(c, d) => w[3 * self.n_vertices + 3 * self.n_internal + c] += coeff * d,
        }
    }
}

/// The fold limit of each constrained crease: the smallest of `max_fold` and the limits
/// naming it (resolved on the model's plan with its gripping vertex as the tip). A limit on
/// a driven crease (its angle is the task's, not the design's) is not the block's.
fn resolve_fold_limits(
    model: &Model,
    creases: &[usize],
    req: &Requirements,
) -> Result<Vec<Option<f64>>, SelectError> {
    let mut limits: Vec<Option<f64>> = vec![req.max_fold; creases.len()];
    for fl in &req.fold_limits {
        let c = select::crease(&model.plan, model.gripping, &fl.crease)?;
        if let Some(i) = creases.iter().position(|k| *k == c) {
            limits[i] = Some(limits[i].map_or(fl.max, |m| m.min(fl.max)));
        }
    }
    Ok(limits)
}

/// The flat layout's edges: creases, then the paper's edges that close open facets.
fn layout_edges(plan: &super::plan::Plan) -> Vec<[usize; 2]> {
    let creases = plan.creases.iter().map(|c| [c.tail, c.head]);
    let paper = plan
        .polygons
        .iter()
        .filter(|(poly, closed)| !closed && poly.len() >= 2)
        .map(|(poly, _)| [poly[poly.len() - 1], poly[0]]);
    creases.chain(paper).collect()
}

/// One sampled state of a start: its t, planes, multipliers, and whether it is live.
#[derive(Clone, Debug)]
struct SampledState {
    t: f64,
    planes: Vec<Option<Plane>>,
    lambda: Vec<f64>,
    /// Pairs near their bound or with a multiplier: the ones the merit visits.
    active: Vec<bool>,
    live: bool,
}

/// The block of one alternative (a model, its modes): a [`Robust`] for the optimizer.
pub struct RobustProblem<'a> {
    model: &'a Model,
    block: &'a RobustModel,
    modes: Vec<f64>,
    states: RefCell<Vec<SampledState>>,
    /// The planes that are variables of the current subproblem: (state, pair, offset).
    layout: RefCell<Vec<(usize, usize, usize)>>,
    /// Multipliers of the flat layout's feature constraints (issue 20), one per slot.
    feature_lambda: RefCell<Vec<f64>>,
    work: RefCell<Work>,
}

impl<'a> RobustProblem<'a> {
    /// The block of `model` with the given modes.
    pub fn new(model: &'a Model, block: &'a RobustModel, modes: &[f64]) -> RobustProblem<'a> {
        let p = RobustProblem {
            model,
            block,
            modes: modes.to_vec(),
            states: RefCell::new(Vec::new()),
            layout: RefCell::new(Vec::new()),
            feature_lambda: RefCell::new(Vec::new()),
            work: RefCell::new(block.work()),
        };
        p.reset();
        p
    }

    fn new_state(&self, t: f64) -> SampledState {
        SampledState {
            t,
            planes: vec![None; self.block.pairs.pairs.len()],
            lambda: vec![0.0; self.block.slots()],
            active: vec![false; self.block.pairs.pairs.len()],
            live: true,
        }
    }

    /// Set every multiplier to `lambda` (to examine the merit where every term is smooth:
    /// with `λ > μ h` for all constraints, no `max(0, ·)` switches). The flat state t = 0
    /// leaves the merit: its fold angles are 0, where `|ρ|` switches, and its vertex
    /// triangles are degenerate.
    pub fn set_multipliers(&self, lambda: f64) {
        for st in self.states.borrow_mut().iter_mut() {
            st.lambda.iter_mut().for_each(|l| *l = lambda);
            st.active.iter_mut().for_each(|a| *a = true);
            st.live = st.t > 0.0;
        }
        self.feature_lambda
            .borrow_mut()
            .iter_mut()
            .for_each(|l| *l = lambda);
    }

    /// Update the feature multipliers at `x` (with `mu`); returns the largest violation.
    fn update_features(&self, x: &[f64], mu: Option<f64>, work: &mut Work) -> f64 {
        let b = self.block;
        if b.feature_required(Level::Imposed).is_none() {
            return 0.0;
        }
        b.eval_flat(x, work);
        let mut lambda = self.feature_lambda.borrow_mut();
        let mut worst = 0.0_f64;
        // Read by the skip test and written by the update: shared as cells.
        let lambda = std::cell::Cell::from_mut(&mut lambda[..]).as_slice_of_cells();
        b.visit_features_where(
            &work.flat,
            Level::Imposed,
            |k| lambda[k].get() == 0.0,
            |slot, h, _| {
                if let Some(mu) = mu {
                    lambda[slot].set((lambda[slot].get() - mu * h).max(0.0));
                }
                worst = worst.max(-h);
            },
        );
        worst
    }

    /// Whether the flat layout at `x` keeps the smallest feature at `level`.
    pub fn features_hold(&self, x: &[f64], level: Level) -> bool {
        let mut work = self.work.borrow_mut();
        self.block.eval_flat(x, &mut work);
        let mut ok = true;
        self.block
            .visit_features_where(&work.flat, level, |_| true, |_, h, _| ok &= h >= -1e-12);
        ok
    }

    /// The planes that are variables of the current subproblem (after
    /// [`Robust::variables`]): the state's t and the pair, in the order of the variables.
    pub fn variable_planes(&self) -> Vec<(f64, Pair)> {
        let states = self.states.borrow();
        self.layout
            .borrow()
            .iter()
            .map(|&(si, p, _)| (states[si].t, self.block.pairs.pairs[p].clone()))
            .collect()
    }

    /// The t of every sampled state (the evenly spaced ones, then those added).
    pub fn sampled_times(&self) -> Vec<f64> {
        self.states.borrow().iter().map(|s| s.t).collect()
    }

    /// Fit a state's planes at the values in `work` and measure it: returns its largest
    /// violation and whether a constraint is near its bound or carries a multiplier.
    fn refit(&self, st: &mut SampledState, work: &mut Work) -> (f64, bool) {
        let b = self.block;
        let lambda = &st.lambda;
        let pairs = &b.pairs.pairs;
        b.fit(
            &work.values,
            &mut st.planes,
            |p| {
                let r = pairs[p].slot..pairs[p].slot + pairs[p].slots();
                lambda[r].iter().any(|l| *l > 0.0)
            },
            Level::Imposed,
            FIT,
            &mut work.buffers,
        );
        let mut worst = 0.0_f64;
        let mut live = false;
        let mut near = vec![false; b.slots()];
        b.visit(
            st.t,
            &work.values,
            &st.planes,
            Level::Imposed,
            |slot, _, h, _| {
                worst = worst.max(-h);
                near[slot] = h < LIVE || lambda[slot] > 0.0;
                live |= near[slot];
            },
        );
        for (p, pair) in pairs.iter().enumerate() {
            st.active[p] = near[pair.slot..pair.slot + pair.slots()].iter().any(|x| *x);
        }
        (worst, live)
    }
}

impl Robust for RobustProblem<'_> {
    fn reset(&self) {
        *self.states.borrow_mut() = self
            .block
            .base_times()
            .into_iter()
            .map(|t| self.new_state(t))
            .collect();
        *self.feature_lambda.borrow_mut() = vec![0.0; self.block.feature_slots()];
    }

    fn update(&self, x: &[f64], mu: Option<f64>) -> f64 {
        let b = self.block;
        let mut states = self.states.borrow_mut();
        let mut work = self.work.borrow_mut();
        let mut worst = 0.0_f64;
        for st in states.iter_mut() {
            b.eval(x, &self.modes, st.t, &mut work);
            if let Some(mu) = mu {
                let lambda = &mut st.lambda;
                b.visit(
                    st.t,
                    &work.values,
                    &st.planes,
                    Level::Imposed,
                    |slot, _, h, _| {
                        lambda[slot] = (lambda[slot] - mu * h).max(0.0);
                    },
                );
            }
            let (w, live) = self.refit(st, &mut work);
            worst = worst.max(w);
            st.live = live;
        }
        worst.max(self.update_features(x, mu, &mut work))
    }

    fn variables(&self) -> Vec<f64> {
        let states = self.states.borrow();
        let mut layout = self.layout.borrow_mut();
        layout.clear();
        let mut z = Vec::new();
        for (si, st) in states.iter().enumerate().filter(|(_, s)| s.live) {
            for (p, plane) in st.planes.iter().enumerate() {
                let Some(plane) = plane else { continue };
                if !st.active[p] {
                    continue;
                }
                layout.push((si, p, z.len()));
                z.extend_from_slice(&plane.n);
                if self.block.pairs.pairs[p].has_offset() {
                    z.push(plane.d);
                }
            }
        }
        z
    }

    fn set_variables(&self, z: &[f64]) {
        let mut states = self.states.borrow_mut();
        for &(si, p, o) in self.layout.borrow().iter() {
            let v = [z[o], z[o + 1], z[o + 2]];
            let len = crate::geom::norm(v);
            if len > 0.0 && len.is_finite() {
                let d = if self.block.pairs.pairs[p].has_offset() {
                    z[o + 3]
                } else {
                    0.0
                };
                states[si].planes[p] = Some(Plane {
                    n: crate::geom::scale(v, 1.0 / len),
                    d,
                });
            }
        }
    }

    fn merit(&self, x: &[f64], z: &[f64], mu: f64, grad_x: &mut [f64], grad_z: &mut [f64]) -> f64 {
        let b = self.block;
        let states = self.states.borrow();
        let layout = self.layout.borrow();
        let mut work = self.work.borrow_mut();
        let mut value = 0.0;
        let mut next = 0;
        for (si, st) in states.iter().enumerate().filter(|(_, s)| s.live) {
            b.eval(x, &self.modes, st.t, &mut work);
            let Work {
                values, weights, ..
            } = &mut *work;
            weights.iter_mut().for_each(|w| *w = 0.0);
            let mut any = false;
            let mut term = |slot: usize, h: f64| {
                let l = st.lambda[slot];
                let a = (l - mu * h).max(0.0);
                value += (a * a - l * l) / (2.0 * mu);
                a
            };
            while next < layout.len() && layout[next].0 == si {
                let (_, p, o) = layout[next];
                next += 1;
                let v = [z[o], z[o + 1], z[o + 2]];
                let len = crate::geom::norm(v).max(1e-300);
                let n = crate::geom::scale(v, 1.0 / len);
                let has_d = b.pairs.pairs[p].has_offset();
                let plane = Plane {
                    n,
                    d: if has_d { z[o + 3] } else { 0.0 },
                };
                b.visit_pair(p, &plane, values, Level::Imposed, |c| {
                    let a = term(c.slot, c.h);
                    if a > 0.0 {
                        b.add_weights(Dep::X(c.dx), -a, weights);
                        any = true;
                        // ∂n/∂v = (I − n nᵀ)/|v|.
                        let dn_n = crate::geom::dot(c.dn, n);
                        for i in 0..3 {
                            grad_z[o + i] -= a * (c.dn[i] - dn_n * n[i]) / len;
                        }
                        if has_d {
                            grad_z[o + 3] -= a * c.dd;
                        }
                    }
                });
            }
            b.visit_rest(st.t, values, Level::Imposed, |slot, h, dep| {
                let a = term(slot, h);
                if a > 0.0 {
                    b.add_weights(dep, -a, weights);
                    any = true;
                }
            });
            if any {
                let w = std::mem::take(&mut work.weights);
                b.pullback(x, &self.modes, st.t, &w, &mut work, grad_x);
                work.weights = w;
            }
        }
        let lambda = self.feature_lambda.borrow();
        value + b.feature_merit(x, &lambda, mu, &mut work, grad_x)
    }

    fn accept(&self, x: &[f64]) -> Acceptance {
        // The flat layout is the same at every t: more states cannot fix a sliver.
        if !self.features_hold(x, Level::Accept) {
            return Acceptance::Rejected;
        }
        let b = self.block;
        let n = b.spec.sweep;
        let np = b.pairs.pairs.len();
        let mut work = self.work.borrow_mut();
        let mut planes: Vec<Option<Plane>> = vec![None; np];
        let mut worst: Vec<(f64, f64)> = Vec::new();
        let mut unwrapped: Option<Vec<f64>> = None;
        let lim = PI - b.crease_gap(Level::Accept);
        let limited = b.fold_limits.iter().any(Option::is_some);
        for i in 0..n {
            let t = self.model.t_max * i as f64 / (n - 1) as f64;
            b.eval(x, &self.modes, t, &mut work);
            // Fold angles followed continuously from the flat state: one passing ±π between
            // two sweep states has flipped a facet through its neighbour.
            let next: Vec<f64> = match &unwrapped {
                None => work.values.rho.iter().map(|r| wrap_angle(*r)).collect(),
                Some(prev) => prev
                    .iter()
                    .zip(&work.values.rho)
                    .map(|(p, r)| p + wrap_angle(r - p))
                    .collect(),
            };
            if !limited && next.iter().any(|r| r.abs() > lim) {
                return Acceptance::Rejected;
            }
            if limited
                && (next.iter().enumerate())
                    .any(|(c, r)| r.abs() > b.crease_limit(c, Level::Accept))
            {
                return Acceptance::Rejected;
            }
            unwrapped = Some(next);
            // Planes carry over from the previous sweep state as a warm start.
            let Work {
                values, buffers, ..
            } = &mut *work;
            b.fit(
                values,
                &mut planes,
                |_| false,
                Level::Accept,
                SWEEP_FIT,
                buffers,
            );
            let mut h_min = f64::INFINITY;
            b.visit(t, values, &planes, Level::Accept, |_, _, h, _| {
                h_min = h_min.min(h);
            });
            if h_min < -1e-12 {
                worst.push((h_min, t));
            }
        }
        // Boxes that hold at one state, which the sweep need not pass through.
        for tb in b.boxes.iter().filter_map(|c| c.t) {
            b.eval(x, &self.modes, tb, &mut work);
            let mut h_min = f64::INFINITY;
            b.visit_walls(tb, &work.values, Level::Accept, |_, h, _| {
                h_min = h_min.min(h)
            });
            if h_min < -1e-12 {
                worst.push((h_min, tb));
            }
        }
        if worst.is_empty() {
            return Acceptance::Accepted;
        }
        let mut states = self.states.borrow_mut();
        let added = states.len().saturating_sub(b.base_times().len());
        worst.sort_by(|p, q| p.0.total_cmp(&q.0));
        let mut new = 0;
        for (_, t) in worst {
            if new == 4 || added + new >= MAX_ADDED_STATES {
                break;
            }
            if states.iter().any(|s| (s.t - t).abs() < 1e-12) {
                continue;
            }
            let mut st = self.new_state(t);
            b.eval(x, &self.modes, t, &mut work);
            let (_, live) = self.refit(&mut st, &mut work);
            st.live = live;
            states.push(st);
            new += 1;
        }
        if new == 0 {
            Acceptance::Rejected
        } else {
            Acceptance::Refined
        }
    }
}

/// A model's robustness block, compiled when an alternative first needs it (issue 14): only
/// an alternative whose phase A meets the target does, and most models have none (only 45
/// of the robotic arm's 159 models need theirs), so compiling every block up front spent
/// most of the blocks' compile time on code that never ran.
pub struct LazyBlock {
    spec: RobustSpec,
    /// The block (or why it failed) and the CPU seconds its compilation took.
    block: OnceLock<(Result<RobustModel, String>, f64)>,
}

impl LazyBlock {
    /// Not compiled yet.
    pub fn new(spec: RobustSpec) -> LazyBlock {
        LazyBlock {
            spec,
            block: OnceLock::new(),
        }
    }

    /// The block of `model` (the model this block belongs to), compiled by the first call
    /// from any thread; with the CPU seconds this call spent compiling it (0 unless it was
    /// the first).
    pub fn get(&self, model: &Model) -> (Result<&RobustModel, &str>, f64) {
        let mut first = false;
        let (block, s) = self.block.get_or_init(|| {
            first = true;
            let t = crate::cpu_time::Stopwatch::start();
            let block = RobustModel::new(model, self.spec.clone()).map_err(|e| e.to_string());
            (block, t.cpu_ms() / 1e3)
        });
        let spent = if first { *s } else { 0.0 };
        (block.as_ref().map_err(String::as_str), spent)
    }

    /// Whether an alternative has needed it (and it was compiled, or failed to).
    pub fn is_compiled(&self) -> bool {
        self.block.get().is_some()
    }

    /// CPU seconds its compilation took (0 if it has not been compiled).
    pub fn compile_s(&self) -> f64 {
        self.block.get().map_or(0.0, |(_, s)| *s)
    }
}

/// The [`Robust`] of one alternative on a [`LazyBlock`]: the block is compiled, and the
/// alternative's [`RobustProblem`] built, on the first call of any method — the same
/// problem, so the same results, as one built up front. Should the block fail to compile,
/// it holds nowhere (the optimizer gives up on it) and [`Deferred::error`] says why.
pub struct Deferred<'a> {
    model: &'a Model,
    lazy: &'a LazyBlock,
    modes: Vec<f64>,
    problem: OnceCell<Result<RobustProblem<'a>, String>>,
    compile_s: Cell<f64>,
}

impl<'a> Deferred<'a> {
    /// The block of `model` with the given modes, not built yet.
    pub fn new(model: &'a Model, lazy: &'a LazyBlock, modes: &[f64]) -> Deferred<'a> {
        Deferred {
            model,
            lazy,
            modes: modes.to_vec(),
            problem: OnceCell::new(),
            compile_s: Cell::new(0.0),
        }
    }

    fn get(&self) -> Option<&RobustProblem<'a>> {
        self.problem
            .get_or_init(|| {
                let (block, spent) = self.lazy.get(self.model);
                self.compile_s.set(spent);
                block
                    .map(|b| RobustProblem::new(self.model, b, &self.modes))
                    .map_err(str::to_string)
            })
            .as_ref()
            .ok()
    }

    /// Why the block could not be compiled, if it was needed and could not.
    pub fn error(&self) -> Option<&str> {
        self.problem.get()?.as_ref().err().map(String::as_str)
    }

    /// CPU seconds this alternative spent compiling the block (0 unless it was the first to
    /// need it).
    pub fn compile_s(&self) -> f64 {
        self.compile_s.get()
    }
}

impl Robust for Deferred<'_> {
    fn reset(&self) {
        if let Some(p) = self.get() {
            p.reset();
        }
    }
    fn update(&self, x: &[f64], mu: Option<f64>) -> f64 {
        self.get().map_or(f64::INFINITY, |p| p.update(x, mu))
    }
    fn variables(&self) -> Vec<f64> {
        self.get().map_or_else(Vec::new, |p| p.variables())
    }
    fn set_variables(&self, z: &[f64]) {
        if let Some(p) = self.get() {
            p.set_variables(z);
        }
    }
    fn merit(&self, x: &[f64], z: &[f64], mu: f64, grad_x: &mut [f64], grad_z: &mut [f64]) -> f64 {
        self.get()
            .map_or(0.0, |p| p.merit(x, z, mu, grad_x, grad_z))
    }
    fn accept(&self, x: &[f64]) -> Acceptance {
        self.get().map_or(Acceptance::Rejected, |p| p.accept(x))
    }
}
