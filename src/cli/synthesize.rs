//! `foldsynth synthesize TASK [--out DIR] [--jobs N] [--starts K] [--seed S] [--resume]`:
//! the whole method on a design task.

use crate::search::{self, SearchOptions};
use crate::task::Task;
use anyhow::Result;
use std::path::PathBuf;

/// Arguments of `foldsynth synthesize`.
#[derive(Debug, clap::Args)]
pub struct SynthesizeArgs {
    /// The task file (e.g. grammar/gripper.toml).
    pub task: PathBuf,
    /// Output directory (default: out/<task name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Worker threads; 0 means one per core.
    #[arg(long, default_value_t = 0)]
    pub jobs: usize,
    /// Starting points per design alternative.
    #[arg(long, default_value_t = SearchOptions::default().starts)]
    pub starts: usize,
    /// Seed of the starting points (same seed, same results).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Continue a killed run: keep the alternatives already in OUT/alternatives.jsonl.
    #[arg(long)]
    pub resume: bool,
    /// Override the task's maximum number of internal vertices.
    #[arg(long)]
    pub n_max: Option<usize>,
    /// States of the rigidity/verification sweep over [0, t_max] (181: every 0.5° of a
    /// π/2 motion; `model --sweep` has the same default).
    #[arg(long, default_value_t = SearchOptions::default().sweep)]
    pub sweep: usize,
    /// Skip the per-design FOLD/SVG/OBJ/STL/picture/animation files (the design JSONs and
    /// report.html, with its 3D views, are written either way).
    #[arg(long)]
    pub no_export: bool,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Run `foldsynth synthesize`.
pub fn run(args: SynthesizeArgs) -> Result<()> {
    let task = Task::load(&args.task)?;
    if args.starts == 0 {
        anyhow::bail!("--starts must be at least 1");
    }
    if args.n_max == Some(0) {
        anyhow::bail!("--n-max must be at least 1");
    }
    let out = args
        .out
        .unwrap_or_else(|| PathBuf::from("out").join(&task.name));
    let opts = SearchOptions {
        out: out.clone(),
        jobs: args.jobs,
        starts: args.starts,
        seed: args.seed,
        resume: args.resume,
        n_max: args.n_max,
        sweep: args.sweep.max(2),
        export: !args.no_export,
        progress: true,
    };
    let summary = search::run(&task, &opts)?;
    let files = format!(
        "report: {}\nsummary: {}\n",
        out.join("report.html").display(),
        out.join("summary.json").display()
    );
    if args.json {
        // stdout stays one JSON document; the file names go to stderr.
        println!("{}", serde_json::to_string_pretty(&summary)?);
        eprint!("{files}");
    } else {
        print!("{}", summary.text());
        print!("{files}");
    }
    if summary.verification_failures > 0 {
        anyhow::bail!(
            "{} designs failed verification (a bug; see the messages above)",
            summary.verification_failures
        );
    }
    Ok(())
}
