use foldsynth::compile::Options;
use foldsynth::grammar::CreaseGraph;
use foldsynth::model::Model;
use foldsynth::model::compiled::{CompiledModel, ModelProblem};
use foldsynth::optimize::{Evaluation, Problem};
use foldsynth::task::Task;
use std::time::Instant;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let task = Task::load(&a[1]).unwrap();
    let g = CreaseGraph::from_sequence(&task, &a[2]).unwrap();
    let model = Model::new(&g, &task, 0).unwrap();
    let c = CompiledModel::new(&model, &Options::default()).unwrap();
    let modes = vec![1.0; model.plan.internal.len()];
    let x: Vec<f64> = model
        .free
        .iter()
        .map(|&i| {
            let (l, h) = model.var_bounds(i);
            0.5 * (l + h)
        })
        .collect();
    let p = c.params(&model, &modes);
    let mut buf = vec![0.0; c.buffer_len()];
    let n = 20000;
    let t = Instant::now();
    for _ in 0..n {
        c.call(&x, &p, &mut buf);
    }
    let jit = t.elapsed().as_secs_f64() / n as f64 * 1e9;
    let prob = ModelProblem::new(&model, &c, &modes);
    let mut e = Evaluation::new(prob.n_vars(), prob.n_constraints());
    let t = Instant::now();
    for _ in 0..n {
        prob.eval(&x, &mut e);
    }
    let pe = t.elapsed().as_secs_f64() / n as f64 * 1e9;
    let no = Options {
        gradients: false,
        ..Options::default()
    };
    let cv = foldsynth::compile::compile(
        &c.compiled.graph,
        &c.compiled.outputs[..1 + c.n_constraints],
        c.n_vars,
        p.len(),
        &no,
    );
    let r = &c.compiled.report;
    println!(
        "stages: build {:.1} simplify {:.1} diff {:.1} jit {:.1} ms",
        c.build_ms, r.simplify_ms, r.diff_ms, r.jit_ms
    );
    println!(
        "{}: n_vars {} n_constraints {} ops {} | jit value+grads {:.0} ns, problem eval {:.0} ns, compile {:.1} ms; value only compiled: {}",
        a[2],
        c.n_vars,
        c.n_constraints,
        c.compiled.report.with_gradients.ops,
        jit,
        pe,
        c.total_ms,
        cv.is_ok()
    );
}
