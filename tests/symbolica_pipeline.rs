//! Symbolica's pipeline (feature `symbolica`) against ours, in process: on the degree-7
//! and degree-12 vertices and the gripper model, Symbolica's values and gradients (its
//! canonical form, its derivatives, its optimized evaluator, SymJIT) equal our JIT's to
//! 1e-12; every Symbolica call runs on one thread, whoever calls; rayon keeps its pool;
//! bad input is an error and the thread lives on.

use foldsynth::compile::symbolica::{self, Job, Peer, PrintFormat};
use foldsynth::compile::vertex::{self, VertexModel};
use foldsynth::compile::{Options, compile};
use foldsynth::expr::{ExprGraph, Names, Node};
use foldsynth::grammar::CreaseGraph;
use foldsynth::kinematics::VertexSpec;
use foldsynth::model::Model;
use foldsynth::model::compiled::{CompiledModel, symbolic};
use foldsynth::task::Task;

const V7: &str = "v(up, ((40,50,45,35,40),(t,-t,t,-t)), (55), (95))";
const V12: &str =
    "v(up, ((30,30,30,30),(t,-t,t)), ((30,30,30,30),(t,-t,t)), ((30,30,30,30),(t,-t,t)))";
const GRIPPER: &str = "2, 3, (4, 8), 4, (7, 8)";

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(1.0)
}

fn max_dev(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| rel(*x, *y))
        .fold(0.0, f64::max)
}

/// Our JIT's values and gradients and Symbolica's, for one vertex at its most rigid t.
fn vertex_both(spec: &str, sym: bool) -> (Vec<f64>, Vec<f64>) {
    let spec = VertexSpec::parse(spec).unwrap();
    let t = vertex::most_rigid_t(&spec);
    let (x, p) = vertex::point(&spec, sym, t);
    let m = VertexModel::build(&spec, sym);
    let g = m.ctx.to_graph();
    let out = m.outputs();
    let ids: Vec<_> = out.iter().map(|(_, id)| *id).collect();
    let ours = compile(&g, &ids, m.n_vars, m.n_params, &Options::default()).unwrap();
    let mut buf = vec![0.0; ours.layout.len()];
    ours.function.call(&x, &p, &mut buf).unwrap();
    let peer = Peer::build(Job {
        graph: g,
        outputs: out,
        names: m.names.clone(),
        n_vars: m.n_vars,
        n_params: m.n_params,
    })
    .unwrap();
    let inputs: Vec<f64> = x.iter().chain(&p).copied().collect();
    (buf, peer.eval(&inputs).unwrap())
}

#[test]
fn vertices_agree_with_ours() {
    for (spec, sym) in [(V7, true), (V7, false), (V12, true), (V12, false)] {
        let (ours, theirs) = vertex_both(spec, sym);
        let d = max_dev(&ours, &theirs);
        // U, θ, φ of all three units and their gradients.
        assert!(ours.len() >= 9);
        assert!(
            d <= 1e-12,
            "{spec} symbolic sectors {sym}: {d:e}\nours {ours:?}\nSymbolica {theirs:?}"
        );
    }
}

#[test]
fn gripper_model_agrees_with_ours() {
    let task = Task::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/grammar/gripper.toml"
    )))
    .unwrap();
    let graph = CreaseGraph::from_sequence(&task, GRIPPER).unwrap();
    let model = Model::new(&graph, &task, 0).unwrap();
    let ours = CompiledModel::new(&model, &Options::default()).unwrap();
    let modes = vec![1.0; model.plan.internal.len()];
    let params = ours.params(&model, &modes);
    let (ctx, outputs) = symbolic(&model);
    let named: Vec<_> = outputs
        .iter()
        .enumerate()
        .map(|(k, o)| (format!("o{k}"), ctx.node_id(o)))
        .collect();
    let peer = Peer::build(Job {
        graph: ctx.to_graph(),
        outputs: named,
        names: Names::default(),
        n_vars: model.free.len(),
        n_params: params.len(),
    })
    .unwrap();
    // Generic points inside the bounds.
    for s in [0.35, 0.5, 0.65] {
        let x: Vec<f64> = model
            .free
            .iter()
            .enumerate()
            .map(|(k, &i)| {
                let (lo, hi) = model.var_bounds(i);
                lo + (s + 0.03 * (k % 4) as f64) * (hi - lo)
            })
            .collect();
        let mut buf = vec![0.0; ours.buffer_len()];
        ours.call(&x, &params, &mut buf);
        let inputs: Vec<f64> = x.iter().chain(&params).copied().collect();
        let theirs = peer.eval(&inputs).unwrap();
        let d = max_dev(&buf, &theirs);
        assert!(d <= 1e-12, "at {s}: {d:e}");
    }
    let r = &peer.report;
    assert!(r.aliases > 0 && r.derivative_aliases > 0, "{r:?}");
    assert!(r.ops_after.total() < r.ops_before.total(), "{r:?}");
}

#[test]
fn every_call_runs_on_one_thread_and_rayon_keeps_its_pool() {
    let ids: Vec<_> = (0..4)
        .map(|_| {
            std::thread::spawn(|| {
                let t = symbolica::thread_id().unwrap();
                assert_ne!(t, std::thread::current().id());
                t
            })
        })
        .collect::<Vec<_>>()
        .into_iter()
        .map(|h| h.join().unwrap())
        .collect();
    assert!(ids.iter().all(|t| *t == ids[0]), "{ids:?}");
    assert!(symbolica::started());
    // Symbolica would have made rayon's global pool one thread wide.
    let (_, _) = vertex_both(V7, true);
    let want = std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|v| v.parse().ok())
        .filter(|n: &usize| *n > 0)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    assert_eq!(rayon::current_num_threads(), want);
}

#[test]
fn bad_input_is_an_error_and_the_thread_lives_on() {
    let mut g = ExprGraph::new();
    let x = g.var(0);
    let inf = g.constant(f64::INFINITY);
    let y = g.add(Node::Add(x, inf));
    let job = Job {
        graph: g,
        outputs: vec![("y".into(), y)],
        names: Names::default(),
        n_vars: 1,
        n_params: 0,
    };
    let e = Peer::build(job.clone())
        .err()
        .expect("an infinite constant has no Symbolica number");
    assert!(e.to_string().contains("inf"), "{e}");
    assert!(symbolica::print(job, PrintFormat::Plain, false).is_err());
    // The thread still serves.
    let (ours, theirs) = vertex_both(V7, false);
    assert!(max_dev(&ours, &theirs) <= 1e-12);
}

/// Each of our functions through Symbolica (its own `acos`, our `atan2`, `sgn`, `clamp`,
/// `select`), by both SymJIT evaluators and by its evaluator without JIT, against our
/// JIT, with `atan2` in all four quadrants.
#[test]
fn every_function_agrees_with_ours() {
    let mut g = ExprGraph::new();
    let (x, y) = (g.var(0), g.var(1));
    let half = g.constant(0.5);
    let hx = g.add(Node::Mul(half, x));
    let outs = vec![
        ("atan2".to_string(), g.add(Node::Atan2(y, x))),
        ("acos".to_string(), g.add(Node::Acos(hx))),
        ("sgn".to_string(), {
            let s = g.add(Node::Sgn(y));
            g.add(Node::Mul(s, x))
        }),
        ("clamp".to_string(), g.add(Node::Clamp(y))),
        ("select".to_string(), g.add(Node::Select(y, x, hx))),
        ("sqrt".to_string(), {
            let xx = g.add(Node::Mul(x, x));
            let a = g.add(Node::Add(xx, half));
            g.add(Node::Sqrt(a))
        }),
        ("sincos".to_string(), {
            let s = g.add(Node::Sin(x));
            let c = g.add(Node::Cos(y));
            g.add(Node::Div(s, c))
        }),
    ];
    let ids: Vec<_> = outs.iter().map(|(_, id)| *id).collect();
    let ours = compile(&g, &ids, 2, 0, &Options::default()).unwrap();
    let peer = Peer::build(Job {
        graph: g,
        outputs: outs.clone(),
        names: Names::default(),
        n_vars: 2,
        n_params: 0,
    })
    .unwrap();
    for (a, b) in [
        (0.7, 0.4),
        (1.3, -0.6),
        (-1.2, 0.9),
        (-0.8, -0.3),
        (0.2, 1.7),
    ] {
        let mut buf = vec![0.0; ours.layout.len()];
        ours.function.call(&[a, b], &[], &mut buf).unwrap();
        let jit = peer.eval(&[a, b]).unwrap();
        let ev = peer.eval_interpreted(&[a, b]).unwrap();
        let values = peer.eval_values(&[a, b]).unwrap();
        for (k, v) in values.iter().enumerate() {
            assert!(
                rel(buf[k], *v) <= 1e-14,
                "{} at ({a}, {b}): ours {} value-only SymJIT {v}",
                outs[k].0,
                buf[k]
            );
        }
        for k in 0..buf.len() {
            let what = if k < outs.len() {
                outs[k].0.clone()
            } else {
                format!(
                    "d{}/d{}",
                    outs[(k - outs.len()) / 2].0,
                    (k - outs.len()) % 2
                )
            };
            assert!(
                rel(buf[k], ev[k]) <= 1e-14,
                "{what} at ({a}, {b}): ours {} evaluator {}",
                buf[k],
                ev[k]
            );
            assert!(
                rel(buf[k], jit[k]) <= 1e-14,
                "{what} at ({a}, {b}): ours {} SymJIT {}",
                buf[k],
                jit[k]
            );
        }
    }
}
