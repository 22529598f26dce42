//! Thick panels that keep the kinematics (issue 32): volume trimming with tapered panels
//! (Tachi, "Rigid-foldable thick origami", 2011).
//!
//! The hinge axes stay on the zero-thickness crease lines. Each panel is its facet's slab
//! (`[fabrication] sides`: offsets `[0, t]` or `[−t/2, t/2]` along the facet normal),
//! trimmed near each crease by a plane through the crease line: at offset `z` on the side
//! toward which the crease closes, the panel edge is set back from the crease by
//! `g/2 + |z|·tan(ρ_max/2)`, where ρ_max is the crease's largest fold toward that side over
//! the motion and `g` the hinge gap. With `g = 0` the two trimming planes of a crease are
//! the bisector of the closed wedge at ρ_max: the panels meet there and not before. A
//! valley (ρ > 0) closes the +normal side, a mountain the −normal side; a crease whose sign
//! changes over the motion is trimmed on both sides. Trimming is local to each crease, so
//! any degree and any sector angles work. See docs/fabrication.md for the construction.
//!
//! This module is low: it reads only [`crate::pattern`], [`crate::geom`] and
//! [`crate::task::fabrication`].

mod bill;
mod outline;
mod solid;

pub use bill::{Bill, CreaseBill, PanelBill, PlyOutline};
pub use solid::{Motion, Solid, facet_motion};

use crate::geom;
use crate::pattern::{EdgeKind, Frame, Pattern};
use crate::task::fabrication::Fabrication;
use std::collections::HashMap;

/// Largest folds of one crease over the motion, rad: the largest positive (valley, toward
/// +normal) and the largest |negative| (mountain) fold angle seen on the sweep.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FoldRange {
    /// Largest valley fold (≥ 0).
    pub valley: f64,
    /// Largest mountain fold, as a magnitude (≥ 0).
    pub mountain: f64,
}

impl FoldRange {
    /// The larger of the two.
    pub fn largest(&self) -> f64 {
        self.valley.max(self.mountain)
    }
}

/// One layer of a panel: a polygon in the flat layout (pattern coordinates, paper units),
/// at `offset` along the flat sheet's +z (paper units).
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// Offset along the facet normal, paper units.
    pub offset: f64,
    /// Counter-clockwise corners; corner k lies over the facet's corner k.
    pub outline: Vec<[f64; 2]>,
}

/// A facet's thick panel: layers sorted by offset, every outline with the same number of
/// corners (corner k of each layer lies over the facet's corner k); the solid is the loft
/// between consecutive layers.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Index into `pattern.faces`.
    pub facet: usize,
    /// The layers, lowest offset first.
    pub layers: Vec<Layer>,
}

/// A crease as a hinge.
#[derive(Clone, Debug, PartialEq)]
pub struct Hinge {
    /// Index into `pattern.edges`.
    pub edge: usize,
    /// The end vertices of the crease.
    pub vertices: [usize; 2],
    /// The two facets: `[left, right]` of the edge `vertices[0] → vertices[1]`.
    pub facets: [usize; 2],
    /// The hinge axis: the zero-thickness crease line, flat coordinates (paper units).
    pub axis: [[f64; 2]; 2],
    /// Its largest folds over the motion.
    pub folds: FoldRange,
    /// Setback of each panel edge from the axis at the slab's faces, paper units:
    /// `[at the +normal face, at the −normal face]`.
    pub setback: [f64; 2],
    /// The widest gap between the two panels' outlines in the ply drawings, mm.
    pub gap_mm: f64,
    /// The hinge length, mm.
    pub length_mm: f64,
}

/// A design made thick.
#[derive(Clone, Debug, PartialEq)]
pub struct ThickDesign {
    /// The setting it was built for.
    pub spec: Fabrication,
    /// One panel per facet, in facet order.
    pub panels: Vec<Panel>,
    /// One hinge per crease, in edge order.
    pub hinges: Vec<Hinge>,
}

/// Why a design cannot be built; names the crease (edge index and end vertices) or facet.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FabError {
    /// A crease folds flat (ρ = π) somewhere in the motion: no thickness fits.
    #[error(
        "crease {edge} (vertices {a}–{b}) reaches a fold of {deg:.3}°: a thick panel cannot fold to 180°; limit the motion below π"
    )]
    FoldsFlat {
        /// Edge index.
        edge: usize,
        /// End vertex.
        a: usize,
        /// End vertex.
        b: usize,
        /// Its largest fold, degrees.
        deg: f64,
    },
    /// Trimming leaves no panel (an edge collapses or the outline turns over).
    #[error(
        "the panel of facet {facet} vanishes: trimming at crease {edge} (vertices {a}–{b}, setback {setback_mm:.3} mm at offset {offset_mm:.3} mm) leaves no panel; use thinner panels or a smaller fold range"
    )]
    Vanishes {
        /// Facet index.
        facet: usize,
        /// The crease with the largest setback on that facet.
        edge: usize,
        /// End vertex.
        a: usize,
        /// End vertex.
        b: usize,
        /// That crease's setback at that layer, mm.
        setback_mm: f64,
        /// The layer's offset, mm.
        offset_mm: f64,
    },
    /// Trimming leaves a panel narrower than `min_width`.
    #[error(
        "the panel of facet {facet} is {width_mm:.3} mm wide after trimming at crease {edge} (vertices {a}–{b}), below min_width = {min_mm} mm"
    )]
    TooThin {
        /// Facet index.
        facet: usize,
        /// The crease with the largest setback on that facet.
        edge: usize,
        /// End vertex.
        a: usize,
        /// End vertex.
        b: usize,
        /// The panel's width there, mm.
        width_mm: f64,
        /// The smallest width allowed, mm.
        min_mm: f64,
    },
    /// The pattern is not something the method can take (a facet side that is no edge, a
    /// crease without two facets, a facet with fewer than 3 corners, a fold range count
    /// that does not match the edges).
    #[error("the pattern cannot be made thick: {0}")]
    Malformed(String),
    /// The setting is invalid (`Fabrication::validate`).
    #[error("[fabrication] {field}: {message}")]
    Setting {
        /// The field.
        field: &'static str,
        /// What is allowed.
        message: String,
    },
}

/// Directed facet sides: `(a, b)` → the facet that walks `a → b`.
fn directed_sides(pattern: &Pattern) -> HashMap<(usize, usize), usize> {
    let mut m = HashMap::new();
    for (f, face) in pattern.faces.iter().enumerate() {
        for k in 0..face.len() {
            m.insert((face[k], face[(k + 1) % face.len()]), f);
        }
    }
    m
}

/// The facets `[left, right]` of each crease (`None` for boundaries or a crease that does
/// not have a facet on each side).
fn crease_facets(pattern: &Pattern) -> Vec<Option<[usize; 2]>> {
    let sides = directed_sides(pattern);
    pattern
        .edges
        .iter()
        .map(|e| match e.kind {
            EdgeKind::Crease { .. } => {
                let [a, b] = e.v;
                Some([*sides.get(&(a, b))?, *sides.get(&(b, a))?])
            }
            EdgeKind::Boundary => None,
        })
        .collect()
}

/// The fold angle of every crease at every frame (`series[frame][edge]`; 0 for boundary
/// edges and degenerate facets), measured from the coordinates with [`geom::fold_angle`].
fn fold_series(pattern: &Pattern, frames: &[Frame]) -> Vec<Vec<f64>> {
    let facets = crease_facets(pattern);
    frames
        .iter()
        .map(|frame| {
            let pts = |f: usize| -> Vec<geom::V3> {
                pattern.faces[f].iter().map(|&v| frame.coords[v]).collect()
            };
            pattern
                .edges
                .iter()
                .enumerate()
                .map(|(i, e)| {
                    let Some([l, r]) = facets[i] else { return 0.0 };
                    let [a, b] = e.v;
                    geom::fold_angle(frame.coords[a], frame.coords[b], &pts(l), &pts(r))
                        .unwrap_or(0.0)
                })
                .collect()
        })
        .collect()
}

/// The largest folds of every edge over `frames` (crease edges only; others zero),
/// measured from the frames' coordinates with [`geom::fold_angle`] (valley positive).
pub fn fold_ranges(pattern: &Pattern, frames: &[Frame]) -> Vec<FoldRange> {
    let mut out = vec![FoldRange::default(); pattern.edges.len()];
    for row in fold_series(pattern, frames) {
        for (o, &rho) in out.iter_mut().zip(&row) {
            if rho > 0.0 {
                o.valley = o.valley.max(rho);
            } else {
                o.mountain = o.mountain.max(-rho);
            }
        }
    }
    out
}

/// [`fold_ranges`], each extreme raised to the peak of the parabola through the largest
/// sample and its two neighbours in `t` when that peak lies between them: a motion sampled
/// at a few frames may fold further between two of them than at either.
pub fn fold_ranges_refined(pattern: &Pattern, frames: &[Frame]) -> Vec<FoldRange> {
    let series = fold_series(pattern, frames);
    let mut out = fold_ranges(pattern, frames);
    let peak = |i: usize, e: usize, sign: f64| -> f64 {
        let (t0, t1, t2) = (frames[i - 1].t, frames[i].t, frames[i + 1].t);
        let (y0, y1, y2) = (
            sign * series[i - 1][e],
            sign * series[i][e],
            sign * series[i + 1][e],
        );
        // Newton's divided differences: y = y0 + d1 (t − t0) + d2 (t − t0)(t − t1).
        let d01 = (y1 - y0) / (t1 - t0);
        let d12 = (y2 - y1) / (t2 - t1);
        let d2 = (d12 - d01) / (t2 - t0);
        if !(d2 < 0.0) {
            return y1;
        }
        let tp = 0.5 * (t0 + t1) - d01 / (2.0 * d2);
        if !(tp > t0 && tp < t2) {
            return y1;
        }
        let yp = y0 + d01 * (tp - t0) + d2 * (tp - t0) * (tp - t1);
        if yp.is_finite() { yp.max(y1) } else { y1 }
    };
    for (e, o) in out.iter_mut().enumerate() {
        for (sign, slot) in [(1.0, &mut o.valley), (-1.0, &mut o.mountain)] {
            let best = (1..frames.len().saturating_sub(1))
                .filter(|&i| frames[i - 1].t < frames[i].t && frames[i].t < frames[i + 1].t)
                .filter(|&i| (sign * series[i][e] - *slot).abs() == 0.0 && *slot > 0.0)
                .map(|i| peak(i, e, sign))
                .fold(*slot, f64::max);
            *slot = best;
        }
    }
    out
}

/// Build the thick panels of `pattern` for the largest folds `ranges` (one per edge).
pub fn build(
    pattern: &Pattern,
    ranges: &[FoldRange],
    spec: &Fabrication,
) -> Result<ThickDesign, FabError> {
    spec.validate()
        .map_err(|(field, message)| FabError::Setting { field, message })?;
    if ranges.len() != pattern.edges.len() {
        return Err(FabError::Malformed(format!(
            "{} fold ranges for {} edges",
            ranges.len(),
            pattern.edges.len()
        )));
    }
    let facets = crease_facets(pattern);
    let hinges = hinges(pattern, ranges, spec, &facets)?;
    let by_edge = edge_index(pattern);
    let mut panels = Vec::with_capacity(pattern.faces.len());
    for (f, face) in pattern.faces.iter().enumerate() {
        panels.push(outline::panel(pattern, f, face, &by_edge, &hinges, spec)?);
    }
    Ok(ThickDesign {
        spec: *spec,
        panels,
        hinges,
    })
}

/// Undirected edge `{a, b}` → its index.
fn edge_index(pattern: &Pattern) -> HashMap<(usize, usize), usize> {
    pattern
        .edges
        .iter()
        .enumerate()
        .map(|(i, e)| ((e.v[0].min(e.v[1]), e.v[0].max(e.v[1])), i))
        .collect()
}

/// The hinges: refuse folds of π, compute each setback, gap and length.
fn hinges(
    pattern: &Pattern,
    ranges: &[FoldRange],
    spec: &Fabrication,
    facets: &[Option<[usize; 2]>],
) -> Result<Vec<Hinge>, FabError> {
    let [lo, hi] = spec.slab_units();
    let half_gap = 0.5 * spec.hinge_gap / spec.scale;
    let mut out = Vec::new();
    for (i, e) in pattern.edges.iter().enumerate() {
        if !matches!(e.kind, EdgeKind::Crease { .. }) {
            continue;
        }
        let [a, b] = e.v;
        let Some(pair) = facets[i] else {
            return Err(FabError::Malformed(format!(
                "crease {i} (vertices {a}–{b}) does not have a facet on each side"
            )));
        };
        let r = ranges[i];
        let largest = r.largest();
        if !largest.is_finite() || largest >= std::f64::consts::PI - 1e-9 {
            return Err(FabError::FoldsFlat {
                edge: i,
                a,
                b,
                deg: largest.to_degrees(),
            });
        }
        let setback = [
            outline::setback(hi, r, half_gap),
            outline::setback(lo, r, half_gap),
        ];
        let (pa, pb) = (pattern.vertices[a], pattern.vertices[b]);
        out.push(Hinge {
            edge: i,
            vertices: [a, b],
            facets: pair,
            axis: [pa, pb],
            folds: r,
            setback,
            gap_mm: 2.0 * setback[0].max(setback[1]) * spec.scale,
            length_mm: (pb[0] - pa[0]).hypot(pb[1] - pa[1]) * spec.scale,
        });
    }
    Ok(out)
}

impl ThickDesign {
    /// Every panel's solid in the flat state (paper units).
    pub fn flat_solids(&self) -> Vec<Solid> {
        self.panels.iter().map(solid::loft).collect()
    }

    /// Every panel's solid moved by its facet's rigid motion at `frame` (flat → frame; the
    /// motion of a facet is fixed by its corners' flat and folded coordinates).
    pub fn solids_at(&self, pattern: &Pattern, frame: &Frame) -> Vec<Solid> {
        self.panels
            .iter()
            .map(|p| {
                let m = facet_motion(pattern, p.facet, frame);
                let mut s = solid::loft(p);
                for v in &mut s.vertices {
                    *v = m.apply(*v);
                }
                s
            })
            .collect()
    }

    /// The hinge of edge `edge`, if it is a crease.
    pub fn hinge_of_edge(&self, edge: usize) -> Option<&Hinge> {
        self.hinges.iter().find(|h| h.edge == edge)
    }
}
