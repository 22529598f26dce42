//! The world a design moves in: obstacles of every common shape, the rotational copies of
//! the designed arm, and boxes the folded pattern must stay inside (issue 31).
//!
//! This module is plain data with the geometry every stage needs to *place* things (box
//! corners and frames, the rotation of copy k, mesh triangles read from STL/OBJ). It holds
//! no judgement: the optimizer's clearance constraints are built in `model/`, the
//! independent judges that re-check every design live in `check/`, and neither calls the
//! other. `task/` parses a task file into a [`Scene`]; `export/` draws and writes it.
//!
//! Units are paper units (G0's shortest crease is the scale a task is written in), angles
//! radians.

pub mod copies;
pub mod mesh;
pub mod shapes;

pub use copies::Copies;
pub use mesh::{MeshError, TriangleMesh};
pub use shapes::{Cylinder, HalfSpace, Obstacle, OrientedBox, Shape, Sphere};

use serde::{Deserialize, Serialize};

/// A box the folded pattern (every facet of every copy) must stay inside, with the task's
/// `obstacle_clearance` to its walls.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Containment {
    /// The box.
    pub bounds: OrientedBox,
    /// The one state it applies at; `None`: every state of the motion (a workspace).
    pub t: Option<f64>,
    /// A short label for messages and records (`inside[0]`, or the task's `name`).
    pub name: String,
}

/// Everything around the designed arm.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Scene {
    /// Obstacles, in the order the task gives them (the legacy `[[check.cylinders]]`
    /// first).
    pub obstacles: Vec<Obstacle>,
    /// Rotational copies of the arm (n = 1: the arm alone).
    pub copies: Copies,
    /// Boxes the folded pattern stays inside.
    pub containment: Vec<Containment>,
}

impl Scene {
    /// The cylinders among the obstacles (what older code and files know how to draw).
    pub fn cylinders(&self) -> impl Iterator<Item = &Cylinder> {
        self.obstacles.iter().filter_map(|o| match &o.shape {
            Shape::Cylinder(c) => Some(c),
            _ => None,
        })
    }

    /// Whether the scene is empty: no obstacle, no copy, no box.
    pub fn is_empty(&self) -> bool {
        self.obstacles.is_empty() && self.copies.n == 1 && self.containment.is_empty()
    }
}
