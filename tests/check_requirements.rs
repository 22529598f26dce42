//! The requirement judges of `check::requirements` and the copies of `check::copies` on
//! hand-built patterns whose answers are known in closed form.

use std::f64::consts::{FRAC_PI_2, PI};

use foldsynth::check::copies::{copy_crossings, with_copies};
use foldsynth::check::requirements::{
    JudgeInput, box_wall_distance, crease_fold_angle, creases, judge, judge_containment,
    judge_folds, judge_orientation, judge_targets, pointer_direction,
};
use foldsynth::check::two_armed;
use foldsynth::pattern::{Edge, EdgeKind, Frame, Pattern};
use foldsynth::scene::{
    Containment, Copies, HalfSpace, Obstacle, OrientedBox, Scene, Shape, Sphere,
};
use foldsynth::task::terms::{
    AreaKind, AreaTerm, CreaseRef, FoldLimit, Goal, Objective, Orientation, Pointer, Requirements,
    Target, VertexRef,
};

/// Two unit squares hinged along the y-axis (crease 0 → 3); the left one (vertices 4, 5)
/// turns up by t about it: its far edge is at x = −cos t, z = sin t.
fn hinge(ts: &[f64]) -> Pattern {
    let vertices = vec![
        [0.0, 0.0],
        [1.0, 0.0],
        [1.0, 1.0],
        [0.0, 1.0],
        [-1.0, 1.0],
        [-1.0, 0.0],
    ];
    let b = |a: usize, c: usize| Edge {
        v: [a, c],
        kind: EdgeKind::Boundary,
    };
    let edges = vec![
        b(0, 1),
        b(1, 2),
        b(2, 3),
        Edge {
            v: [0, 3],
            kind: EdgeKind::Crease { driven: true },
        },
        b(3, 4),
        b(4, 5),
        b(5, 0),
    ];
    let frames = ts
        .iter()
        .map(|&t| Frame {
            t,
            coords: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
                [-t.cos(), 1.0, t.sin()],
                [-t.cos(), 0.0, t.sin()],
            ],
            fold_angles: Vec::new(),
        })
        .collect();
    Pattern {
        vertices,
        edges,
        faces: vec![vec![0, 1, 2, 3], vec![0, 3, 4, 5]],
        frames,
    }
}

/// Whether two points agree to 1e-12 in every coordinate.
fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-12)
}

const TS: [f64; 4] = [0.0, 0.5, 1.2, 0.9];

#[test]
fn fold_angle_of_the_hinge_is_t() {
    let p = hinge(&TS);
    assert_eq!(creases(&p), vec![(0, 3)]);
    for fr in &p.frames {
        let rho = crease_fold_angle(&p, &fr.coords, 0, 3).unwrap();
        assert!((rho.abs() - fr.t).abs() < 1e-12, "{rho} at {}", fr.t);
    }
    let r = judge_folds(&p, &creases(&p), "every crease", 1.0);
    assert!((r.largest.unwrap() - 1.2).abs() < 1e-12);
    assert_eq!(r.t, Some(1.2));
    assert!(!r.holds);
    assert!(judge_folds(&p, &[(0, 3)], "tip", 1.25).holds);
    // Not a crease between two facets: not measured, does not hold.
    assert!(!judge_folds(&p, &[(0, 1)], "v1-v2", 3.0).holds);
}

fn orientation(of: Pointer, direction: [f64; 3], angle: f64, t: Vec<f64>) -> Orientation {
    Orientation {
        name: "o".into(),
        vertex: VertexRef::Tip,
        of,
        direction,
        angle,
        tolerance: 0.01,
        t,
    }
}

#[test]
fn orientation_of_the_folding_facet() {
    let p = hinge(&TS);
    // The facet left of 0 → 3 is the folding one; its upward normal is (sin t, 0, cos t),
    // at π/2 − t from +x.
    let n = pointer_direction(&p, &p.frames[2].coords, Pointer::FacetLeft, 0, 3).unwrap();
    let want = [1.2f64.sin(), 0.0, 1.2f64.cos()];
    assert!(close(n, want), "{n:?}");
    // The right facet stays flat, normal +z.
    let n = pointer_direction(&p, &p.frames[2].coords, Pointer::FacetRight, 0, 3).unwrap();
    assert!((n[2] - 1.0).abs() < 1e-15);
    let o = orientation(
        Pointer::FacetLeft,
        [1.0, 0.0, 0.0],
        FRAC_PI_2 - 1.2,
        vec![1.2],
    );
    let r = judge_orientation(&p, &o, 0, 3);
    assert!(r.holds && r.worst_error.unwrap() < 1e-12, "{r:?}");
    // Also at t = 0.5: off by 0.7 there.
    let o = orientation(
        Pointer::FacetLeft,
        [1.0, 0.0, 0.0],
        FRAC_PI_2 - 1.2,
        vec![1.2, 0.5],
    );
    let r = judge_orientation(&p, &o, 0, 3);
    assert!(!r.holds && (r.worst_error.unwrap() - 0.7).abs() < 1e-12 && r.t == Some(0.5));
    // The crease points along +y at every state; a t without a frame fails.
    let o = orientation(Pointer::Crease, [0.0, -1.0, 0.0], PI, vec![0.0, 0.9]);
    assert!(judge_orientation(&p, &o, 0, 3).holds);
    let o = orientation(Pointer::Crease, [0.0, 1.0, 0.0], 0.0, vec![0.7]);
    let r = judge_orientation(&p, &o, 0, 3);
    assert!(!r.holds && r.missing == vec![0.7]);
}

#[test]
fn containment_is_the_least_wall_distance() {
    let b = OrientedBox::aligned([-0.5, -1.0, -1.0], [1.5, 2.0, 2.0]);
    assert!((box_wall_distance(&b, [0.0, 0.0, 0.0]) - 0.5).abs() < 1e-15);
    assert!((box_wall_distance(&b, [-1.5, 3.0, 0.0]) + 2f64.sqrt()).abs() < 1e-15);
    let p = hinge(&TS);
    // At t = 1.2 the folding edge is at x = −cos 1.2, inside by 0.5 − cos 1.2.
    let at = Containment {
        bounds: b,
        t: Some(1.2),
        name: "stowed".into(),
    };
    let r = judge_containment(&p, &at, 0.1);
    assert!(
        (r.least.unwrap() - (0.5 - 1.2f64.cos())).abs() < 1e-12,
        "{r:?}"
    );
    assert!(r.holds && r.vertex == Some(4));
    // Over the whole motion: flat, x = −1 is outside by 0.5.
    let always = Containment { t: None, ..at };
    let r = judge_containment(&p, &always, 0.0);
    assert!((r.least.unwrap() + 0.5).abs() < 1e-12 && r.t == Some(0.0) && !r.holds);
}

fn target(t: f64, goal: Goal, weight: f64) -> Target {
    Target {
        t,
        vertex: VertexRef::Tip,
        goal,
        weight,
        entry: 0,
    }
}

#[test]
fn targets_omega_from_the_positions() {
    let p = hinge(&TS);
    let s = 1.2f64.sin();
    // Vertex 4 at t = 1.2 is (−cos t, 1, sin t): 1 from (0, 1, 0) and from the y-axis,
    // sin t above the plane z = 0.
    let objective = Objective {
        targets: vec![
            target(
                1.2,
                Goal::Point {
                    point: [0.0, 1.0, 0.0],
                },
                1.0,
            ),
            target(
                1.2,
                Goal::Line {
                    point: [0.0, 5.0, 0.0],
                    direction: [0.0, 1.0, 0.0],
                },
                2.0,
            ),
            target(
                1.2,
                Goal::Plane {
                    point: [3.0, 3.0, 0.0],
                    normal: [0.0, 0.0, 1.0],
                },
                0.5,
            ),
        ],
        threshold: 3.0,
        surfaces: Vec::new(),
        area: None,
    };
    let r = judge_targets(&p, &objective, &[4, 4, 4]);
    let want = 1.0 + 2.0 + 0.5 * s;
    assert!((r.omega.unwrap() - want).abs() < 1e-12, "{r:?}");
    assert!(!r.meets);
}

fn obstacle(name: &str, shape: Shape) -> Obstacle {
    Obstacle {
        name: name.into(),
        shape,
    }
}

#[test]
fn judge_collects_every_term() {
    let p = hinge(&TS);
    let scene = Scene {
        obstacles: vec![
            // Below the flat facet: 1 − 0.5 from it.
            obstacle(
                "ball",
                Shape::Sphere(Sphere {
                    center: [0.5, 0.5, -1.0],
                    radius: 0.5,
                }),
            ),
            obstacle(
                "table",
                Shape::HalfSpace(HalfSpace {
                    point: [0.0, 0.0, -0.25],
                    normal: [0.0, 0.0, 1.0],
                }),
            ),
            // Beside the edge x = 1 of the flat facet.
            obstacle(
                "crate",
                Shape::Box(OrientedBox::aligned([2.0, 0.0, 0.0], [3.0, 1.0, 1.0])),
            ),
        ],
        copies: Copies::default(),
        containment: vec![Containment {
            bounds: OrientedBox::aligned([-2.0; 3], [2.0; 3]),
            t: None,
            name: "workspace".into(),
        }],
    };
    let requirements = Requirements {
        orientations: vec![orientation(
            Pointer::Crease,
            [0.0, 1.0, 0.0],
            0.0,
            vec![1.2],
        )],
        max_fold: Some(1.0),
        fold_limits: vec![FoldLimit {
            crease: CreaseRef::Into(VertexRef::Tip),
            max: 1.5,
        }],
    };
    let objective = Objective {
        targets: vec![target(
            1.2,
            Goal::Point {
                point: [0.0, 1.0, 0.0],
            },
            1.0,
        )],
        threshold: 1.5,
        surfaces: Vec::new(),
        area: Some(AreaTerm {
            kind: AreaKind::Flat,
            weight: 1.0,
            at_least: 1.5,
        }),
    };
    let input = JudgeInput {
        arm: &p,
        scene: &scene,
        requirements: &requirements,
        objective: Some(&objective),
        orientation_creases: vec![(0, 3)],
        fold_limit_creases: vec![(0, 3)],
        target_vertices: vec![4],
        obstacle_clearance: 0.2,
    };
    let r = judge(&input).unwrap();
    let least = |k: usize| r.obstacles[k].least.unwrap();
    assert!((least(0) - 0.5).abs() < 1e-12, "{:?}", r.obstacles[0]);
    assert!((least(1) - 0.25).abs() < 1e-12);
    assert!((least(2) - 1.0).abs() < 1e-12);
    assert!(r.obstacles.iter().all(|o| o.holds && !o.hit));
    assert!((r.containment[0].least.unwrap() - 1.0).abs() < 1e-12);
    assert!(r.orientations[0].holds && r.fold_limits[0].holds);
    // max_fold 1.0 < 1.2 fails; the rest hold; Ω = 1 meets 1.5; area 2 meets 1.5.
    assert!(!r.max_fold.as_ref().unwrap().holds);
    assert_eq!(r.failed.len(), 1, "{:?}", r.failed);
    assert!(r.failed[0].starts_with("fold limit every crease"));
    assert!(!r.holds && !r.meets_target());
    assert!((r.targets.as_ref().unwrap().omega.unwrap() - 1.0).abs() < 1e-12);
    assert_eq!(r.area.as_ref().unwrap().value, Some(2.0));
    // The report goes through JSON and back.
    let json = serde_json::to_string(&r).unwrap();
    let back: foldsynth::check::requirements::RequirementsReport =
        serde_json::from_str(&json).unwrap();
    assert_eq!(back, r);
    // Indices that do not match the terms are an error, not a panic.
    let bad = JudgeInput {
        target_vertices: vec![40],
        ..input.clone()
    };
    assert!(judge(&bad).is_err());
    let bad = JudgeInput {
        fold_limit_creases: Vec::new(),
        ..input
    };
    assert!(judge(&bad).is_err());
}

/// One triangle in the plane x = 0.5, off the z-axis. Turned by 120° its plane meets the
/// original along the vertical line through (0.5, 0.5·√3) — inside both triangles, so
/// three copies cross; turned by 180° (two copies) it is the parallel plane x = −0.5. Its
/// flat layout keeps off the origin: no vertex is shared.
fn wing() -> Pattern {
    Pattern {
        vertices: vec![[1.0, 0.0], [5.0, 0.0], [3.0, 2.0]],
        edges: vec![
            Edge {
                v: [0, 1],
                kind: EdgeKind::Boundary,
            },
            Edge {
                v: [1, 2],
                kind: EdgeKind::Boundary,
            },
            Edge {
                v: [2, 0],
                kind: EdgeKind::Boundary,
            },
        ],
        faces: vec![vec![0, 1, 2]],
        frames: vec![Frame {
            t: 0.0,
            coords: vec![[0.5, -2.0, -1.0], [0.5, 2.0, -1.0], [0.5, 0.0, 1.0]],
            fold_angles: Vec::new(),
        }],
    }
}

#[test]
fn three_copies_collide_two_do_not() {
    let arm = wing();
    let three = with_copies(&arm, &Copies::about_z(3)).unwrap();
    assert_eq!(three.pattern.faces.len(), 3);
    assert_eq!(three.pattern.vertices.len(), 9);
    // Copy 1's positions are the arm's turned by 120° about z.
    let (s, c) = (2.0 * PI / 3.0).sin_cos();
    let q = three.pattern.frames[0].coords[three.index[1][0]];
    let want = [c * 0.5 + s * 2.0, s * 0.5 - c * 2.0, -1.0];
    assert!(close(q, want), "{q:?} vs {want:?}");
    let x = copy_crossings(&three).unwrap();
    // Every pair of the three copies crosses.
    assert_eq!(x.len(), 3, "{x:?}");
    let two = with_copies(&arm, &Copies::about_z(2)).unwrap();
    assert_eq!(two.pattern, two_armed(&arm).unwrap());
    assert!(copy_crossings(&two).unwrap().is_empty());
    // Moved off the axis to x = 1.5, the 120° planes meet at distance 3 from the axis,
    // beyond the triangles' reach: no crossing.
    let mut far = arm.clone();
    for p in &mut far.frames[0].coords {
        p[0] = 1.5;
    }
    let three = with_copies(&far, &Copies::about_z(3)).unwrap();
    assert!(copy_crossings(&three).unwrap().is_empty());
}

#[test]
fn copies_share_the_vertices_on_the_axis() {
    // The hinge's vertices 0 and 3 lie on the y-axis; four copies about it share them.
    let p = hinge(&TS);
    let copies = Copies {
        n: 4,
        point: [0.0, 0.0, 0.0],
        direction: [0.0, 1.0, 0.0],
    };
    let c = with_copies(&p, &copies).unwrap();
    // Vertex 0 is the pivot (flat position (0, 0)); vertex 3 at flat (0, 1) turns away
    // from itself in the flat layout and is copied.
    for k in 1..4 {
        assert_eq!(c.index[k][0], 0);
        assert_ne!(c.index[k][3], 3);
    }
    assert_eq!(c.pattern.faces.len(), 8);
    for fr in &c.pattern.frames {
        for k in 0..4 {
            let arm = &p.frames.iter().find(|f| f.t == fr.t).unwrap().coords;
            for (i, x) in arm.iter().enumerate() {
                assert!(close(copies.apply(k, *x), fr.coords[c.index[k][i]]));
            }
        }
    }
}

#[test]
fn robustness_measures_every_shape_and_copy() {
    use foldsynth::check::robustness::{RobustnessInput, SceneMargins, measure, measure_scene};
    let arm = hinge(&TS);
    let obstacles = vec![
        obstacle(
            "ball",
            Shape::Sphere(Sphere {
                center: [0.5, 0.5, -1.0],
                radius: 0.6,
            }),
        ),
        obstacle(
            "crate",
            Shape::Box(OrientedBox::aligned([2.0, 0.0, 0.0], [3.0, 1.0, 1.0])),
        ),
    ];
    let three = with_copies(&arm, &Copies::about_z(3)).unwrap();
    let input = RobustnessInput {
        pattern: &three.pattern,
        arm_faces: 2,
        face_names: vec!["f1".into(), "f2".into()],
        vertex_names: Vec::new(),
        cylinders: &[],
        units: Vec::new(),
        tip: None,
        t_max: 1.2,
        settings: Default::default(),
        arm: &arm,
    };
    // Without the scene: no obstacle margin; with it: the ball's 1 − 0.6 below the flat
    // facet, the least of the two shapes.
    assert!(measure(&input).unwrap().obstacle_clearance.is_none());
    let scene = SceneMargins {
        obstacles: &obstacles,
        tips: Vec::new(),
    };
    let r = measure_scene(&input, &scene).unwrap();
    let o = r.obstacle_clearance.unwrap();
    assert!((o.value - 0.4).abs() < 1e-12, "{o:?}");
    assert!(o.location.ends_with("ball"), "{}", o.location);
    // The three arms share vertex 0 at the origin (flat and folded): copy facets are
    // measured against the arm, the third copy's named with its number.
    assert!(r.arm_clearance.is_some());
    let judged =
        foldsynth::check::requirements::judge_obstacles(&three.pattern, &obstacles, 0.0).unwrap();
    assert!((judged[0].least.unwrap() - 0.4).abs() < 1e-12);
}
