//! Mesh files a task names (`[[obstacles]] shape = "mesh"`, a target's `surface`): paths
//! relative to the task file's folder, read once, scaled and moved, their bytes digested so
//! that a search resumes only with the same meshes.

use std::path::Path;

use serde::Deserialize;

use super::{Ctx, Number, TaskError};
use crate::scene::mesh::{MESH_TRIANGLES_MAX, read_bytes};
use crate::scene::shapes::MeshObstacle;

/// A target's `surface = { file, scale, translate }`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawSurface {
    pub(crate) file: String,
    pub(crate) scale: Option<Number>,
    pub(crate) translate: Option<Vec<Number>>,
}

/// The meshes of one task as they are loaded: the folder relative paths start from, the
/// digest of every file's bytes (in the order loaded) and the triangles so far.
pub(crate) struct Meshes<'p> {
    dir: &'p Path,
    /// FNV-1a of each file's bytes.
    pub(crate) digests: Vec<u64>,
    triangles: usize,
}

impl<'p> Meshes<'p> {
    /// No mesh loaded yet; relative paths start from `dir`.
    pub(crate) fn new(dir: &'p Path) -> Meshes<'p> {
        Meshes {
            dir,
            digests: Vec::new(),
            triangles: 0,
        }
    }

    /// The mesh of the entry `entry` (a TOML path; its fields are `file`, `scale`,
    /// `translate`), loaded, scaled (default 1) and moved (default 0).
    pub(crate) fn load(
        &mut self,
        cx: &Ctx<'_>,
        entry: &str,
        file: &str,
        scale: Option<&Number>,
        translate: Option<&[Number]>,
    ) -> Result<MeshObstacle, TaskError> {
        let field = format!("{entry}.file");
        if file.trim().is_empty() {
            return Err(cx.err(
                field,
                "empty: name an STL (.stl) or OBJ (.obj) file, relative to the task file's folder or absolute",
            ));
        }
        let scale = match scale {
            None => 1.0,
            Some(s) => cx.positive(&format!("{entry}.scale"), s)?,
        };
        let translate = match translate {
            None => [0.0; 3],
            Some(p) => cx.point::<3>(&format!("{entry}.translate"), p)?,
        };
        let path = self.dir.join(file);
        let mut mesh = MeshObstacle {
            file: std::path::absolute(&path).unwrap_or(path),
            scale,
            translate,
            mesh: None,
        };
        let bytes = read_bytes(&mesh.file).map_err(|e| cx.err(&field, e.to_string()))?;
        let loaded = mesh
            .load_bytes(&bytes)
            .map_err(|e| cx.err(&field, e.to_string()))?;
        self.triangles += loaded.triangles.len();
        let total = crate::limits::MESH_TRIANGLES_TOTAL_MAX;
        if self.triangles > total {
            return Err(cx.err(
                field,
                format!(
                    "{}: the task's meshes hold {} triangles together, more than the limit of {total} (each mesh at most {MESH_TRIANGLES_MAX}; decimate the parts first)",
                    shown(&mesh.file),
                    self.triangles
                ),
            ));
        }
        let (lo, hi) = loaded.bounds();
        let max = crate::limits::COORD_MAX;
        if lo
            .iter()
            .chain(&hi)
            .any(|x| !x.is_finite() || x.abs() > max)
        {
            return Err(cx.err(
                format!("{entry}.scale"),
                format!(
                    "{}: scaled by {} and moved, the mesh reaches beyond ±{} (numbers of a task lie within it)",
                    shown(&mesh.file),
                    crate::text::num(scale),
                    crate::text::num(max)
                ),
            ));
        }
        self.digests.push(super::fnv(super::FNV_START, &bytes));
        Ok(mesh)
    }
}

/// A path for a message.
fn shown(p: &Path) -> String {
    crate::text::excerpt(&p.display().to_string(), 200)
}
