//! Building a symmetric pattern from one arm: the gripper of thesis Sec. 5.5 is the
//! optimized arm plus a copy rotated 180° about the z-axis (Fig. 46a), so that the
//! self-intersection check can cover both arms together.

use thiserror::Error;

use crate::pattern::{Edge, Frame, Pattern};

/// Why a rotated copy could not be merged with the original.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RotatedCopyError {
    /// A vertex is shared in the flat layout but its copy leaves it in some folded state.
    #[error(
        "vertex {vertex} lies on the rotation axis in the flat layout (it is shared by both \
         copies) but at t = {t} its copy is {gap:.3e} away from it; the folded state is not \
         symmetric about the z-axis"
    )]
    SharedVertexMoves {
        /// The shared vertex (original index).
        vertex: usize,
        /// The state where the copies disagree.
        t: f64,
        /// Distance between the vertex and its rotated copy.
        gap: f64,
    },
    /// Frames have the wrong number of positions or angles.
    #[error("frame at t = {t} has {got} positions for {expected} vertices")]
    FrameSize {
        /// The state.
        t: f64,
        /// Vertex count of the pattern.
        expected: usize,
        /// Positions in the frame.
        got: usize,
    },
}

fn rot2(p: [f64; 2], c: f64, s: f64) -> [f64; 2] {
    [c * p[0] - s * p[1], s * p[0] + c * p[1]]
}

fn rot3(p: [f64; 3], c: f64, s: f64) -> [f64; 3] {
    [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]]
}

/// The pattern plus a copy of itself rotated by `angle` about the z-axis (in the flat
/// layout and in every frame). A copied vertex whose flat position coincides (within `tol`)
/// with an original vertex is merged with it — for the gripper that is `v1` at the origin,
/// which both arms share — and must then coincide in every frame too. Edges that become
/// duplicates after merging are kept once. Copies come after the originals: original
/// vertex `i` keeps index `i`, and original facet `f` has its copy at `f + faces.len()`.
pub fn with_rotated_copy(
    pattern: &Pattern,
    angle: f64,
    tol: f64,
) -> Result<Pattern, RotatedCopyError> {
    let (mut c, mut s) = (angle.cos(), angle.sin());
    // Quarter turns (the gripper's half turn) are exact, so copies of exact coordinates are.
    let quarters = angle / std::f64::consts::FRAC_PI_2;
    if (quarters - quarters.round()).abs() < 1e-12 {
        (c, s) = (c.round(), s.round());
    }
    let n = pattern.vertices.len();
    for fr in &pattern.frames {
        if fr.coords.len() != n {
            return Err(RotatedCopyError::FrameSize {
                t: fr.t,
                expected: n,
                got: fr.coords.len(),
            });
        }
    }
    // Map each original vertex to the index of its copy.
    let mut vertices = pattern.vertices.clone();
    let mut copy_of = Vec::with_capacity(n);
    for &p in &pattern.vertices {
        let q = rot2(p, c, s);
        let hit = pattern
            .vertices
            .iter()
            .position(|o| (o[0] - q[0]).hypot(o[1] - q[1]) <= tol);
        match hit {
            Some(j) => copy_of.push(j),
            None => {
                copy_of.push(vertices.len());
                vertices.push(q);
            }
        }
    }
    let merged: Vec<(usize, usize)> = (0..n)
        .filter(|&i| copy_of[i] < n)
        .map(|i| (i, copy_of[i]))
        .collect();
    let mut frames = Vec::with_capacity(pattern.frames.len());
    for fr in &pattern.frames {
        for &(i, j) in &merged {
            let q = rot3(fr.coords[i], c, s);
            let o = fr.coords[j];
            let gap =
                ((q[0] - o[0]).powi(2) + (q[1] - o[1]).powi(2) + (q[2] - o[2]).powi(2)).sqrt();
            if gap.is_nan() || gap > tol {
                return Err(RotatedCopyError::SharedVertexMoves {
                    vertex: j,
                    t: fr.t,
                    gap,
                });
            }
        }
        let mut coords = fr.coords.clone();
        coords.extend(
            (0..n)
                .filter(|&i| copy_of[i] >= n)
                .map(|i| rot3(fr.coords[i], c, s)),
        );
        frames.push(Frame {
            t: fr.t,
            coords,
            fold_angles: Vec::new(),
        });
    }
    let mut edges = pattern.edges.clone();
    let mut copied_angle_of = Vec::new();
    let key = |v: [usize; 2]| (v[0].min(v[1]), v[0].max(v[1]));
    let mut seen: std::collections::HashSet<(usize, usize)> =
        edges.iter().map(|e| key(e.v)).collect();
    for (k, e) in pattern.edges.iter().enumerate() {
        let v = [copy_of[e.v[0]], copy_of[e.v[1]]];
        if seen.insert(key(v)) {
            edges.push(Edge { v, kind: e.kind });
            copied_angle_of.push(k);
        }
    }
    for (fr, src) in frames.iter_mut().zip(&pattern.frames) {
        // Angles only carry over when the frame has one per edge.
        if src.fold_angles.len() == pattern.edges.len() {
            let mut angles = src.fold_angles.clone();
            angles.extend(copied_angle_of.iter().map(|&k| src.fold_angles[k]));
            fr.fold_angles = angles;
        }
    }
    let mut faces = pattern.faces.clone();
    faces.extend(
        pattern
            .faces
            .iter()
            .map(|f| f.iter().map(|&v| copy_of[v]).collect::<Vec<_>>()),
    );
    Ok(Pattern {
        vertices,
        edges,
        faces,
        frames,
    })
}

/// The two-armed gripper of thesis Sec. 5.5: the arm and its copy rotated 180° about the
/// z-axis, sharing the vertices on the axis (v1 at the origin).
pub fn two_armed(arm: &Pattern) -> Result<Pattern, RotatedCopyError> {
    with_rotated_copy(arm, std::f64::consts::PI, 1e-9)
}
