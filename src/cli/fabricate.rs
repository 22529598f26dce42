//! `foldsynth fabricate DESIGN.json... [--thickness MM] [--scale MM_PER_UNIT] --out DIR`:
//! thick panels for a design (issue 32): ply drawings (DXF R12 + SVG) laid out on a sheet
//! with kerf, tabs, registration crosses and alignment holes (issue 50), panel solids and
//! assemblies (STL + 3MF), and `fabrication.json` (the bill, the layout and the check), all
//! written by [`crate::export::fabrication_files`]. The material comes from the flags, then
//! from the design's `fabrication.bill` and `fabrication.laminate` (a search with
//! `[fabrication]` writes them), then from the defaults; the record says which. Several
//! designs with `--sheet` are also laid out side by side on one sheet.

use std::path::PathBuf;

use anyhow::{Context as _, bail};

use crate::check::thick::{ThickInput, ThickReport};
use crate::export::fabrication_files::{self, Laid};
use crate::export::{DesignFile, laminate, print};
use crate::fabricate;
use crate::pattern::Pattern;
use crate::task::fabrication::{
    DEFAULT_HINGE_GAP_MM, DEFAULT_HOLE_MM, DEFAULT_MIN_WIDTH_MM, FabMethod, Fabrication, Laminate,
    MAX_LENGTH_MM, Sides,
};

/// Arguments of `foldsynth fabricate`.
#[derive(Debug, clap::Args)]
pub struct FabricateArgs {
    /// Design JSON as `synthesize` writes it (`OUT/designs/<id>.json`). Several (with
    /// `--sheet`): each design's files go to `OUT/<file stem>/`, and their plies side by
    /// side on one sheet to `OUT/sheet-ply-<name>.dxf`, `.svg`.
    #[arg(required = true, num_args = 1..)]
    pub design: Vec<PathBuf>,
    /// Panel thickness in mm (default: the design's `fabrication.bill`; required without
    /// one).
    #[arg(long, allow_hyphen_values = true)]
    pub thickness: Option<f64>,
    /// mm per paper unit, the design's first crease of G0 being 1 unit (default: the
    /// design's `fabrication.bill`; required without one).
    #[arg(long, allow_hyphen_values = true)]
    pub scale: Option<f64>,
    /// The construction: tapered (volume trimming, Tachi 2011). Default: the design's
    /// bill, else tapered.
    #[arg(long)]
    pub method: Option<String>,
    /// Where the slab lies: one (on the +normal side of the sheet) or both (centred).
    /// Default: the design's bill, else one.
    #[arg(long)]
    pub sides: Option<String>,
    /// Smallest gap between two panels at a crease, mm. Default: the design's bill, else
    /// 0.5.
    #[arg(long, allow_hyphen_values = true)]
    pub hinge_gap: Option<f64>,
    /// Narrowest a trimmed panel may become, mm. Default: the design's bill, else 2.
    #[arg(long, allow_hyphen_values = true)]
    pub min_width: Option<f64>,
    /// The least gap, mm, between two panels that share no vertex, checked on every frame
    /// of the design (panels that share a crease or a vertex must not cross).
    #[arg(long, default_value_t = DEFAULT_CLEARANCE_MM, allow_hyphen_values = true)]
    pub clearance: f64,
    /// States to assemble, comma-separated: flat, half (the frame nearest the middle of
    /// the motion's t), folded (the last frame).
    #[arg(long, default_value = "flat,half,folded")]
    pub states: String,
    /// The laser's kerf, mm: every cut is offset by half of it so that each part keeps its
    /// nominal size. Default: the design's laminate, else 0.
    #[arg(long, allow_hyphen_values = true)]
    pub kerf: Option<f64>,
    /// Tabs (bridges) of this width, mm, left in each panel's cut on the rigid plies (cut
    /// after lamination). Default: the design's laminate, else 0 (none).
    #[arg(long, allow_hyphen_values = true)]
    pub tab_width: Option<f64>,
    /// Diameter of the alignment holes, mm. Default: the design's laminate, else 3.
    #[arg(long, allow_hyphen_values = true)]
    pub hole: Option<f64>,
    /// The sheet every ply is laid out on, `WxH` in mm (e.g. `600x400`). Default: the
    /// design's laminate, else the pattern's bounds plus the margin.
    #[arg(long)]
    pub sheet: Option<String>,
    /// Output directory (created).
    #[arg(long)]
    pub out: PathBuf,
}

/// `--clearance`'s default, mm: half a millimetre between panels that pass each other.
pub const DEFAULT_CLEARANCE_MM: f64 = 0.5;

/// Where each value of the setting came from: `"flag"`, `"design"` (its
/// `fabrication.bill`) or `"default"`.
type Sources = serde_json::Map<String, serde_json::Value>;

/// A design file's `fabrication.bill` and `fabrication.laminate` (as `synthesize` writes
/// them for a task with `[fabrication]`), validated; `None` where the file has none. Errors
/// name the file and the field.
fn design_setting(
    path: &std::path::Path,
) -> anyhow::Result<(Option<Fabrication>, Option<Laminate>)> {
    let text = crate::limits::read_text(path).with_context(|| format!("{}", path.display()))?;
    let doc: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a JSON design file", path.display()))?;
    let lam = match &doc["fabrication"]["laminate"] {
        serde_json::Value::Null => None,
        raw => {
            let lam: Laminate = serde_json::from_value(raw.clone()).with_context(|| {
                format!(
                    "{}: fabrication.laminate is not a laminate as synthesize writes it",
                    path.display()
                )
            })?;
            if let Err((field, message)) = lam.validate() {
                bail!(
                    "{}: fabrication.laminate.{field}: {message}",
                    path.display()
                );
            }
            Some(lam)
        }
    };
    Ok((design_bill(path, &doc)?, lam))
}

/// The design's `fabrication.bill`, validated.
fn design_bill(
    path: &std::path::Path,
    doc: &serde_json::Value,
) -> anyhow::Result<Option<Fabrication>> {
    let raw = &doc["fabrication"]["bill"];
    if raw.is_null() {
        return Ok(None);
    }
    let bill: fabricate::Bill = serde_json::from_value(raw.clone()).with_context(|| {
        format!(
            "{}: fabrication.bill is not a bill as synthesize writes it",
            path.display()
        )
    })?;
    match bill.setting() {
        Ok(spec) => Ok(Some(spec)),
        Err((field, message)) => bail!(
            "{}: fabrication.bill.{}: {message}",
            path.display(),
            fabricate::Bill::field_name(field)
        ),
    }
}

/// The setting from the flags, then the design's bill (and laminate), then the defaults
/// (thickness and scale have none); errors name the flag (or the design's field). With
/// them, where each value came from.
fn setting(
    a: &FabricateArgs,
    path: &std::path::Path,
) -> anyhow::Result<(Fabrication, Laminate, Sources)> {
    let (bill, lam) = design_setting(path)?;
    let mut from = Sources::new();
    let mut pick = |name: &str, flag: Option<f64>, design: Option<f64>, default: Option<f64>| {
        let (v, src) = match (flag, design, default) {
            (Some(v), _, _) => (v, "flag"),
            (None, Some(v), _) => (v, "design"),
            (None, None, Some(v)) => (v, "default"),
            (None, None, None) => bail!(
                "--{name}: required: {} has no fabrication.bill to take it from (a design of a task with [fabrication] has one)",
                path.display()
            ),
        };
        from.insert(name.replace('-', "_"), src.into());
        Ok::<_, anyhow::Error>(v)
    };
    let thickness = pick("thickness", a.thickness, bill.map(|b| b.thickness), None)?;
    let scale = pick("scale", a.scale, bill.map(|b| b.scale), None)?;
    let hinge_gap = pick(
        "hinge-gap",
        a.hinge_gap,
        bill.map(|b| b.hinge_gap),
        Some(DEFAULT_HINGE_GAP_MM),
    )?;
    let min_width = pick(
        "min-width",
        a.min_width,
        bill.map(|b| b.min_width),
        Some(DEFAULT_MIN_WIDTH_MM),
    )?;
    let kerf = pick("kerf", a.kerf, lam.map(|l| l.kerf), Some(0.0))?;
    let tab_width = pick(
        "tab-width",
        a.tab_width,
        lam.map(|l| l.tab_width),
        Some(0.0),
    )?;
    let hole = pick("hole", a.hole, lam.map(|l| l.hole), Some(DEFAULT_HOLE_MM))?;
    let method = match &a.method {
        Some(name) => {
            from.insert("method".into(), "flag".into());
            FabMethod::from_name(name).with_context(|| {
                format!(
                    "--method: unknown method '{}'; allowed: {}",
                    crate::text::excerpt(name, 40),
                    FabMethod::NAMES.join(", ")
                )
            })?
        }
        None => {
            let src = if bill.is_some() { "design" } else { "default" };
            from.insert("method".into(), src.into());
            bill.map_or(FabMethod::Tapered, |b| b.method)
        }
    };
    let sides = match &a.sides {
        Some(name) => {
            from.insert("sides".into(), "flag".into());
            Sides::from_name(name).with_context(|| {
                format!(
                    "--sides: unknown value '{}'; allowed: {}",
                    crate::text::excerpt(name, 40),
                    Sides::NAMES.join(", ")
                )
            })?
        }
        None => {
            let src = if bill.is_some() { "design" } else { "default" };
            from.insert("sides".into(), src.into());
            bill.map_or(Sides::One, |b| b.sides)
        }
    };
    let spec = Fabrication {
        thickness,
        scale,
        method,
        sides,
        hinge_gap,
        min_width,
    };
    if let Err((field, message)) = spec.validate() {
        bail!("--{}: {message}", field.replace('_', "-"));
    }
    let sheet = match &a.sheet {
        Some(text) => {
            from.insert("sheet".into(), "flag".into());
            Some(Laminate::parse_sheet(text).map_err(|m| anyhow::anyhow!("--sheet: {m}"))?)
        }
        None => {
            let given = lam.and_then(|l| l.sheet);
            let src = if given.is_some() { "design" } else { "default" };
            from.insert("sheet".into(), src.into());
            given
        }
    };
    let lam = Laminate {
        kerf,
        tab_width,
        hole,
        sheet,
    };
    if let Err((field, message)) = lam.validate() {
        bail!("--{}: {message}", field.replace('_', "-"));
    }
    if !(a.clearance.is_finite() && (0.0..=MAX_LENGTH_MM).contains(&a.clearance)) {
        bail!(
            "--clearance: must be a number of mm in [0, {}], got {}",
            crate::text::num(MAX_LENGTH_MM),
            crate::text::num(a.clearance)
        );
    }
    Ok((spec, lam, from))
}

/// The states asked for, as (name, frame index or `None` for flat).
fn states(
    text: &str,
    frames: &[crate::pattern::Frame],
) -> anyhow::Result<Vec<(String, Option<usize>)>> {
    let mut out = Vec::new();
    for name in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let frame = match name {
            "flat" => None,
            "folded" | "half" if frames.is_empty() => {
                bail!("--states: '{name}' needs folded frames; the design has none")
            }
            "folded" => Some(frames.len() - 1),
            "half" => {
                let (t0, t1) = (frames[0].t, frames[frames.len() - 1].t);
                let mid = 0.5 * (t0 + t1);
                (0..frames.len()).min_by(|&i, &j| {
                    (frames[i].t - mid)
                        .abs()
                        .total_cmp(&(frames[j].t - mid).abs())
                })
            }
            _ => bail!(
                "--states: unknown state '{}'; allowed: flat, half, folded",
                crate::text::excerpt(name, 40)
            ),
        };
        if !out.iter().any(|(n, _)| n == name) {
            out.push((name.to_string(), frame));
        }
    }
    if out.is_empty() {
        bail!("--states: name at least one of flat, half, folded");
    }
    Ok(out)
}

/// One design, built and checked, its plies laid out: everything but the files.
struct Built {
    path: PathBuf,
    pattern: Pattern,
    spec: Fabrication,
    lam: Laminate,
    from: Sources,
    wanted: Vec<(String, Option<usize>)>,
    design: fabricate::ThickDesign,
    laid: Laid,
    check: ThickReport,
}

/// Read, build, check and lay out one design; every refusal (exit 2) comes from here,
/// before any file is written.
fn build_one(a: &FabricateArgs, path: &std::path::Path) -> anyhow::Result<Built> {
    let d = DesignFile::read(path)?;
    let (spec, lam, from) = setting(a, path)?;
    let pattern = d.pattern;
    let wanted = states(&a.states, &pattern.frames)?;
    let ranges = fabricate::fold_ranges_refined(&pattern, &pattern.frames);
    let design = fabricate::build(&pattern, &ranges, &spec)
        .with_context(|| format!("{}: cannot fabricate", path.display()))?;
    let laid = fabrication_files::lay_out(&pattern, &design, &lam).map_err(|(field, m)| {
        anyhow::anyhow!("--{}: {}: {m}", field.replace('_', "-"), path.display())
    })?;
    // Whether the thick panels still fold without collision: the actual solids, moved by
    // the design's frames (the search checks its dense sweep; a design file holds its
    // frames only), tested by the search's independent mesh check.
    let check = crate::check::thick::check(&ThickInput {
        pattern: &pattern,
        design: &design,
        clearance: a.clearance / spec.scale,
        obstacle_clearance: 0.0,
        obstacles: &[],
        touching: &[],
    });
    Ok(Built {
        path: path.to_path_buf(),
        pattern,
        spec,
        lam,
        from,
        wanted,
        design,
        laid,
        check,
    })
}

/// Write one built design's files into `out` (created) and say what was written.
fn write_one(b: &Built, out: &std::path::Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("--out {}: cannot create the directory", out.display()))?;
    let st: Vec<print::State<'_>> = b
        .wanted
        .iter()
        .map(|(n, f)| (n.clone(), f.map(|i| &b.pattern.frames[i])))
        .collect();
    let mut record = serde_json::Map::new();
    record.insert("design".into(), b.path.display().to_string().into());
    record.insert("material_from".into(), b.from.clone().into());
    record.insert("check".into(), serde_json::json!(b.check));
    let files = fabrication_files::write(out, &b.pattern, &b.design, &st, &b.laid, record)?;
    let (spec, l) = (&b.spec, &b.laid.layout);
    println!(
        "{} panels, {} hinges, {} mm thick (sides = {}) at {} mm per unit (thickness from the {}, scale from the {}); widest hinge gap {:.3} mm",
        b.design.panels.len(),
        b.design.hinges.len(),
        crate::text::num(spec.thickness),
        spec.sides.name(),
        crate::text::num(spec.scale),
        b.from["thickness"].as_str().unwrap_or_default(),
        b.from["scale"].as_str().unwrap_or_default(),
        b.design.hinges.iter().map(|h| h.gap_mm).fold(0.0, f64::max)
    );
    println!(
        "sheet {:.1}x{:.1} mm, kerf {} mm, {} tabs of {} mm, {} alignment holes of {} mm, {} registration crosses",
        l.sheet_mm[0],
        l.sheet_mm[1],
        crate::text::num(b.lam.kerf),
        l.tabs.len(),
        crate::text::num(b.lam.tab_width),
        l.holes_mm.len(),
        crate::text::num(b.lam.hole),
        l.marks_mm.len()
    );
    for f in files {
        println!("wrote {}", f.display());
    }
    Ok(())
}

/// The check's line, or the failure (exit 1) naming the panels and the state.
fn verdict(a: &FabricateArgs, b: &Built) -> anyhow::Result<()> {
    let check = &b.check;
    let mm =
        |d: Option<f64>| d.map_or("–".to_string(), |d| format!("{:.3} mm", d * b.spec.scale));
    match &check.first_failure {
        None => {
            println!(
                "thick check on the design's {} frames: passes (least gap between panels that share no vertex {}, clearance {} mm)",
                check.states,
                mm(check.least_apart),
                crate::text::num(a.clearance)
            );
            Ok(())
        }
        Some(hit) => Err(super::CheckFailed(format!(
            "{}: the thick panels collide: {} (panels {}) at t = {:.4}; the files are written, and fabrication.json holds the check",
            b.path.display(),
            match hit.kind.as_str() {
                "crossing" => "panels that share a crease or a vertex cross".to_string(),
                _ => format!(
                    "{} apart, below --clearance {} mm",
                    mm(Some(hit.distance)),
                    crate::text::num(a.clearance)
                ),
            },
            hit.facets
                .iter()
                .map(|f| format!("P{f}"))
                .collect::<Vec<_>>()
                .join(", "),
            hit.t
        ))
        .into()),
    }
}

/// Run `foldsynth fabricate`.
pub fn run(a: FabricateArgs) -> anyhow::Result<()> {
    if let [one] = &a.design[..] {
        let b = build_one(&a, one)?;
        write_one(&b, &a.out)?;
        return verdict(&a, &b);
    }
    if a.sheet.is_none() {
        bail!(
            "--sheet: required to lay out {} designs on one sheet: give its size as WxH mm, e.g. 600x400",
            a.design.len()
        );
    }
    let mut stems: Vec<String> = Vec::new();
    let mut built = Vec::new();
    for path in &a.design {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if stem.is_empty() || stems.contains(&stem) {
            bail!(
                "{}: two designs would share the folder {:?} under --out: give designs whose file names differ",
                path.display(),
                stem
            );
        }
        stems.push(stem);
        built.push(build_one(&a, path)?);
    }
    let lam = built[0].lam;
    let raw = built
        .iter()
        .map(|b| crate::export::laser::plies(&b.pattern, &b.design))
        .collect();
    let (sheet, offsets) = laminate::lay_out_many(raw, &lam)
        .map_err(|(field, m)| anyhow::anyhow!("--{}: {m}", field.replace('_', "-")))?;
    for (b, stem) in built.iter().zip(&stems) {
        write_one(b, &a.out.join(stem))?;
    }
    write_sheet(&a.out, &sheet, &lam, &stems, &offsets)?;
    let mut first = Ok(());
    for b in &built {
        let v = verdict(&a, b);
        if first.is_ok() {
            first = v;
        }
    }
    first
}

/// The combined plies (`sheet-ply-<name>.dxf`, `.svg`) and `sheet-layout.json`: the sheet,
/// the holes and crosses, and each design's folder and offset.
fn write_sheet(
    out: &std::path::Path,
    plies: &[crate::export::laser::PlyDrawing],
    lam: &Laminate,
    stems: &[String],
    offsets: &[[f64; 2]],
) -> anyhow::Result<()> {
    let mut files = fabrication_files::write_plies(out, "sheet-", plies)?;
    let Some(sheet) = lam.sheet else {
        bail!("--sheet: required");
    };
    let json = out.join("sheet-layout.json");
    let designs: Vec<_> = stems
        .iter()
        .zip(offsets)
        .map(|(s, o)| serde_json::json!({"folder": s, "offset_mm": o}))
        .collect();
    let text = serde_json::to_string_pretty(&serde_json::json!({
        "sheet_mm": sheet,
        "kerf_mm": lam.kerf,
        "tab_width_mm": lam.tab_width,
        "hole_mm": lam.hole,
        "margin_mm": laminate::margin_mm(lam),
        "gap_mm": laminate::GAP_MM,
        "holes_mm": laminate::holes(sheet, lam),
        "marks_mm": laminate::marks(sheet, lam),
        "mark_arm_mm": laminate::mark_arm_mm(lam),
        "designs": designs,
    }))?;
    std::fs::write(&json, text + "\n").with_context(|| format!("{}", json.display()))?;
    files.push(json);
    for f in files {
        println!("wrote {}", f.display());
    }
    Ok(())
}
