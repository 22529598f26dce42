//! The guided search (issue 34): which models to optimize first, and how many, when the
//! design space is too large to enumerate.
//!
//! The plan (every meaningful graph × gripping candidate, as for the exhaustive search)
//! is walked in the order of a score, and the walk stops at a budget: a number of
//! alternatives (deterministic: the same seed and budget give the same records) or CPU
//! seconds (anytime). Records, seeds and keys are the exhaustive search's, so an
//! unlimited guided run has exactly the exhaustive run's records, and either kind of run
//! resumes the other's directory.
//!
//! **The score** of a graph is its combine count minus its vertex count: `r2 − N`, where
//! r2 counts the applications of r2 (and r2′) and N those of r1 (the internal vertices);
//! ties go to fewer vertices (cheaper: 2^N alternatives), then to enumeration order.
//! Measured on the gripper's exhaustive N_max = 4 run (28,122 alternatives, 907 CPU s;
//! `docs/guided-search.md` has the table and the commands): robustness rises with the
//! rules that combine vertices (the median robustness score of a design is 1.2 at level 4
//! and 1.9 at level 9; the 100 most robust designs sit in graphs of levels 6–10), while
//! the cost of a model grows as 2^N. Walking in this order reaches 82 of the 100 most
//! robust designs in the first 20 % of the CPU time; scoring a graph by what its parent
//! reached (best-first down the derivation tree, by the parent's best robustness or its
//! share of designs) reaches 5–19, because a parent's robustness says little about its
//! children's and the walk must pay for every ancestor first.
//!
//! **Shards** of a guided run split the budget's selection, not the whole plan: the
//! selected models are dealt longest first like an exhaustive run's (see
//! `distribute::shard`), so the shards together evaluate exactly the whole run's records.

use super::plan::{Plan, PlannedGraph};
use super::strategy::{Budget, Coverage, Strategy, VertexCoverage};

/// The guided search's score of graph `g`: combine applications minus internal vertices
/// (higher first; see the module's documentation for why).
pub fn score(g: &PlannedGraph) -> i64 {
    let combines = g.level.saturating_sub(g.n) as i64;
    combines - g.n as i64
}

/// Every unit of `plan` in the guided order: score, highest first; then fewer internal
/// vertices; then record order (graph, candidate).
pub fn order(plan: &Plan) -> Vec<usize> {
    let mut units: Vec<usize> = (0..plan.units.len()).collect();
    units.sort_by_key(|&u| rank(plan, u));
    units
}

/// Where unit `u` goes in [`order`] (smaller first).
pub fn rank(plan: &Plan, u: usize) -> (std::cmp::Reverse<i64>, usize, usize) {
    let g = &plan.graphs[plan.units[u].graph];
    (std::cmp::Reverse(score(g)), g.n, u)
}

/// The units a guided search with `alternatives` to spend evaluates, in its order: the
/// shortest prefix of [`order`] holding at least that many alternatives (all with
/// `None`).
pub fn select(plan: &Plan, alternatives: Option<u64>) -> Vec<usize> {
    let mut units = order(plan);
    if let Some(budget) = alternatives {
        let mut sum = 0u64;
        let keep = units
            .iter()
            .take_while(|&&u| {
                let more = sum < budget;
                sum += plan.units[u].count;
                more
            })
            .count();
        units.truncate(keep);
    }
    units
}

/// How much of `plan` the records covered, counted as `(alternatives, designs)` per N
/// (index N − 1).
pub fn coverage(
    plan: &Plan,
    strategy: Strategy,
    budget: Budget,
    counted: &[(u64, u64)],
) -> Coverage {
    let mut by_vertices: Vec<VertexCoverage> = Vec::new();
    for g in &plan.graphs {
        while by_vertices.len() < g.n {
            let n = by_vertices.len() + 1;
            let (alternatives, designs) = counted.get(n - 1).copied().unwrap_or_default();
            by_vertices.push(VertexCoverage {
                n,
                alternatives,
                total: 0,
                designs,
            });
        }
        by_vertices[g.n - 1].total += 3 << g.n;
    }
    Coverage {
        strategy,
        budget,
        alternatives: by_vertices.iter().map(|v| v.alternatives).sum(),
        total: plan.alternatives,
        by_vertices,
    }
}
