//! The crease pattern as SVG, in the convention Origami Simulator imports
//! (amandaghassaei/OrigamiSimulator, `js/pattern.js`, "File > Design Tips").
//!
//! - One `<line>` per edge, no groups, no transforms.
//! - Stroke colour gives the type: mountain `#ff0000`, valley `#0000ff`, boundary
//!   `#000000`. Creases that stay flat over the whole motion (`F`) are `#ffff00`, which
//!   Origami Simulator reads as a flat "facet" crease; any other colour it would drop with
//!   a warning. With [`SvgOptions::flat_grey`] they are grey (`#808080`) instead, for
//!   figures meant for people rather than for import.
//! - Origami Simulator reads the target fold angle of M/V lines from opacity:
//!   angle = ±180° × opacity × stroke-opacity. We write `opacity="1"` and
//!   `stroke-opacity` = |fold angle at the last frame| / 180°, so importing the SVG folds
//!   to our final state. (A crease folded by a few degrees is therefore faint.)
//! - The y-axis is flipped (SVG y points down) so the picture has y up like the pattern;
//!   in Origami Simulator this gives the mirror image of our folded state, with the same
//!   mountains and valleys.
//! - Each line carries `data-edge`, `data-assignment`, `data-fold-angle` (degrees) and
//!   `data-driven` attributes; importers ignore them. Vertex names (`labels`: v1, v2, …,
//!   1-based like everywhere foldsynth numbers vertices for people) are
//!   `<text>` elements, which Origami Simulator ignores too.
//!
//! ## Scale: every feature at least 3 px
//!
//! Origami Simulator's SVG importer snaps: it merges vertices closer than its "vertex
//! merge tolerance" (3 px by default, `globals.vertTol`), splits an edge at any vertex that
//! lies within the tolerance of it (measured along the other edge's line, which is never
//! less than the vertex's distance from the edge), then drops duplicate edges. A pattern
//! whose smallest feature ([`crate::check::features`]: vertex–vertex and vertex–edge
//! distances, edge lengths) is larger than the tolerance therefore imports unchanged, and
//! one with a smaller feature may change shape silently.
//!
//! So the page is [`SvgOptions::scale`] (200) px per unit, and more where the pattern's
//! smallest feature needs it to reach [`SvgOptions::min_feature_px`] (3.1 px: the
//! tolerance plus room for rounding), rounded up to 1, 2, 2.5 or 5 × 10ᵏ px per unit — as
//! long as the page's width and height stay within [`SvgOptions::max_page_px`] (16384 px).
//! Where that is not enough the page is as large as allowed, and the file says so (an XML
//! comment and `data-` attributes on `<svg>`), as does [`svg_scale`]'s [`SvgScale`] (in each
//! design JSON as `svg`), with the largest tolerance that imports the file exactly.
//! Coordinates carry enough decimals that rounding moves no feature by more than 1%.

use std::fmt::Write as _;

use serde::Serialize;

use super::fold::{Assignment, assignments, wrap};
use super::plots::xml_escape;
use super::{Result, validate_pattern};
use crate::check::features::pattern_min_feature;
use crate::pattern::{EdgeKind, Pattern};

/// Origami Simulator's default vertex merge tolerance in px (`globals.vertTol`).
pub const ORIGAMI_SIMULATOR_TOLERANCE_PX: f64 = 3.0;

/// Default [`SvgOptions::min_feature_px`]: Origami Simulator's tolerance plus 0.1 px, so
/// that neither the coordinates' rounding nor a `<` read as `≤` can bring a feature down
/// to it.
pub const DEFAULT_MIN_FEATURE_PX: f64 = 3.1;

/// Default [`SvgOptions::max_page_px`]: 16384 px. SVG itself has no limit, but the tools
/// that show or rasterize a page commonly cap a side at 16384 px (the usual largest GPU
/// texture and the limit of several browsers' canvases), and at 96 px per inch it is 4.3 m,
/// beyond any printer or cutter bed.
pub const DEFAULT_MAX_PAGE_PX: f64 = 16384.0;

/// Options of [`crease_pattern_svg`].
#[derive(Clone, Debug)]
pub struct SvgOptions {
    /// Draw vertex numbers (0-based, as in the FOLD file).
    pub labels: bool,
    /// Flat creases grey instead of Origami Simulator's yellow.
    pub flat_grey: bool,
    /// Pixels per pattern unit at least; more where features need it (see
    /// [`SvgOptions::min_feature_px`]).
    pub scale: f64,
    /// Every feature of the flat layout should be at least this many px on the page (0:
    /// always [`SvgOptions::scale`]).
    pub min_feature_px: f64,
    /// Largest width and height of the page in px, margins included, up to which the scale
    /// grows for the features. A pattern that is larger than this at
    /// [`SvgOptions::scale`] keeps that scale.
    pub max_page_px: f64,
    /// Margin in pixels.
    pub margin: f64,
}

impl Default for SvgOptions {
    fn default() -> Self {
        SvgOptions {
            labels: false,
            flat_grey: false,
            scale: 200.0,
            min_feature_px: DEFAULT_MIN_FEATURE_PX,
            max_page_px: DEFAULT_MAX_PAGE_PX,
            margin: 20.0,
        }
    }
}

/// How a crease pattern lies on its SVG page and what an importer that snaps needs to read
/// it exactly (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SvgScale {
    /// Pixels per pattern unit.
    pub px_per_unit: f64,
    /// Page width in px (margins included).
    pub width_px: f64,
    /// Page height in px (margins included).
    pub height_px: f64,
    /// The smallest feature of the flat layout in paper units (`None`: one vertex only).
    pub min_feature: Option<f64>,
    /// The same on the page, in px.
    pub min_feature_px: Option<f64>,
    /// Where it is, e.g. `"v4 ↔ edge v1–v2"` (vertices numbered from 1).
    pub min_feature_where: Option<String>,
    /// What the page aims for ([`SvgOptions::min_feature_px`]).
    pub target_px: f64,
    /// Whether every feature is at least `target_px` on the page.
    pub features_fit: bool,
    /// A vertex merge tolerance (px) under which Origami Simulator imports the file exactly:
    /// the default 3 px when the features fit, otherwise a round number below the smallest
    /// feature; `None` when two vertices coincide (no tolerance separates them).
    pub import_tolerance_px: Option<f64>,
    /// The same facts as one sentence for people.
    pub note: String,
}

impl SvgScale {
    /// Whether Origami Simulator imports the file exactly with its default tolerance.
    pub fn imports_with_default_tolerance(&self) -> bool {
        self.import_tolerance_px == Some(ORIGAMI_SIMULATOR_TOLERANCE_PX)
    }
}

/// The largest of 1, 2, 2.5, 5 × 10ᵏ that is at most `x` (x > 0).
fn round_down_nice(x: f64) -> f64 {
    let p = 10f64.powf(x.log10().floor());
    [5.0, 2.5, 2.0, 1.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&v| v <= x)
        .unwrap_or(p)
}

/// The smallest of 1, 2, 2.5, 5 × 10ᵏ that is at least `x` (x > 0).
fn round_up_nice(x: f64) -> f64 {
    let p = 10f64.powf(x.log10().floor());
    [1.0, 2.0, 2.5, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&v| v >= x)
        .unwrap_or(10.0 * p)
}

/// The scale of `p`'s crease pattern on its page under `o`, and what it means for import.
pub fn svg_scale(p: &Pattern, o: &SvgOptions) -> Result<SvgScale> {
    validate_pattern(p)?;
    check_options(o)?;
    let (lo, hi) = extent(p);
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let page = |s: f64| span * s + 2.0 * o.margin;
    let feature = pattern_min_feature(p);
    let min_units = feature.map(|f| f.value);
    let mut s = o.scale;
    if let Some(f) = min_units.filter(|_| o.min_feature_px > 0.0)
        && f * s < o.min_feature_px
    {
        let need = if f > 0.0 {
            o.min_feature_px / f
        } else {
            f64::INFINITY
        };
        let room = if span > 0.0 {
            (o.max_page_px - 2.0 * o.margin) / span
        } else {
            f64::INFINITY
        };
        let nice = round_up_nice(need);
        s = if page(nice) <= o.max_page_px {
            nice
        } else if page(need) <= o.max_page_px {
            need
        } else {
            room.max(o.scale)
        };
        if !s.is_finite() {
            // A single point or coincident vertices in an empty extent: nothing to scale.
            s = o.scale;
        }
    }
    let min_px = min_units.map(|f| f * s);
    let fits = min_px.is_none_or(|m| m >= o.min_feature_px);
    let tolerance = match min_px {
        None => Some(ORIGAMI_SIMULATOR_TOLERANCE_PX),
        Some(m) if m > ORIGAMI_SIMULATOR_TOLERANCE_PX + 0.05 => {
            Some(ORIGAMI_SIMULATOR_TOLERANCE_PX)
        }
        // Below the feature by more than the coordinates' rounding (1% of it).
        Some(m) if m > 0.0 => Some(round_down_nice(0.98 * m)),
        Some(_) => None,
    };
    let (width_px, height_px) = (
        (hi[0] - lo[0]) * s + 2.0 * o.margin,
        (hi[1] - lo[1]) * s + 2.0 * o.margin,
    );
    let where_ = feature.map(|f| f.label());
    let at = where_.as_deref().unwrap_or("?");
    let note = match (min_units, min_px, tolerance) {
        (Some(f), Some(m), Some(t)) if t >= ORIGAMI_SIMULATOR_TOLERANCE_PX => format!(
            "{} px per unit: every feature is at least {} px (the smallest, {} units, at {at}), so Origami Simulator imports it exactly with its default {} px vertex merge tolerance",
            fmt_scale(s),
            fmt_px(m),
            fmt_units(f),
            ORIGAMI_SIMULATOR_TOLERANCE_PX
        ),
        (Some(f), Some(m), Some(t)) => format!(
            "{} px per unit ({width_px:.0} × {height_px:.0} px page{}): the smallest feature ({} units, at {at}) is only {} px, below the {} px at which Origami Simulator merges and splits by default; set \"Vertex merge tolerance (px)\" in the SVG import settings that its File → Import… shows to {t} px or less to import this file exactly",
            fmt_scale(s),
            if fits {
                String::new()
            } else {
                format!("; the largest allowed is {} px", o.max_page_px)
            },
            fmt_units(f),
            fmt_px(m),
            ORIGAMI_SIMULATOR_TOLERANCE_PX
        ),
        (Some(_), Some(_), None) => format!(
            "{} px per unit: vertices coincide ({at}); no import tolerance keeps them apart",
            fmt_scale(s)
        ),
        _ => format!("{} px per unit; a single vertex, no features", fmt_scale(s)),
    };
    Ok(SvgScale {
        px_per_unit: s,
        width_px,
        height_px,
        min_feature: min_units,
        min_feature_px: min_px,
        min_feature_where: where_,
        target_px: o.min_feature_px,
        features_fit: fits,
        import_tolerance_px: tolerance,
        note,
    })
}

/// A scale: whole px per unit when it is one, else 1 decimal.
fn fmt_scale(s: f64) -> String {
    if s.fract() == 0.0 {
        format!("{s}")
    } else {
        format!("{s:.1}")
    }
}

/// A length in units with 2 significant digits.
fn fmt_units(x: f64) -> String {
    format!("{:.*}", sig_decimals(x, 2), x)
}

/// A length in px with 3 significant digits (at least 1 decimal), so that 2.97 px does not
/// read as the 3 px tolerance.
fn fmt_px(x: f64) -> String {
    format!("{:.*}", sig_decimals(x, 3).max(1), x)
}

/// Decimals that show `x` with `digits` significant digits.
fn sig_decimals(x: f64, digits: i32) -> usize {
    if x <= 0.0 || !x.is_finite() {
        return 1;
    }
    (digits - 1 - x.log10().floor() as i32).clamp(0, 15) as usize
}

fn check_options(o: &SvgOptions) -> Result<()> {
    let ok = o.scale.is_finite()
        && o.scale > 0.0
        && o.margin.is_finite()
        && o.margin >= 0.0
        && o.min_feature_px.is_finite()
        && o.min_feature_px >= 0.0
        && o.max_page_px.is_finite()
        && o.max_page_px > 2.0 * o.margin;
    if ok {
        Ok(())
    } else {
        Err(super::ExportError::invalid(
            "svg options",
            "scale must be > 0, margin ≥ 0, min_feature_px ≥ 0 and max_page_px > 2 × margin",
        ))
    }
}

/// Lower-left and upper-right corners of the flat layout.
fn extent(p: &Pattern) -> ([f64; 2], [f64; 2]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in &p.vertices {
        for k in 0..2 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    (lo, hi)
}

/// Stroke colour of an assignment in Origami Simulator's convention.
pub fn stroke_color(a: Assignment, flat_grey: bool) -> &'static str {
    match a {
        Assignment::B => "#000000",
        Assignment::M => "#ff0000",
        Assignment::V => "#0000ff",
        Assignment::F | Assignment::J if flat_grey => "#808080",
        Assignment::F | Assignment::J => "#ffff00",
        Assignment::U => "#ff00ff",
    }
}

/// The crease pattern as a standalone SVG document.
pub fn crease_pattern_svg(p: &Pattern, o: &SvgOptions) -> Result<String> {
    Ok(format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n{}\n",
        crease_pattern_element(p, o)?
    ))
}

/// The crease pattern as an `<svg>` element (no XML prolog), for inlining into HTML. Its
/// scale is [`svg_scale`]'s.
pub fn crease_pattern_element(p: &Pattern, o: &SvgOptions) -> Result<String> {
    let sc = svg_scale(p, o)?;
    let (lo, hi) = extent(p);
    let s = sc.px_per_unit;
    let (w, h) = (sc.width_px, sc.height_px);
    // Enough decimals that rounding moves a coordinate by at most 0.5% of the smallest
    // feature (4 at least, as many as f64 carries at most).
    let dec = sc
        .min_feature_px
        .filter(|&m| m > 0.0)
        .map_or(4, |m| sig_decimals(m, 3).clamp(4, 12));
    let x = |v: [f64; 2]| (v[0] - lo[0]) * s + o.margin;
    let y = |v: [f64; 2]| (hi[1] - v[1]) * s + o.margin;
    let asg = assignments(p);
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.1}\" height=\"{h:.1}\" viewBox=\"0 0 {w:.3} {h:.3}\" data-px-per-unit=\"{s}\" data-min-feature-px=\"{}\" data-import-tolerance-px=\"{}\">\n",
        sc.min_feature_px
            .map_or("none".into(), |m| format!("{m:.6}")),
        sc.import_tolerance_px
            .map_or("none".into(), |t| t.to_string()),
    );
    let _ = writeln!(
        out,
        "<!-- foldsynth crease pattern: {} edges; colours and opacity follow Origami Simulator (mountain #ff0000, valley #0000ff, boundary #000000, flat {}); stroke-opacity = |final fold angle| / 180 -->",
        p.edges.len(),
        stroke_color(Assignment::F, o.flat_grey)
    );
    let _ = writeln!(
        out,
        "<!-- scale: {}{} -->",
        if sc.imports_with_default_tolerance() {
            ""
        } else {
            "WARNING: "
        },
        sc.note.replace("--", "–")
    );
    // Boundary first, creases on top.
    let mut order: Vec<usize> = (0..p.edges.len()).collect();
    order.sort_by_key(|&i| asg[i] != Assignment::B);
    for i in order {
        let e = &p.edges[i];
        let (a, b) = (p.vertices[e.v[0]], p.vertices[e.v[1]]);
        let angle = p
            .frames
            .last()
            .map_or(0.0, |f| wrap(f.fold_angles[i]).to_degrees());
        let driven = matches!(e.kind, EdgeKind::Crease { driven: true });
        let opacity = match asg[i] {
            Assignment::M | Assignment::V => angle.abs() / 180.0,
            _ => 1.0,
        };
        let _ = writeln!(
            out,
            "<line x1=\"{:.dec$}\" y1=\"{:.dec$}\" x2=\"{:.dec$}\" y2=\"{:.dec$}\" stroke=\"{}\" stroke-width=\"{}\" stroke-linecap=\"round\" opacity=\"1\" stroke-opacity=\"{opacity:.6}\" data-edge=\"{i}\" data-assignment=\"{}\" data-fold-angle=\"{angle:.6}\" data-driven=\"{driven}\"/>",
            x(a),
            y(a),
            x(b),
            y(b),
            stroke_color(asg[i], o.flat_grey),
            if driven { 3 } else { 2 },
            asg[i].as_str(),
        );
    }
    if o.labels {
        for (i, v) in p.vertices.iter().enumerate() {
            let _ = writeln!(
                out,
                "<text x=\"{:.2}\" y=\"{:.2}\" font-family=\"sans-serif\" font-size=\"12\" fill=\"#333333\">{}</text>",
                x(*v) + 3.0,
                y(*v) - 3.0,
                xml_escape(&format!("v{}", i + 1))
            );
        }
    }
    out.push_str("</svg>");
    Ok(out)
}
