//! Shards: a deterministic, cost-balanced share of a search's units.
//!
//! The units (one per graph × gripping candidate: one compiled model, 2^N alternatives)
//! are dealt longest first: by estimated cost, largest first, each to the shard with the
//! least cost so far (the LPT rule; ties go to the unit first in record order and to the
//! lowest shard number). The deal depends on the plan alone, so every shard — and the
//! merge — computes the same one without talking to the others, and all alternatives of
//! a model land in one shard, which compiles it once.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::DistributeError;
use crate::search::output::ShardSpec;
use crate::search::{self, Plan, SearchOptions, ShardReport, Share};
use crate::task::Task;
use crate::task::digest_with_meshes;

/// The units of each of `count` shards (shard k at index k − 1), each in record order.
pub fn assign(plan: &Plan, count: usize) -> Vec<Vec<usize>> {
    deal(plan, &(0..plan.units.len()).collect::<Vec<_>>(), count)
}

/// The units a search of `plan` evaluates: all of them, or those a guided search of
/// budget `guided` selects (see [`search::guide`]).
pub fn searched(plan: &Plan, guided: Option<search::Selection>) -> Vec<usize> {
    match guided {
        None => (0..plan.units.len()).collect(),
        Some(b) => search::guide::select(plan, b.alternatives),
    }
}

/// As [`assign`] for the units `units` of `plan` only (a guided search's selection).
pub fn deal(plan: &Plan, units: &[usize], count: usize) -> Vec<Vec<usize>> {
    let mut order = units.to_vec();
    order.sort_by_key(|&u| (Reverse(plan.units[u].cost), u));
    // Least loaded first; equal loads: the lowest shard number.
    let mut heap: BinaryHeap<Reverse<(u64, usize)>> = (0..count).map(|k| Reverse((0, k))).collect();
    let mut shards = vec![Vec::new(); count];
    for u in order {
        let Some(Reverse((load, k))) = heap.pop() else {
            break;
        };
        shards[k].push(u);
        heap.push(Reverse((load + plan.units[u].cost, k)));
    }
    for s in &mut shards {
        s.sort_unstable();
    }
    shards
}

/// The units of shard `spec`.
pub fn share(plan: &Plan, spec: ShardSpec) -> Vec<usize> {
    assign(plan, spec.count).swap_remove(spec.index - 1)
}

/// Run shard `spec` of the search of `task` (`task_text`: the task file it was read
/// from, kept in the shard's directory for the merge) into `opts.out`.
pub fn run(
    task: &Task,
    task_text: &str,
    opts: &SearchOptions,
    spec: ShardSpec,
) -> Result<ShardReport, DistributeError> {
    if digest_with_meshes(task_text, &task.mesh_digests) != task.digest {
        return Err(DistributeError::input(
            task.source
                .as_deref()
                .unwrap_or(std::path::Path::new(&task.name)),
            "the task file changed while it was read; run again",
        ));
    }
    let n_max = search::check_search(task, opts)?;
    if opts.budget.cpu_s.is_some() {
        return Err(DistributeError::input(
            "--budget-cpu",
            "a shard's share must be the same on every machine: give a guided search in shards a budget of alternatives (--budget-alternatives), not of CPU seconds",
        ));
    }
    let plan = search::plan(task, n_max, opts.rules, &opts.graphs)?;
    let guided = (opts.strategy == search::Strategy::Guided).then_some(search::Selection {
        alternatives: opts.budget.alternatives,
    });
    let units = deal(&plan, &searched(&plan, guided), spec.count).swap_remove(spec.index - 1);
    // A parent may be in another shard: shards start from no parent's optimum.
    let opts = SearchOptions {
        warm_starts: false,
        ..opts.clone()
    };
    Ok(search::run_shard(
        task,
        &plan,
        Share {
            spec,
            units: &units,
            task_text,
        },
        &opts,
    )?)
}
