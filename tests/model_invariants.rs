//! The proof that the model composes its frames right (issue 5): for every meaningful graph
//! of the gripper task (N_max = 3), every mode assignment and 20 points that satisfy ψ, at
//! 9 states of [0, π/2]: every facet is an isometry of its flat shape (≤ 1e-9), every
//! internal vertex closes (≤ 1e-10), and the compiled model equals the f64 path
//! (≤ 1e-12 relative). Gradients agree with central differences; a point that breaks
//! Eq. 25 at t_max is reported as not rigid, with finite coordinates.

mod common;
use common::{Feasibility, assert_gradients, smooth};
use foldsynth::check::verify::{Tolerances, verify};
use foldsynth::compile::Options;
use foldsynth::grammar::{CreaseGraph, Enumeration, Filters};
use foldsynth::model::compiled::{CompiledModel, ModelProblem, outputs_f64};
use foldsynth::model::numeric::{Evaluated, sample_times};
use foldsynth::model::{Constraint, Model, geometry};
use foldsynth::optimize::{self, Evaluation, Problem};
use foldsynth::task::Task;

fn task() -> Task {
    Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0)
}

#[test]
fn every_meaningful_graph_composes_its_frames_right() {
    let task = task();
    let e = Enumeration::run(&task, 3, Filters::all());
    let ts = sample_times(std::f64::consts::FRAC_PI_2, 9);
    let tol = Tolerances::default();
    let (mut graphs, mut points, mut states) = (0, 0, 0);
    for node in e.meaningful() {
        let graph: &CreaseGraph = &node.graph;
        let model = Model::new(graph, &task, 0).unwrap();
        let compiled = CompiledModel::new(&model, &Options::default()).unwrap();
        let n = model.plan.internal.len();
        let mut buf = vec![0.0; compiled.buffer_len()];
        let mut found_for_graph = 0;
        for bits in 0..(1u32 << n) {
            let modes: Vec<f64> = (0..n)
                .map(|i| if bits >> i & 1 == 1 { -1.0 } else { 1.0 })
                .collect();
            let problem = Feasibility(ModelProblem::new(&model, &compiled, &modes));
            let mut found = 0;
            for seed in 0..40u64 {
                if found == 20 {
                    break;
                }
                let opts = optimize::Options {
                    starts: 1,
                    seed,
                    max_outer: 8,
                    ..Default::default()
                };
                let sol = optimize::minimize(&problem, &opts);
                if !sol.feasible {
                    continue;
                }
                found += 1;
                // Compiled = f64 path.
                compiled.call(&sol.x, &compiled.params(&model, &modes), &mut buf);
                let (f, g) = outputs_f64(&model, &sol.x, &modes);
                assert!(
                    close(buf[0], f),
                    "{}: objective {} vs {}",
                    model.plan.sequence,
                    buf[0],
                    f
                );
                for (k, gk) in g.iter().enumerate() {
                    assert!(
                        close(buf[k + 1], *gk),
                        "{}: constraint {k}: {} vs {gk}",
                        model.plan.sequence,
                        buf[k + 1]
                    );
                }
                // Isometry and closure on every rigid state.
                let design = Evaluated::new(&model.plan, model.full_vars(&sol.x), modes.clone());
                let r = verify(&design, &ts, &tol);
                assert!(
                    r.rigid_at_tmax,
                    "{}: ψ holds but the state at t_max is not rigid: {r:?}",
                    model.plan.sequence
                );
                assert!(
                    r.isometry_max <= 1e-9 && r.closure_max <= 1e-10 && r.fold_angle_max <= 1e-8,
                    "{} modes {modes:?}: {r:?}",
                    model.plan.sequence
                );
                states += r.rigid_states;
            }
            points += found;
            found_for_graph += found;
        }
        assert!(
            found_for_graph > 0,
            "no point satisfies ψ for {}",
            model.plan.sequence
        );
        graphs += 1;
    }
    assert_eq!(graphs, e.meaningful().count());
    // Not vacuous: most (graph, modes) pairs give 20 points, most states are rigid.
    eprintln!("{graphs} graphs, {points} feasible points, {states} rigid states checked");
    assert!(points >= 20 * 300, "only {points} feasible points");
    assert!(
        states >= 8 * points * 3 / 4,
        "only {states} rigid states for {points} points"
    );
}

#[test]
fn gradients_agree_with_central_differences() {
    let task = task();
    let mut checked = 0;
    for seq in [
        "2, 3, (4, 8), 4, (7, 8)",
        "2, 4, 7, (6, 9)",
        "2, 3, 4, (8, 9)",
    ] {
        let graph = CreaseGraph::from_sequence(&task, seq).unwrap();
        let model = Model::new(&graph, &task, 1).unwrap();
        let compiled = CompiledModel::new(&model, &Options::default()).unwrap();
        let modes = vec![1.0, -1.0, 1.0];
        let problem = ModelProblem::new(&model, &compiled, &modes);
        let mut e = Evaluation::new(problem.n_vars(), problem.n_constraints());
        // Points away from every kink, where the function is smooth and central differences
        // mean something: each constraint at least 1e-2 from zero, and every vertex triangle
        // at every evaluated t away from degeneracy (its margins and its perimeter deficit
        // 2π − ΣU at least 1e-2: a triangle's angles have a square-root kink at both).
        let points = optimize::quasi_random_points(model.free.len(), 300, 11);
        for u in &points {
            let x: Vec<f64> = u
                .iter()
                .zip(&model.free)
                .map(|(u, &i)| {
                    let (lo, hi) = model.var_bounds(i);
                    lo + (hi - lo) * u
                })
                .collect();
            problem.eval(&x, &mut e);
            if e.g.iter().any(|g| g.abs() < 1e-2) || !smooth(&model, &x, &modes) {
                continue;
            }
            checked += 1;
            assert_gradients(&model, &e, &x, &modes, seq);
        }
    }
    assert!(checked >= 30, "only {checked} smooth points checked");
}

#[test]
fn a_point_that_breaks_eq25_is_not_rigid_and_has_finite_coordinates() {
    let task = task();
    let graph = CreaseGraph::from_sequence(&task, "2, 3").unwrap();
    let model = Model::new(&graph, &task, 0).unwrap();
    let compiled = CompiledModel::new(&model, &Options::default()).unwrap();
    let modes = vec![1.0, 1.0];
    // Search the box for a point violating a rigid-foldability constraint at t_max.
    let rigid: Vec<usize> = (0..model.plan.constraints.len())
        .filter(|k| matches!(model.plan.constraints[*k], Constraint::Rigid { .. }))
        .collect();
    let mut buf = vec![0.0; compiled.buffer_len()];
    let points = optimize::quasi_random_points(model.free.len(), 400, 3);
    let bad = points
        .iter()
        .map(|u| {
            u.iter()
                .zip(&model.free)
                .map(|(u, &i)| {
                    let (lo, hi) = model.var_bounds(i);
                    lo + (hi - lo) * u
                })
                .collect::<Vec<f64>>()
        })
        .find(|x| {
            compiled.call(x, &compiled.params(&model, &modes), &mut buf);
            rigid.iter().any(|k| buf[k + 1] < -1e-3)
        })
        .expect("some point in the box breaks Eq. 25");
    let design = Evaluated::new(&model.plan, model.full_vars(&bad), modes);
    let r = verify(
        &design,
        &sample_times(model.t_max, 17),
        &Tolerances::default(),
    );
    assert!(!r.rigid_at_tmax && !r.rigid_over_motion, "{r:?}");
    let coords = design.coords(&design.fold(model.t_max));
    assert!(coords.iter().flatten().all(|c| c.is_finite()), "{coords:?}");
    assert!(buf.iter().all(|v| v.is_finite()));
}

#[test]
fn crease_rotations_point_along_the_folded_creases() {
    let task = task();
    let graph = CreaseGraph::from_sequence(&task, "2, 3, (4, 8), 4, (7, 8)").unwrap();
    let model = Model::new(&graph, &task, 0).unwrap();
    let compiled = CompiledModel::new(&model, &Options::default()).unwrap();
    let modes = vec![1.0, -1.0, 1.0];
    let problem = ModelProblem::new(&model, &compiled, &modes);
    let sol = optimize::minimize(
        &problem,
        &optimize::Options {
            starts: 4,
            ..Default::default()
        },
    );
    assert!(sol.feasible);
    let design = Evaluated::new(&model.plan, model.full_vars(&sol.x), modes);
    for t in [0.3, 0.9, std::f64::consts::FRAC_PI_2] {
        let folded = design.fold(t);
        let x = design.coords(&folded);
        for (c, cr) in model.plan.creases.iter().enumerate() {
            let r = geometry::crease_rotation(&model.plan, &design.flat, &folded, c);
            let d: Vec<f64> = (0..3).map(|i| x[cr.head][i] - x[cr.tail][i]).collect();
            let l = d.iter().map(|v| v * v).sum::<f64>().sqrt();
            for i in 0..3 {
                assert!((r[i][0] - d[i] / l).abs() < 1e-12, "crease {c} at t = {t}");
            }
            // A rotation: orthonormal columns.
            for a in 0..3 {
                for b in 0..3 {
                    let dot: f64 = (0..3).map(|i| r[i][a] * r[i][b]).sum();
                    assert!((dot - f64::from(u8::from(a == b))).abs() < 1e-12);
                }
            }
        }
    }
}
