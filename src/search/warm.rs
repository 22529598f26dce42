//! Warm starts of a guided search (issue 34): a child graph is its parent plus one rule
//! application, and its model keeps every variable of the parent's under the same name
//! (the rules replay the parent's steps and name what they create after the vertices),
//! so the parent's optimum is a point of the child's space. An r1 child's new vertex
//! hangs off an existing one; at the parent's values every vertex the two share is
//! placed where the parent's optimum placed it (tests/guided_search.rs checks that).
//!
//! The guided order puts an r1 child after its parent (its score is one lower, see
//! [`guide`](super::guide)), and the search finishes one score before starting the next,
//! so the parent's optimum is on record whenever the child is taken up, whatever the
//! number of workers: the records stay a function of the seed and the budget.
//!
//! Memory: the free variables' values of each alternative that met the target and can
//! still have an r1 child (fewer than N_max vertices), its names once per model.

use super::plan::Plan;
use super::record::AlternativeRecord;
use crate::model::Model;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// The optima a guided search has on record, by alternative number.
#[derive(Default)]
pub(super) struct Optima {
    inner: Mutex<Inner>,
}

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
    /// Keep `rec` (the record of alternative `index` of unit `unit`) when it met the
    /// target and its graph can have an r1 child.
    pub(super) fn keep(&self, plan: &Plan, unit: usize, index: u64, rec: &AlternativeRecord) {
        let g = &plan.graphs[plan.units[unit].graph];
        if !rec.meets_target || g.n >= plan.n_max {
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

    /// The warm starts of alternative `modes` of unit `u` (its model `model`): the optimum
    /// of the same candidate and modes of its parent graph, with the child's other
    /// variables at each of [`PLACEMENTS`]; none when the parent has none on record.
    pub(super) fn starts(&self, plan: &Plan, u: usize, modes: u32, model: &Model) -> Vec<Vec<f64>> {
        let unit = &plan.units[u];
        let Some(p) = plan.graphs[unit.graph].parent else {
            return Vec::new();
        };
        let parent_unit = p * 3 + unit.candidate;
        let pn = plan.graphs[p].n;
        // The child's vertices are the parent's in extension order, then r1's new one.
        let parent_modes = modes & ((1u32 << pn) - 1);
        let index = plan.units[parent_unit].first + u64::from(parent_modes);
        let inner = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        let (Some(names), Some(values)) = (inner.names.get(&parent_unit), inner.values.get(&index))
        else {
            return Vec::new();
        };
        let parent: HashMap<&str, f64> = names
            .iter()
            .map(String::as_str)
            .zip(values.iter().copied())
            .filter(|(_, v)| v.is_finite())
            .collect();
        PLACEMENTS
            .iter()
            .map(|&(length, sector)| {
                model
                    .free
                    .iter()
                    .map(|&i| {
                        let var = &model.plan.variables[i];
                        let (lo, hi) = model.var_bounds(i);
                        parent.get(var.name.as_str()).copied().unwrap_or_else(|| {
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
}
