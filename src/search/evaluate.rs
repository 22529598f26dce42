//! One alternative evaluated: its model prepared (once per unit), then for each
//! alternative the optimization, and for a design that meets the target the intersection
//! and obstacle checks on the dense sweep, the independent verification (and for a cyclic
//! design the sweep and the simulation) and, where every check passed, its robustness:
//! one [`AlternativeRecord`] out.

use super::measure::{
    checked_pattern, judge_requirements, judged_times, measure_robustness, measure_thick, obstacles,
};
use super::options::{Alternative, SearchOptions};
use super::record::AlternativeRecord;
use crate::check::verify::{Tolerances, verify_folded};
use crate::check::{CheckError, Checker, MotionReport, MotionSettings, ObstacleHit, check_states};
use crate::compile::Options as CompileOptions;
use crate::cpu_time::Stopwatch;
use crate::grammar::CreaseGraph;
use crate::model::Model;
use crate::model::compiled::{CompiledModel, ModelProblem, objective_target};
use crate::model::numeric::Evaluated;
use crate::model::robust::{Deferred, LazyBlock, RobustSpec};
use crate::optimize::{self, SharedStarts, Solution, minimize_shared};
use crate::pattern::Pattern;
use crate::task::Task;
use std::collections::BTreeMap;

/// A compiled model ready for its 2^N alternatives.
pub struct Prepared {
    /// The model.
    pub model: Model,
    /// Its native code.
    pub compiled: CompiledModel,
    /// Its robustness block (absent with `--post-check-only`), compiled when an
    /// alternative first needs it.
    pub robust: Option<LazyBlock>,
}

/// Build and compile the model of one graph and candidate, with its robustness block
/// (compiled on first use) when `robust` is given.
pub fn prepare(
    graph: &CreaseGraph,
    task: &Task,
    candidate: usize,
    robust: Option<&RobustSpec>,
) -> Result<Prepared, String> {
    let model = Model::new(graph, task, candidate).map_err(|e| e.to_string())?;
    let compiled =
        CompiledModel::new(&model, &CompileOptions::default()).map_err(|e| e.to_string())?;
    let robust = robust.map(|spec| LazyBlock::new(spec.clone()));
    Ok(Prepared {
        model,
        compiled,
        robust,
    })
}

/// Why an intersection check could not run.
pub(super) enum CheckFailure {
    /// The flat layout is invalid (counts as a self-intersection).
    Layout(String),
    /// Anything else (reported).
    Other(String),
}

/// Optimize, check and verify one alternative; `shared`: the phase-A starts of its class
/// (the alternatives of its model whose modes differ only where no output depends on
/// them), whose seed it optimizes with. An error when the model's robustness block was
/// needed and could not be compiled.
pub(super) fn evaluate(
    task: &Task,
    p: &Prepared,
    alt: &Alternative,
    graph: &CreaseGraph,
    opts: &SearchOptions,
    shared: &SharedStarts,
    warm: Vec<Vec<f64>>,
) -> Result<AlternativeRecord, String> {
    let model = &p.model;
    let modes = alt.mode_signs();
    let key = alt.key();
    let t0 = Stopwatch::start();
    let (sol, block_compile_s) = optimize_alternative(p, &modes, opts, shared, warm)?;
    let optimize_ms = t0.cpu_ms() - block_compile_s * 1e3;
    let full = model.full_vars(&sol.x);
    let omega = model.omega(&full, &modes);
    let mut rec = optimized_record(alt, key, graph, model, &sol, omega, optimize_ms);
    if !rec.meets_target {
        return Ok(rec);
    }
    let t1 = Stopwatch::start();
    let design = Evaluated::new(&model.plan, full, modes);
    judge(task, model, &design, opts, &mut rec);
    rec.check_ms = t1.cpu_ms();
    Ok(rec)
}

/// The optimization of one alternative (mode signs `modes`), with the seed of its class's
/// `shared` starts, and the CPU seconds it spent compiling the model's robustness block
/// (compile time, not optimization). An error when the block could not be compiled.
fn optimize_alternative(
    p: &Prepared,
    modes: &[f64],
    opts: &SearchOptions,
    shared: &SharedStarts,
    warm_starts: Vec<Vec<f64>>,
) -> Result<(Solution, f64), String> {
    let model = &p.model;
    let problem = ModelProblem::new(model, &p.compiled, modes);
    let optimize_opts = optimize::Options {
        starts: crate::model::compiled::search_starts(model, opts.starts),
        seed: shared.seed(),
        target: Some(objective_target(model)),
        all_starts: crate::model::compiled::all_starts(model),
        max_outer: if model.plan.sinks.is_empty() {
            optimize::Options::default().max_outer
        } else {
            crate::model::cycle::MAX_OUTER
        },
        warm_starts,
        ..Default::default()
    };
    let mut block_compile_s = 0.0;
    let mut sol = match &p.robust {
        None => minimize_shared(&problem, None, &optimize_opts, Some(shared)),
        Some(lazy) => {
            let rp = Deferred::new(model, lazy, modes);
            let sol = minimize_shared(&problem, Some(&rp), &optimize_opts, Some(shared));
            if let Some(e) = rp.error() {
                return Err(e.to_string());
            }
            block_compile_s = rp.compile_s();
            sol
        }
    };
    // Cyclic patterns: Newton on the compatibility equations, to rounding.
    crate::model::cycle::polish_solution(
        &problem,
        model,
        modes,
        &mut sol,
        optimize_opts.feasibility_tol,
        optimize_opts.target,
    );
    Ok((sol, block_compile_s))
}

/// The record of an optimized alternative (`omega`: its Ω*), before any check.
fn optimized_record(
    alt: &Alternative,
    key: String,
    graph: &CreaseGraph,
    model: &Model,
    sol: &Solution,
    omega: f64,
    optimize_ms: f64,
) -> AlternativeRecord {
    let meets = crate::model::compiled::meets_target(model, sol.feasible, omega);
    let variables: BTreeMap<String, f64> = model
        .free
        .iter()
        .zip(&sol.x)
        .map(|(&i, x)| (model.plan.variables[i].name.clone(), *x))
        .collect();
    AlternativeRecord {
        key,
        graph: alt.graph,
        sequence: alt.sequence.clone(),
        level: graph.level(),
        internal_vertices: alt.n,
        candidate: alt.candidate + 1,
        gripping_vertex: model.plan.vertices[model.gripping].name,
        modes: alt.mode_names(),
        objective: omega,
        feasible: sol.feasible,
        max_violation: sol.violation,
        min_slack: sol.g.iter().copied().fold(f64::INFINITY, f64::min),
        meets_target: meets,
        self_intersection_free: None,
        self_intersection: None,
        layout_defect: None,
        obstacle_free: None,
        obstacle_hit: None,
        verification: None,
        verification_failed: None,
        robust_accepted: sol.robust,
        robust_attempts: sol.robust_attempts,
        robustness: None,
        short_of_margins: Vec::new(),
        variables,
        starts_run: sol.starts_run,
        warm_start: sol.warm,
        evaluations: sol.evaluations,
        optimize_ms,
        check_ms: 0.0,
        cycle: None,
        simulation: None,
        requirements: None,
        fabrication: None,
    }
}

/// Check, verify and measure a design that meets the target, filling `rec`'s fields of
/// the checks.
fn judge(
    task: &Task,
    model: &Model,
    design: &Evaluated<'_>,
    opts: &SearchOptions,
    rec: &mut AlternativeRecord,
) {
    // The judges run on the dense verification sweep, not only on the states the optimizer
    // saw, so an intersection between sampled states cannot hide.
    // Each state folded once, for the pattern the checks judge and for `verify`.
    // With the states the task's terms name (the sweep's own for the bundled thesis tasks).
    let sweep = judged_times(task, model.t_max, opts.sweep);
    let folds = design.fold_all(&sweep);
    let arm = design.pattern_of(&sweep, &folds);
    let mut checked_pattern = None;
    match check_intersections(task, &arm, opts) {
        Ok((s, hit, pat)) => {
            rec.self_intersection_free = Some(s.self_intersection_free());
            rec.self_intersection = s.first_intersection().cloned();
            rec.obstacle_free = Some(hit.is_none());
            rec.obstacle_hit = hit;
            checked_pattern = Some(pat);
        }
        Err(CheckFailure::Layout(why)) => {
            rec.self_intersection_free = Some(false);
            rec.layout_defect = Some(why);
        }
        Err(CheckFailure::Other(e)) => {
            eprintln!("warning: {}: the intersection check failed: {e}", rec.key);
        }
    }
    let tol = Tolerances::default();
    let report = verify_folded(design, &sweep, &folds, &tol);
    let failed = !report.geometry_passes(&tol);
    if failed && model.plan.sinks.is_empty() {
        eprintln!(
            "BUG: verification failed for {} (graph {}): {}",
            rec.key,
            rec.sequence,
            report.failures(&tol).join("; ")
        );
    }
    if !model.plan.sinks.is_empty() {
        // A cyclic design (r2′): the PTU's frames are only right where the cycle closes, so
        // the sweep and the simulation decide; a geometric failure is a bug only then.
        let verdict = crate::simulate::crossval::verify_cyclic(
            model,
            &design.vars,
            &design.modes,
            opts.sweep,
            tol.geometry_margin,
        );
        let failed = failed && verdict.sweep.passes(crate::check::cycle::CYCLE_TOL);
        rec.verification_failed = Some(failed);
        rec.cycle = Some(verdict);
    } else {
        rec.verification_failed = Some(failed);
    }
    rec.verification = Some(report);
    // Judged where the layout could be checked (a layout that cannot be triangulated
    // already fails as a self-intersection).
    match checked_pattern
        .as_ref()
        .map(|_| judge_requirements(task, model, &arm))
    {
        None => {}
        Some(Ok(r)) => rec.requirements = Some(r),
        Some(Err(e)) => {
            // Nothing measured cannot pass: the design is not reported as one.
            eprintln!(
                "warning: {}: the requirements could not be judged: {e}",
                rec.key
            );
            rec.verification_failed = Some(true);
        }
    }
    // Thick panels (issue 32): built and tested only where every other check passed (the
    // solids on the dense sweep are the most expensive check).
    if let Some(pat) = checked_pattern
        .as_ref()
        .filter(|_| task.fabrication.is_some() && rec.passes_checks())
    {
        rec.fabrication = Some(measure_thick(task, model, &arm, pat));
    }
    // Several drives (a central facet): the bar-and-hinge simulation cross-checks the
    // PTU's motion of a design that passed everything else (0.5-2 s a design). The PTU is
    // exact for an acyclic pattern, so a disagreement is a bug of one of the two.
    if model.plan.actuation.fixed.is_some() && model.plan.sinks.is_empty() && rec.passes_checks() {
        match crate::simulate::crossval::simulate_design(model, &design.vars, &design.modes) {
            Ok(v) => {
                if !v.agrees {
                    eprintln!(
                        "BUG: the bar-and-hinge simulation disagrees with the PTU for {} (graph {}): Γ {:e}, largest distance {:e}",
                        rec.key, rec.sequence, v.gamma, v.max_position_error
                    );
                    rec.verification_failed = Some(true);
                }
                rec.simulation = Some(v);
            }
            Err(e) => eprintln!("warning: {}: the simulation could not run: {e}", rec.key),
        }
    }
    // Margins are a design's: measured only where every check passed (with
    // `--post-check-only` most target-meeting alternatives fail one, and measuring them was
    // half of that run's check time; issue 14).
    if let Some(pat) = checked_pattern.filter(|_| rec.passes_checks()) {
        rec.robustness = match measure_robustness(task, model, &arm, &pat) {
            Ok(r) => Some(r),
            Err(e) => {
                eprintln!(
                    "warning: {}: the robustness measurement failed: {e}",
                    rec.key
                );
                None
            }
        };
        rec.short_of_margins = rec.margins_short();
    }
}

/// The self-intersection check over the sweep's frames of `arm` (with its rotated copy
/// for a two-armed task) and the first obstacle hit; with the pattern checked.
pub(super) fn check_intersections(
    task: &Task,
    arm: &Pattern,
    opts: &SearchOptions,
) -> Result<(MotionReport, Option<ObstacleHit>, Pattern), CheckFailure> {
    let pat = checked_pattern(task, arm).map_err(CheckFailure::Other)?;
    let mut checker = Checker::from_pattern(&pat).map_err(|e| match e {
        // A facet that cannot be triangulated is inverted or overlaps itself in the
        // flat layout: the paper crosses itself before it folds.
        CheckError::Triangulate(t) => CheckFailure::Layout(t.to_string()),
        e => CheckFailure::Other(e.to_string()),
    })?;
    if pat.faces.len() > arm.faces.len() {
        // `two_armed`: the second arm is the first turned by exactly 180°.
        checker = checker.with_half_turn_copy(arm.faces.len());
    }
    let s = check_states(
        &checker,
        Some(&pat.vertices),
        pat.frames.iter().map(|f| (f.t, f.coords.clone())),
        &MotionSettings {
            n_states: opts.sweep,
            stop_at_first: true,
            obstacles: Vec::new(),
        },
    )
    .map_err(|e| CheckFailure::Other(e.to_string()))?;
    let cyl = obstacles(task);
    let hit = pat.frames.iter().find_map(|f| {
        cyl.iter().enumerate().find_map(|(k, c)| {
            checker
                .obstacle_hits(&f.coords, c, k, f.t, true)
                .first()
                .copied()
        })
    });
    Ok((s, hit, pat))
}
