//! `foldsynth model TASK --graph SEQ [--modes …] [--candidate K] [--at VARS.json]
//! [--formulas FORMAT [--no-simplify] [--gradient] [--output FILE]] [--vertex-modes]
//! [--json]`: the optimization model of one graph, compiled, evaluated and verified.

use crate::check::verify::{Tolerances, VerifyReport, verify};
use crate::compile::Options;
use crate::expr::Format;
use crate::grammar::{CreaseGraph, VarKind};
use crate::model::compiled::{CompiledModel, ModelProblem, objective_target};
use crate::model::numeric::{Evaluated, sample_times};
use crate::model::{Model, Plan};
use crate::simulate::crossval::{CyclicVerdict, verify_cyclic};
use crate::task::Task;
use anyhow::{Context, Result, bail};
use serde_json::json;
use std::path::{Path, PathBuf};

/// Arguments of `foldsynth model`.
#[derive(Debug, clap::Args)]
pub struct ModelArgs {
    /// The task file (e.g. grammar/gripper.toml).
    pub task: PathBuf,
    /// The graph as a rule sequence, e.g. "2, 3, (4, 8), 4, (7, 8)".
    #[arg(long)]
    pub graph: String,
    /// Rigid body modes of the internal vertices in extension order, e.g. "up,down,up"
    /// (default: all up).
    #[arg(long)]
    pub modes: Option<String>,
    /// Gripping candidate: 1, 2 or 3 (the successors s1, s2, s3 of the vertex extended last).
    #[arg(long, default_value_t = 1)]
    pub candidate: usize,
    /// Evaluate at these variable values: a JSON object {"name": value, …} (or a design
    /// file with such a "variables" object). Default: the middle of every bound.
    #[arg(long, value_name = "VARS.json")]
    pub at: Option<PathBuf>,
    /// Print the objective and constraint formulas in this format
    /// (plain, latex, mathematica, python, dot), simplified by egg, with a header that
    /// says what each simplification removed.
    #[arg(long, value_name = "FORMAT")]
    pub formulas: Option<String>,
    /// With --formulas: print the graph as built, before egg.
    #[arg(long, requires = "formulas")]
    pub no_simplify: bool,
    /// With --formulas: also print the gradient of the objective and of every constraint
    /// with respect to the free variables.
    #[arg(long, requires = "formulas")]
    pub gradient: bool,
    /// With --formulas: write them to this file instead of standard output.
    #[arg(long, value_name = "FILE", requires = "formulas")]
    pub output: Option<PathBuf>,
    /// Optimize this alternative first (multi-start augmented Lagrangian), then evaluate
    /// and verify at the optimum.
    #[arg(long)]
    pub optimize: bool,
    /// Starting points for --optimize, 1 to 1000.
    #[arg(long, default_value_t = 32, value_parser = crate::limits::count::<1, { crate::limits::STARTS_MAX as u64 }>)]
    pub starts: usize,
    /// Seed for --optimize.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Number of states of the verification sweep over [0, t_max] (as `synthesize --sweep`), 2 to 10000.
    #[arg(long, default_value_t = crate::search::SearchOptions::default().sweep, value_parser = crate::limits::count::<2, { crate::limits::SWEEP_MAX as u64 }>)]
    pub sweep: usize,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Write the design (variables, verification, pattern with 33 frames, metadata) to
    /// this JSON file, as `synthesize` writes `designs/<id>.json`: `foldsynth export` and
    /// `foldsynth simulate` read it.
    #[arg(long, value_name = "DESIGN.json")]
    pub save: Option<PathBuf>,
    /// Judge every assignment of one rigid body mode per internal vertex at this point
    /// (images of a symmetric pattern included: the star pattern's 2^8, thesis Sec. 4.3.2):
    /// rigid over the sweep, free of self-intersection, clear of the obstacles; print the
    /// counts (and with --json every assignment's verdict).
    #[arg(long)]
    pub vertex_modes: bool,
}

/// Parse "up,down,…" into ±1 for `n` internal vertices.
pub fn parse_modes(text: Option<&str>, n: usize) -> Result<Vec<f64>> {
    let Some(text) = text else {
        return Ok(vec![1.0; n]);
    };
    let modes: Vec<f64> = text
        .split(',')
        .map(|m| match crate::kinematics::Mode::parse(m) {
            Some(m) => Ok(m.sign()),
            None => bail!("--modes: '{}' is not a mode; use up or down", m.trim()),
        })
        .collect::<Result<_>>()?;
    if modes.len() != n {
        bail!(
            "--modes: the graph has {n} internal vertices, {} modes were given",
            modes.len()
        );
    }
    Ok(modes)
}

/// Read variable values for the model's free variables from a JSON file.
pub fn read_vars(model: &Model, path: &Path) -> Result<Vec<f64>> {
    let text = crate::limits::read_text(path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{}: not valid JSON", path.display()))?;
    let obj = v.get("variables").unwrap_or(&v);
    let obj = obj.as_object().with_context(|| {
        format!(
            "{}: expected an object {{\"name\": value, …}} of variables",
            path.display()
        )
    })?;
    let mut x = middle(model);
    for (name, value) in obj {
        let Some(k) = model
            .free
            .iter()
            .position(|&i| model.plan.variables[i].name == *name)
        else {
            let known: Vec<&str> = model
                .free
                .iter()
                .map(|&i| model.plan.variables[i].name.as_str())
                .collect();
            bail!(
                "{}: unknown variable '{name}'; this model's variables are {}",
                path.display(),
                known.join(", ")
            );
        };
        let value = value.as_f64().filter(|v| v.is_finite()).with_context(|| {
            format!(
                "{}: variable '{name}' must be a finite number",
                path.display()
            )
        })?;
        let (lo, hi) = model.var_bounds(model.free[k]);
        if !(lo..=hi).contains(&value) {
            bail!(
                "{}: variable '{name}' = {value} is outside its bounds [{lo}, {hi}]",
                path.display()
            );
        }
        x[k] = value;
    }
    Ok(x)
}

/// The middle of every free variable's bounds.
pub fn middle(model: &Model) -> Vec<f64> {
    model
        .free
        .iter()
        .map(|&i| {
            let (lo, hi) = model.var_bounds(i);
            0.5 * (lo + hi)
        })
        .collect()
}

/// Run `foldsynth model`.
pub fn run(args: ModelArgs) -> Result<()> {
    let task = Task::load(&args.task)?;
    let graph = CreaseGraph::from_sequence(&task, &args.graph)
        .with_context(|| format!("--graph '{}'", args.graph))?;
    if !(1..=3).contains(&args.candidate) {
        bail!("--candidate must be 1, 2 or 3 (the successors of the vertex extended last)");
    }
    let plan = Plan::new(&graph)?;
    let model = Model::from_plan(plan, &task, args.candidate - 1)?;
    let n = model.plan.n_modes;
    let modes = parse_modes(args.modes.as_deref(), n)?;
    if let Some(fmt) = &args.formulas {
        return print_formulas(&args, fmt, &model, &task.name);
    }
    let mut x = match &args.at {
        Some(p) => read_vars(&model, p)?,
        None => middle(&model),
    };
    let compiled = CompiledModel::new(&model, &Options::default())?;
    if args.optimize {
        x = optimize(&args, &model, &compiled, &modes);
    }
    if args.vertex_modes {
        return print_vertex_modes(&args, &task, &model, &x);
    }
    let e = Evaluation::new(&model, &compiled, x, modes, args.sweep);
    if let Some(path) = &args.save {
        save_design(path, &task, &model, &e)?;
    }
    if args.json {
        let out = model_json(&args, &task, &model, &compiled, &e);
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    print_model(&args, &task, &model, &compiled, &e);
    if let Some(path) = &args.save {
        println!("\ndesign written to {}", path.display());
    }
    Ok(())
}

/// `--vertex-modes`: the census of every per-vertex mode assignment at `x`.
fn print_vertex_modes(args: &ModelArgs, task: &Task, model: &Model, x: &[f64]) -> Result<()> {
    let all = crate::search::modes::census(task, model, x, args.sweep)
        .map_err(|e| anyhow::anyhow!("--vertex-modes: {e}"))?;
    let rigid = all.iter().filter(|v| v.rigid_over_motion).count();
    let folds = all.iter().filter(|v| v.folds()).count();
    if args.json {
        let out = json!({
            "sequence": model.plan.sequence,
            "internal_vertices": model.plan.internal.iter().map(|&v| format!("v{}", model.plan.vertices[v].name)).collect::<Vec<_>>(),
            "assignments": all.len(),
            "rigid_over_motion": rigid,
            "fold": folds,
            "verdicts": all,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!(
        "{} mode assignments of {} ({} internal vertices, one mode each), {} states over [0, t_max]:",
        all.len(),
        model.plan.sequence,
        model.plan.internal.len(),
        args.sweep
    );
    println!("  rigid over the whole motion                  {rigid}");
    println!("  … also free of self-intersection and obstacles {folds}");
    for v in all.iter().filter(|v| v.folds()) {
        println!("    {}", v.modes.join(","));
    }
    Ok(())
}

/// `--formulas`: the objective and constraint formulas instead of an evaluation.
fn print_formulas(args: &ModelArgs, fmt: &str, model: &Model, task: &str) -> Result<()> {
    let format: Format = fmt
        .parse()
        .map_err(|e| anyhow::anyhow!("--formulas: {e}"))?;
    let opts = super::formulas::ModelFormulaOptions {
        format,
        simplify: !args.no_simplify,
        gradient: args.gradient,
    };
    let text = super::formulas::model_formulas(model, task, opts)?;
    super::formulas::emit(&text, args.output.as_deref())
}

/// `--optimize`: the optimized free variables (reported on stderr).
fn optimize(args: &ModelArgs, model: &Model, compiled: &CompiledModel, modes: &[f64]) -> Vec<f64> {
    let problem = ModelProblem::new(model, compiled, modes);
    let opts = crate::optimize::Options {
        starts: args.starts,
        seed: args.seed,
        target: Some(objective_target(model)),
        // An area objective has no target to stop at: every start runs, as in a search.
        all_starts: crate::model::compiled::all_starts(model),
        max_outer: if model.plan.sinks.is_empty() {
            crate::optimize::Options::default().max_outer
        } else {
            crate::model::cycle::MAX_OUTER
        },
        ..Default::default()
    };
    let t0 = std::time::Instant::now();
    let mut sol = crate::optimize::minimize(&problem, &opts);
    // Cyclic patterns: Newton on the compatibility equations, to rounding.
    crate::model::cycle::polish_solution(
        &problem,
        model,
        modes,
        &mut sol,
        opts.feasibility_tol,
        opts.target,
    );
    eprintln!(
        "optimized in {:.1} ms: {} starts, {} evaluations, feasible {}, target met {}",
        t0.elapsed().as_secs_f64() * 1e3,
        sol.starts_run,
        sol.evaluations,
        sol.feasible,
        sol.met_target
    );
    sol.x
}

/// The model evaluated and verified at one point.
struct Evaluation {
    /// The free variables.
    x: Vec<f64>,
    /// The modes.
    modes: Vec<f64>,
    /// The compiled function's output buffer at `x`.
    buf: Vec<f64>,
    /// The objective Ω by the f64 model.
    omega: f64,
    /// The verification sweep.
    report: VerifyReport,
    /// A cyclic pattern's verdict.
    cycle: Option<CyclicVerdict>,
    /// ψ at `x`.
    constraint_values: Vec<f64>,
}

impl Evaluation {
    fn new(
        model: &Model,
        compiled: &CompiledModel,
        x: Vec<f64>,
        modes: Vec<f64>,
        sweep: usize,
    ) -> Evaluation {
        let params = compiled.params(model, &modes);
        let mut buf = vec![0.0; compiled.buffer_len()];
        compiled.call(&x, &params, &mut buf);
        let full = model.full_vars(&x);
        let omega = model.omega(&full, &modes);
        let design = Evaluated::new(&model.plan, full.clone(), modes.clone());
        let report = verify(
            &design,
            &sample_times(model.t_max, sweep.max(2)),
            &Tolerances::default(),
        );
        // A cyclic pattern (r2′): the compatibility sweep and the bar-and-hinge simulation.
        let cycle = (!model.plan.sinks.is_empty()).then(|| {
            verify_cyclic(
                model,
                &full,
                &modes,
                sweep.max(2),
                Tolerances::default().geometry_margin,
            )
        });
        let layout = &compiled.compiled.layout;
        let constraint_values: Vec<f64> = (0..compiled.n_constraints)
            .map(|k| buf[layout.value(k + 1)])
            .collect();
        Evaluation {
            x,
            modes,
            buf,
            omega,
            report,
            cycle,
            constraint_values,
        }
    }
}

/// "up" or "down".
fn mode_name(m: f64) -> &'static str {
    if m > 0.0 { "up" } else { "down" }
}

/// `--json`: the model, the point and its verification.
fn model_json(
    args: &ModelArgs,
    task: &Task,
    model: &Model,
    compiled: &CompiledModel,
    e: &Evaluation,
) -> serde_json::Value {
    let rep = &compiled.compiled.report;
    let layout = &compiled.compiled.layout;
    let variables: Vec<_> = model
        .free
        .iter()
        .enumerate()
        .map(|(k, &i)| {
            let v = &model.plan.variables[i];
            let (lo, hi) = model.var_bounds(i);
            json!({"name": v.name, "kind": kind(v.kind), "lower": lo, "upper": hi, "value": e.x[k]})
        })
        .collect();
    let constraints: Vec<_> = (0..compiled.n_constraints)
        .map(|k| json!({"label": model.constraint_label(k), "value": e.constraint_values[k]}))
        .collect();
    let mut out = json!({
        "task": task.name,
        "graph": model.plan.sequence,
        "internal_vertices": model.plan.n_modes,
        "modes": e.modes.iter().map(|m| mode_name(*m)).collect::<Vec<_>>(),
        "candidate": args.candidate,
        "gripping_vertex": model.plan.vertices[model.gripping].name,
        "variables": variables,
        "dropped": model.plan.variables.iter().enumerate().filter(|(i, _)| !model.free.contains(i)).map(|(_, v)| &v.name).collect::<Vec<_>>(),
        "constraints": constraints,
        "objective": e.omega,
        "objective_compiled": e.buf[layout.value(0)],
        "meets_target": e.omega <= model.threshold && e.constraint_values.iter().all(|g| *g >= -1e-9),
        "threshold": model.threshold,
        "counts": {"before": rep.input, "after": rep.simplified, "with_gradient": rep.with_gradients},
        "build_ms": compiled.build_ms,
        "compile_ms": compiled.total_ms,
        "verification": e.report,
    });
    if let Some(c) = &e.cycle {
        out["cycle"] = json!(c);
    }
    out
}

/// The text report: the model, its variables and constraints at the point, the compiled
/// graph, the objective and the verification.
fn print_model(
    args: &ModelArgs,
    task: &Task,
    model: &Model,
    compiled: &CompiledModel,
    e: &Evaluation,
) {
    let gripping = model.plan.vertices[model.gripping].name;
    println!(
        "model of {} for task '{}', gripping vertex v{gripping} (candidate {})",
        model.plan.sequence, task.name, args.candidate
    );
    println!(
        "internal vertices (extension order): {}  modes: {}",
        model
            .plan
            .internal
            .iter()
            .map(|v| format!("v{}", model.plan.vertices[*v].name))
            .collect::<Vec<_>>()
            .join(", "),
        e.modes
            .iter()
            .map(|m| mode_name(*m))
            .collect::<Vec<_>>()
            .join(", ")
    );
    print_variables(model, &e.x);
    println!("\nconstraints ψ (g ≥ 0), value at this point:");
    for (k, g) in e.constraint_values.iter().enumerate() {
        println!(
            "  {:>12.6}{}  {}",
            g,
            if *g < -1e-9 { " ✗" } else { "  " },
            model.constraint_label(k)
        );
    }
    let rep = &compiled.compiled.report;
    println!(
        "\nexpression graph: {} operations as built, {} after egg, {} with all gradients; build {:.2} ms, build→native {:.2} ms",
        rep.input.ops,
        rep.simplified.ops,
        rep.with_gradients.ops,
        compiled.build_ms,
        compiled.total_ms
    );
    println!(
        "objective Ω = {:.6e} (threshold {:.1e}; compiled objective {:.6e}, target {:.3e})",
        e.omega,
        model.threshold,
        e.buf[compiled.compiled.layout.value(0)],
        objective_target(model)
    );
    print_verification(&e.report, model.t_max);
    if let Some(c) = &e.cycle {
        print_cycle(c, model.t_max);
    }
}

/// The free variables with their bounds and values, and the dropped ones.
fn print_variables(model: &Model, x: &[f64]) {
    println!("\nvariables (Φ_opt):");
    for (k, &i) in model.free.iter().enumerate() {
        let v = &model.plan.variables[i];
        let (lo, hi) = model.var_bounds(i);
        println!(
            "  {:<10} {:<7} [{lo:.6}, {hi:.6}]  = {:.6}",
            v.name,
            kind(v.kind),
            x[k]
        );
    }
    let dropped: Vec<&str> = model
        .plan
        .variables
        .iter()
        .enumerate()
        .filter(|(i, _)| !model.free.contains(i))
        .map(|(_, v)| v.name.as_str())
        .collect();
    if !dropped.is_empty() {
        println!(
            "  (influence nothing, drawn at their lower bound: {})",
            dropped.join(", ")
        );
    }
}

/// The verification sweep's figures.
fn print_verification(report: &VerifyReport, t_max: f64) {
    println!(
        "\nverification over {} states in [0, {:.6}]:",
        report.states, t_max
    );
    println!("  isometry max          {:.3e}", report.isometry_max);
    println!("  closure max           {:.3e}", report.closure_max);
    println!("  developability max    {:.3e}", report.developability_max);
    println!("  fold angle max        {:.3e}", report.fold_angle_max);
    println!(
        "  rigid over the motion {}  (at t_max: {}; smallest margin {:.3e} at t = {:.6})",
        report.rigid_over_motion, report.rigid_at_tmax, report.min_margin, report.min_margin_t
    );
}

/// The verdict on a cyclic design, in words.
fn print_cycle(c: &CyclicVerdict, t_max: f64) {
    let s = &c.sweep;
    println!(
        "\ncyclic pattern ({} r2′ sink{}): compatibility over {} states in [0, {t_max:.6}] ({} rigid):",
        s.sinks,
        if s.sinks == 1 { "" } else { "s" },
        s.states,
        s.checked_states
    );
    println!(
        "  dihedral angles from both ends, max difference  {:.3e}  (t = {:.6})",
        s.compatibility_max, s.compatibility_t
    );
    println!(
        "  positions through every facet, max disagreement {:.3e}  (t = {:.6})",
        s.position_max, s.position_t
    );
    println!(
        "  largest fold-angle change between states      {:.3e}  (after t = {:.6}; at most {} for one continuous motion)",
        s.jump_max,
        s.jump_t,
        crate::check::cycle::JUMP_TOL
    );
    println!(
        "  largest fold angle of the straight crease        {:.3e}{}",
        s.shared_fold_max,
        if s.folds_shared_crease() {
            ""
        } else {
            "  (it never folds: the cycle closes trivially)"
        }
    );
    match (&c.simulation, &c.error) {
        (Some(r), _) => println!(
            "  bar-and-hinge simulation ({} steps, driven by G0's crease): Γ = {:.3e}, max δ = {:.3e}, max |x − X_PTU| = {:.3e}: {}",
            r.steps,
            r.gamma,
            r.max_delta,
            r.max_position_error,
            if r.agrees { "agrees" } else { "DISAGREES" }
        ),
        (None, Some(e)) => println!("  bar-and-hinge simulation failed: {e}"),
        (None, None) => println!("  bar-and-hinge simulation not run: the sweep failed"),
    }
    println!(
        "  verdict: {}",
        if c.passes {
            "folds rigidly (both verifications pass)"
        } else {
            "does not fold rigidly over the whole motion"
        }
    );
}

/// Write a design file (see [`ModelArgs::save`]).
fn save_design(path: &Path, task: &Task, model: &Model, e: &Evaluation) -> Result<()> {
    let (x, modes) = (&e.x, &e.modes);
    let names: Vec<String> = modes.iter().map(|m| mode_name(*m).to_string()).collect();
    let full = model.full_vars(x);
    let design = Evaluated::new(&model.plan, full.clone(), modes.to_vec());
    let pattern = design.pattern(&sample_times(model.t_max, 33));
    let mut meta = crate::search::model_meta(task, model, &names, e.omega);
    meta.extra
        .insert("candidate".into(), json!(model.candidate + 1));
    let variables: std::collections::BTreeMap<&str, f64> = model
        .free
        .iter()
        .zip(x)
        .map(|(&i, v)| (model.plan.variables[i].name.as_str(), *v))
        .collect();
    let all: std::collections::BTreeMap<&str, f64> = model
        .plan
        .variables
        .iter()
        .zip(&full)
        .map(|(v, x)| (v.name.as_str(), *x))
        .collect();
    let doc = json!({
        "task": task.name,
        "sequence": model.plan.sequence,
        "candidate": model.candidate + 1,
        "gripping_vertex": model.plan.vertices[model.gripping].name,
        "modes": names,
        "objective": e.omega,
        "threshold": model.threshold,
        "variables": variables,
        "all_variables": all,
        "verification": e.report,
        "cycle": e.cycle,
        "pattern": pattern,
        "meta": meta,
    });
    std::fs::write(path, serde_json::to_string_pretty(&doc)?)
        .with_context(|| format!("cannot write {}", path.display()))
}

fn kind(k: VarKind) -> &'static str {
    match k {
        VarKind::Sector => "sector",
        VarKind::Length => "length",
    }
}
