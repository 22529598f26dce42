//! The task language's terms in the model (issue 31): targets of any vertex on lines,
//! planes and surfaces, orientation constraints and the area term. Every term is checked
//! against mathematics: the compiled model against the f64 path (≤ 1e-12 relative),
//! gradients against central differences (at points away from switches), distances against
//! the analytic ones, the packing footprint against a brute-force bounding box, and the
//! orientation constraints against angles computed from the f64 positions.

mod common;
use common::Feasibility;
use foldsynth::compile::Options;
use foldsynth::geom::{V3, cross, dot, norm, normalize, sub};
use foldsynth::grammar::{CreaseGraph, Enumeration, Filters};
use foldsynth::model::compiled::{
    CompiledModel, ModelProblem, all_starts, meets_target, objective_target, outputs_f64,
};
use foldsynth::model::numeric::Evaluated;
use foldsynth::model::{Combination, Model, Plan, area, select};
use foldsynth::optimize::{self, Evaluation, Problem};
use foldsynth::scene::shapes::MeshObstacle;
use foldsynth::scene::{Copies, TriangleMesh};
use foldsynth::task::Task;
use foldsynth::task::terms::{AreaKind, AreaTerm, Goal, Orientation, Pointer, Target, VertexRef};
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::Arc;

fn gripper() -> Task {
    Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap()
}

/// A graph of the gripper task with at least two internal vertices.
fn graph(task: &Task) -> CreaseGraph {
    let e = Enumeration::run(task, 2, Filters::all());
    e.meaningful()
        .map(|n| n.graph.clone())
        .find(|g| Plan::new(g).is_ok_and(|p| p.internal.len() >= 2))
        .expect("a level-2 graph with two internal vertices")
}

/// A point satisfying the gripper model's ψ (rigid over the motion), as a full variable
/// vector, with all modes +1.
fn rigid_point(task: &Task, graph: &CreaseGraph) -> (Vec<f64>, Vec<f64>) {
    let model = Model::new(graph, task, 0).unwrap();
    let compiled = CompiledModel::new(&model, &Options::default()).unwrap();
    let modes = vec![1.0; model.plan.internal.len()];
    let problem = Feasibility(ModelProblem::new(&model, &compiled, &modes));
    for seed in 0..40 {
        let opts = optimize::Options {
            starts: 1,
            seed,
            max_outer: 8,
            ..Default::default()
        };
        let sol = optimize::minimize(&problem, &opts);
        if sol.feasible {
            return (model.full_vars(&sol.x), modes);
        }
    }
    panic!("no feasible point");
}

fn target(t: f64, vertex: VertexRef, goal: Goal, weight: f64, entry: usize) -> Target {
    Target {
        t,
        vertex,
        goal,
        weight,
        entry,
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1.0)
}

/// The free variables of `model` taken from the full vector `full`.
fn free_of(model: &Model, full: &[f64]) -> Vec<f64> {
    model.free.iter().map(|&i| full[i]).collect()
}

/// Compiled = f64 path (≤ 1e-12 relative), and every gradient row against central
/// differences of the f64 path.
fn check_compiled_and_gradients(model: &Model, x: &[f64], modes: &[f64]) -> Evaluation {
    let compiled = CompiledModel::new(model, &Options::default()).unwrap();
    let problem = ModelProblem::new(model, &compiled, modes);
    let (n, m) = (problem.n_vars(), problem.n_constraints());
    let mut e = Evaluation::new(n, m);
    problem.eval(x, &mut e);
    let (f, g) = outputs_f64(model, x, modes);
    assert_eq!(g.len(), m);
    assert!(close(e.f, f, 1e-12), "objective {} vs {f}", e.f);
    for (k, (got, want)) in e.g.iter().zip(&g).enumerate() {
        assert!(close(*got, *want, 1e-12), "constraint {k}: {got} vs {want}");
    }
    for i in 0..n {
        let h = 1e-6 * (1.0 + x[i].abs());
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[i] += h;
        xm[i] -= h;
        let ((fp, gp), (fm, gm)) = (
            outputs_f64(model, &xp, modes),
            outputs_f64(model, &xm, modes),
        );
        let fd = (fp - fm) / (2.0 * h);
        assert!(
            (fd - e.df[i]).abs() <= 1e-6 * (1.0 + fd.abs()),
            "d objective / d x{i}: {} vs central difference {fd}",
            e.df[i]
        );
        for k in 0..m {
            let fd = (gp[k] - gm[k]) / (2.0 * h);
            let an = e.dg[k * n + i];
            assert!(
                (fd - an).abs() <= 1e-6 * (1.0 + fd.abs()),
                "d g{k} ({}) / d x{i}: {an} vs central difference {fd}",
                model.constraint_label(k)
            );
        }
    }
    e
}

/// The 3D position of vertex `v` at `t` on the f64 path.
fn position(model: &Model, full: &[f64], modes: &[f64], v: usize, t: f64) -> V3 {
    let ev = Evaluated::new(&model.plan, full.to_vec(), modes.to_vec());
    ev.coords(&ev.fold(t))[v]
}

#[test]
fn line_and_plane_targets_of_any_vertex() {
    let mut task = gripper();
    let g = graph(&task);
    let (full, modes) = rigid_point(&task, &g);
    let u = normalize([1.0, -2.0, 0.5]).unwrap();
    let nrm = normalize([0.3, 0.2, 1.0]).unwrap();
    let (lp, pp, tip_p) = ([0.2, 0.1, 0.4], [0.0, 0.5, 0.3], [0.5, 0.0, 0.8]);
    let o = task.objective.as_mut().unwrap();
    o.targets = vec![
        target(
            0.7,
            VertexRef::Successor(1),
            Goal::Line {
                point: lp,
                direction: u,
            },
            2.0,
            0,
        ),
        target(
            1.0,
            VertexRef::Last,
            Goal::Plane {
                point: pp,
                normal: nrm,
            },
            0.5,
            1,
        ),
        target(
            FRAC_PI_2,
            VertexRef::Tip,
            Goal::Point { point: tip_p },
            1.0,
            2,
        ),
    ];
    let model = Model::new(&g, &task, 0).unwrap();
    assert_eq!(model.combination, Combination::Smoothed);
    let x = free_of(&model, &full);
    let e = check_compiled_and_gradients(&model, &x, &modes);
    // Analytic distances from the f64 positions.
    let s2 = select::vertex(&model.plan, model.gripping, &VertexRef::Successor(1)).unwrap();
    let last = select::vertex(&model.plan, model.gripping, &VertexRef::Last).unwrap();
    let d_line = norm(cross(sub(position(&model, &full, &modes, s2, 0.7), lp), u));
    let d_plane = dot(sub(position(&model, &full, &modes, last, 1.0), pp), nrm).abs();
    let d_point = norm(sub(
        position(&model, &full, &modes, model.gripping, FRAC_PI_2),
        tip_p,
    ));
    let omega = 2.0 * d_line + 0.5 * d_plane + d_point;
    assert!(
        close(model.omega(&full, &modes), omega, 1e-12),
        "{} vs {omega}",
        model.omega(&full, &modes)
    );
    let eps2 = 1e-18;
    let smooth = 2.0 * (d_line * d_line + eps2).sqrt()
        + 0.5 * (d_plane * d_plane + eps2).sqrt()
        + (d_point * d_point + eps2).sqrt();
    assert!(close(e.f, smooth, 1e-12), "{} vs {smooth}", e.f);
    // The thesis's target keeps its point; the others have none.
    assert_eq!(model.targets[2].tip_point(), Some(tip_p));
    assert!(model.targets[0].tip_point().is_none() && model.targets[1].tip_point().is_none());
    // One line target alone: w² d².
    task.objective.as_mut().unwrap().targets.truncate(1);
    let one = Model::new(&g, &task, 0).unwrap();
    let (f, _) = outputs_f64(&one, &free_of(&one, &full), &modes);
    assert_eq!(one.combination, Combination::Squared);
    assert!(
        close(f, 4.0 * d_line * d_line, 1e-12),
        "{f} vs {}",
        4.0 * d_line * d_line
    );
}

/// A tilted square (two triangles) through `c` with unit normal `n`, half-width `r`.
fn square_mesh(c: V3, n: V3, r: f64) -> MeshObstacle {
    let a = normalize(cross(n, [1.0, 0.0, 0.0])).unwrap();
    let b = cross(n, a);
    let corner = |s: f64, t: f64| std::array::from_fn(|i| c[i] + r * (s * a[i] + t * b[i]));
    MeshObstacle {
        file: "square.stl".into(),
        scale: 1.0,
        translate: [0.0; 3],
        mesh: Some(Arc::new(TriangleMesh {
            vertices: vec![
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            closed: false,
        })),
    }
}

#[test]
fn surface_targets_add_the_nearest_triangle_numerically() {
    let mut task = gripper();
    let g = graph(&task);
    let (full, modes) = rigid_point(&task, &g);
    let n = normalize([0.1, -0.2, 1.0]).unwrap();
    let c = [0.3, 0.2, -0.4];
    let o = task.objective.as_mut().unwrap();
    o.surfaces = vec![square_mesh(c, n, 50.0)];
    o.targets = vec![target(
        FRAC_PI_2,
        VertexRef::Tip,
        Goal::Surface { index: 0 },
        1.5,
        0,
    )];
    let model = Model::new(&g, &task, 0).unwrap();
    assert_eq!(model.surface_aux_len(), 3);
    let x = free_of(&model, &full);
    let e = check_compiled_and_gradients(&model, &x, &modes);
    // Far inside the square: the distance is the plane's.
    let d = dot(
        sub(
            position(&model, &full, &modes, model.gripping, FRAC_PI_2),
            c,
        ),
        n,
    )
    .abs();
    assert!(close(model.omega(&full, &modes), 1.5 * d, 1e-12));
    assert!(
        close(e.f, 2.25 * d * d, 1e-12),
        "{} vs {}",
        e.f,
        2.25 * d * d
    );
    // Beside a point target and an area term, the surface term sits in `threshold − Ω`.
    let o = task.objective.as_mut().unwrap();
    o.targets.push(target(
        1.0,
        VertexRef::Tip,
        Goal::Point {
            point: [0.5, 0.5, 0.5],
        },
        1.0,
        1,
    ));
    o.area = Some(AreaTerm {
        kind: AreaKind::Flat,
        weight: 1.0,
        at_least: 0.0,
    });
    o.threshold = 10.0;
    let model = Model::new(&g, &task, 0).unwrap();
    let x = free_of(&model, &full);
    let e = check_compiled_and_gradients(&model, &x, &modes);
    let k = model.surface_destination().expect("Ω is a constraint");
    let omega_smooth = 10.0 - e.g[k];
    assert!(
        close(omega_smooth, model.omega(&full, &modes), 1e-8),
        "{omega_smooth}"
    );
}

/// The unit normal of a facet from its vertices' 3D positions (Newell's method: the
/// polygon is counter-clockwise in the flat state, so this is the paper's upper side).
fn facet_normal(model: &Model, coords: &[V3], f: usize) -> V3 {
    let poly = &model.plan.polygons[f].0;
    let mut s = [0.0; 3];
    for (k, &i) in poly.iter().enumerate() {
        let (p, q) = (coords[i], coords[poly[(k + 1) % poly.len()]]);
        s[0] += (p[1] - q[1]) * (p[2] + q[2]);
        s[1] += (p[2] - q[2]) * (p[0] + q[0]);
        s[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    normalize(s).unwrap()
}

#[test]
fn orientation_constraints_follow_the_angles_of_the_folded_pattern() {
    let mut task = gripper();
    let g = graph(&task);
    let (full, modes) = rigid_point(&task, &g);
    let o = |name: &str, vertex, of, direction, angle, tolerance, t: Vec<f64>| Orientation {
        name: name.into(),
        vertex,
        of,
        direction,
        angle,
        tolerance,
        t,
    };
    let down = [0.0, 0.0, -1.0];
    let tilted = normalize([1.0, 1.0, 0.5]).unwrap();
    task.requirements.orientations = vec![
        o(
            "tip",
            VertexRef::Tip,
            Pointer::Crease,
            down,
            0.3,
            0.1,
            vec![0.5, FRAC_PI_2],
        ),
        o(
            "left",
            VertexRef::Successor(1),
            Pointer::FacetLeft,
            tilted,
            1.0,
            0.2,
            vec![1.0],
        ),
        // angle − tol ≤ 0: only the upper side.
        o(
            "right",
            VertexRef::Tip,
            Pointer::FacetRight,
            [0.0, 0.0, 1.0],
            0.05,
            0.1,
            vec![1.2],
        ),
        // angle + tol ≥ π: only the lower side.
        o(
            "flip",
            VertexRef::Last,
            Pointer::Crease,
            down,
            3.1,
            0.1,
            vec![0.9],
        ),
    ];
    let model = Model::new(&g, &task, 0).unwrap();
    let x = free_of(&model, &full);
    check_compiled_and_gradients(&model, &x, &modes);
    let (_, gs) = outputs_f64(&model, &x, &modes);
    // 2 states × 2 sides + 2 sides + 1 + 1, the last constraints of the model.
    let ours = &gs[gs.len() - 8..];
    let first = gs.len() - 8;
    let ev = Evaluated::new(&model.plan, full.clone(), modes.clone());
    let mut k = 0;
    for req in &model.orientations {
        let c = &model.plan.creases[req.crease];
        for &t in &req.t {
            let coords = ev.coords(&ev.fold(t));
            let u = match req.of {
                Pointer::Crease => normalize(sub(coords[c.head], coords[c.tail])).unwrap(),
                Pointer::FacetLeft => facet_normal(&model, &coords, c.left),
                Pointer::FacetRight => facet_normal(&model, &coords, c.right),
            };
            let d = req.direction;
            let theta = norm(cross(u, d)).atan2(dot(u, d));
            if req.angle + req.tolerance < PI {
                let gk = ours[k];
                assert!((gk - (theta.cos() - (req.angle + req.tolerance).cos())).abs() <= 1e-9);
                assert_eq!(gk >= 0.0, theta <= req.angle + req.tolerance);
                assert!(model.constraint_label(first + k).contains(&req.name));
                k += 1;
            }
            if req.angle - req.tolerance > 0.0 {
                let gk = ours[k];
                assert!(((req.angle - req.tolerance).cos() - theta.cos() - gk).abs() <= 1e-9);
                assert_eq!(gk >= 0.0, theta >= req.angle - req.tolerance);
                assert!(model.constraint_label(first + k).contains(&req.name));
                k += 1;
            }
        }
    }
    assert_eq!(k, 8);
}

/// Shoelace area of the flat pattern's faces, from the numeric pattern.
fn flat_area(model: &Model, full: &[f64], modes: &[f64]) -> f64 {
    let p = Evaluated::new(&model.plan, full.to_vec(), modes.to_vec()).pattern(&[]);
    p.faces
        .iter()
        .map(|f| {
            (0..f.len())
                .map(|k| {
                    let (a, b) = (p.vertices[f[k]], p.vertices[f[(k + 1) % f.len()]]);
                    a[0] * b[1] - b[0] * a[1]
                })
                .sum::<f64>()
                / 2.0
        })
        .sum()
}

/// Footprint of every copy's vertices at `t` across the axis, by brute force.
fn brute_footprint(model: &Model, full: &[f64], modes: &[f64], t: f64) -> f64 {
    let ev = Evaluated::new(&model.plan, full.to_vec(), modes.to_vec());
    let coords = ev.coords(&ev.fold(t));
    let frame = area::footprint_frame(&model.copies);
    let all: Vec<V3> = (0..model.copies.n)
        .flat_map(|k| coords.iter().map(move |&p| (k, p)))
        .map(|(k, p)| model.copies.apply(k, p))
        .collect();
    frame
        .iter()
        .map(|&e| {
            let v = all.iter().map(|&p| dot(e, p));
            v.clone().fold(f64::NEG_INFINITY, f64::max) - v.fold(f64::INFINITY, f64::min)
        })
        .product()
}

#[test]
fn the_area_terms_and_their_constraints() {
    let mut task = gripper();
    let g = graph(&task);
    let (full, modes) = rigid_point(&task, &g);
    let tilted = Copies {
        n: 2,
        point: [0.3, 0.0, 0.0],
        direction: normalize([0.0, 1.0, 1.0]).unwrap(),
    };
    for copies in [Copies::about_z(3), tilted] {
        task.scene.copies = copies;
        for kind in [AreaKind::Flat, AreaKind::Packing { t: 1.1 }] {
            let o = task.objective.as_mut().unwrap();
            o.area = Some(AreaTerm {
                kind,
                weight: 2.0,
                at_least: 0.25,
            });
            let model = Model::new(&g, &task, 0).unwrap();
            assert!(all_starts(&model) && objective_target(&model) == f64::INFINITY);
            let x = free_of(&model, &full);
            let e = check_compiled_and_gradients(&model, &x, &modes);
            let flat = flat_area(&model, &full, &modes) * model.copies.n as f64;
            let want = match kind {
                AreaKind::Flat => flat,
                AreaKind::Packing { t } => flat / brute_footprint(&model, &full, &modes, t),
            };
            let a = model.area(&full, &modes).unwrap();
            assert!(close(a, want, 1e-12), "{kind:?}: {a} vs {want}");
            assert!(close(e.f, -2.0 * want, 1e-12));
            // The last constraints: threshold − Ω ≥ 0, then A − at_least ≥ 0.
            let m = e.g.len();
            assert!(close(e.g[m - 1], want - 0.25, 1e-12));
            assert!(model.constraint_label(m - 1).contains("area"));
            assert_eq!(model.surface_destination(), Some(m - 2));
            assert!(meets_target(&model, true, 0.0) && !meets_target(&model, false, 0.0));
        }
    }
}

#[test]
fn names_the_graph_lacks_are_errors_of_the_model() {
    let mut task = gripper();
    let g = graph(&task);
    let o = task.objective.as_mut().unwrap();
    o.targets[0].vertex = VertexRef::Initial {
        id: "v99".into(),
        index: 99,
    };
    let err = Model::new(&g, &task, 0).unwrap_err().to_string();
    assert!(
        err.contains("objective.targets[0]") && err.contains("v99"),
        "{err}"
    );
    // A surface goal without a loaded mesh.
    let o = task.objective.as_mut().unwrap();
    o.targets[0].vertex = VertexRef::Tip;
    o.targets[0].goal = Goal::Surface { index: 0 };
    let err = Model::new(&g, &task, 0).unwrap_err().to_string();
    assert!(err.contains("surface 0"), "{err}");
}

/// A bowl in one variable, minimum 1 at x = 0.3: every start meets an infinite target.
struct Bowl;

impl Problem for Bowl {
    fn n_vars(&self) -> usize {
        1
    }
    fn n_constraints(&self) -> usize {
        0
    }
    fn bounds(&self, _: usize) -> (f64, f64) {
        (-1.0, 1.0)
    }
    fn eval(&self, x: &[f64], out: &mut Evaluation) {
        out.f = 1.0 + (x[0] - 0.3).powi(2);
        out.df[0] = 2.0 * (x[0] - 0.3);
    }
}

#[test]
fn all_starts_runs_every_start() {
    let opts = optimize::Options {
        starts: 5,
        target: Some(f64::INFINITY),
        ..Default::default()
    };
    let first = optimize::minimize(&Bowl, &opts);
    assert!(first.met_target && first.starts_run == 1, "{first:?}");
    let every = optimize::minimize(
        &Bowl,
        &optimize::Options {
            all_starts: true,
            ..opts
        },
    );
    assert!(every.met_target && every.starts_run == 5, "{every:?}");
    assert!((every.x[0] - 0.3).abs() < 1e-4, "{every:?}");
}
