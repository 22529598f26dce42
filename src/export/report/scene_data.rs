//! The scene as the report's 3D view reads it: every obstacle (a mesh with its triangles,
//! read from its file), the copies, the containment boxes (as corners) and the meshes of
//! surface goals. A report carries each distinct scene once (the designs of one task share
//! it) and each design names its scene by index, so a mesh is embedded once however many
//! designs are shown.

use serde_json::{Value, json};

use super::super::meta_file::load_meshes;
use super::super::{DesignMeta, Result};
use crate::scene::shapes::MeshObstacle;
use crate::scene::{Shape, TriangleMesh};
use crate::task::terms::Goal;

/// Mesh triangles as flat arrays (`vertices`: x, y, z, …; `triangles`: i, j, k, …).
fn mesh_json(m: &TriangleMesh) -> Value {
    let vertices: Vec<f64> = m.vertices.iter().flatten().copied().collect();
    let triangles: Vec<u32> = m.triangles.iter().flatten().copied().collect();
    json!({ "vertices": vertices, "triangles": triangles })
}

fn loaded(m: &MeshObstacle) -> Value {
    m.triangles().map_or(Value::Null, mesh_json)
}

/// One scene for the page: `obstacles` (each `{name, shape, …}` as a design file writes
/// it, a box with its `corners`, a mesh with its `vertices` and `triangles`), `copies`
/// (`n`, `point`, `direction`), `containment` (`name`, `t`, `corners`: 8 points, corner `k`
/// with sign + on axis i where bit i of k is set) and `surfaces` (meshes of surface goals).
/// Mesh files are read here; a missing one is an error naming it.
pub fn scene_json(meta: &DesignMeta) -> Result<Value> {
    let mut meta = meta.clone();
    load_meshes(&mut meta)?;
    let obstacles: Vec<Value> = meta
        .scene
        .obstacles
        .iter()
        .map(|o| {
            let mut v = serde_json::to_value(o).unwrap_or(Value::Null);
            match &o.shape {
                Shape::Box(b) => v["corners"] = json!(b.corners()),
                Shape::Mesh(m) => v["mesh"] = loaded(m),
                _ => {}
            }
            v
        })
        .collect();
    let containment: Vec<Value> = meta
        .scene
        .containment
        .iter()
        .map(|c| json!({ "name": c.name, "t": c.t, "corners": c.bounds.corners() }))
        .collect();
    let surfaces: Vec<Value> = meta.surfaces.iter().map(loaded).collect();
    Ok(json!({
        "obstacles": obstacles,
        "copies": meta.scene.copies,
        "containment": containment,
        "surfaces": surfaces,
    }))
}

/// The goals the view draws besides target points (lines, planes, surfaces), each once:
/// a path of samples on one line is one line.
pub fn goals_json(meta: &DesignMeta) -> Value {
    let mut out: Vec<&Goal> = Vec::new();
    for t in &meta.goals {
        if !matches!(t.goal, Goal::Point { .. }) && !out.contains(&&t.goal) {
            out.push(&t.goal);
        }
    }
    json!(out)
}
