//! `foldsynth fabricate DESIGN.json [--thickness MM] [--scale MM_PER_UNIT] --out DIR`: thick
//! panels for a design (issue 32): ply drawings (DXF R12 + SVG), panel solids and
//! assemblies (STL + 3MF), and `fabrication.json` (the bill and the hinge axes).
//! The material comes from the flags, then from the design's `fabrication.bill` (a search
//! with `[fabrication]` writes one), then from the defaults; the record says which.

use std::path::PathBuf;

use anyhow::{Context as _, bail};

use crate::check::thick::ThickInput;
use crate::export::{DesignFile, laser, print};
use crate::fabricate;
use crate::task::fabrication::{
    DEFAULT_HINGE_GAP_MM, DEFAULT_MIN_WIDTH_MM, FabMethod, Fabrication, MAX_LENGTH_MM, Sides,
};

/// Arguments of `foldsynth fabricate`.
#[derive(Debug, clap::Args)]
pub struct FabricateArgs {
    /// Design JSON as `synthesize` writes it (`OUT/designs/<id>.json`).
    pub design: PathBuf,
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
    /// Output directory (created).
    #[arg(long)]
    pub out: PathBuf,
}

/// `--clearance`'s default, mm: half a millimetre between panels that pass each other.
pub const DEFAULT_CLEARANCE_MM: f64 = 0.5;

/// Where each value of the setting came from: `"flag"`, `"design"` (its
/// `fabrication.bill`) or `"default"`.
type Sources = serde_json::Map<String, serde_json::Value>;

/// A design file's `fabrication.bill` (as `synthesize` writes it for a task with
/// `[fabrication]`), validated; `None` when the file has none. Errors name the file and
/// the bill's field.
fn design_bill(path: &std::path::Path) -> anyhow::Result<Option<Fabrication>> {
    let text = crate::limits::read_text(path).with_context(|| format!("{}", path.display()))?;
    let doc: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{}: not a JSON design file", path.display()))?;
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

/// The setting from the flags, then the design's bill, then the defaults (thickness and
/// scale have none); errors name the flag (or the design's field). With it, where each
/// value came from.
fn setting(a: &FabricateArgs) -> anyhow::Result<(Fabrication, Sources)> {
    let bill = design_bill(&a.design)?;
    let mut from = Sources::new();
    let mut pick = |name: &str, flag: Option<f64>, design: Option<f64>, default: Option<f64>| {
        let (v, src) = match (flag, design, default) {
            (Some(v), _, _) => (v, "flag"),
            (None, Some(v), _) => (v, "design"),
            (None, None, Some(v)) => (v, "default"),
            (None, None, None) => bail!(
                "--{name}: required: {} has no fabrication.bill to take it from (a design of a task with [fabrication] has one)",
                a.design.display()
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
    if !(a.clearance.is_finite() && (0.0..=MAX_LENGTH_MM).contains(&a.clearance)) {
        bail!(
            "--clearance: must be a number of mm in [0, {}], got {}",
            crate::text::num(MAX_LENGTH_MM),
            crate::text::num(a.clearance)
        );
    }
    Ok((spec, from))
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

/// Run `foldsynth fabricate`.
pub fn run(a: FabricateArgs) -> anyhow::Result<()> {
    let d = DesignFile::read(&a.design)?;
    let (spec, from) = setting(&a)?;
    let pattern = &d.pattern;
    let wanted = states(&a.states, &pattern.frames)?;
    let ranges = fabricate::fold_ranges_refined(pattern, &pattern.frames);
    let design = fabricate::build(pattern, &ranges, &spec)
        .with_context(|| format!("{}: cannot fabricate", a.design.display()))?;
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("--out {}: cannot create the directory", a.out.display()))?;
    let mut files = laser::write_plies(&a.out, pattern, &design)?;
    let st: Vec<print::State<'_>> = wanted
        .iter()
        .map(|(n, f)| (n.clone(), f.map(|i| &pattern.frames[i])))
        .collect();
    files.extend(print::write_solids(&a.out, pattern, &design, &st)?);
    let bill = design.bill();
    // Whether the thick panels still fold without collision: the actual solids, moved by
    // the design's frames (the search checks its dense sweep; a design file holds its
    // frames only), tested by the search's independent mesh check.
    let check = crate::check::thick::check(&ThickInput {
        pattern,
        design: &design,
        clearance: a.clearance / spec.scale,
        obstacle_clearance: 0.0,
        obstacles: &[],
        touching: &[],
    });
    let json = a.out.join("fabrication.json");
    let text = serde_json::to_string_pretty(&serde_json::json!({
        "design": a.design.display().to_string(),
        "states": wanted.iter().map(|(n, f)| serde_json::json!({"name": n, "frame": f})).collect::<Vec<_>>(),
        "fabrication": bill,
        "material_from": from,
        "check": check,
    }))?;
    std::fs::write(&json, text + "\n").with_context(|| format!("{}", json.display()))?;
    files.push(json);
    println!(
        "{} panels, {} hinges, {} mm thick (sides = {}) at {} mm per unit (thickness from the {}, scale from the {}); widest hinge gap {:.3} mm",
        design.panels.len(),
        design.hinges.len(),
        crate::text::num(spec.thickness),
        spec.sides.name(),
        crate::text::num(spec.scale),
        from["thickness"].as_str().unwrap_or_default(),
        from["scale"].as_str().unwrap_or_default(),
        design.hinges.iter().map(|h| h.gap_mm).fold(0.0, f64::max)
    );
    for f in files {
        println!("wrote {}", f.display());
    }
    let mm = |d: Option<f64>| d.map_or("–".to_string(), |d| format!("{:.3} mm", d * spec.scale));
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
            a.design.display(),
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
