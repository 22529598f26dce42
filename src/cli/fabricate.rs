//! `foldsynth fabricate DESIGN.json --thickness MM --scale MM_PER_UNIT --out DIR`: thick
//! panels for a design (issue 32): ply drawings (DXF R12 + SVG), panel solids and
//! assemblies (STL + 3MF), and `fabrication.json` (the bill and the hinge axes).

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
    /// Panel thickness in mm.
    #[arg(long, allow_hyphen_values = true)]
    pub thickness: f64,
    /// mm per paper unit (the design's first crease of G0 is 1 unit).
    #[arg(long, allow_hyphen_values = true)]
    pub scale: f64,
    /// The construction: tapered (volume trimming, Tachi 2011).
    #[arg(long, default_value = "tapered")]
    pub method: String,
    /// Where the slab lies: one (on the +normal side of the sheet) or both (centred).
    #[arg(long, default_value = "one")]
    pub sides: String,
    /// Smallest gap between two panels at a crease, mm.
    #[arg(long, default_value_t = DEFAULT_HINGE_GAP_MM, allow_hyphen_values = true)]
    pub hinge_gap: f64,
    /// Narrowest a trimmed panel may become, mm.
    #[arg(long, default_value_t = DEFAULT_MIN_WIDTH_MM, allow_hyphen_values = true)]
    pub min_width: f64,
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

/// The setting from the flags; errors name the flag.
fn setting(a: &FabricateArgs) -> anyhow::Result<Fabrication> {
    let Some(method) = FabMethod::from_name(&a.method) else {
        bail!(
            "--method: unknown method '{}'; allowed: {}",
            crate::text::excerpt(&a.method, 40),
            FabMethod::NAMES.join(", ")
        );
    };
    let Some(sides) = Sides::from_name(&a.sides) else {
        bail!(
            "--sides: unknown value '{}'; allowed: {}",
            crate::text::excerpt(&a.sides, 40),
            Sides::NAMES.join(", ")
        );
    };
    let spec = Fabrication {
        thickness: a.thickness,
        scale: a.scale,
        method,
        sides,
        hinge_gap: a.hinge_gap,
        min_width: a.min_width,
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
    Ok(spec)
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
    let spec = setting(&a)?;
    let d = DesignFile::read(&a.design)?;
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
        "check": check,
    }))?;
    std::fs::write(&json, text + "\n").with_context(|| format!("{}", json.display()))?;
    files.push(json);
    println!(
        "{} panels, {} hinges, {} mm thick (sides = {}) at {} mm per unit; widest hinge gap {:.3} mm",
        design.panels.len(),
        design.hinges.len(),
        crate::text::num(spec.thickness),
        spec.sides.name(),
        crate::text::num(spec.scale),
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
