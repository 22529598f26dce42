//! `foldsynth bench export DESIGN.json`: what one design's files cost, part by part, on
//! one thread, with this crate's GIF LZW against the `gif` crate's own in the same run.
//!
//! The parts are the ones [`export::write_all`] does for a design of a search (the default
//! [`ExportOptions`]): the FOLD file, the crease-pattern SVG, OBJ and STL, the PNG pictures
//! (drawn anti-aliased, then encoded), their SVG twins, and the GIF (frames drawn into
//! palette entries, delta rectangles, LZW). The last row is `write_all` itself, files and
//! all, into a temporary folder.

use super::time_ns;
use crate::export::render::{Scene, delta_frame, encode_png, gif_palette};
use crate::export::{self, DesignFile, DesignMeta, ExportOptions, lzw, mesh, svg};
use crate::pattern::Pattern;
use anyhow::{Context, Result};
use serde_json::json;
use std::hint::black_box;
use std::time::Duration;

/// The GIF's image data compressed by this crate's LZW and by the `gif` crate's.
#[derive(Clone, Copy, Debug)]
pub struct LzwFigures {
    /// Bytes of image data (the first frame whole, then the delta rectangles).
    pub input_bytes: usize,
    /// Nanoseconds of `export::lzw`.
    pub ours_ns: f64,
    /// Nanoseconds of the `gif` crate's encoder.
    pub gif_crate_ns: f64,
    /// Bytes out of `export::lzw`.
    pub ours_bytes: usize,
    /// Bytes out of the `gif` crate's encoder.
    pub gif_crate_bytes: usize,
}

/// The figures of one `bench export` run.
pub struct ExportBench {
    /// Width and height of the pictures and the GIF.
    pub image_size: (u32, u32),
    /// Frames of the GIF.
    pub gif_frames: usize,
    /// Number of pictures.
    pub pictures: usize,
    /// The parts and their nanoseconds per design.
    pub rows: Vec<(&'static str, f64)>,
    /// The parts together, nanoseconds.
    pub parts_ns: f64,
    /// `export::write_all`, files written, nanoseconds.
    pub write_all_ns: f64,
    /// The LZW comparison.
    pub lzw: LzwFigures,
}

/// What every part is measured on.
struct Subject<'a> {
    p: &'a Pattern,
    meta: &'a DesignMeta,
    opts: ExportOptions,
    scene: Scene<'a>,
    budget: Duration,
}

/// Measure `bench export` on one thread: a search exports one design per worker, so this
/// is a worker's cost.
pub fn measure(d: &DesignFile, budget: Duration) -> Result<ExportBench> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .context("cannot start a thread")?;
    pool.install(|| measure_here(d, budget))
}

/// Measure `bench export` on this thread.
fn measure_here(d: &DesignFile, budget: Duration) -> Result<ExportBench> {
    let (p, meta) = (&d.pattern, &d.meta);
    let opts = ExportOptions::default();
    let scene = Scene::new(p, meta, opts.camera)?;
    let s = Subject {
        p,
        meta,
        opts,
        scene,
        budget,
    };
    let mut rows: Vec<(&'static str, f64)> = Vec::new();
    s.file_rows(&mut rows)?;
    let pictures = s.picture_rows(&mut rows)?;
    let frames = s.gif_rows(&mut rows)?;
    let lzw = s.lzw_row(&frames, &mut rows);
    let dir = std::env::temp_dir().join(format!("foldsynth-bench-export-{}", std::process::id()));
    let all = time_ns(budget, || {
        black_box(export::write_all(&dir, p, s.meta, &s.opts).ok());
    });
    // Best effort: the folder is ours, and a leftover is harmless.
    let _ = std::fs::remove_dir_all(&dir);
    let parts: f64 = rows.iter().map(|r| r.1).sum();
    Ok(ExportBench {
        image_size: s.opts.image_size,
        gif_frames: frames.len(),
        pictures,
        rows,
        parts_ns: parts,
        write_all_ns: all,
        lzw,
    })
}

impl Subject<'_> {
    /// FOLD, the crease-pattern SVG, OBJ and STL of the last state.
    fn file_rows(&self, rows: &mut Vec<(&'static str, f64)>) -> Result<()> {
        let (p, meta, opts, budget) = (self.p, self.meta, &self.opts, self.budget);
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
        let last = p.frames.len().checked_sub(1);
        let state = mesh::state_mesh_copies(p, last, &meta.scene.copies)?;
        rows.push((
            "OBJ and STL of the last state",
            time_ns(budget, || {
                black_box(mesh::to_obj(&state, &opts.name));
                black_box(mesh::to_stl_binary(&state));
            }),
        ));
        Ok(())
    }

    /// The PNG pictures (drawn, encoded) and their SVG twins; how many pictures.
    fn picture_rows(&self, rows: &mut Vec<(&'static str, f64)>) -> Result<usize> {
        let (scene, budget, size) = (&self.scene, self.budget, self.opts.image_size);
        let pictures = export::picked_frames(self.p.frames.len(), self.opts.picture_states);
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
        Ok(pictures.len())
    }

    /// The GIF's frames drawn into palette entries, and their delta rectangles; the
    /// frames.
    fn gif_rows(&self, rows: &mut Vec<(&'static str, f64)>) -> Result<Vec<Vec<u8>>> {
        let (scene, budget, size) = (&self.scene, self.budget, self.opts.image_size);
        let max_frames = self.opts.gif_max_frames;
        let transparent = gif_palette().transparent().unwrap_or(0);
        let frames = scene.gif_frames(size, max_frames)?;
        rows.push((
            "GIF frames: draw into palette entries",
            time_ns(budget, || {
                black_box(scene.gif_frames(size, max_frames).ok());
            }),
        ));
        rows.push((
            "GIF frames: delta rectangles",
            time_ns(budget, || {
                black_box(deltas(&frames, size, transparent));
            }),
        ));
        Ok(frames)
    }

    /// The GIF's image data (the first frame whole, then the deltas) compressed by
    /// `export::lzw` (a row) and by the `gif` crate's encoder.
    fn lzw_row(&self, frames: &[Vec<u8>], rows: &mut Vec<(&'static str, f64)>) -> LzwFigures {
        let budget = self.budget;
        let transparent = gif_palette().transparent().unwrap_or(0);
        let mut data: Vec<Vec<u8>> = frames.first().cloned().into_iter().collect();
        data.extend(
            deltas(frames, self.opts.image_size, transparent)
                .into_iter()
                .map(|f| f.buffer.into_owned()),
        );
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
        LzwFigures {
            input_bytes: data.iter().map(Vec::len).sum(),
            ours_ns: ours,
            gif_crate_ns: theirs,
            ours_bytes: data.iter().map(|f| lzw::encode(f).len()).sum(),
            gif_crate_bytes: data.iter().map(|f| gif_crate_lzw(f).len()).sum(),
        }
    }
}

/// The delta rectangles between consecutive frames of `size` pixels.
fn deltas(frames: &[Vec<u8>], size: (u32, u32), transparent: u8) -> Vec<gif::Frame<'static>> {
    let (w, h) = (size.0 as usize, size.1 as usize);
    frames
        .windows(2)
        .map(|f| delta_frame(&f[0], &f[1], w, h, transparent))
        .collect::<Vec<_>>()
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

impl ExportBench {
    /// The figures as one JSON object (times in nanoseconds per design) for the design
    /// file `design`.
    pub fn json(&self, design: &str) -> serde_json::Value {
        let row_json: Vec<_> = self
            .rows
            .iter()
            .map(|(name, ns)| json!({"part": name, "ns": ns}))
            .collect();
        let (size, lzw) = (self.image_size, &self.lzw);
        json!({
            "design": design,
            "image_size": [size.0, size.1],
            "gif_frames": self.gif_frames,
            "pictures": self.pictures,
            "rows": row_json,
            "parts_ns": self.parts_ns,
            "write_all_ns": self.write_all_ns,
            "lzw": {
                "input_bytes": lzw.input_bytes,
                "ours_ns": lzw.ours_ns,
                "gif_crate_ns": lzw.gif_crate_ns,
                "gif_crate_over_ours": lzw.gif_crate_ns / lzw.ours_ns,
                "ours_bytes": lzw.ours_bytes,
                "gif_crate_bytes": lzw.gif_crate_bytes,
            },
        })
    }
}
