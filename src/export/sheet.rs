//! The print sheet (issue 50): the crease pattern at true scale on paper, to print and fold
//! a paper model, as one PDF (`pdf-writer`, one page per sheet) and one SVG per sheet.
//!
//! - **The sheet**: the design's pattern with every rotational copy that lies in the
//!   sheet's plane (the gripper's two arms, a flasher's sectors), shared vertices merged;
//!   a copy that leaves the plane is not drawn and the sheet says so.
//! - **Lines** (seen from the printed side, which is the pattern's +z side, y up):
//!   the outline is the cut line (black, solid); mountain folds red, dash-dot-dot;
//!   valley folds blue, dashed (the Yoshizawa–Randlett line styles in Origami
//!   Simulator's and FOLD's colours, so a colour print and a black-and-white one both
//!   read); creases that stay flat over the motion grey, dotted. The fold of a crease is
//!   its FOLD assignment ([`super::fold::assignments`]: the sign at the last frame).
//! - **Scale**: a given number of mm per paper unit, or the largest "nice" value (1, 1.2,
//!   1.5, 2, 2.5, 3, 4, 5, 6 or 8 × 10ᵏ mm) that fits the paper. Every sheet prints it,
//!   with a 10 mm check square to measure after printing at 100 %.
//! - **Tiles**: a pattern larger than the paper's printable area is split over a grid of
//!   sheets whose windows overlap by [`SheetOptions::overlap_mm`]; in each overlap strip a
//!   dotted seam line and crosses at the same pattern positions on both sheets show where
//!   to trim one sheet and lay it on the other.
//! - **Page**: a margin of [`SheetOptions::margin_mm`] on every side and a footer of
//!   [`FOOTER_MM`] with the check square, the legend, the scale and the sheet's place in
//!   the grid. The orientation (portrait or landscape) is the one needing fewer sheets
//!   (for "fit": the larger scale).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::fold::{Assignment, assignments};
use super::{ExportError, Result, validate_pattern};
use crate::pattern::Pattern;
use crate::scene::Copies;

/// Height of the footer (check square, legend, scale), mm.
pub const FOOTER_MM: f64 = 22.0;

/// Side of the check square, mm.
pub const CHECK_SQUARE_MM: f64 = 10.0;

/// Most sheets one print may take: beyond it the scale is a typo.
pub const MAX_SHEETS: usize = 400;

/// A paper size, mm (portrait: width ≤ height).
#[derive(Clone, Debug, PartialEq)]
pub struct Paper {
    /// `A4`, `Letter`, `A3` or `W x H mm`.
    pub name: String,
    /// Width, mm.
    pub width: f64,
    /// Height, mm.
    pub height: f64,
}

impl Paper {
    /// The named sizes.
    pub const NAMES: [&'static str; 3] = ["a4", "letter", "a3"];

    /// `a4`, `letter`, `a3` (any case) or `WxH` in mm (each in [50, 5000]).
    pub fn parse(s: &str) -> std::result::Result<Paper, String> {
        let named = |name: &str, width, height| Paper {
            name: name.into(),
            width,
            height,
        };
        match s.trim().to_ascii_lowercase().as_str() {
            "a4" => return Ok(named("A4", 210.0, 297.0)),
            "letter" => return Ok(named("Letter", 215.9, 279.4)),
            "a3" => return Ok(named("A3", 297.0, 420.0)),
            _ => {}
        }
        let bad = || {
            format!(
                "{:?}: expected a4, letter, a3 or WIDTHxHEIGHT in mm (each 50 to 5000), e.g. 300x450",
                crate::text::excerpt(s, 40)
            )
        };
        let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
        let mm = |x: &str| {
            x.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| (50.0..=5000.0).contains(v))
                .ok_or_else(bad)
        };
        let (w, h) = (mm(w)?, mm(h)?);
        Ok(Paper {
            name: format!(
                "{} x {} mm",
                crate::text::num(w.min(h)),
                crate::text::num(w.max(h))
            ),
            width: w.min(h),
            height: w.max(h),
        })
    }
}

/// The print scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PrintScale {
    /// mm per paper unit (G0's first crease is 1 unit).
    MmPerUnit(f64),
    /// The largest nice scale that fits one sheet.
    Fit,
}

impl PrintScale {
    /// `fit` or a number of mm per unit in (0, 10000].
    pub fn parse(s: &str) -> std::result::Result<PrintScale, String> {
        if s.trim().eq_ignore_ascii_case("fit") {
            return Ok(PrintScale::Fit);
        }
        s.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0 && *v <= 10_000.0)
            .map(PrintScale::MmPerUnit)
            .ok_or_else(|| {
                format!(
                    "{:?}: expected fit or a number of mm per paper unit in (0, 10000]",
                    crate::text::excerpt(s, 40)
                )
            })
    }
}

/// How to print.
#[derive(Clone, Debug, PartialEq)]
pub struct SheetOptions {
    /// The paper.
    pub paper: Paper,
    /// The scale.
    pub scale: PrintScale,
    /// Vertex names (v1, v2, …) and crease numbers (e0, e1, …: edge indices).
    pub labels: bool,
    /// Margin on every side, mm.
    pub margin_mm: f64,
    /// How far neighbouring tiles overlap, mm.
    pub overlap_mm: f64,
    /// The name printed in the footer (the design id).
    pub title: String,
    /// The rotational copies of the design (`meta.scene.copies`): those in the sheet's
    /// plane are drawn with it.
    pub copies: Copies,
}

impl Default for SheetOptions {
    fn default() -> Self {
        SheetOptions {
            paper: Paper::parse("a4").unwrap_or(Paper {
                name: "A4".into(),
                width: 210.0,
                height: 297.0,
            }),
            scale: PrintScale::Fit,
            labels: false,
            margin_mm: 10.0,
            overlap_mm: 10.0,
            title: "design".into(),
            copies: Copies::default(),
        }
    }
}

/// The flat sheet to print: the pattern and its in-plane copies, merged.
#[derive(Clone, Debug, PartialEq)]
pub struct FlatSheet {
    /// Vertices, paper units.
    pub vertices: Vec<[f64; 2]>,
    /// Edges and their assignment (`B`: the cut line).
    pub edges: Vec<([usize; 2], Assignment)>,
    /// How many copies are drawn (1: the pattern alone).
    pub copies_drawn: usize,
    /// Why some copies are not drawn, if so.
    pub note: Option<String>,
}

impl FlatSheet {
    /// The outline's length (the cut line), paper units.
    pub fn cut_length(&self) -> f64 {
        self.edges
            .iter()
            .filter(|(_, a)| *a == Assignment::B)
            .map(|([a, b], _)| {
                let (p, q) = (self.vertices[*a], self.vertices[*b]);
                (p[0] - q[0]).hypot(p[1] - q[1])
            })
            .sum()
    }
}

/// The sheet of `pattern` with the copies of `copies` that stay in the plane z = 0 (vertices
/// closer than 1e-9 merged, edges between the same vertices once; an arm edge on the axis
/// shared by two copies becomes a crease if either copy has it as one).
pub fn flat_sheet(pattern: &Pattern, copies: &Copies) -> FlatSheet {
    let kinds = assignments(pattern);
    let mut vertices: Vec<[f64; 2]> = Vec::new();
    let mut edges: Vec<([usize; 2], Assignment)> = Vec::new();
    let index = |p: [f64; 2], vertices: &mut Vec<[f64; 2]>| match vertices
        .iter()
        .position(|q| (q[0] - p[0]).abs() < 1e-9 && (q[1] - p[1]).abs() < 1e-9)
    {
        Some(i) => i,
        None => {
            vertices.push(p);
            vertices.len() - 1
        }
    };
    let mut drawn = 0;
    let mut off_plane = 0;
    for k in 0..copies.n.max(1) {
        let moved: Vec<[f64; 3]> = pattern
            .vertices
            .iter()
            .map(|v| copies.apply(k, [v[0], v[1], 0.0]))
            .collect();
        if moved.iter().any(|p| p[2].abs() > 1e-9) {
            off_plane += 1;
            continue;
        }
        drawn += 1;
        let ids: Vec<usize> = moved
            .iter()
            .map(|p| index([p[0], p[1]], &mut vertices))
            .collect();
        for (e, &a) in pattern.edges.iter().zip(&kinds) {
            let v = [ids[e.v[0]], ids[e.v[1]]];
            let same =
                |w: &[usize; 2]| (w[0] == v[0] && w[1] == v[1]) || (w[0] == v[1] && w[1] == v[0]);
            match edges.iter_mut().find(|(w, _)| same(w)) {
                // Two arms' boundary edges on the same line join as the seam between them.
                Some((_, old)) if *old == Assignment::B && a == Assignment::B => {
                    *old = Assignment::F
                }
                Some((_, old)) if *old == Assignment::B => *old = a,
                Some(_) => {}
                None => edges.push((v, a)),
            }
        }
    }
    let note = (off_plane > 0).then(|| {
        format!(
            "{off_plane} of the design's {} copies leave the sheet's plane and are not drawn: print one sheet per copy",
            copies.n
        )
    });
    FlatSheet {
        vertices,
        edges,
        copies_drawn: drawn,
        note,
    }
}

/// How a line is drawn.
#[derive(Clone, Debug, PartialEq)]
pub struct Style {
    /// Colour, 0–1.
    pub rgb: [f64; 3],
    /// Width, mm.
    pub width_mm: f64,
    /// Dash pattern, mm (empty: solid).
    pub dash_mm: Vec<f64>,
}

/// The style of each assignment (`B` the cut line).
pub fn style_of(a: Assignment) -> Style {
    let s = |rgb, width_mm, dash_mm: &[f64]| Style {
        rgb,
        width_mm,
        dash_mm: dash_mm.to_vec(),
    };
    match a {
        Assignment::B => s([0.0, 0.0, 0.0], 0.35, &[]),
        Assignment::M => s([0.85, 0.0, 0.0], 0.3, &[3.0, 1.0, 0.4, 1.0, 0.4, 1.0]),
        Assignment::V => s([0.0, 0.0, 0.85], 0.3, &[3.0, 1.5]),
        _ => s([0.55, 0.55, 0.55], 0.2, &[0.5, 1.0]),
    }
}

/// One stroked path on a page, mm from the page's lower left corner (y up).
#[derive(Clone, Debug, PartialEq)]
pub struct Stroke {
    /// Corners.
    pub points: Vec<[f64; 2]>,
    /// Whether the last corner joins the first.
    pub closed: bool,
    /// How it is drawn.
    pub style: Style,
    /// Whether it belongs to the pattern (clipped to the page's window) or to the page.
    pub in_window: bool,
}

/// One line of text on a page.
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    /// Where its baseline starts (or its middle, `centred`), mm from the lower left.
    pub at: [f64; 2],
    /// Height, mm.
    pub size_mm: f64,
    /// ASCII text (the PDF's Helvetica is not embedded).
    pub text: String,
    /// Centred on `at`.
    pub centred: bool,
}

/// One sheet.
#[derive(Clone, Debug, PartialEq)]
pub struct Page {
    /// Width and height, mm (as printed: landscape when width > height).
    pub size_mm: [f64; 2],
    /// The pattern's window on the page: `[x0, y0, x1, y1]`, mm.
    pub window: [f64; 4],
    /// Row and column in the grid (from the top left, 0-based).
    pub place: [usize; 2],
    /// Where the sheet's lower left bound ([`Print::bounds`]) lies on the page, mm: a point
    /// `p` of the sheet is drawn at `offset_mm + mm_per_unit · (p − bounds[0])`.
    pub offset_mm: [f64; 2],
    /// What is stroked.
    pub strokes: Vec<Stroke>,
    /// What is written.
    pub labels: Vec<Label>,
}

/// A print: its pages and what they show.
#[derive(Clone, Debug, PartialEq)]
pub struct Print {
    /// The scale, mm per paper unit.
    pub mm_per_unit: f64,
    /// Rows and columns of sheets.
    pub grid: [usize; 2],
    /// The paper's name.
    pub paper: String,
    /// Whether the pages are landscape.
    pub landscape: bool,
    /// The sheets, row by row.
    pub pages: Vec<Page>,
    /// The sheet printed.
    pub sheet: FlatSheet,
    /// The sheet's bounds `[lo, hi]`, paper units.
    pub bounds: [[f64; 2]; 2],
}

/// The largest nice scale ≤ `s`: 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6 or 8 × 10ᵏ.
pub fn nice_below(s: f64) -> f64 {
    let k = s.log10().floor();
    let base = 10f64.powf(k);
    let m = s / base;
    let pick = [1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0]
        .into_iter()
        .rev()
        .find(|&c| c <= m * (1.0 + 1e-12))
        .unwrap_or(1.0);
    pick * base
}

/// The pattern's bounds `[lo, hi]`, paper units.
fn bounds(v: &[[f64; 2]]) -> [[f64; 2]; 2] {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in v {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    [lo, hi]
}

/// Tiles needed along one side: extent `e`, area `a`, overlap `o` (mm).
fn tiles(e: f64, a: f64, o: f64) -> usize {
    if e <= a {
        1
    } else {
        ((e - o) / (a - o)).ceil().max(1.0) as usize
    }
}

/// Lay `pattern` (with its in-plane copies) out on sheets.
pub fn layout(pattern: &Pattern, o: &SheetOptions) -> Result<Print> {
    validate_pattern(pattern)?;
    let sheet = flat_sheet(pattern, &o.copies);
    let [lo, hi] = bounds(&sheet.vertices);
    let ext = [(hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9)];
    let area = |landscape: bool| {
        let (w, h) = if landscape {
            (o.paper.height, o.paper.width)
        } else {
            (o.paper.width, o.paper.height)
        };
        [w - 2.0 * o.margin_mm, h - 2.0 * o.margin_mm - FOOTER_MM]
    };
    if area(false).iter().any(|&a| a <= 2.0 * o.overlap_mm) {
        return Err(ExportError::invalid(
            "--paper",
            format!(
                "{} leaves no room for the pattern within the {} mm margins and the {FOOTER_MM} mm footer",
                o.paper.name, o.margin_mm
            ),
        ));
    }
    let (landscape, s) = match o.scale {
        PrintScale::Fit => {
            let fit = |l: bool| {
                let a = area(l);
                (a[0] / ext[0]).min(a[1] / ext[1])
            };
            let l = fit(true) > fit(false);
            (l, nice_below(fit(l)))
        }
        PrintScale::MmPerUnit(s) => {
            let count = |l: bool| {
                let a = area(l);
                tiles(ext[0] * s, a[0], o.overlap_mm) * tiles(ext[1] * s, a[1], o.overlap_mm)
            };
            (count(true) < count(false), s)
        }
    };
    let a = area(landscape);
    let grid = [
        tiles(ext[1] * s, a[1], o.overlap_mm),
        tiles(ext[0] * s, a[0], o.overlap_mm),
    ];
    if grid[0] * grid[1] > MAX_SHEETS {
        return Err(ExportError::invalid(
            "--print-scale",
            format!(
                "{} mm per unit needs {} × {} sheets of {} (at most {MAX_SHEETS}); use a smaller scale, a larger paper or fit",
                crate::text::num(s),
                grid[0],
                grid[1],
                o.paper.name
            ),
        ));
    }
    let mut pages = Vec::new();
    for r in 0..grid[0] {
        for c in 0..grid[1] {
            pages.push(page(&sheet, o, landscape, s, [lo, hi], grid, [r, c]));
        }
    }
    Ok(Print {
        mm_per_unit: s,
        grid,
        paper: o.paper.name.clone(),
        landscape,
        pages,
        sheet,
        bounds: [lo, hi],
    })
}

/// The window of tile `i` of `n` along one side: its start in pattern mm (from the
/// pattern's lower bound) for a pattern of extent `e` mm on an area `a` mm with overlap `o`.
fn window_start(i: usize, n: usize, e: f64, a: f64, o: f64) -> f64 {
    if n == 1 {
        // Centred.
        0.5 * (e - a)
    } else {
        i as f64 * (a - o)
    }
}

/// Sheet `[r, c]` of the grid.
fn page(
    sheet: &FlatSheet,
    o: &SheetOptions,
    landscape: bool,
    s: f64,
    [lo, hi]: [[f64; 2]; 2],
    grid: [usize; 2],
    [r, c]: [usize; 2],
) -> Page {
    let (w, h) = if landscape {
        (o.paper.height, o.paper.width)
    } else {
        (o.paper.width, o.paper.height)
    };
    let m = o.margin_mm;
    let area = [w - 2.0 * m, h - 2.0 * m - FOOTER_MM];
    let e = [(hi[0] - lo[0]) * s, (hi[1] - lo[1]) * s];
    // Rows count from the top: row 0 shows the pattern's highest y.
    let wx = window_start(c, grid[1], e[0], area[0], o.overlap_mm);
    let wy = e[1] - area[1] - window_start(r, grid[0], e[1], area[1], o.overlap_mm);
    let wy = if grid[0] == 1 {
        0.5 * (e[1] - area[1])
    } else {
        wy
    };
    let origin = [m, m + FOOTER_MM];
    // Pattern mm (from its lower bound) to page mm.
    let at = |q: [f64; 2]| [origin[0] + q[0] - wx, origin[1] + q[1] - wy];
    let to_page = |p: [f64; 2]| at([(p[0] - lo[0]) * s, (p[1] - lo[1]) * s]);
    let mut strokes = Vec::new();
    let mut labels = Vec::new();
    // Folds first, the cut line on top.
    let mut order: Vec<usize> = (0..sheet.edges.len()).collect();
    order.sort_by_key(|&i| sheet.edges[i].1 == Assignment::B);
    for i in order {
        let ([a, b], kind) = sheet.edges[i];
        strokes.push(Stroke {
            points: vec![to_page(sheet.vertices[a]), to_page(sheet.vertices[b])],
            closed: false,
            style: style_of(kind),
            in_window: true,
        });
    }
    if o.labels {
        for (i, &v) in sheet.vertices.iter().enumerate() {
            let p = to_page(v);
            labels.push(label([p[0] + 0.8, p[1] + 0.8], 2.2, format!("v{}", i + 1)));
        }
        for (i, ([a, b], kind)) in sheet.edges.iter().enumerate() {
            if *kind != Assignment::B {
                let (p, q) = (to_page(sheet.vertices[*a]), to_page(sheet.vertices[*b]));
                let mut l = label(
                    [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])],
                    2.0,
                    format!("e{i}"),
                );
                l.centred = true;
                labels.push(l);
            }
        }
        // Labels outside the window would spill over the footer.
        let win = [
            origin[0],
            origin[1],
            origin[0] + area[0],
            origin[1] + area[1],
        ];
        labels.retain(|l| {
            l.at[0] >= win[0] && l.at[0] <= win[2] && l.at[1] >= win[1] && l.at[1] <= win[3]
        });
    }
    let window = [
        origin[0],
        origin[1],
        origin[0] + area[0],
        origin[1] + area[1],
    ];
    seams(&mut strokes, o.overlap_mm, grid, [r, c], window);
    footer(&mut strokes, &mut labels, sheet, o, s, grid, [r, c], w);
    Page {
        size_mm: [w, h],
        window,
        place: [r, c],
        offset_mm: at([0.0, 0.0]),
        strokes,
        labels,
    }
}

fn label(at: [f64; 2], size_mm: f64, text: String) -> Label {
    Label {
        at,
        size_mm,
        text,
        centred: false,
    }
}

/// The overlap strips' seam lines and crosses of sheet `[r, c]`: at the middle of each strip
/// shared with a neighbour, a dotted line and two crosses, at the same pattern positions on
/// both sheets.
fn seams(strokes: &mut Vec<Stroke>, o: f64, grid: [usize; 2], [r, c]: [usize; 2], w: [f64; 4]) {
    let grey = Style {
        rgb: [0.3, 0.3, 0.3],
        width_mm: 0.2,
        dash_mm: vec![1.0, 1.0],
    };
    let solid = Style {
        dash_mm: Vec::new(),
        ..grey.clone()
    };
    let mut cross = |p: [f64; 2]| {
        for (dx, dy) in [(3.0, 0.0), (0.0, 3.0)] {
            strokes.push(Stroke {
                points: vec![[p[0] - dx, p[1] - dy], [p[0] + dx, p[1] + dy]],
                closed: false,
                style: solid.clone(),
                in_window: false,
            });
        }
    };
    let mut lines = Vec::new();
    // Vertical seams: with the left neighbour at the window's left strip, the right one at
    // its right strip.
    for (has, x) in [(c > 0, w[0] + 0.5 * o), (c + 1 < grid[1], w[2] - 0.5 * o)] {
        if has {
            let ys = [w[1] + 0.25 * (w[3] - w[1]), w[1] + 0.75 * (w[3] - w[1])];
            ys.iter().for_each(|&y| cross([x, y]));
            lines.push([[x, w[1]], [x, w[3]]]);
        }
    }
    for (has, y) in [(r > 0, w[3] - 0.5 * o), (r + 1 < grid[0], w[1] + 0.5 * o)] {
        if has {
            let xs = [w[0] + 0.25 * (w[2] - w[0]), w[0] + 0.75 * (w[2] - w[0])];
            xs.iter().for_each(|&x| cross([x, y]));
            lines.push([[w[0], y], [w[2], y]]);
        }
    }
    for l in lines {
        strokes.push(Stroke {
            points: l.to_vec(),
            closed: false,
            style: grey.clone(),
            in_window: false,
        });
    }
}

/// The footer: the check square, the legend, the scale, the sheet's place.
#[allow(clippy::too_many_arguments)]
fn footer(
    strokes: &mut Vec<Stroke>,
    labels: &mut Vec<Label>,
    sheet: &FlatSheet,
    o: &SheetOptions,
    s: f64,
    grid: [usize; 2],
    [r, c]: [usize; 2],
    w: f64,
) {
    let m = o.margin_mm;
    let y0 = m + 2.0;
    let q = CHECK_SQUARE_MM;
    strokes.push(Stroke {
        points: vec![[m, y0], [m + q, y0], [m + q, y0 + q], [m, y0 + q]],
        closed: true,
        style: Style {
            rgb: [0.0; 3],
            width_mm: 0.2,
            dash_mm: Vec::new(),
        },
        in_window: false,
    });
    labels.push(label([m, y0 + q + 1.5], 2.5, "10 mm".into()));
    let x = m + q + 5.0;
    let where_ = if grid == [1, 1] {
        "one sheet".to_string()
    } else {
        format!(
            "sheet {} of {} (row {}, column {} of {} x {}); trim at a dotted seam, lay on the neighbour, match the crosses",
            r * grid[1] + c + 1,
            grid[0] * grid[1],
            r + 1,
            c + 1,
            grid[0],
            grid[1]
        )
    };
    let ascii: String = o
        .title
        .chars()
        .map(|ch| if ch.is_ascii() { ch } else { '?' })
        .collect();
    labels.push(label([x, y0 + q + 1.5], 3.0, format!("{ascii}: {where_}")));
    let mut scale = format!(
        "scale 1 unit = {} mm; print at 100 % (actual size) and check the square",
        crate::text::num(s)
    );
    if let Some(n) = &sheet.note {
        let _ = write!(scale, "; {n}");
    }
    labels.push(label([x, y0 + q - 3.5], 2.4, scale));
    // The legend.
    let mut lx = x;
    for (a, name) in [
        (Assignment::B, "cut"),
        (Assignment::M, "mountain"),
        (Assignment::V, "valley"),
        (Assignment::F, "flat crease"),
    ] {
        if lx + 34.0 > w - m {
            break;
        }
        strokes.push(Stroke {
            points: vec![[lx, y0 + 1.0], [lx + 12.0, y0 + 1.0]],
            closed: false,
            style: style_of(a),
            in_window: false,
        });
        labels.push(label([lx + 14.0, y0], 2.4, name.into()));
        lx += 36.0;
    }
}

/// mm to PDF points.
const PT: f64 = 72.0 / 25.4;

/// The print as one PDF, a page per sheet, at true size (MediaBox in points: 1 mm =
/// 72/25.4 pt).
pub fn to_pdf(print: &Print) -> Vec<u8> {
    use pdf_writer::{Content, Finish, Name, Pdf, Rect, Ref, Str};
    let mut pdf = Pdf::new();
    let catalog = Ref::new(1);
    let tree = Ref::new(2);
    let font = Ref::new(3);
    let ids: Vec<(Ref, Ref)> = (0..print.pages.len())
        .map(|k| (Ref::new(4 + 2 * k as i32), Ref::new(5 + 2 * k as i32)))
        .collect();
    pdf.catalog(catalog).pages(tree);
    pdf.pages(tree)
        .kids(ids.iter().map(|(p, _)| *p))
        .count(ids.len() as i32);
    pdf.type1_font(font).base_font(Name(b"Helvetica"));
    let f = |x: f64| (x * PT) as f32;
    for (page, &(pid, cid)) in print.pages.iter().zip(&ids) {
        let mut p = pdf.page(pid);
        p.media_box(Rect::new(0.0, 0.0, f(page.size_mm[0]), f(page.size_mm[1])));
        p.parent(tree);
        p.contents(cid);
        p.resources().fonts().pair(Name(b"F1"), font);
        p.finish();
        let mut c = Content::new();
        let stroke = |c: &mut Content, st: &Stroke| {
            let s = &st.style;
            c.set_stroke_rgb(s.rgb[0] as f32, s.rgb[1] as f32, s.rgb[2] as f32);
            c.set_line_width(f(s.width_mm));
            c.set_dash_pattern(s.dash_mm.iter().map(|&d| f(d)), 0.0);
            c.move_to(f(st.points[0][0]), f(st.points[0][1]));
            for q in &st.points[1..] {
                c.line_to(f(q[0]), f(q[1]));
            }
            if st.closed {
                c.close_path();
            }
            c.stroke();
        };
        // The pattern, clipped to its window.
        let w = page.window;
        c.save_state();
        c.rect(f(w[0]), f(w[1]), f(w[2] - w[0]), f(w[3] - w[1]));
        c.clip_nonzero();
        c.end_path();
        for st in page.strokes.iter().filter(|s| s.in_window) {
            stroke(&mut c, st);
        }
        c.restore_state();
        for st in page.strokes.iter().filter(|s| !s.in_window) {
            stroke(&mut c, st);
        }
        c.set_fill_rgb(0.0, 0.0, 0.0);
        for l in &page.labels {
            let size = l.size_mm * PT / 0.72;
            // Helvetica's average advance is about half its size: centre by that.
            let dx = if l.centred {
                0.25 * l.size_mm / 0.72 * l.text.len() as f64
            } else {
                0.0
            };
            c.begin_text();
            c.set_font(Name(b"F1"), size as f32);
            c.next_line(f(l.at[0] - dx), f(l.at[1]));
            c.show(Str(l.text.as_bytes()));
            c.end_text();
        }
        pdf.stream(cid, &c.finish());
    }
    pdf.finish()
}

/// One sheet as SVG at true size (`width`/`height` in mm, one user unit = 1 mm), y flipped
/// so the drawing has y up like the pattern; the pattern clipped to its window.
pub fn to_svg(page: &Page) -> String {
    let [w, h] = page.size_mm;
    let y = |v: f64| h - v;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.3}mm" height="{h:.3}mm" viewBox="0 0 {w:.3} {h:.3}" data-sheet="{},{}">"#,
        page.place[0], page.place[1]
    );
    let win = page.window;
    let _ = writeln!(
        s,
        r#"<defs><clipPath id="window"><rect x="{:.4}" y="{:.4}" width="{:.4}" height="{:.4}"/></clipPath></defs>"#,
        win[0],
        y(win[3]),
        win[2] - win[0],
        win[3] - win[1]
    );
    let path = |st: &Stroke| {
        let pts: Vec<String> = st
            .points
            .iter()
            .map(|q| format!("{:.4},{:.4}", q[0], y(q[1])))
            .collect();
        let c = st.style.rgb.map(|v| (v * 255.0).round() as u8);
        let dash = if st.style.dash_mm.is_empty() {
            String::new()
        } else {
            let d: Vec<String> = st.style.dash_mm.iter().map(|d| format!("{d}")).collect();
            format!(r#" stroke-dasharray="{}""#, d.join(" "))
        };
        format!(
            r##"<{} points="{}" fill="none" stroke="#{:02x}{:02x}{:02x}" stroke-width="{}"{dash}/>"##,
            if st.closed { "polygon" } else { "polyline" },
            pts.join(" "),
            c[0],
            c[1],
            c[2],
            st.style.width_mm
        )
    };
    s.push_str("<g clip-path=\"url(#window)\">\n");
    for st in page.strokes.iter().filter(|s| s.in_window) {
        s.push_str(&path(st));
        s.push('\n');
    }
    s.push_str("</g>\n");
    for st in page.strokes.iter().filter(|s| !s.in_window) {
        s.push_str(&path(st));
        s.push('\n');
    }
    for l in &page.labels {
        let _ = writeln!(
            s,
            r#"<text x="{:.4}" y="{:.4}" font-family="Helvetica, Arial, sans-serif" font-size="{:.3}"{}>{}</text>"#,
            l.at[0],
            y(l.at[1]),
            l.size_mm / 0.72,
            if l.centred {
                r#" text-anchor="middle""#
            } else {
                ""
            },
            super::plots::xml_escape(&l.text)
        );
    }
    s.push_str("</svg>\n");
    s
}

/// The files of a print written to `pdf`: the PDF itself and the SVGs beside it
/// (`<stem>.svg` for one sheet, `<stem>-<k>.svg` from 1 for several).
pub fn planned(pdf: &Path, sheets: usize) -> Vec<PathBuf> {
    let stem = pdf
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "print".into());
    let mut out = vec![pdf.to_path_buf()];
    if sheets == 1 {
        out.push(pdf.with_file_name(format!("{stem}.svg")));
    } else {
        out.extend((1..=sheets).map(|k| pdf.with_file_name(format!("{stem}-{k}.svg"))));
    }
    out
}

/// Lay out and write the print of `pattern` to `pdf` and its SVGs; the files written.
pub fn write(pdf: &Path, pattern: &Pattern, o: &SheetOptions) -> Result<(Print, Vec<PathBuf>)> {
    let print = layout(pattern, o)?;
    let files = planned(pdf, print.pages.len());
    super::write_file(&files[0], to_pdf(&print))?;
    for (page, svg) in print.pages.iter().zip(&files[1..]) {
        super::write_file(svg, to_svg(page))?;
    }
    Ok((print, files))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::samples;

    #[test]
    fn nice_scales_round_down() {
        assert_eq!(nice_below(37.6), 30.0);
        assert_eq!(nice_below(41.0), 40.0);
        assert_eq!(nice_below(0.99), 0.8);
        assert_eq!(nice_below(100.0), 100.0);
        assert_eq!(nice_below(13.0), 12.0);
    }

    #[test]
    fn paper_sizes_parse_and_bad_ones_say_what_is_allowed() {
        assert_eq!(Paper::parse("A4").unwrap().width, 210.0);
        assert_eq!(Paper::parse("letter").unwrap().height, 279.4);
        let p = Paper::parse("450x300").unwrap();
        assert_eq!((p.width, p.height), (300.0, 450.0));
        for bad in ["a5", "10x300", "axb", ""] {
            let e = Paper::parse(bad).unwrap_err();
            assert!(e.contains("a4, letter, a3"), "{e}");
        }
        assert!(PrintScale::parse("-3").is_err());
        assert_eq!(PrintScale::parse("fit").unwrap(), PrintScale::Fit);
    }

    #[test]
    fn a_large_scale_tiles_with_the_overlap_and_every_vertex_is_on_a_sheet() {
        let p = samples::single_crease(1.0, 3);
        let o = SheetOptions {
            scale: PrintScale::MmPerUnit(400.0),
            ..SheetOptions::default()
        };
        let print = layout(&p, &o).unwrap();
        let [rows, cols] = print.grid;
        assert!(rows * cols > 1, "{:?}", print.grid);
        let s = print.mm_per_unit;
        let lo = print.bounds[0];
        // A window in the sheet's mm (from its lower bound).
        let seen = |pg: &Page| {
            let w = pg.window;
            [
                w[0] - pg.offset_mm[0],
                w[1] - pg.offset_mm[1],
                w[2] - pg.offset_mm[0],
                w[3] - pg.offset_mm[1],
            ]
        };
        for v in &print.sheet.vertices {
            let q = [(v[0] - lo[0]) * s, (v[1] - lo[1]) * s];
            let on = print.pages.iter().any(|pg| {
                let w = seen(pg);
                q[0] >= w[0] && q[0] <= w[2] && q[1] >= w[1] && q[1] <= w[3]
            });
            assert!(on, "{v:?} is on no sheet");
        }
        // Neighbours overlap by exactly the overlap, along rows and columns.
        for r in 0..rows {
            for c in 0..cols {
                let w = seen(&print.pages[r * cols + c]);
                if c + 1 < cols {
                    let e = seen(&print.pages[r * cols + c + 1]);
                    assert!((w[2] - e[0] - o.overlap_mm).abs() < 1e-9);
                }
                if r + 1 < rows {
                    let e = seen(&print.pages[(r + 1) * cols + c]);
                    assert!((e[3] - w[1] - o.overlap_mm).abs() < 1e-9);
                }
            }
        }
    }

    #[test]
    fn the_gripper_sheet_has_both_arms_and_a_copy_off_the_plane_is_left_out() {
        let (arm, _) = samples::demo_gripper();
        let both = flat_sheet(&arm, &Copies::about_z(2));
        // Brute force: the copy's vertices and edges that land on the arm's are shared.
        let turned = |v: [f64; 2]| [-v[0], -v[1]];
        let find = |q: [f64; 2]| {
            arm.vertices
                .iter()
                .position(|v| (v[0] - q[0]).abs() < 1e-9 && (v[1] - q[1]).abs() < 1e-9)
        };
        let shared_v = arm
            .vertices
            .iter()
            .filter(|v| find(turned(**v)).is_some())
            .count();
        let shared_e = arm
            .edges
            .iter()
            .filter(|e| {
                let [a, b] = e.v.map(|i| find(turned(arm.vertices[i])));
                arm.edges.iter().any(|f| {
                    (Some(f.v[0]), Some(f.v[1])) == (a, b) || (Some(f.v[1]), Some(f.v[0])) == (a, b)
                })
            })
            .count();
        assert_eq!(both.copies_drawn, 2);
        assert_eq!(both.vertices.len(), 2 * arm.vertices.len() - shared_v);
        assert_eq!(both.edges.len(), 2 * arm.edges.len() - shared_e);
        let alone = flat_sheet(&arm, &Copies::default());
        assert_eq!(alone.vertices.len(), arm.vertices.len());
        let tilted = Copies {
            n: 2,
            point: [0.0; 3],
            direction: [1.0, 0.0, 0.0],
        };
        let one = flat_sheet(&arm, &tilted);
        // A half turn about x keeps z = 0 too (it mirrors y): only a quarter turn leaves.
        assert_eq!(one.copies_drawn, 2);
        let quarter = flat_sheet(&arm, &Copies { n: 4, ..tilted });
        assert_eq!(quarter.copies_drawn, 2);
        assert!(
            quarter
                .note
                .as_deref()
                .unwrap_or("")
                .contains("2 of the design's 4 copies")
        );
    }
}
