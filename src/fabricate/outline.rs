//! The layers of one panel: the facet polygon with each crease side set back by the
//! trimming plane's distance at the layer's offset.

use super::{FabError, FoldRange, Hinge, Layer, Panel};
use crate::geom;
use crate::pattern::Pattern;
use crate::task::fabrication::Fabrication;
use std::collections::HashMap;

/// Setback from the crease line at offset `z` (paper units) for a crease with folds `r`:
/// the +normal side closes in a valley, the −normal side in a mountain (Tachi's bisector:
/// `|z|·tan(ρ/2)`), plus half the hinge gap.
pub(super) fn setback(z: f64, r: FoldRange, half_gap: f64) -> f64 {
    let rho = if z > 0.0 {
        r.valley
    } else if z < 0.0 {
        r.mountain
    } else {
        0.0
    };
    half_gap + z.abs() * (0.5 * rho).tan()
}

/// The offsets of the layers: the slab's faces, and the hinge plane when it lies inside
/// (there the trimming switches from mountain to valley planes).
pub(super) fn offsets(spec: &Fabrication) -> Vec<f64> {
    let [lo, hi] = spec.slab_units();
    if lo < 0.0 && hi > 0.0 {
        vec![lo, 0.0, hi]
    } else {
        vec![lo, hi]
    }
}

/// The panel of facet `f`.
pub(super) fn panel(
    pattern: &Pattern,
    f: usize,
    face: &[usize],
    by_edge: &HashMap<(usize, usize), usize>,
    hinges: &[Hinge],
    spec: &Fabrication,
) -> Result<Panel, FabError> {
    let n = face.len();
    if n < 3 {
        return Err(FabError::Malformed(format!(
            "facet {f} has {n} corners (at least 3)"
        )));
    }
    let corners: Vec<[f64; 2]> = face.iter().map(|&v| pattern.vertices[v]).collect();
    if geom::signed_area_2d(&corners) <= 0.0 || !geom::polygon_is_simple_2d(&corners) {
        return Err(FabError::Malformed(format!(
            "facet {f} is not a simple counter-clockwise polygon"
        )));
    }
    // The hinge on each side (None for a boundary side).
    let mut side_hinge = Vec::with_capacity(n);
    for k in 0..n {
        let (a, b) = (face[k], face[(k + 1) % n]);
        let Some(&e) = by_edge.get(&(a.min(b), a.max(b))) else {
            return Err(FabError::Malformed(format!(
                "side {a}–{b} of facet {f} is no edge of the pattern"
            )));
        };
        side_hinge.push(hinges.iter().find(|h| h.edge == e));
    }
    let half_gap = 0.5 * spec.hinge_gap / spec.scale;
    let mut layers = Vec::new();
    for z in offsets(spec) {
        let d: Vec<f64> = side_hinge
            .iter()
            .map(|h| h.map_or(0.0, |h| setback(z, h.folds, half_gap)))
            .collect();
        let blame = || {
            let k = (0..n)
                .filter(|&k| side_hinge[k].is_some())
                .max_by(|&i, &j| d[i].total_cmp(&d[j]))
                .unwrap_or(0);
            (side_hinge[k], d[k])
        };
        let outline = match offset_polygon(&corners, &d) {
            Some(o) => o,
            None => {
                let (h, dk) = blame();
                let Some(&Hinge {
                    edge,
                    vertices: [a, b],
                    ..
                }) = h
                else {
                    return Err(FabError::Malformed(format!("facet {f} is degenerate")));
                };
                return Err(FabError::Vanishes {
                    facet: f,
                    edge,
                    a,
                    b,
                    setback_mm: dk * spec.scale,
                    offset_mm: z * spec.scale,
                });
            }
        };
        let width_mm = caliper_width(&outline) * spec.scale;
        if width_mm < spec.min_width {
            let (h, _) = blame();
            let Some(&Hinge {
                edge,
                vertices: [a, b],
                ..
            }) = h
            else {
                return Err(FabError::Malformed(format!(
                    "facet {f} is {width_mm:.3} mm wide, below min_width = {} mm, without any crease",
                    spec.min_width
                )));
            };
            return Err(FabError::TooThin {
                facet: f,
                edge,
                a,
                b,
                width_mm,
                min_mm: spec.min_width,
            });
        }
        layers.push(Layer { offset: z, outline });
    }
    Ok(Panel { facet: f, layers })
}

/// The polygon `corners` (ccw) with side k moved inward by `d[k]`: corner k is where the
/// moved sides k − 1 and k cross. Where two consecutive sides are collinear the corner
/// moves by the larger setback (it trims a little more than needed, never less). `None`
/// when the result is no longer a simple ccw polygon whose sides keep their directions.
pub(super) fn offset_polygon(corners: &[[f64; 2]], d: &[f64]) -> Option<Vec<[f64; 2]>> {
    let n = corners.len();
    let dir = |k: usize| {
        let (p, q) = (corners[k], corners[(k + 1) % n]);
        [q[0] - p[0], q[1] - p[1]]
    };
    let inward = |k: usize| {
        let u = dir(k);
        let l = u[0].hypot(u[1]);
        [-u[1] / l, u[0] / l]
    };
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let j = (k + n - 1) % n;
        let (nj, nk) = (inward(j), inward(k));
        let pj = [corners[j][0] + d[j] * nj[0], corners[j][1] + d[j] * nj[1]];
        let pk = [corners[k][0] + d[k] * nk[0], corners[k][1] + d[k] * nk[1]];
        let c = match geom::line_intersection_2d(pj, dir(j), pk, dir(k)) {
            Some(c) => c,
            None => {
                if nj[0] * nk[0] + nj[1] * nk[1] <= 0.0 {
                    return None;
                }
                let m = d[j].max(d[k]);
                [corners[k][0] + m * nk[0], corners[k][1] + m * nk[1]]
            }
        };
        if !(c[0].is_finite() && c[1].is_finite()) {
            return None;
        }
        out.push(c);
    }
    for k in 0..n {
        let (p, q) = (out[k], out[(k + 1) % n]);
        let u = dir(k);
        if (q[0] - p[0]) * u[0] + (q[1] - p[1]) * u[1] <= 0.0 {
            return None;
        }
    }
    (geom::signed_area_2d(&out) > 0.0 && geom::polygon_is_simple_2d(&out)).then_some(out)
}

/// The caliper width of a polygon: over its sides, the least of the largest distance of a
/// corner from the side's line (the width of a convex polygon; a bound for others).
pub(super) fn caliper_width(pts: &[[f64; 2]]) -> f64 {
    let n = pts.len();
    (0..n)
        .map(|k| {
            let (p, q) = (pts[k], pts[(k + 1) % n]);
            let u = [q[0] - p[0], q[1] - p[1]];
            let l = u[0].hypot(u[1]);
            pts.iter()
                .map(|r| geom::cross_2d(u, [r[0] - p[0], r[1] - p[1]]).abs() / l)
                .fold(0.0, f64::max)
        })
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_offsets_by_its_setbacks() {
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let o = offset_polygon(&sq, &[0.1, 0.0, 0.2, 0.0]).unwrap();
        let want = [[0.0, 0.1], [1.0, 0.1], [1.0, 0.8], [0.0, 0.8]];
        for (a, b) in o.iter().zip(want) {
            assert!((a[0] - b[0]).abs() < 1e-15 && (a[1] - b[1]).abs() < 1e-15);
        }
        assert!((caliper_width(&o) - 0.7).abs() < 1e-15);
        // Setbacks that meet in the middle leave nothing.
        assert!(offset_polygon(&sq, &[0.5, 0.0, 0.6, 0.0]).is_none());
    }
}
