//! Names a task uses for vertices and creases, resolved on one graph: the task language
//! names vertices independently of the graph the grammar generated (`"tip"`, `"s2"`,
//! `"last"`, a G0 id), and each model turns them into dense indices of its plan.

use super::plan::Plan;
use crate::task::terms::{CreaseRef, VertexRef};

/// Why a name does not resolve on a graph.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct SelectError(pub String);

/// The dense index of the vertex `r` names on `plan` when vertex `tip` grips.
pub fn vertex(plan: &Plan, tip: usize, r: &VertexRef) -> Result<usize, SelectError> {
    let candidates = || {
        plan.candidates.ok_or_else(|| {
            SelectError(format!(
                "{}: the graph has no vertex extended last, so \"{r}\" names nothing",
                plan.sequence
            ))
        })
    };
    match r {
        VertexRef::Tip => Ok(tip),
        VertexRef::Successor(k) => candidates()?
            .get(*k as usize)
            .copied()
            .ok_or_else(|| SelectError(format!("\"{r}\": a vertex has three successors"))),
        VertexRef::Last => {
            let c = crease_into(plan, candidates()?[0])?;
            Ok(plan.creases[c].tail)
        }
        VertexRef::Initial { id, index } => {
            // G0's vertices come first, in the task file's order, and no rule removes one.
            match plan.vertices.get(*index) {
                Some(v) if matches!(v.position, super::plan::Position::Fixed(_)) => Ok(*index),
                _ => Err(SelectError(format!(
                    "{}: G0 vertex \"{id}\" is not vertex {} of the graph",
                    plan.sequence,
                    index + 1
                ))),
            }
        }
    }
}

/// The crease into vertex `v` from its first predecessor (counter-clockwise `p1`; a
/// successor of an extended vertex has exactly one).
pub fn crease_into(plan: &Plan, v: usize) -> Result<usize, SelectError> {
    plan.vertices[v]
        .rays
        .iter()
        .find(|r| !r.outgoing)
        .map(|r| r.crease)
        .ok_or_else(|| {
            SelectError(format!(
                "{}: v{} has no incoming crease",
                plan.sequence, plan.vertices[v].name
            ))
        })
}

/// The dense index of the crease `r` names on `plan` when vertex `tip` grips.
pub fn crease(plan: &Plan, tip: usize, r: &CreaseRef) -> Result<usize, SelectError> {
    match r {
        CreaseRef::Into(v) => crease_into(plan, vertex(plan, tip, v)?),
        CreaseRef::Initial { name, a, b } => plan
            .creases
            .iter()
            .position(|c| (c.tail, c.head) == (*a, *b) || (c.tail, c.head) == (*b, *a))
            .ok_or_else(|| {
                SelectError(format!(
                    "{}: G0 crease \"{name}\" is not in the graph",
                    plan.sequence
                ))
            }),
    }
}
