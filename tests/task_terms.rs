//! The task language of issue 31: a task using every new table loads to the values its text
//! means (a path's samples equal the closed form, an oriented box's axes are orthonormal, a
//! mesh is scaled and moved), and the robotic arm written as one path equals the arm
//! written point by point, bit for bit.

use std::f64::consts::PI;
use std::path::Path;

use foldsynth::scene::{Copies, Shape};
use foldsynth::task::Task;
use foldsynth::task::terms::{AreaKind, CreaseRef, Goal, Pointer, VertexRef};

fn data(name: &str) -> String {
    format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_arm_as_one_path_equals_the_arm_point_by_point() {
    let path = Task::load(format!(
        "{}/grammar/robotic_arm.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let points = Task::load(data("robotic_arm_points.toml")).unwrap();
    let (a, b) = (
        path.objective.as_ref().unwrap(),
        points.objective.as_ref().unwrap(),
    );
    assert_eq!(a.targets.len(), 11);
    assert_eq!(a.targets.len(), b.targets.len());
    assert_eq!(a.threshold.to_bits(), b.threshold.to_bits());
    for (k, (x, y)) in a.targets.iter().zip(&b.targets).enumerate() {
        assert_eq!(x.t.to_bits(), y.t.to_bits(), "t of sample {k}");
        let (p, q) = (x.point().unwrap(), y.point().unwrap());
        for i in 0..3 {
            assert_eq!(p[i].to_bits(), q[i].to_bits(), "point[{i}] of sample {k}");
        }
        assert_eq!((x.weight, &x.vertex), (y.weight, &y.vertex));
        // One entry for the path, one per point for the old file.
        assert_eq!((x.entry, y.entry), (0, k));
    }
    assert_eq!(path.initial, points.initial);
    assert_eq!(path.scene, points.scene);
    assert_ne!(path.digest, points.digest);
}

/// G0 of the gripper plus every new table; meshes from tests/data/meshes.
const ALL: &str = r#"
[grammar]
n_max = 3
[[initial_graph.vertices]]
id = "v1"
xy = [0.0, 0.0]
type = "terminal"
[[initial_graph.vertices]]
id = "v2"
xy = [1.0, 0.0]
type = "extendable"
[[initial_graph.creases]]
from = "v1"
to = "v2"
left = "f1"
right = "f2"
drive = "t"
[motion]
t_max = "pi/2"
[objective]
threshold = 0.2
[[objective.targets]]
vertex = "s2"
t = "pi/6 .. pi/2"
samples = 5
point = ["cos(t)", "t^2", 3]
weight = 2
[[objective.targets]]
vertex = "v2"
t = "pi/4"
line = { point = [0, "t", 1], direction = [0, 0, -2] }
[[objective.targets]]
vertex = "last"
t = 0
plane = { point = [0, 0, 1], normal = [3, 0, 4] }
[[objective.targets]]
t = "0 .. 1"
samples = 3
surface = { file = "meshes/sheet.obj", scale = 2, translate = [1, 0, 0.5] }
[objective.area]
kind = "packing"
t = "pi/2"
weight = 0.5
at_least = 1.5
[constraints]
max_fold = "0.9*pi"
[[constraints.fold_limits]]
crease = "v2-v1"
max = "pi/2"
[[constraints.fold_limits]]
crease = "s3"
max = 1
[[constraints.orientation]]
vertex = "tip"
of = "facet_left"
direction = [0, 0, -5]
angle = "pi/4"
tolerance = "5*pi/180"
t = "0 .. pi/2"
samples = 3
name = "fingertip down"
[[constraints.inside]]
min = [-1, -2, 0]
max = [1, 2, 4]
[[constraints.inside]]
center = [0, 0, 2]
half_extents = [1, 2, 3]
x_axis = [1, 1, 0]
y_axis = [0, 1, 1]
t = "pi/2"
name = "stowed"
[copies]
n = 3
axis = { point = [1, 0, 0], direction = [0, 2, 0] }
[check]
states = 8
[[check.cylinders]]
radius = 0.25
from = [0, -1, 0.5]
to = [0, 1, 0.5]
[[obstacles]]
shape = "sphere"
center = [0, 0, 3]
radius = 0.5
name = "ball"
[[obstacles]]
shape = "box"
min = [2, 2, 0]
max = [3, 4, 1]
[[obstacles]]
shape = "box"
center = [5, 0, 0]
half_extents = [0.5, 1, 2]
x_axis = [0, 1, 0]
y_axis = [-1, 0, 0]
[[obstacles]]
shape = "halfspace"
point = [0, 0, -1]
normal = [0, 0, 2]
name = "table"
[[obstacles]]
shape = "cylinder"
radius = 1
from = [0, 0, 0]
to = [0, 0, 1]
[[obstacles]]
shape = "mesh"
file = "meshes/tetra.stl"
scale = 3
translate = [10, 0, 0]
"#;

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() < 1e-14)
}

#[test]
fn a_task_with_every_new_table_loads_to_what_it_says() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let t = Task::from_toml_str_in(ALL, "all.toml", &dir).unwrap();
    let o = t.objective.as_ref().unwrap();
    assert_eq!(o.threshold, 0.2);
    // Path: 5 samples of [pi/6, pi/2], the closed form of the contract.
    let (a, b) = (PI / 6.0, PI / 2.0);
    for k in 0..5 {
        let tg = &o.targets[k];
        let tk = if k == 0 {
            a
        } else if k == 4 {
            b
        } else {
            a + (k as f64 * (b - a)) / 4.0
        };
        assert_eq!(tg.t.to_bits(), tk.to_bits(), "sample {k}");
        assert_eq!(tg.point(), Some([tk.cos(), tk.powf(2.0), 3.0]));
        assert_eq!(
            (tg.vertex.clone(), tg.weight, tg.entry),
            (VertexRef::Successor(1), 2.0, 0)
        );
    }
    // The line: its point uses t, its direction is made unit.
    let line = &o.targets[5];
    assert_eq!(
        line.vertex,
        VertexRef::Initial {
            id: "v2".into(),
            index: 1
        }
    );
    assert_eq!(
        line.goal,
        Goal::Line {
            point: [0.0, PI / 4.0, 1.0],
            direction: [0.0, 0.0, -1.0]
        }
    );
    let plane = &o.targets[6];
    assert_eq!(
        (plane.vertex.clone(), plane.t, plane.entry),
        (VertexRef::Last, 0.0, 2)
    );
    match plane.goal {
        Goal::Plane { point, normal } => {
            assert_eq!(point, [0.0, 0.0, 1.0]);
            assert!(close(normal, [0.6, 0.0, 0.8]), "{normal:?}");
        }
        ref other => panic!("{other:?}"),
    }
    // The surface: three samples of one mesh, scaled by 2 and moved.
    assert_eq!(o.targets.len(), 10);
    for (k, tg) in o.targets[7..].iter().enumerate() {
        assert_eq!(
            (tg.goal.clone(), tg.vertex.clone()),
            (Goal::Surface { index: 0 }, VertexRef::Tip)
        );
        assert_eq!(tg.t, [0.0, 0.5, 1.0][k]);
    }
    let sheet = o.surfaces[0].triangles().expect("loaded");
    assert!(!sheet.closed);
    assert_eq!(sheet.triangles.len(), 2);
    assert_eq!(sheet.bounds(), ([1.0, 0.0, 0.5], [3.0, 2.0, 0.5]));
    assert!(o.surfaces[0].file.is_absolute());
    let area = o.area.unwrap();
    assert_eq!(area.kind, AreaKind::Packing { t: PI / 2.0 });
    assert_eq!((area.weight, area.at_least), (0.5, 1.5));

    let r = &t.requirements;
    assert_eq!(r.max_fold, Some(0.9 * PI));
    assert_eq!(
        r.fold_limits[0].crease,
        CreaseRef::Initial {
            name: "v2-v1".into(),
            a: 1,
            b: 0
        }
    );
    assert_eq!(r.fold_limits[0].max, PI / 2.0);
    assert_eq!(
        r.fold_limits[1].crease,
        CreaseRef::Into(VertexRef::Successor(2))
    );
    let ori = &r.orientations[0];
    assert_eq!(ori.name, "fingertip down");
    assert_eq!(
        (ori.vertex.clone(), ori.of),
        (VertexRef::Tip, Pointer::FacetLeft)
    );
    assert_eq!(ori.direction, [0.0, 0.0, -1.0]);
    assert_eq!((ori.angle, ori.tolerance), (PI / 4.0, 5.0 * PI / 180.0));
    assert_eq!(ori.t, vec![0.0, PI / 4.0, PI / 2.0]);

    let s = &t.scene;
    let boxes = &s.containment;
    assert_eq!(
        (boxes[0].name.as_str(), boxes[0].t),
        ("constraints.inside[0]", None)
    );
    assert_eq!(
        (boxes[0].bounds.center, boxes[0].bounds.half),
        ([0.0, 0.0, 2.0], [1.0, 2.0, 2.0])
    );
    assert_eq!(
        (boxes[1].name.as_str(), boxes[1].t),
        ("stowed", Some(PI / 2.0))
    );
    let axes = boxes[1].bounds.axes;
    for i in 0..3 {
        for j in 0..3 {
            let d: f64 = (0..3).map(|k| axes[i][k] * axes[j][k]).sum();
            let want = if i == j { 1.0 } else { 0.0 };
            assert!((d - want).abs() < 1e-15, "axes {i}·{j} = {d}");
        }
    }
    let h = std::f64::consts::FRAC_1_SQRT_2;
    assert!(close(axes[0], [h, h, 0.0]));
    // y_axis made orthogonal to x: (0,1,1) − ½(1,1,0) = (−½, ½, 1), normalized.
    let n = (1.5f64).sqrt();
    assert!(close(axes[1], [-0.5 / n, 0.5 / n, 1.0 / n]));
    // Right-handed: z = x × y.
    let z = [
        axes[0][1] * axes[1][2] - axes[0][2] * axes[1][1],
        axes[0][2] * axes[1][0] - axes[0][0] * axes[1][2],
        axes[0][0] * axes[1][1] - axes[0][1] * axes[1][0],
    ];
    assert!(close(axes[2], z));

    assert_eq!(
        s.copies,
        Copies {
            n: 3,
            point: [1.0, 0.0, 0.0],
            direction: [0.0, 1.0, 0.0]
        }
    );
    let names: Vec<&str> = s.obstacles.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "check.cylinders[0]",
            "ball",
            "obstacles[1]",
            "obstacles[2]",
            "table",
            "obstacles[4]",
            "obstacles[5]"
        ]
    );
    let kinds: Vec<&str> = s.obstacles.iter().map(|o| o.kind()).collect();
    assert_eq!(
        kinds,
        [
            "cylinder",
            "sphere",
            "box",
            "box",
            "halfspace",
            "cylinder",
            "mesh"
        ]
    );
    match &s.obstacles[3].shape {
        Shape::Box(b) => {
            assert_eq!((b.center, b.half), ([5.0, 0.0, 0.0], [0.5, 1.0, 2.0]));
            assert_eq!(b.axes, [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
        }
        other => panic!("{other:?}"),
    }
    match &s.obstacles[4].shape {
        Shape::HalfSpace(hs) => {
            assert_eq!((hs.point, hs.normal), ([0.0, 0.0, -1.0], [0.0, 0.0, 1.0]))
        }
        other => panic!("{other:?}"),
    }
    match &s.obstacles[6].shape {
        Shape::Mesh(m) => {
            let tri = m.triangles().expect("loaded");
            assert!(tri.closed);
            assert_eq!(tri.triangles.len(), 4);
            assert_eq!(tri.bounds(), ([10.0, 0.0, 0.0], [13.0, 3.0, 3.0]));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_digest_follows_the_mesh_files() {
    let tmp = std::env::temp_dir().join(format!("foldsynth_digest_{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let text = ALL.replace("meshes/tetra.stl", "part.obj");
    let sheet = std::fs::read(data("meshes/sheet.obj")).unwrap();
    std::fs::create_dir_all(tmp.join("meshes")).unwrap();
    std::fs::write(tmp.join("meshes/sheet.obj"), &sheet).unwrap();
    std::fs::write(tmp.join("part.obj"), &sheet).unwrap();
    let first = Task::from_toml_str_in(&text, "all.toml", &tmp)
        .unwrap()
        .digest;
    let again = Task::from_toml_str_in(&text, "all.toml", &tmp)
        .unwrap()
        .digest;
    assert_eq!(first, again);
    // The same text with an edited mesh: another task.
    let mut edited = sheet.clone();
    edited.extend_from_slice(b"v 0 0 1\nf 1 2 5\n");
    std::fs::write(tmp.join("part.obj"), &edited).unwrap();
    let changed = Task::from_toml_str_in(&text, "all.toml", &tmp)
        .unwrap()
        .digest;
    assert_ne!(first, changed);
    // Without meshes the digest is the text's.
    let plain = Task::load(data("robotic_arm_points.toml")).unwrap();
    let bytes = std::fs::read(data("robotic_arm_points.toml")).unwrap();
    assert_eq!(plain.digest, foldsynth::task::digest(&bytes));
    assert!(plain.mesh_digests.is_empty());
    std::fs::remove_dir_all(&tmp).unwrap();
}

#[test]
fn copies_default_to_the_z_axis_and_second_arm_means_two() {
    let base = ALL.split("[objective]").next().unwrap();
    let t = Task::from_toml_str(&format!("{base}[copies]\nn = 4\n"), "c.toml").unwrap();
    assert_eq!(t.scene.copies, Copies::about_z(4));
    let t = Task::from_toml_str(
        &format!("{base}[check]\nstates = 4\nsecond_arm = true\n"),
        "c.toml",
    )
    .unwrap();
    assert_eq!(t.scene.copies, Copies::about_z(2));
    let t = Task::from_toml_str(base, "c.toml").unwrap();
    assert_eq!(t.scene.copies.n, 1);
    assert!(t.scene.is_empty());
    assert_eq!(t.requirements, Default::default());
}

#[test]
fn an_area_term_alone_is_an_objective() {
    let base = ALL.split("[objective]").next().unwrap();
    let t = Task::from_toml_str(
        &format!("{base}[objective.area]\nkind = \"flat\"\n"),
        "a.toml",
    )
    .unwrap();
    let o = t.objective.unwrap();
    assert!(o.targets.is_empty());
    let a = o.area.unwrap();
    assert_eq!((a.kind, a.weight, a.at_least), (AreaKind::Flat, 1.0, 0.0));
}

/// The three gripping candidates of a graph are three problems only when the gripping
/// vertex matters: a term names `tip`, or names the vertex extended last's successors in
/// a task with copies (the arms may touch at the gripping vertex). `s1`–`s3` and `last`
/// alone name the same vertices whichever successor grips.
#[test]
fn gripping_candidates_matter_only_for_the_tip_or_copies() {
    let base = ALL.split("[objective]").next().unwrap();
    let target = |v: &str| {
        format!(
            "[objective]\nthreshold = 1e-3\n[[objective.targets]]\nvertex = \"{v}\"\nt = \"pi/2\"\npoint = [0, 0, 1]\n"
        )
    };
    let task = |extra: &str| Task::from_toml_str(&format!("{base}{extra}"), "g.toml").unwrap();
    assert!(task(&target("tip")).uses_gripping_vertex());
    assert!(!task(&target("s1")).uses_gripping_vertex());
    assert!(!task(&target("last")).uses_gripping_vertex());
    assert!(task(&format!("{}[copies]\nn = 2\n", target("s1"))).uses_gripping_vertex());
    assert!(!task(&target("v1")).uses_gripping_vertex());
}
