//! The device of n arms (issue 31): the arm and its copies turned by 2πk/n about the
//! scene's axis ([`crate::scene::Copies`]), as one pattern the judges check, and the
//! crossings between copies (Möller's test, as for the two-armed gripper).
//!
//! n = 2 about the z-axis is exactly [`super::two_armed`] (the thesis's gripper: the same
//! pattern bit for bit). Otherwise copy k's positions are [`Copies::apply`]'s, its flat
//! layout (which only the triangulation and the crease detection read) is the arm's turned
//! by 2πk/n about the pivot — the flat position of the first vertex that stays on the axis
//! in every state, or the origin — and an arm vertex on the axis in every state whose
//! turned flat position is its own (within 1e-9) is shared by every copy, as the gripper's
//! v1 is.

use std::collections::HashSet;

use nalgebra::Vector3;

use super::rotated_copy::{RotatedCopyError, two_armed};
use super::self_intersection::{CheckError, Checker, Intersection};
use crate::pattern::{Edge, Frame, Pattern};
use crate::scene::Copies;

/// Distance within which a vertex counts as on the axis, and two flat positions as one.
pub const SHARED_TOL: f64 = 1e-9;

/// The n-armed pattern and where each arm vertex went.
#[derive(Clone, Debug, PartialEq)]
pub struct CopiedPattern {
    /// Arm vertices first (same indices), then each copy's own vertices; arm facets first,
    /// then copy 1's, …, copy n − 1's (facet `f` of copy k is `k · arm_faces + f`).
    pub pattern: Pattern,
    /// `index[k][i]`: the pattern index of arm vertex `i` in copy `k` (`index[0][i] = i`).
    pub index: Vec<Vec<usize>>,
    /// Number of the arm's facets.
    pub arm_faces: usize,
}

impl CopiedPattern {
    /// Which copy facet `f` belongs to.
    pub fn copy_of_face(&self, f: usize) -> usize {
        f / self.arm_faces.max(1)
    }
}

/// The arm and its `copies.n − 1` copies as one pattern (see the module docs).
pub fn with_copies(arm: &Pattern, copies: &Copies) -> Result<CopiedPattern, RotatedCopyError> {
    let nv = arm.vertices.len();
    for fr in &arm.frames {
        if fr.coords.len() != nv {
            return Err(RotatedCopyError::FrameSize {
                t: fr.t,
                expected: nv,
                got: fr.coords.len(),
            });
        }
    }
    let n = copies.n.max(1);
    let arm_faces = arm.faces.len();
    if n == 1 {
        return Ok(CopiedPattern {
            pattern: arm.clone(),
            index: vec![(0..nv).collect()],
            arm_faces,
        });
    }
    if *copies == Copies::about_z(2) {
        let pattern = two_armed(arm)?;
        // two_armed merges the copy of a vertex with the vertex at its turned flat position
        // and appends the others in order.
        let mut next = nv;
        let copy: Vec<usize> = arm
            .vertices
            .iter()
            .map(|p| {
                let q = [-p[0], -p[1]];
                arm.vertices
                    .iter()
                    .position(|o| (o[0] - q[0]).hypot(o[1] - q[1]) <= SHARED_TOL)
                    .unwrap_or_else(|| {
                        next += 1;
                        next - 1
                    })
            })
            .collect();
        return Ok(CopiedPattern {
            pattern,
            index: vec![(0..nv).collect(), copy],
            arm_faces,
        });
    }
    Ok(general(arm, copies, n))
}

/// Whether arm vertex `i` is on the axis in every state (in the flat state lifted to z = 0
/// when the arm has no frames).
fn on_axis(arm: &Pattern, copies: &Copies, i: usize) -> bool {
    let (p0, u) = (Vector3::from(copies.point), Vector3::from(copies.direction));
    let off = |x: [f64; 3]| {
        let w = Vector3::from(x) - p0;
        (w - u * u.dot(&w)).norm() <= SHARED_TOL
    };
    if arm.frames.is_empty() {
        off([arm.vertices[i][0], arm.vertices[i][1], 0.0])
    } else {
        arm.frames.iter().all(|fr| off(fr.coords[i]))
    }
}

/// [`with_copies`] for every case but the half turn about z.
fn general(arm: &Pattern, copies: &Copies, n: usize) -> CopiedPattern {
    let nv = arm.vertices.len();
    let axis: Vec<bool> = (0..nv).map(|i| on_axis(arm, copies, i)).collect();
    let pivot = axis
        .iter()
        .position(|a| *a)
        .map_or([0.0, 0.0], |i| arm.vertices[i]);
    let mut vertices = arm.vertices.clone();
    let mut index: Vec<Vec<usize>> = vec![(0..nv).collect()];
    for k in 1..n {
        let angle = std::f64::consts::TAU * k as f64 / n as f64;
        let (mut s, mut c) = angle.sin_cos();
        let quarters = 4.0 * k as f64 / n as f64;
        if (quarters - quarters.round()).abs() < 1e-12 {
            (c, s) = (c.round(), s.round());
        }
        let turn = |p: [f64; 2]| {
            let (x, y) = (p[0] - pivot[0], p[1] - pivot[1]);
            [pivot[0] + c * x - s * y, pivot[1] + s * x + c * y]
        };
        let row = (0..nv)
            .map(|i| {
                let q = turn(arm.vertices[i]);
                let p = arm.vertices[i];
                if axis[i] && (q[0] - p[0]).hypot(q[1] - p[1]) <= SHARED_TOL {
                    i
                } else {
                    vertices.push(q);
                    vertices.len() - 1
                }
            })
            .collect();
        index.push(row);
    }
    let frames = arm
        .frames
        .iter()
        .map(|fr| {
            let mut coords = vec![[0.0; 3]; vertices.len()];
            for (k, row) in index.iter().enumerate() {
                for (i, &j) in row.iter().enumerate() {
                    coords[j] = if k == 0 || j == i {
                        fr.coords[i]
                    } else {
                        copies.apply(k, fr.coords[i])
                    };
                }
            }
            (coords, fr)
        })
        .collect::<Vec<_>>();
    let (edges, edge_source) = copied_edges(arm, &index);
    let frames = frames
        .into_iter()
        .map(|(coords, fr)| Frame {
            t: fr.t,
            coords,
            fold_angles: if fr.fold_angles.len() == arm.edges.len() {
                edge_source.iter().map(|&e| fr.fold_angles[e]).collect()
            } else {
                Vec::new()
            },
        })
        .collect();
    let faces = index
        .iter()
        .flat_map(|row| {
            arm.faces
                .iter()
                .map(move |f| f.iter().map(|&v| row[v]).collect::<Vec<_>>())
        })
        .collect();
    CopiedPattern {
        pattern: Pattern {
            vertices,
            edges,
            faces,
            frames,
        },
        index,
        arm_faces: arm.faces.len(),
    }
}

/// Every copy's edges, each undirected edge once, and the arm edge each comes from.
fn copied_edges(arm: &Pattern, index: &[Vec<usize>]) -> (Vec<Edge>, Vec<usize>) {
    let key = |v: [usize; 2]| (v[0].min(v[1]), v[0].max(v[1]));
    let mut seen: HashSet<(usize, usize)> = HashSet::new();
    let (mut edges, mut source) = (Vec::new(), Vec::new());
    for row in index {
        for (k, e) in arm.edges.iter().enumerate() {
            let v = [row[e.v[0]], row[e.v[1]]];
            if seen.insert(key(v)) {
                edges.push(Edge { v, kind: e.kind });
                source.push(k);
            }
        }
    }
    (edges, source)
}

/// Möller crossings between facets of different copies at every frame of the n-armed
/// pattern (crossings within one arm are the self-intersection check's).
pub fn copy_crossings(copied: &CopiedPattern) -> Result<Vec<Intersection>, CheckError> {
    let pat = &copied.pattern;
    let checker = Checker::from_pattern(pat)?;
    let mut out = Vec::new();
    for fr in &pat.frames {
        checker.validate_state(&fr.coords, fr.t)?;
        out.extend(
            checker
                .crossings(&fr.coords, fr.t, false)
                .into_iter()
                .filter(|x| copied.copy_of_face(x.face_a) != copied.copy_of_face(x.face_b)),
        );
    }
    Ok(out)
}
