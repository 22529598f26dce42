//! Triangle meshes of a folded state: OBJ and STL (ASCII or binary).
//!
//! Faces are triangulated by ear clipping in the flat layout (exact and planar, and the
//! same triangles stay valid in every folded state because facets are rigid), so
//! non-convex facets come out right. Triangles keep the facets' counter-clockwise order,
//! so normals point to the front side (+z in the flat state).

use std::fmt::Write as _;

use super::{ExportError, Result, validate_pattern};
use crate::geom::{self, V3};
use crate::pattern::Pattern;
use crate::scene::Copies;

/// A triangle mesh of one state; `arm` tells which copy each triangle belongs to.
#[derive(Clone, Debug, PartialEq)]
pub struct StateMesh {
    /// Vertex positions (the second arm's copies follow the first arm's).
    pub positions: Vec<V3>,
    /// Triangles as indices into `positions`, counter-clockwise seen from the front.
    pub triangles: Vec<[usize; 3]>,
    /// Number of arms (1, or the scene's copies: 2 with the copy rotated 180° about z).
    pub arms: usize,
    /// Triangles per arm (the first `per_arm` belong to arm 1, and so on).
    pub per_arm: usize,
}

/// Triangulate every face of the flat pattern (indices into the pattern's vertices).
pub fn triangulate_faces(p: &Pattern) -> Result<Vec<[usize; 3]>> {
    let mut out = Vec::new();
    for (fi, f) in p.faces.iter().enumerate() {
        let tris = crate::check::triangulate_polygon(&p.vertices, f, fi)
            .map_err(|e| ExportError::invalid(format!("pattern.faces[{fi}]"), e.to_string()))?;
        out.extend(tris);
    }
    Ok(out)
}

/// The mesh of frame `frame` (`None` = the flat state); with `both_arms`, a second copy
/// rotated 180° about z is appended (the two-armed gripper).
pub fn state_mesh(p: &Pattern, frame: Option<usize>, both_arms: bool) -> Result<StateMesh> {
    validate_pattern(p)?;
    let coords = match frame {
        None => p.flat_coords(),
        Some(k) => p
            .frames
            .get(k)
            .ok_or_else(|| {
                ExportError::invalid(
                    "frame",
                    format!(
                        "{k} out of range (the pattern has {} frames)",
                        p.frames.len()
                    ),
                )
            })?
            .coords
            .clone(),
    };
    let tris = triangulate_faces(p)?;
    let n = coords.len();
    let mut positions = coords.clone();
    let mut triangles = tris.clone();
    let arms = if both_arms { 2 } else { 1 };
    if both_arms {
        positions.extend(coords.iter().map(|c| [-c[0], -c[1], c[2]]));
        triangles.extend(tris.iter().map(|t| [t[0] + n, t[1] + n, t[2] + n]));
    }
    Ok(StateMesh {
        positions,
        triangles,
        arms,
        per_arm: tris.len(),
    })
}

/// The mesh of frame `frame` with every rotational copy of `copies` appended (arm k + 1 is
/// copy k). The thesis's half turn about z is [`state_mesh`] with both arms, bit for bit.
pub fn state_mesh_copies(p: &Pattern, frame: Option<usize>, copies: &Copies) -> Result<StateMesh> {
    if *copies == Copies::about_z(2) {
        return state_mesh(p, frame, true);
    }
    let mut m = state_mesh(p, frame, false)?;
    let arm = m.positions.clone();
    let tris = m.triangles.clone();
    for k in 1..copies.n.max(1) {
        let base = m.positions.len();
        m.positions.extend(arm.iter().map(|&p| copies.apply(k, p)));
        m.triangles
            .extend(tris.iter().map(|t| [t[0] + base, t[1] + base, t[2] + base]));
    }
    m.arms = copies.n.max(1);
    Ok(m)
}

fn tri_normal(m: &StateMesh, t: &[usize; 3]) -> V3 {
    let [a, b, c] = t.map(|i| m.positions[i]);
    geom::normalize(geom::cross(geom::sub(b, a), geom::sub(c, a))).unwrap_or([0.0, 0.0, 0.0])
}

/// Wavefront OBJ text: `v` lines, then one object per arm with triangular `f` lines.
pub fn to_obj(m: &StateMesh, name: &str) -> String {
    let mut s = format!(
        "# foldsynth: {name}\n# {} vertices, {} triangles\n",
        m.positions.len(),
        m.triangles.len()
    );
    for p in &m.positions {
        let _ = writeln!(s, "v {} {} {}", p[0], p[1], p[2]);
    }
    for arm in 0..m.arms {
        let _ = writeln!(s, "o arm{}", arm + 1);
        for t in &m.triangles[arm * m.per_arm..(arm + 1) * m.per_arm] {
            let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
        }
    }
    s
}

/// ASCII STL text.
pub fn to_stl_ascii(m: &StateMesh, name: &str) -> String {
    let name: String = name.chars().filter(|c| !c.is_whitespace()).collect();
    let mut s = format!("solid {name}\n");
    for t in &m.triangles {
        let n = tri_normal(m, t);
        let _ = writeln!(
            s,
            "  facet normal {:e} {:e} {:e}\n    outer loop",
            n[0], n[1], n[2]
        );
        for &i in t {
            let p = m.positions[i];
            let _ = writeln!(s, "      vertex {:e} {:e} {:e}", p[0], p[1], p[2]);
        }
        s += "    endloop\n  endfacet\n";
    }
    let _ = writeln!(s, "endsolid {name}");
    s
}

/// Binary STL: 80-byte header, triangle count, then per triangle the normal, three
/// vertices (little-endian f32) and a zero attribute word.
pub fn to_stl_binary(m: &StateMesh) -> Vec<u8> {
    let mut out = Vec::with_capacity(84 + 50 * m.triangles.len());
    let mut header = [b' '; 80];
    let text = b"foldsynth binary STL";
    header[..text.len()].copy_from_slice(text);
    out.extend_from_slice(&header);
    out.extend_from_slice(&(m.triangles.len() as u32).to_le_bytes());
    for t in &m.triangles {
        let n = tri_normal(m, t);
        for x in n {
            out.extend_from_slice(&(x as f32).to_le_bytes());
        }
        for &i in t {
            for x in m.positions[i] {
                out.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        out.extend_from_slice(&0u16.to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::samples;

    fn area(m: &StateMesh) -> f64 {
        m.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i]);
                0.5 * geom::norm(geom::cross(geom::sub(b, a), geom::sub(c, a)))
            })
            .sum()
    }

    #[test]
    fn folded_mesh_keeps_the_paper_area() {
        // single_crease: L-shaped hexagon (0.45) plus rectangle (0.6).
        let p = samples::single_crease(1.2, 4);
        for k in [None, Some(0), Some(3)] {
            let m = state_mesh(&p, k, false).unwrap();
            assert!((area(&m) - 1.05).abs() < 1e-12);
            let m2 = state_mesh(&p, k, true).unwrap();
            assert!((area(&m2) - 2.1).abs() < 1e-12);
        }
    }

    #[test]
    fn stl_binary_layout() {
        let p = samples::degree4(1.2, 1.0, 2);
        let m = state_mesh(&p, Some(1), false).unwrap();
        let b = to_stl_binary(&m);
        assert_eq!(b.len(), 84 + 50 * m.triangles.len());
        let count = u32::from_le_bytes([b[80], b[81], b[82], b[83]]) as usize;
        assert_eq!(count, m.triangles.len());
        // The first vertex of the first triangle, read back.
        let x = f32::from_le_bytes([b[96], b[97], b[98], b[99]]);
        assert_eq!(x, m.positions[m.triangles[0][0]][0] as f32);
    }

    #[test]
    fn obj_faces_reference_existing_vertices() {
        let p = samples::degree4(1.2, 1.0, 2);
        let m = state_mesh(&p, Some(1), true).unwrap();
        let obj = to_obj(&m, "x");
        let nv = obj.lines().filter(|l| l.starts_with("v ")).count();
        assert_eq!(nv, 18);
        for l in obj.lines().filter(|l| l.starts_with("f ")) {
            for i in l[2..].split_whitespace() {
                let i: usize = i.parse().unwrap();
                assert!((1..=nv).contains(&i));
            }
        }
        assert_eq!(obj.lines().filter(|l| l.starts_with("o ")).count(), 2);
    }
}
