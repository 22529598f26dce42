//! Triangle meshes read from STL (ASCII or binary, `stl_io`) and OBJ (`tobj`) files: parts
//! from CAD as obstacles, and surfaces a vertex must lie on.
//!
//! A mesh is *closed* when every edge is shared by exactly two triangles that traverse it in
//! opposite directions (a consistently oriented 2-manifold without boundary): it bounds a
//! solid, and the judges also refuse a facet inside it. An open mesh (a teapot without its
//! lid seam, a single sheet) is a surface only: no facet may come within the clearance of
//! any of its triangles, and nothing is said about sides.

use std::collections::HashMap;
use std::io::Cursor;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::geom::{V3, add, norm, scale, sub};

/// Most triangles a mesh file may hold: every facet is kept clear of every triangle near
/// it, so the cost of a state grows with the triangles within reach (decimate a CAD part
/// to a few thousand triangles first).
pub const MESH_TRIANGLES_MAX: usize = 20_000;

/// Largest mesh file read, in bytes (a binary STL of the limit is about 1 MB; an ASCII one
/// about 5 MB).
pub const MESH_BYTES_MAX: u64 = 32 << 20;

/// A triangle mesh in paper units.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TriangleMesh {
    /// Vertex positions (identical positions merged).
    pub vertices: Vec<V3>,
    /// Triangles as vertex indices, in the file's orientation.
    pub triangles: Vec<[u32; 3]>,
    /// Whether the mesh is closed and consistently oriented (see the module docs).
    pub closed: bool,
}

/// A mesh file that cannot be used.
#[derive(Debug, thiserror::Error)]
#[error("{file}: {message}")]
pub struct MeshError {
    /// The file.
    pub file: String,
    /// What is wrong and what is allowed.
    pub message: String,
}

impl TriangleMesh {
    /// Read an STL (`.stl`, ASCII or binary) or OBJ (`.obj`) file, chosen by extension.
    pub fn read(path: &Path) -> Result<TriangleMesh, MeshError> {
        TriangleMesh::parse(path, &read_bytes(path)?)
    }

    /// Parse the bytes of the file `path` (STL or OBJ by its extension; the path labels
    /// the messages).
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<TriangleMesh, MeshError> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match ext.as_str() {
            "stl" => TriangleMesh::from_stl(bytes),
            "obj" => TriangleMesh::from_obj(bytes),
            _ => Err(format!(
                "unknown mesh format {:?}: use an STL (.stl, ASCII or binary) or OBJ (.obj) file",
                crate::text::excerpt(&ext, 20)
            )),
        }
        .map_err(|message| MeshError {
            file: path.display().to_string(),
            message,
        })
    }

    /// Parse STL bytes (ASCII or binary).
    pub fn from_stl(bytes: &[u8]) -> Result<TriangleMesh, String> {
        // A binary STL announces its triangle count in bytes 80..84: refuse a huge count
        // before anything is allocated for it.
        if bytes.len() >= 84 {
            let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
            let binary = bytes.len() as u64 == 84 + 50 * n as u64;
            if binary || !bytes.starts_with(b"solid") {
                check_count(n)?;
            }
        }
        let mut cursor = Cursor::new(bytes);
        let mesh =
            stl_io::read_stl(&mut cursor).map_err(|e| format!("not a readable STL file: {e}"))?;
        check_count(mesh.faces.len())?;
        let vertices: Vec<V3> = mesh
            .vertices
            .iter()
            .map(|v| [f64::from(v[0]), f64::from(v[1]), f64::from(v[2])])
            .collect();
        let triangles: Result<Vec<[u32; 3]>, String> = mesh
            .faces
            .iter()
            .map(|f| {
                let idx = |i: usize| {
                    u32::try_from(f.vertices[i])
                        .ok()
                        .filter(|&k| (k as usize) < vertices.len())
                        .ok_or_else(|| {
                            "a triangle names a vertex the file does not have".to_string()
                        })
                };
                Ok([idx(0)?, idx(1)?, idx(2)?])
            })
            .collect();
        TriangleMesh::build(vertices, triangles?)
    }

    /// Parse OBJ bytes (polygons are triangulated as fans; materials are ignored).
    pub fn from_obj(bytes: &[u8]) -> Result<TriangleMesh, String> {
        let opts = tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ..Default::default()
        };
        let mut reader = std::io::BufReader::new(Cursor::new(bytes));
        let (models, _) = tobj::load_obj_buf(&mut reader, &opts, |_| {
            Err(tobj::LoadError::MaterialParseError)
        })
        .map_err(|e| format!("not a readable OBJ file: {e}"))?;
        let mut vertices: Vec<V3> = Vec::new();
        let mut triangles: Vec<[u32; 3]> = Vec::new();
        for m in &models {
            let mesh = &m.mesh;
            let base = vertices.len();
            for p in mesh.positions.chunks_exact(3) {
                vertices.push([p[0], p[1], p[2]]);
            }
            check_count(triangles.len() + mesh.indices.len() / 3)?;
            for t in mesh.indices.chunks_exact(3) {
                let idx = |k: u32| {
                    let i = base + k as usize;
                    (i < vertices.len())
                        .then_some(i as u32)
                        .ok_or_else(|| "a face names a vertex the file does not have".to_string())
                };
                triangles.push([idx(t[0])?, idx(t[1])?, idx(t[2])?]);
            }
        }
        TriangleMesh::build(vertices, triangles)
    }

    /// Merge identical positions, check the numbers and find whether the mesh is closed.
    fn build(vertices: Vec<V3>, triangles: Vec<[u32; 3]>) -> Result<TriangleMesh, String> {
        if triangles.is_empty() {
            return Err("the file holds no triangles".into());
        }
        if let Some(p) = vertices.iter().find(|p| p.iter().any(|x| !x.is_finite())) {
            return Err(format!("a vertex is not finite: {p:?}"));
        }
        if let Some(p) = vertices
            .iter()
            .find(|p| p.iter().any(|x| x.abs() > crate::limits::COORD_MAX))
        {
            return Err(format!(
                "a vertex lies beyond ±{}: {p:?}",
                crate::limits::COORD_MAX
            ));
        }
        // Merge positions that are bit-identical (STL repeats every vertex per triangle).
        let mut index: HashMap<[u64; 3], u32> = HashMap::new();
        let mut merged: Vec<V3> = Vec::new();
        let remap: Vec<u32> = vertices
            .iter()
            .map(|p| {
                let key = [p[0].to_bits(), p[1].to_bits(), p[2].to_bits()];
                *index.entry(key).or_insert_with(|| {
                    merged.push(*p);
                    (merged.len() - 1) as u32
                })
            })
            .collect();
        let triangles: Vec<[u32; 3]> = triangles
            .iter()
            .map(|t| {
                [
                    remap[t[0] as usize],
                    remap[t[1] as usize],
                    remap[t[2] as usize],
                ]
            })
            // Triangles with a repeated vertex have no area and no sides.
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .collect();
        if triangles.is_empty() {
            return Err("every triangle in the file is degenerate (a repeated vertex)".into());
        }
        let closed = is_closed(&triangles);
        Ok(TriangleMesh {
            vertices: merged,
            triangles,
            closed,
        })
    }

    /// Scale every coordinate, then translate.
    pub fn transform(&mut self, s: f64, t: V3) {
        for p in &mut self.vertices {
            *p = add(scale(*p, s), t);
        }
    }

    /// The corners of triangle `i`.
    pub fn triangle(&self, i: usize) -> [V3; 3] {
        let t = self.triangles[i];
        [
            self.vertices[t[0] as usize],
            self.vertices[t[1] as usize],
            self.vertices[t[2] as usize],
        ]
    }

    /// A ball containing every vertex: the centre of the bounding box and the farthest
    /// vertex from it.
    pub fn bounding_ball(&self) -> (V3, f64) {
        let (lo, hi) = self.bounds();
        let c = scale(add(lo, hi), 0.5);
        let r = self
            .vertices
            .iter()
            .map(|p| norm(sub(*p, c)))
            .fold(0.0, f64::max);
        (c, r)
    }

    /// The axis-aligned bounding box `(min, max)`.
    pub fn bounds(&self) -> (V3, V3) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.vertices {
            for i in 0..3 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
        (lo, hi)
    }
}

/// The bytes of the mesh file `path`: a regular file (not a directory, a device or a
/// pipe, which could block or never end) of at most [`MESH_BYTES_MAX`] bytes, read no
/// further than that limit even if it grows meanwhile.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>, MeshError> {
    use std::io::Read;
    let err = |message: String| MeshError {
        file: path.display().to_string(),
        message,
    };
    let cannot = |e: std::io::Error| err(format!("cannot read the mesh file: {e}"));
    let meta = std::fs::metadata(path).map_err(cannot)?;
    if !meta.is_file() {
        return Err(err(
            "is not a regular file: a mesh is an STL or OBJ file".into()
        ));
    }
    let too_big = |size: u64| {
        err(format!(
            "{size} bytes: mesh files are limited to {MESH_BYTES_MAX} bytes (decimate the part first)"
        ))
    };
    if meta.len() > MESH_BYTES_MAX {
        return Err(too_big(meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    std::fs::File::open(path)
        .map_err(cannot)?
        .take(MESH_BYTES_MAX + 1)
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    if bytes.len() as u64 > MESH_BYTES_MAX {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
}

fn check_count(n: usize) -> Result<(), String> {
    if n > MESH_TRIANGLES_MAX {
        return Err(format!(
            "{n} triangles: meshes are limited to {MESH_TRIANGLES_MAX} (decimate the part first)"
        ));
    }
    Ok(())
}

/// Every directed edge appears once and its reverse once.
fn is_closed(triangles: &[[u32; 3]]) -> bool {
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            *edges.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    edges
        .iter()
        .all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra_obj(flip_one: bool) -> String {
        let f = if flip_one { "f 1 2 3" } else { "f 1 3 2" };
        format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n{f}\nf 1 2 4\nf 2 3 4\nf 1 4 3\n")
    }

    #[test]
    fn a_tetrahedron_is_closed_and_an_open_or_flipped_one_is_not() {
        let m = TriangleMesh::from_obj(tetra_obj(false).as_bytes()).unwrap();
        assert_eq!((m.vertices.len(), m.triangles.len()), (4, 4));
        assert!(m.closed);
        let flipped = TriangleMesh::from_obj(tetra_obj(true).as_bytes()).unwrap();
        assert!(!flipped.closed);
        let open = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
        assert!(!TriangleMesh::from_obj(open.as_bytes()).unwrap().closed);
    }

    #[test]
    fn ascii_and_binary_stl_give_the_same_mesh() {
        let tris = [
            [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            [[1.0f32, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        ];
        let mut ascii = String::from("solid t\n");
        for t in &tris {
            ascii += "facet normal 0 0 1\nouter loop\n";
            for v in t {
                ascii += &format!("vertex {} {} {}\n", v[0], v[1], v[2]);
            }
            ascii += "endloop\nendfacet\n";
        }
        ascii += "endsolid t\n";
        let mut bin = vec![0u8; 80];
        bin.extend_from_slice(&(tris.len() as u32).to_le_bytes());
        for t in &tris {
            for x in [0.0f32, 0.0, 1.0] {
                bin.extend_from_slice(&x.to_le_bytes());
            }
            for v in t {
                for x in v {
                    bin.extend_from_slice(&x.to_le_bytes());
                }
            }
            bin.extend_from_slice(&[0, 0]);
        }
        let a = TriangleMesh::from_stl(ascii.as_bytes()).unwrap();
        let b = TriangleMesh::from_stl(&bin).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.vertices.len(), 4);
        assert!(!a.closed);
    }

    #[test]
    fn garbage_and_huge_counts_are_refused() {
        assert!(TriangleMesh::from_stl(b"hello").is_err());
        let mut bin = vec![0u8; 80];
        bin.extend_from_slice(&u32::MAX.to_le_bytes());
        let e = TriangleMesh::from_stl(&bin).unwrap_err();
        assert!(e.contains("limited"), "{e}");
        assert!(TriangleMesh::from_obj(b"v 0 0 0\nf 1 1 1\n").is_err());
        assert!(TriangleMesh::from_obj(b"v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").is_err());
    }
}
