//! A crease pattern as plain numbers: flat layout, creases, facets and folded states.
//!
//! This is the hand-off point between the model (which computes it) and everything that
//! only needs geometry: verification, intersection checks, export and the bar-and-hinge
//! simulator. It carries no symbols and no graph-grammar structure.

use serde::{Deserialize, Serialize};

/// What an edge of the pattern is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EdgeKind {
    /// A side of the paper (belongs to exactly one facet).
    Boundary,
    /// A crease between two facets; `driven` marks an actuated crease.
    Crease {
        /// Whether this crease is actuated by the task (its angle is prescribed).
        driven: bool,
    },
}

/// An edge between two vertices (indices into [`Pattern::vertices`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Edge {
    /// The two end vertices. For creases, `v[0]` is the tail of the directed graph edge.
    pub v: [usize; 2],
    /// Boundary or crease.
    pub kind: EdgeKind,
}

/// One folded state of the pattern.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    /// The driving parameter of this state.
    pub t: f64,
    /// 3D position of every vertex.
    pub coords: Vec<[f64; 3]>,
    /// Fold angle of every edge in radians, valley positive (0 for boundary edges). A
    /// design file may leave it out (read as empty; see `export::motion`).
    #[serde(default)]
    pub fold_angles: Vec<f64>,
}

/// A crease pattern with its folded states.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pattern {
    /// Flat (unfolded) 2D coordinates of every vertex.
    pub vertices: Vec<[f64; 2]>,
    /// Creases and boundary edges.
    pub edges: Vec<Edge>,
    /// Facets as vertex index lists, counter-clockwise in the flat state.
    pub faces: Vec<Vec<usize>>,
    /// Folded states, ordered by `t`.
    pub frames: Vec<Frame>,
}

impl Pattern {
    /// The indices of the edges marked as driven creases, in edge order.
    pub fn driven_edges(&self) -> Vec<usize> {
        (0..self.edges.len())
            .filter(|&i| matches!(self.edges[i].kind, EdgeKind::Crease { driven: true }))
            .collect()
    }

    /// The flat state lifted to 3D (z = 0).
    pub fn flat_coords(&self) -> Vec<[f64; 3]> {
        self.vertices.iter().map(|p| [p[0], p[1], 0.0]).collect()
    }

    /// The crease pattern with its folded form alone: the last frame, the state a FOLD
    /// viewer folds toward (no frame when there is none).
    pub fn folded_form(&self) -> Pattern {
        Pattern {
            vertices: self.vertices.clone(),
            edges: self.edges.clone(),
            faces: self.faces.clone(),
            frames: self.frames.last().cloned().into_iter().collect(),
        }
    }
}
