//! `merge`: shard directories → the run a single machine would have written.
//!
//! Everything is checked before anything is written: every directory is a shard
//! (`settings.json` with a `shard`), all of one search (the same task file, N_max, starts,
//! seed, sweep and foldsynth version), every shard 1 … N given once, each shard's task
//! file the one its settings name, and each shard complete — every alternative of its
//! units on record exactly once (the alternatives of a model its `shard.json` lists as
//! failed excepted: a single run has no records for most of them either). An incomplete
//! shard is named with the alternatives it lacks and the command that resumes it. Then the
//! records are copied into one `alternatives.jsonl` and summarized, and the designs,
//! exports and report are written by the same code as a single run's.

use std::collections::{BTreeMap, HashSet};
use std::fs::File;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::DistributeError;
use super::shard::{deal, searched};
use crate::grammar::Rules;
use crate::search::output::{OutputDir, RECORDS, RunSettings, SETTINGS, ShardSpec};
use crate::search::plan::Done;
use crate::search::{
    self, AlternativeRecord, Evaluation, FailedModel, Plan, SHARD_REPORT, SHARD_TASK,
    SearchOptions, ShardReport, Summary,
};
use crate::task::Task;
use crate::task::digest;

/// How many missing alternatives an error names per shard.
const MISSING_SHOWN: usize = 5;

/// Settings of a merge that are not the search's own (those come from the shards).
#[derive(Clone, Debug)]
pub struct MergeOptions {
    /// Output directory of the merged run.
    pub out: PathBuf,
    /// Replace a run of other settings there (see `synthesize --force`).
    pub force: bool,
    /// Worker threads for the designs and exports (0: one per core).
    pub jobs: usize,
    /// Write FOLD/SVG/OBJ/STL/pictures/GIF (the design JSONs and the report are written
    /// either way).
    pub export: bool,
    /// With `export`, of only this many most robust designs (`None`: all).
    pub export_top: Option<usize>,
    /// How many most robust designs the report draws with their motion (`None`: all).
    pub report_motions: Option<usize>,
    /// How many most robust designs the report carries in full (`None`: all).
    pub report_designs: Option<usize>,
}

/// One shard directory, read.
struct ShardDir {
    dir: PathBuf,
    settings: RunSettings,
    spec: ShardSpec,
    report: Option<ShardReport>,
}

fn read_json(path: &Path, what: &str) -> Result<Option<serde_json::Value>, DistributeError> {
    match crate::limits::read_text(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(DistributeError::input(
            path,
            format!("cannot read {what}: {e}"),
        )),
        Ok(text) => serde_json::from_str(&text)
            .map(Some)
            .map_err(|e| DistributeError::input(path, format!("{what} is not valid JSON ({e})"))),
    }
}

fn read_shard(dir: &Path) -> Result<ShardDir, DistributeError> {
    match std::fs::metadata(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(DistributeError::input(
                dir,
                "no such shard directory (give the --out of each `synthesize --shard K/N` run)",
            ));
        }
        Err(e) => return Err(DistributeError::input(dir, e.to_string())),
        Ok(m) if !m.is_dir() => {
            return Err(DistributeError::input(dir, "is not a directory"));
        }
        Ok(_) => {}
    }
    let path = dir.join(SETTINGS);
    let value = read_json(&path, "the settings")?.ok_or_else(|| {
        DistributeError::input(
            dir,
            format!("not a shard: it has no {SETTINGS} (was `synthesize --shard K/N` run there?)"),
        )
    })?;
    let settings: RunSettings = serde_json::from_value(value).map_err(|e| {
        DistributeError::input(&path, format!("not the settings of a foldsynth run ({e})"))
    })?;
    let spec = settings.shard.ok_or_else(|| {
        DistributeError::input(
            dir,
            "holds a whole run, not a shard (its settings name no shard); merge takes the directories of `synthesize --shard K/N` runs",
        )
    })?;
    let report_path = dir.join(SHARD_REPORT);
    let report = match read_json(&report_path, "the shard report")? {
        None => None,
        Some(v) => Some(serde_json::from_value(v).map_err(|e| {
            DistributeError::input(&report_path, format!("not a shard report ({e})"))
        })?),
    };
    Ok(ShardDir {
        dir: dir.to_path_buf(),
        settings,
        spec,
        report,
    })
}

/// Check that the shards are one search, shards 1 … N each given once.
fn check_one_search(shards: &[ShardDir]) -> Result<(), DistributeError> {
    let first = &shards[0];
    let fields = |s: &RunSettings| -> BTreeMap<String, serde_json::Value> {
        let mut v = serde_json::to_value(s).unwrap_or_default();
        if let Some(m) = v.as_object_mut() {
            m.remove("shard");
        }
        serde_json::from_value(v).unwrap_or_default()
    };
    let base = fields(&first.settings);
    for s in &shards[1..] {
        let other = fields(&s.settings);
        let differ: Vec<String> = base
            .keys()
            .chain(other.keys())
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .filter(|k| base.get(*k) != other.get(*k))
            .map(|k| {
                let show = |v: Option<&serde_json::Value>| {
                    v.map_or("(absent)".into(), |v| {
                        crate::text::excerpt(&v.to_string(), 80)
                    })
                };
                format!(
                    "{k}: {} in {}, {} in {}",
                    show(base.get(k)),
                    first.dir.display(),
                    show(other.get(k)),
                    s.dir.display()
                )
            })
            .collect();
        if !differ.is_empty() {
            return Err(DistributeError::input(
                &s.dir,
                format!(
                    "a shard of another search than {} ({}); merge takes the shards of one search",
                    first.dir.display(),
                    differ.join("; ")
                ),
            ));
        }
    }
    let count = first.spec.count;
    let mut by_index: BTreeMap<usize, &Path> = BTreeMap::new();
    for s in shards {
        if s.spec.count != count {
            return Err(DistributeError::input(
                &s.dir,
                format!(
                    "shard {} of a split into {} shards, but {} is shard {} ({} shards): the shards of one split are merged",
                    s.spec,
                    s.spec.count,
                    first.dir.display(),
                    first.spec,
                    count
                ),
            ));
        }
        if let Some(other) = by_index.insert(s.spec.index, &s.dir) {
            return Err(DistributeError::input(
                &s.dir,
                format!("shard {} is given twice (also {})", s.spec, other.display()),
            ));
        }
    }
    let missing: Vec<String> = (1..=count)
        .filter(|k| !by_index.contains_key(k))
        .map(|k| format!("{k}/{count}"))
        .collect();
    if !missing.is_empty() {
        return Err(DistributeError::input(
            &first.dir,
            format!(
                "shards {} of this search are not given ({} of {count} given); merge needs the directory of every shard",
                crate::text::excerpt(&missing.join(", "), 300),
                shards.len()
            ),
        ));
    }
    Ok(())
}

/// The task the shards ran, from their `task.toml` (each must be the file their
/// settings' digest names).
fn read_task(shards: &[ShardDir]) -> Result<(Task, String), DistributeError> {
    let mut found: Option<(Task, String)> = None;
    for s in shards {
        let path = s.dir.join(SHARD_TASK);
        let text = crate::limits::read_text(&path).map_err(|e| {
            DistributeError::input(
                &path,
                format!("cannot read the shard's task file ({e}); a shard keeps the task it ran"),
            )
        })?;
        if digest(text.as_bytes()) != s.settings.task_digest {
            return Err(DistributeError::input(
                &path,
                "is not the task file this shard ran (its digest differs from settings.json's task_digest)",
            ));
        }
        if found.is_none() {
            let label = path.display().to_string();
            let mut task = Task::from_toml_str(&text, &label)
                .map_err(|e| DistributeError::input(&path, e.to_string()))?;
            if task.name.is_empty() {
                task.name = s.settings.task.clone();
            }
            if task.name != s.settings.task {
                return Err(DistributeError::input(
                    &path,
                    format!(
                        "names task '{}', but the shard's settings say '{}'",
                        task.name, s.settings.task
                    ),
                ));
            }
            task.source = Some(path.clone());
            found = Some((task, text));
        }
    }
    Ok(found.expect("at least one shard"))
}

/// Check one shard's records against its units; the lines to copy are read again later.
/// Returns the number of records.
fn check_records(
    plan: &Plan,
    s: &ShardDir,
    mine: &[bool],
    done: &mut Done,
) -> Result<usize, DistributeError> {
    let path = s.dir.join(RECORDS);
    let file = match File::open(&path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(0),
        r => r.map_err(|e| DistributeError::input(&path, e.to_string()))?,
    };
    let mut reader = BufReader::new(file);
    let mut buf = Vec::new();
    let mut line = 0usize;
    let mut records = 0;
    loop {
        buf.clear();
        let n = reader
            .read_until(b'\n', &mut buf)
            .map_err(|e| DistributeError::input(&path, e.to_string()))?;
        if n == 0 {
            break;
        }
        line += 1;
        let at = |why: String| DistributeError::input(&path, format!("line {line}: {why}"));
        if !buf.ends_with(b"\n") {
            // Torn by a kill: its alternative counts as missing (resuming redoes it).
            break;
        }
        let text = std::str::from_utf8(&buf).map_err(|_| at("not UTF-8 text".into()))?;
        if text.trim().is_empty() {
            continue;
        }
        let rec: AlternativeRecord = serde_json::from_str(text).map_err(|e| {
            at(format!(
                "not a record ({})",
                crate::text::excerpt(&e.to_string(), 200)
            ))
        })?;
        let place = plan.locate(&rec.key).ok_or_else(|| {
            at(format!(
                "alternative {} is not part of this search",
                crate::text::excerpt(&rec.key, 200)
            ))
        })?;
        if !mine[place.unit] {
            return Err(at(format!(
                "alternative {} belongs to another shard than {}: the directory's records are not this shard's",
                rec.key, s.spec
            )));
        }
        if !done.insert(place.index) {
            return Err(at(format!("alternative {} appears twice", rec.key)));
        }
        records += 1;
    }
    Ok(records)
}

/// Merge the shard directories `dirs` into `opts.out`.
pub fn merge(dirs: &[PathBuf], opts: &MergeOptions) -> Result<Summary, DistributeError> {
    let start = Instant::now();
    let shards = read_shards(dirs, &opts.out)?;
    let (task, _) = read_task(&shards)?;
    let guided = shards[0].settings.guided;
    let settings = RunSettings {
        shard: None,
        guided: None,
        ..shards[0].settings.clone()
    };
    let mut search_opts = search_options(&settings, &shards[0], opts)?;
    if let Some(selection) = guided {
        search_opts.strategy = search::Strategy::Guided;
        search_opts.budget.alternatives = selection.alternatives;
    }
    let n_max = search::check_search(&task, &search_opts)?;
    let plan = search::plan(&task, n_max, search_opts.rules, &search_opts.graphs)?;
    let deal = deal(&plan, &searched(&plan, guided), shards[0].spec.count);
    // Every shard complete, every record in its place, before anything is written.
    let (failed, compile_s) = check_complete(&plan, &shards, &deal, &settings)?;

    let (out, _) = search::open_output(&settings, &search_opts)?;
    copy_records(&shards, &out)?;
    let ev = Evaluation {
        compile_s,
        jobs: rayon::ThreadPoolBuilder::new()
            .num_threads(opts.jobs)
            .build()
            .map_or(1, |p| p.current_num_threads()),
        resumed: 0,
        resume: None,
        failed,
    };
    Ok(search::finish(
        &task,
        &plan,
        &out,
        &search_opts,
        &ev,
        start,
        &search::Progress::new(search_opts.progress),
    )?)
}

/// The shard directories `dirs`, read and checked to be one search (shards 1 … N each
/// given once), in shard order; none of them the merged run's directory `out`.
fn read_shards(dirs: &[PathBuf], out: &Path) -> Result<Vec<ShardDir>, DistributeError> {
    if dirs.is_empty() {
        return Err(DistributeError::input(
            "merge",
            "no shard directories given",
        ));
    }
    let mut shards = dirs
        .iter()
        .map(|d| read_shard(d))
        .collect::<Result<Vec<_>, _>>()?;
    check_one_search(&shards)?;
    shards.sort_by_key(|s| s.spec.index);
    // The merged run must not replace a shard it reads.
    if let Ok(canonical) = std::fs::canonicalize(out) {
        for s in &shards {
            if std::fs::canonicalize(&s.dir).is_ok_and(|d| d == canonical) {
                return Err(DistributeError::input(
                    out,
                    format!(
                        "is shard {}'s own directory; give the merged run a directory of its own",
                        s.spec
                    ),
                ));
            }
        }
    }
    Ok(shards)
}

/// The search's options for the merged run: the shards' `settings` (read from `first`),
/// the merge's own `opts`.
fn search_options(
    settings: &RunSettings,
    first: &ShardDir,
    opts: &MergeOptions,
) -> Result<SearchOptions, DistributeError> {
    let rules = match &settings.rules {
        None => Rules::default(),
        Some(names) => Rules::parse(names)
            .map_err(|m| DistributeError::input(first.dir.join(SETTINGS), format!("rules: {m}")))?,
    };
    Ok(SearchOptions {
        out: opts.out.clone(),
        jobs: opts.jobs,
        starts: settings.starts,
        seed: settings.seed,
        resume: false,
        force: opts.force,
        n_max: Some(settings.n_max),
        sweep: settings.sweep,
        export: opts.export,
        export_top: opts.export_top,
        report_motions: opts.report_motions,
        report_designs: opts.report_designs,
        progress: false,
        rules,
        post_check_only: settings.post_check_only,
        strategy: search::Strategy::Exhaustive,
        budget: search::Budget::default(),
        warm_starts: false,
        on_progress: None,
        graphs: settings.graphs.clone(),
    })
}

/// Check that every shard holds every alternative of its units (`deal`) once, the
/// alternatives of its failed models excepted; an error names each incomplete shard with
/// what it lacks and the command that resumes it. The failed models of all shards and
/// their compile seconds.
fn check_complete(
    plan: &Plan,
    shards: &[ShardDir],
    deal: &[Vec<usize>],
    settings: &RunSettings,
) -> Result<(Vec<FailedModel>, f64), DistributeError> {
    let mut done = Done::new(plan.alternatives);
    let mut incomplete = Vec::new();
    let mut failed: Vec<FailedModel> = Vec::new();
    let mut compile_s = 0.0;
    for s in shards {
        let units = &deal[s.spec.index - 1];
        let mut mine = vec![false; plan.units.len()];
        for &u in units {
            mine[u] = true;
        }
        check_records(plan, s, &mine, &mut done)?;
        let (missing, shown) = missing_alternatives(plan, s, units, &done);
        if missing > 0 {
            incomplete.push(format!(
                "shard {} ({}) lacks {missing} of its {} alternatives, e.g. {}{}; resume just that shard: foldsynth synthesize {} --shard {} --n-max {} --starts {} --seed {} --sweep {} --resume --out {}",
                s.spec,
                s.dir.display(),
                units.iter().map(|&u| plan.units[u].count).sum::<u64>(),
                shown.join("; "),
                if missing > shown.len() as u64 { "; …" } else { "" },
                s.dir.join(SHARD_TASK).display(),
                s.spec,
                settings.n_max,
                settings.starts,
                settings.seed,
                settings.sweep,
                s.dir.display()
            ));
        }
        if let Some(r) = &s.report {
            failed.extend(r.failed_models.iter().cloned());
            compile_s += r.timings.compile_s;
        }
    }
    if !incomplete.is_empty() {
        return Err(DistributeError::input(
            "merge",
            format!(
                "{} of {} shards are incomplete, nothing was merged:\n  {}",
                incomplete.len(),
                shards.len(),
                incomplete.join("\n  ")
            ),
        ));
    }
    Ok((failed, compile_s))
}

/// How many alternatives of shard `s`'s `units` are not `done` (those of the models its
/// report lists as failed excepted), and the keys of the first [`MISSING_SHOWN`].
fn missing_alternatives(
    plan: &Plan,
    s: &ShardDir,
    units: &[usize],
    done: &Done,
) -> (u64, Vec<String>) {
    let failed_here: HashSet<(String, usize)> = s
        .report
        .iter()
        .flat_map(|r| &r.failed_models)
        .map(|f| (f.sequence.clone(), f.candidate))
        .collect();
    let mut missing = 0u64;
    let mut shown = Vec::new();
    for &u in units {
        let unit = &plan.units[u];
        let key = (plan.graphs[unit.graph].sequence.clone(), unit.candidate + 1);
        if failed_here.contains(&key) {
            continue;
        }
        for m in 0..unit.count {
            if !done.contains(unit.first + m) {
                missing += 1;
                if shown.len() < MISSING_SHOWN {
                    shown.push(plan.alternative(u, m as u32).key());
                }
            }
        }
    }
    (missing, shown)
}

/// Copy the shards' records, in shard order, into the merged run's records file (torn
/// last lines and blank lines left out).
fn copy_records(shards: &[ShardDir], out: &OutputDir) -> Result<(), DistributeError> {
    let (path, file) = out.create(RECORDS)?;
    let mut w = std::io::BufWriter::new(file);
    let werr = |e: std::io::Error| DistributeError::input(&path, e.to_string());
    for s in shards {
        let from = s.dir.join(RECORDS);
        let Ok(file) = File::open(&from) else {
            continue;
        };
        let mut reader = BufReader::new(file);
        let mut buf = Vec::new();
        loop {
            buf.clear();
            let n = reader
                .read_until(b'\n', &mut buf)
                .map_err(|e| DistributeError::input(&from, e.to_string()))?;
            if n == 0 || !buf.ends_with(b"\n") {
                break;
            }
            if !buf.iter().all(u8::is_ascii_whitespace) {
                w.write_all(&buf).map_err(werr)?;
            }
        }
    }
    w.flush().map_err(werr)?;
    Ok(())
}
