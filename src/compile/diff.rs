//! Reverse-mode symbolic differentiation on the DAG.
//!
//! The adjoint of every node is accumulated in reverse topological order (decreasing node
//! id) as new nodes of the same graph, so the gradient shares every forward node (the
//! value+gradient cost is a small multiple of the value's). Only nodes that depend on a
//! variable get adjoints.
//!
//! Derivatives never produce NaN or infinities where the function is finite:
//! - `sgn`: 0;
//! - clamped `acos(x)`: `-1/sqrt(p)` with `p = (1 - c)(1 + c)`, `c = clamp(x)`, selected
//!   only where `p > 0` (that is `|x| < 1`), 0 elsewhere. `sqrt(p)` is the very node the
//!   simplifier makes of `sin(acos x)`, so the two share;
//! - `clamp(x)`: 1 where `(1 - x)(1 + x) > 0`, else 0;
//! - `sqrt(x) = s`: `0.5/s` where `s > 0`, else 0;
//! - `atan2(y, x)`: `(x, -y)/r`, `r = x² + y²`, where `r > 0`, else 0;
//! - `select(c, a, b)`: routes the adjoint to the selected branch (c is not differentiated).
//!
//! The guards are [`Node::Select`] nodes: both branches are evaluated and the discarded
//! one may be infinite, which is harmless (no traps, no NaN reaches the result).
//!
//! Limitation: a `select` in the *forward* graph sends a zero adjoint into the branch it
//! discards; if a value in that branch is NaN or infinite, `0 · NaN` makes the gradient
//! NaN although the value is finite (forward mode would not). The kinematics never
//! discards a non-finite branch (its only forward selects are `max(0, x)`).

use crate::expr::{ExprGraph, Node, NodeId, ShapeError, check_indices};

/// The gradient of `output` with respect to variables `0..n_vars`, as nodes of `graph`.
pub fn gradient(
    graph: &mut ExprGraph,
    output: NodeId,
    n_vars: usize,
) -> Result<Vec<NodeId>, ShapeError> {
    check_indices(graph, &[output], n_vars, usize::MAX)?;
    Ok(sweep(graph, output, n_vars))
}

/// The gradients of several outputs (one reverse sweep each; equal adjoint expressions
/// are shared through hash-consing).
pub fn gradients(
    graph: &mut ExprGraph,
    outputs: &[NodeId],
    n_vars: usize,
) -> Result<Vec<Vec<NodeId>>, ShapeError> {
    check_indices(graph, outputs, n_vars, usize::MAX)?;
    Ok(outputs.iter().map(|&o| sweep(graph, o, n_vars)).collect())
}

struct Adjoints<'a> {
    g: &'a mut ExprGraph,
    adj: Vec<Option<NodeId>>,
    dep: &'a [bool],
}

impl Adjoints<'_> {
    /// adj[child] += contribution (or -= with `neg`).
    fn acc(&mut self, child: NodeId, contrib: NodeId, neg: bool) {
        if !self.dep[child.index()] {
            return;
        }
        let new = match (self.adj[child.index()], neg) {
            (None, false) => contrib,
            (None, true) => self.g.add(Node::Neg(contrib)),
            (Some(e), false) => self.g.add(Node::Add(e, contrib)),
            (Some(e), true) => self.g.add(Node::Sub(e, contrib)),
        };
        self.adj[child.index()] = Some(new);
    }

    fn op(&mut self, node: Node) -> NodeId {
        self.g.add(node)
    }

    fn constant(&mut self, c: f64) -> NodeId {
        self.g.constant(c)
    }
}

fn sweep(g: &mut ExprGraph, output: NodeId, n_vars: usize) -> Vec<NodeId> {
    let n = output.index() + 1;
    let mark = g.reachable(&[output]);
    // Which nodes depend on a variable (forward pass; children precede parents).
    let mut dep = vec![false; n];
    for i in 0..n {
        if mark[i] {
            let node = g.node(NodeId(i as u32));
            dep[i] =
                matches!(node, Node::Var(_)) || node.children().into_iter().any(|c| dep[c.index()]);
        }
    }
    let mut grad: Vec<Option<NodeId>> = vec![None; n_vars];
    if dep[output.index()] {
        let one = g.constant(1.0);
        let mut s = Adjoints {
            g,
            adj: vec![None; n],
            dep: &dep,
        };
        s.adj[output.index()] = Some(one);
        for i in (0..n).rev() {
            if !dep[i] {
                continue;
            }
            let Some(a) = s.adj[i] else { continue };
            let id = NodeId(i as u32);
            match *s.g.node(id) {
                Node::Var(k) => grad[k as usize] = Some(a),
                Node::Const(_) | Node::Param(_) => {}
                Node::Add(x, y) => {
                    s.acc(x, a, false);
                    s.acc(y, a, false);
                }
                Node::Sub(x, y) => {
                    s.acc(x, a, false);
                    s.acc(y, a, true);
                }
                Node::Mul(x, y) => {
                    if dep[x.index()] {
                        let c = s.op(Node::Mul(a, y));
                        s.acc(x, c, false);
                    }
                    if dep[y.index()] {
                        let c = s.op(Node::Mul(a, x));
                        s.acc(y, c, false);
                    }
                }
                Node::Div(x, y) => {
                    // d(x/y) = dx/y - (x/y) dy/y: share r = a/y.
                    let r = s.op(Node::Div(a, y));
                    s.acc(x, r, false);
                    if dep[y.index()] {
                        let c = s.op(Node::Mul(r, id));
                        s.acc(y, c, true);
                    }
                }
                Node::Neg(x) => s.acc(x, a, true),
                Node::Sin(x) => {
                    let c = s.op(Node::Cos(x));
                    let c = s.op(Node::Mul(a, c));
                    s.acc(x, c, false);
                }
                Node::Cos(x) => {
                    let sn = s.op(Node::Sin(x));
                    let c = s.op(Node::Mul(a, sn));
                    s.acc(x, c, true);
                }
                Node::Acos(x) => {
                    let p = one_minus_sq(&mut s, x);
                    let r = s.op(Node::Sqrt(p));
                    let q = s.op(Node::Div(a, r));
                    let zero = s.constant(0.0);
                    let c = s.op(Node::Select(p, q, zero));
                    s.acc(x, c, true);
                }
                Node::Sqrt(x) => {
                    let half = s.constant(0.5);
                    let h = s.op(Node::Mul(half, a));
                    let q = s.op(Node::Div(h, id));
                    let zero = s.constant(0.0);
                    let c = s.op(Node::Select(id, q, zero));
                    s.acc(x, c, false);
                }
                Node::Atan2(y, x) => {
                    let xx = s.op(Node::Mul(x, x));
                    let yy = s.op(Node::Mul(y, y));
                    let r = s.op(Node::Add(xx, yy));
                    let q = s.op(Node::Div(a, r));
                    let zero = s.constant(0.0);
                    let w = s.op(Node::Select(r, q, zero));
                    if dep[y.index()] {
                        let c = s.op(Node::Mul(w, x));
                        s.acc(y, c, false);
                    }
                    if dep[x.index()] {
                        let c = s.op(Node::Mul(w, y));
                        s.acc(x, c, true);
                    }
                }
                Node::Sgn(_) => {}
                Node::Clamp(x) => {
                    let one = s.constant(1.0);
                    let omx = s.op(Node::Sub(one, x));
                    let opx = s.op(Node::Add(one, x));
                    let p = s.op(Node::Mul(omx, opx));
                    let zero = s.constant(0.0);
                    let c = s.op(Node::Select(p, a, zero));
                    s.acc(x, c, false);
                }
                Node::Select(c, u, v) => {
                    let zero = s.constant(0.0);
                    if dep[u.index()] {
                        let d = s.op(Node::Select(c, a, zero));
                        s.acc(u, d, false);
                    }
                    if dep[v.index()] {
                        let d = s.op(Node::Select(c, zero, a));
                        s.acc(v, d, false);
                    }
                }
            }
        }
    }
    let zero = g.constant(0.0);
    grad.into_iter().map(|d| d.unwrap_or(zero)).collect()
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

fn one_minus_sq(s: &mut Adjoints<'_>, x: NodeId) -> NodeId {
    one_minus_sq_node(s.g, x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compile::dual::Dual;
    use crate::expr::{Ctx, Sym, Tape};
    use crate::kinematics::Scalar;

    fn f<S: Scalar>(x: S, y: S) -> S {
        let a = (x.clone() * y.clone()).sin() / (y.clone().cos() + 2.0);
        let b = (x.clone() * 0.3).acos() * y.sqrt();
        let c = y.atan2(&x) - x.sgn() * a.clone();
        a + b * c
    }

    #[test]
    fn matches_dual_numbers() {
        let ctx = Ctx::new();
        let out = f(ctx.var(0), ctx.var(1));
        let id = ctx.node_id(&out);
        let mut g = ctx.to_graph();
        let grad = gradient(&mut g, id, 2).unwrap();
        let tape = Tape::new(&g, &grad, 2, 0).unwrap();
        for &(x, y) in &[(0.3, 0.9), (-1.2, 2.5), (5.0, 0.1), (0.7, 1e-3)] {
            let d = f(Dual::var(x, 0, 2), Dual::var(y, 1, 2));
            let mut r = [0.0; 2];
            tape.eval(&[x, y], &[], &mut r).unwrap();
            for (k, (got, want)) in r.iter().zip(&d.g).enumerate() {
                let e = (got - want).abs() / want.abs().max(1.0);
                assert!(e < 1e-12, "({x}, {y}) d{k}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn guarded_derivatives_are_zero_not_nan() {
        let ctx = Ctx::new();
        let x = ctx.var(0);
        let outs = [
            x.acos(),
            x.sqrt(),
            x.sgn(),
            x.atan2(&Sym::from_f64(0.0)),
            x.clamp_unit(),
        ];
        let ids: Vec<NodeId> = outs.iter().map(|s| ctx.node_id(s)).collect();
        let mut g = ctx.to_graph();
        let grads: Vec<NodeId> = gradients(&mut g, &ids, 1)
            .unwrap()
            .into_iter()
            .map(|v| v[0])
            .collect();
        let tape = Tape::new(&g, &grads, 1, 0).unwrap();
        let mut r = [0.0; 5];
        tape.eval(&[1.5], &[], &mut r).unwrap();
        assert_eq!(r[0], 0.0, "acos outside");
        assert_eq!(r[2], 0.0, "sgn");
        assert_eq!(r[4], 0.0, "clamp outside");
        tape.eval(&[1.0], &[], &mut r).unwrap();
        assert_eq!(r[0], 0.0, "acos at the boundary");
        tape.eval(&[0.0], &[], &mut r).unwrap();
        assert_eq!(r[1], 0.0, "sqrt at 0");
        assert_eq!(r[3], 0.0, "atan2 at the origin");
        assert_eq!(r[2], 0.0);
        tape.eval(&[-3.0], &[], &mut r).unwrap();
        assert!(r.iter().all(|v| !v.is_nan()), "{r:?}");
    }
}
