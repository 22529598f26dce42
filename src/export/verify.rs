//! `foldsynth verify`: an independent check of any FOLD file.
//!
//! The key frame (frame 0) is the flat crease pattern; every later frame with coordinates
//! is a folded state of the same mesh. Checks:
//!
//! - **flat crease pattern**: frame 0 lies in z = 0;
//! - **faces counter-clockwise** in frame 0 (positive area about +z) and **planar**;
//! - **face sides are edges** of `edges_vertices`;
//! - **manifold**: a boundary edge (`B`) has one face, any other edge exactly two, one on
//!   each side (consistent orientation);
//! - **Euler**: V − E + F = 2c − b for c components and b boundary loops (1 for a disk):
//!   every component is a sheet without genus;
//! - **developability**: at every interior vertex the sector angles sum to 2π;
//! - **assignment vs. fold angle**: the sign of frame 0's `edges_foldAngle` matches
//!   `edges_assignment` (V ≥ 0, M ≤ 0, B/F/J = 0), as the spec asks;
//! - per folded frame, **isometry**: every pairwise distance within every face equals its
//!   flat value (error relative to the face's largest flat distance), and **fold angles**:
//!   where the frame states its own `edges_foldAngle`, it equals the signed dihedral
//!   angle of the geometry (see [`super::geom`] for the sign), compared modulo 360°.

use std::fmt;
use std::path::Path;

use serde::Serialize;

use super::fold::{Assignment, EdgeFaces, FoldError, FoldFile};
use crate::geom;

/// Tolerances of [`verify`].
#[derive(Clone, Copy, Debug)]
pub struct VerifyOptions {
    /// Isometry tolerance, relative to each face's size (largest flat distance in it).
    pub tol: f64,
    /// Fold-angle and sector-sum tolerance in degrees.
    pub angle_tol_deg: f64,
}

impl Default for VerifyOptions {
    fn default() -> Self {
        VerifyOptions {
            tol: 1e-9,
            angle_tol_deg: 1e-6,
        }
    }
}

/// One structural check.
#[derive(Clone, Debug, Serialize)]
pub struct Check {
    /// What is checked.
    pub name: String,
    /// Whether it passed.
    pub ok: bool,
    /// The measured figures, or the first offenders.
    pub detail: String,
}

/// The checks of one folded frame.
#[derive(Clone, Debug, Serialize)]
pub struct FrameCheck {
    /// Frame index (1 = first entry of `file_frames`).
    pub frame: usize,
    /// `foldsynth:t`, if present.
    pub t: Option<f64>,
    /// Largest relative distance error over all faces.
    pub max_isometry_error: f64,
    /// The face where it occurs.
    pub worst_face: Option<usize>,
    /// Largest fold-angle error in degrees, if the frame states its own fold angles.
    pub max_fold_angle_error_deg: Option<f64>,
    /// The edge where it occurs.
    pub worst_edge: Option<usize>,
    /// Whether the frame passed.
    pub ok: bool,
}

/// The result of [`verify`].
#[derive(Clone, Debug, Serialize)]
pub struct VerifyReport {
    /// The file checked.
    pub file: String,
    /// Whether everything passed.
    pub ok: bool,
    /// Number of vertices.
    pub vertices: usize,
    /// Number of edges.
    pub edges: usize,
    /// Number of faces.
    pub faces: usize,
    /// Whether the faces were derived from the planar graph (absent from the file).
    pub faces_derived: bool,
    /// Whether the edges were derived from the faces (absent from the file).
    pub edges_derived: bool,
    /// The isometry tolerance used.
    pub tol: f64,
    /// The angle tolerance used, in degrees.
    pub angle_tol_deg: f64,
    /// Structural checks.
    pub checks: Vec<Check>,
    /// Per folded frame.
    pub frames: Vec<FrameCheck>,
}

/// Read and verify a FOLD file.
pub fn verify_file(path: &Path, opts: &VerifyOptions) -> Result<VerifyReport, FoldError> {
    Ok(verify(&FoldFile::read(path)?, opts))
}

fn list<T: fmt::Display>(items: &[T]) -> String {
    let shown: Vec<String> = items.iter().take(5).map(|x| x.to_string()).collect();
    let more = if items.len() > 5 {
        format!(" and {} more", items.len() - 5)
    } else {
        String::new()
    };
    format!("{}{more}", shown.join(", "))
}

/// Verify a FOLD file read by [`FoldFile`]; see the module docs for the checks.
pub fn verify(f: &FoldFile, opts: &VerifyOptions) -> VerifyReport {
    let key = &f.frames[0].coords;
    let n = key.len();
    let angle_tol_rad = opts.angle_tol_deg.to_radians();
    let mut checks = Vec::new();
    let mut check = |name: &str, ok: bool, detail: String| {
        checks.push(Check {
            name: name.into(),
            ok,
            detail,
        })
    };

    // Scale of the whole sheet, for relative tolerances.
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in key {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let size = geom::dist(lo, hi).max(f64::MIN_POSITIVE);

    let max_z = key.iter().map(|p| p[2].abs()).fold(0.0, f64::max);
    let flat = max_z <= opts.tol * size;
    check(
        "flat crease pattern",
        flat,
        if flat {
            format!("frame 0 lies in z = 0 (max |z| = {max_z:.2e})")
        } else {
            format!(
                "frame 0 is not flat: max |z| = {max_z:.3e} (sheet size {size:.3}); verify needs the crease pattern as frame 0"
            )
        },
    );

    let face_pts = |coords: &[[f64; 3]], fi: usize| -> Vec<[f64; 3]> {
        f.faces[fi].iter().map(|&v| coords[v]).collect()
    };
    let normals: Vec<[f64; 3]> = (0..f.faces.len())
        .map(|fi| geom::newell_normal(&face_pts(key, fi)))
        .collect();
    let face_size: Vec<f64> = f
        .faces
        .iter()
        .map(|fc| {
            let mut s: f64 = 0.0;
            for i in 0..fc.len() {
                for j in i + 1..fc.len() {
                    s = s.max(geom::dist(key[fc[i]], key[fc[j]]));
                }
            }
            s
        })
        .collect();

    // Counter-clockwise: positive area about +z (Newell z = twice the signed xy area).
    let bad_ccw: Vec<String> = (0..f.faces.len())
        .filter(|&fi| normals[fi][2] <= 1e-12 * face_size[fi] * face_size[fi])
        .map(|fi| format!("face {fi} (area {:.3e})", 0.5 * normals[fi][2]))
        .collect();
    check(
        "faces counter-clockwise",
        bad_ccw.is_empty(),
        if bad_ccw.is_empty() {
            format!("all {} faces have positive area about +z", f.faces.len())
        } else {
            format!("clockwise or degenerate: {}", list(&bad_ccw))
        },
    );

    // Planar faces in frame 0: distance of every vertex from the face's plane.
    let mut worst_planar = (0.0f64, None);
    for fi in 0..f.faces.len() {
        let Some(nrm) = geom::normalize(normals[fi]) else {
            continue;
        };
        let pts = face_pts(key, fi);
        let c = pts.iter().fold([0.0; 3], |a, &p| geom::add(a, p));
        let c = geom::scale(c, 1.0 / pts.len() as f64);
        for p in &pts {
            let d = geom::dot(geom::sub(*p, c), nrm).abs() / face_size[fi].max(f64::MIN_POSITIVE);
            if d > worst_planar.0 {
                worst_planar = (d, Some(fi));
            }
        }
    }
    check(
        "planar faces",
        worst_planar.0 <= opts.tol,
        match worst_planar.1 {
            Some(fi) => format!(
                "max distance from the face plane {:.2e} (relative, face {fi})",
                worst_planar.0
            ),
            None => "every face is planar".into(),
        },
    );

    let adj = EdgeFaces::new(&f.edges, &f.faces);
    let missing: Vec<String> = adj
        .missing
        .iter()
        .map(|(fi, u, v)| format!("side {u}–{v} of face {fi}"))
        .collect();
    check(
        "face sides are edges",
        missing.is_empty(),
        if missing.is_empty() {
            "every side of every face is in edges_vertices".into()
        } else {
            format!("not in edges_vertices: {}", list(&missing))
        },
    );

    let mut bad_manifold = Vec::new();
    let (mut n_boundary, mut n_interior) = (0, 0);
    let mut topo_boundary = vec![false; f.edges.len()];
    for (i, e) in f.edges.iter().enumerate() {
        let (l, r) = (adj.left[i].len(), adj.right[i].len());
        let is_b = f.assignment[i] == Assignment::B;
        topo_boundary[i] = l + r == 1;
        let desc = format!("edge {i} ({}–{})", e[0], e[1]);
        if is_b {
            n_boundary += 1;
            if l + r != 1 {
                bad_manifold.push(format!(
                    "{desc}: boundary edge in {} faces (expected 1)",
                    l + r
                ));
            }
        } else {
            n_interior += 1;
            if l > 1 || r > 1 {
                bad_manifold.push(format!(
                    "{desc}: {} faces on one side (inconsistent orientation or overlap)",
                    l.max(r)
                ));
            } else if l + r != 2 {
                bad_manifold.push(format!(
                    "{desc}: {} edge in {} face(s) (expected 2, one on each side)",
                    f.assignment[i].as_str(),
                    l + r
                ));
            }
        }
    }
    check(
        "manifold",
        bad_manifold.is_empty(),
        if bad_manifold.is_empty() {
            format!(
                "{n_boundary} boundary edges in one face each, {n_interior} creases in two faces each"
            )
        } else {
            list(&bad_manifold)
        },
    );

    // Euler characteristic against the topology of a planar sheet.
    let mut used = vec![false; n];
    for e in &f.edges {
        used[e[0]] = true;
        used[e[1]] = true;
    }
    for fc in &f.faces {
        for &v in fc {
            used[v] = true;
        }
    }
    let nv = used.iter().filter(|&&u| u).count();
    let components = |edges: &mut dyn Iterator<Item = [usize; 2]>, verts: &[bool]| -> usize {
        let mut parent: Vec<usize> = (0..n).collect();
        fn find(p: &mut [usize], mut x: usize) -> usize {
            while p[x] != x {
                p[x] = p[p[x]];
                x = p[x];
            }
            x
        }
        for [a, b] in edges {
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            parent[ra] = rb;
        }
        (0..n)
            .filter(|&v| verts[v] && find(&mut parent, v) == v)
            .count()
    };
    let mut all_edges = f.edges.iter().copied();
    let c = components(&mut all_edges, &used);
    let mut bverts = vec![false; n];
    let bedges: Vec<[usize; 2]> = f
        .edges
        .iter()
        .zip(&topo_boundary)
        .filter(|(_, b)| **b)
        .map(|(e, _)| *e)
        .collect();
    for e in &bedges {
        bverts[e[0]] = true;
        bverts[e[1]] = true;
    }
    let nbv = bverts.iter().filter(|&&b| b).count();
    let mut bit = bedges.iter().copied();
    let bc = components(&mut bit, &bverts);
    // Cycle rank of the boundary graph = number of boundary loops.
    let loops = bedges.len() as i64 - nbv as i64 + bc as i64;
    let chi = nv as i64 - f.edges.len() as i64 + f.faces.len() as i64;
    let expected = 2 * c as i64 - loops;
    check(
        "Euler characteristic",
        chi == expected,
        format!(
            "V − E + F = {nv} − {} + {} = {chi}; 2·{c} component(s) − {loops} boundary loop(s) = {expected}{}",
            f.edges.len(),
            f.faces.len(),
            if c == 1 && loops == 1 && chi == 1 {
                ": a disk"
            } else {
                ""
            }
        ),
    );

    // Developability at interior vertices (on no boundary edge).
    let mut sums = vec![0.0f64; n];
    let mut has_face = vec![false; n];
    for (fi, fc) in f.faces.iter().enumerate() {
        let m = fc.len();
        for k in 0..m {
            let v = fc[k];
            has_face[v] = true;
            sums[v] += geom::corner_angle(
                key[fc[(k + m - 1) % m]],
                key[v],
                key[fc[(k + 1) % m]],
                normals[fi],
            );
        }
    }
    let interior: Vec<usize> = (0..n).filter(|&v| has_face[v] && !bverts[v]).collect();
    let mut worst_dev = (0.0f64, None);
    for &v in &interior {
        let err = (sums[v] - std::f64::consts::TAU).abs();
        if err > worst_dev.0 || worst_dev.1.is_none() {
            worst_dev = (err, Some(v));
        }
    }
    check(
        "developability",
        worst_dev.0 <= angle_tol_rad,
        match worst_dev.1 {
            Some(v) => format!(
                "{} interior vertex(es); max |Σ sectors − 2π| = {:.2e} rad (vertex {v})",
                interior.len(),
                worst_dev.0
            ),
            None => "no interior vertices".into(),
        },
    );

    // The sign of frame 0's fold angles against the assignment.
    if let Some(angles) = &f.frames[0].fold_angles {
        let mut bad = Vec::new();
        for (i, a) in angles.iter().enumerate() {
            let Some(a) = *a else { continue };
            let ok = match f.assignment[i] {
                Assignment::V => a >= -opts.angle_tol_deg,
                Assignment::M => a <= opts.angle_tol_deg,
                Assignment::B | Assignment::F | Assignment::J => a.abs() <= opts.angle_tol_deg,
                Assignment::U => true,
            };
            if !ok {
                bad.push(format!("edge {i}: {} with {a}°", f.assignment[i].as_str()));
            }
        }
        check(
            "assignment vs fold angle",
            bad.is_empty(),
            if bad.is_empty() {
                "signs of frame 0's edges_foldAngle match edges_assignment".into()
            } else {
                list(&bad)
            },
        );
    }

    // Folded frames.
    let mut frames = Vec::new();
    for (k, fr) in f.frames.iter().enumerate().skip(1) {
        let mut worst_iso = (0.0f64, None);
        for (fi, fc) in f.faces.iter().enumerate() {
            let s = face_size[fi];
            for i in 0..fc.len() {
                for j in i + 1..fc.len() {
                    let d0 = geom::dist(key[fc[i]], key[fc[j]]);
                    let d1 = geom::dist(fr.coords[fc[i]], fr.coords[fc[j]]);
                    let err = if s > 0.0 {
                        (d1 - d0).abs() / s
                    } else {
                        f64::INFINITY
                    };
                    if err > worst_iso.0 || worst_iso.1.is_none() {
                        worst_iso = (err, Some(fi));
                    }
                }
            }
        }
        let mut worst_angle = None;
        if let (Some(given), true) = (&fr.fold_angles, fr.fold_angles_own) {
            let geo = adj.fold_angles(&f.faces, &fr.coords);
            let mut w = (0.0f64, None);
            for i in 0..f.edges.len() {
                let (Some(g), Some(r)) = (given[i], geo[i]) else {
                    continue;
                };
                let diff = super::fold::wrap((g - r.to_degrees()).to_radians())
                    .to_degrees()
                    .abs();
                if diff > w.0 || w.1.is_none() {
                    w = (diff, Some(i));
                }
            }
            worst_angle = Some(w);
        }
        let ok = worst_iso.0 <= opts.tol && worst_angle.is_none_or(|w| w.0 <= opts.angle_tol_deg);
        frames.push(FrameCheck {
            frame: k,
            t: fr.t,
            max_isometry_error: worst_iso.0,
            worst_face: worst_iso.1,
            max_fold_angle_error_deg: worst_angle.map(|w| w.0),
            worst_edge: worst_angle.and_then(|w| w.1),
            ok,
        });
    }

    let ok = checks.iter().all(|c| c.ok) && frames.iter().all(|fr| fr.ok);
    VerifyReport {
        file: f.source.clone(),
        ok,
        vertices: n,
        edges: f.edges.len(),
        faces: f.faces.len(),
        faces_derived: f.faces_derived,
        edges_derived: f.edges_derived,
        tol: opts.tol,
        angle_tol_deg: opts.angle_tol_deg,
        checks,
        frames,
    }
}

impl fmt::Display for VerifyReport {
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(out, "verify {}", self.file)?;
        writeln!(
            out,
            "  mesh: {} vertices, {} edges{}, {} faces{}",
            self.vertices,
            self.edges,
            if self.edges_derived {
                " (derived from the faces)"
            } else {
                ""
            },
            self.faces,
            if self.faces_derived {
                " (derived from the planar graph)"
            } else {
                ""
            },
        )?;
        writeln!(
            out,
            "  tolerances: isometry {:e} (relative to face size), angles {:e}°",
            self.tol, self.angle_tol_deg
        )?;
        for c in &self.checks {
            writeln!(
                out,
                "  [{}] {:<26} {}",
                if c.ok { " ok " } else { "FAIL" },
                c.name,
                c.detail
            )?;
        }
        if self.frames.is_empty() {
            writeln!(
                out,
                "  no folded frames: only the crease pattern was checked"
            )?;
        } else {
            writeln!(
                out,
                "  {:>5} {:>10} {:>14} {:>6} {:>16} {:>6}",
                "frame", "t", "isometry err", "face", "fold-angle err°", "edge"
            )?;
            for fr in &self.frames {
                let t = fr.t.map_or("-".into(), |t| format!("{t:.6}"));
                let face = fr.worst_face.map_or("-".into(), |x| x.to_string());
                let (ang, edge) = match fr.max_fold_angle_error_deg {
                    Some(a) => (
                        format!("{a:.2e}"),
                        fr.worst_edge.map_or("-".into(), |x| x.to_string()),
                    ),
                    None => ("not given".into(), "-".into()),
                };
                writeln!(
                    out,
                    "  {:>5} {:>10} {:>14.2e} {:>6} {:>16} {:>6}  {}",
                    fr.frame,
                    t,
                    fr.max_isometry_error,
                    face,
                    ang,
                    edge,
                    if fr.ok { "ok" } else { "FAIL" }
                )?;
            }
        }
        let failed_checks = self.checks.iter().filter(|c| !c.ok).count();
        let failed_frames = self.frames.iter().filter(|f| !f.ok).count();
        if self.ok {
            writeln!(
                out,
                "result: OK ({} checks, {} folded frames)",
                self.checks.len(),
                self.frames.len()
            )
        } else {
            writeln!(
                out,
                "result: FAILED ({failed_checks} of {} checks, {failed_frames} of {} folded frames)",
                self.checks.len(),
                self.frames.len()
            )
        }
    }
}
