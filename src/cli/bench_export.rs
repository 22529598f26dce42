//! `foldsynth bench export DESIGN.json`: what one design's files cost, part by part, on
//! one thread, with this crate's GIF LZW against the `gif` crate's own in the same run.
//!
//! The parts are the ones [`export::write_all`] does for a design of a search (the default
//! [`ExportOptions`]): the FOLD file, the crease-pattern SVG, OBJ and STL, the PNG pictures
//! (drawn anti-aliased, then encoded), their SVG twins, and the GIF (frames drawn into
//! palette entries, delta rectangles, LZW). The last row is `write_all` itself, files and
//! all, into a temporary folder.

use super::bench::time_ns;
use crate::export::render::{Scene, delta_frame, encode_png, gif_palette};
use crate::export::{self, DesignFile, ExportOptions, lzw, mesh, svg};
use anyhow::{Context, Result};
use serde_json::json;
use std::hint::black_box;
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
    // One thread: a search exports one design per worker, so this is a worker's cost.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .context("cannot start a thread")?;
    pool.install(|| measure(&args, &d))
}

fn measure(args: &ExportBenchArgs, d: &DesignFile) -> Result<()> {
    let (p, meta) = (&d.pattern, &d.meta);
    let opts = ExportOptions::default();
    let budget = Duration::from_millis(args.millis);
    let scene = Scene::new(p, meta, opts.camera)?;
    let size = opts.image_size;
    let pictures = export::picked_frames(p.frames.len(), opts.picture_states);
    let last = p.frames.len().checked_sub(1);
    let mut rows: Vec<(&str, f64)> = Vec::new();

    rows.push((
        "FOLD file",
        time_ns(budget, || {
            black_box(export::fold::to_fold_string(p, meta, opts.fold_spec).ok());
        }),
    ));
    rows.push((
        "crease-pattern SVG",
        time_ns(budget, || {
            black_box(svg::crease_pattern_svg(p, &svg::SvgOptions::default()).ok());
        }),
    ));
    let state = mesh::state_mesh(p, last, meta.second_arm)?;
    rows.push((
        "OBJ and STL of the last state",
        time_ns(budget, || {
            black_box(mesh::to_obj(&state, &opts.name));
            black_box(mesh::to_stl_binary(&state));
        }),
    ));
    let pixmaps = pictures
        .iter()
        .map(|&k| scene.pixmap(Some(k), size))
        .collect::<export::Result<Vec<_>>>()?;
    rows.push((
        "PNG pictures: draw, anti-aliased",
        time_ns(budget, || {
            for &k in &pictures {
                black_box(scene.pixmap(Some(k), size).ok());
            }
        }),
    ));
    rows.push((
        "PNG pictures: encode",
        time_ns(budget, || {
            for pm in &pixmaps {
                black_box(encode_png(pm).ok());
            }
        }),
    ));
    rows.push((
        "SVG pictures of the same states",
        time_ns(budget, || {
            for &k in &pictures {
                black_box(scene.svg(Some(k), size));
            }
        }),
    ));
    let frames = scene.gif_frames(size, opts.gif_max_frames)?;
    rows.push((
        "GIF frames: draw into palette entries",
        time_ns(budget, || {
            black_box(scene.gif_frames(size, opts.gif_max_frames).ok());
        }),
    ));
    let (w, h) = (size.0 as usize, size.1 as usize);
    let transparent = gif_palette().transparent().unwrap_or(0);
    let deltas = || {
        frames
            .windows(2)
            .map(|f| delta_frame(&f[0], &f[1], w, h, transparent))
            .collect::<Vec<_>>()
    };
    rows.push((
        "GIF frames: delta rectangles",
        time_ns(budget, || {
            black_box(deltas());
        }),
    ));
    // The GIF's image data: the first frame whole, then the deltas.
    let mut data: Vec<Vec<u8>> = frames.first().cloned().into_iter().collect();
    data.extend(deltas().into_iter().map(|f| f.buffer.into_owned()));
    let ours = time_ns(budget, || {
        for f in &data {
            black_box(lzw::encode(f));
        }
    });
    let theirs = time_ns(budget, || {
        for f in &data {
            black_box(gif_crate_lzw(f));
        }
    });
    rows.push(("GIF frames: LZW (export::lzw)", ours));
    let bytes_ours: usize = data.iter().map(|f| lzw::encode(f).len()).sum();
    let bytes_theirs: usize = data.iter().map(|f| gif_crate_lzw(f).len()).sum();
    let dir = std::env::temp_dir().join(format!("foldsynth-bench-export-{}", std::process::id()));
    let all = time_ns(budget, || {
        black_box(export::write_all(&dir, p, meta, &opts).ok());
    });
    // Best effort: the folder is ours, and a leftover is harmless.
    let _ = std::fs::remove_dir_all(&dir);
    let parts: f64 = rows.iter().map(|r| r.1).sum();
    let pixels: usize = data.iter().map(Vec::len).sum();

    if args.json {
        let row_json: Vec<_> = rows
            .iter()
            .map(|(name, ns)| json!({"part": name, "ns": ns}))
            .collect();
        println!(
            "{}",
            serde_json::to_string_pretty(&json!({
                "design": args.design.display().to_string(),
                "image_size": [size.0, size.1],
                "gif_frames": frames.len(),
                "pictures": pictures.len(),
                "rows": row_json,
                "parts_ns": parts,
                "write_all_ns": all,
                "lzw": {
                    "input_bytes": pixels,
                    "ours_ns": ours,
                    "gif_crate_ns": theirs,
                    "gif_crate_over_ours": theirs / ours,
                    "ours_bytes": bytes_ours,
                    "gif_crate_bytes": bytes_theirs,
                },
            }))?
        );
        return Ok(());
    }
    println!(
        "{}: {} pictures and a GIF of {} frames, {}×{} pixels (one thread)",
        args.design.display(),
        pictures.len(),
        frames.len(),
        size.0,
        size.1
    );
    for (name, ns) in &rows {
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
        all / 1e6
    );
    println!(
        "LZW of the GIF's {} bytes of image data: the gif crate's encoder {:.3} ms, export::lzw {:.3} ms ({:.1}× faster); {} and {} bytes out",
        pixels,
        theirs / 1e6,
        ours / 1e6,
        theirs / ours,
        bytes_theirs,
        bytes_ours
    );
    Ok(())
}

/// `data` compressed by the `gif` crate's own encoder (`weezl`), as a pre-encoded frame.
fn gif_crate_lzw(data: &[u8]) -> Vec<u8> {
    let mut frame = gif::Frame {
        buffer: std::borrow::Cow::Borrowed(data),
        ..Default::default()
    };
    frame.make_lzw_pre_encoded();
    frame.buffer.into_owned()
}
