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
    let mut order: Vec<usize> = (0..plan.units.len()).collect();
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
    let plan = search::plan(task, n_max, opts.rules)?;
    let units = share(&plan, spec);
    Ok(search::run_shard(
        task,
        &plan,
        Share {
            spec,
            units: &units,
            task_text,
        },
        opts,
    )?)
}
