//! Ear-clipping triangulation of facet polygons in their flat 2D coordinates.
//!
//! Facets are simple polygons (they may be non-convex at their ends), so ear clipping is
//! exact and cheap at the sizes origami facets have. The triangles are computed once from
//! the flat layout and reused for every folded state.

use thiserror::Error;

/// Why a facet could not be triangulated.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TriangulateError {
    /// Fewer than three vertices.
    #[error("facet {face} has {len} vertices; a facet needs at least 3")]
    TooFewVertices {
        /// Index of the facet.
        face: usize,
        /// Number of vertices it has.
        len: usize,
    },
    /// A vertex index points past the vertex list.
    #[error("facet {face} refers to vertex {vertex}, but there are only {count} vertices")]
    VertexOutOfRange {
        /// Index of the facet.
        face: usize,
        /// The offending vertex index.
        vertex: usize,
        /// Number of vertices in the pattern.
        count: usize,
    },
    /// The polygon is clockwise in the flat layout (facets must be counter-clockwise).
    #[error("facet {face} is clockwise (signed area {area:.3e}); facets must be counter-clockwise")]
    Clockwise {
        /// Index of the facet.
        face: usize,
        /// Its signed area in the flat layout.
        area: f64,
    },
    /// No ear was found: the polygon is not simple (self-touching or self-crossing).
    #[error("facet {face} is not a simple polygon (no ear left among {remaining} vertices)")]
    NotSimple {
        /// Index of the facet.
        face: usize,
        /// Vertices left when clipping got stuck.
        remaining: usize,
    },
}

/// Signed area of a polygon (positive when counter-clockwise).
pub fn signed_area(layout: &[[f64; 2]], poly: &[usize]) -> f64 {
    let n = poly.len();
    let mut a = 0.0;
    for k in 0..n {
        let p = layout[poly[k]];
        let q = layout[poly[(k + 1) % n]];
        a += p[0] * q[1] - q[0] * p[1];
    }
    0.5 * a
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Whether `p` lies in the closed triangle `a b c` (counter-clockwise), with tolerance `eps`
/// on the edge functions.
fn in_closed_triangle(p: [f64; 2], a: [f64; 2], b: [f64; 2], c: [f64; 2], eps: f64) -> bool {
    cross(a, b, p) >= -eps && cross(b, c, p) >= -eps && cross(c, a, p) >= -eps
}

/// Triangulate one counter-clockwise simple polygon by ear clipping.
///
/// Returns counter-clockwise triangles as vertex-index triples. Triangles of zero area
/// (left over when the polygon has collinear vertices) are dropped: they cover no area and
/// have no interior to intersect. `face` only labels errors.
pub fn triangulate_polygon(
    layout: &[[f64; 2]],
    poly: &[usize],
    face: usize,
) -> Result<Vec<[usize; 3]>, TriangulateError> {
    if poly.len() < 3 {
        return Err(TriangulateError::TooFewVertices {
            face,
            len: poly.len(),
        });
    }
    if let Some(&vertex) = poly.iter().find(|&&v| v >= layout.len()) {
        return Err(TriangulateError::VertexOutOfRange {
            face,
            vertex,
            count: layout.len(),
        });
    }
    let area = signed_area(layout, poly);
    // Scale for the collinearity tolerance: twice-areas are compared against size².
    let size = poly
        .iter()
        .flat_map(|&v| layout[v])
        .fold(0.0_f64, |m, x| m.max(x.abs()))
        .max(1e-300);
    let eps = 1e-12 * size * size;
    if area <= eps {
        return Err(TriangulateError::Clockwise { face, area });
    }
    let mut rest: Vec<usize> = poly.to_vec();
    let mut tris = Vec::with_capacity(poly.len() - 2);
    while rest.len() > 3 {
        let n = rest.len();
        let ear = (0..n).find(|&k| {
            let (ia, ib, ic) = (rest[(k + n - 1) % n], rest[k], rest[(k + 1) % n]);
            let (a, b, c) = (layout[ia], layout[ib], layout[ic]);
            if cross(a, b, c) <= eps {
                return false; // reflex or collinear tip
            }
            // No other vertex may lie in the ear (on its boundary counts: the diagonal
            // would pass through it). Vertices coinciding with a corner are the same point.
            rest.iter().all(|&iv| {
                if iv == ia || iv == ib || iv == ic {
                    return true;
                }
                let p = layout[iv];
                if p == a || p == b || p == c {
                    return true;
                }
                !in_closed_triangle(p, a, b, c, eps)
            })
        });
        let Some(k) = ear else {
            // Only collinear vertices left means the remaining area is zero: done.
            let left = signed_area(layout, &rest);
            if left.abs() <= eps * rest.len() as f64 {
                return Ok(tris);
            }
            return Err(TriangulateError::NotSimple {
                face,
                remaining: rest.len(),
            });
        };
        tris.push([rest[(k + n - 1) % n], rest[k], rest[(k + 1) % n]]);
        rest.remove(k);
    }
    let (a, b, c) = (layout[rest[0]], layout[rest[1]], layout[rest[2]]);
    if cross(a, b, c) > eps {
        tris.push([rest[0], rest[1], rest[2]]);
    }
    Ok(tris)
}

/// Triangulate every facet. `result[f]` holds the triangles of facet `f`.
pub fn triangulate_faces(
    layout: &[[f64; 2]],
    faces: &[Vec<usize>],
) -> Result<Vec<Vec<[usize; 3]>>, TriangulateError> {
    faces
        .iter()
        .enumerate()
        .map(|(f, poly)| triangulate_polygon(layout, poly, f))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn total_area(layout: &[[f64; 2]], tris: &[[usize; 3]]) -> f64 {
        tris.iter().map(|t| signed_area(layout, t)).sum()
    }

    #[test]
    fn square_gives_two_triangles_of_its_area() {
        let l = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
        let t = triangulate_polygon(&l, &[0, 1, 2, 3], 0).unwrap();
        assert_eq!(t.len(), 2);
        assert!((total_area(&l, &t) - 4.0).abs() < 1e-12);
        assert!(t.iter().all(|tri| signed_area(&l, tri) > 0.0));
    }

    #[test]
    fn non_convex_polygon_is_covered_exactly() {
        // An L-shape (area 3) and an arrow with a reflex vertex.
        let l = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ];
        let t = triangulate_polygon(&l, &[0, 1, 2, 3, 4, 5], 0).unwrap();
        assert_eq!(t.len(), 4);
        assert!((total_area(&l, &t) - 3.0).abs() < 1e-12);
        assert!(t.iter().all(|tri| signed_area(&l, tri) > 0.0));
        // Every triangle's centroid lies inside the L (not in the missing square).
        for tri in &t {
            let cx = (l[tri[0]][0] + l[tri[1]][0] + l[tri[2]][0]) / 3.0;
            let cy = (l[tri[0]][1] + l[tri[1]][1] + l[tri[2]][1]) / 3.0;
            assert!(!(cx > 1.0 && cy > 1.0));
        }
    }

    #[test]
    fn collinear_vertex_is_kept_and_area_preserved() {
        let l = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [1.0, 1.0]];
        let t = triangulate_polygon(&l, &[0, 1, 2, 3], 0).unwrap();
        assert!((total_area(&l, &t) - 1.0).abs() < 1e-12);
        assert!(t.iter().all(|tri| signed_area(&l, tri) > 0.0));
    }

    #[test]
    fn clockwise_and_short_polygons_are_rejected() {
        let l = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        assert!(matches!(
            triangulate_polygon(&l, &[0, 2, 1], 4),
            Err(TriangulateError::Clockwise { face: 4, .. })
        ));
        assert!(matches!(
            triangulate_polygon(&l, &[0, 1], 1),
            Err(TriangulateError::TooFewVertices { face: 1, len: 2 })
        ));
        assert!(matches!(
            triangulate_polygon(&l, &[0, 1, 7], 2),
            Err(TriangulateError::VertexOutOfRange { vertex: 7, .. })
        ));
    }
}
