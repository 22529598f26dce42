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

use std::fmt::Write as _;

use super::fold::{Assignment, assignments, wrap};
use super::plots::xml_escape;
use super::{Result, validate_pattern};
use crate::pattern::{EdgeKind, Pattern};

/// Options of [`crease_pattern_svg`].
#[derive(Clone, Debug)]
pub struct SvgOptions {
    /// Draw vertex numbers (0-based, as in the FOLD file).
    pub labels: bool,
    /// Flat creases grey instead of Origami Simulator's yellow.
    pub flat_grey: bool,
    /// Pixels per pattern unit.
    pub scale: f64,
    /// Margin in pixels.
    pub margin: f64,
}

impl Default for SvgOptions {
    fn default() -> Self {
        SvgOptions {
            labels: false,
            flat_grey: false,
            scale: 200.0,
            margin: 20.0,
        }
    }
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

/// The crease pattern as an `<svg>` element (no XML prolog), for inlining into HTML.
pub fn crease_pattern_element(p: &Pattern, o: &SvgOptions) -> Result<String> {
    validate_pattern(p)?;
    if !(o.scale.is_finite() && o.scale > 0.0 && o.margin.is_finite() && o.margin >= 0.0) {
        return Err(super::ExportError::invalid(
            "svg options",
            "scale must be > 0 and margin ≥ 0",
        ));
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in &p.vertices {
        for k in 0..2 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let s = o.scale;
    let w = (hi[0] - lo[0]) * s + 2.0 * o.margin;
    let h = (hi[1] - lo[1]) * s + 2.0 * o.margin;
    let x = |v: [f64; 2]| (v[0] - lo[0]) * s + o.margin;
    let y = |v: [f64; 2]| (hi[1] - v[1]) * s + o.margin;
    let asg = assignments(p);
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.1}\" height=\"{h:.1}\" viewBox=\"0 0 {w:.3} {h:.3}\">\n"
    );
    let _ = writeln!(
        out,
        "<!-- foldsynth crease pattern: {} edges; colours and opacity follow Origami Simulator (mountain #ff0000, valley #0000ff, boundary #000000, flat {}); stroke-opacity = |final fold angle| / 180 -->",
        p.edges.len(),
        stroke_color(Assignment::F, o.flat_grey)
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
            "<line x1=\"{:.4}\" y1=\"{:.4}\" x2=\"{:.4}\" y2=\"{:.4}\" stroke=\"{}\" stroke-width=\"{}\" stroke-linecap=\"round\" opacity=\"1\" stroke-opacity=\"{opacity:.6}\" data-edge=\"{i}\" data-assignment=\"{}\" data-fold-angle=\"{angle:.6}\" data-driven=\"{driven}\"/>",
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
