//! The Jacobian of several outputs, by reverse sweeps or by vertex elimination.
//!
//! [`super::diff`] differentiates one output per reverse sweep: optimal for one scalar
//! with a cone of its own (the objective), but outputs that share their cone (the
//! constraints: rigid margins of one vertex are sums of the same sector angles) repeat the
//! shared part once per output. Vertex elimination (Griewank & Walther, *Evaluating
//! Derivatives*, ch. 9) works on the linearized graph instead: every edge carries its local
//! partial, and eliminating an intermediate vertex `v` replaces each path `p → v → s` by
//! the edge `p → s` with weight `∂p·∂s` (added to an existing one). When only variables
//! and outputs are left, the edge weights are the Jacobian. The order is Markowitz's: the
//! vertex with the fewest `preds × succs` products first.
//!
//! Measured on the gripper task's 159 design models (objective first, then the
//! constraints): a reverse sweep for the objective and elimination for the constraints
//! compile 37% fewer operations than reverse sweeps for all, and the compiled code runs
//! and compiles about a quarter faster; on the robotic arm's (whose objective dominates)
//! 7% fewer. Elimination for the objective too is smaller again on some models and much
//! larger on others, so [`Jacobian::Auto`] builds both and keeps the smaller.
//!
//! The local partials and their guards are the reverse sweep's too (one function is
//! shared), so both have the same NaN behaviour (see [`super::diff`]'s docs).

use super::diff::gradients;
use super::partials::{partials, scale};
use crate::expr::{ExprGraph, Node, NodeId, ShapeError, check_indices};
use std::cmp::Reverse;
use std::collections::{BTreeMap, BTreeSet, BinaryHeap};

/// How the rows of a Jacobian are computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Jacobian {
    /// One reverse sweep per output.
    Reverse,
    /// Vertex elimination in Markowitz order for all outputs.
    Eliminate,
    /// A reverse sweep for the first output and vertex elimination for the others (a
    /// model's objective comes first, its constraints after it), or elimination for all
    /// outputs, whichever has fewer operations (both are built). Measured on 2 Dec:
    /// elimination for all wins on the gripper's model `2, 3, (4, 8), 4, (7, 8)` (1,474
    /// operations against 1,600; value + gradients 590 against 613 ns) and loses on the
    /// robotic arm's `2, 4, 6, (3, 9), (6, 10)` (14,322 against 12,136; 6.4 against 4.6 µs).
    #[default]
    Auto,
}

/// Row `k`: the gradient of `outputs[k]` with respect to variables `0..n_vars`, as nodes
/// of `graph`.
pub fn jacobian(
    graph: &mut ExprGraph,
    outputs: &[NodeId],
    n_vars: usize,
    method: Jacobian,
) -> Result<Vec<Vec<NodeId>>, ShapeError> {
    check_indices(graph, outputs, n_vars, usize::MAX)?;
    Ok(match method {
        Jacobian::Reverse => gradients(graph, outputs, n_vars)?,
        Jacobian::Eliminate => eliminate(graph, outputs, n_vars),
        Jacobian::Auto => {
            // Elimination for all outputs as well, on a copy; the fewer operations win.
            let mut all = graph.clone();
            let elim = eliminate(&mut all, outputs, n_vars);
            let k = outputs.len().min(1);
            let mut rows = gradients(graph, &outputs[..k], n_vars)?;
            rows.extend(eliminate(graph, &outputs[k..], n_vars));
            let ops = |g: &ExprGraph, rows: &[Vec<NodeId>]| {
                let ids: Vec<NodeId> = rows.iter().flatten().copied().collect();
                g.counts(&ids).ops
            };
            if ops(&all, &elim) < ops(graph, &rows) {
                *graph = all;
                elim
            } else {
                rows
            }
        }
    })
}

/// The linearized graph: vertex `i < n` is node `i`, vertex `n + k` is output `k`'s sink.
struct Linear {
    preds: Vec<BTreeMap<usize, NodeId>>,
    succs: Vec<BTreeSet<usize>>,
}

impl Linear {
    fn cost(&self, v: usize) -> usize {
        self.preds[v].len() * self.succs[v].len()
    }
}

/// Rows of the Jacobian of `outputs` by vertex elimination in Markowitz order.
fn eliminate(g: &mut ExprGraph, outputs: &[NodeId], n_vars: usize) -> Vec<Vec<NodeId>> {
    if outputs.is_empty() {
        return Vec::new();
    }
    let zero = g.constant(0.0);
    let one = g.constant(1.0);
    let n = g.len();
    let mark = g.reachable(outputs);
    let mut dep = vec![false; n];
    for i in 0..n {
        if mark[i] {
            let node = &g.nodes()[i];
            dep[i] =
                matches!(node, Node::Var(_)) || node.children().into_iter().any(|c| dep[c.index()]);
        }
    }
    let total = n + outputs.len();
    let mut lin = Linear {
        preds: vec![BTreeMap::new(); total],
        succs: vec![BTreeSet::new(); total],
    };
    let mut ids: Vec<Option<NodeId>> = vec![None; n];
    for (i, node) in g.nodes()[..n].iter().enumerate() {
        if dep[i] {
            ids[i] = g.lookup(node);
        }
    }
    let mut vars = vec![None; n_vars];
    let mut eliminable = Vec::new();
    for i in 0..n {
        if !dep[i] {
            continue;
        }
        let id = ids[i].expect("a node of the graph");
        debug_assert_eq!(id.index(), i);
        match *g.node(id) {
            Node::Var(k) => vars[k as usize] = Some(i),
            _ => {
                eliminable.push(i);
                for (c, w) in partials(g, id, &dep) {
                    lin.preds[i].insert(c, w);
                    lin.succs[c].insert(i);
                }
            }
        }
    }
    for (k, o) in outputs.iter().enumerate() {
        if dep[o.index()] {
            lin.preds[n + k].insert(o.index(), one);
            lin.succs[o.index()].insert(n + k);
        }
    }
    let mut alive = vec![false; total];
    let mut heap: BinaryHeap<Reverse<(usize, usize)>> = BinaryHeap::new();
    for &v in &eliminable {
        alive[v] = true;
        heap.push(Reverse((lin.cost(v), v)));
    }
    while let Some(Reverse((c, v))) = heap.pop() {
        if !alive[v] {
            continue;
        }
        let now = lin.cost(v);
        if now != c {
            heap.push(Reverse((now, v)));
            continue;
        }
        alive[v] = false;
        let ps: Vec<(usize, NodeId)> = std::mem::take(&mut lin.preds[v]).into_iter().collect();
        let ss: Vec<usize> = std::mem::take(&mut lin.succs[v]).into_iter().collect();
        for &(p, _) in &ps {
            lin.succs[p].remove(&v);
        }
        for &s in &ss {
            let w_vs = lin.preds[s].remove(&v).expect("edge v → s");
            for &(p, w_pv) in &ps {
                let m = scale(g, w_pv, w_vs);
                let w = match lin.preds[s].get(&p) {
                    Some(&e) => g.add(Node::Add(e, m)),
                    None => m,
                };
                if w == zero {
                    lin.preds[s].remove(&p);
                    lin.succs[p].remove(&s);
                } else {
                    lin.preds[s].insert(p, w);
                    lin.succs[p].insert(s);
                }
            }
            if alive[s] {
                heap.push(Reverse((lin.cost(s), s)));
            }
        }
        for &(p, _) in &ps {
            if alive[p] {
                heap.push(Reverse((lin.cost(p), p)));
            }
        }
    }
    (0..outputs.len())
        .map(|k| {
            (0..n_vars)
                .map(|i| {
                    vars[i]
                        .and_then(|v| lin.preds[n + k].get(&v).copied())
                        .unwrap_or(zero)
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compile::dual::Dual;
    use crate::expr::{Ctx, Sym, Tape};
    use crate::kinematics::Scalar;

    /// Three outputs sharing a cone, one of them a variable, one constant.
    fn outputs<S: Scalar>(x: S, y: S, z: S) -> Vec<S> {
        let a = (x.clone() * y.clone()).sin() / (y.clone().cos() + 2.0);
        let b = (x.clone() * 0.3).acos() * y.clone().sqrt() + z.atan2(&x);
        let m = a.clone() + b.clone() * b.clone() - x.sgn() * a.clone();
        vec![m.clone() - b.clone(), m * 2.0 + a, x, S::from_f64(3.0), b]
    }

    #[test]
    fn every_method_matches_dual_numbers() {
        for method in [Jacobian::Reverse, Jacobian::Eliminate, Jacobian::Auto] {
            let ctx = Ctx::new();
            let outs = outputs::<Sym>(ctx.var(0), ctx.var(1), ctx.var(2));
            let ids: Vec<NodeId> = outs.iter().map(|s| ctx.node_id(s)).collect();
            let mut g = ctx.to_graph();
            let rows = jacobian(&mut g, &ids, 3, method).unwrap();
            let flat: Vec<NodeId> = rows.iter().flatten().copied().collect();
            let tape = Tape::new(&g, &flat, 3, 0).unwrap();
            for &(x, y, z) in &[(0.3, 0.9, -1.0), (-1.2, 2.5, 0.4), (0.7, 1e-3, 2.0)] {
                let d = outputs(Dual::var(x, 0, 3), Dual::var(y, 1, 3), Dual::var(z, 2, 3));
                let mut r = vec![0.0; flat.len()];
                tape.eval(&[x, y, z], &[], &mut r).unwrap();
                for (k, out) in d.iter().enumerate() {
                    let want = out.grad(3);
                    for i in 0..3 {
                        let got = r[3 * k + i];
                        let e = (got - want[i]).abs() / want[i].abs().max(1.0);
                        assert!(
                            e < 1e-12,
                            "{method:?} ({x}, {y}, {z}) d{k}/d{i}: {got} vs {}",
                            want[i]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn elimination_shares_what_sweeps_repeat() {
        // n outputs s_k = u + k·v over one deep shared cone u(x, y), v(x, y): one sweep per
        // output repeats the cone, elimination folds it once.
        let ctx = Ctx::new();
        let (x, y) = (ctx.var(0), ctx.var(1));
        let mut u = x.clone();
        for _ in 0..20 {
            u = (u.clone() * y.clone()).sin() + u;
        }
        let v = (u.clone() * x.clone()).cos();
        let outs: Vec<Sym> = (0..12)
            .map(|k| u.clone() + v.clone() * (k as f64 + 1.0))
            .collect();
        let ids: Vec<NodeId> = outs.iter().map(|s| ctx.node_id(s)).collect();
        let g0 = ctx.to_graph();
        let count = |method| {
            let mut g = g0.clone();
            let rows = jacobian(&mut g, &ids, 2, method).unwrap();
            let all: Vec<NodeId> = rows.into_iter().flatten().collect();
            g.counts(&all).ops
        };
        let (rev, elim) = (count(Jacobian::Reverse), count(Jacobian::Eliminate));
        assert!(2 * elim < rev, "elimination {elim} vs reverse sweeps {rev}");
    }
}
