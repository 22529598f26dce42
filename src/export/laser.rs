//! Laser-cutting drawings of a thick design (issue 32): one DXF (R12, written by the
//! `dxf` crate) and one SVG per ply of the laminate, in mm at real scale.
//!
//! Plies: each rigid ply (`top` over the hinge plane, `bottom` under it with
//! `sides = "both"`; one `rigid` ply with `sides = "one"`) and the flexible `hinge` layer
//! at the hinge plane. A rigid ply is cut straight through, so its panel outline is the
//! panel's layer at the ply's outer face: there the taper sets the panel back the most, so
//! the straight cut lies inside the tapered panel and the cut ply never collides before
//! the tapered one would.
//!
//! Layers (the same in every drawing, so one laser set-up serves all plies):
//! - `CUT`: rigid plies: panel outlines; hinge ply: the sheet's outline.
//! - `SCORE`: rigid plies: the hinge axes, for aligning the plies when laminating
//!   (engrave lightly or switch off; they run in the gaps, not through material).
//! - `MOUNTAIN`, `VALLEY`: hinge ply: the creases by the sign of their largest fold (a
//!   crease folding both ways goes by the larger).
//! - `LABEL`: panel ids (`P3` is facet 3 of the design), as text.
//! - `REGISTER`: registration crosses at the sheet's corners, the same on every ply
//!   (engrave lightly, or use them to place the sheet); see [`super::laminate`].
//!
//! On every ply, `CUT` also holds the sheet's outline and the alignment holes (circles)
//! that [`super::laminate`] adds.
//!
//! Why not ORIPA's `CutLine`/`MountainLine`/`ValleyLine`: laser software (LightBurn,
//! LaserGRBL) assigns an operation per layer, and a laminate needs a cut, a light score and
//! the fold lines kept apart; ORIPA's names describe a crease pattern, have no score, and
//! ORIPA does not read plies.

use std::fmt::Write as _;
use std::path::Path;

use super::{ExportError, Result};
use crate::fabricate::ThickDesign;
use crate::pattern::{EdgeKind, Pattern};
use crate::task::fabrication::Sides;

/// The layer names of every drawing.
pub const LAYERS: [&str; 6] = ["CUT", "SCORE", "MOUNTAIN", "VALLEY", "LABEL", "REGISTER"];

/// One line or closed polygon of a drawing, mm.
#[derive(Clone, Debug, PartialEq)]
pub struct Path2 {
    /// One of [`LAYERS`].
    pub layer: &'static str,
    /// Corners, mm.
    pub points: Vec<[f64; 2]>,
    /// Whether the last corner joins the first.
    pub closed: bool,
    /// The panel (facet) whose outline this is, on a rigid ply's `CUT`.
    pub panel: Option<usize>,
}

/// One ply's drawing, mm.
#[derive(Clone, Debug, PartialEq)]
pub struct PlyDrawing {
    /// `top`, `bottom`, `rigid` or `hinge`.
    pub name: &'static str,
    /// Lines and outlines.
    pub paths: Vec<Path2>,
    /// Labels: text, where (mm), height (mm).
    pub labels: Vec<(String, [f64; 2], f64)>,
    /// Circles on `CUT` (the alignment holes): centre (mm), radius (mm).
    pub circles: Vec<([f64; 2], f64)>,
}

/// The drawings of every ply of `design`.
pub fn plies(pattern: &Pattern, design: &ThickDesign) -> Vec<PlyDrawing> {
    let s = design.spec.scale;
    let mm = |p: [f64; 2]| [p[0] * s, p[1] * s];
    let rigid: Vec<(&'static str, bool)> = match design.spec.sides {
        Sides::One => vec![("rigid", true)],
        Sides::Both => vec![("top", true), ("bottom", false)],
    };
    let mut out = Vec::new();
    for (name, upper) in rigid {
        let mut paths = Vec::new();
        let mut labels = Vec::new();
        for p in &design.panels {
            let layer = if upper {
                p.layers.last()
            } else {
                p.layers.first()
            };
            let Some(layer) = layer else { continue };
            let pts: Vec<[f64; 2]> = layer.outline.iter().map(|&q| mm(q)).collect();
            labels.push(label(p.facet, &pts));
            paths.push(Path2 {
                layer: "CUT",
                points: pts,
                closed: true,
                panel: Some(p.facet),
            });
        }
        for h in &design.hinges {
            paths.push(Path2 {
                layer: "SCORE",
                points: vec![mm(h.axis[0]), mm(h.axis[1])],
                closed: false,
                panel: None,
            });
        }
        out.push(PlyDrawing {
            name,
            paths,
            labels,
            circles: Vec::new(),
        });
    }
    let (loops, loose) = boundary_loops(pattern);
    let mut paths: Vec<Path2> = loops
        .into_iter()
        .map(|l| Path2 {
            layer: "CUT",
            points: l.iter().map(|&v| mm(pattern.vertices[v])).collect(),
            closed: true,
            panel: None,
        })
        .collect();
    paths.extend(loose.into_iter().map(|[a, b]| Path2 {
        layer: "CUT",
        points: vec![mm(pattern.vertices[a]), mm(pattern.vertices[b])],
        closed: false,
        panel: None,
    }));
    for h in &design.hinges {
        paths.push(Path2 {
            layer: if h.folds.valley >= h.folds.mountain {
                "VALLEY"
            } else {
                "MOUNTAIN"
            },
            points: vec![mm(h.axis[0]), mm(h.axis[1])],
            closed: false,
            panel: None,
        });
    }
    out.push(PlyDrawing {
        name: "hinge",
        paths,
        labels: Vec::new(),
        circles: Vec::new(),
    });
    out
}

/// The sheet's outline: its boundary edges chained into closed loops of vertices, each
/// walked as its facets walk it (the material on its left: the outer outline
/// counter-clockwise, a hole's clockwise); at a vertex where two loops touch, the walk
/// takes the sharpest left turn, so each loop stays simple. Boundary edges that no facet
/// walks, or that close no loop, come back as loose segments.
pub fn boundary_loops(pattern: &Pattern) -> (Vec<Vec<usize>>, Vec<[usize; 2]>) {
    let mut walked = std::collections::HashSet::new();
    for face in &pattern.faces {
        for k in 0..face.len() {
            walked.insert((face[k], face[(k + 1) % face.len()]));
        }
    }
    let mut out_of: std::collections::HashMap<usize, Vec<usize>> = Default::default();
    let mut loose = Vec::new();
    for e in &pattern.edges {
        if !matches!(e.kind, EdgeKind::Boundary) {
            continue;
        }
        let [a, b] = e.v;
        match (walked.contains(&(a, b)), walked.contains(&(b, a))) {
            (true, false) => out_of.entry(a).or_default().push(b),
            (false, true) => out_of.entry(b).or_default().push(a),
            _ => loose.push([a, b]),
        }
    }
    let v = |i: usize| pattern.vertices[i];
    let turn = |from: usize, at: usize, to: usize| {
        let (p, q, r) = (v(from), v(at), v(to));
        let (u, w) = ([q[0] - p[0], q[1] - p[1]], [r[0] - q[0], r[1] - q[1]]);
        (u[0] * w[1] - u[1] * w[0]).atan2(u[0] * w[0] + u[1] * w[1])
    };
    let mut loops = Vec::new();
    let mut starts: Vec<usize> = out_of.keys().copied().collect();
    starts.sort_unstable();
    for start in starts {
        while let Some(first) = out_of.get_mut(&start).and_then(Vec::pop) {
            let mut lp = vec![start];
            let (mut prev, mut at) = (start, first);
            while at != start {
                lp.push(at);
                let Some(next) = out_of.get_mut(&at).filter(|n| !n.is_empty()) else {
                    break;
                };
                let k = (0..next.len())
                    .max_by(|&i, &j| turn(prev, at, next[i]).total_cmp(&turn(prev, at, next[j])))
                    .unwrap_or(0);
                let n = next.swap_remove(k);
                (prev, at) = (at, n);
            }
            if at == start && lp.len() >= 3 {
                loops.push(lp);
            } else {
                if at == start {
                    lp.push(start);
                }
                loose.extend(lp.windows(2).map(|w| [w[0], w[1]]));
            }
        }
    }
    (loops, loose)
}

/// A panel's label: `P<facet>` at the outline's centroid, sized to fit.
fn label(facet: usize, pts: &[[f64; 2]]) -> (String, [f64; 2], f64) {
    let n = pts.len().max(1) as f64;
    let c = pts
        .iter()
        .fold([0.0, 0.0], |a, p| [a[0] + p[0] / n, a[1] + p[1] / n]);
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in pts {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let size = (hi[0] - lo[0]).min(hi[1] - lo[1]);
    (format!("P{facet}"), c, (size / 6.0).clamp(0.5, 5.0))
}

fn io_err(path: &Path, e: impl std::fmt::Display) -> ExportError {
    ExportError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e.to_string()),
    }
}

/// Write one ply as DXF R12. R12 has no units variable (`$INSUNITS` came with R2000):
/// coordinates are mm, which LightBurn, LaserGRBL and LibreCAD assume for a unitless file.
pub fn write_dxf(path: &Path, ply: &PlyDrawing) -> Result<()> {
    use dxf::entities::{Circle, Entity, EntityType, Line, Polyline, Text, Vertex};
    use dxf::{Color, Drawing, Point, enums::AcadVersion, tables::Layer};
    let mut d = Drawing::new();
    d.header.version = AcadVersion::R12;
    for (name, colour) in LAYERS.iter().zip([7u8, 3, 1, 5, 8, 6]) {
        d.add_layer(Layer {
            name: (*name).into(),
            color: Color::from_index(colour),
            ..Default::default()
        });
    }
    for p in &ply.paths {
        let mut e = if p.points.len() == 2 && !p.closed {
            let [a, b] = [p.points[0], p.points[1]];
            Entity::new(EntityType::Line(Line::new(
                Point::new(a[0], a[1], 0.0),
                Point::new(b[0], b[1], 0.0),
            )))
        } else {
            let mut poly = Polyline::default();
            poly.set_is_closed(p.closed);
            for q in &p.points {
                poly.add_vertex(&mut d, Vertex::new(Point::new(q[0], q[1], 0.0)));
            }
            Entity::new(EntityType::Polyline(poly))
        };
        e.common.layer = p.layer.into();
        d.add_entity(e);
    }
    for (c, r) in &ply.circles {
        let mut e = Entity::new(EntityType::Circle(Circle::new(
            Point::new(c[0], c[1], 0.0),
            *r,
        )));
        e.common.layer = "CUT".into();
        d.add_entity(e);
    }
    for (text, at, height) in &ply.labels {
        let mut e = Entity::new(EntityType::Text(Text {
            location: Point::new(at[0], at[1], 0.0),
            text_height: *height,
            value: text.clone(),
            ..Default::default()
        }));
        e.common.layer = "LABEL".into();
        d.add_entity(e);
    }
    let mut buf = Vec::new();
    d.save(&mut buf).map_err(|e| io_err(path, e))?;
    super::write_file(path, strip_subclass_markers(&buf))
}

/// The `dxf` crate writes subclass markers (group code 100) in the TABLES section even for
/// R12, which has no group 100; strict R12 readers (ezdxf) then lose the table entries'
/// names. Drop those pairs: everything else is as the crate wrote it.
fn strip_subclass_markers(dxf: &[u8]) -> Vec<u8> {
    let text = String::from_utf8_lossy(dxf);
    let lines: Vec<&str> = text.split('\n').collect();
    let mut out = String::with_capacity(text.len());
    // Group code and value alternate, one a line: walk pairs so that a value of 100 stays.
    for pair in lines.chunks(2) {
        if pair.len() == 2 && pair[0].trim() == "100" {
            continue;
        }
        for line in pair {
            out.push_str(line);
            out.push('\n');
        }
    }
    // `split` gave a last empty piece after the final newline: do not double it.
    if !text.ends_with('\n') || out.ends_with("\n\n") {
        out.pop();
    }
    out.into_bytes()
}

/// Write one ply as SVG: one Inkscape layer (`<g inkscape:groupmode="layer">`) per DXF
/// layer, the page in mm at real scale (y flipped so the drawing has y up like the
/// pattern).
pub fn write_svg(path: &Path, ply: &PlyDrawing) -> Result<()> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for q in ply.paths.iter().flat_map(|p| &p.points) {
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    if !lo[0].is_finite() {
        (lo, hi) = ([0.0; 2], [1.0; 2]);
    }
    let m = 5.0;
    let (w, h) = (hi[0] - lo[0] + 2.0 * m, hi[1] - lo[1] + 2.0 * m);
    let x = |q: [f64; 2]| q[0] - lo[0] + m;
    let y = |q: [f64; 2]| hi[1] - q[1] + m;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" width="{w:.4}mm" height="{h:.4}mm" viewBox="0 0 {w:.4} {h:.4}" data-ply="{}">"#,
        ply.name
    );
    let colour = |l: &str| match l {
        "CUT" => "#000000",
        "SCORE" => "#00a000",
        "MOUNTAIN" => "#ff0000",
        "VALLEY" => "#0000ff",
        "REGISTER" => "#ff00ff",
        _ => "#808080",
    };
    for layer in LAYERS {
        let _ = writeln!(
            s,
            r#"<g inkscape:groupmode="layer" inkscape:label="{layer}" id="{layer}" fill="none" stroke="{}" stroke-width="0.1">"#,
            colour(layer)
        );
        for p in ply.paths.iter().filter(|p| p.layer == layer) {
            let pts: Vec<String> = p
                .points
                .iter()
                .map(|&q| format!("{:.4},{:.4}", x(q), y(q)))
                .collect();
            let tag = if p.closed { "polygon" } else { "polyline" };
            let _ = writeln!(s, r#"<{tag} points="{}"/>"#, pts.join(" "));
        }
        if layer == "CUT" {
            for (c, r) in &ply.circles {
                let _ = writeln!(
                    s,
                    r#"<circle cx="{:.4}" cy="{:.4}" r="{r:.4}"/>"#,
                    x(*c),
                    y(*c)
                );
            }
        }
        if layer == "LABEL" {
            for (text, at, height) in &ply.labels {
                let _ = writeln!(
                    s,
                    r#"<text x="{:.4}" y="{:.4}" font-size="{height:.3}" fill="{}" stroke="none" text-anchor="middle">{text}</text>"#,
                    x(*at),
                    y(*at),
                    colour(layer)
                );
            }
        }
        s.push_str("</g>\n");
    }
    s.push_str("</svg>\n");
    super::write_file(path, s)
}
