//! One PTU vertex evaluation (all of U, θ, β, δ, φ and the margins) in f64, for degree
//! 4, 8 and 360 — the thesis calls this "real time".

use criterion::{Criterion, criterion_group, criterion_main};
use foldsynth::kinematics::{Unit, VertexSpec, solve_vertex};
use std::hint::black_box;

fn symmetric(n: usize, t: f64) -> [Unit<f64>; 3] {
    let m = n / 3;
    let rho: Vec<f64> = (0..m - 1)
        .map(|i| if i % 2 == 0 { t } else { -t })
        .collect();
    let u = Unit::new(vec![2.0 * std::f64::consts::PI / n as f64; m], rho);
    [u.clone(), u.clone(), u]
}

fn bench(c: &mut Criterion) {
    let d4 = VertexSpec::parse("v(up, ((100,80),(t)), (95), (85))")
        .unwrap()
        .units_at(1.0);
    let d8 = VertexSpec::parse("v(up, ((40,50,45,35),(t,-t,t)), ((55,45),(-t)), ((40,50),(t)))")
        .unwrap()
        .units_at(1.0);
    let d360 = symmetric(360, 1.2);
    let mut g = c.benchmark_group("ptu_vertex");
    g.bench_function("degree4", |b| {
        b.iter(|| solve_vertex(black_box(&d4), black_box(&1.0)))
    });
    g.bench_function("degree8", |b| {
        b.iter(|| solve_vertex(black_box(&d8), black_box(&1.0)))
    });
    g.bench_function("degree360", |b| {
        b.iter(|| solve_vertex(black_box(&d360), black_box(&1.0)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
