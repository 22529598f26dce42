//! [`DesignMeta`] as files write it, old and new: design JSON and FOLD files written
//! before the scene existed carry `obstacle` (one cylinder) and `second_arm` (a copy
//! turned 180° about z); newer ones carry `scene`. Both read into the same
//! [`DesignMeta`], so every design file ever written still draws and meshes as before.

use std::collections::BTreeMap;

use serde::Deserialize;

use super::fold::{FoldError, FoldFile};
use super::{Cylinder, DesignMeta, ExportError, Mode, Result, TargetPoint, check_finite};
use crate::geom::{V3, dot, norm, sub};
use crate::scene::shapes::MeshObstacle;
use crate::scene::{Copies, Obstacle, OrientedBox, Scene, Shape};
use crate::task::terms::{Goal, Target};

/// The name a legacy `obstacle` gets in the scene: it was the task's first
/// `[[check.cylinders]]` entry.
pub const LEGACY_OBSTACLE_NAME: &str = "check.cylinders[0]";

/// Every key a design's `meta` may have, the legacy ones included.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MetaFile {
    task: String,
    #[serde(default)]
    rule_sequence: String,
    #[serde(default)]
    modes: Vec<Mode>,
    #[serde(default)]
    gripping_vertex: Option<usize>,
    #[serde(default)]
    objective: Option<f64>,
    #[serde(default)]
    targets: Vec<TargetPoint>,
    #[serde(default)]
    trajectory: Vec<[f64; 3]>,
    #[serde(default)]
    scene: Option<Scene>,
    #[serde(default)]
    goals: Vec<Target>,
    #[serde(default)]
    surfaces: Vec<MeshObstacle>,
    /// Legacy: the one cylinder.
    #[serde(default)]
    obstacle: Option<Cylinder>,
    /// Legacy: the half-turn copy about z.
    #[serde(default)]
    second_arm: bool,
    #[serde(default)]
    extra: BTreeMap<String, serde_json::Value>,
}

/// The scene of a file before the scene existed.
pub fn legacy_scene(obstacle: Option<Cylinder>, second_arm: bool) -> Scene {
    Scene {
        obstacles: obstacle
            .map(|c| Obstacle {
                name: LEGACY_OBSTACLE_NAME.into(),
                shape: Shape::Cylinder(c),
            })
            .into_iter()
            .collect(),
        copies: Copies::about_z(if second_arm { 2 } else { 1 }),
        containment: Vec::new(),
    }
}

impl TryFrom<MetaFile> for DesignMeta {
    type Error = String;

    fn try_from(m: MetaFile) -> std::result::Result<DesignMeta, String> {
        let legacy = m.obstacle.is_some() || m.second_arm;
        let scene = match m.scene {
            Some(_) if legacy => {
                return Err(
                    "meta: give either `scene` or the older `obstacle`/`second_arm`, not both"
                        .into(),
                );
            }
            Some(s) => s,
            None => {
                // Checked under its old name, so a message points at the key in the file.
                if let Some(c) = &m.obstacle {
                    shape("meta.obstacle", &Shape::Cylinder(*c)).map_err(|e| e.to_string())?;
                }
                legacy_scene(m.obstacle, m.second_arm)
            }
        };
        Ok(DesignMeta {
            task: m.task,
            rule_sequence: m.rule_sequence,
            modes: m.modes,
            gripping_vertex: m.gripping_vertex,
            objective: m.objective,
            targets: m.targets,
            trajectory: m.trajectory,
            scene,
            goals: m.goals,
            surfaces: m.surfaces,
            extra: m.extra,
        })
    }
}

/// Most copies a design file may ask for (the task language's limit).
pub const COPIES_MAX: usize = 12;

/// How far from 1 a unit vector's length and from 0 a frame's dot products may be in a
/// file (they were normalized when written; JSON keeps 17 digits).
const UNIT_TOLERANCE: f64 = 1e-9;

fn unit_vector(what: impl Fn() -> String, v: &V3) -> Result<()> {
    check_finite(&what, v)?;
    if (norm(*v) - 1.0).abs() > UNIT_TOLERANCE {
        return Err(ExportError::invalid(
            what(),
            format!("{v:?} must be a unit vector (length 1)"),
        ));
    }
    Ok(())
}

fn positive(what: impl Fn() -> String, x: f64) -> Result<()> {
    check_finite(&what, &[x])?;
    if x <= 0.0 {
        return Err(ExportError::invalid(what(), format!("{x} must be > 0")));
    }
    Ok(())
}

fn oriented_box(what: &str, b: &OrientedBox) -> Result<()> {
    check_finite(|| format!("{what}.center"), &b.center)?;
    for (i, h) in b.half.iter().enumerate() {
        positive(|| format!("{what}.half[{i}]"), *h)?;
    }
    for (i, a) in b.axes.iter().enumerate() {
        unit_vector(|| format!("{what}.axes[{i}]"), a)?;
    }
    let [x, y, z] = b.axes;
    if [dot(x, y), dot(y, z), dot(x, z)]
        .iter()
        .any(|d| d.abs() > UNIT_TOLERANCE)
    {
        return Err(ExportError::invalid(
            format!("{what}.axes"),
            "the axes must be orthonormal",
        ));
    }
    Ok(())
}

fn mesh_obstacle(what: &str, m: &MeshObstacle) -> Result<()> {
    positive(|| format!("{what}.scale"), m.scale)?;
    check_finite(|| format!("{what}.translate"), &m.translate)
}

fn shape(what: &str, s: &Shape) -> Result<()> {
    match s {
        Shape::Cylinder(c) => {
            check_finite(|| format!("{what}.a"), &c.a)?;
            check_finite(|| format!("{what}.b"), &c.b)?;
            positive(|| format!("{what}.radius"), c.radius)?;
            if norm(sub(c.b, c.a)) == 0.0 {
                return Err(ExportError::invalid(what, "the axis ends a and b coincide"));
            }
            Ok(())
        }
        Shape::Sphere(b) => {
            check_finite(|| format!("{what}.center"), &b.center)?;
            positive(|| format!("{what}.radius"), b.radius)
        }
        Shape::Box(b) => oriented_box(what, b),
        Shape::HalfSpace(h) => {
            check_finite(|| format!("{what}.point"), &h.point)?;
            unit_vector(|| format!("{what}.normal"), &h.normal)
        }
        Shape::Mesh(m) => mesh_obstacle(what, m),
    }
}

fn goal(what: &str, g: &Goal, surfaces: usize) -> Result<()> {
    match g {
        Goal::Point { point } => check_finite(|| format!("{what}.point"), point),
        Goal::Line { point, direction } => {
            check_finite(|| format!("{what}.point"), point)?;
            unit_vector(|| format!("{what}.direction"), direction)
        }
        Goal::Plane { point, normal } => {
            check_finite(|| format!("{what}.point"), point)?;
            unit_vector(|| format!("{what}.normal"), normal)
        }
        Goal::Surface { index } if *index < surfaces => Ok(()),
        Goal::Surface { index } => Err(ExportError::invalid(
            format!("{what}.index"),
            format!("surface {index} out of range: meta.surfaces has {surfaces}"),
        )),
    }
}

/// Check the scene, goals and surfaces of a design's metadata (numbers finite, radii and
/// half extents positive, directions unit, 1 ≤ copies ≤ [`COPIES_MAX`]); mesh files are
/// not read here (see [`load_meshes`]).
pub fn validate_scene(meta: &DesignMeta) -> Result<()> {
    let sc = &meta.scene;
    for (k, o) in sc.obstacles.iter().enumerate() {
        shape(&format!("meta.scene.obstacles[{k}]"), &o.shape)?;
    }
    let c = &sc.copies;
    if !(1..=COPIES_MAX).contains(&c.n) {
        return Err(ExportError::invalid(
            "meta.scene.copies.n",
            format!("{} is not allowed: 1 to {COPIES_MAX} copies", c.n),
        ));
    }
    check_finite(|| "meta.scene.copies.point".into(), &c.point)?;
    unit_vector(|| "meta.scene.copies.direction".into(), &c.direction)?;
    for (k, b) in sc.containment.iter().enumerate() {
        oriented_box(&format!("meta.scene.containment[{k}].bounds"), &b.bounds)?;
        if let Some(t) = b.t {
            check_finite(|| format!("meta.scene.containment[{k}].t"), &[t])?;
        }
    }
    for (k, m) in meta.surfaces.iter().enumerate() {
        mesh_obstacle(&format!("meta.surfaces[{k}]"), m)?;
    }
    for (k, t) in meta.goals.iter().enumerate() {
        check_finite(|| format!("meta.goals[{k}].t"), &[t.t])?;
        positive(|| format!("meta.goals[{k}].weight"), t.weight)?;
        goal(&format!("meta.goals[{k}]"), &t.goal, meta.surfaces.len())?;
    }
    Ok(())
}

/// The meshes of a design, read from their files: every mesh obstacle of the scene and
/// every surface, loaded in place (a file already loaded is not read again). A missing or
/// unreadable file is an error naming the field and the file.
pub fn load_meshes(meta: &mut DesignMeta) -> Result<()> {
    for (k, o) in meta.scene.obstacles.iter_mut().enumerate() {
        if let Shape::Mesh(m) = &mut o.shape {
            m.load().map_err(|e| {
                ExportError::invalid(
                    format!("meta.scene.obstacles[{k}] ({})", o.name),
                    e.to_string(),
                )
            })?;
        }
    }
    for (k, m) in meta.surfaces.iter_mut().enumerate() {
        m.load()
            .map_err(|e| ExportError::invalid(format!("meta.surfaces[{k}]"), e.to_string()))?;
    }
    Ok(())
}

/// The scene a FOLD file written by foldsynth carries: `foldsynth:scene`, or, in files
/// written before the scene existed, `foldsynth:obstacle` and `foldsynth:secondArm`
/// mapped as [`legacy_scene`] maps them. A file with neither has an empty scene.
pub fn scene_from_fold(f: &FoldFile) -> std::result::Result<Scene, FoldError> {
    let err = |field: &str, e: serde_json::Error| FoldError {
        file: f.source.clone(),
        field: field.into(),
        message: format!("not a foldsynth scene: {e}"),
    };
    if let Some(v) = f.custom.get("foldsynth:scene") {
        return Scene::deserialize(v).map_err(|e| err("foldsynth:scene", e));
    }
    let obstacle = match f.custom.get("foldsynth:obstacle") {
        Some(v) => Some(Cylinder::deserialize(v).map_err(|e| err("foldsynth:obstacle", e))?),
        None => None,
    };
    let second_arm = match f.custom.get("foldsynth:secondArm") {
        Some(v) => bool::deserialize(v).map_err(|e| err("foldsynth:secondArm", e))?,
        None => false,
    };
    Ok(legacy_scene(obstacle, second_arm))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_old_meta_reads_as_a_scene_and_writes_back_the_same_scene() {
        let old = r#"{"task": "gripper", "obstacle": {"a": [0, 0, 0], "b": [0, 0, 1], "radius": 0.2},
                      "second_arm": true}"#;
        let m: DesignMeta = serde_json::from_str(old).unwrap();
        assert!(m.second_arm());
        assert_eq!(m.first_cylinder().map(|c| c.radius), Some(0.2));
        assert_eq!(m.scene.obstacles[0].name, LEGACY_OBSTACLE_NAME);
        let again: DesignMeta = serde_json::from_str(&serde_json::to_string(&m).unwrap()).unwrap();
        assert_eq!(again, m);
        let text = serde_json::to_string(&m).unwrap();
        assert!(
            !text.contains("second_arm") && !text.contains("\"obstacle\""),
            "{text}"
        );
    }

    #[test]
    fn both_forms_at_once_and_unknown_keys_are_refused() {
        let both = r#"{"task": "x", "second_arm": true, "scene": {"obstacles": [],
                       "copies": {"n": 1, "point": [0,0,0], "direction": [0,0,1]}, "containment": []}}"#;
        let e = serde_json::from_str::<DesignMeta>(both).unwrap_err();
        assert!(e.to_string().contains("either"), "{e}");
        assert!(serde_json::from_str::<DesignMeta>(r#"{"task": "x", "obstacles": []}"#).is_err());
        let m: DesignMeta = serde_json::from_str(r#"{"task": "x"}"#).unwrap();
        assert!(m.scene.is_empty() && !m.second_arm());
    }
}
