//! Reverse-mode symbolic differentiation on the DAG.
//!
//! The adjoint of every node is accumulated in reverse topological order (decreasing node
//! id) as new nodes of the same graph, so the gradient shares every forward node (the
//! value+gradient cost is a small multiple of the value's). Only nodes that depend on a
//! variable get adjoints. The local partials are those of the vertex elimination
//! ([`mod@super::jacobian`]) too, from one shared file (independent of the adjoint, and
//! every quotient by `y` in them is a product with the one reciprocal `1/y`).
//!
//! Derivatives never produce NaN or infinities where the function is finite:
//! - `sgn`: 0;
//! - clamped `acos(x)`: `-1/sqrt(p)` with `p = (1 - c)(1 + c)`, `c = clamp(x)`, selected
//!   only where `p > 0` (that is `|x| < 1`), 0 elsewhere. `sqrt(p)` is the very node the
//!   simplifier makes of `sin(acos x)`, so the two share;
//! - `clamp(x)`: 1 where `(1 - x)(1 + x) > 0`, else 0;
//! - `sqrt(x) = s`: `0.5·(1/s)` where `s > 0`, else 0;
//! - `atan2(y, x)`: `(x, -y)·(1/r)`, `r = x² + y²`, where `r > 0`, else 0;
//! - `select(c, a, b)`: routes the adjoint to the selected branch (c is not differentiated).
//!
//! The guards are [`Node::Select`] nodes: both branches are evaluated and the discarded
//! one may be infinite, which is harmless (no traps, no NaN reaches the result).
//!
//! Limitation: a `select` in the *forward* graph sends a zero adjoint into the branch it
//! discards; if a value in that branch is NaN or infinite, `0 · NaN` makes the gradient
//! NaN although the value is finite (forward mode would not). The kinematics never
//! discards a non-finite branch (its only forward selects are `max(0, x)`).

use super::partials::{atan2_weight, partials, recip, scale};
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
    /// adj[child] += contribution.
    fn acc(&mut self, child: NodeId, contrib: NodeId) {
        // A constant zero contribution adds nothing (and would leave `a + 0` or a zero
        // adjoint scaling the child's partials: issue 18's `0 · x`).
        if !self.dep[child.index()] || self.g.const_value(contrib) == Some(0.0) {
            return;
        }
        let new = match self.adj[child.index()] {
            None => contrib,
            Some(e) => self.g.add(Node::Add(e, contrib)),
        };
        self.adj[child.index()] = Some(new);
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
            // A constant zero adjoint passes nothing on (no `0 · x`, issue 18).
            if s.g.const_value(a) == Some(0.0) {
                continue;
            }
            let id = NodeId(i as u32);
            if let Node::Var(k) = *s.g.node(id) {
                grad[k as usize] = Some(a);
                continue;
            }
            match *s.g.node(id) {
                // Two partials with a common factor: scale it by the adjoint once.
                Node::Div(x, y) => {
                    // d(x/y) = a/y·dx − (a/y)·(x/y)·dy
                    let r = recip(s.g, y);
                    let r = scale(s.g, a, r);
                    s.acc(x, r);
                    if dep[y.index()] {
                        let c = s.g.add(Node::Mul(r, id));
                        let c = s.g.add(Node::Neg(c));
                        s.acc(y, c);
                    }
                }
                Node::Atan2(y, x) => {
                    let w = atan2_weight(s.g, y, x);
                    let w = scale(s.g, a, w);
                    if dep[y.index()] {
                        let c = s.g.add(Node::Mul(w, x));
                        s.acc(y, c);
                    }
                    if dep[x.index()] {
                        let c = s.g.add(Node::Mul(w, y));
                        let c = s.g.add(Node::Neg(c));
                        s.acc(x, c);
                    }
                }
                // adj[child] += adj[node] · ∂node/∂child, with the elimination's partials
                // (so both share them and their reciprocals) and ±1 and indicator factors
                // folded.
                _ => {
                    for (c, w) in partials(s.g, id, &dep) {
                        let contrib = scale(s.g, a, w);
                        s.acc(NodeId(c as u32), contrib);
                    }
                }
            }
        }
    }
    let zero = g.constant(0.0);
    grad.into_iter().map(|d| d.unwrap_or(zero)).collect()
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
