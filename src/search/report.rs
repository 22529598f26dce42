//! What a search puts into `report.html`: the task as the run saw it, the counts and
//! timings, the search tree, the distribution plot, and per feasible design its geometry,
//! figures and files (the page itself is [`crate::export::report`]).

use super::options::{SearchError, SearchOptions};
use super::output::OutputDir;
use super::progress::Progress;
use super::record::{AlternativeRecord, LevelCounts, Summary};
use crate::export::plots::{DistributionPlot, Series, TreeNode};
use crate::export::report::{CountRow, Fact, ReportDesign, ReportInput, ReportSummary, TimingRow};
use crate::export::{DesignMeta, Files, verify::VerifyReport};
use crate::grammar::VertexType;
use crate::pattern::Pattern;
use crate::task::Task;
use std::path::PathBuf;

/// Write `OUT/report.html` (always: its 3D views need only the geometry) from the summary
/// `s`, the search tree and the designs' cards.
pub(super) fn write_report(
    task: &Task,
    tree: Vec<TreeNode>,
    s: &Summary,
    opts: &SearchOptions,
    out_dir: &OutputDir,
    progress: &Progress,
    cards: Vec<ReportDesign>,
) -> Result<(), SearchError> {
    progress.phase("write report", "", None);
    let input = report_input(task, tree, s, task_facts(task, opts, s), cards);
    out_dir.register([out_dir.path("report.html")])?;
    let path = crate::export::report::write_report(out_dir.root(), &input)
        .map_err(|e| SearchError::Export(e.to_string()))?;
    let bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
    progress.finish_phase_with(&format!("{} ({bytes} bytes)", path.display()));
    Ok(())
}

/// A number for the task table: at most 4 decimals, trailing zeros dropped.
fn n4(x: f64) -> String {
    let s = format!("{x:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

fn point(p: [f64; 3]) -> String {
    format!("({}, {}, {})", n4(p[0]), n4(p[1]), n4(p[2]))
}

/// An angle in radians with its degrees.
fn angle(a: f64) -> String {
    format!("{} rad ({}°)", n4(a), n4(a.to_degrees()))
}

/// The task as the run used it: G0, N_max, symmetry, motion, bounds, objective, checks,
/// obstacles, and the search settings (starts, seed, sweep, workers, export).
fn task_facts(task: &Task, opts: &SearchOptions, s: &Summary) -> Vec<Fact> {
    let mut f = vec![Fact::new(
        "task",
        match &task.description {
            Some(d) => format!("{}: {d}", task.name),
            None => task.name.clone(),
        },
    )];
    if let Some(src) = &task.source {
        f.push(Fact::new("task file", src.display()));
    }
    g0_facts(task, &mut f);
    f.push(Fact::new(
        "N_max",
        format!(
            "{} internal vertices at most ({} meaningful graphs)",
            s.n_max, s.graphs
        ),
    ));
    f.push(Fact::new(
        "symmetry",
        if task.symmetry.mirror_xz {
            "mirror-symmetric about the xz-plane: mirror-image graphs are dropped"
        } else {
            "none"
        },
    ));
    problem_facts(task, &mut f);
    check_facts(task, &mut f);
    f.push(Fact::new(
        "search",
        format!(
            "{} starting points per alternative, seed {}, {} workers; rigidity and verification over {} states of the motion; {}",
            opts.starts,
            opts.seed,
            s.settings["jobs"],
            opts.sweep,
            match (opts.export, opts.export_top) {
                (false, _) => "--no-export: design JSONs only, no per-design files".to_string(),
                (true, None) => "--export all: every design's files (FOLD, SVG, OBJ, STL, pictures, GIF)".to_string(),
                (true, Some(n)) => format!(
                    "every design's FOLD file; the SVG, OBJ, STL, pictures and GIF of the {n} most robust (--export {n}; a design's 'files' row gives the command for the others, --export all writes every one)"
                ),
            }
        ),
    ));
    f
}

/// G0's vertices and creases.
fn g0_facts(task: &Task, f: &mut Vec<Fact>) {
    let g0 = &task.initial;
    f.push(Fact::new(
        "G0 vertices",
        g0.vertices
            .iter()
            .map(|v| {
                format!(
                    "{} at ({}, {}), {}",
                    v.id,
                    n4(v.xy[0]),
                    n4(v.xy[1]),
                    match v.ty {
                        VertexType::Extendable => "extendable χ",
                        VertexType::Terminal => "terminal ∅",
                    }
                )
            })
            .collect::<Vec<_>>()
            .join("; "),
    ));
    f.push(Fact::new(
        "G0 creases",
        g0.creases
            .iter()
            .map(|c| {
                let name = |i: usize| g0.vertices.get(i).map_or("?", |v| v.id.as_str());
                let facet = |i: usize| g0.facets.get(i).map_or("?", |s| s.as_str());
                format!(
                    "{} → {} ({} left, {} right){}",
                    name(c.tail),
                    name(c.head),
                    facet(c.left),
                    facet(c.right),
                    c.drive
                        .as_ref()
                        .map_or(String::new(), |d| format!(", driven: ρ = {d}"))
                )
            })
            .collect::<Vec<_>>()
            .join("; "),
    ));
}

/// The motion, the bounds and the objective.
fn problem_facts(task: &Task, f: &mut Vec<Fact>) {
    if let Some(m) = &task.motion {
        f.push(Fact::new(
            "motion",
            format!("t from 0 to {}", angle(m.t_max)),
        ));
    }
    if let Some(b) = &task.bounds {
        f.push(Fact::new(
            "bounds",
            format!(
                "crease lengths l in [{}, {}] (G0's crease = 1); sector angles α in [{}, {}]",
                n4(b.l_min),
                n4(b.l_max),
                angle(b.alpha_min),
                angle(b.alpha_max)
            ),
        ));
    }
    if let Some(o) = &task.objective {
        let targets: Vec<String> = o
            .targets
            .iter()
            .map(|t| {
                let w = if t.weight == 1.0 {
                    String::new()
                } else {
                    format!(", weight {}", n4(t.weight))
                };
                match t.point() {
                    Some(p) => format!("{} at t = {}{w}", point(p), n4(t.t)),
                    None => format!("{:?} at t = {}{w}", t.goal, n4(t.t)),
                }
            })
            .collect();
        f.push(Fact::new(
            if targets.len() == 1 {
                "target"
            } else {
                "targets"
            },
            format!(
                "the gripping vertex reaches {}; success when Ω* ≤ {:e}",
                targets.join("; "),
                o.threshold
            ),
        ));
    }
}

/// The intersection check and the obstacles.
fn check_facts(task: &Task, f: &mut Vec<Fact>) {
    if let Some(c) = &task.check {
        f.push(Fact::new(
            "intersection check",
            format!(
                "{} states over [0, t_max]{}",
                c.states,
                if task.scene.copies.n == 2 {
                    "; two-armed: the arm and its copy rotated 180° about z"
                } else {
                    ""
                }
            ),
        ));
        for (i, cy) in task.scene.cylinders().enumerate() {
            f.push(Fact::new(
                format!("obstacle {}", i + 1),
                format!(
                    "cylinder of radius {} around the axis {} → {}",
                    n4(cy.radius),
                    point(cy.a),
                    point(cy.b)
                ),
            ));
        }
    }
}

/// Per-design figures below the views: key, verification, variables.
fn design_facts(rec: &AlternativeRecord, threshold: f64) -> Vec<Fact> {
    let mut f = vec![
        Fact::new("key", &rec.key),
        Fact::new(
            "objective",
            format!(
                "Ω* = {:.3e} (threshold {threshold:e}); largest constraint violation {:.1e}",
                rec.objective, rec.max_violation
            ),
        ),
        Fact::new(
            "checks",
            format!(
                "free of self-intersection: {}; clear of the obstacles: {}",
                yes(rec.self_intersection_free),
                yes(rec.obstacle_free)
            ),
        ),
    ];
    if let Some(v) = &rec.verification {
        f.push(Fact::new(
            "verification",
            format!(
                "{} states: isometry {:.1e}, closure {:.1e}, developability {:.1e}, fold angles {:.1e} rad; rigid over the whole motion: {}",
                v.states,
                v.isometry_max,
                v.closure_max,
                v.developability_max,
                v.fold_angle_max,
                if v.rigid_over_motion { "yes" } else { "no" }
            ),
        ));
        f.push(Fact::new(
            "smallest rigid margin (Eq. 25)",
            format!("{:.3e} rad at t = {:.4}", v.min_margin, v.min_margin_t),
        ));
    }
    f.push(Fact::new(
        "variables",
        rec.variables
            .iter()
            .map(|(k, v)| format!("{k} = {v:.4}"))
            .collect::<Vec<_>>()
            .join(", "),
    ));
    f.push(Fact::new(
        "optimization",
        format!(
            "{} starts, {} evaluations, {:.0} ms; checks {:.0} ms",
            rec.starts_run, rec.evaluations, rec.optimize_ms, rec.check_ms
        ),
    ));
    f
}

fn yes(b: Option<bool>) -> &'static str {
    match b {
        Some(true) => "yes",
        Some(false) => "no",
        None => "not checked",
    }
}

/// The robustness record (shared contract), read from the record's JSON by its name so
/// the report shows it whenever the search writes it.
fn robustness(rec: &AlternativeRecord) -> Option<serde_json::Value> {
    serde_json::to_value(rec)
        .ok()?
        .get("robustness")
        .filter(|v| v.is_object())
        .cloned()
}

/// One design of the report.
pub(super) fn report_design(
    rec: &AlternativeRecord,
    threshold: f64,
    pattern: Pattern,
    meta: DesignMeta,
    design_file: PathBuf,
    files: Option<Files>,
    verify: Option<VerifyReport>,
) -> ReportDesign {
    let mut facts = design_facts(rec, threshold);
    if let Ok(sc) = crate::export::svg::svg_scale(&pattern, &Default::default()) {
        facts.push(Fact::new("crease-pattern SVG", sc.note));
    }
    // The page's geometry now, and the frames dropped: the cards of every design wait in
    // memory for the report (the text is about a fifth of the frames' memory). A pattern
    // the page cannot draw keeps its frames, and the report says why.
    let geometry = crate::export::report::geometry_text(&pattern).ok();
    let pattern = if geometry.is_some() {
        Pattern {
            frames: Vec::new(),
            ..pattern
        }
    } else {
        pattern
    };
    ReportDesign {
        id: rec.id(),
        level: rec.level,
        candidate: Some(rec.candidate),
        pattern,
        geometry,
        meta,
        robustness: robustness(rec),
        area: area(rec),
        facts,
        design_file: Some(design_file),
        files,
        verify,
        thick: None,
        in_full: true,
    }
}

/// A design the report shows as a row of its table only (outside `--report-designs N`):
/// what its cells show and its design JSON, no geometry (memory holds this for each).
pub(super) fn row_design(
    rec: &AlternativeRecord,
    meta: DesignMeta,
    design_file: PathBuf,
) -> ReportDesign {
    // The values the row shows (score and margins), not their settings and places.
    let value_only = |v: &serde_json::Value| match v.get("value") {
        Some(x) => serde_json::json!({ "value": x }),
        None => v.clone(),
    };
    let robustness = robustness(rec).map(|r| match r {
        serde_json::Value::Object(o) => {
            serde_json::Value::Object(o.iter().map(|(k, v)| (k.clone(), value_only(v))).collect())
        }
        other => other,
    });
    ReportDesign {
        id: rec.id(),
        level: rec.level,
        candidate: Some(rec.candidate),
        pattern: Pattern {
            vertices: Vec::new(),
            edges: Vec::new(),
            faces: Vec::new(),
            frames: Vec::new(),
        },
        geometry: None,
        meta: DesignMeta {
            task: meta.task,
            rule_sequence: meta.rule_sequence,
            modes: meta.modes,
            gripping_vertex: meta.gripping_vertex,
            objective: meta.objective,
            ..Default::default()
        },
        robustness,
        area: area(rec),
        facts: Vec::new(),
        design_file: Some(design_file),
        files: None,
        verify: None,
        thick: None,
        in_full: false,
    }
}

/// The area of an area task as the check measured it.
fn area(rec: &AlternativeRecord) -> Option<f64> {
    rec.requirements
        .as_ref()
        .and_then(|r| r.area.as_ref())
        .and_then(|a| a.value)
}

/// The report's content.
fn report_input(
    task: &Task,
    tree: Vec<TreeNode>,
    s: &Summary,
    task_rows: Vec<Fact>,
    designs: Vec<ReportDesign>,
) -> ReportInput {
    let th = |i: usize| s.thesis.map(|t| t[i] as u64);
    let row = |label: &str, value: usize, thesis: Option<u64>| CountRow {
        label: label.into(),
        value: value as u64,
        thesis,
    };
    let counts = vec![
        row("meaningful graphs", s.graphs, s.thesis.map(|_| 52)),
        row("alternatives evaluated", s.alternatives, th(0)),
        row("meet the target", s.meets_target, th(1)),
        row("… free of self-intersection", s.no_self_intersection, th(2)),
        row("… also clear of the obstacles", s.no_intersection, th(3)),
        row("… also rigid over the whole motion", s.feasible, None),
        row(
            "rigid at t_max only (thesis check passes, full motion fails)",
            s.rigid_at_tmax_only,
            None,
        ),
        row("verification failures", s.verification_failures, None),
    ];
    let t = &s.timings;
    let timing = |stage: &str, seconds: f64| TimingRow {
        stage: stage.into(),
        seconds,
    };
    let timings = vec![
        timing("enumerate (wall)", t.enumerate_s),
        timing("compile (CPU)", t.compile_s),
        timing("optimize (CPU)", t.optimize_s),
        timing("check + verify (CPU)", t.check_s),
        timing("search before export (wall)", t.total_s),
    ];
    let series = |name: &str, f: &dyn Fn(&LevelCounts) -> usize| Series {
        name: name.into(),
        points: s
            .levels
            .iter()
            .map(|l| [l.level as f64, f(l) as f64])
            .collect(),
    };
    let distribution = DistributionPlot {
        title: format!(
            "{}: designs over rule applications (thesis Fig. 51)",
            task.name
        ),
        x_label: "rule applications".into(),
        y_label: "designs".into(),
        series: vec![
            series("all", &|l| l.alternatives),
            series("meet the target", &|l| l.meets_target),
            series("no self-intersection", &|l| l.no_self_intersection),
            series("no intersection", &|l| l.no_intersection),
        ],
    };
    ReportInput {
        summary: ReportSummary {
            title: format!("foldsynth — {}", task.name),
            task: task.name.clone(),
            counts,
            timings,
            notes: std::iter::once(format!(
                "Times: compile, optimize and check add up every worker's time (CPU seconds); the export (design files and this page) follows the search and is in summary.json. {} of the alternatives were taken over from an earlier run (--resume).",
                s.settings["resumed"]
            ))
            .chain(s.coverage.as_ref().map(|c| format!("Coverage: the {}.", c.text())))
            .collect(),
        },
        task: task_rows,
        tree,
        // A run with no record yet (a CPU budget spent before its first alternative) has no
        // level to plot.
        distribution: (!s.levels.is_empty()).then_some(distribution),
        designs,
    }
}
