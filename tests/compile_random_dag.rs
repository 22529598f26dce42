//! Random expression DAGs (proptest): the interpreter equals a direct f64 evaluation of
//! the same program, the JIT equals the interpreter (both compute the transcendentals with
//! `foldsynth::trig`; the JIT in batches), and gradients by reverse sweeps and by vertex
//! elimination equal forward-mode dual numbers, also when the JIT fuses the gradients'
//! sums of products into `fma`.

use foldsynth::compile::vanish::fold_vanishing;
use foldsynth::compile::{CompiledFn, Dual, Jacobian, Options, compile, jacobian};
use foldsynth::expr::{Ctx, NodeId, Sym, Tape, clamp_unit, select};
use foldsynth::kinematics::Scalar;
use proptest::prelude::*;

/// The operations `Scalar` lacks but the graph has.
trait Ext: Scalar {
    fn select3(c: &Self, a: &Self, b: &Self) -> Self;
    fn clamp1(&self) -> Self;
}

impl Ext for f64 {
    fn select3(c: &Self, a: &Self, b: &Self) -> Self {
        select(*c, *a, *b)
    }
    fn clamp1(&self) -> Self {
        clamp_unit(*self)
    }
}

impl Ext for Sym {
    fn select3(c: &Self, a: &Self, b: &Self) -> Self {
        Sym::select(c, a, b)
    }
    fn clamp1(&self) -> Self {
        self.clamp_unit()
    }
}

impl Ext for Dual {
    fn select3(c: &Self, a: &Self, b: &Self) -> Self {
        if c.v > 0.0 { a.clone() } else { b.clone() }
    }
    fn clamp1(&self) -> Self {
        self.clamp_unit()
    }
}

const N_VARS: usize = 3;
const N_PARAMS: usize = 2;

/// One instruction: an opcode, three operand picks (taken modulo the values so far) and
/// a constant.
type Instr = (u8, usize, usize, usize, f64);

fn program() -> impl Strategy<Value = Vec<Instr>> {
    prop::collection::vec(
        (
            0u8..15,
            any::<usize>(),
            any::<usize>(),
            any::<usize>(),
            -3.0f64..3.0,
        ),
        1..25,
    )
}

/// Programs that also write zero terms `0·x` and `x - x` of values that are NaN or
/// infinite at some inputs (opcodes 15–17).
fn program_with_zeros() -> impl Strategy<Value = Vec<Instr>> {
    prop::collection::vec(
        (
            0u8..18,
            any::<usize>(),
            any::<usize>(),
            any::<usize>(),
            -3.0f64..3.0,
        ),
        1..25,
    )
}

/// Inputs with exact zeros among them (where the directions are NaN).
fn inputs_with_zeros() -> impl Strategy<Value = (Vec<f64>, Vec<f64>)> {
    let v = || prop_oneof![3 => -2.0f64..2.0, 1 => Just(0.0), 1 => Just(1e-170)];
    (
        prop::collection::vec(v(), N_VARS),
        prop::collection::vec(v(), N_PARAMS),
    )
}

/// Run the program in any scalar type; all values (inputs first).
/// Denominators are `b² + 0.5` and atan2's x is `b² + 0.1` (both positive), so that no
/// result depends on the sign of a zero (see `ExprGraph::add`).
fn run_all<S: Ext>(prog: &[Instr], vars: &[S], params: &[S]) -> Vec<S> {
    let mut v: Vec<S> = vars.iter().chain(params).cloned().collect();
    for &(op, i, j, k, c) in prog {
        let n = v.len();
        let (a, b, d) = (v[i % n].clone(), v[j % n].clone(), v[k % n].clone());
        let x = match op {
            0 => a + b,
            1 => a - b,
            2 => a * b,
            3 => a / (b.clone() * b + 0.5),
            4 => -a,
            5 => a.sin(),
            6 => a.cos(),
            7 => a.acos(),
            8 => a.sqrt(),
            9 => a.atan2(&(b.clone() * b + 0.1)),
            10 => a.sgn() * b,
            11 => S::select3(&a, &b, &d),
            12 => a.clamp1(),
            13 => a * c,
            14 => a + c,
            // Only in `program_with_zeros`: a zero term, a direction (NaN where b = d = 0,
            // infinite where b² + d² underflows) and a difference with itself.
            15 => a * 0.0,
            16 => a / (b.clone() * b + d.clone() * d).sqrt(),
            _ => a.clone() - a,
        };
        v.push(x);
    }
    v
}

/// The outputs: the last three values.
fn run<S: Ext>(prog: &[Instr], vars: &[S], params: &[S]) -> Vec<S> {
    let v = run_all(prog, vars, params);
    v[v.len().saturating_sub(3)..].to_vec()
}

/// Whether every intermediate value is finite. Reverse mode sends a zero adjoint into
/// the branch a `select` discards; if that branch holds a NaN, `0 · NaN` poisons the
/// gradient (a documented limitation of `compile::diff`), so gradients are compared on
/// programs whose every value is finite.
fn all_finite(prog: &[Instr], x: &[f64], p: &[f64]) -> bool {
    run_all(prog, x, p).iter().all(|v| v.is_finite())
}

fn same(a: f64, b: f64) -> bool {
    // Numeric equality (±0 are equal), NaN equals NaN.
    a == b || (a.is_nan() && b.is_nan())
}

fn inputs() -> impl Strategy<Value = (Vec<f64>, Vec<f64>)> {
    (
        prop::collection::vec(-2.0f64..2.0, N_VARS),
        prop::collection::vec(-2.0f64..2.0, N_PARAMS),
    )
}

fn build(prog: &[Instr]) -> (foldsynth::expr::ExprGraph, Vec<NodeId>) {
    let ctx = Ctx::new();
    let vars: Vec<Sym> = (0..N_VARS).map(|i| ctx.var(i)).collect();
    let params: Vec<Sym> = (0..N_PARAMS).map(|i| ctx.param(i)).collect();
    let outs = run(prog, &vars, &params);
    let ids = outs.iter().map(|s| ctx.node_id(s)).collect();
    (ctx.to_graph(), ids)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn interpreter_jit_and_f64_agree(prog in program(), (x, p) in inputs()) {
        let (g, ids) = build(&prog);
        let direct = run(&prog, &x, &p);
        let tape = Tape::new(&g, &ids, N_VARS, N_PARAMS).unwrap();
        let jit = CompiledFn::new(&g, &ids, N_VARS, N_PARAMS).unwrap();
        let mut ti = vec![0.0; ids.len()];
        let mut tj = vec![0.0; ids.len()];
        tape.eval(&x, &p, &mut ti).unwrap();
        jit.call(&x, &p, &mut tj).unwrap();
        for k in 0..ids.len() {
            // Construction-time folding is exact, so the graph reproduces f64 exactly.
            prop_assert!(same(ti[k], direct[k]), "interpreter {} vs f64 {} (output {k})", ti[k], direct[k]);
            prop_assert!(same(tj[k], ti[k]), "JIT {} vs interpreter {} (output {k})", tj[k], ti[k]);
        }
    }

    #[test]
    fn gradients_equal_dual_numbers(prog in program(), (x, p) in inputs()) {
        prop_assume!(all_finite(&prog, &x, &p));
        for method in [Jacobian::Reverse, Jacobian::Eliminate] {
            let (mut g, ids) = build(&prog);
            let grads = jacobian(&mut g, &ids, N_VARS, method).unwrap();
            let flat: Vec<NodeId> = grads.iter().flatten().copied().collect();
            let tape = Tape::new(&g, &flat, N_VARS, N_PARAMS).unwrap();
            let mut r = vec![0.0; flat.len()];
            tape.eval(&x, &p, &mut r).unwrap();
            let dx: Vec<Dual> = (0..N_VARS).map(|i| Dual::var(x[i], i, N_VARS)).collect();
            let dp: Vec<Dual> = p.iter().map(|&v| Dual::constant(v)).collect();
            let d = run(&prog, &dx, &dp);
            for (k, out) in d.iter().enumerate() {
                if !out.v.is_finite() || out.g.iter().any(|v| !v.is_finite()) {
                    continue; // gradients of NaN values are not compared
                }
                let want = out.grad(N_VARS);
                for i in 0..N_VARS {
                    let got = r[k * N_VARS + i];
                    let scale = got.abs().max(want[i].abs()).max(1.0);
                    prop_assert!(
                        (got - want[i]).abs() <= 1e-10 * scale,
                        "{method:?}: d out{k} / d x{i}: {got} vs dual {}", want[i]
                    );
                }
            }
        }
    }

    #[test]
    fn gradients_are_never_nan_for_finite_values(prog in program(), (x, p) in inputs()) {
        // Guarded derivatives: finite values never get a NaN gradient from sgn, acos
        // outside (-1, 1), sqrt at 0, atan2, clamp or select.
        prop_assume!(all_finite(&prog, &x, &p));
        for method in [Jacobian::Reverse, Jacobian::Eliminate] {
            let (mut g, ids) = build(&prog);
            let grads = jacobian(&mut g, &ids, N_VARS, method).unwrap();
            let tape_v = Tape::new(&g, &ids, N_VARS, N_PARAMS).unwrap();
            let mut v = vec![0.0; ids.len()];
            tape_v.eval(&x, &p, &mut v).unwrap();
            let dx: Vec<Dual> = (0..N_VARS).map(|i| Dual::var(x[i], i, N_VARS)).collect();
            let dp: Vec<Dual> = p.iter().map(|&q| Dual::constant(q)).collect();
            let d = run(&prog, &dx, &dp);
            for (k, grad) in grads.iter().enumerate() {
                let tape = Tape::new(&g, grad, N_VARS, N_PARAMS).unwrap();
                let mut r = vec![0.0; N_VARS];
                tape.eval(&x, &p, &mut r).unwrap();
                if v[k].is_finite() && d[k].g.iter().all(|q| q.is_finite()) {
                    prop_assert!(r.iter().all(|q| !q.is_nan()), "{method:?} output {k}: {r:?}");
                }
            }
        }
    }
}

/// `compile` with and without fused multiply-add in the gradients (no egg: the program's
/// own graph).
fn compile_both(prog: &[Instr]) -> [foldsynth::compile::Compiled; 2] {
    let (g, ids) = build(prog);
    [true, false].map(|fma| {
        let opts = Options {
            simplify: None,
            fma,
            ..Options::default()
        };
        compile(&g, &ids, N_VARS, N_PARAMS, &opts).unwrap()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn fused_gradients_equal_dual_numbers(prog in program(), (x, p) in inputs()) {
        // The values are the interpreter's bits with or without fusion; the fused
        // gradients equal forward-mode dual numbers as the unfused ones do.
        prop_assume!(all_finite(&prog, &x, &p));
        let [fused, plain] = compile_both(&prog);
        let len = fused.layout.len();
        let (mut rf, mut rp) = (vec![0.0; len], vec![0.0; len]);
        fused.function.call(&x, &p, &mut rf).unwrap();
        plain.function.call(&x, &p, &mut rp).unwrap();
        let dx: Vec<Dual> = (0..N_VARS).map(|i| Dual::var(x[i], i, N_VARS)).collect();
        let dp: Vec<Dual> = p.iter().map(|&v| Dual::constant(v)).collect();
        let d = run(&prog, &dx, &dp);
        let direct = run(&prog, &x, &p);
        for (k, out) in d.iter().enumerate() {
            let k_v = fused.layout.value(k);
            prop_assert!(same(rf[k_v], rp[k_v]), "value {k}: fused {} vs plain {}", rf[k_v], rp[k_v]);
            prop_assert!(same(rf[k_v], direct[k]), "value {k}: JIT {} vs f64 {}", rf[k_v], direct[k]);
            if !out.v.is_finite() || out.g.iter().any(|v| !v.is_finite()) {
                continue;
            }
            let want = out.grad(N_VARS);
            for (i, j) in fused.layout.gradient(k).enumerate() {
                let scale = rf[j].abs().max(want[i].abs()).max(1.0);
                prop_assert!(
                    (rf[j] - want[i]).abs() <= 1e-10 * scale,
                    "d out{k} / d x{i}: fused {} vs dual {}", rf[j], want[i]
                );
            }
        }
    }

    #[test]
    fn removing_vanishing_terms_keeps_every_value(
        prog in program_with_zeros(),
        (x, p) in inputs_with_zeros(),
    ) {
        // Every output, NaN and infinities included, before and after `fold_vanishing`.
        let (g, ids) = build(&prog);
        let (h, outs, _) = fold_vanishing(&g, &ids);
        let (a, b) = (eval_unsigned_zeros(&g, &ids, &x, &p), eval_unsigned_zeros(&h, &outs, &x, &p));
        for k in 0..ids.len() {
            prop_assert!(same(a[k], b[k]), "output {k}: {} before, {} after", a[k], b[k]);
        }
    }
}

/// The graph's values with every zero made +0 after each operation. `a + 0 → a` may turn
/// `-0 + 0 = +0` into `-0` (the one documented change of folding), and `acos(±0)` differ
/// in the last bit, which would hide what is checked here: equal values, NaN included.
fn eval_unsigned_zeros(
    g: &foldsynth::expr::ExprGraph,
    outs: &[NodeId],
    x: &[f64],
    p: &[f64],
) -> Vec<f64> {
    let mut v = vec![0.0; g.len()];
    for (i, n) in g.nodes().iter().enumerate() {
        let args: Vec<f64> = n.children().into_iter().map(|c| v[c.index()]).collect();
        let r = n.eval_with(&args, x, p);
        v[i] = if r == 0.0 { 0.0 } else { r };
    }
    outs.iter().map(|o| v[o.index()]).collect()
}

#[test]
fn vanishing_terms_are_removed_in_random_programs() {
    // The property above is not vacuous: over fixed random programs, terms do go.
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let mut removed = 0;
    for _ in 0..300 {
        let prog = program_with_zeros()
            .new_tree(&mut runner)
            .unwrap()
            .current();
        let (g, ids) = build(&prog);
        removed += fold_vanishing(&g, &ids).2;
    }
    assert!(removed > 0);
}

#[test]
fn fusion_saves_instructions_where_the_cpu_has_fma() {
    // f = Σ xᵢ·xⱼ·sin(xₖ): its gradient is sums of products. A value of
    // f(0.3, -1.2, 2.0) and ∂f/∂x₀ against the closed form in f64.
    let ctx = Ctx::new();
    let x: Vec<Sym> = (0..N_VARS).map(|i| ctx.var(i)).collect();
    let mut f = Sym::from_f64(0.0);
    for i in 0..N_VARS {
        for j in 0..N_VARS {
            let k = (i + j) % N_VARS;
            f = f + x[i].clone() * x[j].clone() * x[k].sin();
        }
    }
    let ids = [ctx.node_id(&f)];
    let g = ctx.to_graph();
    let [fused, plain] = [true, false].map(|fma| {
        let opts = Options {
            fma,
            ..Options::default()
        };
        compile(&g, &ids, N_VARS, N_PARAMS, &opts).unwrap()
    });
    let v = [0.3, -1.2, 2.0];
    let (mut rf, mut rp) = ([0.0; 4], [0.0; 4]);
    fused.function.call(&v, &[0.0; N_PARAMS], &mut rf).unwrap();
    plain.function.call(&v, &[0.0; N_PARAMS], &mut rp).unwrap();
    assert_eq!(rf[0].to_bits(), rp[0].to_bits(), "values are not fused");
    let (s, c) = (|i: usize| v[i].sin(), |i: usize| v[i].cos());
    // ∂/∂x₀ of Σᵢⱼ xᵢ xⱼ sin(x₍ᵢ₊ⱼ₎ mod 3).
    let mut want = 0.0;
    for i in 0..N_VARS {
        for j in 0..N_VARS {
            let k = (i + j) % N_VARS;
            let xi = if i == 0 { 1.0 } else { 0.0 };
            let xj = if j == 0 { 1.0 } else { 0.0 };
            let xk = if k == 0 { 1.0 } else { 0.0 };
            want += (xi * v[j] + v[i] * xj) * s(k) + v[i] * v[j] * xk * c(k);
        }
    }
    for r in [rf, rp] {
        assert!(
            (r[1] - want).abs() <= 1e-13 * want.abs().max(1.0),
            "{} vs {want}",
            r[1]
        );
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("fma") {
        let (nf, np) = (
            fused.function.n_instructions(),
            plain.function.n_instructions(),
        );
        assert!(nf < np, "fused {nf} vs plain {np} instructions");
    }
}

#[test]
fn compiled_fn_is_send_and_sync() {
    fn check<T: Send + Sync>() {}
    check::<CompiledFn>();
}
