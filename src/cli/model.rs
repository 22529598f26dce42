//! `foldsynth model TASK --graph SEQ [--modes …] [--candidate K] [--at VARS.json]
//! [--formulas FORMAT] [--json]`: the optimization model of one graph, compiled, evaluated
//! and verified.

use crate::check::verify::{Tolerances, verify};
use crate::compile::Options;
use crate::expr::{Format, Names, print::print};
use crate::grammar::{CreaseGraph, VarKind};
use crate::model::compiled::{CompiledModel, ModelProblem, objective_target, symbolic};
use crate::model::numeric::{Evaluated, sample_times};
use crate::model::{Model, Plan};
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
    /// (plain, latex, mathematica, python, dot).
    #[arg(long, value_name = "FORMAT")]
    pub formulas: Option<String>,
    /// Optimize this alternative first (multi-start augmented Lagrangian), then evaluate
    /// and verify at the optimum.
    #[arg(long)]
    pub optimize: bool,
    /// Starting points for --optimize.
    #[arg(long, default_value_t = 32)]
    pub starts: usize,
    /// Seed for --optimize.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Number of states of the verification sweep over [0, t_max] (as `synthesize --sweep`).
    #[arg(long, default_value_t = crate::search::SearchOptions::default().sweep)]
    pub sweep: usize,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
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
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
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
    let n = model.plan.internal.len();
    let modes = parse_modes(args.modes.as_deref(), n)?;
    let mut x = match &args.at {
        Some(p) => read_vars(&model, p)?,
        None => middle(&model),
    };
    let compiled = CompiledModel::new(&model, &Options::default())?;
    if args.optimize {
        let problem = ModelProblem::new(&model, &compiled, &modes);
        let opts = crate::optimize::Options {
            starts: args.starts,
            seed: args.seed,
            target: Some(objective_target(&model)),
            ..Default::default()
        };
        let t0 = std::time::Instant::now();
        let sol = crate::optimize::minimize(&problem, &opts);
        eprintln!(
            "optimized in {:.1} ms: {} starts, {} evaluations, feasible {}, target met {}",
            t0.elapsed().as_secs_f64() * 1e3,
            sol.starts_run,
            sol.evaluations,
            sol.feasible,
            sol.met_target
        );
        x = sol.x;
    }
    let params = compiled.params(&model, &modes);
    let mut buf = vec![0.0; compiled.buffer_len()];
    compiled.call(&x, &params, &mut buf);
    let full = model.full_vars(&x);
    let omega = model.omega(&full, &modes);
    let design = Evaluated::new(&model.plan, full.clone(), modes.clone());
    let report = verify(
        &design,
        &sample_times(model.t_max, args.sweep.max(2)),
        &Tolerances::default(),
    );
    let rep = &compiled.compiled.report;
    let layout = &compiled.compiled.layout;
    let constraint_values: Vec<f64> = (0..compiled.n_constraints)
        .map(|k| buf[layout.value(k + 1)])
        .collect();
    let gripping = model.plan.vertices[model.gripping].name;

    if let Some(fmt) = &args.formulas {
        let format: Format = fmt
            .parse()
            .map_err(|e| anyhow::anyhow!("--formulas: {e}"))?;
        let (ctx, outputs) = symbolic(&model);
        let mut named = vec![("objective".to_string(), ctx.node_id(&outputs[0]))];
        for (k, o) in outputs[1..].iter().enumerate() {
            named.push((format!("g{}", k + 1), ctx.node_id(o)));
        }
        let names = Names {
            vars: model
                .free
                .iter()
                .map(|&i| ascii_name(&model.plan.variables[i].name))
                .collect(),
            params: (0..n)
                .map(|k| format!("M{}", k + 1))
                .chain((0..model.times.len()).map(|k| format!("t{k}")))
                .collect(),
        };
        println!("{}", print(&ctx.graph(), &named, &names, format));
        return Ok(());
    }

    if args.json {
        let variables: Vec<_> = model
            .free
            .iter()
            .enumerate()
            .map(|(k, &i)| {
                let v = &model.plan.variables[i];
                let (lo, hi) = model.var_bounds(i);
                json!({"name": v.name, "kind": kind(v.kind), "lower": lo, "upper": hi, "value": x[k]})
            })
            .collect();
        let constraints: Vec<_> = (0..compiled.n_constraints)
            .map(|k| json!({"label": model.constraint_label(k), "value": constraint_values[k]}))
            .collect();
        let out = json!({
            "task": task.name,
            "graph": model.plan.sequence,
            "internal_vertices": n,
            "modes": modes.iter().map(|m| if *m > 0.0 { "up" } else { "down" }).collect::<Vec<_>>(),
            "candidate": args.candidate,
            "gripping_vertex": gripping,
            "variables": variables,
            "dropped": model.plan.variables.iter().enumerate().filter(|(i, _)| !model.free.contains(i)).map(|(_, v)| &v.name).collect::<Vec<_>>(),
            "constraints": constraints,
            "objective": omega,
            "objective_compiled": buf[layout.value(0)],
            "meets_target": omega <= model.threshold && constraint_values.iter().all(|g| *g >= -1e-9),
            "threshold": model.threshold,
            "counts": {"before": rep.input, "after": rep.simplified, "with_gradient": rep.with_gradients},
            "build_ms": compiled.build_ms,
            "compile_ms": compiled.total_ms,
            "verification": report,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }

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
        modes
            .iter()
            .map(|m| if *m > 0.0 { "up" } else { "down" })
            .collect::<Vec<_>>()
            .join(", ")
    );
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
    println!("\nconstraints ψ (g ≥ 0), value at this point:");
    for (k, g) in constraint_values.iter().enumerate() {
        println!(
            "  {:>12.6}{}  {}",
            g,
            if *g < -1e-9 { " ✗" } else { "  " },
            model.constraint_label(k)
        );
    }
    println!(
        "\nexpression graph: {} operations as built, {} after egg, {} with all gradients; build {:.2} ms, build→native {:.2} ms",
        rep.input.ops,
        rep.simplified.ops,
        rep.with_gradients.ops,
        compiled.build_ms,
        compiled.total_ms
    );
    println!(
        "objective Ω = {omega:.6e} (threshold {:.1e}; compiled objective {:.6e}, target {:.3e})",
        model.threshold,
        buf[layout.value(0)],
        objective_target(&model)
    );
    println!(
        "\nverification over {} states in [0, {:.6}]:",
        report.states, model.t_max
    );
    println!("  isometry max          {:.3e}", report.isometry_max);
    println!("  closure max           {:.3e}", report.closure_max);
    println!("  developability max    {:.3e}", report.developability_max);
    println!("  fold angle max        {:.3e}", report.fold_angle_max);
    println!(
        "  rigid over the motion {}  (at t_max: {}; smallest margin {:.3e} at t = {:.6})",
        report.rigid_over_motion, report.rigid_at_tmax, report.min_margin, report.min_margin_t
    );
    Ok(())
}

fn kind(k: VarKind) -> &'static str {
    match k {
        VarKind::Sector => "sector",
        VarKind::Length => "length",
    }
}

/// Variable names for printers that need identifiers (α_5 → alpha_5, l_2,5 → l_2_5).
fn ascii_name(name: &str) -> String {
    name.replace('α', "alpha").replace([',', '\''], "_")
}
