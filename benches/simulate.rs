//! Bar-and-hinge simulation and intersection checks on the adapted flasher (thesis Sec. 3:
//! one simulation of J = 30 steps took about 10 s there).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use foldsynth::check::{StateTracker, triangles_intersect};
use foldsynth::simulate::flasher::{FlasherTask, THESIS_BEST};
use foldsynth::simulate::{PatternFile, checker_for, simulate};
use nalgebra::Vector3;

fn flasher() -> PatternFile {
    PatternFile::parse(foldsynth::simulate::flasher::FLASHER_TOML, "flasher")
        .expect("shipped file parses")
}

fn bench(c: &mut Criterion) {
    let file = flasher();
    c.bench_function("flasher: simulate J=30 with intersection check", |b| {
        b.iter(|| simulate(black_box(&file.input)).expect("simulates"))
    });
    let mut plain = file.input.clone();
    plain.check_intersections = false;
    c.bench_function("flasher: simulate J=30 without check", |b| {
        b.iter(|| simulate(black_box(&plain)).expect("simulates"))
    });
    let states = simulate(&plain).expect("simulates").states;
    let checker = checker_for(&file.input).expect("checker");
    c.bench_function("flasher: self-intersection check of 31 states", |b| {
        b.iter(|| {
            let mut tr = StateTracker::new(&checker);
            states
                .iter()
                .map(|x| tr.step(black_box(x), 0.0, false).len())
                .sum::<usize>()
        })
    });
    let task = FlasherTask::shipped().expect("task");
    c.bench_function("flasher: one annealing objective evaluation", |b| {
        b.iter(|| task.evaluate_positions(black_box(&THESIS_BEST)))
    });
    let a = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(2.0, 0.0, 0.0),
        Vector3::new(0.0, 2.0, 0.0),
    ];
    let t = [
        Vector3::new(0.5, 0.5, -1.0),
        Vector3::new(0.6, 0.4, 1.0),
        Vector3::new(2.0, 2.0, 0.5),
    ];
    c.bench_function("moller: one crossing pair", |b| {
        b.iter(|| triangles_intersect(black_box(&a), black_box(&t), 1e-9))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
