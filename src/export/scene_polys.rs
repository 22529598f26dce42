//! The scene's obstacles and boxes as the pictures draw them (PNG, SVG and GIF share
//! these): polygons of every obstacle but the first cylinder (which the pictures have
//! always drawn as 24 side quads and two caps, kept so their bytes do not change), and the
//! edges of the containment boxes.

use super::DesignMeta;
use super::scene_mesh::{cylinder, half_space, oriented_box, sphere};
use crate::geom::V3;
use crate::scene::Shape;

/// Segments of a sphere's or a further cylinder's outline in pictures.
const SEGMENTS: usize = 24;

/// Polygons (3D, counter-clockwise seen from outside) of every obstacle but the scene's
/// first cylinder; a half-space is a square of half side `half` about the point of its
/// plane nearest `near`; a mesh obstacle not loaded draws nothing (loading it is the
/// caller's, see [`super::with_meshes`]).
pub fn obstacle_polys(meta: &DesignMeta, near: V3, half: f64) -> Vec<Vec<V3>> {
    let first = meta
        .scene
        .obstacles
        .iter()
        .position(|o| matches!(o.shape, Shape::Cylinder(_)));
    let mut out = Vec::new();
    for (k, o) in meta.scene.obstacles.iter().enumerate() {
        let (pos, tris) = match &o.shape {
            Shape::Cylinder(_) if Some(k) == first => continue,
            Shape::Cylinder(c) => cylinder(c, SEGMENTS),
            Shape::Sphere(s) => sphere(s, SEGMENTS),
            Shape::Box(b) => oriented_box(b),
            Shape::HalfSpace(h) => half_space(h, near, half),
            Shape::Mesh(m) => match m.triangles() {
                Some(mesh) => {
                    let tris = mesh.triangles.iter().map(|t| t.map(|i| i as usize));
                    (mesh.vertices.clone(), tris.collect())
                }
                None => continue,
            },
        };
        out.extend(tris.iter().map(|t| t.iter().map(|&i| pos[i]).collect()));
    }
    out
}

/// The 12 edges of every containment box.
pub fn containment_edges(meta: &DesignMeta) -> Vec<[V3; 2]> {
    let mut out = Vec::new();
    for c in &meta.scene.containment {
        let p = c.bounds.corners();
        for k in 0..8 {
            for bit in [1, 2, 4] {
                if k & bit == 0 {
                    out.push([p[k], p[k | bit]]);
                }
            }
        }
    }
    out
}
