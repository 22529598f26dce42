//! The local partials `∂node/∂child` of one node, shared by the reverse sweep
//! ([`super::diff`]) and the vertex elimination ([`super::jacobian`]), with the guards that
//! keep them finite (see [`super::diff`]'s docs) and the reciprocals that every quotient by
//! the same `y` shares.

use crate::expr::{ExprGraph, Node, NodeId};

/// `1/y`: the one division by `y` that every partial dividing by `y` shares (hash-consed
/// across the reverse sweep and the elimination). Divisions are the slowest arithmetic in
/// the generated code (on the gripper's design model the gradients had 59 divisions by
/// 30 distinct denominators); a reciprocal and a product round twice, within 1 ulp of the
/// quotient.
pub(crate) fn recip(g: &mut ExprGraph, y: NodeId) -> NodeId {
    let one = g.constant(1.0);
    g.add(Node::Div(one, y))
}

/// `1/r` where `r = x² + y² > 0`, else 0: `atan2(y, x)`'s partials are `(x, −y)` times it.
pub(crate) fn atan2_weight(g: &mut ExprGraph, y: NodeId, x: NodeId) -> NodeId {
    let xx = g.add(Node::Mul(x, x));
    let yy = g.add(Node::Mul(y, y));
    let r = g.add(Node::Add(xx, yy));
    let q = recip(g, r);
    let zero = g.constant(0.0);
    g.add(Node::Select(r, q, zero))
}

/// `a · w` where either factor may be an indicator `select(c, 1, 0)` (or
/// `select(c, 0, 1)`): then the other factor is routed by the select instead of
/// multiplied, which saves the product and keeps a discarded non-finite factor from
/// turning `0 · ∞` into NaN. A constant zero factor gives the constant zero.
pub(crate) fn scale(g: &mut ExprGraph, a: NodeId, w: NodeId) -> NodeId {
    // A constant zero factor (an indicator whose condition folded, or a zero adjoint)
    // contributes nothing: no `0 · x` is built (issue 18), as for a dropped sibling term.
    if g.const_value(a) == Some(0.0) || g.const_value(w) == Some(0.0) {
        return g.constant(0.0);
    }
    for (s, t) in [(a, w), (w, a)] {
        if let Node::Select(c, u, v) = *g.node(s) {
            let (u1, v0) = (g.const_value(u), g.const_value(v));
            if u1 == Some(1.0) && v0 == Some(0.0) {
                return g.add(Node::Select(c, t, v));
            }
            if u1 == Some(0.0) && v0 == Some(1.0) {
                return g.add(Node::Select(c, u, t));
            }
        }
    }
    g.add(Node::Mul(a, w))
}

/// The local partials `(child, ∂node/∂child)` of node `id` for the children that depend
/// on a variable (a child appearing twice gets the sum). They do not depend on the
/// adjoint, so the reverse sweep of [`super::diff`] (which multiplies them by it) and
/// the elimination share them.
pub(crate) fn partials(g: &mut ExprGraph, id: NodeId, dep: &[bool]) -> Vec<(usize, NodeId)> {
    let node = *g.node(id);
    let one = g.constant(1.0);
    let mone = g.constant(-1.0);
    let zero = g.constant(0.0);
    let mut out: Vec<(NodeId, NodeId)> = Vec::with_capacity(3);
    match node {
        Node::Const(_) | Node::Var(_) | Node::Param(_) | Node::Sgn(_) => {}
        Node::Add(x, y) => out.extend([(x, one), (y, one)]),
        Node::Sub(x, y) => out.extend([(x, one), (y, mone)]),
        Node::Neg(x) => out.push((x, mone)),
        Node::Mul(x, y) => out.extend([(x, y), (y, x)]),
        Node::Div(x, y) => {
            // d(x/y) = dx/y − (x/y)·dy/y
            let r = recip(g, y);
            out.push((x, r));
            if dep[y.index()] {
                let q = g.add(Node::Mul(id, r));
                out.push((y, g.add(Node::Neg(q))));
            }
        }
        Node::Sin(x) => out.push((x, g.add(Node::Cos(x)))),
        Node::Cos(x) => {
            let s = g.add(Node::Sin(x));
            out.push((x, g.add(Node::Neg(s))));
        }
        Node::Acos(x) => {
            // −1/√p where p = (1 − c)(1 + c) > 0, else 0.
            let p = one_minus_sq_node(g, x);
            let r = g.add(Node::Sqrt(p));
            let r = recip(g, r);
            let q = g.add(Node::Neg(r));
            out.push((x, g.add(Node::Select(p, q, zero))));
        }
        Node::Sqrt(x) => {
            // 0.5/√x where √x > 0, else 0.
            let half = g.constant(0.5);
            let r = recip(g, id);
            let q = g.add(Node::Mul(half, r));
            out.push((x, g.add(Node::Select(id, q, zero))));
        }
        Node::Atan2(y, x) => {
            let w = atan2_weight(g, y, x);
            if dep[y.index()] {
                out.push((y, g.add(Node::Mul(w, x))));
            }
            if dep[x.index()] {
                let c = g.add(Node::Mul(w, y));
                out.push((x, g.add(Node::Neg(c))));
            }
        }
        Node::Clamp(x) => {
            let omx = g.add(Node::Sub(one, x));
            let opx = g.add(Node::Add(one, x));
            let p = g.add(Node::Mul(omx, opx));
            out.push((x, g.add(Node::Select(p, one, zero))));
        }
        Node::Select(c, u, v) => {
            out.push((u, g.add(Node::Select(c, one, zero))));
            out.push((v, g.add(Node::Select(c, zero, one))));
        }
    }
    let mut merged: Vec<(usize, NodeId)> = Vec::with_capacity(out.len());
    for (c, w) in out {
        if !dep[c.index()] {
            continue;
        }
        match merged.iter_mut().find(|(k, _)| *k == c.index()) {
            Some((_, e)) => *e = g.add(Node::Add(*e, w)),
            None => merged.push((c.index(), w)),
        }
    }
    merged
}

/// `(1 - c)(1 + c)` with `c = clamp(x)`: `1 - x²` computed without cancellation, and
/// never negative. The simplifier builds `sin(acos x)` as the square root of this very node.
pub(crate) fn one_minus_sq_node(g: &mut ExprGraph, x: NodeId) -> NodeId {
    let c = g.add(Node::Clamp(x));
    let one = g.constant(1.0);
    let a = g.add(Node::Sub(one, c));
    let b = g.add(Node::Add(one, c));
    g.add(Node::Mul(a, b))
}
