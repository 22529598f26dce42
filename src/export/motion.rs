//! A design's motion as `designs/<id>.json` stores it: each frame's `t` and vertex
//! positions, both rounded to [`DIGITS`] significant digits, without its fold angles, which are
//! read back from the positions ([`fill_fold_angles`]).
//!
//! Why: the 33 frames are three quarters of a design file, and a search writes one per
//! design (700 for the default gripper). The fold angles are the positions' dihedral
//! angles, so storing both stored the motion twice; ten digits are 1e-10 of G0's crease,
//! far below any tolerance a reader applies (`foldsynth verify` widens its own by the
//! digits a file gives).

use serde_json::{Value, json};

use super::fold::EdgeFaces;
use super::{ExportError, Result};
use crate::geom;
use crate::pattern::{EdgeKind, Pattern};

/// Significant digits of the stored vertex positions.
pub const DIGITS: usize = 10;

/// `x` rounded to [`DIGITS`] significant digits (the shortest decimal that reads back as
/// the rounded value has at most that many).
pub fn round_sig(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    format!("{x:.prec$e}", prec = DIGITS - 1)
        .parse()
        .unwrap_or(x)
}

/// `p` as the design file stores it: [`Pattern`]'s fields, each frame with `t` and
/// `coords` only (both rounded).
pub fn pattern_json(p: &Pattern) -> Value {
    let frames: Vec<Value> = p
        .frames
        .iter()
        .map(|f| {
            let coords: Vec<[f64; 3]> = f
                .coords
                .iter()
                .map(|c| [round_sig(c[0]), round_sig(c[1]), round_sig(c[2])])
                .collect();
            json!({"t": round_sig(f.t), "coords": coords})
        })
        .collect();
    json!({
        "vertices": p.vertices,
        "edges": p.edges,
        "faces": p.faces,
        "frames": frames,
    })
}

/// Give every frame stored without fold angles (an empty list) the fold angle of each
/// edge read from its vertex positions: 0 for a boundary edge, for a crease the signed
/// dihedral angle between its two facets (valley positive, [`geom::fold_angle`]). The
/// pattern's indices must be valid ([`super::validate_pattern`] but for the fold angles).
pub fn fill_fold_angles(p: &mut Pattern) -> Result<()> {
    if p.frames.iter().all(|f| !f.fold_angles.is_empty()) || p.edges.is_empty() {
        return Ok(());
    }
    let ends: Vec<[usize; 2]> = p.edges.iter().map(|e| e.v).collect();
    let sides = EdgeFaces::new(&ends, &p.faces);
    let faces = &p.faces;
    for (j, frame) in p.frames.iter_mut().enumerate() {
        if !frame.fold_angles.is_empty() {
            continue;
        }
        let x = &frame.coords;
        let pts = |f: usize| -> Vec<[f64; 3]> { faces[f].iter().map(|&v| x[v]).collect() };
        let mut angles = Vec::with_capacity(ends.len());
        for (i, e) in p.edges.iter().enumerate() {
            let angle = match e.kind {
                EdgeKind::Boundary => Some(0.0),
                EdgeKind::Crease { .. } => {
                    match (sides.left[i].as_slice(), sides.right[i].as_slice()) {
                        ([l], [r]) => geom::fold_angle(x[e.v[0]], x[e.v[1]], &pts(*l), &pts(*r)),
                        _ => None,
                    }
                }
            };
            angles.push(angle.ok_or_else(|| {
                ExportError::invalid(
                    format!("pattern.frames[{j}].fold_angles"),
                    format!(
                        "absent, and the fold angle of crease {i} cannot be read from the positions (it needs one facet on each side and facets of nonzero area); give fold_angles, one per edge in radians"
                    ),
                )
            })?);
        }
        frame.fold_angles = angles;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::samples;

    /// The dihedral angles read from the positions are the motion's own fold angles (the
    /// degree-4 sample's are exact: closed form, see `samples::degree4`), after rounding
    /// the positions as the design file does.
    #[test]
    fn fold_angles_read_from_rounded_positions_are_the_motions() {
        for gamma in [0.7, 1.2, 2.0] {
            let p = samples::degree4(gamma, 2.8, 9);
            let text = json!({"pattern": pattern_json(&p)}).to_string();
            let v: Value = serde_json::from_str(&text).unwrap();
            let mut q: Pattern = serde_json::from_value(v["pattern"].clone()).unwrap();
            assert!(q.frames.iter().all(|f| f.fold_angles.is_empty()));
            fill_fold_angles(&mut q).unwrap();
            for (a, b) in p.frames.iter().zip(&q.frames) {
                assert_eq!(round_sig(a.t), b.t);
                for (x, y) in a.fold_angles.iter().zip(&b.fold_angles) {
                    assert!((x - y).abs() < 1e-8, "γ {gamma}: {x} vs {y}");
                }
                for (c, d) in a.coords.iter().zip(&b.coords) {
                    for k in 0..3 {
                        assert!((c[k] - d[k]).abs() <= 1e-9 * c[k].abs().max(1e-300));
                    }
                }
            }
        }
    }

    #[test]
    fn rounding_keeps_ten_significant_digits() {
        assert_eq!(round_sig(1.167878471977619), 1.167878472);
        assert_eq!(round_sig(-0.08512900956416271), -0.08512900956);
        assert_eq!(round_sig(0.0), 0.0);
        assert_eq!(round_sig(1.0), 1.0);
    }

    /// A crease whose facet is missing cannot be read: the error names the frame.
    #[test]
    fn a_crease_without_two_facets_is_refused() {
        let mut p = samples::single_crease(1.0, 3);
        p.faces.pop();
        for f in &mut p.frames {
            f.fold_angles.clear();
        }
        let e = fill_fold_angles(&mut p).unwrap_err().to_string();
        assert!(e.contains("pattern.frames[0].fold_angles"), "{e}");
    }
}
