//! `foldsynth export DESIGN.json --format fold|svg|obj|stl|scene-obj|scene-stl|gif|png|state-svg|print|all`.
//!
//! The design file is `{"pattern": <Pattern>, "meta": <DesignMeta>}` (see
//! [`crate::export::DesignFile`]); the synthesis stage writes one per feasible design.

use std::path::{Path, PathBuf};

use anyhow::Context as _;

use crate::export::{
    self, DesignFile, ExportOptions, FoldSpec, mesh, render, scene_mesh, sheet, svg,
};

/// What to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// FOLD file with the crease pattern and every folded frame.
    Fold,
    /// Crease pattern SVG (Origami Simulator colours).
    Svg,
    /// OBJ mesh of one state.
    Obj,
    /// STL mesh of one state (binary unless --stl-ascii).
    Stl,
    /// OBJ of one state with every copy and every obstacle (one object each).
    SceneObj,
    /// STL of the same scene (binary unless --stl-ascii).
    SceneStl,
    /// Animated GIF of the motion.
    Gif,
    /// PNG picture of one state.
    Png,
    /// SVG picture of one folded state.
    StateSvg,
    /// The print sheet at true scale on paper (PDF, and an SVG per sheet beside it).
    Print,
    /// Everything, into the directory --out.
    All,
}

impl Format {
    fn extension(self) -> &'static str {
        match self {
            Format::Fold => "fold",
            Format::Svg => "svg",
            Format::Obj => "obj",
            Format::Stl => "stl",
            Format::SceneObj => "scene.obj",
            Format::SceneStl => "scene.stl",
            Format::Gif => "gif",
            Format::Png => "png",
            Format::StateSvg => "state.svg",
            Format::Print => "print.pdf",
            Format::All => "export",
        }
    }
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{s:?}: expected WIDTHxHEIGHT, e.g. 480x360"))?;
    let p = |x: &str| {
        x.trim()
            .parse::<u32>()
            .map_err(|_| format!("{s:?}: expected WIDTHxHEIGHT in pixels, e.g. 480x360"))
    };
    Ok((p(w)?, p(h)?))
}

/// Arguments of `foldsynth export`.
#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// Design JSON: {"pattern": {vertices, edges, faces, frames}, "meta": {task, …}}.
    pub design: PathBuf,
    /// Output format.
    #[arg(long, value_enum)]
    pub format: Format,
    /// Output file (a directory for --format all). Default: the design's path with the
    /// format's extension.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// State for png, obj, stl, scene-obj, scene-stl and state-svg: index into the pattern's frames
    /// (0-based; default: the last frame).
    #[arg(long)]
    pub frame: Option<usize>,
    /// Vertex names (v1, v2, …) in the crease pattern SVG.
    #[arg(long)]
    pub labels: bool,
    /// Grey instead of Origami Simulator's yellow for flat creases.
    #[arg(long)]
    pub flat_grey: bool,
    /// FOLD spec version.
    #[arg(long, value_enum, default_value = "1.2")]
    pub spec: FoldSpec,
    /// ASCII STL instead of binary.
    #[arg(long)]
    pub stl_ascii: bool,
    /// Picture size in pixels.
    #[arg(long, default_value = "480x360", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Camera azimuth in degrees (about +z, from +x).
    #[arg(long, default_value_t = -60.0, allow_hyphen_values = true)]
    pub azimuth: f64,
    /// Camera elevation in degrees, in (−90, 90).
    #[arg(long, default_value_t = 25.0, allow_hyphen_values = true)]
    pub elevation: f64,
    /// Paper of the print sheet (print, all): a4, letter, a3 or WIDTHxHEIGHT in mm.
    #[arg(long, default_value = "a4", value_parser = sheet::Paper::parse)]
    pub paper: sheet::Paper,
    /// Scale of the print sheet (print, all): mm per paper unit (G0's first crease is 1
    /// unit), or fit (the largest of 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k mm that fits
    /// one sheet). A pattern larger than the paper is split over several sheets.
    #[arg(long, default_value = "fit", value_parser = sheet::PrintScale::parse, allow_hyphen_values = true)]
    pub print_scale: sheet::PrintScale,
}

fn default_out(design: &Path, f: Format) -> PathBuf {
    let stem = design
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "design".into());
    design.with_file_name(format!("{stem}.{}", f.extension()))
}

/// Run `foldsynth export`.
pub fn run(a: ExportArgs) -> anyhow::Result<()> {
    let d = DesignFile::read(&a.design)?;
    // Mesh obstacles are read only for what draws or meshes the scene: the FOLD file and
    // the crease pattern name them without their triangles.
    let draws = !matches!(
        a.format,
        Format::Fold | Format::Svg | Format::Obj | Format::Stl
    );
    let loaded = if draws {
        export::with_meshes(&d.meta)?
    } else {
        std::borrow::Cow::Borrowed(&d.meta)
    };
    let (p, meta) = (&d.pattern, &*loaded);
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| default_out(&a.design, a.format));
    let camera = render::Camera {
        azimuth_deg: a.azimuth,
        elevation_deg: a.elevation,
    };
    let n = p.frames.len();
    let frame = match a.frame {
        Some(k) if k >= n => anyhow::bail!(
            "--frame {k}: out of range; {} has {n} frames (0-based)",
            a.design.display()
        ),
        Some(k) => Some(k),
        None => n.checked_sub(1),
    };
    let print = sheet_options(&a, meta);
    let write = |bytes: Vec<u8>| -> anyhow::Result<()> {
        std::fs::write(&out, bytes).with_context(|| format!("writing {}", out.display()))
    };
    if matches!(a.format, Format::Svg | Format::All) {
        // The SVG's scale note: only when Origami Simulator would need a finer tolerance.
        let sc = svg::svg_scale(p, &svg::SvgOptions::default())?;
        if !sc.imports_with_default_tolerance() {
            eprintln!(
                "warning: {}: crease pattern SVG: {}",
                a.design.display(),
                sc.note
            );
        }
    }
    match a.format {
        Format::Fold => write(export::fold::to_fold_string(p, meta, a.spec)?.into_bytes())?,
        Format::Svg => write(
            svg::crease_pattern_svg(
                p,
                &svg::SvgOptions {
                    labels: a.labels,
                    flat_grey: a.flat_grey,
                    ..svg::SvgOptions::default()
                },
            )?
            .into_bytes(),
        )?,
        Format::Obj => write(
            mesh::to_obj(
                &mesh::state_mesh_copies(p, frame, &meta.scene.copies)?,
                &meta.task,
            )
            .into_bytes(),
        )?,
        Format::SceneObj => write(
            scene_mesh::to_obj(&scene_mesh::scene_mesh(p, frame, meta)?, &meta.task).into_bytes(),
        )?,
        Format::Stl | Format::SceneStl => {
            let m = if a.format == Format::Stl {
                mesh::state_mesh_copies(p, frame, &meta.scene.copies)?
            } else {
                scene_mesh::scene_mesh(p, frame, meta)?.as_state_mesh()
            };
            write(if a.stl_ascii {
                mesh::to_stl_ascii(&m, &meta.task).into_bytes()
            } else {
                mesh::to_stl_binary(&m)
            })?
        }
        Format::Gif => write(render::Scene::new(p, meta, camera)?.gif(a.size, 8, 60)?)?,
        Format::Png => write(render::Scene::new(p, meta, camera)?.png(frame, a.size)?)?,
        Format::StateSvg => write(
            render::Scene::new(p, meta, camera)?
                .svg(frame, a.size)
                .into_bytes(),
        )?,
        Format::Print => return print_sheet(&a, &out, p, &print),
        Format::All => {
            let name = a
                .design
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "design".into());
            let opts = ExportOptions {
                name,
                fold_spec: a.spec,
                labels: a.labels,
                flat_grey: a.flat_grey,
                image_size: a.size,
                camera,
                stl_binary: !a.stl_ascii,
                print: Some(print),
                ..ExportOptions::default()
            };
            let files = export::write_all(&out, p, meta, &opts)?;
            println!("{}", serde_json::to_string_pretty(&files)?);
            return Ok(());
        }
    }
    println!("{}", out.display());
    Ok(())
}

/// `--format print`: the sheets, and what was written.
fn print_sheet(
    a: &ExportArgs,
    out: &Path,
    p: &crate::pattern::Pattern,
    print: &sheet::SheetOptions,
) -> anyhow::Result<()> {
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--out: cannot create {}", dir.display()))?;
    }
    let (print, files) = sheet::write(out, p, print)?;
    println!(
        "{} sheet(s) of {} ({} x {}{}) at {} mm per unit; cut line {} mm",
        print.pages.len(),
        print.paper,
        print.grid[0],
        print.grid[1],
        if print.landscape { ", landscape" } else { "" },
        crate::text::num(print.mm_per_unit),
        crate::text::num((print.sheet.cut_length() * print.mm_per_unit * 10.0).round() / 10.0)
    );
    if let Some(n) = &print.sheet.note {
        eprintln!("note: {}: {n}", a.design.display());
    }
    for f in files {
        println!("wrote {}", f.display());
    }
    Ok(())
}

/// The print sheet's options from the flags; the copies are the design's.
fn sheet_options(a: &ExportArgs, meta: &export::DesignMeta) -> sheet::SheetOptions {
    sheet::SheetOptions {
        paper: a.paper.clone(),
        scale: a.print_scale,
        labels: a.labels,
        title: a
            .design
            .file_stem()
            .map_or("design".into(), |s| s.to_string_lossy().into_owned()),
        copies: meta.scene.copies,
        ..Default::default()
    }
}
