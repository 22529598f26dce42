//! The scene written out with each design (`<name>-scene.obj`, `-scene.stl`, `foldsynth
//! export --format scene-obj|scene-stl`) and the scene in the design's metadata and FOLD
//! file: the files parse back with the readers other programs use (`tobj`, `stl_io`),
//! hold the triangles each shape should have, and every obstacle triangle lies on its
//! shape's surface, facing outward.

use std::f64::consts::PI;
use std::path::Path;
use std::process::Command;

use foldsynth::export::fold::FoldFile;
use foldsynth::export::meta_file::{LEGACY_OBSTACLE_NAME, scene_from_fold};
use foldsynth::export::scene_mesh::{self, SEGMENTS};
use foldsynth::export::{DesignFile, DesignMeta, ExportOptions, mesh, samples, write_all};
use foldsynth::geom::{V3, add, cross, dot, norm, scale, sub};
use foldsynth::scene::{Copies, Shape};

const S: usize = SEGMENTS;

/// Triangles per obstacle kind (the octahedron file has 8).
fn expected(kind: &str) -> usize {
    match kind {
        "cylinder" => 4 * S,
        "sphere" => 2 * S * (S / 2 - 1),
        "box" => 12,
        "halfspace" => 2,
        "mesh" => 8,
        _ => unreachable!("{kind}"),
    }
}

fn load_obj(path: &Path) -> Vec<tobj::Model> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    tobj::load_obj(path, &opts).unwrap().0
}

fn corners(m: &tobj::Model) -> Vec<[V3; 3]> {
    let p = &m.mesh.positions;
    let at = |i: u32| {
        let i = 3 * i as usize;
        [p[i], p[i + 1], p[i + 2]]
    };
    m.mesh
        .indices
        .chunks_exact(3)
        .map(|t| [at(t[0]), at(t[1]), at(t[2])])
        .collect()
}

fn normal(t: &[V3; 3]) -> V3 {
    cross(sub(t[1], t[0]), sub(t[2], t[0]))
}

fn centroid(t: &[V3; 3]) -> V3 {
    scale(add(add(t[0], t[1]), t[2]), 1.0 / 3.0)
}

/// Points of the triangle: corners, edge midpoints, centroid.
fn samples_of(t: &[V3; 3]) -> Vec<V3> {
    let mid = |a: V3, b: V3| scale(add(a, b), 0.5);
    vec![
        t[0],
        t[1],
        t[2],
        mid(t[0], t[1]),
        mid(t[1], t[2]),
        mid(t[0], t[2]),
        centroid(t),
    ]
}

/// Each obstacle's triangles on its surface and facing outward (tolerance `eps`, relative
/// to the shape's size: 1e-12 for the OBJ's shortest round-trip decimals, 1e-6 for f32).
fn check_on_surface(meta: &DesignMeta, name: &str, tris: &[[V3; 3]], eps: f64) {
    let o = meta
        .scene
        .obstacles
        .iter()
        .find(|o| o.name == name)
        .unwrap();
    assert_eq!(tris.len(), expected(o.kind()), "{name}");
    match &o.shape {
        Shape::Cylinder(c) => {
            let axis = sub(c.b, c.a);
            let len = norm(axis);
            let w = scale(axis, 1.0 / len);
            for t in tris {
                for p in samples_of(t) {
                    let along = dot(sub(p, c.a), w);
                    let radial = norm(sub(sub(p, c.a), scale(w, along)));
                    // Inside the solid cylinder, and on its boundary: a cap or the side's
                    // inscribed polygon (at least r·cos(π/segments) from the axis).
                    assert!(along > -eps && along < len + eps, "{name}: {p:?}");
                    assert!(radial < c.radius + eps, "{name}: {p:?}");
                    let on_cap = along.abs() < eps || (along - len).abs() < eps;
                    assert!(
                        on_cap || radial > c.radius * (PI / S as f64).cos() - eps,
                        "{name}: {p:?}"
                    );
                }
                let n = normal(t);
                let c0 = centroid(t);
                let along = dot(sub(c0, c.a), w);
                let out = sub(sub(c0, c.a), scale(w, along));
                let outward = if along.abs() < eps {
                    scale(w, -1.0)
                } else if (along - len).abs() < eps {
                    w
                } else {
                    out
                };
                assert!(dot(n, outward) > 0.0, "{name}: a triangle faces inward");
            }
        }
        Shape::Sphere(s) => {
            for t in tris {
                for p in t {
                    assert!((norm(sub(*p, s.center)) - s.radius).abs() < eps, "{name}");
                }
                // A UV-sphere triangle spans at most 2π/S of arc (a band's diagonal is
                // √2·π/S·… < 2π/S): its plane is at least r·cos(2π/S) from the centre,
                // and being a chord it lies inside the ball.
                let n = normal(t);
                let d = dot(scale(n, 1.0 / norm(n)), sub(t[0], s.center));
                assert!(d > s.radius * (2.0 * PI / S as f64).cos(), "{name}: {d}");
                for p in samples_of(t) {
                    assert!(norm(sub(p, s.center)) < s.radius + eps, "{name}");
                }
            }
        }
        Shape::Box(b) => {
            for t in tris {
                // All three corners on one face: one local coordinate is ±half there.
                let local = t.map(|p| b.local(p));
                let face = (0..3).find(|&i| {
                    local
                        .iter()
                        .all(|q| (q[i].abs() - b.half[i]).abs() < eps && q[i] * local[0][i] > 0.0)
                });
                let i = face.unwrap_or_else(|| panic!("{name}: {local:?} on no face"));
                for q in &local {
                    assert!(q.iter().zip(b.half).all(|(x, h)| x.abs() < h + eps));
                }
                let outward = scale(b.axes[i], local[0][i].signum());
                assert!(dot(normal(t), outward) > 0.0, "{name}: faces inward");
            }
        }
        Shape::HalfSpace(h) => {
            for t in tris {
                for p in t {
                    assert!(h.height(*p).abs() < eps, "{name}: {p:?} off the plane");
                }
                assert!(
                    dot(normal(t), h.normal) > 0.0,
                    "{name}: faces the solid side"
                );
            }
        }
        Shape::Mesh(m) => {
            let mut m = m.clone();
            let mesh = m.load().unwrap();
            for (k, t) in tris.iter().enumerate() {
                let want = mesh.triangle(k);
                for i in 0..3 {
                    assert!(norm(sub(t[i], want[i])) < eps, "{name}: triangle {k}");
                }
            }
        }
    }
}

/// The arms: arm k + 1 is copy k of the pattern's last frame.
fn check_arms(meta: &DesignMeta, p: &foldsynth::pattern::Pattern, arms: &[Vec<[V3; 3]>], eps: f64) {
    let m = mesh::state_mesh(p, Some(p.frames.len() - 1), false).unwrap();
    assert_eq!(arms.len(), meta.scene.copies.n);
    for (k, tris) in arms.iter().enumerate() {
        assert_eq!(tris.len(), m.triangles.len());
        for (t, want) in tris.iter().zip(&m.triangles) {
            for i in 0..3 {
                let w = meta.scene.copies.apply(k, m.positions[want[i]]);
                assert!(
                    norm(sub(t[i], w)) < eps,
                    "arm {}: {:?} vs {w:?}",
                    k + 1,
                    t[i]
                );
            }
        }
    }
}

#[test]
fn scene_obj_and_stl_parse_back_with_every_shape_on_its_surface() {
    let dir = tempfile::tempdir().unwrap();
    let (p, meta) = samples::every_shape(dir.path()).unwrap();
    let out = dir.path().join("out");
    let files = write_all(&out, &p, &meta, &ExportOptions::default()).unwrap();
    assert_eq!(files.scene_obj, out.join("design-scene.obj"));

    // OBJ: one object per arm and per obstacle, in that order.
    let models = load_obj(&files.scene_obj);
    let names: Vec<&str> = models.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "arm1", "arm2", "arm3", "post", "ball", "crate", "floor", "part"
        ]
    );
    let arms: Vec<Vec<[V3; 3]>> = models[..3].iter().map(corners).collect();
    check_arms(&meta, &p, &arms, 1e-12);
    for m in &models[3..] {
        check_on_surface(&meta, &m.name, &corners(m), 1e-12);
    }

    // STL (binary, f32): the same triangles in the same order.
    let mut f = std::fs::File::open(&files.scene_stl).unwrap();
    let stl = stl_io::read_stl(&mut f).unwrap();
    let per_arm = arms[0].len();
    let obstacles: usize = meta
        .scene
        .obstacles
        .iter()
        .map(|o| expected(o.kind()))
        .sum();
    assert_eq!(stl.faces.len(), 3 * per_arm + obstacles);
    let tris: Vec<[V3; 3]> = stl
        .faces
        .iter()
        .map(|f| {
            f.vertices.map(|i| {
                let v = stl.vertices[i];
                [f64::from(v[0]), f64::from(v[1]), f64::from(v[2])]
            })
        })
        .collect();
    let arms: Vec<Vec<[V3; 3]>> = tris[..3 * per_arm]
        .chunks(per_arm)
        .map(<[_]>::to_vec)
        .collect();
    check_arms(&meta, &p, &arms, 1e-5);
    let mut at = 3 * per_arm;
    for o in &meta.scene.obstacles {
        let n = expected(o.kind());
        check_on_surface(&meta, &o.name, &tris[at..at + n], 1e-5);
        at += n;
    }
}

#[test]
fn the_cli_writes_the_scene_and_names_a_missing_mesh_file() {
    let dir = tempfile::tempdir().unwrap();
    let (p, meta) = samples::every_shape(dir.path()).unwrap();
    let design = dir.path().join("d.json");
    let file = DesignFile {
        pattern: p.clone(),
        meta: meta.clone(),
    };
    std::fs::write(&design, serde_json::to_string(&file).unwrap()).unwrap();
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_foldsynth"))
            .args(args)
            .output()
            .unwrap()
    };
    let ds = design.to_str().unwrap();
    let o = run(&["export", ds, "--format", "scene-obj"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let loaded = foldsynth::export::with_meshes(&meta).unwrap();
    let want = scene_mesh::scene_mesh(&p, Some(p.frames.len() - 1), &loaded).unwrap();
    assert_eq!(
        std::fs::read_to_string(dir.path().join("d.scene.obj")).unwrap(),
        scene_mesh::to_obj(&want, &meta.task)
    );
    let o = run(&["export", ds, "--format", "scene-stl", "--frame", "0"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stl = stl_io::read_stl(&mut std::fs::File::open(dir.path().join("d.scene.stl")).unwrap())
        .unwrap();
    assert_eq!(stl.faces.len(), want.triangles.len());

    // The design names the mesh; without the file nothing is drawn or meshed.
    std::fs::remove_file(dir.path().join("octahedron.obj")).unwrap();
    for fmt in ["fold", "obj"] {
        let o = run(&["export", ds, "--format", fmt]);
        assert!(
            o.status.success(),
            "{fmt}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    for fmt in ["scene-obj", "scene-stl", "png", "all"] {
        let o = run(&["export", ds, "--format", fmt]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{fmt}");
        assert!(
            err.contains("octahedron.obj") && err.contains("meta.scene.obstacles[4]"),
            "{fmt}: {err}"
        );
    }
}

#[test]
fn an_old_design_maps_to_a_scene_and_its_fold_file_carries_it() {
    let design = format!(
        "{}/tests/data/demo_gripper_design.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&design).unwrap();
    assert!(text.contains("\"second_arm\": true") && text.contains("\"obstacle\""));
    let d = DesignFile::parse(&text, &design).unwrap();
    assert_eq!(d.meta.scene.copies, Copies::about_z(2));
    assert_eq!(d.meta.scene.obstacles.len(), 1);
    assert_eq!(d.meta.scene.obstacles[0].name, LEGACY_OBSTACLE_NAME);

    // The half turn about z meshes as before: (−x, −y, z), bit for bit.
    let last = Some(d.pattern.frames.len() - 1);
    assert_eq!(
        mesh::state_mesh_copies(&d.pattern, last, &d.meta.scene.copies).unwrap(),
        mesh::state_mesh(&d.pattern, last, true).unwrap()
    );

    // The FOLD file: the scene, and the keys older readers know.
    let fold =
        foldsynth::export::fold::to_fold_string(&d.pattern, &d.meta, Default::default()).unwrap();
    let f = FoldFile::parse(&fold, "x.fold").unwrap();
    assert_eq!(f.custom["foldsynth:secondArm"], true);
    assert!(f.custom.contains_key("foldsynth:obstacle"));
    assert_eq!(scene_from_fold(&f).unwrap(), d.meta.scene);
    // A FOLD file from before the scene: obstacle and secondArm only.
    let mut v: serde_json::Value = serde_json::from_str(&fold).unwrap();
    v.as_object_mut().unwrap().remove("foldsynth:scene");
    let old = FoldFile::parse(&v.to_string(), "old.fold").unwrap();
    assert_eq!(scene_from_fold(&old).unwrap(), d.meta.scene);

    // The new design JSON writes the scene, and reads back equal.
    let again = serde_json::to_string(&d).unwrap();
    assert!(!again.contains("second_arm"));
    assert_eq!(DesignFile::parse(&again, "again").unwrap(), d);

    // A scene with copies about another axis is written in full and read back.
    let dir = tempfile::tempdir().unwrap();
    let (p, meta) = samples::every_shape(dir.path()).unwrap();
    let fold = foldsynth::export::fold::to_fold_string(&p, &meta, Default::default()).unwrap();
    let f = FoldFile::parse(&fold, "x.fold").unwrap();
    assert_eq!(f.custom["foldsynth:secondArm"], false);
    assert_eq!(scene_from_fold(&f).unwrap(), meta.scene);
    assert_eq!(f.custom["foldsynth:goals"].as_array().unwrap().len(), 4);
}

#[test]
fn bad_scenes_in_a_design_file_name_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let (p, meta) = samples::every_shape(dir.path()).unwrap();
    type Edit = fn(&mut DesignMeta);
    let cases: [(&str, Edit); 5] = [
        ("meta.scene.copies.n", |m| m.scene.copies.n = 0),
        ("meta.scene.copies.direction", |m| {
            m.scene.copies.direction = [0.0, 0.0, 2.0]
        }),
        ("meta.scene.obstacles[1].radius", |m| {
            if let Shape::Sphere(s) = &mut m.scene.obstacles[1].shape {
                s.radius = -1.0;
            }
        }),
        ("meta.scene.obstacles[2].axes", |m| {
            if let Shape::Box(b) = &mut m.scene.obstacles[2].shape {
                b.axes[1] = b.axes[0];
            }
        }),
        ("meta.goals[3].index", |m| m.surfaces.clear()),
    ];
    for (field, edit) in cases {
        let mut m = meta.clone();
        edit(&mut m);
        let text = serde_json::to_string(&DesignFile {
            pattern: p.clone(),
            meta: m,
        })
        .unwrap();
        let e = DesignFile::parse(&text, "d.json").unwrap_err().to_string();
        assert!(e.contains(field), "{field}: {e}");
    }
}
