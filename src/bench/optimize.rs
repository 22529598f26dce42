//! `foldsynth bench optimize TASK`: our optimizer against IPOPT on the same alternatives
//! from the same starting points (issue 33).
//!
//! The problem is each alternative's model as the thesis states it (objective Ω, the
//! constraints ψ, the variables' bounds): the search's phase A, what `--post-check-only`
//! optimizes. The robustness block (clearances and margins over the motion, phase B) is
//! ours alone and has no formulas to hand a peer. Ours: [`optimize::minimize`] with the
//! search's options (16 starts, stopping at the first that meets the target feasibly,
//! giving up after 10 starts none of which came within 4× the target). IPOPT: the CasADi
//! wheel's, on the model's formulas as `foldsynth model --formulas python` prints them,
//! evaluated on CasADi symbols (exact gradients, Jacobian and Hessian by CasADi's AD;
//! `benches/peers/ipopt_optimize.py`), from each of the same starting points; its points
//! are then judged by our compiled model and the same stopping rule is applied to them, so
//! both sides count the same starts the same way.

use crate::cpu_time::Stopwatch;
use crate::model::Model;
use crate::model::compiled::{CompiledModel, ModelProblem, meets_target, objective_target};
use crate::optimize::{self, Evaluation, Problem};
use crate::search::Plan;
use crate::task::Task;
use anyhow::{Context, Result, bail};
use serde::Serialize;
use serde_json::json;
use std::path::Path;

/// What to compare.
pub struct OptimizeBenchOptions<'a> {
    /// N_max of the enumeration (the task's when `None`).
    pub n_max: Option<usize>,
    /// At most this many alternatives, spread evenly over the enumeration.
    pub alternatives: usize,
    /// Starting points per alternative (the search's 16 by default).
    pub starts: usize,
    /// Seed of the starting points.
    pub seed: u64,
    /// The Python with CasADi.
    pub python: &'a str,
    /// The peer script (default: the crate's `benches/peers/ipopt_optimize.py`).
    pub script: Option<&'a Path>,
    /// The model's formulas as Python text (`foldsynth model --formulas python`), made by
    /// the caller (the printers live with the CLI).
    pub formulas: &'a dyn Fn(&Model) -> Result<String>,
}

/// One solver on one alternative, over the starts it ran.
#[derive(Clone, Debug, Serialize)]
pub struct Side {
    /// The best point reached the target (objective ≤ target), feasible or not.
    pub reached: bool,
    /// It reached it feasibly (the search's "meets the target").
    pub met: bool,
    /// Starts run until the stopping rule.
    pub starts_run: usize,
    /// Objective evaluations (ours: evaluations of objective, constraints and all their
    /// gradients at once).
    pub evaluations: usize,
    /// CPU milliseconds of the solves.
    pub cpu_ms: f64,
}

/// One alternative, both solvers.
#[derive(Clone, Debug, Serialize)]
pub struct AltResult {
    /// `sequence|candidate|modes`.
    pub key: String,
    /// Free variables.
    pub n: usize,
    /// Constraints.
    pub m: usize,
    /// Ours.
    pub ours: Side,
    /// IPOPT.
    pub ipopt: Side,
    /// IPOPT's iterations over the starts it ran.
    pub ipopt_iterations: usize,
    /// IPOPT's Hessian evaluations over the starts it ran.
    pub ipopt_hessians: usize,
    /// Relative difference between the printed formulas (in CasADi) and our compiled model,
    /// the largest over objective and constraints at one start, median over the starts:
    /// that both solve the same problem.
    pub formula_deviation: f64,
    /// Starts where that difference exceeds [`BRANCH_DEVIATION`]: points where the model
    /// takes a branch by the sign of a rounding error (a vertex triangle degenerate at
    /// the flat state `t = 0` gives a unit angle of 0 or π there), so two evaluation
    /// orders may differ; 1e-13 away from such a point they agree again.
    pub formula_branch_starts: usize,
}

/// The comparison.
#[derive(Clone, Debug, Serialize)]
pub struct OptimizeBench {
    /// The task.
    pub task: String,
    /// N_max enumerated.
    pub n_max: usize,
    /// Alternatives in the enumeration.
    pub enumerated: u64,
    /// Starting points per alternative (at most; both stop at the first that meets the
    /// target).
    pub starts: usize,
    /// CasADi's version, or why the peer did not run.
    pub peer: String,
    /// IPOPT's options.
    pub ipopt_options: serde_json::Value,
    /// Per alternative.
    pub alternatives: Vec<AltResult>,
}

/// A prepared alternative.
struct Prepared {
    key: String,
    model: Model,
    compiled: CompiledModel,
    modes: Vec<f64>,
}

/// IPOPT's settings: tolerances as tight as ours (feasible means violation ≤ 1e-9),
/// iterations enough that it stops by convergence, not by its cap.
fn ipopt_options() -> serde_json::Value {
    json!({"tol": 1e-10, "constr_viol_tol": 1e-9, "max_iter": 3000})
}

/// Run both on the alternatives of `task` (see the module docs). `Err` when the peer
/// script fails; a missing CasADi is an error too (the comparison is the point).
pub fn run(task: &Task, opts: &OptimizeBenchOptions<'_>) -> Result<OptimizeBench> {
    let n_max = opts.n_max.unwrap_or(task.n_max);
    let plan = Plan::new(task, n_max);
    let every = (plan.alternatives as usize)
        .div_ceil(opts.alternatives.max(1))
        .max(1);
    let mut prepared = Vec::new();
    let mut index = 0usize;
    for (u, unit) in plan.units.iter().enumerate() {
        for modes in 0..unit.count as u32 {
            let take = index.is_multiple_of(every) && prepared.len() < opts.alternatives;
            index += 1;
            if !take {
                continue;
            }
            // One model per alternative: compile time is not what is compared.
            let graph = plan.graph(task, unit.graph);
            let model = Model::new(&graph, task, unit.candidate)
                .with_context(|| format!("graph {}", plan.graphs[unit.graph].sequence))?;
            let compiled = CompiledModel::new(&model, &Default::default())?;
            let alt = plan.alternative(u, modes);
            prepared.push(Prepared {
                key: alt.key(),
                model,
                compiled,
                modes: alt.mode_signs(),
            });
        }
    }
    let settings = |p: &Prepared| optimize::Options {
        starts: opts.starts,
        seed: opts.seed,
        target: Some(objective_target(&p.model)),
        ..Default::default()
    };
    // The peer's job: every alternative's formulas, parameters, bounds and starts.
    let mut job = Vec::new();
    for p in &prepared {
        let problem = ModelProblem::new(&p.model, &p.compiled, &p.modes);
        let (lo, hi): (Vec<f64>, Vec<f64>) =
            (0..problem.n_vars()).map(|i| problem.bounds(i)).unzip();
        job.push(json!({
            "key": p.key,
            "formulas": (opts.formulas)(&p.model)?,
            "params": p.compiled.params(&p.model, &p.modes),
            "lo": lo,
            "hi": hi,
            "starts": optimize::start_points(&problem, &settings(p)),
        }));
    }
    let peer = run_peer(
        opts,
        &json!({"alternatives": job, "options": ipopt_options()}),
    )?;
    let theirs = peer["alternatives"]
        .as_array()
        .context("the peer gave no alternatives")?;
    if theirs.len() != prepared.len() {
        bail!(
            "the peer solved {} alternatives of {}",
            theirs.len(),
            prepared.len()
        );
    }
    let mut results = Vec::new();
    for (p, t) in prepared.iter().zip(theirs) {
        let problem = ModelProblem::new(&p.model, &p.compiled, &p.modes);
        let o = settings(p);
        let clock = Stopwatch::start();
        let sol = optimize::minimize(&problem, &o);
        let cpu_ms = clock.cpu_ms();
        let target = o.target.unwrap_or(f64::INFINITY);
        let omega = p.model.omega(&p.model.full_vars(&sol.x), &p.modes);
        let ours = Side {
            reached: sol.f <= target,
            met: meets_target(&p.model, sol.feasible, omega),
            starts_run: sol.starts_run,
            evaluations: sol.evaluations,
            cpu_ms,
        };
        let (ipopt, iterations, hessians) = judge_peer(p, &problem, &o, t)?;
        let deviations = formula_deviations(&problem, &o, t)?;
        let formula_branch_starts = deviations
            .iter()
            .filter(|&&d| d.is_nan() || d > BRANCH_DEVIATION)
            .count();
        results.push(AltResult {
            key: p.key.clone(),
            n: problem.n_vars(),
            m: problem.n_constraints(),
            ours,
            ipopt,
            ipopt_iterations: iterations,
            ipopt_hessians: hessians,
            formula_deviation: median(&deviations),
            formula_branch_starts,
        });
    }
    Ok(OptimizeBench {
        task: task.name.clone(),
        n_max,
        enumerated: plan.alternatives,
        starts: opts.starts,
        peer: format!("IPOPT in CasADi {}", peer["casadi"].as_str().unwrap_or("?")),
        ipopt_options: ipopt_options(),
        alternatives: results,
    })
}

/// IPOPT's starts of one alternative, judged by our model and cut by the search's stopping
/// rule; with its iterations and Hessian evaluations over the starts counted.
fn judge_peer(
    p: &Prepared,
    problem: &ModelProblem<'_>,
    o: &optimize::Options,
    t: &serde_json::Value,
) -> Result<(Side, usize, usize)> {
    let starts = t["starts"].as_array().context("the peer gave no starts")?;
    let target = o.target.unwrap_or(f64::INFINITY);
    let mut e = Evaluation::new(problem.n_vars(), problem.n_constraints());
    let (mut best_f, mut best_feasible_f) = (f64::INFINITY, f64::INFINITY);
    let mut side = Side {
        reached: false,
        met: false,
        starts_run: 0,
        evaluations: 0,
        cpu_ms: 0.0,
    };
    let (mut iterations, mut hessians) = (0, 0);
    for (k, s) in starts.iter().enumerate() {
        let x: Vec<f64> = s["x"]
            .as_array()
            .context("a start without its point")?
            .iter()
            .map(|v| v.as_f64().unwrap_or(f64::NAN))
            .collect();
        let count = |key: &str| s[key].as_u64().unwrap_or(0) as usize;
        side.starts_run = k + 1;
        side.evaluations += count("f_calls");
        side.cpu_ms += s["cpu_s"].as_f64().unwrap_or(0.0) * 1e3;
        iterations += count("iterations");
        hessians += count("hess_calls");
        if x.len() != problem.n_vars() || x.iter().any(|v| !v.is_finite()) {
            continue;
        }
        problem.eval(&x, &mut e);
        let feasible = e.violation() <= o.feasibility_tol;
        best_f = best_f.min(e.f);
        if feasible {
            best_feasible_f = best_feasible_f.min(e.f);
        }
        let omega = p.model.omega(&p.model.full_vars(&x), &p.modes);
        if meets_target(&p.model, feasible, omega) && e.f <= target {
            side.met = true;
            break;
        }
        if optimize::gives_up(o, k + 1, best_feasible_f) {
            break;
        }
    }
    side.reached = side.met || best_f <= target;
    Ok((side, iterations, hessians))
}

/// A start whose formula deviation exceeds this is counted as lying on a branch.
pub const BRANCH_DEVIATION: f64 = 1e-6;

/// Per start: the largest relative difference between the peer's formula values and our
/// compiled model's, over objective and constraints (NaN where either is not finite).
fn formula_deviations(
    problem: &ModelProblem<'_>,
    o: &optimize::Options,
    t: &serde_json::Value,
) -> Result<Vec<f64>> {
    let theirs = t["at_starts"]
        .as_array()
        .context("the peer gave no check values")?;
    let mut e = Evaluation::new(problem.n_vars(), problem.n_constraints());
    let mut out = Vec::new();
    for (x, values) in optimize::start_points(problem, o).iter().zip(theirs) {
        problem.eval(x, &mut e);
        let mine = std::iter::once(e.f).chain(e.g.iter().copied());
        let values = values.as_array().context("check values not a list")?;
        let d = values
            .iter()
            .zip(mine)
            .map(|(a, b)| (a.as_f64().unwrap_or(f64::NAN) - b).abs() / (1.0 + b.abs()))
            .fold(0.0, |m: f64, d| {
                if m.is_nan() || d.is_nan() {
                    f64::NAN
                } else {
                    m.max(d)
                }
            });
        out.push(d);
    }
    Ok(out)
}

/// The median of non-negative values (a NaN counts as the largest; NaN when empty).
fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    // Deviations are absolute values: any NaN among them is positive, which total_cmp
    // orders above every number.
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// Run the peer script on `job`; its results.
fn run_peer(opts: &OptimizeBenchOptions<'_>, job: &serde_json::Value) -> Result<serde_json::Value> {
    let script = super::peer_script(opts.script, "ipopt_optimize.py")?;
    let dir = super::scratch_dir("ipopt");
    std::fs::create_dir_all(&dir).with_context(|| format!("{}", dir.display()))?;
    let (job_path, out_path) = (dir.join("job.json"), dir.join("out.json"));
    let result = std::fs::write(&job_path, job.to_string())
        .with_context(|| format!("{}", job_path.display()))
        .and_then(|()| peer_output(opts, &script, &job_path, &out_path));
    let _ = std::fs::remove_dir_all(&dir);
    result
}

/// Run the script on the job file; the results file's JSON.
fn peer_output(
    opts: &OptimizeBenchOptions<'_>,
    script: &Path,
    job_path: &Path,
    out_path: &Path,
) -> Result<serde_json::Value> {
    let out = std::process::Command::new(opts.python)
        .arg(script)
        .arg(job_path)
        .arg(out_path)
        .output()
        .with_context(|| format!("cannot run {}", opts.python))?;
    let text = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        bail!(
            "the IPOPT peer failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    let last: serde_json::Value = serde_json::from_str(text.lines().last().unwrap_or(""))
        .with_context(|| format!("the IPOPT peer printed no JSON object: {text}"))?;
    if let Some(why) = last.get("skipped") {
        bail!(
            "the IPOPT peer cannot run: {} (--python names a Python with CasADi)",
            why.as_str().unwrap_or("?")
        );
    }
    let results =
        std::fs::read_to_string(out_path).with_context(|| format!("{}", out_path.display()))?;
    Ok(serde_json::from_str(&results)?)
}
