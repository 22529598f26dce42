//! The bill of the build: what to cut, how big, and how far each hinge folds.

use super::ThickDesign;
use crate::geom;
use crate::task::fabrication::{FabMethod, Fabrication, Sides};
use serde::{Deserialize, Serialize};

/// One layer of a panel in mm.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlyOutline {
    /// Offset along the facet normal, mm.
    pub offset_mm: f64,
    /// Counter-clockwise corners in the flat layout, mm.
    pub outline_mm: Vec<[f64; 2]>,
    /// Its area, mm².
    pub area_mm2: f64,
}

/// One panel of the bill.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PanelBill {
    /// The facet (panel id).
    pub facet: usize,
    /// Panel thickness, mm.
    pub thickness_mm: f64,
    /// Its smallest layer: what a straight cut through the whole slab leaves, mm.
    pub outline_mm: Vec<[f64; 2]>,
    /// The area of that outline, mm².
    pub area_mm2: f64,
    /// Every layer of the tapered panel (the slab's faces and the hinge plane inside).
    pub layers: Vec<PlyOutline>,
}

/// One crease of the bill.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CreaseBill {
    /// Edge index in the pattern.
    pub edge: usize,
    /// End vertices.
    pub vertices: [usize; 2],
    /// The two facets (panel ids).
    pub facets: [usize; 2],
    /// The hinge axis (the crease line) in the flat layout, mm.
    pub axis_mm: [[f64; 2]; 2],
    /// Largest valley fold over the motion, degrees.
    pub valley_deg: f64,
    /// Largest mountain fold over the motion (magnitude), degrees.
    pub mountain_deg: f64,
    /// The larger of the two, degrees.
    pub largest_fold_deg: f64,
    /// Setback of each panel edge from the axis at the +normal and −normal faces, mm.
    pub setback_mm: [f64; 2],
    /// The widest gap between the two panels in the ply drawings, mm.
    pub gap_mm: f64,
    /// Hinge length, mm.
    pub hinge_length_mm: f64,
}

/// The bill of a thick design.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Bill {
    /// The method's name.
    pub method: String,
    /// "one" or "both".
    pub sides: String,
    /// Panel thickness, mm.
    pub thickness_mm: f64,
    /// mm per paper unit.
    pub scale_mm_per_unit: f64,
    /// The hinge gap asked for, mm.
    pub hinge_gap_mm: f64,
    /// The narrowest panel allowed, mm.
    pub min_width_mm: f64,
    /// Per panel.
    pub panels: Vec<PanelBill>,
    /// Per crease.
    pub creases: Vec<CreaseBill>,
    /// The sum of the panels' outline areas, mm².
    pub total_area_mm2: f64,
}

impl ThickDesign {
    /// The bill of the build: per panel its outline (mm), area (mm²), thickness; per crease
    /// its largest fold angle (deg), gap width (mm), hinge length (mm).
    pub fn bill(&self) -> Bill {
        let s = self.spec.scale;
        let mm = |pts: &[[f64; 2]]| -> Vec<[f64; 2]> {
            pts.iter().map(|p| [p[0] * s, p[1] * s]).collect()
        };
        let panels: Vec<PanelBill> = self
            .panels
            .iter()
            .map(|p| {
                let layers: Vec<PlyOutline> = p
                    .layers
                    .iter()
                    .map(|l| {
                        let o = mm(&l.outline);
                        PlyOutline {
                            offset_mm: l.offset * s,
                            area_mm2: geom::signed_area_2d(&o),
                            outline_mm: o,
                        }
                    })
                    .collect();
                let least = layers
                    .iter()
                    .min_by(|a, b| a.area_mm2.total_cmp(&b.area_mm2))
                    .cloned();
                let (outline_mm, area_mm2) =
                    least.map_or((Vec::new(), 0.0), |l| (l.outline_mm, l.area_mm2));
                PanelBill {
                    facet: p.facet,
                    thickness_mm: self.spec.thickness,
                    outline_mm,
                    area_mm2,
                    layers,
                }
            })
            .collect();
        let creases = self
            .hinges
            .iter()
            .map(|h| CreaseBill {
                edge: h.edge,
                vertices: h.vertices,
                facets: h.facets,
                axis_mm: [
                    [h.axis[0][0] * s, h.axis[0][1] * s],
                    [h.axis[1][0] * s, h.axis[1][1] * s],
                ],
                valley_deg: h.folds.valley.to_degrees(),
                mountain_deg: h.folds.mountain.to_degrees(),
                largest_fold_deg: h.folds.largest().to_degrees(),
                setback_mm: [h.setback[0] * s, h.setback[1] * s],
                gap_mm: h.gap_mm,
                hinge_length_mm: h.length_mm,
            })
            .collect();
        Bill {
            method: self.spec.method.name().into(),
            sides: self.spec.sides.name().into(),
            thickness_mm: self.spec.thickness,
            scale_mm_per_unit: s,
            hinge_gap_mm: self.spec.hinge_gap,
            min_width_mm: self.spec.min_width,
            total_area_mm2: panels.iter().map(|p| p.area_mm2).sum(),
            panels,
            creases,
        }
    }
}

impl Bill {
    /// The setting this bill was built with, validated: how `foldsynth fabricate` takes the
    /// material from a design file (`fabrication.bill` of `designs/<id>.json`) when its
    /// flags leave it out. `Err((field, what is allowed))` names the bill's field.
    pub fn setting(&self) -> Result<Fabrication, (&'static str, String)> {
        let method = FabMethod::from_name(&self.method).ok_or_else(|| {
            (
                "method",
                format!(
                    "unknown method '{}'; allowed: {}",
                    crate::text::excerpt(&self.method, 40),
                    FabMethod::NAMES.join(", ")
                ),
            )
        })?;
        let sides = Sides::from_name(&self.sides).ok_or_else(|| {
            (
                "sides",
                format!(
                    "unknown value '{}'; allowed: {}",
                    crate::text::excerpt(&self.sides, 40),
                    Sides::NAMES.join(", ")
                ),
            )
        })?;
        let spec = Fabrication {
            thickness: self.thickness_mm,
            scale: self.scale_mm_per_unit,
            method,
            sides,
            hinge_gap: self.hinge_gap_mm,
            min_width: self.min_width_mm,
        };
        spec.validate().map(|()| spec)
    }

    /// The bill's field named by [`Fabrication::validate`]'s `field`.
    pub fn field_name(field: &str) -> &'static str {
        match field {
            "thickness" => "thickness_mm",
            "scale" => "scale_mm_per_unit",
            "hinge_gap" => "hinge_gap_mm",
            "min_width" => "min_width_mm",
            "method" => "method",
            _ => "sides",
        }
    }
}
