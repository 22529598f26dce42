//! Feature size of a flat layout: how close the crease pattern comes to itself (issue 20).
//!
//! Three kinds of feature, all measured in the flat state in paper units:
//!
//! * the distance between two vertices (when they are joined by an edge, the length of that
//!   crease or boundary edge);
//! * the distance from a vertex to an edge it is not an end of (point to segment; counted
//!   as this kind where the nearest point is inside the edge, else it is a vertex pair).
//!
//! The smallest of these is the pattern's *minimum feature*. It matters twice: a sheet
//! cannot be cut or creased at features far below its thickness, and importers that snap
//! geometry — Origami Simulator merges SVG vertices closer than its tolerance (3 px by
//! default) and splits an edge at any vertex within that tolerance of it — change a pattern
//! whose features fall below their tolerance. If every feature is larger than the
//! tolerance, neither happens: a split needs a vertex within the tolerance of a segment it
//! does not end on, a merge two vertices within it (see `export::svg`).
//!
//! ```
//! use foldsynth::check::features::{FeatureKind, min_feature};
//! // A unit square with two creases from its bottom corners up to (0.5, 0.97): that
//! // vertex is 0.03 below the top side, closer than anything else comes.
//! let v = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.97]];
//! let edges = [[0, 1], [1, 2], [2, 3], [3, 0], [0, 4], [1, 4]];
//! let f = min_feature(&v, &edges).unwrap();
//! assert!((f.value - 0.03).abs() < 1e-12);
//! assert_eq!(f.kind, FeatureKind::VertexEdge { v: 4, a: 2, b: 3 });
//! assert_eq!(f.label(), "v5 ↔ edge v3–v4");
//! ```

use serde::Serialize;

/// Which two parts of the pattern a feature lies between (0-based vertex indices).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum FeatureKind {
    /// Two vertices not joined by an edge.
    Vertices {
        /// One vertex.
        a: usize,
        /// The other vertex.
        b: usize,
    },
    /// The length of the edge (crease or boundary edge) from `a` to `b`.
    Edge {
        /// First end.
        a: usize,
        /// Second end.
        b: usize,
    },
    /// Vertex `v` and the edge from `a` to `b`, which does not end at `v`.
    VertexEdge {
        /// The vertex.
        v: usize,
        /// First end of the edge.
        a: usize,
        /// Second end of the edge.
        b: usize,
    },
}

/// One measured feature: its size and where it is.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Feature {
    /// Its size in paper units.
    pub value: f64,
    /// Where it is.
    #[serde(flatten)]
    pub kind: FeatureKind,
}

impl Feature {
    /// A label for people, with vertices numbered from 1 as everywhere foldsynth shows
    /// them: `"v3 ↔ v7"`, `"edge v2–v5"`, `"v4 ↔ edge v1–v2"`.
    pub fn label(&self) -> String {
        match self.kind {
            FeatureKind::Vertices { a, b } => format!("v{} ↔ v{}", a + 1, b + 1),
            FeatureKind::Edge { a, b } => format!("edge v{}–v{}", a + 1, b + 1),
            FeatureKind::VertexEdge { v, a, b } => {
                format!("v{} ↔ edge v{}–v{}", v + 1, a + 1, b + 1)
            }
        }
    }
}

/// Distance from `p` to the segment `a`–`b` (to `a` when the segment is a point).
pub fn point_segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let s = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - s * dx).hypot(p[1] - a[1] - s * dy)
}

/// Every feature of the layout `vertices` with `edges`: one per vertex pair and one per
/// vertex and edge it is not an end of whose nearest point to the vertex lies inside the
/// edge (when it is an end, the vertex pair has it), in no particular order. `edges` must
/// index into `vertices`.
pub fn features(vertices: &[[f64; 2]], edges: &[[usize; 2]]) -> Vec<Feature> {
    let n = vertices.len();
    let joined = |a: usize, b: usize| {
        edges
            .iter()
            .any(|e| (e[0] == a && e[1] == b) || (e[0] == b && e[1] == a))
    };
    let mut out = Vec::with_capacity(n * n / 2 + n * edges.len());
    for a in 0..n {
        for b in a + 1..n {
            let (p, q) = (vertices[a], vertices[b]);
            let value = (p[0] - q[0]).hypot(p[1] - q[1]);
            let kind = if joined(a, b) {
                FeatureKind::Edge { a, b }
            } else {
                FeatureKind::Vertices { a, b }
            };
            out.push(Feature { value, kind });
        }
    }
    for (v, &p) in vertices.iter().enumerate() {
        for e in edges {
            if e[0] == v || e[1] == v {
                continue;
            }
            let (a, b) = (vertices[e[0]], vertices[e[1]]);
            // Only where the nearest point is inside the edge: otherwise it is an end, and
            // that distance is already a vertex–vertex feature (this keeps labels exact
            // instead of letting rounding pick between two names for one distance).
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let s = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy);
            if s > 0.0 && s < 1.0 {
                out.push(Feature {
                    value: point_segment_distance(p, a, b),
                    kind: FeatureKind::VertexEdge {
                        v,
                        a: e[0],
                        b: e[1],
                    },
                });
            }
        }
    }
    out
}

/// The smallest feature of the layout, `None` with fewer than two vertices.
pub fn min_feature(vertices: &[[f64; 2]], edges: &[[usize; 2]]) -> Option<Feature> {
    features(vertices, edges)
        .into_iter()
        .min_by(|x, y| x.value.total_cmp(&y.value))
}

/// The smallest feature of a pattern's flat layout (creases and boundary edges alike).
pub fn pattern_min_feature(p: &crate::pattern::Pattern) -> Option<Feature> {
    let edges: Vec<[usize; 2]> = p.edges.iter().map(|e| e.v).collect();
    min_feature(&p.vertices, &edges)
}
