//! The designs of a search: every feasible design rebuilt from its record, written as
//! `designs/<id>.json` and (with export) its files, most robust first, each with its card
//! for the report; the export metadata of a design; a recorded design's robustness
//! measured again.

use super::measure::{checked_pattern, judged_times, measure_robustness, thick_design};
use super::options::{SearchError, SearchOptions};
use super::output::OutputDir;
use super::plan::Plan;
use super::progress::Progress;
use super::readback::read_at;
use super::record::AlternativeRecord;
use super::report::report_design;
use crate::check::robustness::RobustnessReport;
use crate::export::report::ReportDesign;
use crate::export::{self, DesignMeta, ExportOptions};
use crate::grammar::CreaseGraph;
use crate::model::Model;
use crate::model::numeric::{Evaluated, sample_times};
use crate::pattern::Pattern;
use crate::task::Task;
use rayon::prelude::*;
use serde_json::json;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Write `designs/<id>.json` for every feasible design (`feasible`: their places in the
/// records file, most robust first) and, with export, its files; the report's card of
/// each, in that order.
pub(super) fn write_designs(
    task: &Task,
    plan: &Plan,
    records: &Path,
    feasible: &[(u64, u64)],
    opts: &SearchOptions,
    out_dir: &OutputDir,
    progress: &Progress,
) -> Result<Vec<ReportDesign>, SearchError> {
    // The earlier run's designs were deleted when the directory was opened (only the
    // files its manifest lists).
    out_dir.create_dir("designs")?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs)
        .build()
        .map_err(|e| SearchError::Export(e.to_string()))?;
    progress.phase(
        if opts.export {
            "write designs and their files"
        } else {
            "write design JSONs"
        },
        "designs",
        Some(feasible.len() as u64),
    );
    // Designs are independent: built and written in parallel, a chunk at a time (memory
    // holds one chunk); each chunk's files are listed in the manifest in one step before
    // any is written. The cards stay in the order of `feasible`: most robust first, `rank`
    // 1.
    let mut cards: Vec<ReportDesign> = Vec::new();
    for (c, chunk) in feasible.chunks(256).enumerate() {
        let recs = read_at(records, chunk)?;
        let work = pool.install(|| {
            recs.par_iter()
                .enumerate()
                .map(|(k, rec)| build_design(task, plan, c * 256 + k + 1, rec, opts.sweep))
                .collect::<Result<Vec<_>, _>>()
        })?;
        // Listed before they are written, so a kill leaves nothing unlisted.
        let mut files: Vec<PathBuf> = work
            .iter()
            .map(|w| out_dir.path(&format!("designs/{}.json", w.id)))
            .collect();
        if opts.export {
            let dirs: Vec<String> = work.iter().map(|w| format!("designs/{}", w.id)).collect();
            for (w, dir) in work.iter().zip(out_dir.create_dirs(&dirs)?) {
                files.extend(export::planned_files(&dir, &w.pattern, &w.options).all());
            }
        }
        out_dir.register(&files)?;
        let written = pool.install(|| {
            work.into_par_iter()
                .map(|w| write_design(w, opts.export, out_dir, progress))
                .collect::<Result<Vec<_>, _>>()
        })?;
        cards.extend(written);
    }
    Ok(cards)
}

/// One design, built and ready to write.
struct DesignWork {
    id: String,
    rec: AlternativeRecord,
    threshold: f64,
    /// `designs/<id>.json`.
    doc: String,
    pattern: Pattern,
    meta: DesignMeta,
    options: ExportOptions,
    /// The thick panels for the report's view and bill (`[fabrication]` only).
    thick: Option<serde_json::Value>,
}

/// Rebuild the design of `rec` (ranked `rank`, from 1) and its `designs/<id>.json`
/// (`sweep`: the search's dense sweep, on which a thick design's folds were measured).
fn build_design(
    task: &Task,
    plan: &Plan,
    rank: usize,
    rec: &AlternativeRecord,
    sweep: usize,
) -> Result<DesignWork, SearchError> {
    let (model, free, full, modes) = design_of(task, &plan.graph(task, rec.graph), rec)?;
    let design = Evaluated::new(&model.plan, full.clone(), modes);
    let thick = thick_of(task, &model, &design, rec, sweep)?;
    let pattern = design.pattern(&sample_times(model.t_max, 33));
    let meta = design_meta(task, &model, rec);
    let all_vars: BTreeMap<String, f64> = model
        .plan
        .variables
        .iter()
        .zip(&full)
        .map(|(v, x)| (v.name.clone(), *x))
        .collect();
    let constraints: Vec<_> = {
        let (_, g) = crate::model::compiled::outputs_f64(&model, &free, &design.modes);
        g.iter()
            .enumerate()
            .map(|(k, v)| json!({"label": model.constraint_label(k), "value": v}))
            .collect()
    };
    let id = rec.id();
    let doc = json!({
        "id": id,
        "task": task.name,
        "sequence": rec.sequence,
        "level": rec.level,
        "candidate": rec.candidate,
        "gripping_vertex": rec.gripping_vertex,
        "modes": rec.modes,
        "objective": rec.objective,
        "threshold": model.threshold,
        "variables": rec.variables,
        "all_variables": all_vars,
        "constraint_slack": rec.min_slack,
        "constraints": constraints,
        "verification": rec.verification,
        "self_intersection_free": rec.self_intersection_free,
        "obstacle_free": rec.obstacle_free,
        "robustness": rec.robustness,
        "requirements": rec.requirements,
        "fabrication": thick.as_ref().map(|t| &t.doc),
        "rank": rank,
        "pattern": pattern,
        "meta": meta,
        "svg": export::svg::svg_scale(&pattern, &Default::default()).ok(),
    });
    Ok(DesignWork {
        rec: rec.clone(),
        threshold: model.threshold,
        doc: serde_json::to_string_pretty(&doc).unwrap_or_default(),
        options: ExportOptions {
            name: id.clone(),
            ..Default::default()
        },
        thick: thick
            .as_ref()
            .map(|t| crate::export::report::thick_json(&pattern, &t.design)),
        id,
        pattern,
        meta,
    })
}

/// Write a design's `designs/<id>.json` and, with `export`, its files (the FOLD file
/// verified); its card for the report.
fn write_design(
    w: DesignWork,
    export: bool,
    out_dir: &OutputDir,
    progress: &Progress,
) -> Result<ReportDesign, SearchError> {
    let id = &w.id;
    let path = out_dir.path(&format!("designs/{id}.json"));
    std::fs::write(&path, &w.doc).map_err(|source| SearchError::Io {
        path: path.display().to_string(),
        source,
    })?;
    if !export {
        progress.inc(1);
        let mut card = report_design(&w.rec, w.threshold, w.pattern, w.meta, path, None, None);
        card.thick = w.thick;
        return Ok(card);
    }
    let out = out_dir.path(&format!("designs/{id}"));
    let files = export::write_all(&out, &w.pattern, &w.meta, &w.options)
        .map_err(|e| SearchError::Export(e.to_string()))?;
    let check = export::verify::verify_file(&files.fold, &Default::default())
        .map_err(|e| SearchError::Export(e.to_string()))?;
    if !check.ok {
        eprintln!("BUG: the exported FOLD file of {id} fails verification");
    }
    progress.inc(1);
    let mut card = report_design(
        &w.rec,
        w.threshold,
        w.pattern,
        w.meta,
        path,
        Some(files),
        Some(check),
    );
    card.thick = w.thick;
    Ok(card)
}

/// A design's thick panels (issue 32): the bill, the hinge axes and the check, for the
/// design JSON and the report.
pub(crate) struct ThickOf {
    /// `"fabrication"` of `designs/<id>.json`: `bill`, `hinges`, `check`.
    pub doc: serde_json::Value,
    /// The panels, built on the checked pattern (the arm with its copies).
    pub design: crate::fabricate::ThickDesign,
}

/// The thick panels of a kept design, rebuilt as the search built them (the same sweep,
/// the same folds), `None` without `[fabrication]`.
fn thick_of(
    task: &Task,
    model: &Model,
    design: &Evaluated<'_>,
    rec: &AlternativeRecord,
    sweep: usize,
) -> Result<Option<ThickOf>, SearchError> {
    let Some(spec) = &task.fabrication else {
        return Ok(None);
    };
    let times = judged_times(task, model.t_max, sweep);
    let arm = design.pattern(&times);
    let pat = checked_pattern(task, &arm).map_err(SearchError::Export)?;
    let built = thick_design(spec, &pat).map_err(|e| SearchError::Export(e.to_string()))?;
    let hinges: Vec<_> = built
        .hinges
        .iter()
        .map(|h| {
            json!({
                "edge": h.edge,
                "vertices": h.vertices,
                "facets": h.facets,
                "axis": h.axis,
                "setback": h.setback,
            })
        })
        .collect();
    let doc = json!({
        "bill": built.bill(),
        "hinges": hinges,
        "check": rec.fabrication,
    });
    Ok(Some(ThickOf { doc, design: built }))
}

/// The model of a record's graph and candidate, and the record's free variables, all
/// variables and mode signs.
type Design = (Model, Vec<f64>, Vec<f64>, Vec<f64>);

/// Rebuild a recorded design ([`Design`]).
fn design_of(
    task: &Task,
    graph: &CreaseGraph,
    rec: &AlternativeRecord,
) -> Result<Design, SearchError> {
    let model = Model::new(graph, task, rec.candidate - 1)?;
    let free: Vec<f64> = model
        .free
        .iter()
        .map(|&i| {
            rec.variables
                .get(&model.plan.variables[i].name)
                .copied()
                .unwrap_or(model.var_bounds(i).0)
        })
        .collect();
    let full = model.full_vars(&free);
    let modes: Vec<f64> = rec
        .modes
        .iter()
        .map(|m| if m == "up" { 1.0 } else { -1.0 })
        .collect();
    Ok((model, free, full, modes))
}

/// The robustness of a recorded design measured again by `check::robustness` on a sweep of
/// `states` states (e.g. denser than the search's): `graph` is the record's graph (the
/// enumeration's meaningful graphs, in order, indexed by `rec.graph`).
pub fn remeasure(
    task: &Task,
    graph: &CreaseGraph,
    rec: &AlternativeRecord,
    states: usize,
) -> Result<RobustnessReport, String> {
    let (model, _, full, modes) = design_of(task, graph, rec).map_err(|e| e.to_string())?;
    let design = Evaluated::new(&model.plan, full, modes);
    let arm = design.pattern(&sample_times(model.t_max, states.max(2)));
    let pat = checked_pattern(task, &arm)?;
    measure_robustness(task, &model, &arm, &pat)
}

/// The export metadata of a design.
fn design_meta(task: &Task, model: &Model, rec: &AlternativeRecord) -> DesignMeta {
    let mut meta = model_meta(task, model, &rec.modes, rec.objective);
    meta.extra
        .insert("candidate".to_string(), json!(rec.candidate));
    meta.extra.insert("key".to_string(), json!(rec.key));
    meta
}

/// The export metadata of a design of `model` with `modes` ("up"/"down") and objective
/// Ω* (also for designs outside a search, e.g. `foldsynth model --save`).
pub fn model_meta(task: &Task, model: &Model, modes: &[String], objective: f64) -> DesignMeta {
    let multi = model.targets.len() > 1;
    DesignMeta {
        task: task.name.clone(),
        rule_sequence: model.plan.sequence.clone(),
        modes: modes
            .iter()
            .map(|m| {
                if m == "up" {
                    export::Mode::Up
                } else {
                    export::Mode::Down
                }
            })
            .collect(),
        // The vertex name (1-based), as in the rule sequence and the record.
        gripping_vertex: Some(model.plan.vertices[model.gripping].name),
        objective: Some(objective),
        // The thesis's markers: point targets of the tip (other goals have no point).
        targets: model
            .targets
            .iter()
            .filter_map(|t| {
                t.tip_point()
                    .map(|p| export::TargetPoint { p, t: Some(t.t) })
            })
            .collect(),
        trajectory: if multi {
            model.targets.iter().filter_map(|t| t.tip_point()).collect()
        } else {
            Vec::new()
        },
        scene: task.scene.clone(),
        goals: task
            .objective
            .as_ref()
            .map(|o| o.targets.clone())
            .unwrap_or_default(),
        surfaces: task
            .objective
            .as_ref()
            .map(|o| o.surfaces.clone())
            .unwrap_or_default(),
        extra: BTreeMap::new(),
    }
}
