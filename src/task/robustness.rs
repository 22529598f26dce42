//! The `[robustness]` table of a task file: how far from a rigid limit, from each other and
//! from the obstacles the optimizer keeps a design over its whole motion (issue 12).
//!
//! ```toml
//! [robustness]
//! rigid_margin = "pi/180"     # rad: Eq. 25 margin of every vertex (default 1°)
//! clearance = 0.01            # paper units (G0's crease = 1): facets apart (default 1%)
//! obstacle_clearance = 0.01   # paper units: facets off every obstacle (default 1%)
//! min_feature = 0.015         # paper units: flat layout's smallest feature (default 1.5%)
//! ```
//!
//! All four at 0 reproduce the thesis's setting (only Eq. 33 at t_max with its 1e-8 floor,
//! and intersection-free).

use super::{Ctx, InitialGraph, Number, TaskError};
use serde::Deserialize;

/// Default `rigid_margin`: 1°. A sector angle cut or creased δ off its design value moves
/// each Eq. 25 margin `U_j + U_k − U_i` by at most 2δ (one sector belongs to one unit), so
/// 1° keeps a vertex rigid under the ±0.5° angular errors of a careful laser cut or fold.
pub const DEFAULT_RIGID_MARGIN: f64 = std::f64::consts::PI / 180.0;

/// Default `clearance` and `obstacle_clearance`: 1% of G0's crease. The model's facets have
/// no thickness; a sheet whose thickness is 1% of its first crease (1 mm card for a 10 cm
/// gripper) needs that much room between the mid-surfaces of two facets, or between a
/// facet and an obstacle, for the real sheet not to touch.
pub const DEFAULT_CLEARANCE: f64 = 0.01;

/// Default `min_feature`: 1.5% of G0's crease. Origami Simulator's SVG importer merges
/// vertices closer than 3 px and splits edges at vertices within 3 px; at the 200 px per unit
/// of a 1:1 crease-pattern page that is 0.015 units. It is also 1.5 sheet thicknesses at the
/// default clearance (1 mm card on a 10 cm gripper: 1.5 mm), about the narrowest sliver
/// a blade or scoring tool still cuts and creases without tearing.
pub const DEFAULT_MIN_FEATURE: f64 = 0.015;

/// The largest Eq. 25 margin any vertex can have: the three margins `P − 2U_i` sum to the
/// perimeter `P ≤ 2π` of the vertex triangle, so their minimum is at most `2π/3`.
pub const MAX_RIGID_MARGIN: f64 = 2.0 * std::f64::consts::PI / 3.0;

/// Robustness settings (the `[robustness]` table; defaults when absent).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Robustness {
    /// Radians: every internal vertex keeps `U_j + U_k − U_i ≥ rigid_margin · (t/t_max)²`
    /// over the whole motion (the flat state t = 0 is degenerate for every vertex whose
    /// first unit spans more than π, and the margin grows as t² from there; at t_max the
    /// full margin applies).
    pub rigid_margin: f64,
    /// Paper units: facets that share no vertex stay this far apart; facets that share a
    /// vertex keep this gap at unit distance from it; creases stay this far (rad) from
    /// folding flat. Includes the rotated copy of two-armed tasks.
    pub clearance: f64,
    /// Paper units: every facet stays this far from every obstacle.
    pub obstacle_clearance: f64,
    /// Paper units: in the flat layout, every two vertices, every vertex and edge it does
    /// not end on, and so every crease and boundary edge, are at least this far apart.
    pub min_feature: f64,
}

impl Default for Robustness {
    fn default() -> Self {
        Robustness {
            rigid_margin: DEFAULT_RIGID_MARGIN,
            clearance: DEFAULT_CLEARANCE,
            obstacle_clearance: DEFAULT_CLEARANCE,
            min_feature: DEFAULT_MIN_FEATURE,
        }
    }
}

impl Robustness {
    /// The thesis's setting: no margins (only intersection-free and rigid).
    pub fn zero() -> Robustness {
        Robustness {
            rigid_margin: 0.0,
            clearance: 0.0,
            obstacle_clearance: 0.0,
            min_feature: 0.0,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawRobustness {
    rigid_margin: Option<Number>,
    clearance: Option<Number>,
    obstacle_clearance: Option<Number>,
    min_feature: Option<Number>,
}

/// The length unit of the task: G0's shortest crease (1 for the thesis's tasks).
pub(crate) fn unit_length(g0: &InitialGraph) -> f64 {
    g0.creases
        .iter()
        .map(|c| {
            let (a, b) = (g0.vertices[c.tail].xy, g0.vertices[c.head].xy);
            (a[0] - b[0]).hypot(a[1] - b[1])
        })
        .fold(f64::INFINITY, f64::min)
}

pub(crate) fn build(
    cx: &Ctx<'_>,
    raw: Option<&RawRobustness>,
    g0: &InitialGraph,
) -> Result<Robustness, TaskError> {
    let mut r = Robustness::default();
    let Some(raw) = raw else { return Ok(r) };
    let unit = unit_length(g0);
    let value = |field: &str, n: &Option<Number>, default: f64| -> Result<f64, TaskError> {
        let Some(n) = n else { return Ok(default) };
        let v = cx.num(field, n)?;
        if v < 0.0 {
            return Err(cx.err(
                field,
                format!("{v} is not allowed: a margin must be ≥ 0 (0 turns it off)"),
            ));
        }
        Ok(v)
    };
    r.rigid_margin = value("robustness.rigid_margin", &raw.rigid_margin, r.rigid_margin)?;
    if r.rigid_margin >= MAX_RIGID_MARGIN {
        return Err(cx.err(
            "robustness.rigid_margin",
            format!(
                "{} rad is not allowed: no vertex has an Eq. 25 margin of 2π/3 or more (the three margins sum to at most 2π); allowed [0, 2π/3)",
                r.rigid_margin
            ),
        ));
    }
    for (field, raw_value, slot) in [
        ("robustness.clearance", &raw.clearance, &mut r.clearance),
        (
            "robustness.obstacle_clearance",
            &raw.obstacle_clearance,
            &mut r.obstacle_clearance,
        ),
        (
            "robustness.min_feature",
            &raw.min_feature,
            &mut r.min_feature,
        ),
    ] {
        *slot = value(field, raw_value, *slot)?;
        if *slot >= unit {
            return Err(cx.err(
                field,
                format!(
                    "{} is larger than the pattern: clearances and feature sizes are in paper units and must stay below G0's crease length {unit} (allowed [0, {unit}))",
                    *slot
                ),
            ));
        }
    }
    Ok(r)
}
