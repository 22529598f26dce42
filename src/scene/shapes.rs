//! Obstacle shapes: cylinder, sphere, box (any orientation), half-space and triangle mesh.
//!
//! Each is a closed solid (a mesh: its surface, and its inside when it is closed) that no
//! facet of any copy may come within the task's `obstacle_clearance` of. What "within"
//! means is decided twice, independently: by the optimizer's constraints (`model/`) and by
//! the judges (`check/`).

use std::path::PathBuf;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::mesh::{MeshError, TriangleMesh};
use crate::geom::{V3, add, cross, dot, norm, scale, sub};

/// A finite solid cylinder: axis segment `a → b` and radius (flat caps).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cylinder {
    /// One end of the axis segment (centre of one cap).
    pub a: [f64; 3],
    /// The other end of the axis segment (centre of the other cap).
    pub b: [f64; 3],
    /// Radius (> 0).
    pub radius: f64,
}

/// A solid ball.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sphere {
    /// Centre.
    pub center: V3,
    /// Radius (> 0).
    pub radius: f64,
}

/// A box in any orientation: `center + Σ_i s_i · half[i] · axes[i]`, `s_i ∈ [−1, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct OrientedBox {
    /// Centre.
    pub center: V3,
    /// Half the edge length along each axis (> 0).
    pub half: V3,
    /// Orthonormal, right-handed axes (rows): the box's local x, y, z.
    pub axes: [V3; 3],
}

impl OrientedBox {
    /// The axis-aligned box `[min, max]`.
    pub fn aligned(min: V3, max: V3) -> OrientedBox {
        OrientedBox {
            center: scale(add(min, max), 0.5),
            half: scale(sub(max, min), 0.5),
            axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    /// The point's coordinates in the box frame (relative to the centre).
    pub fn local(&self, p: V3) -> V3 {
        let d = sub(p, self.center);
        [
            dot(d, self.axes[0]),
            dot(d, self.axes[1]),
            dot(d, self.axes[2]),
        ]
    }

    /// The point with box-frame coordinates `q`.
    pub fn world(&self, q: V3) -> V3 {
        let mut p = self.center;
        for (i, axis) in self.axes.iter().enumerate() {
            p = add(p, scale(*axis, q[i]));
        }
        p
    }

    /// The 8 corners; corner `k` has sign `−` on axis `i` when bit `i` of `k` is 0.
    pub fn corners(&self) -> [V3; 8] {
        std::array::from_fn(|k| {
            let s = |i: usize| if k >> i & 1 == 1 { 1.0 } else { -1.0 };
            self.world([
                s(0) * self.half[0],
                s(1) * self.half[1],
                s(2) * self.half[2],
            ])
        })
    }
}

/// A half-space obstacle: everything on the side the unit `normal` points away from,
/// `n·(x − point) < 0`. The free side is `n·(x − point) ≥ 0` (a table with normal +z).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HalfSpace {
    /// A point on the boundary plane.
    pub point: V3,
    /// Unit normal, pointing into free space.
    pub normal: V3,
}

impl HalfSpace {
    /// Signed height of `x` above the boundary (positive in free space).
    pub fn height(&self, x: V3) -> f64 {
        dot(self.normal, sub(x, self.point))
    }
}

/// A triangle mesh obstacle read from an STL or OBJ file.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MeshObstacle {
    /// The file, as resolved when the task was loaded (absolute).
    pub file: PathBuf,
    /// Scale applied to the file's coordinates (paper units per file unit).
    pub scale: f64,
    /// Translation applied after scaling.
    pub translate: V3,
    /// The triangles, transformed (filled by [`MeshObstacle::load`]; not serialized: a
    /// design file names the mesh file instead of copying it).
    #[serde(skip)]
    pub mesh: Option<Arc<TriangleMesh>>,
}

impl PartialEq for MeshObstacle {
    fn eq(&self, other: &Self) -> bool {
        self.file == other.file && self.scale == other.scale && self.translate == other.translate
    }
}

impl MeshObstacle {
    /// Read the file (STL, ASCII or binary, or OBJ), scale and translate it (once: a
    /// loaded mesh is kept).
    pub fn load(&mut self) -> Result<&TriangleMesh, MeshError> {
        if self.mesh.is_none() {
            let bytes = super::mesh::read_bytes(&self.file)?;
            self.load_bytes(&bytes)?;
        }
        Ok(self.mesh.as_deref().expect("loaded above"))
    }

    /// Parse `bytes` as the contents of the file (read by the caller, who also digests
    /// them), scale and translate the mesh and keep it.
    pub fn load_bytes(&mut self, bytes: &[u8]) -> Result<&TriangleMesh, MeshError> {
        let mut m = TriangleMesh::parse(&self.file, bytes)?;
        m.transform(self.scale, self.translate);
        Ok(&**self.mesh.insert(Arc::new(m)))
    }

    /// The loaded triangles (`None` before [`MeshObstacle::load`]).
    pub fn triangles(&self) -> Option<&TriangleMesh> {
        self.mesh.as_deref()
    }
}

/// The shape of an obstacle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "lowercase")]
pub enum Shape {
    /// A finite solid cylinder.
    Cylinder(Cylinder),
    /// A solid ball.
    Sphere(Sphere),
    /// A solid box in any orientation.
    Box(OrientedBox),
    /// A half-space (a table, a wall).
    #[serde(rename = "halfspace")]
    HalfSpace(HalfSpace),
    /// A triangle mesh (a part from CAD).
    Mesh(MeshObstacle),
}

/// An obstacle: a shape with a name for messages and records.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Obstacle {
    /// `obstacles[k]` (or `check.cylinders[k]`), or the task's `name` for it.
    pub name: String,
    /// Its shape.
    #[serde(flatten)]
    pub shape: Shape,
}

impl Obstacle {
    /// The shape's kind as the task file writes it.
    pub fn kind(&self) -> &'static str {
        match self.shape {
            Shape::Cylinder(_) => "cylinder",
            Shape::Sphere(_) => "sphere",
            Shape::Box(_) => "box",
            Shape::HalfSpace(_) => "halfspace",
            Shape::Mesh(_) => "mesh",
        }
    }

    /// A ball containing the obstacle (`None` for a half-space, which no ball contains).
    pub fn bounding_ball(&self) -> Option<(V3, f64)> {
        match &self.shape {
            Shape::Cylinder(c) => {
                let mid = scale(add(c.a, c.b), 0.5);
                Some((mid, 0.5 * norm(sub(c.b, c.a)) + c.radius))
            }
            Shape::Sphere(s) => Some((s.center, s.radius)),
            Shape::Box(b) => Some((b.center, norm(b.half))),
            Shape::HalfSpace(_) => None,
            Shape::Mesh(m) => m.triangles().map(TriangleMesh::bounding_ball),
        }
    }
}

/// A unit vector along `v`, or `None` when `v` has (almost) no length.
pub fn unit(v: V3) -> Option<V3> {
    let n = norm(v);
    (n.is_finite() && n > 1e-12).then(|| scale(v, 1.0 / n))
}

/// Orthonormal right-handed axes from a box's `x_axis` and `y_axis` as a task gives them:
/// `y` is made orthogonal to `x` (Gram–Schmidt), `z = x × y`. `Err` names which is
/// degenerate.
pub fn frame(x: V3, y: V3) -> Result<[V3; 3], &'static str> {
    let ex = unit(x).ok_or("x_axis has zero length")?;
    let ey = unit(sub(y, scale(ex, dot(y, ex)))).ok_or("y_axis is zero or parallel to x_axis")?;
    Ok([ex, ey, cross(ex, ey)])
}
