//! The design in its world as one triangle mesh: every copy of the folded pattern at one
//! state and every obstacle as triangles (cylinders and spheres tessellated, boxes, a
//! half-space as a large square of its boundary plane, meshes as they are), written as OBJ
//! (one object per arm and per obstacle) or STL, so the design and what it must avoid open
//! together in any mesh viewer.

use std::fmt::Write as _;

use super::mesh::{StateMesh, state_mesh_copies};
use super::{DesignMeta, ExportError, Result};
use crate::geom::{self, V3, add, cross, dot, scale, sub};
use crate::pattern::Pattern;
use crate::scene::{Cylinder, HalfSpace, OrientedBox, Shape, Sphere};

/// Segments around a cylinder's axis and a sphere's equator (a sphere has half as many
/// rings from pole to pole).
pub const SEGMENTS: usize = 32;

/// A named run of triangles of a [`SceneMesh`].
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    /// `arm1`, `arm2`, …, or the obstacle's name.
    pub name: String,
    /// What it is: `"arm"` or the obstacle's shape (`"cylinder"`, `"sphere"`, …).
    pub kind: &'static str,
    /// Its triangles: `triangles[first..first + count]`.
    pub first: usize,
    /// How many triangles.
    pub count: usize,
}

/// The scene at one state as triangles.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct SceneMesh {
    /// Vertex positions.
    pub positions: Vec<V3>,
    /// Triangles (indices into `positions`), counter-clockwise seen from outside (the
    /// arms: from the paper's front side; a half-space: from its free side).
    pub triangles: Vec<[usize; 3]>,
    /// The arms first, then the obstacles in the scene's order.
    pub groups: Vec<Group>,
}

impl SceneMesh {
    fn push(&mut self, name: String, kind: &'static str, positions: &[V3], tris: &[[usize; 3]]) {
        let base = self.positions.len();
        self.positions.extend_from_slice(positions);
        self.groups.push(Group {
            name,
            kind,
            first: self.triangles.len(),
            count: tris.len(),
        });
        self.triangles
            .extend(tris.iter().map(|t| [t[0] + base, t[1] + base, t[2] + base]));
    }

    /// The mesh as a [`StateMesh`] with one "arm" (for the STL writers).
    pub fn as_state_mesh(&self) -> StateMesh {
        StateMesh {
            positions: self.positions.clone(),
            triangles: self.triangles.clone(),
            arms: 1,
            per_arm: self.triangles.len(),
        }
    }
}

/// The design at frame `frame` (`None`: the flat state) with all its copies and every
/// obstacle of `meta.scene`. Mesh obstacles must be loaded
/// ([`super::meta_file::load_meshes`]); one that is not is an error naming it.
pub fn scene_mesh(p: &Pattern, frame: Option<usize>, meta: &DesignMeta) -> Result<SceneMesh> {
    let arms = state_mesh_copies(p, frame, &meta.scene.copies)?;
    let mut out = SceneMesh::default();
    for arm in 0..arms.arms {
        let tris = &arms.triangles[arm * arms.per_arm..(arm + 1) * arms.per_arm];
        // Positions are shared by every arm's triangles; each group keeps its own copy so
        // the OBJ's objects are independent.
        let used: Vec<usize> = {
            let mut v: Vec<usize> = tris.iter().flatten().copied().collect();
            v.sort_unstable();
            v.dedup();
            v
        };
        let local: Vec<[usize; 3]> = tris
            .iter()
            .map(|t| t.map(|i| used.binary_search(&i).expect("collected above")))
            .collect();
        let pos: Vec<V3> = used.iter().map(|&i| arms.positions[i]).collect();
        out.push(format!("arm{}", arm + 1), "arm", &pos, &local);
    }
    let (centre, radius) = extent(&arms.positions);
    for (k, o) in meta.scene.obstacles.iter().enumerate() {
        let (pos, tris) = match &o.shape {
            Shape::Cylinder(c) => cylinder(c, SEGMENTS),
            Shape::Sphere(s) => sphere(s, SEGMENTS),
            Shape::Box(b) => oriented_box(b),
            Shape::HalfSpace(h) => half_space(h, centre, 2.0 * radius.max(1.0)),
            Shape::Mesh(m) => {
                let mesh = m.triangles().ok_or_else(|| {
                    ExportError::invalid(
                        format!("meta.scene.obstacles[{k}] ({})", o.name),
                        format!("the mesh {} is not loaded", m.file.display()),
                    )
                })?;
                let tris = mesh.triangles.iter().map(|t| t.map(|i| i as usize));
                (mesh.vertices.clone(), tris.collect())
            }
        };
        out.push(o.name.clone(), o.kind(), &pos, &tris);
    }
    Ok(out)
}

/// Centre of the bounding box of `pts` and the radius of the ball about it holding them.
pub fn extent(pts: &[V3]) -> (V3, f64) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in pts {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    if pts.is_empty() {
        return ([0.0; 3], 0.0);
    }
    let c = scale(add(lo, hi), 0.5);
    let r = pts.iter().map(|p| geom::dist(*p, c)).fold(0.0, f64::max);
    (c, r)
}

/// Two unit vectors completing the unit `w` to a right-handed frame `(u, v, w)`.
fn frame_about(w: V3) -> (V3, V3) {
    let helper = if w[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = geom::normalize(cross(helper, w)).unwrap_or([1.0, 0.0, 0.0]);
    (u, cross(w, u))
}

/// A closed cylinder: `segments` points on each rim, both caps' centres; `4·segments`
/// triangles (side quads split in two, caps as fans), facing outward.
pub fn cylinder(c: &Cylinder, segments: usize) -> (Vec<V3>, Vec<[usize; 3]>) {
    let axis = sub(c.b, c.a);
    let w = geom::normalize(axis).unwrap_or([0.0, 0.0, 1.0]);
    let (u, v) = frame_about(w);
    let ring = |base: V3, k: usize| {
        let th = std::f64::consts::TAU * k as f64 / segments as f64;
        add(
            base,
            add(scale(u, c.radius * th.cos()), scale(v, c.radius * th.sin())),
        )
    };
    let s = segments;
    let mut pos: Vec<V3> = (0..s).map(|k| ring(c.a, k)).collect();
    pos.extend((0..s).map(|k| ring(c.b, k)));
    pos.push(c.a);
    pos.push(c.b);
    let (ca, cb) = (2 * s, 2 * s + 1);
    let mut tris = Vec::with_capacity(4 * s);
    for k in 0..s {
        let k1 = (k + 1) % s;
        // (u, v, w) is right-handed, so counter-clockwise about w faces outward on the
        // side, the b cap faces +w and the a cap −w.
        tris.push([k, k1, s + k1]);
        tris.push([k, s + k1, s + k]);
        tris.push([cb, s + k, s + k1]);
        tris.push([ca, k1, k]);
    }
    (pos, tris)
}

/// A UV sphere: `segments` meridians, `segments / 2` bands from pole to pole (at least 2);
/// every vertex on the sphere, `2·segments·(bands − 1)` triangles facing outward.
pub fn sphere(s: &Sphere, segments: usize) -> (Vec<V3>, Vec<[usize; 3]>) {
    let bands = (segments / 2).max(2);
    let point = |lat: f64, lon: f64| {
        add(
            s.center,
            scale(
                [lat.sin() * lon.cos(), lat.sin() * lon.sin(), lat.cos()],
                s.radius,
            ),
        )
    };
    // Poles first, then the rings between them (ring j = 1..bands, at polar angle jπ/bands).
    let mut pos = vec![point(0.0, 0.0), point(std::f64::consts::PI, 0.0)];
    for j in 1..bands {
        let lat = std::f64::consts::PI * j as f64 / bands as f64;
        for k in 0..segments {
            pos.push(point(
                lat,
                std::f64::consts::TAU * k as f64 / segments as f64,
            ));
        }
    }
    let at = |j: usize, k: usize| 2 + (j - 1) * segments + k % segments;
    let mut tris = Vec::new();
    for k in 0..segments {
        tris.push([0, at(1, k), at(1, k + 1)]);
        tris.push([1, at(bands - 1, k + 1), at(bands - 1, k)]);
        for j in 1..bands - 1 {
            tris.push([at(j, k), at(j + 1, k), at(j + 1, k + 1)]);
            tris.push([at(j, k), at(j + 1, k + 1), at(j, k + 1)]);
        }
    }
    (pos, tris)
}

/// A box's 8 corners (as [`OrientedBox::corners`] numbers them) and 12 triangles facing
/// outward.
pub fn oriented_box(b: &OrientedBox) -> (Vec<V3>, Vec<[usize; 3]>) {
    // Per face: the axis, its sign, and the corners counter-clockwise seen from outside
    // (corner bit i set: + on axis i; the axes are right-handed).
    const QUADS: [[usize; 4]; 6] = [
        [0, 2, 3, 1], // −z
        [4, 5, 7, 6], // +z
        [0, 1, 5, 4], // −y
        [2, 6, 7, 3], // +y
        [0, 4, 6, 2], // −x
        [1, 3, 7, 5], // +x
    ];
    let tris = QUADS
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    (b.corners().to_vec(), tris)
}

/// The boundary plane of a half-space as a square of half side `half` centred at the
/// projection of `near` onto the plane, facing the free side (2 triangles).
pub fn half_space(h: &HalfSpace, near: V3, half: f64) -> (Vec<V3>, Vec<[usize; 3]>) {
    let n = h.normal;
    let c = sub(near, scale(n, dot(n, sub(near, h.point))));
    let (u, v) = frame_about(n);
    let corner = |a: f64, b: f64| add(c, add(scale(u, a * half), scale(v, b * half)));
    let pos = vec![
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    ];
    (pos, vec![[0, 1, 2], [0, 2, 3]])
}

/// Wavefront OBJ text: `v` lines, then one object (`o`) per group.
pub fn to_obj(m: &SceneMesh, name: &str) -> String {
    let mut s = format!(
        "# foldsynth scene: {name}\n# {} vertices, {} triangles\n",
        m.positions.len(),
        m.triangles.len()
    );
    for p in &m.positions {
        let _ = writeln!(s, "v {} {} {}", p[0], p[1], p[2]);
    }
    for g in &m.groups {
        // OBJ names end at whitespace.
        let label: String = g
            .name
            .chars()
            .map(|c| if c.is_whitespace() { '_' } else { c })
            .collect();
        let _ = writeln!(s, "o {label}");
        for t in &m.triangles[g.first..g.first + g.count] {
            let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
        }
    }
    s
}
