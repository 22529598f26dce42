//! `foldsynth verify`: an independent check of any FOLD file.
//!
//! A FOLD file from another tool may hold a crease pattern in any plane, only a folded
//! form, a flat-folded state, no `edges_assignment`, coordinates rounded to a few digits.
//! `verify` checks what the file allows, says plainly what it cannot check and why, and
//! fails only on a real violation.
//!
//! **Frame 0** (the key frame) is classified by its geometry and `frame_classes`:
//!
//! - a **crease pattern**: its vertices lie in one plane (fitted by least squares; not
//!   necessarily z = 0) and every face turns the same way about that plane's normal. For a
//!   pattern in a plane z = const the normal is +z and faces must be counter-clockwise,
//!   as the spec asks; in any other plane the normal is oriented by the faces themselves;
//! - a **flat-folded state**: planar, but faces turned both ways (paper folded flat), and
//!   not declared `creasePattern`;
//! - a **folded form**: not planar and not declared `creasePattern`. A frame declared
//!   `creasePattern` that is not flat, or whose faces turn both ways, fails.
//!
//! **Checks**, each reported as ok, failed, or not checkable (with the reason):
//!
//! - **flat crease pattern** and **faces oriented** (crease patterns only);
//! - **planar faces** in frame 0;
//! - **face sides are edges** of `edges_vertices`;
//! - **manifold**: a boundary edge (`B`) has one face, any other edge exactly two, one on
//!   each side (consistent orientation). Without `edges_assignment` the boundary is
//!   taken from the faces (edges of one face);
//! - **Euler**: V − E + F = 2c − b for c components and b boundary loops;
//! - **developability**: at every interior vertex the face corner angles sum to 2π (also
//!   in a folded form: folding keeps every face's angles);
//! - **assignment vs fold angle** (crease pattern): the sign of frame 0's
//!   `edges_foldAngle` matches `edges_assignment` (V ≥ 0, M ≤ 0, B/F/J = 0);
//! - **fold angles vs geometry** (folded frame 0) and per later frame **isometry** (every
//!   pairwise distance within every face equals frame 0's, relative to the face's size)
//!   and **fold angles** (where the frame states its own `edges_foldAngle`, it equals the
//!   signed dihedral angle of the geometry, see [`crate::geom`], modulo 360°).
//!
//! **Tolerances** are the user's (`tol`, `angle_tol_deg`) plus what the file's own
//! precision allows: coordinates with 6 to 15 significant digits are taken as rounded to
//! that many digits, coordinates that are all exact float32 values (as WebGL tools such as
//! Origami Simulator write them) as rounded to float32, shorter numbers as exact;
//! [`VerifyOptions::digits`] overrides the detection. Each check adds the error that
//! rounding of that size can cause in what it measures.

use std::fmt;
use std::path::Path;

use serde::Serialize;

use super::fold::{Assignment, EdgeFaces, FoldError, FoldFile};
use crate::geom;

/// Tolerances of [`verify`].
#[derive(Clone, Copy, Debug)]
pub struct VerifyOptions {
    /// Isometry and flatness tolerance, relative to each face's (or the sheet's) size.
    pub tol: f64,
    /// Fold-angle and sector-sum tolerance in degrees.
    pub angle_tol_deg: f64,
    /// Significant digits of the file's coordinates: `None` detects them (see the module
    /// docs); `Some(17)` takes the numbers as exact.
    pub digits: Option<u32>,
}

impl Default for VerifyOptions {
    fn default() -> Self {
        VerifyOptions {
            tol: 1e-9,
            angle_tol_deg: 1e-6,
            digits: None,
        }
    }
}

/// One structural check.
#[derive(Clone, Debug, Serialize)]
pub struct Check {
    /// What is checked.
    pub name: String,
    /// Whether it passed (true when it could not be checked).
    pub ok: bool,
    /// Whether the file allowed the check at all.
    pub checked: bool,
    /// The measured figures, the first offenders, or why it cannot be checked.
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

/// What frame 0 is (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum KeyFrame {
    /// A flat crease pattern (in some plane).
    CreasePattern,
    /// A state folded flat: planar, faces turned both ways.
    FlatFolded,
    /// A folded form, not planar.
    FoldedForm,
}

impl KeyFrame {
    fn as_str(self) -> &'static str {
        match self {
            KeyFrame::CreasePattern => "a crease pattern",
            KeyFrame::FlatFolded => "a flat-folded state",
            KeyFrame::FoldedForm => "a folded form",
        }
    }
}

/// The precision of the file's coordinates and the error it allows.
#[derive(Clone, Debug, Serialize)]
pub struct Precision {
    /// Most significant digits of any coordinate (17: full double precision).
    pub digits: u32,
    /// Whether every coordinate is an exact float32 value (and some are long).
    pub float32: bool,
    /// The relative rounding error assumed (0 when the numbers are taken as exact).
    pub relative: f64,
    /// How it was decided.
    pub basis: String,
}

/// The result of [`verify`].
#[derive(Clone, Debug, Serialize)]
pub struct VerifyReport {
    /// The file checked.
    pub file: String,
    /// Whether everything that could be checked passed.
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
    /// Whether `edges_assignment` was absent (boundary edges then come from the faces).
    pub assignment_derived: bool,
    /// What frame 0 is.
    pub key_frame: KeyFrame,
    /// The fitted plane of frame 0 (point, unit normal), when it is planar.
    pub plane: Option<[[f64; 3]; 2]>,
    /// The isometry tolerance asked for.
    pub tol: f64,
    /// The angle tolerance asked for, in degrees.
    pub angle_tol_deg: f64,
    /// The coordinates' precision, which widens the tolerances.
    pub precision: Precision,
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

/// Significant digits of the shortest decimal that reads back as `x`.
fn sig_digits(x: f64) -> u32 {
    if x == 0.0 || !x.is_finite() {
        return 1;
    }
    let s = format!("{:e}", x.abs());
    let mantissa = s.split('e').next().unwrap_or("");
    mantissa.chars().filter(char::is_ascii_digit).count() as u32
}

/// The precision of `coords` (see the module docs).
fn precision(frames: &[&[[f64; 3]]], digits: Option<u32>) -> Precision {
    if let Some(d) = digits {
        let d = d.clamp(1, 17);
        return Precision {
            digits: d,
            float32: false,
            relative: if d >= 16 {
                0.0
            } else {
                0.5 * 10f64.powi(1 - d as i32)
            },
            basis: format!("{d} significant digits, as given"),
        };
    }
    let values = || frames.iter().flat_map(|c| c.iter().flatten().copied());
    let most = values().map(sig_digits).max().unwrap_or(1);
    let float32 = most >= 6 && values().all(|x| f64::from(x as f32) == x);
    let (relative, basis) = if float32 {
        (
            f64::from(f32::EPSILON) / 2.0,
            "every coordinate is a float32 value: rounded to float32 (±6e-8 relative)".to_string(),
        )
    } else if (6..=15).contains(&most) {
        (
            0.5 * 10f64.powi(1 - most as i32),
            format!("coordinates have at most {most} significant digits: rounded to {most}"),
        )
    } else if most <= 5 {
        (
            0.0,
            format!("short numbers (at most {most} significant digits): taken as exact"),
        )
    } else {
        (0.0, "full double precision".to_string())
    };
    Precision {
        digits: most,
        float32,
        relative,
        basis,
    }
}

/// Largest |coordinate| of a frame.
fn magnitude(coords: &[[f64; 3]]) -> f64 {
    coords.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Verify a FOLD file read by [`FoldFile`]; see the module docs for the checks.
pub fn verify(f: &FoldFile, opts: &VerifyOptions) -> VerifyReport {
    let frames_coords: Vec<&[[f64; 3]]> = f.frames.iter().map(|fr| fr.coords.as_slice()).collect();
    let prec = precision(&frames_coords, opts.digits);
    let sheet = Sheet::new(f, opts, &prec);
    let mut checks = Vec::new();
    let kf = classify(&sheet);
    check_key_frame(&sheet, &kf, &mut checks);
    check_planar_faces(&sheet, &mut checks);
    let adj = EdgeFaces::new(&f.edges, &f.faces);
    check_face_sides(&adj, &mut checks);
    let topo_boundary = check_manifold(&sheet, &adj, &mut checks);
    let bverts = check_euler(&sheet, &topo_boundary, &mut checks);
    check_developability(&sheet, &bverts, &mut checks);
    check_key_fold_angles(&sheet, &adj, kf.key_frame, &mut checks);
    let frames = check_frames(&sheet, &adj);
    if frames.is_empty() {
        not_checked_push(
            &mut checks,
            "folded frames",
            "the file has no frames after frame 0: no motion to check".into(),
        );
    }

    let ok = checks.iter().all(|c| c.ok) && frames.iter().all(|fr| fr.ok);
    let Classified {
        plane,
        planar,
        reference,
        key_frame,
        ..
    } = kf;
    VerifyReport {
        file: f.source.clone(),
        ok,
        vertices: sheet.key.len(),
        edges: f.edges.len(),
        faces: f.faces.len(),
        faces_derived: f.faces_derived,
        edges_derived: f.edges_derived,
        assignment_derived: f.assignment_derived,
        key_frame,
        plane: plane.filter(|_| planar).map(|(c, _)| {
            [
                c,
                reference.unwrap_or_else(|| plane.map_or([0.0, 0.0, 1.0], |p| p.1)),
            ]
        }),
        tol: opts.tol,
        angle_tol_deg: opts.angle_tol_deg,
        precision: prec,
        checks,
        frames,
    }
}

/// What the checks of one file share: the file, the tolerances, frame 0 with its scale and
/// faces, and the rounding error the coordinates allow.
struct Sheet<'a> {
    f: &'a FoldFile,
    opts: &'a VerifyOptions,
    /// Frame 0's coordinates.
    key: &'a [[f64; 3]],
    /// Absolute rounding error of a coordinate, per frame.
    delta: Vec<f64>,
    /// Frame 0's, `delta[0]`.
    d0: f64,
    /// Scale of the whole sheet (its bounding box's diagonal), for relative tolerances.
    size: f64,
    /// Newell normal of each face in frame 0 (its length is twice the face's area).
    normals: Vec<[f64; 3]>,
    /// Longest chord of each face in frame 0.
    face_size: Vec<f64>,
    /// A face's height over its longest chord (twice its area over its size): how far a
    /// rounding error of a coordinate can tilt it.
    face_height: Vec<f64>,
}

impl<'a> Sheet<'a> {
    fn new(f: &'a FoldFile, opts: &'a VerifyOptions, prec: &Precision) -> Sheet<'a> {
        let key = &f.frames[0].coords;
        let delta: Vec<f64> = f
            .frames
            .iter()
            .map(|fr| prec.relative * magnitude(&fr.coords))
            .collect();
        let d0 = delta[0];
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in key {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let size = geom::dist(lo, hi).max(f64::MIN_POSITIVE);
        let normals: Vec<[f64; 3]> = (0..f.faces.len())
            .map(|fi| geom::newell_normal(&face_pts(f, key, fi)))
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
        let face_height: Vec<f64> = (0..f.faces.len())
            .map(|fi| geom::norm(normals[fi]) / face_size[fi].max(f64::MIN_POSITIVE))
            .collect();
        Sheet {
            f,
            opts,
            key,
            delta,
            d0,
            size,
            normals,
            face_size,
            face_height,
        }
    }
}

/// The corners of face `fi` at `coords`.
fn face_pts(f: &FoldFile, coords: &[[f64; 3]], fi: usize) -> Vec<[f64; 3]> {
    f.faces[fi].iter().map(|&v| coords[v]).collect()
}

/// The plane of frame 0 and what frame 0 is.
struct Classified {
    /// The best plane through frame 0 (point, unit normal).
    plane: Option<([f64; 3], [f64; 3])>,
    /// The largest distance of a vertex from it.
    flatness: f64,
    /// The largest distance allowed for a flat frame 0.
    flat_allowed: f64,
    planar: bool,
    /// The normal the faces should turn about: +z for a plane z = const (the spec's
    /// counter-clockwise), else the one the faces turn to.
    reference: Option<[f64; 3]>,
    /// Faces turned about `reference` counter-clockwise.
    forward: Vec<usize>,
    /// The others (degenerate faces count as turned the wrong way).
    backward: Vec<usize>,
    key_frame: KeyFrame,
}

/// Fit frame 0's plane and decide what frame 0 is (see the module docs).
fn classify(s: &Sheet) -> Classified {
    let f = s.f;
    let declared = |c: &str| f.frames[0].classes.iter().any(|x| x == c);
    let declared_cp = declared("creasePattern");
    let plane = geom::fit_plane(s.key);
    let flatness = plane.map_or(0.0, |(c, nrm)| {
        s.key
            .iter()
            .map(|p| geom::dot(geom::sub(*p, c), nrm).abs())
            .fold(0.0, f64::max)
    });
    let flat_allowed = s.opts.tol * s.size + 4.0 * s.d0;
    let planar = plane.is_some() && flatness <= flat_allowed;
    let reference = plane.map(|(_, nrm)| {
        if nrm[0].abs() <= 1e-9 && nrm[1].abs() <= 1e-9 {
            [0.0, 0.0, 1.0]
        } else {
            let total = s.normals.iter().fold([0.0; 3], |a, &b| geom::add(a, b));
            if geom::dot(total, nrm) < 0.0 {
                geom::scale(nrm, -1.0)
            } else {
                nrm
            }
        }
    });
    let (forward, backward) = turning(s, reference);
    let mixed = !forward.is_empty() && !backward.is_empty();
    let key_frame = if !planar {
        if declared_cp {
            KeyFrame::CreasePattern
        } else {
            KeyFrame::FoldedForm
        }
    } else if declared_cp || !mixed && forward.len() == f.faces.len() {
        KeyFrame::CreasePattern
    } else if mixed {
        KeyFrame::FlatFolded
    } else {
        // Planar, every face turned backward: a crease pattern seen from behind (a plane
        // z = const with clockwise faces) when not declared a folded form.
        if declared("foldedForm") {
            KeyFrame::FlatFolded
        } else {
            KeyFrame::CreasePattern
        }
    };
    Classified {
        plane,
        flatness,
        flat_allowed,
        planar,
        reference,
        forward,
        backward,
        key_frame,
    }
}

/// Faces by the way they turn about the reference normal (degenerate: neither, counted
/// backward): (forward, backward); both empty without a reference.
fn turning(s: &Sheet, reference: Option<[f64; 3]>) -> (Vec<usize>, Vec<usize>) {
    let (mut forward, mut backward) = (Vec::new(), Vec::new());
    if let Some(r) = reference {
        for fi in 0..s.f.faces.len() {
            let a = geom::dot(s.normals[fi], r);
            let size = s.face_size[fi];
            // Twice the area; rounding can move it by about δ per unit of perimeter.
            let slack = 1e-12 * size * size + 8.0 * s.d0 * size;
            // Degenerate faces count as turned the wrong way.
            if a > slack {
                forward.push(fi);
            } else {
                backward.push(fi);
            }
        }
    }
    (forward, backward)
}

/// A plane in words: `the plane z = 0.5` when it is normal to an axis.
fn plane_text(c: [f64; 3], nrm: [f64; 3]) -> String {
    let axis = [(0, "x"), (1, "y"), (2, "z")]
        .into_iter()
        .find(|&(k, _)| nrm[k].abs() >= 1.0 - 1e-9);
    match axis {
        Some((k, name)) => format!("the plane {name} = {:.4}", tidy(c[k])),
        None => format!(
            "the plane through ({:.4}, {:.4}, {:.4}) with normal ({:.4}, {:.4}, {:.4})",
            tidy(c[0]),
            tidy(c[1]),
            tidy(c[2]),
            tidy(nrm[0]),
            tidy(nrm[1]),
            tidy(nrm[2])
        ),
    }
}

/// "flat crease pattern" and "faces oriented": checked for a crease pattern, said why not
/// for the others.
fn check_key_frame(s: &Sheet, kf: &Classified, checks: &mut Vec<Check>) {
    let why = match kf.key_frame {
        KeyFrame::CreasePattern => return check_crease_pattern(s, kf, checks),
        KeyFrame::FlatFolded => format!(
            "frame 0 is a flat-folded state ({} faces face one way, {} the other), not the crease pattern: the file has no flat sheet to check",
            kf.forward.len(),
            kf.backward.len()
        ),
        KeyFrame::FoldedForm => format!(
            "frame 0 is a folded form (not planar: {:.2e} from its best plane; frame_classes {:?}): the file has no crease pattern, so flatness, face orientation and the isometry to the flat sheet cannot be checked",
            kf.flatness, s.f.frames[0].classes
        ),
    };
    not_checked_push(checks, "flat crease pattern", why.clone());
    not_checked_push(checks, "faces oriented", why);
}

/// Frame 0 of a crease pattern is flat, and its faces turn one way.
fn check_crease_pattern(s: &Sheet, kf: &Classified, checks: &mut Vec<Check>) {
    let (flatness, flat_allowed, size) = (kf.flatness, kf.flat_allowed, s.size);
    let ok = kf.planar;
    let detail = match (kf.plane, kf.reference) {
        (Some((c, _)), Some(nrm)) if ok => format!(
            "frame 0 lies in {} (max distance {flatness:.2e}, allowed {flat_allowed:.1e})",
            plane_text(c, nrm)
        ),
        _ => format!(
            "frame 0 is declared a crease pattern but is not flat: max distance from its best plane {flatness:.3e} (sheet size {size:.3}, allowed {flat_allowed:.1e})"
        ),
    };
    push(checks, "flat crease pattern", ok, detail);
    if let (true, Some(r)) = (kf.planar, kf.reference) {
        let bad: Vec<String> = kf.backward.iter().map(|&fi| format!("face {fi}")).collect();
        let about = if r == [0.0, 0.0, 1.0] {
            "counter-clockwise about +z".to_string()
        } else {
            format!(
                "turned one way about the plane's normal ({:.4}, {:.4}, {:.4})",
                tidy(r[0]),
                tidy(r[1]),
                tidy(r[2])
            )
        };
        push(
            checks,
            "faces oriented",
            bad.is_empty(),
            if bad.is_empty() {
                format!("all {} faces {about}", s.f.faces.len())
            } else {
                format!("not {about} (clockwise or degenerate): {}", list(&bad))
            },
        );
    }
}

/// Planar faces in frame 0: distance of every vertex from the face's plane.
fn check_planar_faces(s: &Sheet, checks: &mut Vec<Check>) {
    let mut worst_planar = (0.0f64, None, 0.0);
    for fi in 0..s.f.faces.len() {
        let Some(nrm) = geom::normalize(s.normals[fi]) else {
            continue;
        };
        let pts = face_pts(s.f, s.key, fi);
        let c = pts.iter().fold([0.0; 3], |a, &p| geom::add(a, p));
        let c = geom::scale(c, 1.0 / pts.len() as f64);
        let size = s.face_size[fi].max(f64::MIN_POSITIVE);
        let allowed = s.opts.tol + 4.0 * s.d0 / size;
        for p in &pts {
            let d = geom::dot(geom::sub(*p, c), nrm).abs() / size;
            if d - allowed > worst_planar.0 - worst_planar.2 || worst_planar.1.is_none() {
                worst_planar = (d, Some(fi), allowed);
            }
        }
    }
    push(
        checks,
        "planar faces",
        worst_planar.0 <= worst_planar.2,
        match worst_planar.1 {
            Some(fi) => format!(
                "max distance from the face plane {:.2e} (relative, face {fi}; allowed {:.1e})",
                worst_planar.0, worst_planar.2
            ),
            None => "every face is planar".into(),
        },
    );
}

/// Every side of every face is an edge of `edges_vertices`.
fn check_face_sides(adj: &EdgeFaces, checks: &mut Vec<Check>) {
    let missing: Vec<String> = adj
        .missing
        .iter()
        .map(|(fi, u, v)| format!("side {u}–{v} of face {fi}"))
        .collect();
    push(
        checks,
        "face sides are edges",
        missing.is_empty(),
        if missing.is_empty() {
            "every side of every face is in edges_vertices".into()
        } else {
            format!("not in edges_vertices: {}", list(&missing))
        },
    );
}

/// A boundary edge in one face, any other in two, one on each side. Returns which edges
/// are in exactly one face (the boundary as the faces have it).
fn check_manifold(s: &Sheet, adj: &EdgeFaces, checks: &mut Vec<Check>) -> Vec<bool> {
    let f = s.f;
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
    push(
        checks,
        "manifold",
        bad_manifold.is_empty(),
        if bad_manifold.is_empty() {
            format!(
                "{n_boundary} boundary edges in one face each, {n_interior} creases in two faces each{}",
                if f.assignment_derived {
                    " (no edges_assignment: the boundary is the edges of one face)"
                } else {
                    ""
                }
            )
        } else {
            list(&bad_manifold)
        },
    );
    topo_boundary
}

/// Connected components among the vertices `verts` of `0..n` joined by `edges`.
fn components(n: usize, edges: impl Iterator<Item = [usize; 2]>, verts: &[bool]) -> usize {
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
}

/// Euler characteristic against the topology of a planar sheet. Returns which vertices
/// are on the boundary (on an edge of `topo_boundary`).
fn check_euler(s: &Sheet, topo_boundary: &[bool], checks: &mut Vec<Check>) -> Vec<bool> {
    let (f, n) = (s.f, s.key.len());
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
    let c = components(n, f.edges.iter().copied(), &used);
    let mut bverts = vec![false; n];
    let bedges: Vec<[usize; 2]> = f
        .edges
        .iter()
        .zip(topo_boundary)
        .filter(|(_, b)| **b)
        .map(|(e, _)| *e)
        .collect();
    for e in &bedges {
        bverts[e[0]] = true;
        bverts[e[1]] = true;
    }
    let nbv = bverts.iter().filter(|&&b| b).count();
    let bc = components(n, bedges.iter().copied(), &bverts);
    // Cycle rank of the boundary graph = number of boundary loops.
    let loops = bedges.len() as i64 - nbv as i64 + bc as i64;
    let chi = nv as i64 - f.edges.len() as i64 + f.faces.len() as i64;
    let expected = 2 * c as i64 - loops;
    push(
        checks,
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
    bverts
}

/// Developability at interior vertices (not in `bverts`): the corner angles of the faces
/// around it sum to 2π, in the flat sheet and in any folded form.
fn check_developability(s: &Sheet, bverts: &[bool], checks: &mut Vec<Check>) {
    let (key, n, d0) = (s.key, s.key.len(), s.d0);
    let angle_tol_rad = s.opts.angle_tol_deg.to_radians();
    let mut sums = vec![0.0f64; n];
    let mut slack = vec![0.0f64; n];
    let mut has_face = vec![false; n];
    for (fi, fc) in s.f.faces.iter().enumerate() {
        let m = fc.len();
        for k in 0..m {
            let v = fc[k];
            let (prev, next) = (key[fc[(k + m - 1) % m]], key[fc[(k + 1) % m]]);
            has_face[v] = true;
            sums[v] += geom::corner_angle(prev, key[v], next, s.normals[fi]);
            // Rounding moves each side's direction by up to about 2δ/length.
            let inv = |p| 1.0 / geom::dist(p, key[v]).max(f64::MIN_POSITIVE);
            slack[v] += 4.0 * d0 * (inv(prev) + inv(next));
        }
    }
    let interior: Vec<usize> = (0..n).filter(|&v| has_face[v] && !bverts[v]).collect();
    let mut worst_dev = (0.0f64, None, 0.0);
    for &v in &interior {
        let err = (sums[v] - std::f64::consts::TAU).abs();
        let allowed = angle_tol_rad + slack[v];
        if err - allowed > worst_dev.0 - worst_dev.2 || worst_dev.1.is_none() {
            worst_dev = (err, Some(v), allowed);
        }
    }
    push(
        checks,
        "developability",
        worst_dev.0 <= worst_dev.2,
        match worst_dev.1 {
            Some(v) => format!(
                "{} interior vertex(es); max |Σ sectors − 2π| = {:.2e} rad (vertex {v}; allowed {:.1e})",
                interior.len(),
                worst_dev.0,
                worst_dev.2
            ),
            None => "no interior vertices".into(),
        },
    );
}

/// Fold angles of a frame (coordinates `coords`, rounding error `delta`) against its
/// geometry: the worst (difference, edge, allowed), in degrees.
fn angle_errors(
    s: &Sheet,
    adj: &EdgeFaces,
    coords: &[[f64; 3]],
    given: &[Option<f64>],
    delta: f64,
) -> (f64, Option<usize>, f64) {
    let geo = adj.fold_angles(&s.f.faces, coords);
    let mut w: (f64, Option<usize>, f64) = (0.0, None, 0.0);
    for i in 0..s.f.edges.len() {
        let (Some(g), Some(r)) = (given[i], geo[i]) else {
            continue;
        };
        let diff = super::fold::wrap((g - r.to_degrees()).to_radians())
            .to_degrees()
            .abs();
        let tilt = match (adj.left[i].as_slice(), adj.right[i].as_slice()) {
            ([l], [r]) => {
                4.0 * (delta + s.d0)
                    * (1.0 / s.face_height[*l].max(f64::MIN_POSITIVE)
                        + 1.0 / s.face_height[*r].max(f64::MIN_POSITIVE))
            }
            _ => 0.0,
        };
        let allowed = s.opts.angle_tol_deg + tilt.to_degrees();
        if diff - allowed > w.0 - w.2 || w.1.is_none() {
            w = (diff, Some(i), allowed);
        }
    }
    w
}

/// Frame 0's fold angles: the target of a crease pattern (their signs against the
/// assignment), or the geometry of a folded frame 0.
fn check_key_fold_angles(s: &Sheet, adj: &EdgeFaces, key_frame: KeyFrame, checks: &mut Vec<Check>) {
    let (f, opts) = (s.f, s.opts);
    match (&f.frames[0].fold_angles, key_frame) {
        (None, _) => not_checked_push(
            checks,
            "fold angles of frame 0",
            "the file has no edges_foldAngle".into(),
        ),
        (Some(_), KeyFrame::CreasePattern) if f.assignment_derived => not_checked_push(
            checks,
            "assignment vs fold angle",
            "the file has no edges_assignment: mountain and valley are not stated".into(),
        ),
        (Some(angles), KeyFrame::CreasePattern) => {
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
            checks.push(Check {
                name: "assignment vs fold angle".into(),
                ok: bad.is_empty(),
                checked: true,
                detail: if bad.is_empty() {
                    "signs of frame 0's edges_foldAngle match edges_assignment".into()
                } else {
                    list(&bad)
                },
            });
        }
        (Some(angles), _) => {
            let (diff, edge, allowed) = angle_errors(s, adj, s.key, angles, 0.0);
            checks.push(Check {
                name: "fold angles vs geometry".into(),
                ok: diff <= allowed,
                checked: true,
                detail: match edge {
                    Some(e) => format!(
                        "frame 0's edges_foldAngle against its dihedral angles: max error {diff:.2e}° (edge {e}; allowed {allowed:.1e}°)"
                    ),
                    None => "no edge with a fold angle between two faces".into(),
                },
            });
        }
    }
}

/// Folded frames: isometric to frame 0 (distances within faces), fold angles as stated.
fn check_frames(s: &Sheet, adj: &EdgeFaces) -> Vec<FrameCheck> {
    let mut frames = Vec::new();
    for (k, fr) in s.f.frames.iter().enumerate().skip(1) {
        let worst_iso = isometry_error(s, k, &fr.coords);
        let mut worst_angle = None;
        if let (Some(given), true) = (&fr.fold_angles, fr.fold_angles_own) {
            worst_angle = Some(angle_errors(s, adj, &fr.coords, given, s.delta[k]));
        }
        let ok = worst_iso.0 <= worst_iso.2 && worst_angle.is_none_or(|w| w.0 <= w.2);
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
    frames
}

/// Frame `k` (at `coords`) against frame 0: the worst relative change of a distance within
/// a face as (error, face, allowed).
fn isometry_error(s: &Sheet, k: usize, coords: &[[f64; 3]]) -> (f64, Option<usize>, f64) {
    let key = s.key;
    let mut worst_iso = (0.0f64, None, 0.0);
    for (fi, fc) in s.f.faces.iter().enumerate() {
        let size = s.face_size[fi];
        let allowed = s.opts.tol + 4.0 * (s.d0 + s.delta[k]) / size.max(f64::MIN_POSITIVE);
        for i in 0..fc.len() {
            for j in i + 1..fc.len() {
                let d0 = geom::dist(key[fc[i]], key[fc[j]]);
                let d1 = geom::dist(coords[fc[i]], coords[fc[j]]);
                let err = if size > 0.0 {
                    (d1 - d0).abs() / size
                } else {
                    f64::INFINITY
                };
                if err - allowed > worst_iso.0 - worst_iso.2 || worst_iso.1.is_none() {
                    worst_iso = (err, Some(fi), allowed);
                }
            }
        }
    }
    worst_iso
}

/// `x` rounded to 4 decimals for a message, without a "-0.0000".
fn tidy(x: f64) -> f64 {
    (x * 1e4).round() / 1e4 + 0.0
}

fn push(checks: &mut Vec<Check>, name: &str, ok: bool, detail: String) {
    checks.push(Check {
        name: name.into(),
        ok,
        checked: true,
        detail,
    });
}

fn not_checked_push(checks: &mut Vec<Check>, name: &str, why: String) {
    checks.push(Check {
        name: name.into(),
        ok: true,
        checked: false,
        detail: why,
    });
}

impl fmt::Display for VerifyReport {
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(out, "verify {}", self.file)?;
        writeln!(
            out,
            "  mesh: {} vertices, {} edges{}, {} faces{}{}",
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
            if self.assignment_derived {
                "; no edges_assignment"
            } else {
                ""
            },
        )?;
        writeln!(out, "  frame 0: {}", self.key_frame.as_str())?;
        writeln!(
            out,
            "  tolerances: isometry {:e} (relative to face size), angles {:e}°; coordinates: {}",
            self.tol, self.angle_tol_deg, self.precision.basis
        )?;
        for c in &self.checks {
            writeln!(
                out,
                "  [{}] {:<26} {}",
                match (c.checked, c.ok) {
                    (false, _) => " -- ",
                    (true, true) => " ok ",
                    (true, false) => "FAIL",
                },
                c.name,
                c.detail
            )?;
        }
        if !self.frames.is_empty() {
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
        let checked = self.checks.iter().filter(|c| c.checked).count();
        let unchecked = self.checks.len() - checked;
        let failed_checks = self.checks.iter().filter(|c| !c.ok).count();
        let failed_frames = self.frames.iter().filter(|f| !f.ok).count();
        let skipped = if unchecked > 0 {
            format!("; {unchecked} not checkable, see [ -- ]")
        } else {
            String::new()
        };
        if self.ok {
            writeln!(
                out,
                "result: OK ({checked} checks, {} folded frames{skipped})",
                self.frames.len()
            )
        } else {
            writeln!(
                out,
                "result: FAILED ({failed_checks} of {checked} checks, {failed_frames} of {} folded frames{skipped})",
                self.frames.len()
            )
        }
    }
}
