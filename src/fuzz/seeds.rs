//! The valid examples every mutation starts from: the task and pattern files of
//! `grammar/`, the FOLD, design and record files of `tests/data/`, FOLD and design files
//! written from the sample patterns, and notation examples.

use std::sync::OnceLock;

use super::Target;
use crate::export::{DesignFile, DesignMeta, FoldSpec, samples};

/// A task small enough to enumerate and model quickly.
const SMALL_TASK: &str = r#"name = "small"
[grammar]
n_max = 2
[symmetry]
mirror_xz = true
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
[bounds]
l_min = 0.1
l_max = 1.5
alpha_min = "pi/18"
alpha_max = "17*pi/18"
[objective]
threshold = 1e-5
[[objective.targets]]
t = "pi/2"
point = [0.0, 0.0, 1.0]
[check]
states = 4
[[check.cylinders]]
radius = 0.25
from = [0.0, -1.0, 0.5]
to = [0.0, 1.0, 0.5]
"#;

/// A task using every table of the task language (issue 31) but meshes, so that mutations
/// reach their checks.
const TERMS_TASK: &str = r#"name = "terms"
[grammar]
n_max = 2
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
threshold = 0.3
[[objective.targets]]
vertex = "s2"
t = "0 .. pi/2"
samples = 3
point = ["1 + 2*cos(t)", 0, "2*sin(t)"]
weight = 2
[[objective.targets]]
vertex = "v2"
t = "pi/4"
line = { point = [0, "t", 1], direction = [0, 0, 1] }
[[objective.targets]]
vertex = "last"
t = 0
plane = { point = [0, 0, 1], normal = [0, 0, 1] }
[objective.area]
kind = "packing"
t = "pi/2"
weight = 1
at_least = 0.5
[constraints]
max_fold = "0.9*pi"
[[constraints.fold_limits]]
crease = "v1-v2"
max = "pi/2"
[[constraints.orientation]]
vertex = "tip"
of = "crease"
direction = [0, 0, -1]
angle = 0
tolerance = "5*pi/180"
t = "pi/4 .. pi/2"
samples = 2
name = "down"
[[constraints.inside]]
min = [-3, -3, -1]
max = [3, 3, 4]
[[constraints.inside]]
center = [0, 0, 2]
half_extents = [2, 2, 2]
x_axis = [1, 1, 0]
y_axis = [0, 0, 1]
t = "pi/2"
[copies]
n = 3
axis = { point = [0, 0, 0], direction = [0, 0, 1] }
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
shape = "halfspace"
point = [0, 0, -1]
normal = [0, 0, 1]
[[obstacles]]
shape = "cylinder"
radius = 0.25
from = [0, -1, 0.5]
to = [0, 1, 0.5]
"#;

/// A task with a mesh obstacle and a surface target (read relative to the current
/// directory: accepted when run from the crate's root).
const MESH_TASK: &str = r#"name = "meshes"
[grammar]
n_max = 2
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
threshold = 0.3
[[objective.targets]]
t = "0 .. 1"
samples = 2
surface = { file = "tests/data/meshes/sheet.obj", scale = 2, translate = [0, 0, 1] }
[[obstacles]]
shape = "mesh"
file = "tests/data/meshes/tetra.stl"
scale = 0.5
translate = [2, 0, 0]
"#;

/// A pattern file of four vertices (one simulation step is quick).
const SMALL_PATTERN: &str = r#"name = "hinge"
vertices = [
  { name = "a", at = [0, 0] },
  { name = "b", at = [0, 1] },
  { name = "c", at = [1, 0] },
  { name = "d", at = [-1, 0] },
]
faces = [["a", "c", "b"], ["a", "b", "d"]]
fixed = ["a", "b", "c"]
[motion]
t_start = 0
t_end = 1
steps = 4
[[drive]]
kind = "trajectory"
vertex = "d"
x = "-cos(t)"
y = 0
z = "sin(t)"
"#;

const VERTICES: [&str; 5] = [
    "v(up, ((80,40,40),(t,-t)), ((90,40,50),(t,-t)), (20))",
    "v(down, (90), (90), ((90,90),(t)))",
    "v(up, ((60,60),(t/2)), ((60,60),(-t)), ((60,60),(t)))",
    "v(down, ((100,30),(t)), (110), ((70,50),(-t/1.2)))",
    "v(up, (120), (120), ((60,60),(pi/2 - t)))",
];

const EXPRS: [&str; 10] = [
    "t",
    "-t",
    "t/1.2",
    "pi/2",
    "17*pi/18",
    "1 + 2*cos(pi/20)",
    "-cos(t)",
    "sin(t)*2",
    "sqrt(2)/2*t",
    "2^3 - t*(1 - t)",
];

fn fold_texts() -> Vec<Vec<u8>> {
    let mut v: Vec<Vec<u8>> = vec![
        include_str!("../../tests/data/diagonal_spec_example.fold").into(),
        include_str!("../../tests/data/mountain_no_faces.fold").into(),
        include_str!("../../tests/data/thirdparty/pleat_in_plane_y0.fold").into(),
        include_str!("../../tests/data/thirdparty/folded_form_only.fold").into(),
        include_str!("../../tests/data/thirdparty/flat_folded_state.fold").into(),
        include_str!("../../tests/data/thirdparty/no_assignment.fold").into(),
        include_str!("../../tests/data/thirdparty/seven_digits_tilted.fold").into(),
    ];
    let (gp, gm) = samples::demo_gripper();
    for (p, m) in [
        (samples::single_crease(1.5, 3), DesignMeta::default()),
        (samples::degree4(1.2, 2.0, 4), DesignMeta::default()),
        (gp, gm),
    ] {
        if let Ok(s) = crate::export::fold::to_fold_string(&p, &m, FoldSpec::default()) {
            v.push(s.into_bytes());
        }
    }
    v
}

fn design_texts() -> Vec<Vec<u8>> {
    let mut v: Vec<Vec<u8>> =
        vec![include_str!("../../tests/data/demo_gripper_design.json").into()];
    let (ap, am) = samples::demo_arm();
    for (pattern, meta) in [
        (samples::single_crease(2.0, 3), DesignMeta::default()),
        (samples::degree4(1.0, 1.5, 3), DesignMeta::default()),
        (ap, am),
    ] {
        if let Ok(s) = serde_json::to_string(&DesignFile { pattern, meta }) {
            v.push(s.into_bytes());
        }
    }
    v
}

/// The seeds of `target`.
pub fn of(target: Target) -> &'static [Vec<u8>] {
    static SEEDS: [OnceLock<Vec<Vec<u8>>>; 8] = [const { OnceLock::new() }; 8];
    SEEDS[target as usize].get_or_init(|| match target {
        Target::Task => vec![
            include_str!("../../grammar/gripper.toml").into(),
            include_str!("../../grammar/robotic_arm.toml").into(),
            SMALL_TASK.into(),
            TERMS_TASK.into(),
            MESH_TASK.into(),
            include_str!("../../tests/data/robotic_arm_points.toml").into(),
        ],
        Target::Pattern => vec![
            include_str!("../../grammar/flasher_adapted.toml").into(),
            SMALL_PATTERN.into(),
        ],
        Target::Vertex => VERTICES.iter().map(|s| s.as_bytes().to_vec()).collect(),
        Target::Expr => EXPRS.iter().map(|s| s.as_bytes().to_vec()).collect(),
        Target::Fold => fold_texts(),
        Target::Design => design_texts(),
        Target::Records => vec![include_str!("../../tests/data/fuzz/records.jsonl").into()],
        Target::Mesh => mesh_files(),
    })
}

/// Mesh files: a closed tetrahedron as ASCII and binary STL, an open sheet and a cube of
/// quads as OBJ.
fn mesh_files() -> Vec<Vec<u8>> {
    let tetra = include_bytes!("../../tests/data/meshes/tetra.stl");
    let mut v = vec![
        tetra.to_vec(),
        include_bytes!("../../tests/data/meshes/sheet.obj").to_vec(),
        CUBE_OBJ.into(),
    ];
    if let Ok(m) = crate::scene::TriangleMesh::from_stl(tetra) {
        v.push(binary_stl(&m));
    }
    v
}

/// A unit cube of six quads (triangulated as fans when read).
const CUBE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

/// `m` as a binary STL: an 80-byte header, the count, then per triangle a normal, three
/// vertices (f32) and two attribute bytes.
fn binary_stl(m: &crate::scene::TriangleMesh) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&(m.triangles.len() as u32).to_le_bytes());
    for i in 0..m.triangles.len() {
        b.extend_from_slice(&[0u8; 12]);
        for p in m.triangle(i) {
            for x in p {
                b.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}
