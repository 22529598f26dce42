//! Thick panels as the report's 3D view reads them (issue 32): each panel of the arm as a
//! triangle mesh in the flat layout with three corners of its facet, so the page moves it
//! with the facet's rigid motion at any t of the slider (the motion that takes those corners
//! from the flat layout to the frame).

use serde_json::{Value, json};

use crate::fabricate::ThickDesign;
use crate::pattern::Pattern;

/// Three corners of facet `face` spanning it: the first two and the one farthest from
/// their line.
fn spanning(flat: &[[f64; 2]], face: &[usize]) -> [usize; 3] {
    let (a, b) = (flat[face[0]], flat[face[1]]);
    let c = face[2..]
        .iter()
        .copied()
        .max_by(|&p, &q| {
            let area = |v: usize| {
                let c = flat[v];
                ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs()
            };
            area(p).total_cmp(&area(q))
        })
        .unwrap_or(face[face.len() - 1]);
    [face[0], face[1], c]
}

/// `{panels: [{facet, corners, vertices, triangles}], bill}` for the panels of `arm`'s
/// facets (the first `arm.faces.len()` of `design`, built on the arm with its copies; the
/// view turns the arm's group for each copy): `vertices` flattened x, y, z in the flat
/// layout (paper units), `triangles` flattened indices, `corners` three vertex indices of
/// the pattern that fix the facet's motion.
pub fn thick_json(arm: &Pattern, design: &ThickDesign) -> Value {
    let panels: Vec<Value> = design
        .flat_solids()
        .into_iter()
        .filter(|s| s.facet < arm.faces.len() && arm.faces[s.facet].len() >= 3)
        .map(|s| {
            json!({
                "facet": s.facet,
                "corners": spanning(&arm.vertices, &arm.faces[s.facet]),
                "vertices": s.vertices.iter().flatten().map(|&x| (x * 1e6).round() / 1e6).collect::<Vec<_>>(),
                "triangles": s.triangles.iter().flatten().collect::<Vec<_>>(),
            })
        })
        .collect();
    json!({ "panels": panels, "bill": design.bill() })
}
