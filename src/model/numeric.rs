//! The numeric path: a model evaluated in `f64` for given variables and modes, turned into
//! a [`Pattern`] (flat layout, creases, facets, folded frames) for verification, checks
//! and export.

use super::geometry::{self, Flat, Folded};
use super::linalg;
use super::plan::Plan;
use crate::kinematics::{solve_vertex, wrap_angle};
use crate::pattern::{Edge, EdgeKind, Frame, Pattern};

/// A design evaluated numerically: the flat pattern and any number of folded states.
#[derive(Clone, Debug)]
pub struct Evaluated<'a> {
    /// The plan it belongs to.
    pub plan: &'a Plan,
    /// The full variable vector.
    pub vars: Vec<f64>,
    /// ±1 per internal vertex.
    pub modes: Vec<f64>,
    /// The flat pattern.
    pub flat: Flat<f64>,
}

impl<'a> Evaluated<'a> {
    /// Evaluate `plan` at `vars` (full vector) with `modes`.
    pub fn new(plan: &'a Plan, vars: Vec<f64>, modes: Vec<f64>) -> Evaluated<'a> {
        let flat = geometry::flat(plan, &vars);
        Evaluated {
            plan,
            vars,
            modes,
            flat,
        }
    }

    /// The folded state at `t`.
    pub fn fold(&self, t: f64) -> Folded<f64> {
        let mut folded = geometry::fold(self.plan, &self.flat, &self.modes, &t);
        // The flat state of a cyclic pattern (r2′) is flat by definition: every fold angle
        // 0, every facet map the identity. There a flat-foldable vertex (the Miura-ori's)
        // has a doubly degenerate triangle (zero area, perimeter 2π) and the PTU's φ is
        // undefined; the sweep skips that state, but frames and exports start from it.
        if !self.plan.sinks.is_empty()
            && self
                .plan
                .creases
                .iter()
                .all(|c| c.drive.as_ref().is_none_or(|d| d.eval(&t) == 0.0))
        {
            folded.rho.iter_mut().for_each(|r| *r = 0.0);
            folded.rot.iter_mut().for_each(|r| *r = linalg::identity());
            folded.trans.iter_mut().for_each(|c| *c = [0.0; 3]);
            // The vertex states must describe that configuration too: with a vertex
            // triangle of perimeter 2π (s = π), sin s is rounding (~1e-16), so the PTU's
            // θ miss π by √ε and its φ are ~1e-8 of noise, which the next vertex takes as
            // its driving angle. Left in place, they disagree with the zeroed fold angles
            // and closure, measured on both, fails by that noise (issue 19: 8.6e-8 at t = 0
            // for a gripper design). Re-solve every vertex on the zeroed driving angles
            // and take the flat state's φ = 0.
            let rho: Vec<Option<f64>> = folded.rho.iter().map(|r| Some(*r)).collect();
            let modes = self.plan.vertex_modes(&self.modes);
            for (k, &a) in self.plan.internal.iter().enumerate() {
                let units = geometry::units(self.plan, &self.flat, &rho, a)
                    .expect("every fold angle is set");
                let mut st = solve_vertex(&units, &modes[k]);
                st.phi = [0.0; 3];
                folded.states[a] = Some(st);
            }
        }
        folded
    }

    /// 3D position of every vertex at the folded state `folded`.
    pub fn coords(&self, folded: &Folded<f64>) -> Vec<[f64; 3]> {
        (0..self.plan.vertices.len())
            .map(|v| geometry::position(self.plan, &self.flat, folded, v))
            .collect()
    }

    /// The edges of the pattern: every crease (tail first), then the paper's edges that
    /// close open facets.
    pub fn edges(&self) -> Vec<Edge> {
        let mut edges: Vec<Edge> = self
            .plan
            .creases
            .iter()
            .map(|c| Edge {
                v: [c.tail, c.head],
                kind: EdgeKind::Crease {
                    driven: c.drive.is_some(),
                },
            })
            .collect();
        for (poly, closed) in &self.plan.polygons {
            if !closed && poly.len() >= 2 {
                edges.push(Edge {
                    v: [poly[poly.len() - 1], poly[0]],
                    kind: EdgeKind::Boundary,
                });
            }
        }
        edges
    }

    /// The pattern with frames at the given values of t.
    pub fn pattern(&self, ts: &[f64]) -> Pattern {
        self.pattern_of(ts, &self.fold_all(ts))
    }

    /// The folded state at each of `ts`.
    pub fn fold_all(&self, ts: &[f64]) -> Vec<Folded<f64>> {
        ts.iter().map(|&t| self.fold(t)).collect()
    }

    /// [`Evaluated::pattern`] from states already folded at `ts` (`folds[i]` at `ts[i]`),
    /// so that the search folds each state once for the pattern and for `check::verify`.
    pub fn pattern_of(&self, ts: &[f64], folds: &[Folded<f64>]) -> Pattern {
        let edges = self.edges();
        let ncreases = self.plan.creases.len();
        let frames = ts
            .iter()
            .zip(folds)
            .map(|(&t, folded)| {
                let mut fold_angles: Vec<f64> = folded.rho.iter().map(|r| wrap_angle(*r)).collect();
                fold_angles.resize(edges.len(), 0.0);
                debug_assert!(fold_angles.len() >= ncreases);
                Frame {
                    t,
                    coords: self.coords(folded),
                    fold_angles,
                }
            })
            .collect();
        Pattern {
            vertices: self.flat.pos.clone(),
            edges,
            faces: self
                .plan
                .polygons
                .iter()
                .filter(|(p, _)| p.len() >= 3)
                .map(|(p, _)| p.clone())
                .collect(),
            frames,
        }
    }
}

/// `n` evenly spaced values over `[0, t_max]` (both ends included, `n ≥ 2`).
pub fn sample_times(t_max: f64, n: usize) -> Vec<f64> {
    let n = n.max(2);
    (0..n).map(|i| t_max * i as f64 / (n - 1) as f64).collect()
}
