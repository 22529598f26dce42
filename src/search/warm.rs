//! Warm starts of a guided search (issue 34): a child graph is its parent plus one rule
//! application, and the two models share their variables by name (the rules replay the
//! parent's steps and name what they create after the vertices), so an optimum of one is
//! a point of the other's space. An r1 child's new vertex hangs off an existing one; at
//! the parent's values every vertex the two share is placed where the parent's optimum
//! placed it (tests/guided_search.rs checks that). An r2 child keeps the parent's
//! vertices and gripping vertex and joins two of its boundary vertices: its optimum is a
//! parent's configuration with the gripping vertex on target.
//!
//! The guided order (see [`guide`](super::guide)) takes an r2 child one score before its
//! parent and an r1 child one score after, and the search finishes one score before it
//! starts the next: an alternative's warm starts are the optima on record of its parent
//! (same candidate, the parent's modes) and of its r2 children (same modes), whatever the
//! number of workers, so the records stay a function of the seed and the budget. They
//! run after the quasi-random starts, only when those failed.
//!
//! Memory: the free variables' values of each alternative that met the target and can
//! warm-start another (it has fewer than N_max vertices, or it is an r2 child), its names
//! once per model.

use super::plan::Plan;
use super::record::AlternativeRecord;
use crate::model::Model;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// The optima a guided search has on record, by alternative number.
pub(super) struct Optima {
    inner: Mutex<Inner>,
    /// Per graph: its children made by combining two vertices (r2, r2′: the same internal
    /// vertices, the same gripping vertex), whose optima its warm starts may come from.
    combined: Vec<Vec<u32>>,
}

/// At most this many warm starts per alternative.
const MAX_WARM: usize = 4;

#[derive(Default)]
struct Inner {
    /// Per unit: the names of its model's free variables, sorted.
    names: HashMap<usize, Arc<[String]>>,
    /// Per alternative: the values in the order of its unit's names.
    values: HashMap<u64, Box<[f64]>>,
}

/// Where the new variables of a child start: (a length's share of its range, a sector
/// angle's). The first keeps the new creases short, so the child's gripping vertex
/// starts close to where the parent's optimum put the parent's; the second puts them in
/// the middle of their ranges.
const PLACEMENTS: [(f64, f64); 2] = [(0.0, 0.5), (0.5, 0.5)];

impl Optima {
    /// None on record yet, for the graphs of `plan`.
    pub(super) fn new(plan: &Plan) -> Optima {
        let mut combined = vec![Vec::new(); plan.graphs.len()];
        for (i, g) in plan.graphs.iter().enumerate() {
            if let Some(p) = g.parent.filter(|&p| plan.graphs[p].n == g.n) {
                combined[p].push(i as u32);
            }
        }
        Optima {
            inner: Mutex::default(),
            combined,
        }
    }

    /// Keep `rec` (the record of alternative `index` of unit `unit`) when it met the
    /// target and its graph can have an r1 child.
    pub(super) fn keep(&self, plan: &Plan, unit: usize, index: u64, rec: &AlternativeRecord) {
        let graph = plan.units[unit].graph;
        let g = &plan.graphs[graph];
        // Of use to an r1 child (fewer than N_max vertices) or to the parent of an r2 one.
        let parent_of_combined = g.parent.is_some_and(|p| plan.graphs[p].n == g.n);
        if !rec.meets_target || (g.n >= plan.n_max && !parent_of_combined) {
            return;
        }
        let mut inner = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        let names = inner
            .names
            .entry(unit)
            .or_insert_with(|| rec.variables.keys().cloned().collect())
            .clone();
        let values = names
            .iter()
            .map(|n| rec.variables.get(n).copied().unwrap_or(f64::NAN))
            .collect();
        inner.values.insert(index, values);
    }

    /// The warm starts of alternative `modes` of unit `u` (its model `model`): the optima
    /// on record of the same candidate and modes of its parent graph and of its children
    /// by r2 (same vertices, same gripping vertex: a child's optimum puts the gripping
    /// vertex where the parent's must go), each with the other variables at each of
    /// [`PLACEMENTS`]; at most [`MAX_WARM`], parent first.
    pub(super) fn starts(&self, plan: &Plan, u: usize, modes: u32, model: &Model) -> Vec<Vec<f64>> {
        let unit = &plan.units[u];
        let inner = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        // (graph, modes) of each source: the child's vertices are the parent's in
        // extension order, then r1's new one.
        let parent = plan.graphs[unit.graph]
            .parent
            .map(|p| (p, modes & ((1u32 << plan.graphs[p].n) - 1)));
        let children = self.combined[unit.graph]
            .iter()
            .map(|&c| (c as usize, modes));
        let mut starts = Vec::new();
        for (g, m) in parent.into_iter().chain(children) {
            let source = g * 3 + unit.candidate;
            let index = plan.units[source].first + u64::from(m);
            let (Some(names), Some(values)) = (inner.names.get(&source), inner.values.get(&index))
            else {
                continue;
            };
            let known: HashMap<&str, f64> = names
                .iter()
                .map(String::as_str)
                .zip(values.iter().copied())
                .filter(|(_, v)| v.is_finite())
                .collect();
            starts.extend(placed(&known, model));
            if starts.len() >= MAX_WARM {
                starts.truncate(MAX_WARM);
                break;
            }
        }
        starts
    }
}

/// The free variables of `model` at the values `known` by name, the others at each of
/// [`PLACEMENTS`].
fn placed(known: &HashMap<&str, f64>, model: &Model) -> Vec<Vec<f64>> {
    PLACEMENTS
        .iter()
        .map(|&(length, sector)| {
            model
                .free
                .iter()
                .map(|&i| {
                    let var = &model.plan.variables[i];
                    let (lo, hi) = model.var_bounds(i);
                    known.get(var.name.as_str()).copied().unwrap_or_else(|| {
                        let share = match var.kind {
                            crate::grammar::VarKind::Length => length,
                            _ => sector,
                        };
                        lo + share * (hi - lo)
                    })
                })
                .collect()
        })
        .collect()
}
