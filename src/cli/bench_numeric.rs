//! `foldsynth bench numeric TASK|DESIGN`: one folding motion of one design, J + 1 states,
//! computed by the compiled PTU model and by the thesis's bar-and-hinge simulation
//! (Sec. 3), measured in one run by [`crate::bench::numeric`] and reported as a ratio.

use super::model::{parse_modes, read_vars};
use crate::bench::numeric::{Design, NumericBench, measure, rigid_design};
use crate::grammar::CreaseGraph;
use crate::model::Model;
use crate::task::Task;
use anyhow::{Context, Result, bail};
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

/// Optimize a design of `args.graph` on `task` that is rigid over its whole motion.
fn optimized(task: &Task, args: &NumericBenchArgs) -> Result<Design> {
    let graph = CreaseGraph::from_sequence(task, &args.graph)
        .with_context(|| format!("--graph '{}'", args.graph))?;
    if !(1..=3).contains(&args.candidate) {
        bail!("--candidate must be 1, 2 or 3");
    }
    let model = Model::new(&graph, task, args.candidate - 1)?;
    let n = model.plan.n_modes;
    let modes = match &args.modes {
        Some(m) => Some(parse_modes(Some(m), n)?),
        None => None,
    };
    match rigid_design(model, modes)? {
        Some(d) => Ok(d),
        None => bail!(
            "no design of graph '{}' with {} is feasible and rigid over the whole motion; try another --graph or --modes",
            args.graph,
            args.modes
                .as_deref()
                .map_or("any modes".to_string(), |m| format!("modes {m}"))
        ),
    }
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
    let modes = parse_modes(Some(&modes_text.join(",")), model.plan.n_modes)
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
    let b = measure(
        &d,
        args.steps as usize,
        Duration::from_millis(args.millis.max(10)),
    )?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&b.json())?);
        return Ok(());
    }
    print_text(&b);
    Ok(())
}

/// The text report of `bench numeric`.
fn print_text(b: &NumericBench) {
    let (steps, jit, f64_path) = (b.steps, b.ptu_jit_ns, b.ptu_f64_ns);
    let (eq2, panels) = (&b.sim_eq2, &b.sim_panels);
    println!(
        "design {} (graph {}): {} vertices, one motion of J = {steps} steps ({} states), t = 0 … {:.4}, one run",
        b.design,
        b.sequence,
        b.vertices,
        steps + 1,
        b.t_max
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
        eq2.ns / 1e3,
        eq2.ns / steps as f64,
        eq2.ns / jit
    );
    println!(
        "  bar-and-hinge, rigid panels           {:>12.1} µs per motion  ({:>9.0} ns per step,  {:.0}× the JIT)",
        panels.ns / 1e3,
        panels.ns / steps as f64,
        panels.ns / jit
    );
    println!(
        "same motion: JIT = f64 to {:.1e}; simulation end state vs PTU X(t_max): {:.1e} (Eq. 2 bars, Γ {:.1e}), {:.1e} (rigid panels, Γ {:.1e})",
        b.jit_vs_f64_max, eq2.end_gap, eq2.gamma, panels.end_gap, panels.gamma
    );
    println!(
        "compile (once per graph, not in the times above): {:.1} ms, {} operations",
        b.compile_ms, b.ops
    );
}
