//! `foldsynth simulate FILE [--steps J] [--json]`: the bar-and-hinge simulation of a
//! pattern file, a FOLD file or a design JSON, with a table of δ(j), Γ, θ and the verdict;
//! `foldsynth simulate --crossval DIR`: every design of a synthesis run simulated and
//! compared with the PTU.
//!
//! FILE is read by its extension: `.toml` is a pattern file (`grammar/*.toml`, drives in
//! the file); `.fold` a FOLD file and `.json` a design (`designs/<id>.json`, or any
//! `{"pattern": …}`). Those two are driven like the design tasks (SPEC §4, see
//! [`crate::simulate::crossval`]): the crease marked driven (`edges_foldsynth:driven`,
//! or `--driven`) is folded to ρ(t) mirror-symmetrically, or, where several marked
//! creases bound one facet (a driven central facet), that facet stays fixed and each
//! crease turns the facet across it; ρ is read from the frames (or `--angle`). Their
//! frames are the PTU's motion, so every simulated state that has a frame is compared
//! with it.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, bail};
use clap::Args;
use rayon::prelude::*;
use serde_json::json;

use crate::export::fold::FoldFile;
use crate::pattern::Pattern;
use crate::simulate::crossval::{
    self, CrossvalOptions, CrossvalReport, DrivenCrease, G0Drive, GAMMA_TOL, POSITION_TOL,
};
use crate::simulate::{Formula, PatternFile, RIGID_DELTA, SimReport, simulate};

/// Arguments of `foldsynth simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// A pattern file (.toml, see `grammar/flasher_adapted.toml`), a FOLD file (.fold) or a
    /// design JSON (.json, e.g. `OUT/designs/<id>.json` of `foldsynth synthesize`).
    #[arg(required_unless_present = "crossval")]
    pub file: Option<PathBuf>,
    /// Cross-validate every design of DIR (a `foldsynth synthesize` output directory, or
    /// a directory of design JSON files) against the PTU; fails unless all agree.
    #[arg(long, value_name = "DIR", conflicts_with = "file")]
    pub crossval: Option<PathBuf>,
    /// Number of folding steps J (default: the file's `motion.steps`; for FOLD/design files
    /// one step per frame after the first, or 30 without frames).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=crate::limits::STEPS_MAX))]
    pub steps: Option<u64>,
    /// FOLD/design: the driven crease, folded symmetrically (0-based edge index; default:
    /// the edges marked driven: one, or the sides of a central facet that stays fixed).
    #[arg(long, value_name = "EDGE")]
    pub driven: Option<usize>,
    /// FOLD/design: the driven creases' fold angle as a formula in t, valley positive,
    /// 0 at the start (default: read from the frames; "t" without frames).
    #[arg(long, value_name = "FORMULA", allow_hyphen_values = true)]
    pub angle: Option<String>,
    /// FOLD/design: end of the motion, a number or a formula without t (default: the
    /// last frame's t).
    #[arg(long, value_name = "T", allow_hyphen_values = true)]
    pub t_max: Option<String>,
    /// FOLD/design: skip the self-intersection check (θ is then reported as 0).
    #[arg(long)]
    pub no_intersections: bool,
    /// FOLD/design: Eq. 2's bars only, without the rigid-panel apexes on facets with more
    /// than three corners (those then bend at second order; see
    /// `simulate::crossval::add_panel_apexes`).
    #[arg(long)]
    pub eq2_bars: bool,
    /// Print the full report as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// What FILE is.
enum Kind {
    Toml,
    Fold,
    Design,
}

fn kind_of(path: &Path) -> Kind {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_lowercase)
    {
        Some(e) if e == "fold" => Kind::Fold,
        Some(e) if e == "json" => Kind::Design,
        _ => Kind::Toml,
    }
}

/// Run `foldsynth simulate`.
pub fn run(args: SimulateArgs) -> anyhow::Result<()> {
    if let Some(dir) = &args.crossval {
        return run_crossval(dir, &args);
    }
    let path = args
        .file
        .clone()
        .context("give a FILE to simulate, or --crossval DIR")?;
    match kind_of(&path) {
        Kind::Toml => {
            if args.driven.is_some() || args.angle.is_some() || args.t_max.is_some() {
                bail!(
                    "{}: --driven, --angle and --t-max are for FOLD and design files; a pattern file states its drives and motion itself",
                    path.display()
                );
            }
            run_toml(&path, &args)
        }
        Kind::Fold => {
            let fold = FoldFile::read(&path)?;
            let mut pattern = fold.to_pattern()?;
            let note = if fold.frames.len() > 1 && fold.frames[1..].iter().any(|f| f.t.is_none()) {
                // Without foldsynth:t the frames' t is unknown: they cannot be compared or
                // give the angle, so the drive comes from the flags alone.
                pattern.frames.clear();
                Some("the file's frames have no foldsynth:t: they are not compared".to_string())
            } else {
                None
            };
            run_pattern(&path, &path.display().to_string(), &pattern, note, &args)
        }
        Kind::Design => {
            let (name, pattern) = read_design(&path)?;
            run_pattern(&path, &name, &pattern, None, &args)
        }
    }
}

fn run_toml(path: &Path, args: &SimulateArgs) -> anyhow::Result<()> {
    let mut file = PatternFile::load(path)?;
    if let Some(j) = args.steps {
        file.input.steps = j as usize;
    }
    let start = Instant::now();
    let report = simulate(&file.input).with_context(|| {
        format!(
            "simulating {} (vertex numbers: {})",
            path.display(),
            legend(&file.vertex_names)
        )
    })?;
    let seconds = start.elapsed().as_secs_f64();
    if args.json {
        let out = json!({
            "name": file.name,
            "vertex_names": file.vertex_names,
            "steps": report.steps,
            "gamma": report.gamma,
            "theta": report.theta,
            "rigid": report.rigid,
            "max_delta": report.max_delta(),
            "rigid_delta_bound": RIGID_DELTA,
            "initial_intersections": report.initial_intersections,
            "final_positions": report.final_positions(),
            "states": report.states,
            "bars": report.bars,
            "free_vertices": report.free_vertices,
            "seconds": seconds,
        });
        emit(&(serde_json::to_string_pretty(&out)? + "\n"))
    } else {
        let mut o = String::new();
        let _ = writeln!(o, "{}", file.name);
        let _ = writeln!(
            o,
            "{} vertices ({} free), {} facets, {} bars, J = {}",
            file.vertex_names.len(),
            report.free_vertices,
            file.input.faces.len(),
            report.bars,
            report.steps.len()
        );
        steps_table(&mut o, &report, None);
        summary(&mut o, &report);
        positions(&mut o, &file.vertex_names, report.final_positions());
        let _ = writeln!(o, "time                {seconds:.3} s");
        emit(&o)
    }
}

fn legend(names: &[String]) -> String {
    names
        .iter()
        .enumerate()
        .map(|(i, n)| format!("{i}={n}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A design JSON: `{"pattern": <Pattern>, …}` (any other keys are ignored), or a bare
/// Pattern. Returns a display name (`id`, else the file name) and the pattern.
pub fn read_design(path: &Path) -> anyhow::Result<(String, Pattern)> {
    let text = crate::limits::read_text(path)
        .with_context(|| format!("{}: cannot read", path.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{}: not valid JSON", path.display()))?;
    let body = match v.get("pattern") {
        Some(p) => p.clone(),
        None if v.get("vertices").is_some() && v.get("faces").is_some() => v.clone(),
        None => bail!(
            "{}: not a design file: expected {{\"pattern\": {{vertices, edges, faces, frames}}, …}}",
            path.display()
        ),
    };
    let mut pattern: Pattern = serde_json::from_value(body).with_context(|| {
        format!(
            "{}: pattern: expected {{vertices, edges, faces, frames}} as foldsynth writes them",
            path.display()
        )
    })?;
    crate::export::read_pattern(&mut pattern).with_context(|| format!("{}", path.display()))?;
    let name = v
        .get("id")
        .and_then(|x| x.as_str())
        .map(str::to_string)
        .unwrap_or_else(|| path.display().to_string());
    Ok((name, pattern))
}

/// The G0 drive for a FOLD/design pattern from the flags and the pattern: `--driven EDGE`
/// folds that one crease symmetrically; otherwise every marked crease is driven (one, or
/// the sides of a central facet that stays fixed, [`G0Drive::of_creases`]). Each crease's
/// angle is `--angle`, else its frames', else t.
fn drive_for(pattern: &Pattern, args: &SimulateArgs) -> anyhow::Result<G0Drive> {
    let edges = match args.driven {
        Some(e) => vec![e],
        None => G0Drive::marked_edges(pattern)?,
    };
    let formula = match &args.angle {
        Some(src) => {
            let f = Formula::parse(src).map_err(|e| anyhow::anyhow!("--angle: {e}"))?;
            Some((f, src.clone()))
        }
        None => None,
    };
    let mut creases = Vec::with_capacity(edges.len());
    for edge in edges {
        let crease = match &formula {
            Some((f, src)) => {
                let f = f.clone();
                DrivenCrease {
                    edge,
                    source: src.clone(),
                    angle: Arc::new(move |t| f.eval(t)),
                }
            }
            None if pattern.frames.is_empty() => DrivenCrease {
                edge,
                source: "t".into(),
                angle: Arc::new(|t| t),
            },
            None => DrivenCrease::from_frames(pattern, edge)?,
        };
        creases.push(crease);
    }
    if args.driven.is_some() {
        // One named crease: the symmetric fold, whatever else the file marks.
        return Ok(G0Drive::Symmetric(creases.remove(0)));
    }
    Ok(G0Drive::of_creases(pattern, creases)?)
}

fn parse_t_max(src: &str) -> anyhow::Result<f64> {
    let f = Formula::parse(src).map_err(|e| anyhow::anyhow!("--t-max: {e}"))?;
    let x = f.eval(f64::NAN);
    if !x.is_finite() {
        bail!("--t-max: must be a finite number or a formula without t (e.g. \"pi/2\")");
    }
    Ok(x)
}

/// The cross-validation settings for a FOLD/design pattern from the flags: the end of
/// the motion (`--t-max`, else the frames') and the steps.
fn pattern_options(
    path: &Path,
    pattern: &Pattern,
    args: &SimulateArgs,
) -> anyhow::Result<CrossvalOptions> {
    let t_end = match &args.t_max {
        Some(s) => Some(parse_t_max(s)?),
        None if pattern.frames.len() < 2 => {
            bail!(
                "{}: the file has no folded frames to take the motion from: give its end with --t-max (e.g. --t-max \"pi/2\")",
                path.display()
            )
        }
        None => None,
    };
    let steps = match args.steps {
        Some(j) => Some(j as usize),
        None if pattern.frames.len() < 2 => Some(30),
        None => None,
    };
    Ok(CrossvalOptions {
        steps,
        t_end,
        check_intersections: !args.no_intersections,
        rigid_panels: !args.eq2_bars,
        ..Default::default()
    })
}

fn run_pattern(
    path: &Path,
    name: &str,
    pattern: &Pattern,
    note: Option<String>,
    args: &SimulateArgs,
) -> anyhow::Result<()> {
    let drive = drive_for(pattern, args).with_context(|| path.display().to_string())?;
    let opts = pattern_options(path, pattern, args)?;
    let start = Instant::now();
    let r = crossval::crossval(pattern, &drive, &opts)
        .with_context(|| format!("simulating {}", path.display()))?;
    let seconds = start.elapsed().as_secs_f64();
    // Comparing with the file's frames is a check: disagreement exits with status 1.
    let verdict = || -> anyhow::Result<()> {
        if r.compared_states > 0 && !r.agrees(GAMMA_TOL, POSITION_TOL) {
            return Err(super::CheckFailed(format!(
                "{name}: the simulation does not agree with the file's frames (max |x - X| {}, Γ {})",
                crate::text::num(r.max_position_error),
                crate::text::num(r.gamma)
            ))
            .into());
        }
        Ok(())
    };
    if args.json {
        let mut out = serde_json::to_value(&r)?;
        let extra = json!({
            "name": name,
            "note": note,
            "steps_report": r.sim.steps,
            "initial_intersections": r.sim.initial_intersections,
            "final_positions": r.sim.final_positions(),
            "sim_states": r.sim.states,
            "rigid_delta_bound": RIGID_DELTA,
            "gamma_tol": GAMMA_TOL,
            "position_tol": POSITION_TOL,
            "agrees_with_ptu": (r.compared_states > 0).then(|| r.agrees(GAMMA_TOL, POSITION_TOL)),
            "seconds": seconds,
        });
        if let (Some(o), Some(e)) = (out.as_object_mut(), extra.as_object()) {
            o.extend(e.clone());
        }
        emit(&(serde_json::to_string_pretty(&out)? + "\n"))?;
        return verdict();
    }
    let mut o = String::new();
    pattern_text(&mut o, name, pattern, &drive, &r, note.as_deref());
    let _ = writeln!(o, "time                {seconds:.3} s");
    emit(&o)?;
    verdict()
}

/// The text report of one FOLD/design simulation, compared with its frames.
fn pattern_text(
    o: &mut String,
    name: &str,
    pattern: &Pattern,
    drive: &G0Drive,
    r: &CrossvalReport,
    note: Option<&str>,
) {
    let creases: Vec<String> = drive
        .creases()
        .iter()
        .map(|c| {
            let [p, q] = pattern.edges[c.edge].v;
            format!("{} ({p}→{q})", c.edge)
        })
        .collect();
    let driven = match drive.fixed_face() {
        None => format!("driven crease {}", creases.join(", ")),
        Some(f) => format!("facet {f} fixed, driven creases {}", creases.join(", ")),
    };
    let _ = writeln!(o, "{name}");
    let _ = writeln!(
        o,
        "{} vertices ({} free), {} facets, {} bars, J = {}; {driven}, ρ(t) = {}, t ∈ [{:.6}, {:.6}]",
        pattern.vertices.len(),
        r.free_vertices,
        pattern.faces.len(),
        r.bars,
        r.steps,
        drive.source(),
        r.t_start,
        r.t_end
    );
    if let Some(n) = note {
        let _ = writeln!(o, "note: {n}");
    }
    steps_table(o, &r.sim, Some(r));
    summary(o, &r.sim);
    if r.compared_states > 0 {
        let _ = writeln!(
            o,
            "vs the frames       max |x - X| {:.3e} over {} states ({} ill-conditioned, within their error bound); final {}; prescribed vertices {:.3e}",
            r.max_position_error,
            r.compared_states,
            r.widened_states,
            r.final_position_error
                .map_or("not compared".into(), |e| format!("{e:.3e}")),
            r.drive_error
        );
        let _ = writeln!(
            o,
            "agrees with the PTU {} (Γ <= {GAMMA_TOL:e}, |x - X| <= {POSITION_TOL:e})",
            if r.agrees(GAMMA_TOL, POSITION_TOL) {
                "yes"
            } else {
                "NO"
            }
        );
    }
    let names: Vec<String> = (0..pattern.vertices.len()).map(|i| i.to_string()).collect();
    positions(o, &names, r.sim.final_positions());
}

/// One design of a `--crossval` run.
struct Row {
    name: String,
    vertices: usize,
    result: Result<CrossvalReport, String>,
}

fn design_files(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let sub = dir.join("designs");
    let dir = if sub.is_dir() { sub } else { dir.to_path_buf() };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .with_context(|| format!("{}: cannot read the directory", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == "json"))
        .collect();
    files.sort();
    if files.is_empty() {
        bail!(
            "{}: no design JSON files (expected a `foldsynth synthesize` output directory or its designs/)",
            dir.display()
        );
    }
    Ok(files)
}

fn run_crossval(dir: &Path, args: &SimulateArgs) -> anyhow::Result<()> {
    if args.angle.is_some() || args.t_max.is_some() || args.driven.is_some() {
        bail!(
            "--crossval drives every design by its marked creases over its frames; --driven, --angle and --t-max do not apply"
        );
    }
    let files = design_files(dir)?;
    let start = Instant::now();
    let opts = CrossvalOptions {
        steps: args.steps.map(|j| j as usize),
        check_intersections: !args.no_intersections,
        rigid_panels: !args.eq2_bars,
        ..Default::default()
    };
    let rows = crossval_rows(&files, &opts);
    let seconds = start.elapsed().as_secs_f64();
    let totals = Totals::new(&rows);
    let failed = rows.len() - totals.passed;
    if args.json {
        let out = crossval_json(&rows, &totals, seconds);
        emit(&(serde_json::to_string_pretty(&out)? + "\n"))?;
    } else {
        emit(&crossval_text(&rows, &totals, seconds))?;
    }
    if failed > 0 {
        return Err(super::CheckFailed(format!(
            "{failed} of {} designs do not agree with the PTU",
            rows.len()
        ))
        .into());
    }
    Ok(())
}

/// Every design simulated and compared: one design per task on the rayon pool
/// (`collect` keeps the files' order).
fn crossval_rows(files: &[PathBuf], opts: &CrossvalOptions) -> Vec<Row> {
    files
        .par_iter()
        .map(|path| match read_design(path) {
            Err(e) => Row {
                name: path.display().to_string(),
                vertices: 0,
                result: Err(format!("{e:#}")),
            },
            Ok((name, pattern)) => {
                let result = G0Drive::from_frames(&pattern)
                    .and_then(|d| crossval::crossval(&pattern, &d, opts))
                    .map_err(|e| e.to_string());
                Row {
                    name,
                    vertices: pattern.vertices.len(),
                    result,
                }
            }
        })
        .collect()
}

/// Whether a design agrees with the PTU.
fn pass(r: &CrossvalReport) -> bool {
    r.agrees(GAMMA_TOL, POSITION_TOL)
}

/// The worst figures over the designs that ran, and how many agree.
struct Totals {
    passed: usize,
    max_gamma: f64,
    max_delta: f64,
    max_err: f64,
    max_drive: f64,
    max_final: f64,
    max_theta: f64,
}

impl Totals {
    fn new(rows: &[Row]) -> Totals {
        let ok: Vec<&CrossvalReport> = rows.iter().filter_map(|r| r.result.as_ref().ok()).collect();
        let max = |f: &dyn Fn(&CrossvalReport) -> f64| ok.iter().map(|r| f(r)).fold(0.0, f64::max);
        Totals {
            passed: ok.iter().filter(|r| pass(r)).count(),
            max_gamma: max(&|r| r.gamma),
            max_delta: max(&|r| r.max_delta),
            max_err: max(&|r| r.max_position_error),
            max_drive: max(&|r| r.drive_error),
            max_final: max(&|r| r.final_position_error.unwrap_or(f64::INFINITY)),
            max_theta: max(&|r| r.theta),
        }
    }
}

/// `--crossval --json`.
fn crossval_json(rows: &[Row], t: &Totals, seconds: f64) -> serde_json::Value {
    let designs: Vec<_> = rows
        .iter()
        .map(|row| match &row.result {
            Ok(r) => json!({
                "design": row.name,
                "vertices": row.vertices,
                "free_vertices": r.free_vertices,
                "steps": r.steps,
                "compared_states": r.compared_states,
                "gamma": r.gamma,
                "max_delta": r.max_delta,
                "rigid": r.rigid,
                "theta": r.theta,
                "max_position_error": r.max_position_error,
                "final_position_error": r.final_position_error,
                "drive_error": r.drive_error,
                "widened_states": r.widened_states,
                "start_gap": r.start_gap,
                "agrees": pass(r),
            }),
            Err(e) => json!({"design": row.name, "error": e, "agrees": false}),
        })
        .collect();
    json!({
        "designs": designs,
        "count": rows.len(),
        "agree": t.passed,
        "max_gamma": t.max_gamma,
        "max_delta": t.max_delta,
        "max_position_error": t.max_err,
        "max_final_position_error": t.max_final,
        "max_drive_error": t.max_drive,
        "max_theta": t.max_theta,
        "gamma_tol": GAMMA_TOL,
        "position_tol": POSITION_TOL,
        "seconds": seconds,
    })
}

/// `--crossval`: a table of the designs and the totals.
fn crossval_text(rows: &[Row], t: &Totals, seconds: f64) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "{:<14} {:>3} {:>4} {:>3} {:>10} {:>10} {:>10} {:>10} {:>6}  agrees",
        "design", "n", "free", "J", "Gamma", "max delta", "max |x-X|", "final", "theta"
    );
    for row in rows {
        match &row.result {
            Ok(r) => {
                let _ = writeln!(
                    o,
                    "{:<14} {:>3} {:>4} {:>3} {:>10.2e} {:>10.2e} {:>10.2e} {:>10} {:>6.3}  {}",
                    row.name,
                    row.vertices,
                    r.free_vertices,
                    r.steps,
                    r.gamma,
                    r.max_delta,
                    r.max_position_error,
                    r.final_position_error
                        .map_or("-".into(), |e| format!("{e:.2e}")),
                    r.theta,
                    if pass(r) { "yes" } else { "NO" }
                );
            }
            Err(e) => {
                let _ = writeln!(o, "{:<14} error: {e}", row.name);
            }
        }
    }
    let _ = writeln!(
        o,
        "{} designs, {} agree with the PTU (Γ <= {GAMMA_TOL:e}, |x - X| <= {POSITION_TOL:e} at every compared state)",
        rows.len(),
        t.passed
    );
    let _ = writeln!(
        o,
        "max Γ {:.3e}, max δ(j) {:.3e}, max |x - X| {:.3e} (final state {:.3e}), prescribed vertices {:.3e}, max θ {:.3}",
        t.max_gamma, t.max_delta, t.max_err, t.max_final, t.max_drive, t.max_theta
    );
    let _ = writeln!(o, "time {seconds:.2} s");
    o
}

/// Write to stdout; a closed pipe (`| head`) ends the output quietly instead of failing.
pub(crate) fn emit(text: &str) -> anyhow::Result<()> {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        r => Ok(r?),
    }
}

/// The per-step table; with a cross-validation, a column of the distance to the PTU.
fn steps_table(o: &mut String, r: &SimReport, cv: Option<&CrossvalReport>) {
    let _ = write!(
        o,
        "{:>4} {:>12} {:>12} {:>12} {:>5}",
        "j", "t", "delta(j)", "sum|l-lt|", "iter"
    );
    if cv.is_some() {
        let _ = write!(o, " {:>11}", "|x - X_PTU|");
    }
    let _ = writeln!(o, "  intersection");
    for s in &r.steps {
        let x = match &s.intersection {
            Some(i) => format!("{:?} f{}-f{}", i.kind, i.face_a, i.face_b),
            None => String::new(),
        };
        let _ = write!(
            o,
            "{:>4} {:>12.6} {:>12.3e} {:>12.3e} {:>5}",
            s.j, s.t, s.delta, s.delta_length, s.iterations
        );
        if let Some(cv) = cv {
            let e = cv
                .states
                .get(s.j)
                .and_then(|c| c.position_error)
                .map_or("-".into(), |e| format!("{e:.3e}"));
            let _ = write!(o, " {e:>11}");
        }
        let _ = writeln!(o, "  {x}");
    }
}

fn summary(o: &mut String, r: &SimReport) {
    if !r.initial_intersections.is_empty() {
        let _ = writeln!(
            o,
            "initial state already intersects: {} facet pairs",
            r.initial_intersections.len()
        );
    }
    let _ = writeln!(o, "Gamma (mean delta)  {:.3e}", r.gamma);
    let _ = writeln!(o, "max delta(j)        {:.3e}", r.max_delta());
    let _ = writeln!(o, "theta               {:.4}", r.theta);
    let _ = writeln!(
        o,
        "verdict             {}",
        if r.rigid {
            format!("rigid (every delta(j) <= {RIGID_DELTA:e})")
        } else {
            format!("not rigid (some delta(j) > {RIGID_DELTA:e})")
        }
    );
}

fn positions(o: &mut String, names: &[String], x: &[[f64; 3]]) {
    let _ = writeln!(o, "final positions:");
    for (name, p) in names.iter().zip(x) {
        let _ = writeln!(
            o,
            "  {name:>8}  ({:>10.6}, {:>10.6}, {:>10.6})",
            p[0], p[1], p[2]
        );
    }
}
