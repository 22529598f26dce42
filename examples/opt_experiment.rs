use foldsynth::compile::Options;
use foldsynth::grammar::{Enumeration, Filters};
use foldsynth::model::Model;
use foldsynth::model::compiled::{CompiledModel, ModelProblem, objective_target};
use foldsynth::optimize;
use foldsynth::task::Task;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let task = Task::load(&args[1]).unwrap();
    let max_outer: usize = args[2].parse().unwrap();
    let max_inner: u64 = args[3].parse().unwrap();
    let starts: usize = args[4].parse().unwrap();
    let e = Enumeration::run(&task, 3, Filters::all());
    let graphs: Vec<_> = e.meaningful().map(|n| n.graph.clone()).collect();
    let mut meets = 0;
    let mut total = 0;
    let mut evals = 0;
    let t0 = Instant::now();
    for (gi, g) in graphs.iter().enumerate().step_by(4) {
        let cand = gi % 3;
        let model = Model::new(g, &task, cand).unwrap();
        let compiled = CompiledModel::new(&model, &Options::default()).unwrap();
        let n = model.plan.internal.len();
        for bits in [0u32, (1 << n) - 1] {
            let modes: Vec<f64> = (0..n)
                .map(|i| if bits >> i & 1 == 1 { -1.0 } else { 1.0 })
                .collect();
            let p = ModelProblem::new(&model, &compiled, &modes);
            let sol = optimize::minimize(
                &p,
                &optimize::Options {
                    starts,
                    seed: gi as u64,
                    max_outer,
                    max_inner,
                    target: Some(objective_target(&model)),
                    ..Default::default()
                },
            );
            let full = model.full_vars(&sol.x);
            let omega = model.omega(&full, &modes);
            total += 1;
            evals += sol.evaluations;
            if sol.feasible && omega <= model.threshold {
                meets += 1;
            }
        }
    }
    println!(
        "outer {max_outer} inner {max_inner} starts {starts}: {meets}/{total} meet, {evals} evals, {:.2} s",
        t0.elapsed().as_secs_f64()
    );
}
