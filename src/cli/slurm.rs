//! `foldsynth slurm TASK --shards N [--partition P] [--time T] [--cpus-per-task C]
//! [--submit] --out DIR`: Slurm batch scripts for a sharded search and its merge.

use crate::distribute::slurm::{self, SlurmOptions};
use crate::limits;
use crate::search::{self, SearchOptions};
use crate::task::Task;
use anyhow::{Context, Result};
use std::path::PathBuf;

/// Arguments of `foldsynth slurm`.
#[derive(Debug, clap::Args)]
pub struct SlurmArgs {
    /// The task file (copied into DIR/task/ for the jobs).
    pub task: PathBuf,
    /// Number of shards: array tasks 1 … N.
    #[arg(long, value_parser = limits::count::<1, { limits::SHARDS_MAX as u64 }>)]
    pub shards: usize,
    /// Slurm partition (default: the cluster's default partition).
    #[arg(long)]
    pub partition: Option<String>,
    /// Time limit per job, in Slurm's format (e.g. 30, 2:00:00, 1-00:00:00).
    #[arg(long)]
    pub time: Option<String>,
    /// CPUs per shard (its worker threads), 1 to 256.
    #[arg(long, default_value_t = 1, value_parser = limits::count::<1, { limits::JOBS_MAX as u64 }>)]
    pub cpus_per_task: usize,
    /// Submit both jobs with sbatch (the merge with --dependency=afterok) and print their
    /// ids; without it, print the commands that do.
    #[arg(long)]
    pub submit: bool,
    /// Directory for the scripts, logs/, shards/ and the merged result/.
    #[arg(long)]
    pub out: PathBuf,
    /// Override the task's maximum number of internal vertices, 1 to 6.
    #[arg(long, value_parser = limits::count::<1, { limits::N_MAX as u64 }>)]
    pub n_max: Option<usize>,
    /// Starting points per design alternative, 1 to 1000.
    #[arg(long, default_value_t = SearchOptions::default().starts, value_parser = limits::count::<1, { limits::STARTS_MAX as u64 }>)]
    pub starts: usize,
    /// Seed of the starting points.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// States of the rigidity/verification sweep, 2 to 10000.
    #[arg(long, default_value_t = SearchOptions::default().sweep, value_parser = limits::count::<2, { limits::SWEEP_MAX as u64 }>)]
    pub sweep: usize,
    /// The merged run skips exports and the report.
    #[arg(long)]
    pub no_export: bool,
    /// The grammar's rules: r1,r2 (the thesis's, default) or r1,r2,r2p (with r2′).
    #[arg(long, default_value = "r1,r2", value_name = "RULES")]
    pub rules: crate::grammar::Rules,
    /// Optimize without the robustness block and only check afterwards (as in the thesis).
    #[arg(long)]
    pub post_check_only: bool,
    /// `exhaustive` (default) or `guided`: the shards share the models a guided search
    /// of `--budget-alternatives` evaluates (see `synthesize --strategy`).
    #[arg(long, default_value_t = search::Strategy::Exhaustive, value_name = "STRATEGY")]
    pub strategy: search::Strategy,
    /// With `--strategy guided`: the alternatives the shards optimize together.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub budget_alternatives: Option<u64>,
}

/// Run `foldsynth slurm`.
pub fn run(args: SlurmArgs) -> Result<()> {
    // Read and checked here, so that a bad task fails now, not in every array task.
    let task = Task::load(&args.task)?;
    let text = limits::read_text(&args.task)
        .with_context(|| format!("cannot read {}", args.task.display()))?;
    let foldsynth = std::env::current_exe()
        .and_then(std::fs::canonicalize)
        .context("cannot find the foldsynth binary the jobs should run")?;
    let files = slurm::write_scripts(
        &args.task,
        &text,
        &task.name,
        &SlurmOptions {
            shards: args.shards,
            partition: args.partition,
            time: args.time,
            cpus_per_task: args.cpus_per_task,
            out: args.out,
            n_max: args.n_max,
            starts: args.starts,
            seed: args.seed,
            sweep: args.sweep,
            export: !args.no_export,
            rules: args.rules,
            post_check_only: args.post_check_only,
            guided: match args.strategy {
                search::Strategy::Guided => Some(args.budget_alternatives),
                search::Strategy::Exhaustive if args.budget_alternatives.is_some() => {
                    anyhow::bail!(
                        "--budget-alternatives is for the guided search: add --strategy guided"
                    )
                }
                search::Strategy::Exhaustive => None,
            },
            foldsynth,
        },
    )?;
    println!("wrote {}", files.shards_script.display());
    println!("wrote {}", files.merge_script.display());
    if args.submit {
        let ids = slurm::submit(&files)?;
        println!(
            "submitted: shards job {} (array 1-{}), merge job {} (after all shards succeed)",
            ids.shards, args.shards, ids.merge
        );
        println!("the merged run will be in {}", files.result.display());
    } else {
        println!("submit with:\n  {}", files.submit_commands());
    }
    Ok(())
}
