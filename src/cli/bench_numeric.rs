//! `foldsynth bench numeric TASK|DESIGN`: one folding motion of one design, J + 1 states,
//! computed by the compiled PTU model and by the thesis's bar-and-hinge simulation
//! (Sec. 3), measured in one run and reported as a ratio.
//!
//! The PTU side evaluates every vertex's position at t₀ … t_J with the JIT-compiled
//! forward kinematics ([`CompiledMotion`]); the plain f64 path (the same generic code,
//! not compiled) is a second row. The simulation side runs the G0 drive of
//! [`crate::simulate::crossval`] over the same J steps, once with Eq. 2's bars and the
//! simulator's default settings, as in the thesis, and once with the rigid panels and
//! settings the cross-validation uses; no intersection
//! check on either side, so both compute kinematics only. Both motions are compared at
//! the end, so the times are of the same motion.

use super::bench::time_ns;
use super::model::{parse_modes, read_vars};
use crate::check::verify::{Tolerances, verify};
use crate::compile::Options;
use crate::grammar::CreaseGraph;
use crate::model::Model;
use crate::model::compiled::{CompiledModel, CompiledMotion, ModelProblem, objective_target};
use crate::model::numeric::{Evaluated, sample_times};
use crate::optimize;
use crate::simulate::crossval::{
    CrossvalOptions, add_panel_apexes, branch_offsets, design_drive, g0_input,
};
use crate::simulate::{SimInput, simulate};
use crate::task::Task;
use anyhow::{Context, Result, bail};
use serde_json::json;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Arguments of `foldsynth bench numeric`.
#[derive(Debug, clap::Args)]
pub struct NumericBenchArgs {
    /// A task file (.toml: a design of --graph is optimized first) or a design JSON
    /// (`OUT/designs/<id>.json` of `foldsynth synthesize`).
    pub target: PathBuf,
    /// With a design JSON: its task file (default: `grammar/<task>.toml`, after the
    /// design's "task").
    #[arg(long)]
    pub task: Option<PathBuf>,
    /// With a task file: the graph as a rule sequence.
    #[arg(long, default_value = "2, 3, (4, 8), 4, (7, 8)")]
    pub graph: String,
    /// With a task file: the modes, e.g. "up,down,up" (default: the first assignment,
    /// in binary order from all up, that gives a design rigid over the whole motion).
    #[arg(long)]
    pub modes: Option<String>,
    /// With a task file: gripping candidate 1, 2 or 3.
    #[arg(long, default_value_t = 1)]
    pub candidate: usize,
    /// Number of folding steps J (the motion has J + 1 states, t = 0 … t_max).
    #[arg(long, default_value_t = 32, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub steps: u64,
    /// Milliseconds of measurement per row.
    #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u64).range(1..=crate::limits::BENCH_MILLIS_MAX))]
    pub millis: u64,
    /// Print one JSON object (times in nanoseconds per motion).
    #[arg(long)]
    pub json: bool,
}

/// The design being measured.
struct Design {
    model: Model,
    free: Vec<f64>,
    modes: Vec<f64>,
    name: String,
}

fn modes_of(bits: u32, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| if bits >> i & 1 == 1 { -1.0 } else { 1.0 })
        .collect()
}

/// Optimize a design of `args.graph` on `task` that is rigid over its whole motion.
fn optimized(task: &Task, args: &NumericBenchArgs) -> Result<Design> {
    let graph = CreaseGraph::from_sequence(task, &args.graph)
        .with_context(|| format!("--graph '{}'", args.graph))?;
    if !(1..=3).contains(&args.candidate) {
        bail!("--candidate must be 1, 2 or 3");
    }
    let model = Model::new(&graph, task, args.candidate - 1)?;
    let n = model.plan.internal.len();
    let tries: Vec<Vec<f64>> = match &args.modes {
        Some(m) => vec![parse_modes(Some(m), n)?],
        None => (0..1u32 << n).map(|b| modes_of(b, n)).collect(),
    };
    let compiled = CompiledModel::new(&model, &Options::default())?;
    let ts = sample_times(model.t_max, 181);
    for modes in tries {
        let problem = ModelProblem::new(&model, &compiled, &modes);
        let sol = optimize::minimize(
            &problem,
            &optimize::Options {
                starts: 16,
                target: Some(objective_target(&model)),
                ..Default::default()
            },
        );
        if !sol.feasible {
            continue;
        }
        let design = Evaluated::new(&model.plan, model.full_vars(&sol.x), modes.clone());
        if verify(&design, &ts, &Tolerances::default()).rigid_over_motion {
            let name = format!("optimized, modes {}", mode_names(&modes));
            return Ok(Design {
                model,
                free: sol.x,
                modes,
                name,
            });
        }
    }
    bail!(
        "no design of graph '{}' with {} is feasible and rigid over the whole motion; try another --graph or --modes",
        args.graph,
        args.modes
            .as_deref()
            .map_or("any modes".to_string(), |m| format!("modes {m}"))
    )
}

fn mode_names(modes: &[f64]) -> String {
    modes
        .iter()
        .map(|&m| if m > 0.0 { "up" } else { "down" })
        .collect::<Vec<_>>()
        .join(",")
}

/// Rebuild a design JSON's model from its task, sequence, candidate, modes and variables.
fn from_design_file(path: &Path, task_flag: Option<&Path>) -> Result<Design> {
    let text = crate::limits::read_text(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{}: not valid JSON", path.display()))?;
    let field = |k: &str| {
        v.get(k).with_context(|| {
            format!(
                "{}: field '{k}' is missing; expected a design JSON written by `foldsynth synthesize`",
                path.display()
            )
        })
    };
    let task_path = match task_flag {
        Some(p) => p.to_path_buf(),
        None => {
            let name = field("task")?
                .as_str()
                .with_context(|| format!("{}: 'task' must be a string", path.display()))?;
            let p = PathBuf::from(format!("grammar/{name}.toml"));
            if !p.is_file() {
                bail!(
                    "{}: its task '{name}' is not at {}; give the task file with --task",
                    path.display(),
                    p.display()
                );
            }
            p
        }
    };
    let task = Task::load(&task_path)?;
    let sequence = field("sequence")?
        .as_str()
        .with_context(|| format!("{}: 'sequence' must be a string", path.display()))?;
    let graph = CreaseGraph::from_sequence(&task, sequence)
        .with_context(|| format!("{}: sequence '{sequence}'", path.display()))?;
    let candidate = field("candidate")?
        .as_u64()
        .filter(|c| (1..=3).contains(c))
        .with_context(|| format!("{}: 'candidate' must be 1, 2 or 3", path.display()))?;
    let model = Model::new(&graph, &task, candidate as usize - 1)?;
    let modes_text: Vec<&str> = field("modes")?
        .as_array()
        .and_then(|a| a.iter().map(|m| m.as_str()).collect::<Option<Vec<_>>>())
        .with_context(|| {
            format!(
                "{}: 'modes' must be a list of \"up\"/\"down\"",
                path.display()
            )
        })?;
    let modes = parse_modes(Some(&modes_text.join(",")), model.plan.internal.len())
        .with_context(|| format!("{}: modes", path.display()))?;
    let free = read_vars(&model, path)?;
    let name = v
        .get("id")
        .and_then(|i| i.as_str())
        .unwrap_or(sequence)
        .to_string();
    Ok(Design {
        model,
        free,
        modes,
        name,
    })
}

/// The simulation of `design`'s motion in `steps` steps (Eq. 2's bars, or rigid panels).
fn sim_input(
    design: &Evaluated<'_>,
    model: &Model,
    steps: usize,
    panels: bool,
) -> Result<SimInput> {
    let pattern = design.pattern(&sample_times(model.t_max, steps + 1));
    let drive = design_drive(model)?;
    let mut input = g0_input(&pattern, &drive, 0.0, model.t_max, steps)?;
    let apexes = if panels {
        add_panel_apexes(&mut input)
    } else {
        Vec::new()
    };
    input.first_step_offsets = branch_offsets(&pattern, &input, &apexes);
    // Rigid panels: the cross-validation's settings. Eq. 2's bars: the simulator's own
    // defaults, as `foldsynth simulate` runs the thesis's model (its flexible quadrilaterals
    // would send the cross-validation's deep step refinement down to 2^18 substeps).
    if panels {
        input.solver = CrossvalOptions::default().solver;
    }
    Ok(input)
}

/// Run `foldsynth bench numeric`.
pub fn run(args: NumericBenchArgs) -> Result<()> {
    let is_design = args
        .target
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    let d = if is_design {
        from_design_file(&args.target, args.task.as_deref())?
    } else {
        if args.task.is_some() {
            bail!(
                "--task is for a design JSON; {} is the task",
                args.target.display()
            );
        }
        let task = Task::load(&args.target)?;
        optimized(&task, &args)?
    };
    let model = &d.model;
    let steps = args.steps as usize;
    let budget = Duration::from_millis(args.millis.max(10));
    let ts = sample_times(model.t_max, steps + 1);
    let design = Evaluated::new(&model.plan, model.full_vars(&d.free), d.modes.clone());
    let v = verify(&design, &ts, &Tolerances::default());
    if !v.rigid_over_motion {
        bail!(
            "{}: the design is not rigid over its whole motion (margin {:.3e} at t = {:.4}); the bar-and-hinge simulation would measure its distortion, not its kinematics",
            d.name,
            v.min_margin,
            v.min_margin_t
        );
    }

    // (a) The compiled PTU model.
    let motion = CompiledMotion::new(model, &Options::default())?;
    let params = CompiledMotion::params(&d.free, &d.modes);
    let nv = motion.n_vertices;
    let mut states = vec![0.0; (steps + 1) * motion.buffer_len()];
    let len = motion.buffer_len();
    let jit = time_ns(budget, || {
        for (j, &t) in ts.iter().enumerate() {
            motion.positions(black_box(t), &params, &mut states[j * len..(j + 1) * len]);
        }
    });
    let f64_path = time_ns(budget, || {
        for &t in &ts {
            black_box(design.coords(&design.fold(black_box(t))));
        }
    });

    // (b) The bar-and-hinge simulation, same states.
    let thesis_input = sim_input(&design, model, steps, false)?;
    let panel_input = sim_input(&design, model, steps, true)?;
    let thesis_report = simulate(&thesis_input)?;
    let panel_report = simulate(&panel_input)?;
    let sim_thesis = time_ns(budget, || {
        black_box(simulate(black_box(&thesis_input)).ok());
    });
    let sim_panels = time_ns(budget, || {
        black_box(simulate(black_box(&panel_input)).ok());
    });

    // The same motion: compiled = f64 path at every state; simulation = PTU at t_max.
    let mut jit_vs_f64 = 0.0_f64;
    for (j, &t) in ts.iter().enumerate() {
        let x = design.coords(&design.fold(t));
        for (v, p) in x.iter().enumerate() {
            for k in 0..3 {
                jit_vs_f64 = jit_vs_f64.max((states[j * len + 3 * v + k] - p[k]).abs());
            }
        }
    }
    let end = &states[steps * len..];
    let sim_gap = |r: &crate::simulate::SimReport| {
        r.final_positions()
            .iter()
            .take(nv)
            .enumerate()
            .map(|(v, p)| {
                (0..3)
                    .map(|k| (p[k] - end[3 * v + k]).abs())
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max)
    };
    let (gap_thesis, gap_panels) = (sim_gap(&thesis_report), sim_gap(&panel_report));
    let rep = &motion.compiled.report;

    let out = json!({
        "design": d.name, "graph": model.plan.sequence, "vertices": nv, "steps": steps,
        "states": steps + 1,
        "ptu_jit_ns": jit, "ptu_f64_ns": f64_path,
        "sim_eq2_bars_ns": sim_thesis, "sim_rigid_panels_ns": sim_panels,
        "ratio_sim_eq2_over_jit": sim_thesis / jit,
        "ratio_sim_panels_over_jit": sim_panels / jit,
        "compile_ms": motion.total_ms, "ops": rep.simplified.ops,
        "jit_vs_f64_max": jit_vs_f64,
        "sim_eq2_gamma": thesis_report.gamma, "sim_eq2_end_gap": gap_thesis,
        "sim_panels_gamma": panel_report.gamma, "sim_panels_end_gap": gap_panels,
    });
    if args.json {
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!(
        "design {} (graph {}): {nv} vertices, one motion of J = {steps} steps ({} states), t = 0 … {:.4}, one run",
        d.name,
        model.plan.sequence,
        steps + 1,
        model.t_max
    );
    let per = |ns: f64| ns / (steps + 1) as f64;
    println!(
        "  PTU, JIT-compiled                     {:>12.1} µs per motion  ({:>9.0} ns per state)",
        jit / 1e3,
        per(jit)
    );
    println!(
        "  PTU, f64 (same code, not compiled)    {:>12.1} µs per motion  ({:>9.0} ns per state, {:.1}× the JIT)",
        f64_path / 1e3,
        per(f64_path),
        f64_path / jit
    );
    println!(
        "  bar-and-hinge, Eq. 2 bars (thesis)    {:>12.1} µs per motion  ({:>9.0} ns per step,  {:.0}× the JIT)",
        sim_thesis / 1e3,
        sim_thesis / steps as f64,
        sim_thesis / jit
    );
    println!(
        "  bar-and-hinge, rigid panels           {:>12.1} µs per motion  ({:>9.0} ns per step,  {:.0}× the JIT)",
        sim_panels / 1e3,
        sim_panels / steps as f64,
        sim_panels / jit
    );
    println!(
        "same motion: JIT = f64 to {jit_vs_f64:.1e}; simulation end state vs PTU X(t_max): {gap_thesis:.1e} (Eq. 2 bars, Γ {:.1e}), {gap_panels:.1e} (rigid panels, Γ {:.1e})",
        thesis_report.gamma, panel_report.gamma
    );
    println!(
        "compile (once per graph, not in the times above): {:.1} ms, {} operations",
        motion.total_ms, rep.simplified.ops
    );
    Ok(())
}
