//! `foldsynth merge SHARD_DIR… --out DIR [--jobs N] [--export N|all | --no-export] [--force] [--json]`:
//! the shards of one search merged into the run one machine would have written.

use crate::distribute::merge::{self, MergeOptions};
use crate::limits;
use crate::search::ExportCount;
use anyhow::Result;
use std::path::PathBuf;

/// Arguments of `foldsynth merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// The directories of every shard (`synthesize --shard K/N --out DIR`), in any order.
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    /// Output directory of the merged run (new, empty, or a run of the same settings).
    #[arg(long)]
    pub out: PathBuf,
    /// Worker threads for the designs and exports, 0 (one per core) to 256.
    #[arg(long, default_value_t = 0, value_parser = limits::count::<0, { limits::JOBS_MAX as u64 }>)]
    pub jobs: usize,
    /// Skip the FOLD/SVG/OBJ/STL/picture/animation files (the design JSONs and the report
    /// are written either way).
    #[arg(long, conflicts_with = "export")]
    pub no_export: bool,
    /// Write the files of the N most robust designs (default 20), or of every design with
    /// `all` (see synthesize --export).
    #[arg(long, value_name = "N|all", default_value_t = ExportCount(Some(crate::search::EXPORT_TOP)), value_parser = clap::value_parser!(ExportCount))]
    pub export: ExportCount,
    /// Draw the whole motion of the N most robust designs in report.html (default 100),
    /// or of every design with `all` (see synthesize --report-motions).
    #[arg(long, value_name = "N|all", default_value_t = ExportCount(Some(crate::search::REPORT_MOTIONS)), value_parser = clap::value_parser!(ExportCount))]
    pub report_motions: ExportCount,
    /// Carry the N most robust designs in full in report.html (default 1000), or every
    /// design with `all` (see synthesize --report-designs).
    #[arg(long, value_name = "N|all", default_value_t = ExportCount(Some(crate::search::REPORT_DESIGNS)), value_parser = clap::value_parser!(ExportCount))]
    pub report_designs: ExportCount,
    /// Use OUT even if it holds a run of other settings (see synthesize --force).
    #[arg(long)]
    pub force: bool,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Run `foldsynth merge`.
pub fn run(args: MergeArgs) -> Result<()> {
    let summary = merge::merge(
        &args.shards,
        &MergeOptions {
            out: args.out.clone(),
            force: args.force,
            jobs: args.jobs,
            export: !args.no_export,
            export_top: args.export.0,
            report_motions: args.report_motions.0,
            report_designs: args.report_designs.0,
        },
    )?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print!("{}", summary.text());
        println!(
            "{} shards merged; results in {}",
            args.shards.len(),
            args.out.display()
        );
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
