//! `foldsynth optimize-flasher [--evals N] [--seed S] [--json]`: simulated annealing of the
//! adapted flasher (thesis Sec. 3.6–3.7), reported next to the thesis's figures.

use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Args;

use crate::simulate::PatternFile;
use crate::simulate::flasher::{
    AnnealSettings, FlasherEvaluation, FlasherTask, THESIS_BEST, VARIABLE_NAMES, anneal,
};

/// Arguments of `foldsynth optimize-flasher`.
#[derive(Debug, Args)]
pub struct OptimizeFlasherArgs {
    /// Objective evaluations (the thesis: 50 × 50 = 2500).
    #[arg(long, default_value_t = 2500, value_parser = clap::value_parser!(u64).range(1..=crate::limits::EVALS_MAX))]
    pub evals: u64,
    /// Seed of the random start point and moves.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// A flasher pattern file to use instead of the shipped grammar/flasher_adapted.toml.
    #[arg(long)]
    pub pattern: Option<PathBuf>,
    /// Start from the pattern file's v3, v4, v5 instead of a random point.
    #[arg(long)]
    pub start_from_file: bool,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Run `foldsynth optimize-flasher`.
pub fn run(args: OptimizeFlasherArgs) -> anyhow::Result<()> {
    let task = match &args.pattern {
        Some(p) => FlasherTask::new(PatternFile::load(p)?)?,
        None => FlasherTask::shipped()?,
    };
    let settings = AnnealSettings {
        evaluations: args.evals as usize,
        seed: args.seed,
        start: args.start_from_file.then(|| task.file_variables()),
        ..AnnealSettings::default()
    };
    let t0 = std::time::Instant::now();
    let result =
        anneal(&task, &settings).map_err(|e| anyhow::anyhow!("simulated annealing failed: {e}"))?;
    let seconds = t0.elapsed().as_secs_f64();
    let thesis_design = task.evaluate_positions(&THESIS_BEST);
    if args.json {
        let out = serde_json::json!({
            "settings": settings,
            "best": result.best,
            "best_feasible": result.best_feasible,
            "start": result.start,
            "evaluations": result.evaluations,
            "seconds": seconds,
            "trace": result.trace,
            "thesis": {"objective": -0.88, "area": 44.0, "omega": 0.0, "theta": 0.0,
                       "gamma": 1.6e-6, "hours": 8.5, "evaluations": 2500},
            "thesis_design_here": thesis_design,
        });
        return super::simulate::emit(&(serde_json::to_string_pretty(&out)? + "\n"));
    }
    let mut o = String::new();
    let _ = writeln!(
        o,
        "simulated annealing: {} evaluations, seed {}, T0 = {}, factor {} per {} evaluations",
        result.evaluations,
        settings.seed,
        settings.start_temperature,
        settings.factor,
        settings.inner
    );
    let e = &result.best;
    comparison(&mut o, e, &thesis_design, seconds);
    design(&mut o, "best design", e);
    match &result.best_feasible {
        Some(f) if f != e => {
            let _ = writeln!(
                o,
                "best feasible design: objective {:.4}, A = {:.3}, Gamma = {:.2e}, theta = 0, Omega = {:.1e}",
                f.objective, f.area, f.gamma, f.omega
            );
            design(&mut o, "best feasible design", f);
        }
        Some(_) => {}
        None => {
            let _ = writeln!(o, "no feasible design among the evaluations");
        }
    }
    super::simulate::emit(&o)
}

/// This run's best design, the thesis's figures and the thesis's design evaluated here,
/// side by side.
fn comparison(o: &mut String, e: &FlasherEvaluation, d: &FlasherEvaluation, seconds: f64) {
    let _ = writeln!(
        o,
        "{:<28} {:>12} {:>12} {:>12}",
        "", "this run", "thesis", "thesis design here"
    );
    let mut row = |name: &str, a: String, b: &str, c: String| {
        let _ = writeln!(o, "{name:<28} {a:>12} {b:>12} {c:>12}");
    };
    row(
        "best objective",
        format!("{:.4}", e.objective),
        "-0.88",
        format!("{:.4}", d.objective),
    );
    row(
        "projected area A",
        format!("{:.3}", e.area),
        "44.0",
        format!("{:.3}", d.area),
    );
    row(
        "rigidity error Gamma",
        format!("{:.2e}", e.gamma),
        "1.6e-6",
        format!("{:.2e}", d.gamma),
    );
    row(
        "max delta(j)",
        format!("{:.2e}", e.max_delta),
        "<= 1e-4",
        format!("{:.2e}", d.max_delta),
    );
    row(
        "self-intersection theta",
        format!("{:.4}", e.theta),
        "0",
        format!("{:.4}", d.theta),
    );
    row(
        "spatial feasibility Omega",
        format!("{:.4}", e.omega),
        "0",
        format!("{:.4}", d.omega),
    );
    row(
        "feasible",
        e.feasible.to_string(),
        "true",
        d.feasible.to_string(),
    );
    row(
        "wall time",
        format!("{seconds:.1} s"),
        "8.5 h",
        String::new(),
    );
}

/// A design's positions x3, x4, x5 and its Eq. 5 variables.
fn design(o: &mut String, title: &str, e: &FlasherEvaluation) {
    let _ = writeln!(o, "{title}:");
    for (k, name) in ["x3", "x4", "x5"].iter().enumerate() {
        let p = e.positions[k];
        let _ = writeln!(o, "  {name} = ({:.4}, {:.4}, {:.4})", p[0], p[1], p[2]);
    }
    let vars: Vec<String> = VARIABLE_NAMES
        .iter()
        .zip(e.variables)
        .enumerate()
        .map(|(k, (n, v))| {
            if k % 3 == 0 {
                format!("{n} = {v:.4}")
            } else {
                format!("{n} = {:.2}°", v.to_degrees())
            }
        })
        .collect();
    let _ = writeln!(o, "  Eq. 5: {}", vars.join(", "));
}
