//! How G0's drives move the paper: creases driven from both ends (the thesis's
//! double-sided arrows, Fig. 32) split at their midpoints, the corners of a driven
//! polygon, and which facet stays fixed.
//!
//! A driven crease between two extendable vertices enters both ends as an incoming crease
//! (a corner of the rigid flasher's central facet has two, Sec. 4.3.1). G0 holds it as two
//! collinear halves leaving a terminal source at its midpoint: each end then has the drive
//! among its predecessors, the directed graph stays acyclic (the closed chain around the
//! central facet is no directed cycle), and every later stage sees an ordinary G0 whose
//! terminal vertices drive their creases. The two halves fold by the same angle, so they
//! are one straight crease; the midpoint is a vertex of degree 2 on it (as an r2′ sink
//! is, and Origami Simulator merges both away on import).

use super::initial::{G0Actuation, InitialCrease, InitialVertex, RawInitial, cf};
use super::{Ctx, TaskError};

/// Which facet stays fixed: the one `initial_graph.fixed` names (it must bound every
/// driven crease), else the one facet every driven crease bounds (a driven polygon's
/// central facet); driven creases on one straight line between the same two facets (the
/// thesis's single crease) fold symmetrically instead. Anything else cannot keep one facet
/// rigid while every drive turns its own neighbour, and is refused.
pub(crate) fn actuation(
    cx: &Ctx<'_>,
    vertices: &[InitialVertex],
    creases: &[InitialCrease],
    facets: &[String],
    raw: &RawInitial,
) -> Result<G0Actuation, TaskError> {
    let driven: Vec<usize> = (0..creases.len())
        .filter(|&i| creases[i].drive.is_some())
        .collect();
    let Some(&first) = driven.first() else {
        return Err(cx.err(
            "initial_graph.creases",
            "no crease is driven: give the crease (or the sides of the central facet) the paper folds by a drive, e.g. drive = \"t\"",
        ));
    };
    let sides = |i: usize| [creases[i].left, creases[i].right];
    let common: Vec<usize> = sides(first)
        .into_iter()
        .filter(|f| driven.iter().all(|&i| sides(i).contains(f)))
        .collect();
    let names = |list: &[usize]| {
        list.iter()
            .map(|&i| {
                let c = &creases[i];
                format!("{} → {}", vertices[c.tail].id, vertices[c.head].id)
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Some(name) = &raw.fixed {
        let Some(f) = facets.iter().position(|x| x == name) else {
            return Err(cx.err(
                "initial_graph.fixed",
                format!(
                    "\"{name}\" is not a facet of G0 (its facets: {})",
                    facets.join(", ")
                ),
            ));
        };
        if let Some(&bad) = driven.iter().find(|&&i| !sides(i).contains(&f)) {
            return Err(cx.err(
                "initial_graph.fixed",
                format!(
                    "facet \"{name}\" does not bound the driven crease {}: the fixed facet must border every driven crease (each drive turns the facet across it from the fixed one)",
                    names(&[bad])
                ),
            ));
        }
        return Ok(G0Actuation::Fixed { facet: f });
    }
    let collinear = driven.iter().all(|&i| {
        let p = vertices[creases[first].tail].xy;
        let q = vertices[creases[first].head].xy;
        let d = [q[0] - p[0], q[1] - p[1]];
        let l = d[0].hypot(d[1]);
        [creases[i].tail, creases[i].head].iter().all(|&v| {
            let x = vertices[v].xy;
            ((x[0] - p[0]) * d[1] - (x[1] - p[1]) * d[0]).abs() <= 1e-9 * l.max(1.0) * l
        })
    });
    let same_drive = driven
        .iter()
        .all(|&i| creases[i].drive == creases[first].drive);
    match common.as_slice() {
        [_, _] if collinear && same_drive => Ok(G0Actuation::Split { crease: first }),
        [_, _] => Err(cx.err(
            "initial_graph.fixed",
            format!(
                "the driven creases {} all lie between facets \"{}\" and \"{}\" but not on one line with one drive: name the facet that stays fixed with initial_graph.fixed",
                names(&driven),
                facets[common[0]],
                facets[common[1]]
            ),
        )),
        [f] => Ok(G0Actuation::Fixed { facet: *f }),
        _ => Err(cx.err(
            format!("{}.drive", cf(first)),
            format!(
                "the driven creases {} do not all bound one facet: with one facet held fixed each drive turns its neighbour, so drives on creases of different facets cannot keep the pattern between them rigid; drive the sides of one central facet (or one straight crease)",
                names(&driven)
            ),
        )),
    }
}
