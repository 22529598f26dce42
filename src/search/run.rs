//! A search from end to end, its phases in order: the check of the task and settings, the
//! plan, the output directory, the units evaluated, and (for a whole run) the finish —
//! summary, designs, report; a shard instead reports its share in `shard.json`.

use super::finish::finish;
use super::guide;
use super::open::{open_output, settings};
use super::options::{
    SHARD_REPORT, SHARD_TASK, SearchError, SearchOptions, ShardReport, Share, check_search,
};
use super::output::RECORDS;
use super::plan::{Plan, plan};
use super::progress::Progress;
use super::readback::tally_records;
use super::record::{Summary, Timings};
use super::schedule::evaluate_units;
use super::strategy::Strategy;
use crate::task::Task;
use std::time::Instant;

/// Run the search of `task` and write everything under `opts.out`.
pub fn run(task: &Task, opts: &SearchOptions) -> Result<Summary, SearchError> {
    let start = Instant::now();
    let n_max = check_search(task, opts)?;
    let progress = Progress::new(opts.progress).with_hook(opts.on_progress.clone());
    progress.phase("enumerate graphs", "graphs", None);
    let plan = plan(task, n_max, opts.rules, &opts.graphs)?;
    progress.inc(plan.graphs.len() as u64);
    progress.finish_phase_with(&format!(
        "{} generated, {} meaningful",
        plan.generated,
        plan.graphs.len()
    ));
    let (out, resume) = open_output(&settings(task, n_max, opts, None), opts)?;
    let units = match opts.strategy {
        Strategy::Exhaustive => (0..plan.units.len()).collect(),
        Strategy::Guided => guide::select(&plan, opts.budget.alternatives),
    };
    let ev = evaluate_units(task, &plan, &units, &out, resume, opts, &progress)?;
    finish(task, &plan, &out, opts, &ev, start, &progress)
}

/// Run shard `share` of the search of `task` (planned as `plan`) into `opts.out`: its
/// records, the task file and `shard.json`; `merge` makes the whole run of the shards.
pub fn run_shard(
    task: &Task,
    plan: &Plan,
    share: Share<'_>,
    opts: &SearchOptions,
) -> Result<ShardReport, SearchError> {
    let start = Instant::now();
    let n_max = check_search(task, opts)?;
    let (out, resume) = open_output(&settings(task, n_max, opts, Some(share.spec)), opts)?;
    out.write(SHARD_TASK, share.task_text)?;
    let progress = Progress::new(opts.progress).with_hook(opts.on_progress.clone());
    let ev = evaluate_units(task, plan, share.units, &out, resume, opts, &progress)?;
    drop(progress);
    let tally = tally_records(plan, &out.path(RECORDS))?.0;
    super::parquet::write_results(&out)?;
    let report = ShardReport {
        shard: share.spec,
        units: share.units.len(),
        alternatives: share.units.iter().map(|&u| plan.units[u].count).sum(),
        records: tally.records,
        cost: plan.cost(share.units),
        total_cost: plan.units.iter().map(|u| u.cost).sum(),
        failed_models: ev.failed,
        timings: Timings {
            enumerate_s: plan.enumerate_s,
            compile_s: ev.compile_s,
            optimize_s: tally.optimize_ms / 1e3 + 0.0,
            check_s: tally.check_ms / 1e3 + 0.0,
            export_s: 0.0,
            total_s: start.elapsed().as_secs_f64(),
            cpu_s: crate::cpu_time::process_seconds(),
        },
    };
    out.write(
        SHARD_REPORT,
        serde_json::to_string_pretty(&report).unwrap_or_default() + "\n",
    )?;
    Ok(report)
}
