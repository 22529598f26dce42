//! The mirror image of G0 about the x-axis, for tasks symmetric about the xz-plane.

use super::initial::MirrorMap;
use super::{Ctx, InitialGraph, TaskError};

/// The vertex at the mirror position of every vertex and the mirror image of every facet,
/// or why G0 is not symmetric (positions within `tol`, types, creases, drives, facets).
pub(crate) fn mirror_map(cx: &Ctx<'_>, g: &InitialGraph, tol: f64) -> Result<MirrorMap, TaskError> {
    let (vs, cs, facets) = (&g.vertices, &g.creases, &g.facets);
    let field = "symmetry.mirror_xz";
    let mut vertex = Vec::with_capacity(vs.len());
    for v in vs {
        let m = vs
            .iter()
            .position(|u| (u.xy[0] - v.xy[0]).abs() <= tol && (u.xy[1] + v.xy[1]).abs() <= tol);
        let Some(m) = m else {
            return Err(cx.err(
                field,
                format!("G0 is not symmetric about the x-axis: no vertex at the mirror position ({}, {}) of \"{}\"", v.xy[0], -v.xy[1], v.id),
            ));
        };
        if vs[m].ty != v.ty {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: \"{}\" and its mirror image \"{}\" have different types",
                    v.id, vs[m].id
                ),
            ));
        }
        vertex.push(m);
    }
    let mut facet = vec![usize::MAX; facets.len()];
    for c in cs {
        let Some(m) = cs
            .iter()
            .find(|d| d.tail == vertex[c.tail] && d.head == vertex[c.head])
        else {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: crease {} → {} has no mirror image",
                    vs[c.tail].id, vs[c.head].id
                ),
            ));
        };
        if c.drive != m.drive {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: crease {} → {} and its mirror image have different drives",
                    vs[c.tail].id, vs[c.head].id
                ),
            ));
        }
        // Mirroring swaps left and right.
        for (f, g) in [(c.left, m.right), (c.right, m.left)] {
            if facet[f] != usize::MAX && facet[f] != g {
                return Err(cx.err(
                    field,
                    format!("G0's facet labels are not mirror-symmetric: facet {} maps to both {} and {}", facets[f], facets[facet[f]], facets[g]),
                ));
            }
            facet[f] = g;
        }
    }
    Ok(MirrorMap { vertex, facet })
}
