//! The files of a thick design (issues 32 and 50), as `foldsynth fabricate` and a search
//! with `[fabrication]` write them into one folder: the plies laid out on their sheet
//! ([`super::laminate`]: `ply-<name>.dxf`, `.svg`), the panel solids and assemblies
//! ([`super::print`]: `panel-<facet>.stl`, `.3mf`, `assembly-<state>.stl`, `.3mf`) and
//! `fabrication.json` (the caller's record, the states, the bill and the layout).

use std::path::{Path, PathBuf};

use super::laminate::{self, Layout, Refusal};
use super::laser::{self, PlyDrawing};
use super::{Result, print};
use crate::fabricate::ThickDesign;
use crate::pattern::Pattern;
use crate::task::fabrication::{Laminate, Sides};

/// The plies of a design laid out on its sheet, and where everything lies.
#[derive(Clone, Debug, PartialEq)]
pub struct Laid {
    /// The drawings, sheet mm.
    pub plies: Vec<PlyDrawing>,
    /// The layout, for `fabrication.json`.
    pub layout: Layout,
}

/// The plies of `design` laid out with `lam` ([`laminate::lay_out`]); a refusal names the
/// setting's field.
pub fn lay_out(pattern: &Pattern, design: &ThickDesign, lam: &Laminate) -> Result<Laid, Refusal> {
    let (plies, layout) = laminate::lay_out(laser::plies(pattern, design), lam)?;
    Ok(Laid { plies, layout })
}

/// The ply names of a design: `rigid` and `hinge` with one side, `top`, `bottom` and
/// `hinge` with both.
pub fn ply_names(design: &ThickDesign) -> Vec<&'static str> {
    match design.spec.sides {
        Sides::One => vec!["rigid", "hinge"],
        Sides::Both => vec!["top", "bottom", "hinge"],
    }
}

/// The files [`write()`] writes into `dir` for `design` and the states named `states`, in
/// writing order (so a caller can list them before they exist).
pub fn planned(dir: &Path, design: &ThickDesign, states: &[&str]) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for name in ply_names(design) {
        out.push(dir.join(format!("ply-{name}.dxf")));
        out.push(dir.join(format!("ply-{name}.svg")));
    }
    for p in &design.panels {
        out.push(dir.join(format!("panel-{}.stl", p.facet)));
        out.push(dir.join(format!("panel-{}.3mf", p.facet)));
    }
    for s in states {
        out.push(dir.join(format!("assembly-{s}.stl")));
        out.push(dir.join(format!("assembly-{s}.3mf")));
    }
    out.push(dir.join("fabrication.json"));
    out
}

/// Write plies as `<prefix>ply-<name>.dxf` and `.svg` into `dir`.
pub fn write_plies(dir: &Path, prefix: &str, plies: &[PlyDrawing]) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for ply in plies {
        let dxf = dir.join(format!("{prefix}ply-{}.dxf", ply.name));
        laser::write_dxf(&dxf, ply)?;
        let svg = dir.join(format!("{prefix}ply-{}.svg", ply.name));
        laser::write_svg(&svg, ply)?;
        files.extend([dxf, svg]);
    }
    Ok(files)
}

/// Write every file of `design` into `dir` (which must exist): the plies of `laid`, the
/// solids of every panel and the assemblies at `states`, and `fabrication.json`: `record`
/// (the caller's keys) with `states`, `fabrication` (the bill) and `laminate` (the layout).
/// The paths, as [`planned`] lists them.
pub fn write(
    dir: &Path,
    pattern: &Pattern,
    design: &ThickDesign,
    states: &[print::State<'_>],
    laid: &Laid,
    mut record: serde_json::Map<String, serde_json::Value>,
) -> Result<Vec<PathBuf>> {
    let mut files = write_plies(dir, "", &laid.plies)?;
    files.extend(print::write_solids(dir, pattern, design, states)?);
    let frame_of = |f: &Option<&crate::pattern::Frame>| {
        f.and_then(|f| pattern.frames.iter().position(|g| std::ptr::eq(g, f)))
    };
    record.insert(
        "states".into(),
        states
            .iter()
            .map(|(n, f)| serde_json::json!({"name": n, "frame": frame_of(f)}))
            .collect(),
    );
    record.insert("fabrication".into(), serde_json::json!(design.bill()));
    record.insert("laminate".into(), serde_json::json!(laid.layout));
    let json = dir.join("fabrication.json");
    let text = serde_json::to_string_pretty(&record).unwrap_or_default();
    super::write_file(&json, text + "\n")?;
    files.push(json);
    Ok(files)
}
