//! 3D-printing files of a thick design (issue 32): one STL (`stl_io`) and one 3MF
//! (`threemf`) per panel, and assemblies of every panel at chosen states of the motion.
//! Every file is in mm.

use std::path::{Path, PathBuf};

use super::{ExportError, Result};
use crate::fabricate::{Solid, ThickDesign};
use crate::geom;
use crate::pattern::Pattern;

fn io_err(path: &Path, e: impl std::fmt::Display) -> ExportError {
    ExportError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(e.to_string()),
    }
}

/// The triangles of `solids` in mm, as `stl_io` takes them (normals from the corners'
/// order, which is outward).
fn stl_triangles(solids: &[Solid], scale: f64) -> Vec<stl_io::Triangle> {
    let mut out = Vec::new();
    for s in solids {
        for t in &s.triangles {
            let [a, b, c] = t.map(|i| geom::scale(s.vertices[i], scale));
            let n = geom::normalize(geom::cross(geom::sub(b, a), geom::sub(c, a)))
                .unwrap_or([0.0, 0.0, 1.0]);
            let v = |p: [f64; 3]| stl_io::Vertex::new([p[0] as f32, p[1] as f32, p[2] as f32]);
            out.push(stl_io::Triangle {
                normal: stl_io::Normal::new([n[0] as f32, n[1] as f32, n[2] as f32]),
                vertices: [v(a), v(b), v(c)],
            });
        }
    }
    out
}

/// Write `solids` (paper units, scaled to mm by `scale`) as one binary STL.
pub fn write_stl(path: &Path, solids: &[Solid], scale: f64) -> Result<()> {
    let tris = stl_triangles(solids, scale);
    let mut f = std::fs::File::create(path).map_err(|source| ExportError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    stl_io::write_stl(&mut f, tris.iter()).map_err(|source| ExportError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Write `solids` as one 3MF model in mm, one object per solid named `P<facet>`.
pub fn write_3mf(path: &Path, solids: &[Solid], scale: f64) -> Result<()> {
    use threemf::model::{Build, Item, Model, Object, Resources, Triangle, Triangles, Unit};
    use threemf::model::{Vertex, Vertices};
    let objects: Vec<Object> = solids
        .iter()
        .enumerate()
        .map(|(k, s)| Object {
            id: k + 1,
            partnumber: None,
            name: Some(format!("P{}", s.facet)),
            pid: None,
            pindex: None,
            mesh: Some(threemf::Mesh {
                vertices: Vertices {
                    vertex: s
                        .vertices
                        .iter()
                        .map(|p| Vertex {
                            x: p[0] * scale,
                            y: p[1] * scale,
                            z: p[2] * scale,
                        })
                        .collect(),
                },
                triangles: Triangles {
                    triangle: s
                        .triangles
                        .iter()
                        .map(|t| Triangle {
                            v1: t[0],
                            v2: t[1],
                            v3: t[2],
                        })
                        .collect(),
                },
            }),
            components: None,
        })
        .collect();
    let build = Build {
        item: (1..=objects.len())
            .map(|id| Item {
                objectid: id,
                transform: None,
                partnumber: None,
            })
            .collect(),
    };
    let model = Model {
        resources: Resources {
            object: objects,
            basematerials: None,
        },
        build,
        unit: Unit::Millimeter,
        ..Default::default()
    };
    let mut packed = std::io::Cursor::new(Vec::new());
    threemf::write(&mut packed, model).map_err(|e| io_err(path, e))?;
    let bytes = conventional_part_name(packed.into_inner()).map_err(|e| io_err(path, e))?;
    std::fs::write(path, bytes).map_err(|source| ExportError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// The part name threemf writes, and the one the 3MF core specification's examples use and
/// readers such as trimesh look for (slicers follow `_rels/.rels`, which names either).
const PART_WRITTEN: &str = "3D/model.model";
const PART_CONVENTIONAL: &str = "3D/3dmodel.model";

/// Re-pack a 3MF archive with its model part at [`PART_CONVENTIONAL`] and the relationship
/// pointing there; every other entry is copied unchanged.
fn conventional_part_name(archive: Vec<u8>) -> std::result::Result<Vec<u8>, zip::result::ZipError> {
    use std::io::{Read, Write};
    let mut input = zip::ZipArchive::new(std::io::Cursor::new(archive))?;
    let mut out = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    for k in 0..input.len() {
        let mut entry = input.by_index(k)?;
        let mut data = Vec::new();
        entry.read_to_end(&mut data)?;
        let name = entry.name()?.to_string();
        let (name, data) = match name.as_str() {
            PART_WRITTEN => (PART_CONVENTIONAL.to_string(), data),
            "_rels/.rels" => {
                let text = String::from_utf8_lossy(&data).replace(
                    &format!("/{PART_WRITTEN}"),
                    &format!("/{PART_CONVENTIONAL}"),
                );
                (name, text.into_bytes())
            }
            _ => (name, data),
        };
        out.start_file(name, options)?;
        out.write_all(&data)?;
    }
    Ok(out.finish()?.into_inner())
}

/// A state of the motion to assemble: its name and the frame (`None`: the flat layout).
pub type State<'a> = (String, Option<&'a crate::pattern::Frame>);

/// Write every panel (`panel-<facet>.stl`, `.3mf`, flat, in mm) and an assembly of all
/// panels at each state (`assembly-<name>.stl`, `.3mf`) into `dir`.
pub fn write_solids(
    dir: &Path,
    pattern: &Pattern,
    design: &ThickDesign,
    states: &[State<'_>],
) -> Result<Vec<PathBuf>> {
    let s = design.spec.scale;
    let mut files = Vec::new();
    for solid in design.flat_solids() {
        let stl = dir.join(format!("panel-{}.stl", solid.facet));
        write_stl(&stl, std::slice::from_ref(&solid), s)?;
        let tmf = dir.join(format!("panel-{}.3mf", solid.facet));
        write_3mf(&tmf, std::slice::from_ref(&solid), s)?;
        files.extend([stl, tmf]);
    }
    for (name, frame) in states {
        let solids = match frame {
            Some(f) => design.solids_at(pattern, f),
            None => design.flat_solids(),
        };
        let stl = dir.join(format!("assembly-{name}.stl"));
        write_stl(&stl, &solids, s)?;
        let tmf = dir.join(format!("assembly-{name}.3mf"));
        write_3mf(&tmf, &solids, s)?;
        files.extend([stl, tmf]);
    }
    Ok(files)
}
