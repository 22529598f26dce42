//! Origami Simulator's SVG import, re-implemented from its rules (issue 20).
//!
//! Origami Simulator (amandaghassaei/OrigamiSimulator, MIT) reads an SVG crease pattern in
//! `js/pattern.js` (`loadSVG`, `parseSVG`) with the FOLD library's filters
//! (`dependencies/fold.js`). This is an independent re-implementation of those steps as
//! they act on the files foldsynth writes (`<line>` elements with `stroke`, `opacity` and
//! `stroke-opacity` attributes, no transforms), in the app's order, with its quirks where
//! they decide the outcome:
//!
//! 1. every line of a recognized colour gives two new vertices and one edge, all borders
//!    first, then mountains, valleys, cuts, facet ("triangulation") and hinge lines, each in
//!    document order; the edge list is then borders, mountains, valleys, facets, hinges,
//!    cuts. A mountain's target angle is −180° × opacity × stroke-opacity, a valley's +180° ×
//!    the same, kept only when non-zero; facet edges get 0, the others none;
//! 2. merge vertices closer than the tolerance (each vertex joins the first earlier one
//!    found within it, searching the 3 × 3 grid cells of the tolerance's size around it;
//!    the merged vertex keeps the coordinates of the last vertex merged into it), drop
//!    edges whose ends merged, drop duplicate edges (the last duplicate's data wins);
//! 3. split edges at intersections: for each pair of edges (later ones first) intersect
//!    their lines; where the intersection lies on both segments up to the tolerance
//!    (measured along each segment) and more than the tolerance inside at least one,
//!    split that one at the crossing or at the other's nearby end;
//! 4. step 2 again; then drop vertices without edges and merge the two edges at any vertex
//!    of degree 2 whose edges are within 0.01 of straight (cosine) and have one assignment.
//!
//! The result is the graph the app folds (before it triangulates faces). [`compare`] holds
//! it against the pattern foldsynth exported.

#![allow(dead_code)] // each test crate uses part of it

use std::collections::HashMap;

use foldsynth::export::fold::{Assignment, assignments, wrap};
use foldsynth::export::svg::{SvgOptions, SvgScale, svg_scale};
use foldsynth::pattern::Pattern;

/// The vertex merge tolerance Origami Simulator uses unless the user changes it (px).
pub const DEFAULT_TOLERANCE: f64 = 3.0;

/// An imported crease pattern: coordinates as in the file (px, y down).
#[derive(Clone, Debug, Default)]
pub struct Imported {
    /// Vertex coordinates.
    pub coords: Vec<[f64; 2]>,
    /// Edge ends.
    pub edges: Vec<[usize; 2]>,
    /// Edge assignments: B, M, V, F, U or C.
    pub assignment: Vec<char>,
    /// Target fold angles in degrees (valley positive); `None` is the app's null/undefined.
    pub angle: Vec<Option<f64>>,
}

/// Read the SVG text the way Origami Simulator does and import it with `tol`.
pub fn import_svg(text: &str, tol: f64) -> Imported {
    let doc = roxmltree::Document::parse(text).expect("SVG is well-formed XML");
    for shape in ["path", "rect", "polygon", "polyline"] {
        assert!(
            !doc.descendants().any(|n| n.has_tag_name(shape)),
            "the importer model reads <line> only, the file has a <{shape}>"
        );
    }
    let lines: Vec<_> = doc
        .descendants()
        .filter(|n| n.has_tag_name("line"))
        .collect();
    let mut raw: Vec<[f64; 2]> = Vec::new();
    // Segments per type: (first vertex, target angle if any).
    let mut by_type: HashMap<char, Vec<Segment>> = HashMap::new();
    for ty in ['B', 'M', 'V', 'C', 'F', 'U'] {
        for l in &lines {
            let Some(stroke) = l.attribute("stroke") else {
                continue;
            };
            if type_for_stroke(stroke) != Some(ty) {
                continue;
            }
            let num = |k: &str| -> f64 {
                l.attribute(k)
                    .unwrap_or_else(|| panic!("<line> without {k}"))
                    .parse()
                    .unwrap_or_else(|e| panic!("<line> {k}: {e}"))
            };
            raw.push([num("x1"), num("y1")]);
            raw.push([num("x2"), num("y2")]);
            let opacity = |k: &str| {
                l.attribute(k)
                    .and_then(|s| s.trim().parse::<f64>().ok())
                    .unwrap_or(1.0)
            };
            let op = opacity("opacity") * opacity("stroke-opacity");
            // `if (element.targetAngle)`: a zero angle is not recorded.
            let angle = match ty {
                'M' => Some(-op * 180.0),
                'V' => Some(op * 180.0),
                _ => None,
            }
            .filter(|a| *a != 0.0);
            by_type
                .entry(ty)
                .or_default()
                .push(([raw.len() - 2, raw.len() - 1], angle));
        }
    }
    let mut f = Imported {
        coords: raw,
        ..Imported::default()
    };
    for ty in ['B', 'M', 'V', 'F', 'U', 'C'] {
        for (e, a) in by_type.remove(&ty).unwrap_or_default() {
            f.edges.push(e);
            f.assignment.push(ty);
            f.angle.push(match ty {
                'M' | 'V' => a,
                'F' => Some(0.0),
                _ => None,
            });
        }
    }
    import(f, tol)
}

/// A line's two raw vertices and its target angle, if any.
type Segment = ([usize; 2], Option<f64>);

fn type_for_stroke(stroke: &str) -> Option<char> {
    let s: String = stroke
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_lowercase();
    Some(match s.as_str() {
        "#000000" | "#000" | "black" | "rgb(0,0,0)" => 'B',
        "#ff0000" | "#f00" | "red" | "rgb(255,0,0)" => 'M',
        "#0000ff" | "#00f" | "blue" | "rgb(0,0,255)" => 'V',
        "#00ff00" | "#0f0" | "green" | "rgb(0,255,0)" => 'C',
        "#ffff00" | "#ff0" | "yellow" | "rgb(255,255,0)" => 'F',
        "#ff00ff" | "#f0f" | "magenta" | "rgb(255,0,255)" => 'U',
        _ => return None,
    })
}

/// Steps 2–4 on raw vertices and edges.
pub fn import(mut f: Imported, tol: f64) -> Imported {
    collapse_nearby_vertices(&mut f, tol);
    remove_loop_edges(&mut f);
    remove_duplicate_edges(&mut f);
    find_intersections(&mut f, tol);
    collapse_nearby_vertices(&mut f, tol);
    remove_loop_edges(&mut f);
    remove_duplicate_edges(&mut f);
    let mut nbrs = vertices_vertices(&f);
    remove_stray_vertices(&mut f, &mut nbrs);
    remove_redundant_vertices(&mut f, &mut nbrs, 0.01);
    f
}

/// JavaScript's `Math.round` (halves toward +∞), with −0 read as 0 as in a string key.
fn js_round(x: f64) -> u64 {
    ((x + 0.5).floor() + 0.0).to_bits()
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    (dx * dx + dy * dy).sqrt()
}

/// `filter.remapField(fold, 'vertices', old2new)` on coordinates and edges: each new vertex
/// takes the coordinates of the last old vertex mapped to it.
fn remap_vertices(f: &mut Imported, old2new: &[Option<usize>]) {
    let n = old2new.iter().flatten().map(|&j| j + 1).max().unwrap_or(0);
    let mut new2old = vec![usize::MAX; n];
    for (i, j) in old2new.iter().enumerate() {
        if let Some(j) = j {
            new2old[*j] = i;
        }
    }
    f.coords = new2old.iter().map(|&i| f.coords[i]).collect();
    for e in &mut f.edges {
        for v in e.iter_mut() {
            *v = old2new[*v].expect("an edge ends at a removed vertex");
        }
    }
}

/// `filter.remapField(fold, 'edges', old2new)`: each new edge takes the data of the last old
/// edge mapped to it.
fn remap_edges(f: &mut Imported, old2new: &[Option<usize>]) {
    let n = old2new.iter().flatten().map(|&j| j + 1).max().unwrap_or(0);
    let mut new2old = vec![usize::MAX; n];
    for (i, j) in old2new.iter().enumerate() {
        if let Some(j) = j {
            new2old[*j] = i;
        }
    }
    f.edges = new2old.iter().map(|&i| f.edges[i]).collect();
    f.assignment = new2old.iter().map(|&i| f.assignment[i]).collect();
    f.angle = new2old.iter().map(|&i| f.angle[i]).collect();
}

/// `filter.collapseNearbyVertices` (its `RepeatedPointsDS`).
fn collapse_nearby_vertices(f: &mut Imported, eps: f64) {
    let mut kept: Vec<[f64; 2]> = Vec::new();
    let mut hash: HashMap<(u64, u64), Vec<usize>> = HashMap::new();
    let old2new: Vec<Option<usize>> = f
        .coords
        .iter()
        .map(|&c| {
            let (xr, yr) = ((c[0] / eps + 0.5).floor(), (c[1] / eps + 0.5).floor());
            for xt in [xr, xr - 1.0, xr + 1.0] {
                for yt in [yr, yr - 1.0, yr + 1.0] {
                    let key = ((xt + 0.0).to_bits(), (yt + 0.0).to_bits());
                    if let Some(found) = hash
                        .get(&key)
                        .and_then(|list| list.iter().find(|&&v| eps > dist(kept[v], c)))
                    {
                        return Some(*found);
                    }
                }
            }
            let key = (js_round(c[0] / eps), js_round(c[1] / eps));
            hash.entry(key).or_default().push(kept.len());
            kept.push(c);
            Some(kept.len() - 1)
        })
        .collect();
    remap_vertices(f, &old2new);
}

/// `filter.removeLoopEdges`.
fn remove_loop_edges(f: &mut Imported) {
    let mut next = 0;
    let old2new: Vec<Option<usize>> = f
        .edges
        .iter()
        .map(|e| {
            (e[0] != e[1]).then(|| {
                next += 1;
                next - 1
            })
        })
        .collect();
    remap_edges(f, &old2new);
}

/// `filter.removeDuplicateEdges_vertices`.
fn remove_duplicate_edges(f: &mut Imported) {
    let mut seen: HashMap<(usize, usize), usize> = HashMap::new();
    let old2new: Vec<Option<usize>> = f
        .edges
        .iter()
        .map(|e| {
            let key = (e[0].min(e[1]), e[0].max(e[1]));
            let id = seen.len();
            Some(*seen.entry(key).or_insert(id))
        })
        .collect();
    remap_edges(f, &old2new);
}

/// Paul Bourke's line intersection as the app writes it: the point and both parameters.
fn line_intersect(
    v1: [f64; 2],
    v2: [f64; 2],
    v3: [f64; 2],
    v4: [f64; 2],
) -> Option<([f64; 2], f64, f64)> {
    let ([x1, y1], [x2, y2], [x3, y3], [x4, y4]) = (v1, v2, v3, v4);
    let denom = (y4 - y3) * (x2 - x1) - (x4 - x3) * (y2 - y1);
    if denom == 0.0 {
        return None;
    }
    let ua = ((x4 - x3) * (y1 - y3) - (y4 - y3) * (x1 - x3)) / denom;
    let ub = ((x2 - x1) * (y1 - y3) - (y2 - y1) * (x1 - x3)) / denom;
    Some(([x1 + ua * (x2 - x1), y1 + ua * (y2 - y1)], ua, ub))
}

fn dist_from_end(t: f64, length: f64, tol: f64) -> Option<f64> {
    let d = t * length;
    (d >= -tol && d <= length + tol).then_some(d)
}

/// The app's `findIntersections`, index arithmetic included.
fn find_intersections(f: &mut Imported, tol: f64) {
    let mut steps = 0usize;
    let mut i = f.edges.len() as isize - 1;
    while i >= 0 {
        let mut j = i - 1;
        while j >= 0 {
            steps += 1;
            assert!(steps < 100_000_000, "findIntersections does not end");
            let (iu, ju) = (i as usize, j as usize);
            let (ei, ej) = (f.edges[iu], f.edges[ju]);
            let (v1, v2, v3, v4) = (
                f.coords[ei[0]],
                f.coords[ei[1]],
                f.coords[ej[0]],
                f.coords[ej[1]],
            );
            if let Some((x, t1, t2)) = line_intersect(v1, v2, v3, v4) {
                let len1 = dist(v2, v1);
                let len2 = dist(v4, v3);
                if let (Some(d1), Some(d2)) =
                    (dist_from_end(t1, len1, tol), dist_from_end(t2, len2, tol))
                {
                    let seg1 = d1 > tol && d1 < len1 - tol;
                    let seg2 = d2 > tol && d2 < len2 - tol;
                    if seg1 || seg2 {
                        let vi = if seg1 && seg2 {
                            f.coords.push(x);
                            f.coords.len() - 1
                        } else if seg1 {
                            if d2 <= tol { ej[0] } else { ej[1] }
                        } else if d1 <= tol {
                            ei[0]
                        } else {
                            ei[1]
                        };
                        if seg1 {
                            split(f, iu, vi);
                            i += 1;
                        }
                        if seg2 {
                            split(f, ju, vi);
                            j += 1;
                            i += 1;
                        }
                    }
                }
            }
            j -= 1;
        }
        i -= 1;
    }
}

/// `edges.splice(k, 1, [v, e0], [v, e1])` and the same for its data.
fn split(f: &mut Imported, k: usize, v: usize) {
    let e = f.edges[k];
    let (a, g) = (f.assignment[k], f.angle[k]);
    f.edges.splice(k..=k, [[v, e[0]], [v, e[1]]]);
    f.assignment.splice(k..=k, [a, a]);
    f.angle.splice(k..=k, [g, g]);
}

fn vertices_vertices(f: &Imported) -> Vec<Vec<usize>> {
    let mut n = vec![Vec::new(); f.coords.len()];
    for e in &f.edges {
        n[e[0]].push(e[1]);
        n[e[1]].push(e[0]);
    }
    n
}

/// `removeStrayVertices`.
fn remove_stray_vertices(f: &mut Imported, nbrs: &mut Vec<Vec<usize>>) {
    let mut next = 0;
    let old2new: Vec<Option<usize>> = nbrs
        .iter()
        .map(|l| {
            (!l.is_empty()).then(|| {
                next += 1;
                next - 1
            })
        })
        .collect();
    remap_vertices(f, &old2new);
    *nbrs = vertices_vertices(f);
}

/// `removeRedundantVertices` with its `mergeEdge`.
fn remove_redundant_vertices(f: &mut Imported, nbrs: &mut [Vec<usize>], eps: f64) {
    let mut old2new = Vec::with_capacity(nbrs.len());
    let mut next = 0;
    let mut merged_any = false;
    for i in 0..nbrs.len() {
        let keep = |next: &mut usize| {
            *next += 1;
            Some(*next - 1)
        };
        if nbrs[i].len() != 2 {
            old2new.push(keep(&mut next));
            continue;
        }
        let c = f.coords[i];
        let (n0, n1) = (f.coords[nbrs[i][0]], f.coords[nbrs[i][1]]);
        let v0 = [n0[0] - c[0], n0[1] - c[1]];
        let w0 = [n1[0] - c[0], n1[1] - c[1]];
        let dot = (v0[0] * w0[0] + v0[1] * w0[1])
            / ((v0[0] * v0[0] + v0[1] * v0[1]) * (w0[0] * w0[0] + w0[1] * w0[1])).sqrt();
        let (a, b) = (nbrs[i][0], nbrs[i][1]);
        if (dot + 1.0).abs() < eps && merge_edge(f, nbrs, a, i, b) {
            merged_any = true;
            old2new.push(None);
        } else {
            old2new.push(keep(&mut next));
        }
    }
    if merged_any {
        remap_vertices(f, &old2new);
    }
}

fn merge_edge(f: &mut Imported, nbrs: &mut [Vec<usize>], v1: usize, v2: usize, v3: usize) -> bool {
    let mut asg = None;
    let (mut sum, mut count) = (0.0, 0);
    let mut found = Vec::new();
    for k in (0..f.edges.len()).rev() {
        let e = f.edges[k];
        if e.contains(&v2) && (e.contains(&v1) || e.contains(&v3)) {
            match asg {
                None => asg = Some(f.assignment[k]),
                Some(a) if a != f.assignment[k] => return false,
                Some(_) => {}
            }
            // `if (angle)`: null, undefined, 0 and NaN do not count.
            if let Some(a) = f.angle[k].filter(|a| *a != 0.0 && !a.is_nan()) {
                sum += a;
                count += 1;
            }
            found.push(k);
        }
    }
    for k in found {
        f.edges.remove(k);
        f.assignment.remove(k);
        f.angle.remove(k);
    }
    f.edges.push([v1, v3]);
    f.assignment
        .push(asg.expect("a vertex of degree 2 has edges"));
    f.angle.push((count > 0).then(|| sum / count as f64));
    for (a, b) in [(v1, v3), (v3, v1)] {
        if let Some(pos) = nbrs[a].iter().position(|&w| w == v2) {
            nbrs[a].remove(pos);
        }
        nbrs[a].push(b);
    }
    true
}

/// Whether `imported` is `p`'s graph as written into an SVG with options `o`: the same
/// vertices (each imported vertex within a quarter of the smallest feature of where the
/// page puts one of ours, one to one), the same edges with the same assignments, and the
/// final fold angles (degrees, within 0.001°; none for boundary edges, 0 for flat ones).
/// `Err` names the first difference.
pub fn compare(p: &Pattern, o: &SvgOptions, imported: &Imported) -> Result<(), String> {
    let sc: SvgScale = svg_scale(p, o).map_err(|e| e.to_string())?;
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for v in &p.vertices {
        for k in 0..2 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let s = sc.px_per_unit;
    let page: Vec<[f64; 2]> = p
        .vertices
        .iter()
        .map(|v| [(v[0] - lo[0]) * s + o.margin, (hi[1] - v[1]) * s + o.margin])
        .collect();
    if imported.coords.len() != page.len() {
        return Err(format!(
            "{} vertices imported, {} written",
            imported.coords.len(),
            page.len()
        ));
    }
    let near = 0.25 * sc.min_feature_px.unwrap_or(1.0);
    let mut ours = vec![usize::MAX; imported.coords.len()];
    let mut taken = vec![false; page.len()];
    for (k, c) in imported.coords.iter().enumerate() {
        let (best, d) = page
            .iter()
            .enumerate()
            .map(|(i, q)| (i, dist(*c, *q)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("vertices");
        if d > near || taken[best] {
            return Err(format!(
                "imported vertex {k} at ({:.4}, {:.4}) px is no written vertex (nearest v{} at {d:.4} px)",
                c[0],
                c[1],
                best + 1
            ));
        }
        taken[best] = true;
        ours[k] = best;
    }
    let asg = assignments(p);
    let last = p.frames.last();
    let key = |a: usize, b: usize| (a.min(b), a.max(b));
    let mut want: HashMap<(usize, usize), (char, Option<f64>)> = HashMap::new();
    for (i, e) in p.edges.iter().enumerate() {
        let angle = last.map_or(0.0, |f| wrap(f.fold_angles[i]).to_degrees());
        let (c, a) = match asg[i] {
            Assignment::B => ('B', None),
            Assignment::M => ('M', Some(angle)),
            Assignment::V => ('V', Some(angle)),
            Assignment::F | Assignment::J => ('F', Some(0.0)),
            Assignment::U => ('U', None),
        };
        want.insert(key(e.v[0], e.v[1]), (c, a));
    }
    if imported.edges.len() != want.len() {
        return Err(format!(
            "{} edges imported, {} written",
            imported.edges.len(),
            want.len()
        ));
    }
    for (k, e) in imported.edges.iter().enumerate() {
        let (a, b) = (ours[e[0]], ours[e[1]]);
        let label = format!("imported edge {k} (v{}–v{})", a + 1, b + 1);
        let Some(&(c, angle)) = want.get(&key(a, b)) else {
            return Err(format!("{label} is no written edge"));
        };
        if imported.assignment[k] != c {
            return Err(format!(
                "{label}: assignment {} imported, {c} written",
                imported.assignment[k]
            ));
        }
        match (imported.angle[k], angle) {
            (None, None) => {}
            (Some(x), Some(y)) if (x - y).abs() <= 1e-3 => {}
            (x, y) => {
                return Err(format!(
                    "{label}: fold angle {x:?}° imported, {y:?}° written"
                ));
            }
        }
    }
    Ok(())
}
