//! Each family of rewrites fires where it should and never changes a value: checked at
//! random points, including arguments outside `[-1, 1]` for the acos identities (the
//! clamp must survive) and non-finite inputs where a rule needs finiteness.

use foldsynth::compile::simplify::{Limits, simplify};
use foldsynth::compile::{Options, compile};
use foldsynth::expr::{Ctx, ExprGraph, Node, NodeId, Sym, Tape};
use foldsynth::kinematics::Scalar;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn close(a: f64, b: f64) -> bool {
    a == b || (a.is_nan() && b.is_nan()) || (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0)
}

/// Simplify `f(x, y)`; check values at random points (and the given extra points) and
/// return the operation counts before and after.
fn check(f: impl Fn(&Sym, &Sym) -> Sym, extra: &[(f64, f64)]) -> (usize, usize, ExprGraph, NodeId) {
    let ctx = Ctx::new();
    let out = f(&ctx.var(0), &ctx.var(1));
    let id = ctx.node_id(&out);
    let g = ctx.to_graph();
    let (s, outs, rep) = simplify(&g, &[id], &Limits::default());
    let t0 = Tape::new(&g, &[id], 2, 0).unwrap();
    let t1 = Tape::new(&s, &outs, 2, 0).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut pts: Vec<(f64, f64)> = (0..500)
        .map(|_| (rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0)))
        .collect();
    pts.extend_from_slice(extra);
    for (x, y) in pts {
        let (mut a, mut b) = ([0.0], [0.0]);
        t0.eval(&[x, y], &[], &mut a).unwrap();
        t1.eval(&[x, y], &[], &mut b).unwrap();
        assert!(close(a[0], b[0]), "at ({x}, {y}): {} became {}", a[0], b[0]);
    }
    (rep.ops_before, rep.ops_after, s, outs[0])
}

#[test]
fn cos_and_sin_of_acos_keep_the_clamp() {
    // More operations, but three calls fewer: cheaper.
    let (_, _, s, o) = check(
        |x, y| {
            let u = (x.clone() * y.clone()).acos();
            u.cos() * x.clone() + u.sin() * y.clone()
        },
        &[(2.0, 1.5), (-3.0, 0.9), (1.0, 1.0), (1.0, -1.0)],
    );
    assert_eq!(s.counts(&[o]).calls, 0, "no acos, cos or sin left");
}

#[test]
fn max0_becomes_a_select() {
    let (b, a, s, o) = check(|x, y| (x.sin() * y.clone()).max0().sqrt(), &[(0.0, 0.0)]);
    assert!(a < b, "{b} -> {a}");
    let has_select = s
        .nodes()
        .iter()
        .take(o.index() + 1)
        .any(|n| matches!(n, Node::Select(..)));
    assert!(has_select);
}

#[test]
fn max0_of_a_possibly_infinite_value_is_kept() {
    // 1/x may be infinite: (inf + inf·1)/2 = inf but select would also give inf, and
    // (-inf + -inf·-1) = NaN where select gives 0; the rule needs finiteness.
    let (_, _, s, o) = check(
        |x, _| (Sym::from_f64(1.0) / x.clone()).max0(),
        &[(0.0, 1.0)],
    );
    let g = s.eval(&[o], &[-0.0, 1.0], &[]);
    let ctx = Ctx::new();
    let r = (Sym::from_f64(1.0) / ctx.var(0)).max0();
    let id = ctx.node_id(&r);
    let want = ctx.graph().eval(&[id], &[-0.0, 1.0], &[]);
    assert!(close(g[0], want[0]), "{} vs {}", g[0], want[0]);
}

#[test]
fn pythagoras_and_cancellation() {
    let (b, a, _, _) = check(
        |x, y| {
            let s = (x.clone() + y.clone()).sin();
            let c = (x.clone() + y.clone()).cos();
            (s.clone() * s + c.clone() * c) * x.clone() + (y.clone() - y.clone())
        },
        &[],
    );
    assert!(a < b, "{b} -> {a}");
}

#[test]
fn factoring_shrinks() {
    let (b, a, _, _) = check(
        |x, y| {
            let k = x.cos();
            k.clone() * y.sin() + k * y.cos()
        },
        &[],
    );
    assert!(a < b, "{b} -> {a}");
}

#[test]
fn signs_and_negations() {
    let (b, a, _, _) = check(
        |x, y| {
            let n = -(x.clone() - y.clone());
            n.sgn().sgn() * (-x.clone()).sin() + (-y.clone()).cos()
        },
        &[(1.0, 1.0), (0.0, 0.0)],
    );
    assert!(a <= b, "{b} -> {a}");
}

#[test]
fn simplification_never_grows_the_cost() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for _ in 0..50 {
        let ctx = Ctx::new();
        let mut v = vec![ctx.var(0), ctx.var(1)];
        for _ in 0..30 {
            let a = v[rng.random_range(0..v.len())].clone();
            let b = v[rng.random_range(0..v.len())].clone();
            let x = match rng.random_range(0..6) {
                0 => a + b,
                1 => a - b,
                2 => a * b,
                3 => a.sin(),
                4 => a.cos(),
                _ => (a * 0.3).acos(),
            };
            v.push(x);
        }
        let id = ctx.node_id(v.last().unwrap());
        let g = ctx.to_graph();
        let (_, _, rep) = simplify(&g, &[id], &Limits::default());
        assert!(rep.cost_after <= rep.cost_before, "{rep:?}");
    }
}

#[test]
fn compile_without_simplification_is_exactly_the_interpreter() {
    let ctx = Ctx::new();
    let x = ctx.var(0);
    let f = (x.clone() * 3.0).cos().acos() + x.sin();
    let id = ctx.node_id(&f);
    let g = ctx.to_graph();
    let c = compile(
        &g,
        &[id],
        1,
        0,
        &Options {
            simplify: None,
            gradients: false,
            ..Options::default()
        },
    )
    .unwrap();
    let t = Tape::new(&g, &[id], 1, 0).unwrap();
    for x in [-1.0, 0.1, 0.7, 2.5] {
        let (mut a, mut b) = ([0.0], [0.0]);
        c.function.call(&[x], &[], &mut a).unwrap();
        t.eval(&[x], &[], &mut b).unwrap();
        assert_eq!(a[0].to_bits(), b[0].to_bits());
    }
}
