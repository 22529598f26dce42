//! Small crease patterns with exact rigid motions, built by rotating facets: fixtures for
//! tests and demos of the export stage (`foldsynth export` needs a design to export).

use std::f64::consts::PI;

use nalgebra::{Rotation3, Unit, Vector3};

use super::{Cylinder, DesignMeta, Mode, TargetPoint};
use crate::pattern::{Edge, EdgeKind, Frame, Pattern};

fn crease(a: usize, b: usize, driven: bool) -> Edge {
    Edge {
        v: [a, b],
        kind: EdgeKind::Crease { driven },
    }
}

fn boundary(a: usize, b: usize) -> Edge {
    Edge {
        v: [a, b],
        kind: EdgeKind::Boundary,
    }
}

fn ts(t_max: f64, frames: usize) -> Vec<f64> {
    match frames {
        0 => Vec::new(),
        1 => vec![t_max],
        n => (0..n).map(|k| t_max * k as f64 / (n - 1) as f64).collect(),
    }
}

fn apply(r: &Rotation3<f64>, p: [f64; 2]) -> [f64; 3] {
    let q = r * Vector3::new(p[0], p[1], 0.0);
    [q.x, q.y, q.z]
}

/// One driven crease along the x-axis from (0,0) to (1,0), like the thesis's G0: the facet
/// left of it (y > 0, an L-shaped, non-convex hexagon) turns by +t/2 about x and the
/// facet right of it (a rectangle) by −t/2, a valley fold of angle t. `frames` states,
/// evenly over [0, t_max].
pub fn single_crease(t_max: f64, frames: usize) -> Pattern {
    let vertices = vec![
        [0.0, 0.0],
        [1.0, 0.0],
        [1.0, 0.3],
        [0.5, 0.3],
        [0.5, 0.6],
        [0.0, 0.6],
        [0.0, -0.6],
        [1.0, -0.6],
    ];
    let edges = vec![
        crease(0, 1, true),
        boundary(1, 2),
        boundary(2, 3),
        boundary(3, 4),
        boundary(4, 5),
        boundary(5, 0),
        boundary(0, 6),
        boundary(6, 7),
        boundary(7, 1),
    ];
    let faces = vec![vec![0, 1, 2, 3, 4, 5], vec![1, 0, 6, 7]];
    let frames = ts(t_max, frames)
        .into_iter()
        .map(|t| {
            let up = Rotation3::from_axis_angle(&Vector3::x_axis(), t / 2.0);
            let down = Rotation3::from_axis_angle(&Vector3::x_axis(), -t / 2.0);
            let coords = vertices
                .iter()
                .map(|&p| {
                    if p[1] >= 0.0 {
                        apply(&up, p)
                    } else {
                        apply(&down, p)
                    }
                })
                .collect();
            let mut fold_angles = vec![0.0; edges.len()];
            fold_angles[0] = t;
            Frame {
                t,
                coords,
                fold_angles,
            }
        })
        .collect();
    Pattern {
        vertices,
        edges,
        faces,
        frames,
    }
}

/// A flat-foldable degree-4 vertex at the origin of the square [−1, 1]²: creases along
/// +x (driven, valley t), at angle γ, along −x and at angle −γ (γ in (π/4, π/2), so the
/// slanted creases end on the top and bottom sides). The motion is mirror-symmetric about
/// the xz-plane: the facet between +x and γ turns by +t/2 about x, its mirror image by
/// −t/2; the facets beyond the slanted creases follow by R_left = R_right · Rot(d, ρ)
/// with ρ = −2 atan(tan(t/2)/cos γ), the value that makes both sides meet on the −x
/// crease (its image must stay in the xz-plane). The −x crease's angle is read off the
/// relative rotation of its two facets. Valid for t_max < π.
pub fn degree4(gamma: f64, t_max: f64, frames: usize) -> Pattern {
    let cot = gamma.cos() / gamma.sin();
    let vertices = vec![
        [0.0, 0.0],
        [1.0, 0.0],
        [cot, 1.0],
        [-1.0, 0.0],
        [cot, -1.0],
        [1.0, 1.0],
        [-1.0, 1.0],
        [-1.0, -1.0],
        [1.0, -1.0],
    ];
    let edges = vec![
        crease(0, 1, true),
        crease(0, 2, false),
        crease(0, 3, false),
        crease(0, 4, false),
        boundary(1, 5),
        boundary(5, 2),
        boundary(2, 6),
        boundary(6, 3),
        boundary(3, 7),
        boundary(7, 4),
        boundary(4, 8),
        boundary(8, 1),
    ];
    // F1 (+x..γ), F2 (γ..π), F3 (π..−γ), F4 (−γ..+x), all counter-clockwise.
    let faces = vec![
        vec![0, 1, 5, 2],
        vec![0, 2, 6, 3],
        vec![0, 3, 7, 4],
        vec![0, 4, 8, 1],
    ];
    let d2 = Unit::new_normalize(Vector3::new(gamma.cos(), gamma.sin(), 0.0));
    let d4 = Unit::new_normalize(Vector3::new(gamma.cos(), -gamma.sin(), 0.0));
    let d3 = Vector3::new(-1.0, 0.0, 0.0);
    let frames = ts(t_max, frames)
        .into_iter()
        .map(|t| {
            let rho = -2.0 * ((t / 2.0).tan() / gamma.cos()).atan();
            let r1 = Rotation3::from_axis_angle(&Vector3::x_axis(), t / 2.0);
            let r4 = Rotation3::from_axis_angle(&Vector3::x_axis(), -t / 2.0);
            let r2 = r1 * Rotation3::from_axis_angle(&d2, rho);
            // Crossing the ray −γ counter-clockwise goes from F3 (right) to F4 (left).
            let r3 = r4 * Rotation3::from_axis_angle(&d4, -rho);
            // F3 = F2 · Rot(d3, ρ3): read ρ3 off the relative rotation about d3.
            let rel = r2.inverse() * r3;
            let u = Vector3::new(0.0, 1.0, 0.0);
            let ru = rel * u;
            let rho3 = u.cross(&ru).dot(&d3).atan2(u.dot(&ru));
            let face_rot = [&r1, &r2, &r3, &r4];
            // Each vertex from one facet containing it.
            let owner = [0usize, 0, 0, 1, 3, 0, 1, 2, 3];
            let coords = vertices
                .iter()
                .zip(owner)
                .map(|(&p, f)| apply(face_rot[f], p))
                .collect();
            let mut fold_angles = vec![0.0; edges.len()];
            fold_angles[0] = t;
            fold_angles[1] = rho;
            fold_angles[2] = rho3;
            fold_angles[3] = rho;
            Frame {
                t,
                coords,
                fold_angles,
            }
        })
        .collect();
    Pattern {
        vertices,
        edges,
        faces,
        frames,
    }
}

/// A demo design for pictures and the report: [`degree4`] dressed as a gripper task
/// (target, cylinder obstacle, two arms).
pub fn demo_gripper() -> (Pattern, DesignMeta) {
    let p = degree4(PI / 3.0, PI / 2.0, 9);
    let g = 6; // index; the metadata names it v7
    let meta = DesignMeta {
        task: "demo gripper".into(),
        rule_sequence: "2".into(),
        modes: vec![Mode::Down],
        gripping_vertex: Some(g + 1),
        objective: Some(0.0),
        targets: vec![TargetPoint {
            p: p.frames.last().map_or([0.0; 3], |f| f.coords[g]),
            t: Some(PI / 2.0),
        }],
        trajectory: Vec::new(),
        scene: super::meta_file::legacy_scene(
            Some(Cylinder {
                a: [0.0, -1.0, 0.5],
                b: [0.0, 1.0, 0.5],
                radius: 0.25,
            }),
            true,
        ),
        extra: Default::default(),
        ..DesignMeta::default()
    };
    (p, meta)
}

/// A demo design with a trajectory (robotic-arm style): [`single_crease`], the tip vertex
/// v5 (index 4) following its own circular path, with target points along it.
pub fn demo_arm() -> (Pattern, DesignMeta) {
    let p = single_crease(PI / 2.0, 11);
    let g = 4; // index; the metadata names it v5
    let targets: Vec<TargetPoint> = p
        .frames
        .iter()
        .map(|f| TargetPoint {
            p: f.coords[g],
            t: Some(f.t),
        })
        .collect();
    let trajectory = (0..=40)
        .map(|k| {
            let t = PI / 2.0 * k as f64 / 40.0;
            let r = Rotation3::from_axis_angle(&Vector3::x_axis(), t / 2.0);
            apply(&r, [0.5, 0.6])
        })
        .collect();
    let meta = DesignMeta {
        task: "demo arm".into(),
        rule_sequence: String::new(),
        modes: Vec::new(),
        gripping_vertex: Some(g + 1),
        objective: Some(0.0),
        targets,
        trajectory,
        extra: Default::default(),
        ..DesignMeta::default()
    };
    (p, meta)
}

/// An OBJ octahedron with vertices at ±1 on each axis: 8 triangles, closed, facing
/// outward (the mesh obstacle and the surface goal of [`every_shape`]).
pub const OCTAHEDRON_OBJ: &str = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

/// [`demo_arm`]'s pattern in a scene with every kind of thing a task may put around it: a
/// cylinder, a sphere, a turned box, a half-space (the floor), a mesh (an octahedron,
/// written to `dir/octahedron.obj`, which the metadata names), a containment box, three
/// copies about a tilted axis, and line, plane and surface goals beside a point goal.
pub fn every_shape(dir: &std::path::Path) -> std::io::Result<(Pattern, DesignMeta)> {
    use crate::scene::shapes::{HalfSpace, MeshObstacle, OrientedBox, Sphere, frame};
    use crate::scene::{Containment, Copies, Obstacle, Scene, Shape};
    use crate::task::terms::{Goal, Target, VertexRef};

    let file = dir.join("octahedron.obj");
    std::fs::write(&file, OCTAHEDRON_OBJ)?;
    let octahedron = MeshObstacle {
        file,
        scale: 0.3,
        translate: [1.8, 1.2, 0.6],
        mesh: None,
    };
    let (p, mut meta) = demo_arm();
    let obstacle = |name: &str, shape: Shape| Obstacle {
        name: name.into(),
        shape,
    };
    meta.task = "every shape".into();
    meta.scene = Scene {
        obstacles: vec![
            obstacle(
                "post",
                Shape::Cylinder(Cylinder {
                    a: [0.0, -1.0, 0.5],
                    b: [0.0, 1.0, 0.5],
                    radius: 0.25,
                }),
            ),
            obstacle(
                "ball",
                Shape::Sphere(Sphere {
                    center: [1.5, -0.5, 0.8],
                    radius: 0.35,
                }),
            ),
            obstacle(
                "crate",
                Shape::Box(OrientedBox {
                    center: [-1.2, 0.4, 0.3],
                    half: [0.3, 0.2, 0.25],
                    axes: frame([1.0, 1.0, 0.0], [-1.0, 1.0, 0.5]).expect("independent axes"),
                }),
            ),
            obstacle(
                "floor",
                Shape::HalfSpace(HalfSpace {
                    point: [0.0, 0.0, -0.2],
                    normal: [0.0, 0.0, 1.0],
                }),
            ),
            obstacle("part", Shape::Mesh(octahedron.clone())),
        ],
        copies: Copies {
            n: 3,
            point: [0.0, 0.0, 0.0],
            direction: [0.0, 0.6, 0.8],
        },
        containment: vec![Containment {
            bounds: OrientedBox::aligned([-2.0, -2.0, -0.5], [2.0, 2.0, 2.5]),
            t: None,
            name: "workspace".into(),
        }],
    };
    let goal = |goal: Goal, entry: usize| Target {
        t: PI / 2.0,
        vertex: VertexRef::Tip,
        goal,
        weight: 1.0,
        entry,
    };
    meta.goals = vec![
        goal(
            Goal::Point {
                point: [0.5, 0.0, 0.6],
            },
            0,
        ),
        goal(
            Goal::Line {
                point: [0.0, 0.0, 1.0],
                direction: [1.0, 0.0, 0.0],
            },
            1,
        ),
        goal(
            Goal::Plane {
                point: [0.0, 0.0, 1.2],
                normal: [0.0, 0.0, 1.0],
            },
            2,
        ),
        goal(Goal::Surface { index: 0 }, 3),
    ];
    meta.surfaces = vec![octahedron];
    Ok((p, meta))
}
