//! `foldsynth synthesize TASK [--out DIR] [--jobs N] [--starts K] [--seed S] [--resume]
//! [--force] [--export N|all | --no-export] [--shard K/N] [--graph SEQ]...`: the whole method on a design task, or one shard of it.

use crate::distribute;
use crate::limits;
use crate::search::output::ShardSpec;
use crate::search::{self, ExportCount, SearchOptions, output};
use crate::task::Task;
use anyhow::Result;
use std::path::PathBuf;

/// Arguments of `foldsynth synthesize`.
#[derive(Debug, clap::Args)]
pub struct SynthesizeArgs {
    /// The task file (e.g. grammar/gripper.toml).
    pub task: PathBuf,
    /// Output directory (default: `out/<task name>`). It must be new, empty, or an earlier
    /// run of the same settings (see --force).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Worker threads, 0 (one per core) to 256.
    #[arg(long, default_value_t = 0, value_parser = limits::count::<0, { limits::JOBS_MAX as u64 }>)]
    pub jobs: usize,
    /// Starting points per design alternative, 1 to 1000 (an area objective runs three
    /// times as many: it has no target to stop at).
    #[arg(long, default_value_t = SearchOptions::default().starts, value_parser = limits::count::<1, { limits::STARTS_MAX as u64 }>)]
    pub starts: usize,
    /// Seed of the starting points (same seed, same results).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Continue a killed run of the same settings: keep the alternatives already in
    /// OUT/alternatives.jsonl (says how many it reused and why it dropped any).
    #[arg(long)]
    pub resume: bool,
    /// Use OUT even if it holds a run of other settings (its files, as its manifest.json
    /// lists them, are deleted) or is not a foldsynth run (nothing is deleted).
    #[arg(long)]
    pub force: bool,
    /// Override the task's maximum number of internal vertices, 1 to 6.
    #[arg(long, value_parser = limits::count::<1, { limits::N_MAX as u64 }>)]
    pub n_max: Option<usize>,
    /// States of the rigidity/verification sweep over [0, t_max], 2 to 10000 (181: every
    /// 0.5° of a π/2 motion; `model --sweep` has the same default).
    #[arg(long, default_value_t = SearchOptions::default().sweep, value_parser = limits::count::<2, { limits::SWEEP_MAX as u64 }>)]
    pub sweep: usize,
    /// Skip the per-design FOLD/SVG/OBJ/STL/picture/animation files (the design JSONs and
    /// report.html, with its 3D views, are written either way).
    #[arg(long, conflicts_with = "export")]
    pub no_export: bool,
    /// Write the FOLD/SVG/OBJ/STL/picture/animation files of the N most robust designs
    /// (default 20), or of every design with `all`; report.html gives the command that
    /// writes any other design's files.
    #[arg(long, value_name = "N|all", default_value_t = ExportCount(Some(search::EXPORT_TOP)), value_parser = clap::value_parser!(ExportCount))]
    pub export: ExportCount,
    /// Draw the whole motion of the N most robust designs in report.html (default 100),
    /// or of every design with `all`; the others are drawn in their folded form (a
    /// design's motion is 5–8 KB of the page).
    #[arg(long, value_name = "N|all", default_value_t = ExportCount(Some(search::REPORT_MOTIONS)), value_parser = clap::value_parser!(ExportCount))]
    pub report_motions: ExportCount,
    /// Carry the N most robust designs in full in report.html (card, 3D view, crease
    /// pattern; default 1000), or every design with `all`; every design is a row of its
    /// table either way, so a run of 100,000 designs still makes a page of about 13 MB.
    #[arg(long, value_name = "N|all", default_value_t = ExportCount(Some(search::REPORT_DESIGNS)), value_parser = clap::value_parser!(ExportCount))]
    pub report_designs: ExportCount,
    /// Run only shard K of N (1 ≤ K ≤ N) of the search: a deterministic, cost-balanced
    /// share of its models, into its own directory (records only; `foldsynth merge` makes
    /// the whole run of all N). Resumable with --resume like a whole run.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<ShardSpec>,
    /// How to choose what to optimize: `exhaustive` (every alternative, the default) or
    /// `guided` (the most promising models first, until a budget is spent; see
    /// docs/guided-search.md).
    #[arg(long, default_value_t = search::Strategy::Exhaustive, value_name = "STRATEGY")]
    pub strategy: search::Strategy,
    /// With `--strategy guided`: optimize this many alternatives (rounded up to whole
    /// models); the same seed and budget give the same records.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub budget_alternatives: Option<u64>,
    /// With `--strategy guided`: start no alternative after this many CPU seconds (all threads;
    /// the run ends at most one alternative per worker past it)
    #[arg(long, value_name = "SECONDS")]
    pub budget_cpu: Option<f64>,
    /// With `--strategy guided`: no warm starts from the parents' optima (then an
    /// unlimited guided run has exactly the exhaustive run's records; shards never use
    /// them, since a parent may be in another shard).
    #[arg(long)]
    pub no_warm_starts: bool,
    /// Search only this graph (a rule sequence as `foldsynth enumerate` lists the
    /// meaningful graphs, e.g. "1, (9, 20), 9"); repeat for several. Every mode assignment
    /// of each is optimized; the others are not searched.
    #[arg(long, value_name = "SEQ")]
    pub graph: Vec<String>,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
    /// The grammar's rules: r1,r2 (the thesis's, default) or r1,r2,r2p (with r2′: cyclic,
    /// overconstrained patterns such as the Miura-ori, verified by simulation).
    #[arg(long, default_value = "r1,r2", value_name = "RULES")]
    pub rules: crate::grammar::Rules,
    /// Today's behaviour before issue 12: optimize without the clearance and margin
    /// constraints, judge only afterwards (to compare the two on the same alternatives).
    #[arg(long)]
    pub post_check_only: bool,
}

/// Run `foldsynth synthesize`.
pub fn run(args: SynthesizeArgs) -> Result<()> {
    let task = Task::load(&args.task)?;
    let out = args.out.unwrap_or_else(|| match args.shard {
        Some(s) => {
            output::default_dir(&task.name).join(format!("shard-{}-of-{}", s.index, s.count))
        }
        None => output::default_dir(&task.name),
    });
    let opts = SearchOptions {
        out: out.clone(),
        jobs: args.jobs,
        starts: args.starts,
        seed: args.seed,
        resume: args.resume,
        force: args.force,
        n_max: args.n_max,
        sweep: args.sweep,
        export: !args.no_export,
        export_top: args.export.0,
        report_motions: args.report_motions.0,
        report_designs: args.report_designs.0,
        progress: true,
        rules: args.rules,
        post_check_only: args.post_check_only,
        strategy: args.strategy,
        budget: search::Budget {
            alternatives: args.budget_alternatives,
            cpu_s: args.budget_cpu,
        },
        warm_starts: !args.no_warm_starts,
        on_progress: None,
        graphs: args.graph,
    };
    if let Some(spec) = args.shard {
        // The text the task was read from, kept with the shard for the merge.
        let text = limits::read_text(&args.task)
            .map_err(|e| anyhow::anyhow!("{}: {e}", args.task.display()))?;
        let report = distribute::shard::run(&task, &text, &opts, spec)?;
        if args.json {
            println!("{}", serde_json::to_string_pretty(&report)?);
        } else {
            println!(
                "shard {spec} of task {}: {} models, {} alternatives ({:.1}% of the estimated cost), {} records{}",
                task.name,
                report.units,
                report.alternatives,
                100.0 * report.cost as f64 / report.total_cost.max(1) as f64,
                report.records,
                if report.failed_models.is_empty() {
                    String::new()
                } else {
                    format!("; {} models failed", report.failed_models.len())
                }
            );
            println!(
                "results in {}; merge all {} shards with: foldsynth merge DIR… --out DIR",
                out.display(),
                spec.count
            );
        }
        return Ok(());
    }
    let summary = search::run(&task, &opts)?;
    let mut files = format!(
        "report: {}\nsummary: {}\nrecords: {} (and alternatives.parquet)\n",
        out.join("report.html").display(),
        out.join("summary.json").display(),
        out.join(output::RECORDS).display(),
    );
    if let (true, Some(n)) = (opts.export, opts.export_top)
        && summary.designs.len() > n
    {
        files += &format!(
            "design files: the FOLD file of each of the {} designs; SVG, meshes, pictures and animation of the {n} most robust (--export all: of every design; the report gives the command for any one)\n",
            summary.designs.len()
        );
    }
    if args.json {
        // stdout stays one JSON document; the file names go to stderr.
        println!("{}", serde_json::to_string_pretty(&summary)?);
        eprint!("{files}");
    } else {
        print!("{}", summary.text());
        print!("{files}");
    }
    if summary.verification_failures > 0 {
        return Err(super::CheckFailed(format!(
            "{} designs failed verification (a bug; see the messages above)",
            summary.verification_failures
        ))
        .into());
    }
    Ok(())
}
