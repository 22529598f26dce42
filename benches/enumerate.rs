//! Enumeration speed: the gripper task with all filters at N_max = 3 and 4, and the raw
//! language (no filter) at N_max = 3.

use criterion::{Criterion, criterion_group, criterion_main};
use foldsynth::grammar::{Enumeration, Filters};
use foldsynth::task::Task;

fn bench(c: &mut Criterion) {
    let task = Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap();
    let mut g = c.benchmark_group("enumerate_gripper");
    g.sample_size(20);
    g.bench_function("n_max_3_all_filters", |b| {
        b.iter(|| Enumeration::run(&task, 3, Filters::all()).nodes.len())
    });
    g.bench_function("n_max_4_all_filters", |b| {
        b.iter(|| Enumeration::run(&task, 4, Filters::all()).nodes.len())
    });
    g.bench_function("n_max_3_no_filters", |b| {
        b.iter(|| Enumeration::run(&task, 3, Filters::none()).nodes.len())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
