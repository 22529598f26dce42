//! Vertex and crease names in a task file (`vertex = "tip"`, `crease = "v1-v2"`), checked
//! against G0: the selectors of the vertex extended last and its successors, or G0's ids.

use super::terms::{CreaseRef, VertexRef};
use super::{Ctx, InitialGraph, TaskError};

/// The selectors that name vertices of every generated graph.
const SELECTORS: [&str; 5] = ["tip", "s1", "s2", "s3", "last"];

/// G0's ids, listed for a message.
fn ids(g0: &InitialGraph) -> String {
    let all: Vec<&str> = g0.vertices.iter().map(|v| v.id.as_str()).collect();
    crate::text::excerpt(&all.join(", "), 200)
}

/// The selector `s` names, if it is one.
fn selector(s: &str) -> Option<VertexRef> {
    Some(match s {
        "tip" => VertexRef::Tip,
        "s1" => VertexRef::Successor(0),
        "s2" => VertexRef::Successor(1),
        "s3" => VertexRef::Successor(2),
        "last" => VertexRef::Last,
        _ => return None,
    })
}

/// The vertex `name` names (`"tip"` when absent).
pub(crate) fn vertex(
    cx: &Ctx<'_>,
    field: &str,
    name: Option<&str>,
    g0: &InitialGraph,
) -> Result<VertexRef, TaskError> {
    let Some(name) = name else {
        return Ok(VertexRef::Tip);
    };
    let index = g0.vertices.iter().position(|v| v.id == name);
    match (selector(name), index) {
        (Some(_), Some(_)) => Err(cx.err(
            field,
            format!(
                "\"{name}\" is both a selector and the id of a G0 vertex: rename the G0 vertex (the selectors {} are reserved)",
                SELECTORS.join(", ")
            ),
        )),
        (Some(r), None) => Ok(r),
        (None, Some(index)) => Ok(VertexRef::Initial {
            id: name.to_owned(),
            index,
        }),
        (None, None) => Err(cx.err(
            field,
            format!(
                "unknown vertex \"{}\": allowed {} (the vertex extended last, its successors, the tip) or a G0 vertex id ({})",
                crate::text::excerpt(name, 40),
                SELECTORS.join(", "),
                ids(g0)
            ),
        )),
    }
}

/// The crease `name` names: the crease into a selected vertex (`"tip"`, `"last"`,
/// `"s1"`…`"s3"`) or a crease of G0 by its end ids (`"v1-v2"`, either order).
pub(crate) fn crease(
    cx: &Ctx<'_>,
    field: &str,
    name: &str,
    g0: &InitialGraph,
) -> Result<CreaseRef, TaskError> {
    if let Some(r) = selector(name) {
        return Ok(CreaseRef::Into(r));
    }
    let index = |id: &str| g0.vertices.iter().position(|v| v.id == id);
    // Ids may contain '-': every split into two known ids is a reading.
    let readings: Vec<(usize, usize)> = name
        .match_indices('-')
        .filter_map(|(i, _)| Some((index(&name[..i])?, index(&name[i + 1..])?)))
        .collect();
    let shown = crate::text::excerpt(name, 60);
    let (a, b) = match readings.as_slice() {
        [one] => *one,
        [] => {
            return Err(cx.err(
                field,
                format!(
                    "unknown crease \"{shown}\": allowed tip, last, s1, s2, s3 (the crease into that vertex) or a G0 crease \"a-b\" by its end ids ({})",
                    ids(g0)
                ),
            ));
        }
        _ => {
            return Err(cx.err(
                field,
                format!(
                    "\"{shown}\" splits into G0 ids in more than one way: rename the vertices so their ids do not contain '-'"
                ),
            ));
        }
    };
    let joined = g0
        .creases
        .iter()
        .any(|c| (c.tail, c.head) == (a, b) || (c.tail, c.head) == (b, a));
    if !joined {
        return Err(cx.err(
            field,
            format!(
                "no crease of G0 joins \"{}\" and \"{}\": name a crease of [[initial_graph.creases]]",
                g0.vertices[a].id, g0.vertices[b].id
            ),
        ));
    }
    Ok(CreaseRef::Initial {
        name: name.to_owned(),
        a,
        b,
    })
}
