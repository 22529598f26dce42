//! A laminate that can be made (issue 50): the ply drawings of [`super::laser`] laid out on
//! a sheet to be cut.
//!
//! - **Kerf.** Every closed `CUT` path is offset by half the kerf away from the material it
//!   bounds (the material lies on the left of its walk: panel outlines and the sheet's
//!   outline grow, a hole in the pattern shrinks), each side moved along its normal and
//!   neighbouring sides intersected, so every part keeps its nominal size. Alignment holes
//!   are cut half a kerf inside their nominal circle.
//! - **Tabs.** With a tab width `w > 0`, each panel's cut on every rigid ply is interrupted
//!   by one gap of exactly `w` (measured along the outline, which is straight there) at the
//!   middle of every side at least [`TAB_SIDE_SHARE`] as long as its longest side: the cut
//!   becomes open polylines. The tabs hold the panels in their ply while the plies are
//!   laminated; a release cut frees them afterwards.
//! - **The sheet.** Every ply has the sheet's outline on `CUT`; the pattern lies inside it
//!   [`margin_mm`] from its lower-left corner (the same offset on every ply). In that margin,
//!   every ply has the same registration crosses (layer `REGISTER`, one at each corner) and
//!   three alignment holes placed so that no flip or half turn of a ply brings its holes
//!   over another ply's.
//! - **Several designs on one sheet**: [`lay_out_many`] packs their bounding boxes in
//!   shelves, [`GAP_MM`] apart.

use super::laser::{Path2, PlyDrawing};
use crate::task::fabrication::Laminate;
use serde::Serialize;

/// A tab goes on every side of a panel at least this share of its longest side.
pub const TAB_SIDE_SHARE: f64 = 0.75;

/// The gap between two designs' bounding boxes on one sheet, mm.
pub const GAP_MM: f64 = 5.0;

/// The band between the sheet's edge and the pattern, mm: 10 mm plus twice the hole's
/// diameter plus the kerf (room for the crosses and the holes).
pub fn margin_mm(lam: &Laminate) -> f64 {
    10.0 + 2.0 * lam.hole + lam.kerf
}

/// A tab left in a panel's cut.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Tab {
    /// The ply.
    pub ply: String,
    /// The panel (facet).
    pub panel: usize,
    /// The middle of the gap, sheet mm.
    pub at_mm: [f64; 2],
}

/// Where everything of one sheet lies, for `fabrication.json`. Sheet coordinates: mm, the
/// sheet's lower-left corner at the origin.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Layout {
    /// The kerf, mm.
    pub kerf_mm: f64,
    /// The tab width, mm (0: no tabs).
    pub tab_width_mm: f64,
    /// The alignment holes' nominal diameter, mm.
    pub hole_mm: f64,
    /// The band between the sheet's edge and the pattern, mm.
    pub margin_mm: f64,
    /// The sheet, `[width, height]` mm.
    pub sheet_mm: [f64; 2],
    /// Whether the sheet was given (else: the pattern's bounds plus the margin).
    pub sheet_given: bool,
    /// Added to the design's mm coordinates (the flat layout times the scale, as in the
    /// bill) to place it on the sheet.
    pub offset_mm: [f64; 2],
    /// The alignment holes' centres.
    pub holes_mm: Vec<[f64; 2]>,
    /// The registration crosses' centres.
    pub marks_mm: Vec<[f64; 2]>,
    /// The registration crosses' half arm length, mm.
    pub mark_arm_mm: f64,
    /// Every tab.
    pub tabs: Vec<Tab>,
}

/// A refusal: the setting's field (`kerf`, `tab_width`, `hole`, `sheet`) and what is
/// allowed.
pub type Refusal = (&'static str, String);

/// `pts` (a closed outline, the material on its left) with every side moved `d` to its
/// right, corner k where the moved sides k − 1 and k cross (collinear sides: the corner
/// moved along their normal). `None` when a side turns over.
pub fn offset_right(pts: &[[f64; 2]], d: f64) -> Option<Vec<[f64; 2]>> {
    let mut p: Vec<[f64; 2]> = Vec::with_capacity(pts.len());
    for &q in pts {
        if p.last().is_none_or(|l| l != &q) {
            p.push(q);
        }
    }
    while p.len() > 1 && p.first() == p.last() {
        p.pop();
    }
    let n = p.len();
    if n < 3 || d == 0.0 {
        return (n >= 3).then_some(p);
    }
    let dir = |k: usize| {
        let (a, b) = (p[k], p[(k + 1) % n]);
        [b[0] - a[0], b[1] - a[1]]
    };
    let right = |k: usize| {
        let u = dir(k);
        let l = u[0].hypot(u[1]);
        [u[1] / l, -u[0] / l]
    };
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let j = (k + n - 1) % n;
        let (nj, nk) = (right(j), right(k));
        let pj = [p[j][0] + d * nj[0], p[j][1] + d * nj[1]];
        let pk = [p[k][0] + d * nk[0], p[k][1] + d * nk[1]];
        let c = crate::geom::line_intersection_2d(pj, dir(j), pk, dir(k)).unwrap_or(pk);
        if !(c[0].is_finite() && c[1].is_finite()) {
            return None;
        }
        out.push(c);
    }
    for k in 0..n {
        let (a, b) = (out[k], out[(k + 1) % n]);
        let u = dir(k);
        if (b[0] - a[0]) * u[0] + (b[1] - a[1]) * u[1] <= 0.0 {
            return None;
        }
    }
    Some(out)
}

/// An outline cut open by tabs: the pieces (open polylines) and the gaps' middles.
pub type Tabbed = (Vec<Vec<[f64; 2]>>, Vec<[f64; 2]>);

/// A closed outline cut open by a gap of `w` at the middle of every side at least
/// [`TAB_SIDE_SHARE`] of the longest; the pieces (open polylines) and the gaps' middles.
/// `None` when the longest side is not longer than `2 w`.
pub fn with_tabs(pts: &[[f64; 2]], w: f64) -> Option<Tabbed> {
    let n = pts.len();
    let len = |k: usize| {
        let (a, b) = (pts[k], pts[(k + 1) % n]);
        (b[0] - a[0]).hypot(b[1] - a[1])
    };
    let longest = (0..n).map(len).fold(0.0, f64::max);
    if n < 3 || longest <= 2.0 * w {
        return None;
    }
    let sides: Vec<usize> = (0..n)
        .filter(|&k| len(k) >= TAB_SIDE_SHARE * longest)
        .collect();
    // The gap on side k: from a (before the middle) to b (after it).
    let gap = |k: usize| {
        let (a, b) = (pts[k], pts[(k + 1) % n]);
        let l = len(k);
        let u = [(b[0] - a[0]) / l, (b[1] - a[1]) / l];
        let m = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
        let h = 0.5 * w;
        (
            [m[0] - h * u[0], m[1] - h * u[1]],
            m,
            [m[0] + h * u[0], m[1] + h * u[1]],
        )
    };
    let mut pieces = Vec::with_capacity(sides.len());
    for (j, &k) in sides.iter().enumerate() {
        let next = sides[(j + 1) % sides.len()];
        let end = if next > k { next } else { next + n };
        let mut piece = vec![gap(k).2];
        piece.extend((k + 1..=end).map(|c| pts[c % n]));
        piece.push(gap(next).0);
        pieces.push(piece);
    }
    Some((pieces, sides.iter().map(|&k| gap(k).1).collect()))
}

/// Offset every closed `CUT` path of `plies` by half the kerf and cut tabs into the rigid
/// plies' panel outlines; the tabs (in the plies' coordinates).
pub fn prepare(plies: &mut [PlyDrawing], lam: &Laminate) -> Result<Vec<Tab>, Refusal> {
    let mut tabs = Vec::new();
    for ply in plies.iter_mut() {
        let mut paths = Vec::with_capacity(ply.paths.len());
        for p in std::mem::take(&mut ply.paths) {
            if p.layer != "CUT" || !p.closed {
                paths.push(p);
                continue;
            }
            let what = match p.panel {
                Some(f) => format!("panel P{f}"),
                None => "the sheet's outline".to_string(),
            };
            let points = offset_right(&p.points, 0.5 * lam.kerf).ok_or_else(|| {
                ("kerf", format!(
                    "{} mm turns the cut of {what} on ply {} over (allowed: a kerf below the narrowest feature of the cut)",
                    crate::text::num(lam.kerf),
                    ply.name
                ))
            })?;
            let Some(panel) = p.panel.filter(|_| lam.tab_width > 0.0) else {
                paths.push(Path2 { points, ..p });
                continue;
            };
            let (pieces, at) = with_tabs(&points, lam.tab_width).ok_or_else(|| {
                ("tab_width", format!(
                    "{} mm does not fit {what} on ply {}: its longest side is not longer than twice the tab (allowed: below half the longest side of every panel, or 0 for no tabs)",
                    crate::text::num(lam.tab_width),
                    ply.name
                ))
            })?;
            paths.extend(pieces.into_iter().map(|points| Path2 {
                layer: "CUT",
                points,
                closed: false,
                panel: Some(panel),
            }));
            tabs.extend(at.into_iter().map(|at_mm| Tab {
                ply: ply.name.to_string(),
                panel,
                at_mm,
            }));
        }
        ply.paths = paths;
        for (_, r) in &mut ply.circles {
            *r -= 0.5 * lam.kerf;
        }
    }
    Ok(tabs)
}

/// The lower-left and upper-right corners of every path of `plies`.
pub fn bounds(plies: &[PlyDrawing]) -> ([f64; 2], [f64; 2]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for q in plies.iter().flat_map(|p| &p.paths).flat_map(|p| &p.points) {
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    if !lo[0].is_finite() {
        return ([0.0; 2], [0.0; 2]);
    }
    (lo, hi)
}

/// Move a ply by `d`, mm.
pub fn translate(ply: &mut PlyDrawing, d: [f64; 2]) {
    let mv = |q: &mut [f64; 2]| {
        q[0] += d[0];
        q[1] += d[1];
    };
    ply.paths
        .iter_mut()
        .flat_map(|p| p.points.iter_mut())
        .for_each(mv);
    ply.labels.iter_mut().for_each(|(_, at, _)| mv(at));
    ply.circles.iter_mut().for_each(|(c, _)| mv(c));
}

/// The registration crosses' centres on a sheet: one at each corner, half the margin in.
pub fn marks(sheet: [f64; 2], lam: &Laminate) -> Vec<[f64; 2]> {
    let c = 0.5 * margin_mm(lam);
    let [w, h] = sheet;
    vec![[c, c], [w - c, c], [w - c, h - c], [c, h - c]]
}

/// The alignment holes' centres on a sheet, half the margin in from the edge: on the
/// bottom a third of the way along, on the left two thirds up, on the right a quarter up.
/// A ply flipped about either axis or turned half round puts none of them over another.
pub fn holes(sheet: [f64; 2], lam: &Laminate) -> Vec<[f64; 2]> {
    let c = 0.5 * margin_mm(lam);
    let [w, h] = sheet;
    let (sw, sh) = (w - 2.0 * c, h - 2.0 * c);
    vec![
        [c + sw / 3.0, c],
        [c, c + 2.0 * sh / 3.0],
        [w - c, c + sh / 4.0],
    ]
}

/// The crosses' half arm length, mm.
pub fn mark_arm_mm(lam: &Laminate) -> f64 {
    0.2 * margin_mm(lam)
}

/// Add the sheet's outline (offset by half the kerf), the alignment holes and the
/// registration crosses to a ply.
pub fn frame(ply: &mut PlyDrawing, sheet: [f64; 2], lam: &Laminate) {
    let k = 0.5 * lam.kerf;
    let [w, h] = sheet;
    ply.paths.push(Path2 {
        layer: "CUT",
        points: vec![[-k, -k], [w + k, -k], [w + k, h + k], [-k, h + k]],
        closed: true,
        panel: None,
    });
    let r = 0.5 * lam.hole - k;
    ply.circles
        .extend(holes(sheet, lam).into_iter().map(|c| (c, r)));
    let a = mark_arm_mm(lam);
    for m in marks(sheet, lam) {
        for (dx, dy) in [(a, 0.0), (0.0, a)] {
            ply.paths.push(Path2 {
                layer: "REGISTER",
                points: vec![[m[0] - dx, m[1] - dy], [m[0] + dx, m[1] + dy]],
                closed: false,
                panel: None,
            });
        }
    }
}

/// Check the holes against the kerf: a hole must be wider than the kerf.
fn check_hole(lam: &Laminate) -> Result<(), Refusal> {
    if lam.hole <= lam.kerf {
        return Err((
            "hole",
            format!(
                "{} mm is not wider than the kerf {} mm (allowed: a diameter above the kerf)",
                crate::text::num(lam.hole),
                crate::text::num(lam.kerf)
            ),
        ));
    }
    Ok(())
}

fn sheet_refusal(need: [f64; 2], sheet: [f64; 2], what: &str) -> Refusal {
    (
        "sheet",
        format!(
            "{}x{} mm is too small for {what}: it needs at least {:.3}x{:.3} mm with the margins (allowed: a sheet at least that large)",
            crate::text::num(sheet[0]),
            crate::text::num(sheet[1]),
            need[0],
            need[1]
        ),
    )
}

/// One design's plies on its sheet (`lam.sheet`, else its bounds plus the margin): kerf,
/// tabs, the pattern moved to the margin, the sheet's outline, holes and crosses.
pub fn lay_out(
    mut plies: Vec<PlyDrawing>,
    lam: &Laminate,
) -> Result<(Vec<PlyDrawing>, Layout), Refusal> {
    check_hole(lam)?;
    let mut tabs = prepare(&mut plies, lam)?;
    let m = margin_mm(lam);
    let (lo, hi) = bounds(&plies);
    let need = [hi[0] - lo[0] + 2.0 * m, hi[1] - lo[1] + 2.0 * m];
    let sheet = lam.sheet.unwrap_or(need);
    if need[0] > sheet[0] + 1e-9 || need[1] > sheet[1] + 1e-9 {
        return Err(sheet_refusal(need, sheet, "the pattern"));
    }
    let offset = [m - lo[0], m - lo[1]];
    for ply in &mut plies {
        translate(ply, offset);
        frame(ply, sheet, lam);
    }
    for t in &mut tabs {
        t.at_mm = [t.at_mm[0] + offset[0], t.at_mm[1] + offset[1]];
    }
    let layout = Layout {
        kerf_mm: lam.kerf,
        tab_width_mm: lam.tab_width,
        hole_mm: lam.hole,
        margin_mm: m,
        sheet_mm: sheet,
        sheet_given: lam.sheet.is_some(),
        offset_mm: offset,
        holes_mm: holes(sheet, lam),
        marks_mm: marks(sheet, lam),
        mark_arm_mm: mark_arm_mm(lam),
        tabs,
    };
    Ok((plies, layout))
}

/// Shelf packing: the lower-left corners of boxes of `sizes` inside `[m, W − m] × [m,
/// H − m]` of a `sheet`, [`GAP_MM`] apart (tallest first, left to right, shelf above
/// shelf); `None` when they do not all fit.
pub fn pack(sizes: &[[f64; 2]], sheet: [f64; 2], m: f64) -> Option<Vec<[f64; 2]>> {
    let mut order: Vec<usize> = (0..sizes.len()).collect();
    order.sort_by(|&a, &b| sizes[b][1].total_cmp(&sizes[a][1]));
    let mut at = vec![[0.0; 2]; sizes.len()];
    let (mut x, mut y, mut shelf) = (m, m, 0.0f64);
    let eps = 1e-9;
    for i in order {
        let [w, h] = sizes[i];
        if x > m && x + w > sheet[0] - m + eps {
            (x, y) = (m, y + shelf + GAP_MM);
            shelf = 0.0;
        }
        if x + w > sheet[0] - m + eps || y + h > sheet[1] - m + eps {
            return None;
        }
        at[i] = [x, y];
        x += w + GAP_MM;
        shelf = shelf.max(h);
    }
    Some(at)
}

/// Several designs' plies on one sheet (`lam.sheet` required): each design's plies
/// prepared as in [`lay_out`] and moved to its place; plies of the same name merged into
/// one drawing per name (in order of first appearance), each framed by the sheet. With
/// them, each design's offset (added to its mm coordinates).
pub fn lay_out_many(
    designs: Vec<Vec<PlyDrawing>>,
    lam: &Laminate,
) -> Result<(Vec<PlyDrawing>, Vec<[f64; 2]>), Refusal> {
    check_hole(lam)?;
    let Some(sheet) = lam.sheet else {
        return Err((
            "sheet",
            "needed to lay out several designs on one sheet: give its size as WxH mm, e.g. 600x400"
                .into(),
        ));
    };
    let m = margin_mm(lam);
    let mut prepared = Vec::with_capacity(designs.len());
    for mut plies in designs {
        prepare(&mut plies, lam)?;
        prepared.push(plies);
    }
    let boxes: Vec<_> = prepared.iter().map(|p| bounds(p)).collect();
    let sizes: Vec<[f64; 2]> = boxes
        .iter()
        .map(|(lo, hi)| [hi[0] - lo[0], hi[1] - lo[1]])
        .collect();
    let at = pack(&sizes, sheet, m).ok_or_else(|| {
        let boxes: Vec<String> = sizes
            .iter()
            .map(|s| format!("{:.3}x{:.3}", s[0], s[1]))
            .collect();
        (
            "sheet",
            format!(
                "{}x{} mm does not hold the {} designs' boxes {} mm, {GAP_MM} mm apart, in shelves inside a margin of {:.3} mm (allowed: a sheet that holds them, or fewer designs)",
                crate::text::num(sheet[0]),
                crate::text::num(sheet[1]),
                sizes.len(),
                boxes.join(", "),
                m
            ),
        )
    })?;
    let mut merged: Vec<PlyDrawing> = Vec::new();
    let mut offsets = Vec::with_capacity(at.len());
    for ((plies, (lo, _)), pos) in prepared.into_iter().zip(&boxes).zip(&at) {
        let d = [pos[0] - lo[0], pos[1] - lo[1]];
        offsets.push(d);
        for mut ply in plies {
            translate(&mut ply, d);
            match merged.iter_mut().find(|p| p.name == ply.name) {
                Some(into) => {
                    into.paths.extend(ply.paths);
                    into.labels.extend(ply.labels);
                    into.circles.extend(ply.circles);
                }
                None => merged.push(ply),
            }
        }
    }
    for ply in &mut merged {
        frame(ply, sheet, lam);
    }
    Ok((merged, offsets))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_grows_by_half_the_kerf_and_keeps_its_tab_gaps() {
        let sq = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
        let o = offset_right(&sq, 0.1).unwrap();
        assert!((o[0][0] + 0.1).abs() < 1e-12 && (o[0][1] + 0.1).abs() < 1e-12);
        assert!((o[2][0] - 10.1).abs() < 1e-12 && (o[2][1] - 10.1).abs() < 1e-12);
        // Clockwise (a hole in the material): it shrinks.
        let hole: Vec<_> = sq.iter().rev().copied().collect();
        let o = offset_right(&hole, 0.1).unwrap();
        assert!(o.iter().all(|p| p[0] > 0.0 && p[1] > 0.0));
        let (pieces, at) = with_tabs(&sq, 1.0).unwrap();
        assert_eq!((pieces.len(), at.len()), (4, 4));
        for (k, p) in pieces.iter().enumerate() {
            let next = &pieces[(k + 1) % 4];
            let (a, b) = (p[p.len() - 1], next[0]);
            assert!(((a[0] - b[0]).hypot(a[1] - b[1]) - 1.0).abs() < 1e-12);
        }
        assert!(with_tabs(&sq, 5.0).is_none());
    }

    #[test]
    fn shelves_fit_or_refuse() {
        let at = pack(&[[100.0, 50.0], [100.0, 80.0]], [300.0, 120.0], 10.0).unwrap();
        assert_eq!(at, vec![[115.0, 10.0], [10.0, 10.0]]);
        assert!(pack(&[[100.0, 50.0], [200.0, 80.0]], [300.0, 120.0], 10.0).is_none());
        // A second shelf.
        let at = pack(&[[200.0, 40.0], [200.0, 40.0]], [220.0, 120.0], 10.0).unwrap();
        assert_eq!(at[1], [10.0, 55.0]);
    }
}
