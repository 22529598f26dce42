//! `foldsynth bench export DESIGN.json`: what one design's files cost, part by part, on
//! one thread (measured by [`crate::bench::export`]).

use crate::bench::export::{ExportBench, measure};
use crate::export::DesignFile;
use anyhow::Result;
use std::path::PathBuf;
use std::time::Duration;

/// Arguments of `foldsynth bench export`.
#[derive(Debug, clap::Args)]
pub struct ExportBenchArgs {
    /// A design JSON (`OUT/designs/<id>.json` of `foldsynth synthesize`, or any file
    /// `foldsynth export` reads).
    pub design: PathBuf,
    /// Milliseconds of measurement per row.
    #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u64).range(1..=crate::limits::BENCH_MILLIS_MAX))]
    pub millis: u64,
    /// Print one JSON object (times in nanoseconds per design).
    #[arg(long)]
    pub json: bool,
}

/// Run `foldsynth bench export`.
pub fn run(args: ExportBenchArgs) -> Result<()> {
    let d = DesignFile::read(&args.design)?;
    let b = measure(&d, Duration::from_millis(args.millis))?;
    let design = args.design.display().to_string();
    if args.json {
        println!("{}", serde_json::to_string_pretty(&b.json(&design))?);
        return Ok(());
    }
    print_text(&b, &design);
    Ok(())
}

/// The text report of `bench export`.
fn print_text(b: &ExportBench, design: &str) {
    let size = b.image_size;
    println!(
        "{design}: {} pictures and a GIF of {} frames, {}×{} pixels (one thread)",
        b.pictures, b.gif_frames, size.0, size.1
    );
    let parts = b.parts_ns;
    for (name, ns) in &b.rows {
        println!(
            "  {name:<40} {:>8.3} ms  {:>5.1} %",
            ns / 1e6,
            100.0 * ns / parts
        );
    }
    println!("  {:<40} {:>8.3} ms", "the parts together", parts / 1e6);
    println!(
        "  {:<40} {:>8.3} ms  (files written)",
        "export::write_all",
        b.write_all_ns / 1e6
    );
    let l = &b.lzw;
    println!(
        "LZW of the GIF's {} bytes of image data: the gif crate's encoder {:.3} ms, export::lzw {:.3} ms ({:.1}× faster); {} and {} bytes out",
        l.input_bytes,
        l.gif_crate_ns / 1e6,
        l.ours_ns / 1e6,
        l.gif_crate_ns / l.ours_ns,
        l.gif_crate_bytes,
        l.ours_bytes
    );
}
