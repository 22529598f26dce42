//! Large and deep DAGs: nothing recurses (no stack overflow), printed output stays linear
//! in the DAG size (a tree expansion would be exponential), and hash-consing shares.

use foldsynth::compile::simplify::{Limits, simplify};
use foldsynth::compile::{CompiledFn, gradient};
use foldsynth::expr::{Ctx, Format, Names, Sym, Tape, print::print};
use foldsynth::kinematics::Scalar;

/// x_{k+1} = sin(x_k)·x_k + t: every x_k is used three times, the tree is exponential.
fn chain(depth: usize) -> (Ctx, Sym) {
    let ctx = Ctx::new();
    let t = ctx.param(0);
    let mut x = ctx.var(0);
    for _ in 0..depth {
        x = x.sin() * x.clone() + t.clone();
    }
    (ctx, x)
}

fn f64_chain(depth: usize, x0: f64, t: f64) -> f64 {
    let mut x = x0;
    for _ in 0..depth {
        x = x.sin() * x + t;
    }
    x
}

#[test]
fn deep_chain_interpreter_diff_and_printers() {
    let depth = 100_000;
    let (ctx, x) = chain(depth);
    let id = ctx.node_id(&x);
    let mut g = ctx.to_graph();
    // Equal subexpressions are one node: 3 new nodes per level, plus leaves.
    assert_eq!(g.counts(&[id]).nodes, 3 * depth + 2);
    let tape = Tape::new(&g, &[id], 1, 1).unwrap();
    let mut out = [0.0];
    tape.eval(&[0.3], &[0.1], &mut out).unwrap();
    assert_eq!(out[0], f64_chain(depth, 0.3, 0.1));

    let grad = gradient(&mut g, id, 1).unwrap();
    let gt = Tape::new(&g, &grad, 1, 1).unwrap();
    let mut d = [0.0];
    gt.eval(&[0.3], &[0.1], &mut d).unwrap();
    assert!(d[0].is_finite());

    let names = Names {
        vars: vec!["x".into()],
        params: vec!["t".into()],
    };
    for fmt in [
        Format::Plain,
        Format::Python,
        Format::Mathematica,
        Format::Latex,
        Format::Dot,
    ] {
        let text = print(&g, &[("y".into(), id)], &names, fmt);
        assert!(
            text.len() < 120 * g.counts(&[id]).nodes,
            "{fmt:?}: {} bytes for {} nodes",
            text.len(),
            g.counts(&[id]).nodes
        );
    }
}

#[test]
fn deep_chain_jit_and_simplify() {
    let depth = 3_000;
    let (ctx, x) = chain(depth);
    let id = ctx.node_id(&x);
    let g = ctx.to_graph();
    let jit = CompiledFn::new(&g, &[id], 1, 1).unwrap();
    let mut out = [0.0];
    jit.call(&[0.3], &[0.1], &mut out).unwrap();
    assert_eq!(out[0], f64_chain(depth, 0.3, 0.1));

    let (s, outs, rep) = simplify(&g, &[id], &Limits::default());
    assert!(rep.cost_after <= rep.cost_before);
    let t = Tape::new(&s, &outs, 1, 1).unwrap();
    t.eval(&[0.3], &[0.1], &mut out).unwrap();
    assert_eq!(out[0], f64_chain(depth, 0.3, 0.1));
}
