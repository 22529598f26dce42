//! The robustness block on the whole scene (issue 31): obstacles of every shape, copies of
//! any order about any axis, containment boxes and fold-angle limits. Tasks are built in
//! code from the gripper's (its models and targets) with the scene and requirements set
//! here.
//!
//! - every new constraint's gradient (through the compiled pullback) agrees with central
//!   differences of its value, planes held fixed;
//! - a design placed inside an obstacle (every shape) or outside a box is infeasible for the
//!   block, by at least what the separating-plane argument says, and one placed clear of it
//!   feasible;
//! - with 3 and 4 copies the block's clearance pairs (the arm against copies 1..=n/2) hold
//!   exactly when every two copies, measured facet by facet by the independent judge
//!   (`check::robustness::triangle_distance`), keep the clearance;
//! - the slot counts and their owners.

use std::f64::consts::PI;
use std::sync::Arc;

use foldsynth::check::robustness::triangle_distance;
use foldsynth::geom::V3;
use foldsynth::grammar::{Enumeration, Filters};
use foldsynth::kinematics::wrap_angle;
use foldsynth::model::Model;
use foldsynth::model::clearance::{Buffers, Effort, Group, PairKind, Plane, VRef};
use foldsynth::model::plan::Position;
use foldsynth::model::robust::{Level, RobustModel, RobustSpec, SlotOwner};
use foldsynth::model::select;
use foldsynth::scene::shapes::MeshObstacle;
use foldsynth::scene::{
    Containment, Copies, Cylinder, HalfSpace, Obstacle, OrientedBox, Scene, Shape, Sphere,
    TriangleMesh,
};
use foldsynth::task::Task;
use foldsynth::task::terms::{CreaseRef, FoldLimit, VertexRef};
use nalgebra::Vector3;

const GRIPPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml");

/// Plane fits that try hard: the max-margin plane, the separating axes when overlapping.
const FULL: Effort = Effort {
    enough: f64::INFINITY,
    iters: 64,
    tol: 1e-13,
    axes: true,
};

/// Up to `count` models of the gripper (depth 2) with a design inside their bounds
/// (`shift` moves it) and all modes +1.
fn models(task: &Task, count: usize, shift: f64) -> Vec<(Model, Vec<f64>, Vec<f64>)> {
    let enumeration = Enumeration::run(task, 2, Filters::all());
    let mut out = Vec::new();
    for node in enumeration.meaningful() {
        let n = node.graph.internal_count();
        for candidate in 0..3 {
            let Ok(model) = Model::new(&node.graph, task, candidate) else {
                continue;
            };
            let x: Vec<f64> = (0..model.free.len())
                .map(|i| {
                    let (lo, hi) = model.var_bounds(model.free[i]);
                    let u = (0.618_034 * (i + 1) as f64 + shift).fract();
                    lo + (hi - lo) * (0.2 + 0.6 * u)
                })
                .collect();
            out.push((model, x, vec![1.0; n]));
            if out.len() == count {
                return out;
            }
        }
    }
    out
}

fn spec_with(task: &Task, scene: Scene) -> RobustSpec {
    let mut spec = RobustSpec::from_task(task, 181);
    spec.scene = scene;
    spec
}

/// The planes the block fits at the values in `work` (far pairs none).
fn planes(block: &RobustModel, v: &foldsynth::model::robust::StateValues) -> Vec<Option<Plane>> {
    let mut planes = vec![None; block.pairs.pairs.len()];
    block.fit(
        v,
        &mut planes,
        |_| false,
        Level::Imposed,
        FULL,
        &mut Buffers::default(),
    );
    planes
}

/// The least value over the block's sampled states of the slots `pick` selects (∞ when none
/// was visited).
fn least(block: &RobustModel, x: &[f64], modes: &[f64], pick: impl Fn(SlotOwner) -> bool) -> f64 {
    let mut work = block.work();
    let mut least = f64::INFINITY;
    for t in block.base_times() {
        block.eval(x, modes, t, &mut work);
        let planes = planes(block, &work.values);
        block.visit(t, &work.values, &planes, Level::Imposed, |slot, _, h, _| {
            if pick(block.slot_owner(slot)) {
                least = least.min(h);
            }
        });
    }
    least
}

/// Every vertex of every copy at every sampled state: their box, and the position of
/// vertex `v` of the arm at the middle state.
fn extent(block: &RobustModel, x: &[f64], modes: &[f64], v: usize) -> (V3, V3, V3, f64) {
    let mut work = block.work();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let times = block.base_times();
    for &t in &times {
        block.eval(x, modes, t, &mut work);
        let s = &work.values.scene;
        for copy in 0..block.pairs.copies.n() {
            for vertex in 0..s.x.len() {
                let p = s.at(VRef { vertex, copy });
                for i in 0..3 {
                    lo[i] = lo[i].min(p[i]);
                    hi[i] = hi[i].max(p[i]);
                }
            }
        }
    }
    let t = times[times.len() / 2];
    block.eval(x, modes, t, &mut work);
    (lo, hi, work.values.scene.x[v], t)
}

fn tetrahedron(c: V3, size: f64) -> Shape {
    let vertices = vec![
        [c[0] + size, c[1] + size, c[2] + size],
        [c[0] + size, c[1] - size, c[2] - size],
        [c[0] - size, c[1] + size, c[2] - size],
        [c[0] - size, c[1] - size, c[2] + size],
    ];
    let mesh = TriangleMesh {
        vertices,
        triangles: vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
        closed: true,
    };
    Shape::Mesh(MeshObstacle {
        file: "tetrahedron.obj".into(),
        scale: 1.0,
        translate: [0.0; 3],
        mesh: Some(Arc::new(mesh)),
    })
}

fn obstacle(name: &str, shape: Shape) -> Obstacle {
    Obstacle {
        name: name.to_string(),
        shape,
    }
}

#[test]
fn inside_an_obstacle_or_outside_a_box_is_infeasible_and_clear_of_it_feasible() {
    let task = Task::load(GRIPPER).unwrap();
    let (model, x, modes) = models(&task, 1, 0.0).remove(0);
    let tilted = Copies {
        n: 3,
        point: [0.1, -0.05, 0.0],
        direction: {
            let l = (0.04_f64 + 0.01 + 1.0).sqrt();
            [0.2 / l, 0.1 / l, 1.0 / l]
        },
    };
    for copies in [Copies::default(), tilted] {
        let bare = Scene {
            copies,
            ..Scene::default()
        };
        let block = RobustModel::new(&model, spec_with(&task, bare.clone())).unwrap();
        let g = block.wall_gap(Level::Imposed);
        let (lo, hi, p, t_in) = extent(&block, &x, &modes, model.gripping);
        let mid = [0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])];
        let beyond = hi[0] + g + 0.02;
        let oriented = OrientedBox {
            center: p,
            half: [0.1, 0.15, 0.2],
            axes: foldsynth::scene::shapes::frame([1.0, 1.0, 0.0], [0.0, 0.3, 1.0]).unwrap(),
        };
        let shapes: Vec<(&str, Shape, Shape, f64)> = vec![
            (
                "sphere",
                Shape::Sphere(Sphere {
                    center: p,
                    radius: 0.2,
                }),
                Shape::Sphere(Sphere {
                    center: [beyond + 0.2, mid[0], mid[1]],
                    radius: 0.2,
                }),
                0.2,
            ),
            (
                "cylinder",
                Shape::Cylinder(Cylinder {
                    a: [p[0], p[1] - 0.3, p[2]],
                    b: [p[0], p[1] + 0.3, p[2]],
                    radius: 0.1,
                }),
                Shape::Cylinder(Cylinder {
                    a: [beyond + 0.1, lo[1], mid[1]],
                    b: [beyond + 0.1, hi[1], mid[1]],
                    radius: 0.1,
                }),
                0.1,
            ),
            (
                "box",
                Shape::Box(oriented),
                Shape::Box(OrientedBox::aligned(
                    [beyond, lo[1], lo[2]],
                    [beyond + 0.5, hi[1], hi[2]],
                )),
                0.0,
            ),
            (
                "mesh",
                tetrahedron(p, 0.15),
                tetrahedron([beyond + 0.3, mid[0], mid[1]], 0.3),
                0.0,
            ),
            (
                "halfspace",
                Shape::HalfSpace(HalfSpace {
                    point: p,
                    normal: [0.0, 0.0, 1.0],
                }),
                Shape::HalfSpace(HalfSpace {
                    point: [beyond, 0.0, 0.0],
                    normal: [-1.0, 0.0, 0.0],
                }),
                0.0,
            ),
        ];
        let of_obstacle = |o: SlotOwner, block: &RobustModel| match o {
            SlotOwner::Pair(q) => block.pairs.pairs[q].group == Group::Obstacle,
            SlotOwner::HalfSpace { .. } => true,
            _ => false,
        };
        for (kind, inside, clear, radius) in shapes {
            for (is_inside, shape) in [(true, inside), (false, clear)] {
                let mut scene = bare.clone();
                scene.obstacles.push(obstacle(kind, shape));
                let block = RobustModel::new(&model, spec_with(&task, scene)).unwrap();
                let h = least(&block, &x, &modes, |o| of_obstacle(o, &block));
                if is_inside {
                    // A vertex inside the piece's hull: no plane has it on one side and the
                    // hull `gap` beyond the other, and the two bounds fail by their sum at
                    // least (a half-space: the vertex on its boundary fails by g).
                    let gap = radius + g;
                    assert!(h <= -0.5 * gap + 1e-9, "{kind} inside, {copies:?}: {h}");
                } else {
                    assert!(h >= 0.0, "{kind} clear, {copies:?}: {h}");
                }
            }
        }
        // A box around every copy at every state, 0.02 beyond the wall gap: the least
        // room is exactly 0.02.
        let mut scene = bare.clone();
        let pad = g + 0.02;
        scene.containment.push(Containment {
            bounds: OrientedBox::aligned(
                [lo[0] - pad, lo[1] - pad, lo[2] - pad],
                [hi[0] + pad, hi[1] + pad, hi[2] + pad],
            ),
            t: None,
            name: "workspace".into(),
        });
        // A box at one state (not an evenly spaced one) that leaves the tip 0.1 outside.
        let t_box = 0.37 * model.t_max;
        let mut work = block.work();
        block.eval(&x, &modes, t_box, &mut work);
        let tip = work.values.scene.x[model.gripping];
        scene.containment.push(Containment {
            bounds: OrientedBox::aligned(
                [tip[0] - 1.0, tip[1] - 1.0, tip[2] - 1.0],
                [tip[0] - 0.1 - g, tip[1] + 1.0, tip[2] + 1.0],
            ),
            t: Some(t_box),
            name: "stowed".into(),
        });
        let block = RobustModel::new(&model, spec_with(&task, scene)).unwrap();
        let times = block.base_times();
        assert_eq!(times.len(), block.spec.states.max(2) + 1);
        assert_eq!(*times.last().unwrap(), t_box);
        let workspace = least(&block, &x, &modes, |o| {
            matches!(o, SlotOwner::Box { k: 0, .. })
        });
        assert!((workspace - 0.02).abs() < 1e-9, "{workspace}");
        let stowed = least(&block, &x, &modes, |o| {
            matches!(o, SlotOwner::Box { k: 1, .. })
        });
        assert!(stowed <= -0.1 + 1e-9, "{stowed}");
        // The stowed box only at its state.
        for &t in &times {
            block.eval(&x, &modes, t, &mut work);
            let mut seen = 0;
            block.visit_walls(t, &work.values, Level::Imposed, |slot, _, _| {
                if matches!(block.slot_owner(slot), SlotOwner::Box { k: 1, .. }) {
                    seen += 1;
                }
            });
            let n = block.pairs.copies.n() * work.values.scene.x.len();
            assert_eq!(seen, if t == t_box { 6 * n } else { 0 }, "t {t}");
        }
        let _ = t_in;
    }
}

#[test]
fn fold_limits_lower_the_crease_constraint() {
    let mut task = Task::load(GRIPPER).unwrap();
    let (model, x, modes) = models(&task, 1, 0.3).remove(0);
    let base = RobustModel::new(&model, RobustSpec::from_task(&task, 181)).unwrap();
    let mut work = base.work();
    let t = model.t_max;
    base.eval(&x, &modes, t, &mut work);
    let rho: Vec<f64> = work
        .values
        .rho
        .iter()
        .map(|r| wrap_angle(*r).abs())
        .collect();
    let biggest = rho.iter().cloned().fold(0.0, f64::max);
    assert!(biggest > 0.1, "{rho:?}");
    // Every crease limited to 0.9 of the largest fold, the tip's crease to 0.5 of it.
    task.requirements.max_fold = Some(0.9 * biggest);
    task.requirements.fold_limits = vec![FoldLimit {
        crease: CreaseRef::Into(VertexRef::Tip),
        max: 0.5 * biggest,
    }];
    let block = RobustModel::new(&model, RobustSpec::from_task(&task, 181)).unwrap();
    let tip_crease = select::crease(
        &model.plan,
        model.gripping,
        &CreaseRef::Into(VertexRef::Tip),
    )
    .unwrap();
    let mut seen = 0;
    block.eval(&x, &modes, t, &mut work);
    let lim = PI - block.crease_gap(Level::Imposed);
    block.visit_rest(t, &work.values, Level::Imposed, |slot, h, _| {
        if let SlotOwner::Crease(c) = block.slot_owner(slot) {
            let m = if block.creases[c] == tip_crease {
                0.5 * biggest
            } else {
                0.9 * biggest
            };
            let want = lim.min(m / 1.01 - 1e-6) - rho[c];
            assert!((h - want).abs() < 1e-12, "crease {c}: {h} vs {want}");
            seen += 1;
        }
    });
    assert_eq!(seen, block.creases.len());
    for c in 0..block.creases.len() {
        let m = block.fold_limits[c].unwrap();
        let setting = PI - block.crease_gap(Level::Setting);
        assert_eq!(block.crease_limit(c, Level::Setting), setting.min(m));
    }
    // The largest fold breaks the limit: the block says so at t_max.
    let h = least(&block, &x, &modes, |o| matches!(o, SlotOwner::Crease(_)));
    assert!(h <= 0.9 * biggest / 1.01 - 1e-6 - biggest + 1e-12, "{h}");
    // A limit naming a crease the graph does not have is an error, not a panic.
    task.requirements.fold_limits = vec![FoldLimit {
        crease: CreaseRef::Initial {
            name: "v7-v9".into(),
            a: 6,
            b: 8,
        },
        max: 1.0,
    }];
    assert!(RobustModel::new(&model, RobustSpec::from_task(&task, 181)).is_err());
}

/// Every kind of new slot at one state: its value's gradient, assembled from the slot's
/// dependencies and pulled back through the compiled kinematics, against central
/// differences of the value with the planes held fixed. Copies: four about a tilted axis
/// (rotations by Rodrigues' formula, pairs with copies 1 and 2); obstacles of every shape
/// next to the pattern; a half-space through it; a box around it; fold limits.
#[test]
fn new_constraints_gradients_match_central_differences() {
    let mut task = Task::load(GRIPPER).unwrap();
    task.requirements.max_fold = Some(2.0);
    let copies = Copies {
        n: 4,
        point: [0.05, 0.02, 0.0],
        direction: {
            let l = (0.01_f64 + 0.04 + 1.0).sqrt();
            [-0.1 / l, 0.2 / l, 1.0 / l]
        },
    };
    let mut checked: Vec<&str> = Vec::new();
    for (model, x, modes) in models(&task, 3, 0.1) {
        let bare = RobustModel::new(
            &model,
            spec_with(
                &task,
                Scene {
                    copies,
                    ..Scene::default()
                },
            ),
        )
        .unwrap();
        let (lo, hi, p, t) = extent(&bare, &x, &modes, model.gripping);
        let c = [
            0.5 * (lo[0] + hi[0]),
            0.5 * (lo[1] + hi[1]),
            0.5 * (lo[2] + hi[2]),
        ];
        let near = [p[0] + 0.05, p[1] - 0.04, p[2] + 0.12];
        let scene = Scene {
            copies,
            obstacles: vec![
                obstacle(
                    "sphere",
                    Shape::Sphere(Sphere {
                        center: near,
                        radius: 0.05,
                    }),
                ),
                obstacle(
                    "cylinder",
                    Shape::Cylinder(Cylinder {
                        a: [near[0] - 0.3, near[1], near[2] + 0.1],
                        b: [near[0] + 0.3, near[1] + 0.1, near[2] + 0.1],
                        radius: 0.04,
                    }),
                ),
                obstacle(
                    "box",
                    Shape::Box(OrientedBox {
                        center: [near[0], near[1] + 0.1, near[2] - 0.2],
                        half: [0.05, 0.08, 0.06],
                        axes: foldsynth::scene::shapes::frame([1.0, 0.2, 0.1], [0.0, 1.0, 0.3])
                            .unwrap(),
                    }),
                ),
                obstacle("mesh", tetrahedron([near[0] - 0.1, near[1], near[2]], 0.07)),
                obstacle(
                    "halfspace",
                    Shape::HalfSpace(HalfSpace {
                        point: c,
                        normal: [0.6, 0.0, 0.8],
                    }),
                ),
                // Next to copy 1's tip: the copy's pairs with it get planes.
                obstacle(
                    "copy sphere",
                    Shape::Sphere(Sphere {
                        center: copies.apply(1, near),
                        radius: 0.05,
                    }),
                ),
            ],
            containment: vec![Containment {
                bounds: OrientedBox {
                    center: c,
                    half: [
                        0.5 * (hi[0] - lo[0]),
                        0.4 * (hi[1] - lo[1]),
                        0.5 * (hi[2] - lo[2]),
                    ],
                    axes: foldsynth::scene::shapes::frame([1.0, 0.1, 0.0], [0.0, 1.0, 0.2])
                        .unwrap(),
                },
                t: None,
                name: "inside[0]".into(),
            }],
        };
        let block = RobustModel::new(&model, spec_with(&task, scene)).unwrap();
        let mut work = block.work();
        block.eval(&x, &modes, t, &mut work);
        let planes = planes(&block, &work.values);
        // The slots to check: up to two of each kind.
        let kind = |slot: usize| -> Option<&'static str> {
            match block.slot_owner(slot) {
                SlotOwner::Pair(q) => {
                    let pair = &block.pairs.pairs[q];
                    match (pair.group, pair.kind) {
                        (Group::Obstacle, PairKind::Obstacle { k, .. }) => {
                            let o = block.pairs.obstacles[k].obstacle;
                            let name = match block.spec.scene.obstacles[o].name.as_str() {
                                "sphere" => "sphere",
                                "cylinder" => "cylinder",
                                "box" => "box",
                                "mesh" => "mesh",
                                _ => "other",
                            };
                            Some(if pair.a.1 > 0 { "copy obstacle" } else { name })
                        }
                        (Group::Arm, _) => Some(match pair.b.unwrap().1 {
                            1 => "copy 1",
                            _ => "copy 2",
                        }),
                        _ => None,
                    }
                }
                SlotOwner::Crease(_) => Some("fold limit"),
                SlotOwner::HalfSpace { copy, .. } => Some(if copy > 0 {
                    "copy halfspace"
                } else {
                    "halfspace"
                }),
                SlotOwner::Box { .. } => Some("containment"),
                SlotOwner::Margin(_) => None,
            }
        };
        let mut chosen: Vec<(usize, &str, Vec<f64>)> = Vec::new();
        let nw = block.n_weights();
        block.visit(
            t,
            &work.values,
            &planes,
            Level::Imposed,
            |slot, _, _, dep| {
                let Some(k) = kind(slot) else { return };
                if chosen.iter().filter(|(_, c, _)| *c == k).count() < 2 {
                    let mut w = vec![0.0; nw];
                    block.add_weights(dep, 1.0, &mut w);
                    chosen.push((slot, k, w));
                }
            },
        );
        let value = |x: &[f64], slot: usize, work: &mut foldsynth::model::robust::Work| {
            block.eval(x, &modes, t, work);
            let mut v = f64::NAN;
            block.visit(t, &work.values, &planes, Level::Imposed, |s, _, h, _| {
                if s == slot {
                    v = h;
                }
            });
            v
        };
        for (slot, k, w) in &chosen {
            let mut g = vec![0.0; x.len()];
            block.pullback(&x, &modes, t, w, &mut work, &mut g);
            for i in 0..x.len() {
                let fd = central_difference(g[i], |d| {
                    let mut xd = x.clone();
                    xd[i] += d;
                    value(&xd, *slot, &mut work)
                });
                assert!(
                    (fd - g[i]).abs() <= 1e-6 * (1.0 + g[i].abs()),
                    "{k} slot {slot} ({}), x{i}: {} vs central differences {fd}",
                    block.slot_label(*slot),
                    g[i]
                );
            }
            if !checked.contains(k) {
                checked.push(k);
            }
        }
    }
    for k in [
        "sphere",
        "cylinder",
        "box",
        "mesh",
        "copy obstacle",
        "copy 1",
        "copy 2",
        "fold limit",
        "halfspace",
        "copy halfspace",
        "containment",
    ] {
        assert!(checked.contains(&k), "no {k} slot was checked: {checked:?}");
    }
}

/// With n copies about z, the block's clearance pairs between copies (the arm against
/// copies 1..=n/2, apart pairs: no shared vertex, not both at the tips) hold at the
/// setting exactly when every two copies' facets of that kind keep the clearance, measured
/// by the independent judge on every pair of copies (i, j), i < j.
#[test]
fn three_and_four_copies_keep_their_clearance() {
    let task = Task::load(GRIPPER).unwrap();
    let mut verdicts = [0usize; 2];
    for (n, clearance) in [(3, 0.05), (4, 0.05), (3, 0.5), (4, 0.5)] {
        for shift in [0.0, 0.25, 0.5] {
            for (model, x, modes) in models(&task, 4, shift) {
                let mut spec = spec_with(
                    &task,
                    Scene {
                        copies: Copies::about_z(n),
                        ..Scene::default()
                    },
                );
                spec.settings.clearance = clearance;
                let block = RobustModel::new(&model, spec).unwrap();
                let plan = &model.plan;
                let on_axis = |v: usize| matches!(plan.vertices[v].position, Position::Fixed(p) if p[0].hypot(p[1]) < 1e-9);
                let tip = block
                    .pairs
                    .pairs
                    .iter()
                    .any(|p| matches!(p.kind, PairKind::Cone { a, b } if a.copy != b.copy))
                    .then_some(model.gripping);
                let facets = &block.pairs.facets;
                let mut work = block.work();
                for t in block.base_times().into_iter().filter(|t| *t > 0.0) {
                    block.eval(&x, &modes, t, &mut work);
                    let mut planes = vec![None; block.pairs.pairs.len()];
                    block.fit(
                        &work.values,
                        &mut planes,
                        |_| true,
                        Level::Setting,
                        FULL,
                        &mut Buffers::default(),
                    );
                    let mut holds = true;
                    for (q, pair) in block.pairs.pairs.iter().enumerate() {
                        if pair.group != Group::Arm || pair.kind != PairKind::Apart {
                            continue;
                        }
                        block.visit_pair(
                            q,
                            planes[q].as_ref().unwrap(),
                            &work.values,
                            Level::Setting,
                            |c| {
                                holds &= c.h >= 0.0;
                            },
                        );
                    }
                    // The judge: every two copies, every two facets not sharing a vertex
                    // on the axis and not both at the tips.
                    let s = &work.values.scene;
                    let tris = |f: usize, copy: usize| -> Vec<[Vector3<f64>; 3]> {
                        let vs = &facets[f].1;
                        let at = |v: usize| {
                            let p = s.at(VRef { vertex: v, copy });
                            Vector3::new(p[0], p[1], p[2])
                        };
                        (1..vs.len() - 1)
                            .map(|i| [at(vs[0]), at(vs[i]), at(vs[i + 1])])
                            .collect()
                    };
                    let mut least = f64::INFINITY;
                    for i in 0..n {
                        for j in i + 1..n {
                            for (f, (_, vf)) in facets.iter().enumerate() {
                                for (g, (_, vg)) in facets.iter().enumerate() {
                                    let shared = vf.iter().any(|v| on_axis(*v) && vg.contains(v));
                                    let tips =
                                        tip.is_some_and(|g| vf.contains(&g) && vg.contains(&g));
                                    if shared || tips {
                                        continue;
                                    }
                                    for a in tris(f, i) {
                                        for b in tris(g, j) {
                                            least = least.min(triangle_distance(&a, &b));
                                        }
                                    }
                                }
                            }
                        }
                    }
                    if least > clearance + 1e-7 {
                        assert!(
                            holds,
                            "n {n}, t {t}: copies {least} apart, the block refuses"
                        );
                        verdicts[0] += 1;
                    } else if least < clearance - 1e-7 {
                        assert!(
                            !holds,
                            "n {n}, t {t}: copies {least} apart, the block accepts"
                        );
                        verdicts[1] += 1;
                    }
                }
            }
        }
    }
    assert!(verdicts[0] > 0 && verdicts[1] > 0, "{verdicts:?}");
}

/// The slots: pairs', creases', margins', one per half-space, copy and vertex, six per
/// box, copy and vertex; each owned as counted, and labelled with the obstacle's name.
#[test]
fn slot_counts_and_owners() {
    let task = Task::load(GRIPPER).unwrap();
    let (model, _, _) = models(&task, 1, 0.0).remove(0);
    let scene = Scene {
        copies: Copies::about_z(3),
        obstacles: vec![
            obstacle(
                "table",
                Shape::HalfSpace(HalfSpace {
                    point: [0.0, 0.0, -1.0],
                    normal: [0.0, 0.0, 1.0],
                }),
            ),
            obstacle(
                "ball",
                Shape::Sphere(Sphere {
                    center: [0.0, 0.0, 3.0],
                    radius: 0.5,
                }),
            ),
            obstacle("part", tetrahedron([2.0, 0.0, 1.0], 0.3)),
        ],
        containment: vec![Containment {
            bounds: OrientedBox::aligned([-3.0; 3], [3.0; 3]),
            t: None,
            name: "cell".into(),
        }],
    };
    let block = RobustModel::new(&model, spec_with(&task, scene)).unwrap();
    let nv = model.plan.vertices.len();
    let ni = model.plan.internal.len();
    let nf = block.pairs.facets.len();
    // The ball is on the axis: the copies' pairs with it are the arm's turned. The
    // tetrahedron is not: 3 copies × 4 triangles.
    let obstacle_pairs = block
        .pairs
        .pairs
        .iter()
        .filter(|p| p.group == Group::Obstacle)
        .count();
    assert_eq!(obstacle_pairs, nf + 3 * 4 * nf);
    let wall = 3 * nv + 6 * 3 * nv;
    assert_eq!(
        block.slots(),
        block.pairs.slots + block.creases.len() + 3 * ni + wall
    );
    let mut counts = [0usize; 5];
    for slot in 0..block.slots() {
        let label = block.slot_label(slot);
        match block.slot_owner(slot) {
            SlotOwner::Pair(q) => {
                let p = &block.pairs.pairs[q];
                assert!(slot >= p.slot && slot < p.slot + p.slots());
                counts[0] += 1;
            }
            SlotOwner::Crease(_) => counts[1] += 1,
            SlotOwner::Margin(_) => counts[2] += 1,
            SlotOwner::HalfSpace { k, copy, vertex } => {
                assert_eq!(k, 0);
                assert!(copy < 3 && vertex < nv);
                assert!(label.starts_with("table"), "{label}");
                counts[3] += 1;
            }
            SlotOwner::Box {
                k,
                copy,
                vertex,
                wall,
            } => {
                assert!(k == 0 && copy < 3 && vertex < nv && wall < 6);
                assert!(label.starts_with("cell"), "{label}");
                counts[4] += 1;
            }
        }
    }
    assert_eq!(
        counts,
        [
            block.pairs.slots,
            block.creases.len(),
            3 * ni,
            3 * nv,
            18 * nv
        ]
    );
}

/// Central differences of `f` at 0 (Richardson-extrapolated from steps h and h/2) for steps
/// h = 1e-4 … 1e-7, each compared with the gradient `g`: the estimate closest to `g` (as in
/// `robust_constraints.rs`).
fn central_difference(g: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
    let mut diff = |h: f64| (f(h) - f(-h)) / (2.0 * h);
    let mut best = f64::NAN;
    for h in [1e-4, 1e-5, 1e-6, 1e-7] {
        let (coarse, fine) = (diff(h), diff(h / 2.0));
        let fd = (4.0 * fine - coarse) / 3.0;
        if best.is_nan() || (fd - g).abs() < (best - g).abs() {
            best = fd;
        }
    }
    best
}

/// A closed UV sphere of `slices · 2 · (stacks − 1)` triangles.
fn uv_sphere(c: V3, r: f64, slices: usize, stacks: usize) -> TriangleMesh {
    let mut vertices = vec![[c[0], c[1], c[2] + r]];
    for i in 1..stacks {
        let th = PI * i as f64 / stacks as f64;
        for j in 0..slices {
            let ph = 2.0 * PI * j as f64 / slices as f64;
            vertices.push([
                c[0] + r * th.sin() * ph.cos(),
                c[1] + r * th.sin() * ph.sin(),
                c[2] + r * th.cos(),
            ]);
        }
    }
    vertices.push([c[0], c[1], c[2] - r]);
    let ring = |i: usize, j: usize| (1 + (i - 1) * slices + j % slices) as u32;
    let bottom = (vertices.len() - 1) as u32;
    let mut triangles = Vec::new();
    for j in 0..slices {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
        triangles.push([bottom, ring(stacks - 1, j + 1), ring(stacks - 1, j)]);
    }
    for i in 1..stacks - 1 {
        for j in 0..slices {
            triangles.push([ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)]);
            triangles.push([ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)]);
        }
    }
    TriangleMesh {
        vertices,
        triangles,
        closed: true,
    }
}

/// A 5,000-triangle mesh next to the pattern: every triangle is a piece with its own
/// pairs, but only those whose bounding ball comes within reach of a facet's get a plane;
/// the time a state's fit takes is printed (debug build).
#[test]
fn a_large_mesh_fits_planes_only_near_the_pattern() {
    use foldsynth::model::robust::ACTIVATE;
    use std::time::Instant;
    let task = Task::load(GRIPPER).unwrap();
    let (model, x, modes) = models(&task, 1, 0.0).remove(0);
    let bare = RobustModel::new(&model, spec_with(&task, Scene::default())).unwrap();
    let (_, _, p, t) = extent(&bare, &x, &modes, model.gripping);
    let mesh = uv_sphere([p[0], p[1], p[2] + 0.55], 0.5, 50, 51);
    assert_eq!(mesh.triangles.len(), 5000);
    let tris: Vec<[V3; 3]> = (0..mesh.triangles.len())
        .map(|i| mesh.triangle(i))
        .collect();
    let scene = Scene {
        obstacles: vec![obstacle(
            "part",
            Shape::Mesh(MeshObstacle {
                file: "part.stl".into(),
                scale: 1.0,
                translate: [0.0; 3],
                mesh: Some(Arc::new(mesh)),
            }),
        )],
        ..Scene::default()
    };
    let block = RobustModel::new(&model, spec_with(&task, scene)).unwrap();
    let nf = block.pairs.facets.len();
    assert_eq!(block.pairs.pairs.len(), bare.pairs.pairs.len() + 5000 * nf);
    let mut work = block.work();
    block.eval(&x, &modes, t, &mut work);
    let mut planes = vec![None; block.pairs.pairs.len()];
    let mut buffers = Buffers::default();
    let start = Instant::now();
    let reps = 5;
    for _ in 0..reps {
        planes.iter_mut().for_each(|p| *p = None);
        block.fit(
            &work.values,
            &mut planes,
            |_| false,
            Level::Imposed,
            FULL,
            &mut buffers,
        );
    }
    let per_state = start.elapsed().as_secs_f64() / reps as f64;
    let base = bare.pairs.pairs.len();
    let fitted = planes[base..].iter().filter(|p| p.is_some()).count();
    // Within reach by the triangles' own balls (centroid, farthest corner): an upper bound
    // on the pairs the block may fit.
    let need = block.wall_gap(Level::Imposed) + ACTIVATE;
    let s = &work.values.scene;
    let mut reach = 0;
    for f in 0..nf {
        let (c, r) = s.sphere(f, 0, nf);
        for tri in &tris {
            let m = [0, 1, 2].map(|i| (tri[0][i] + tri[1][i] + tri[2][i]) / 3.0);
            let d = |a: V3, b: V3| {
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
            };
            let rt = tri.iter().map(|q| d(*q, m)).fold(0.0, f64::max);
            if d(c, m) - rt - r <= need + 1e-9 {
                reach += 1;
            }
        }
    }
    eprintln!(
        "5000-triangle mesh, {nf} facets: {fitted} planes fitted of {} pairs ({reach} within \
         reach by balls), fit {:.2} ms per state (debug build)",
        5000 * nf,
        per_state * 1e3
    );
    assert!(
        fitted > 0 && fitted <= reach,
        "{fitted} fitted, {reach} within reach"
    );
    assert!(reach < 5000 * nf / 4, "the mesh is mostly far: {reach}");
}
