//! Criterion benchmarks of the symbolic compiler on the degree-7 vertex with symbolic
//! sectors (the reference case): JIT value, JIT value+gradient, the interpreter,
//! f64 + central differences, dual numbers, and the compile pipeline.
//! `foldsynth bench vertex` reports the same figures as ratios from one run.

use criterion::{Criterion, criterion_group, criterion_main};
use foldsynth::compile::vertex::{self, VertexModel};
use foldsynth::compile::{Dual, Options, compile};
use foldsynth::expr::Tape;
use foldsynth::kinematics::VertexSpec;
use std::hint::black_box;

const V7: &str = "v(up, ((40,50,45,35,40),(t,-t,t,-t)), (55), (95))";

fn bench(c: &mut Criterion) {
    let spec = VertexSpec::parse(V7).expect("valid vertex");
    let t = vertex::most_rigid_t(&spec);
    let (x, p) = vertex::point(&spec, true, t);
    let n = x.len();
    let model = VertexModel::build(&spec, true);
    let g = model.ctx.to_graph();
    let out = [model.phi_sum_id()];
    let (nv, np) = (model.n_vars, model.n_params);
    let vg = compile(&g, &out, nv, np, &Options::default()).expect("compiles");
    let v = compile(
        &g,
        &out,
        nv,
        np,
        &Options {
            gradients: false,
            ..Options::default()
        },
    )
    .expect("compiles");
    let tape = Tape::new(&vg.graph, &vg.outputs, nv, np).expect("tape");

    let mut buf = vec![0.0; vg.layout.len()];
    c.bench_function("v7/jit_value", |b| {
        let mut o = [0.0];
        b.iter(|| v.function.call(black_box(&x), black_box(&p), &mut o))
    });
    c.bench_function("v7/jit_value_grad", |b| {
        b.iter(|| vg.function.call(black_box(&x), black_box(&p), &mut buf))
    });
    c.bench_function("v7/interpreter_value_grad", |b| {
        let mut scratch = Vec::new();
        let mut o = vec![0.0; vg.layout.len()];
        b.iter(|| tape.eval_with(&mut scratch, black_box(&x), black_box(&p), &mut o))
    });
    c.bench_function("v7/f64_central_diff", |b| {
        b.iter(|| {
            let mut g = vec![0.0; n];
            let mut y = x.clone();
            let f0 = vertex::phi_sum(&spec, true, &y, &p);
            for i in 0..n {
                let xi = y[i];
                y[i] = xi + 1e-6;
                let fp = vertex::phi_sum(&spec, true, &y, &p);
                y[i] = xi - 1e-6;
                let fm = vertex::phi_sum(&spec, true, &y, &p);
                y[i] = xi;
                g[i] = (fp - fm) / 2e-6;
            }
            black_box((f0, g))
        })
    });
    c.bench_function("v7/dual", |b| {
        let dp: Vec<Dual> = p.iter().map(|&q| Dual::constant(q)).collect();
        b.iter(|| {
            let dx: Vec<Dual> = (0..n).map(|i| Dual::var(x[i], i, n)).collect();
            black_box(vertex::phi_sum(&spec, true, &dx, &dp))
        })
    });
    c.bench_function("v7/compile_pipeline", |b| {
        b.iter(|| {
            let m = VertexModel::build(&spec, true);
            let g = m.ctx.to_graph();
            compile(&g, &[m.phi_sum_id()], nv, np, &Options::default()).expect("compiles")
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
