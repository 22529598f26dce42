//! The end of a search (or of a merge): the records read back into the summary and the
//! ranking, `alternatives.parquet`, then the designs and the report written, and
//! `summary.json` last.

use super::designs::write_designs;
use super::guide::coverage;
use super::options::{Evaluation, SearchError, SearchOptions};
use super::output::{OutputDir, RECORDS};
use super::parquet::write_results;
use super::plan::Plan;
use super::progress::Progress;
use super::readback::{read_at, tally_records};
use super::record::{RankEntry, Summary, Tally, Timings};
use super::report::write_report;
use super::strategy::Budget;
use crate::model::robust::RobustSpec;
use crate::task::Task;
use serde_json::json;
use std::path::Path;
use std::time::Instant;

/// Summarize the records in `OUT/alternatives.jsonl` and write `summary.json`, the
/// designs and (with export) their files and the report. `start` is when the run began.
pub fn finish(
    task: &Task,
    plan: &Plan,
    out: &OutputDir,
    opts: &SearchOptions,
    ev: &Evaluation,
    start: Instant,
    progress: &Progress,
) -> Result<Summary, SearchError> {
    let records = out.path(RECORDS);
    let (tally, designs) = tally_records(plan, &records)?;
    // The columnar copy of the records, complete before anything else is written.
    write_results(out)?;
    let mut timings = Timings {
        enumerate_s: plan.enumerate_s,
        compile_s: ev.compile_s,
        optimize_s: tally.optimize_ms / 1e3 + 0.0,
        check_s: tally.check_ms / 1e3 + 0.0,
        export_s: 0.0,
        total_s: 0.0,
        cpu_s: 0.0,
    };
    let mut summary = summarize(task, plan, opts, ev, tally, timings.clone());
    (summary.designs, summary.ranking) = ranking(&records, &designs)?;

    let t2 = Instant::now();
    summary.timings.total_s = start.elapsed().as_secs_f64();
    let cards = write_designs(task, plan, &records, &designs, opts, out, progress)?;
    write_report(
        task,
        plan.tree.clone(),
        &summary,
        opts,
        out,
        progress,
        cards,
    )?;
    timings.export_s = t2.elapsed().as_secs_f64();
    timings.total_s = start.elapsed().as_secs_f64();
    // A run (or a merge) is one process: its CPU time so far.
    timings.cpu_s = crate::cpu_time::process_seconds();
    summary.timings = timings;
    out.write(
        "summary.json",
        serde_json::to_string_pretty(&summary).unwrap_or_default(),
    )?;
    Ok(summary)
}

/// The summary of the records' `tally`, without its designs and ranking.
fn summarize(
    task: &Task,
    plan: &Plan,
    opts: &SearchOptions,
    ev: &Evaluation,
    tally: Tally,
    timings: Timings,
) -> Summary {
    Summary {
        task: task.name.clone(),
        n_max: plan.n_max,
        graphs: plan.graphs.len(),
        alternatives: tally.records,
        meets_target: tally.meets_target,
        no_self_intersection: tally.no_self_intersection,
        no_intersection: tally.no_intersection,
        feasible: tally.feasible,
        rigid_at_tmax_only: tally.rigid_at_tmax_only,
        verification_failures: tally.verification_failures,
        // The thesis's counts are of the whole space, not of a guided run's budget.
        thesis: if plan.n_max == 3 && opts.budget == Budget::default() {
            Summary::thesis_counts(&task.name)
        } else {
            None
        },
        timings,
        levels: tally.levels,
        settings: json!({
            "starts": opts.starts, "seed": opts.seed, "jobs": ev.jobs,
            "sweep": opts.sweep, "resumed": ev.resumed, "resume": ev.resume,
            "post_check_only": opts.post_check_only,
            "optimize_states": (!opts.post_check_only)
                .then(|| RobustSpec::from_task(task, opts.sweep).states),
            "robustness": {
                "rigid_margin": task.robustness.rigid_margin,
                "clearance": task.robustness.clearance,
                "obstacle_clearance": task.robustness.obstacle_clearance,
                "min_feature": task.robustness.min_feature,
            },
        }),
        meets_margins: tally.meets_margins,
        near_rigid_limit: tally.near_rigid_limit,
        short_of_margins: tally.short_of_margins,
        ranking: Vec::new(),
        designs: Vec::new(),
        cyclic: opts.rules.r2p.then(|| {
            let mut c = tally.cyclic.clone();
            c.graphs = plan.cyclic_graphs;
            c
        }),
        coverage: Some(coverage(
            plan,
            opts.strategy,
            opts.budget,
            &tally.by_vertices,
        )),
    }
}

/// The ids and scores of the designs at `designs` (places in the records file, most
/// robust first), in that order, from the records.
fn ranking(
    records: &Path,
    designs: &[(u64, u64)],
) -> Result<(Vec<String>, Vec<RankEntry>), SearchError> {
    let mut ids = Vec::with_capacity(designs.len());
    let mut ranking = Vec::with_capacity(designs.len());
    for chunk in designs.chunks(1024) {
        for rec in read_at(records, chunk)? {
            ids.push(rec.id());
            ranking.push(RankEntry {
                id: rec.id(),
                score: rec.robustness.as_ref().map(|x| x.score),
            });
        }
    }
    Ok((ids, ranking))
}
