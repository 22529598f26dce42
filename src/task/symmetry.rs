//! The symmetry of a pattern (`[symmetry] rotations`, `center`, `mirror_axis`): a finite
//! group of isometries of the plane that maps G0 onto itself (thesis Sec. 4.3: the rigid
//! flasher and the star repeat four times about the central facet, the chair is its own
//! mirror image). The grammar grows one representative of every orbit and its images
//! follow (`grammar::symmetric`).
//!
//! Not to be confused with `mirror_xz`, which says the *task* is symmetric about the
//! xz-plane, so that a graph and its mirror image are the same design (a filter).

use super::initial::InitialGraph;
use super::isometry::{Group, Isometry, MAX_ROTATIONS, PatternSymmetry};
use super::{Ctx, TaskError, VertexType};

/// The group `sym` generates, with its action on `g` (positions within `tol`), or why G0
/// is not symmetric under it.
pub(crate) fn group(
    cx: &Ctx<'_>,
    g: &InitialGraph,
    sym: &PatternSymmetry,
    tol: f64,
) -> Result<Group, TaskError> {
    let vs = &g.vertices;
    let centroid = {
        let k = vs.len() as f64;
        [
            vs.iter().map(|v| v.xy[0]).sum::<f64>() / k,
            vs.iter().map(|v| v.xy[1]).sum::<f64>() / k,
        ]
    };
    let center = sym.center.unwrap_or(centroid);
    let mut gens = Vec::new();
    if sym.rotations > 1 {
        gens.push((
            "symmetry.rotations",
            Isometry::rotation(center, std::f64::consts::TAU / sym.rotations as f64),
        ));
    }
    if let Some([p, q]) = sym.mirror_axis {
        if sym.rotations > 1 {
            let d = [q[0] - p[0], q[1] - p[1]];
            let off =
                ((center[0] - p[0]) * d[1] - (center[1] - p[1]) * d[0]).abs() / d[0].hypot(d[1]);
            if off > tol {
                return Err(cx.err(
                    "symmetry.mirror_axis",
                    format!(
                        "the mirror axis misses the centre of rotation ({}, {}) by {}: with rotations the axis must pass through the centre (otherwise the symmetries generate an infinite group)",
                        crate::text::num(center[0]),
                        crate::text::num(center[1]),
                        crate::text::num(off)
                    ),
                ));
            }
        }
        gens.push(("symmetry.mirror_axis", Isometry::reflection(p, q)));
    }
    // Close the generators under composition.
    let mut elements = vec![Isometry::identity()];
    let mut k = 0;
    while k < elements.len() {
        for (_, gn) in &gens {
            let e = gn.then_after(&elements[k]);
            if !elements.iter().any(|x| x.close_to(&e, tol)) {
                elements.push(e);
            }
        }
        k += 1;
        if elements.len() > 4 * MAX_ROTATIONS {
            return Err(cx.err("symmetry", "the symmetries generate too many elements"));
        }
    }
    let find = |e: &Isometry| elements.iter().position(|x| x.close_to(e, tol));
    let mut mul = vec![vec![0; elements.len()]; elements.len()];
    for a in 0..elements.len() {
        for b in 0..elements.len() {
            mul[a][b] = find(&elements[a].then_after(&elements[b])).ok_or_else(|| {
                cx.err(
                    "symmetry",
                    "the symmetries do not form a finite group (check the centre and the axis)",
                )
            })?;
        }
    }
    let field = gens.first().map_or("symmetry", |g| g.0);
    let mut vertex = Vec::new();
    let mut crease = Vec::new();
    let mut facet = Vec::new();
    for e in &elements {
        let (v, c, f) = action(cx, g, e, tol, field)?;
        vertex.push(v);
        crease.push(c);
        facet.push(f);
    }
    // An extendable vertex must have as many images as the group has elements: one fixed
    // by a symmetry would need an extension symmetric in itself.
    for (i, v) in vs.iter().enumerate() {
        if v.ty != VertexType::Extendable {
            continue;
        }
        if let Some(gi) = (1..elements.len()).find(|&gi| vertex[gi][i] == i) {
            return Err(cx.err(
                field,
                format!(
                    "extendable vertex \"{}\" is its own image under a symmetry ({}): an extendable vertex must lie off the mirror axis and off the centre of rotation (its extension cannot be its own image); make it terminal or move it",
                    v.id,
                    if elements[gi].reflects {
                        "the mirror"
                    } else {
                        "a rotation"
                    }
                ),
            ));
        }
    }
    let out = Group {
        elements,
        mul,
        vertex,
        crease,
        facet,
        rotations: sym.rotations.max(1),
        center,
        mirror_axis: sym.mirror_axis,
    };
    fixed_part_invariant(cx, g, &out, field)?;
    Ok(out)
}

/// The permutations of G0's vertices, creases and facets under `e`, or why it does not map
/// G0 onto itself.
#[allow(clippy::type_complexity)]
fn action(
    cx: &Ctx<'_>,
    g: &InitialGraph,
    e: &Isometry,
    tol: f64,
    field: &str,
) -> Result<(Vec<usize>, Vec<usize>, Vec<usize>), TaskError> {
    let (vs, cs) = (&g.vertices, &g.creases);
    let mut vertex = Vec::with_capacity(vs.len());
    for v in vs {
        let p = e.apply(v.xy);
        let Some(m) = vs
            .iter()
            .position(|u| (u.xy[0] - p[0]).hypot(u.xy[1] - p[1]) <= tol.max(1e-9))
        else {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: no vertex at ({}, {}), the image of \"{}\"",
                    crate::text::num(p[0]),
                    crate::text::num(p[1]),
                    v.id
                ),
            ));
        };
        if vs[m].ty != v.ty {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: \"{}\" and its image \"{}\" have different types",
                    v.id, vs[m].id
                ),
            ));
        }
        vertex.push(m);
    }
    let mut crease = Vec::with_capacity(cs.len());
    let mut facet = vec![usize::MAX; g.facets.len()];
    for c in cs {
        let Some(d) = cs
            .iter()
            .position(|d| d.tail == vertex[c.tail] && d.head == vertex[c.head])
        else {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: crease {} → {} has no image running {} → {}",
                    vs[c.tail].id, vs[c.head].id, vs[vertex[c.tail]].id, vs[vertex[c.head]].id
                ),
            ));
        };
        if cs[d].drive != c.drive {
            return Err(cx.err(
                field,
                format!(
                    "G0 is not symmetric: crease {} → {} and its image have different drives (a symmetric pattern is driven alike on every side)",
                    vs[c.tail].id, vs[c.head].id
                ),
            ));
        }
        let pairs = if e.reflects {
            [(c.left, cs[d].right), (c.right, cs[d].left)]
        } else {
            [(c.left, cs[d].left), (c.right, cs[d].right)]
        };
        for (f, h) in pairs {
            if facet[f] != usize::MAX && facet[f] != h {
                return Err(cx.err(
                    field,
                    format!(
                        "G0's facet labels are not symmetric: facet {} maps to both {} and {}",
                        g.facets[f], g.facets[facet[f]], g.facets[h]
                    ),
                ));
            }
            facet[f] = h;
        }
        crease.push(d);
    }
    Ok((vertex, crease, facet))
}

/// The symmetry must keep what the drives hold in place where it is: the fixed facet, or
/// the two facets a straight driven line folds symmetrically.
fn fixed_part_invariant(
    cx: &Ctx<'_>,
    g: &InitialGraph,
    group: &Group,
    field: &str,
) -> Result<(), TaskError> {
    use super::initial::G0Actuation;
    let held: Vec<usize> = match g.actuation {
        G0Actuation::Fixed { facet } => vec![facet],
        G0Actuation::Split { crease } => vec![g.creases[crease].left, g.creases[crease].right],
    };
    for e in 0..group.order() {
        for &f in &held {
            if !held.contains(&group.facet[e][f]) {
                return Err(cx.err(
                    field,
                    format!(
                        "a symmetry moves facet {} to {}: it must keep the facet the drives hold fixed in place (the central facet), or the pattern's motion could not be symmetric",
                        g.facets[f], g.facets[group.facet[e][f]]
                    ),
                ));
            }
        }
    }
    Ok(())
}
