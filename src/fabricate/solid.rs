//! Closed triangle meshes of the panels, and the rigid motion of a facet.

use super::Panel;
use crate::geom::{self, V3};
use crate::pattern::{Frame, Pattern};

/// A closed triangle mesh (outward-facing, manifold), paper units.
#[derive(Clone, Debug, PartialEq)]
pub struct Solid {
    /// The facet whose panel this is.
    pub facet: usize,
    /// Corners.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as indices into `vertices`, counter-clockwise seen from outside.
    pub triangles: Vec<[usize; 3]>,
}

/// The loft of a panel's layers: caps at the lowest and highest layer, one quad (two
/// triangles) per side between consecutive layers. Corner k of layer i is vertex `i·n + k`.
pub(super) fn loft(panel: &Panel) -> Solid {
    let n = panel.layers[0].outline.len();
    let top = panel.layers.len() - 1;
    let vertices = panel
        .layers
        .iter()
        .flat_map(|l| l.outline.iter().map(move |p| [p[0], p[1], l.offset]))
        .collect();
    let mut triangles = Vec::new();
    // The caps' outlines passed `offset_polygon`'s simplicity test, so ear clipping finds
    // ears; a fan is the fallback for a cap it could not clip.
    let cap = |l: usize| {
        geom::triangulate_2d(&panel.layers[l].outline)
            .unwrap_or_else(|| (1..n - 1).map(|k| [0, k, k + 1]).collect())
    };
    for [a, b, c] in cap(0) {
        triangles.push([a, c, b]);
    }
    for [a, b, c] in cap(top) {
        triangles.push([top * n + a, top * n + b, top * n + c]);
    }
    for i in 0..top {
        for k in 0..n {
            let k1 = (k + 1) % n;
            let (a, b) = (i * n + k, i * n + k1);
            let (c, d) = ((i + 1) * n + k1, (i + 1) * n + k);
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    Solid {
        facet: panel.facet,
        vertices,
        triangles,
    }
}

/// A rigid motion `x ↦ R·x + t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// Rotation, rows.
    pub r: [[f64; 3]; 3],
    /// Translation.
    pub t: V3,
}

impl Motion {
    /// The image of `p`.
    pub fn apply(&self, p: V3) -> V3 {
        let r = &self.r;
        [
            geom::dot(r[0], p) + self.t[0],
            geom::dot(r[1], p) + self.t[1],
            geom::dot(r[2], p) + self.t[2],
        ]
    }

    /// The image of the direction `v` (no translation).
    pub fn rotate(&self, v: V3) -> V3 {
        [
            geom::dot(self.r[0], v),
            geom::dot(self.r[1], v),
            geom::dot(self.r[2], v),
        ]
    }
}

/// The rigid motion of facet `facet` from the flat layout (z = 0, +z its normal) to
/// `frame`: fixed by its longest side and its Newell normal, through its centroid.
/// A degenerate facet (zero side or zero normal) gets the identity.
pub fn facet_motion(pattern: &Pattern, facet: usize, frame: &Frame) -> Motion {
    let face = &pattern.faces[facet];
    let n = face.len();
    let flat: Vec<V3> = face
        .iter()
        .map(|&v| [pattern.vertices[v][0], pattern.vertices[v][1], 0.0])
        .collect();
    let moved: Vec<V3> = face.iter().map(|&v| frame.coords[v]).collect();
    let k = (0..n)
        .max_by(|&i, &j| {
            let l = |k: usize| geom::dist(flat[k], flat[(k + 1) % n]);
            l(i).total_cmp(&l(j))
        })
        .unwrap_or(0);
    let basis = |pts: &[V3]| -> Option<[V3; 3]> {
        let u = geom::normalize(geom::sub(pts[(k + 1) % n], pts[k]))?;
        let nn = geom::newell_normal(pts);
        let z = geom::normalize(geom::sub(nn, geom::scale(u, geom::dot(nn, u))))?;
        Some([u, geom::cross(z, u), z])
    };
    let centroid = |pts: &[V3]| {
        let s = pts.iter().fold([0.0; 3], |a, p| geom::add(a, *p));
        geom::scale(s, 1.0 / n as f64)
    };
    let (Some(f), Some(m)) = (basis(&flat), basis(&moved)) else {
        return Motion {
            r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            t: [0.0; 3],
        };
    };
    // R = M·Fᵀ: columns of M are the moved basis, rows of Fᵀ… the flat basis.
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = (0..3).map(|b| m[b][i] * f[b][j]).sum();
        }
    }
    let mo = Motion { r, t: [0.0; 3] };
    let t = geom::sub(centroid(&moved), mo.apply(centroid(&flat)));
    Motion { r, t }
}
