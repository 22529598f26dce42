//! Values and the pullback of their weighted sum as two functions that share a tape.
//!
//! The robustness block evaluates a model's values `v(x)` at a state, forms weights `w`
//! from them (which constraints are active and how much), and then needs `∇ₓ Σ wₖ vₖ`.
//! Compiled as one reverse sweep of `Σ wₖ vₖ` with the weights as parameters, that
//! gradient recomputes the whole forward sweep the values function just ran. Here the
//! sweep is split where the weights enter: [`Taped::forward`] computes the values and
//! writes every forward quantity the reverse sweep reads (the *tape*) after them;
//! [`Taped::reverse`] takes the weights and the tape as parameters and computes only what
//! depends on the weights.

use super::codegen::{CompileError, Math, OptLevel};
use super::diff::gradient;
use super::jit::CompiledFn;
use super::simplify;
use crate::expr::{ExprGraph, Node, NodeId, check_indices};
use std::collections::HashMap;

/// The two functions.
///
/// - `forward(x, p)` writes `n_values` values, then `n_tape` tape entries;
/// - `reverse(x, [p, w, tape])` writes the `n_vars` entries of `∇ₓ Σ wₖ vₖ`.
#[derive(Debug)]
pub struct Taped {
    /// Values, then the tape.
    pub forward: CompiledFn,
    /// The gradient of the weighted sum.
    pub reverse: CompiledFn,
    /// Number of values (and of weights).
    pub n_values: usize,
    /// Number of tape entries.
    pub n_tape: usize,
    /// Operations of the values alone (after simplification), of the forward function
    /// and of the reverse function.
    pub ops: [usize; 3],
}

/// Compile `values` over `n_vars` variables and `n_params` parameters, and the gradient of
/// their sum weighted by parameters `n_params..n_params + values.len()`, as a [`Taped`].
pub fn taped(
    graph: &ExprGraph,
    values: &[NodeId],
    n_vars: usize,
    n_params: usize,
    limits: Option<&simplify::Limits>,
) -> Result<Taped, CompileError> {
    check_indices(graph, values, n_vars, n_params)?;
    let (mut g, outs) = match limits {
        Some(l) => {
            let (g, o, _) = simplify::simplify(graph, values, l);
            (g, o)
        }
        None => graph.extract(values),
    };
    let value_ops = g.counts(&outs).ops;
    let mut s = g.constant(0.0);
    for (k, &v) in outs.iter().enumerate() {
        let w = g.param(n_params + k);
        let term = g.add(Node::Mul(w, v));
        s = g.add(Node::Add(s, term));
    }
    let grad = gradient(&mut g, s, n_vars)?;
    let (reverse_graph, reverse_outs, tape) = split(&g, &grad, n_params, values.len());
    let mut fwd_outs = outs.clone();
    fwd_outs.extend(&tape);
    // The values keep the interpreter's bits; the reverse sweep is all gradient (fused
    // where the CPU has FMA, as [`super::Options::fma`]).
    let forward = CompiledFn::with_fma_from(
        &g,
        &fwd_outs,
        n_vars,
        n_params,
        OptLevel::Auto,
        Math::Batch,
        usize::MAX,
    )?;
    let n_rev_params = n_params + values.len() + tape.len();
    let reverse = CompiledFn::with_fma_from(
        &reverse_graph,
        &reverse_outs,
        n_vars,
        n_rev_params,
        OptLevel::Auto,
        Math::Batch,
        0,
    )?;
    Ok(Taped {
        forward,
        reverse,
        n_values: values.len(),
        n_tape: tape.len(),
        ops: [
            value_ops,
            g.counts(&fwd_outs).ops,
            reverse_graph.counts(&reverse_outs).ops,
        ],
    })
}

/// Split `outputs` of `g` where parameters `≥ first_weight` enter: the graph of the nodes
/// that depend on them (every other operand read from a tape parameter after the
/// weights, of which there are `n_weights`), its outputs, and the tape (nodes of `g`, in order).
fn split(
    g: &ExprGraph,
    outputs: &[NodeId],
    first_weight: usize,
    n_weights: usize,
) -> (ExprGraph, Vec<NodeId>, Vec<NodeId>) {
    let nodes = g.nodes();
    // Children precede parents, so one pass in id order settles every node.
    let mut dep = vec![false; nodes.len()];
    for (i, node) in nodes.iter().enumerate() {
        dep[i] = match *node {
            Node::Param(p) => p as usize >= first_weight,
            _ => node.children().into_iter().any(|c| dep[c.index()]),
        };
    }
    let reach = g.reachable(outputs);
    let tape_base = first_weight + n_weights;
    let mut r = ExprGraph::new();
    let mut map: Vec<Option<NodeId>> = vec![None; nodes.len()];
    let mut tape: Vec<NodeId> = Vec::new();
    let mut slot: HashMap<usize, usize> = HashMap::new();
    // A node the reverse graph reads but does not compute: a leaf as itself, any other
    // forward value from the tape.
    let mut operand = |r: &mut ExprGraph, c: NodeId, map: &[Option<NodeId>]| -> NodeId {
        if let Some(m) = map[c.index()] {
            return m;
        }
        match nodes[c.index()] {
            Node::Const(v) => r.constant(v),
            Node::Var(i) => r.var(i as usize),
            Node::Param(p) => r.param(p as usize),
            _ => {
                let k = *slot.entry(c.index()).or_insert_with(|| {
                    tape.push(c);
                    tape.len() - 1
                });
                r.param(tape_base + k)
            }
        }
    };
    for i in 0..nodes.len() {
        if !(reach[i] && dep[i]) {
            continue;
        }
        let node = nodes[i];
        let id = match node {
            Node::Param(p) => r.param(p as usize),
            _ => {
                let new = node.map_children(|c| operand(&mut r, c, &map));
                r.add(new)
            }
        };
        map[i] = Some(id);
    }
    let outs = outputs.iter().map(|&o| operand(&mut r, o, &map)).collect();
    (r, outs, tape)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compile::{Options, compile};
    use crate::expr::Ctx;
    use crate::expr::Sym;
    use crate::kinematics::Scalar;

    /// Values of every kind the robustness block has: transcendental, a quotient, a bare
    /// variable, a constant and one that ignores the variables.
    fn model() -> (ExprGraph, Vec<NodeId>) {
        let ctx = Ctx::new();
        let (x, y, t) = (ctx.var(0), ctx.var(1), ctx.param(0));
        let values = [
            (x.clone() * t.clone()).sin() + y.clone() * y.clone(),
            y.clone().atan2(&x) * (x.clone() * x.clone() + Sym::from_f64(1.0)).sqrt(),
            x.clone(),
            Sym::from_f64(2.0),
            t.clone().cos(),
            (x.clone() * y.clone()).cos() / (t + Sym::from_f64(3.0)),
        ];
        let ids = values.iter().map(|v| ctx.node_id(v)).collect();
        (ctx.to_graph(), ids)
    }

    #[test]
    fn the_split_equals_one_reverse_sweep_of_the_weighted_sum() {
        let (graph, values) = model();
        let n = values.len();
        let taped = taped(&graph, &values, 2, 1, Some(&Default::default())).unwrap();
        assert_eq!(taped.n_values, n);
        // The reference: the values alone, and Σ wₖ vₖ with its gradient, as `compile`
        // builds them.
        let plain = compile(
            &graph,
            &values,
            2,
            1,
            &Options {
                gradients: false,
                ..Options::default()
            },
        )
        .unwrap();
        let mut g = graph.clone();
        let mut s = g.constant(0.0);
        for (k, &v) in values.iter().enumerate() {
            let w = g.param(1 + k);
            let term = g.add(Node::Mul(w, v));
            s = g.add(Node::Add(s, term));
        }
        let summed = compile(&g, &[s], 2, 1 + n, &Options::default()).unwrap();
        for (x, y, t) in [(0.3, -1.2, 0.7), (-2.0, 0.5, 1.9), (1e-3, 4.0, -0.4)] {
            let w: Vec<f64> = (0..n).map(|k| (k as f64 * 0.9 - 1.3).sin()).collect();
            let mut out = vec![0.0; n + taped.n_tape];
            taped.forward.call(&[x, y], &[t], &mut out).unwrap();
            let mut reference = vec![0.0; n];
            plain.function.call(&[x, y], &[t], &mut reference).unwrap();
            // The same values, bit for bit.
            assert_eq!(
                out[..n].iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                reference.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
            );
            let mut params = vec![t];
            params.extend(&w);
            params.extend(&out[n..]);
            let mut grad = [0.0; 2];
            taped.reverse.call(&[x, y], &params, &mut grad).unwrap();
            let mut full = vec![0.0; summed.layout.len()];
            summed
                .function
                .call(&[x, y], &params[..1 + n], &mut full)
                .unwrap();
            for (i, gi) in grad.iter().enumerate() {
                let r = full[summed.layout.gradient(0).start + i];
                assert!(
                    (gi - r).abs() <= 1e-13 * (1.0 + r.abs()),
                    "∂/∂x{i} at ({x}, {y}, {t}): {gi} against {r}"
                );
            }
        }
        // The reverse function computes only what the weights reach: fewer operations
        // than the whole sweep.
        assert!(taped.ops[2] < summed.report.with_gradients.ops);
    }
}
