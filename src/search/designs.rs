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
use super::report::{report_design, row_design};
use crate::check::robustness::RobustnessReport;
use crate::export::fabrication_files::{self, Laid};
use crate::export::report::{Fact, ReportDesign};
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
    let what = |rank: usize| files_of(opts, rank);
    progress.phase(
        match what(1) {
            Written::All => "write designs and their files",
            Written::Fold => "write designs and their FOLD files",
            Written::None => "write design JSONs",
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
                .map(|(k, rec)| {
                    let rank = c * 256 + k + 1;
                    let with_files = what(rank) == Written::All;
                    build_design(task, plan, rank, rec, opts.sweep, with_files)
                })
                .collect::<Result<Vec<_>, _>>()
        })?;
        // Listed before they are written, so a kill leaves nothing unlisted: every
        // design's JSON and (with export) its FOLD file beside it; the most robust also
        // their directory of files, as `foldsynth export --format all` writes it.
        let mut files: Vec<PathBuf> = Vec::new();
        for w in &work {
            files.push(out_dir.path(&format!("designs/{}.json", w.id)));
            if what(w.rank) != Written::None {
                files.push(out_dir.path(&format!("designs/{}.fold", w.id)));
            }
        }
        let with_dir: Vec<&DesignWork> = work
            .iter()
            .filter(|w| what(w.rank) == Written::All)
            .collect();
        let dirs: Vec<String> = with_dir
            .iter()
            .map(|w| format!("designs/{}", w.id))
            .collect();
        for (w, dir) in with_dir.into_iter().zip(out_dir.create_dirs(&dirs)?) {
            files.extend(export::planned_files(&dir, &w.pattern, &w.meta, &w.options).all());
            if let Some(fab) = &w.fab {
                files.extend(fabrication_files::planned(&dir, &fab.design, &STATES));
            }
        }
        out_dir.register(&files)?;
        let written = pool.install(|| {
            work.into_par_iter()
                .map(|w| {
                    let files = what(w.rank);
                    let in_full = opts.report_designs.is_none_or(|n| w.rank <= n);
                    let shown = Shown {
                        in_full,
                        motion: opts.report_motions,
                    };
                    let mut card = write_design(w, files, shown, out_dir, progress)?;
                    if in_full && files == Written::Fold {
                        card.facts.push(files_on_demand(&card.id, out_dir, opts));
                    }
                    Ok::<_, SearchError>(card)
                })
                .collect::<Result<Vec<_>, _>>()
        })?;
        cards.extend(written);
    }
    Ok(cards)
}

/// Which of its files a design gets besides its JSON.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Written {
    /// None (`--no-export`).
    None,
    /// Its FOLD file of the crease pattern and folded form, `designs/<id>.fold` (a design
    /// outside `--export N`'s most robust).
    Fold,
    /// That, and every file of `foldsynth export --format all` in `designs/<id>/` (FOLD
    /// with the motion, SVG, meshes, pictures, GIF).
    All,
}

/// The files of the design ranked `rank` (from 1, the most robust) with `opts`.
fn files_of(opts: &SearchOptions, rank: usize) -> Written {
    if !opts.export {
        Written::None
    } else if opts.export_top.is_none_or(|n| rank <= n) {
        Written::All
    } else {
        Written::Fold
    }
}

/// One design, built and ready to write.
struct DesignWork {
    id: String,
    /// 1: the most robust.
    rank: usize,
    rec: AlternativeRecord,
    threshold: f64,
    /// `designs/<id>.json`.
    doc: String,
    pattern: Pattern,
    meta: DesignMeta,
    options: ExportOptions,
    /// The thick panels for the report's view and bill (`[fabrication]` only).
    thick: Option<serde_json::Value>,
    /// The thick design's files to write (`[fabrication]`, designs with their folder).
    fab: Option<FabWork>,
}

/// The states of a searched thick design's assemblies: flat, the middle of the dense
/// sweep, its last state.
const STATES: [&str; 3] = ["flat", "half", "folded"];

/// A thick design's files to write into its folder: the panels, built on the checked
/// pattern (the arm with its copies, on the search's dense sweep), their plies laid out.
struct FabWork {
    pattern: Pattern,
    design: crate::fabricate::ThickDesign,
    laid: Laid,
}

/// Rebuild the design of `rec` (ranked `rank`, from 1) and its `designs/<id>.json`
/// (`sweep`: the search's dense sweep, on which a thick design's folds were measured;
/// `with_files`: it gets its folder, and a thick design its fabrication files there).
fn build_design(
    task: &Task,
    plan: &Plan,
    rank: usize,
    rec: &AlternativeRecord,
    sweep: usize,
    with_files: bool,
) -> Result<DesignWork, SearchError> {
    let (model, free, full, modes) = design_of(task, &plan.graph(task, rec.graph), rec)?;
    let design = Evaluated::new(&model.plan, full.clone(), modes);
    let mut thick = thick_of(task, &model, &design, rec, sweep)?;
    let id = rec.id();
    let fab = match thick.as_mut().filter(|_| with_files) {
        Some(t) => Some(fab_work(task, &id, t)?),
        None => None,
    };
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
            // Ten digits, as the motion's positions: informative, not read back.
            .map(|(k, v)| {
                json!({"label": model.constraint_label(k), "value": export::motion::round_sig(*v)})
            })
            .collect()
    };
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
        "cycle": rec.cycle,
        "simulation": rec.simulation,
        "fabrication": thick.as_ref().map(|t| &t.doc),
        "rank": rank,
        // The motion once: positions to ten digits, fold angles read back (issue 35).
        "pattern": export::motion::pattern_json(&pattern),
        "meta": meta,
        "svg": export::svg::svg_scale(&pattern, &Default::default()).ok(),
    });
    Ok(DesignWork {
        rec: rec.clone(),
        threshold: model.threshold,
        // Compact: 700 gripper designs' JSONs are 22 MB so, 44 MB pretty-printed (issue 35);
        // the report is where people read a design, `jq .` prints one.
        doc: serde_json::to_string(&doc).unwrap_or_default() + "\n",
        options: ExportOptions {
            name: id.clone(),
            // A task with [fabrication] prints at its scale, the paper model of its panels.
            print: Some(export::sheet::SheetOptions {
                scale: task
                    .fabrication
                    .as_ref()
                    .map_or(export::sheet::PrintScale::Fit, |f| {
                        export::sheet::PrintScale::MmPerUnit(f.scale)
                    }),
                ..Default::default()
            }),
            ..Default::default()
        },
        thick: thick
            .as_ref()
            .map(|t| crate::export::report::thick_json(&pattern, &t.design)),
        fab,
        id,
        rank,
        pattern,
        meta,
    })
}

/// A thick design's files for its folder `designs/<id>/`: its plies laid out with the
/// task's laminate (a refusal names the `[fabrication]` field and the design), and the
/// files listed in the design JSON's `fabrication.files` (relative to `designs/`).
fn fab_work(task: &Task, id: &str, t: &mut ThickOf) -> Result<FabWork, SearchError> {
    let laid = fabrication_files::lay_out(&t.pattern, &t.design, &task.laminate).map_err(
        |(field, m)| {
            SearchError::Export(format!(
                "design {id}: [fabrication] {field}: {m} (the task's fabrication.{field})"
            ))
        },
    )?;
    let files: Vec<String> = fabrication_files::planned(Path::new(id), &t.design, &STATES)
        .iter()
        .map(|p| p.display().to_string().replace('\\', "/"))
        .collect();
    t.doc["files"] = json!(files);
    Ok(FabWork {
        pattern: t.pattern.clone(),
        design: t.design.clone(),
        laid,
    })
}

/// The report's line for a design outside `--export N`'s most robust (only its FOLD file
/// written): the command that writes the rest.
fn files_on_demand(id: &str, out_dir: &OutputDir, opts: &SearchOptions) -> Fact {
    let n = opts.export_top.unwrap_or_default();
    Fact::new(
        "files",
        format!(
            "the FOLD file (crease pattern, folded form); the rest, as for the {n} most robust: foldsynth export {} --format all --out {}",
            shell_word(&out_dir.path(&format!("designs/{id}.json"))),
            shell_word(&out_dir.path(&format!("designs/{id}"))),
        ),
    )
}

/// `path` as one word of a POSIX shell command (quoted when it needs to be).
fn shell_word(path: &Path) -> String {
    let s = path.display().to_string();
    let plain = s
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || "-_./+=:,@".contains(c));
    if plain && !s.is_empty() {
        s
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// How the report shows a design.
#[derive(Clone, Copy)]
struct Shown {
    /// In full (`--report-designs N`), or a row of its table only.
    in_full: bool,
    /// `--report-motions N`: the motion of the N most robust (`None`: of all).
    motion: Option<usize>,
}

/// Write a design's `designs/<id>.json` and its `files` (the FOLD file verified); its
/// card for the report (its row only, without geometry, outside `--report-designs N`).
fn write_design(
    w: DesignWork,
    files: Written,
    shown: Shown,
    out_dir: &OutputDir,
    progress: &Progress,
) -> Result<ReportDesign, SearchError> {
    let id = &w.id;
    let path = out_dir.path(&format!("designs/{id}.json"));
    std::fs::write(&path, &w.doc).map_err(|source| SearchError::Io {
        path: path.display().to_string(),
        source,
    })?;
    let err = |e: export::ExportError| SearchError::Export(e.to_string());
    let verified = |fold: &Path| {
        let check = export::verify::verify_file(fold, &Default::default())
            .map_err(|e| SearchError::Export(e.to_string()))?;
        if !check.ok {
            eprintln!(
                "BUG: the exported FOLD file {} fails verification",
                fold.display()
            );
        }
        Ok::<_, SearchError>(check)
    };
    let (written, check) = if files == Written::None {
        (None, None)
    } else {
        // `designs/<id>.fold`: the crease pattern and its folded form (the last frame),
        // what Origami Simulator and the FOLD tools open; the motion is the design JSON's
        // (issue 35: it was written twice per design), and `foldsynth export` makes FOLD
        // frames of it, as it does below for the most robust.
        let fold = out_dir.path(&format!("designs/{id}.fold"));
        let meta = export::with_meshes(&w.meta).map_err(err)?;
        let text =
            export::fold::to_fold_string(&w.pattern.folded_form(), &meta, w.options.fold_spec)
                .map_err(err)?;
        std::fs::write(&fold, text).map_err(|source| SearchError::Io {
            path: fold.display().to_string(),
            source,
        })?;
        let check = verified(&fold)?;
        if files == Written::All {
            let out = out_dir.path(&format!("designs/{id}"));
            let all = export::write_all(&out, &w.pattern, &w.meta, &w.options).map_err(err)?;
            let check = verified(&all.fold)?;
            if let Some(fab) = &w.fab {
                // The design JSON as the run's folder names it (the same on every machine).
                let json = Path::new("designs").join(format!("{id}.json"));
                write_fab(&out, &json, fab, &w.rec).map_err(err)?;
            }
            (Some(all), Some(check))
        } else {
            // The other paths stay empty (the report links only what exists).
            let f = export::Files {
                fold,
                ..Default::default()
            };
            (Some(f), Some(check))
        }
    };
    progress.inc(1);
    if !shown.in_full {
        return Ok(row_design(&w.rec, w.meta, path));
    }
    // Outside the `REPORT_MOTIONS` most robust, the page draws the folded form alone.
    let report_motions = shown.motion;
    let motion = report_motions.is_none_or(|n| w.rank <= n);
    let drawn = if motion {
        w.pattern
    } else {
        w.pattern.folded_form()
    };
    let mut card = report_design(&w.rec, w.threshold, drawn, w.meta, path, written, check);
    if !motion {
        card.facts.push(Fact::new(
            "motion",
            format!(
                "its folded form (this page draws the motion of the {} most robust designs; --report-motions)",
                report_motions.unwrap_or_default()
            ),
        ));
    }
    card.thick = w.thick;
    Ok(card)
}

/// Write a thick design's files into its folder `out` (as `foldsynth fabricate` writes
/// them): `fabrication.json` records the design JSON (`json`, relative to the run's
/// folder), that the material is the task's, and
/// the search's thick check.
fn write_fab(
    out: &Path,
    json: &Path,
    fab: &FabWork,
    rec: &AlternativeRecord,
) -> export::Result<Vec<PathBuf>> {
    let frames = &fab.pattern.frames;
    let states: Vec<export::print::State<'_>> = STATES
        .iter()
        .map(|&s| {
            let frame = match s {
                "flat" => None,
                "half" => frames.get(frames.len() / 2),
                _ => frames.last(),
            };
            (s.to_string(), frame)
        })
        .collect();
    let mut record = serde_json::Map::new();
    record.insert("design".into(), json.display().to_string().into());
    record.insert("material_from".into(), "task".into());
    record.insert("check".into(), json!(rec.fabrication));
    fabrication_files::write(out, &fab.pattern, &fab.design, &states, &fab.laid, record)
}

/// A design's thick panels (issue 32): the bill, the hinge axes and the check, for the
/// design JSON and the report.
pub(crate) struct ThickOf {
    /// `"fabrication"` of `designs/<id>.json`: `bill`, `hinges`, `check`.
    pub doc: serde_json::Value,
    /// The panels, built on the checked pattern (the arm with its copies).
    pub design: crate::fabricate::ThickDesign,
    /// That pattern, on the search's dense sweep.
    pub pattern: Pattern,
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
        "laminate": task.laminate,
        "hinges": hinges,
        "check": rec.fabrication,
    });
    Ok(Some(ThickOf {
        doc,
        design: built,
        pattern: pat,
    }))
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
