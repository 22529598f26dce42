//! What one fuzz input runs: the parser, then everything a user's file of that kind
//! reaches, at small sizes so a million inputs run in minutes. Each returns whether the
//! parser accepted the input.

use std::f64::consts::PI;

use crate::check::verify::{Tolerances, verify as verify_design};
use crate::check::{MotionSettings, check_frames};
use crate::export::fold::FoldFile;
use crate::export::verify::{VerifyOptions, verify};
use crate::export::{DesignFile, DesignMeta, FoldSpec, mesh, render, svg, validate_pattern};
use crate::grammar::{Enumeration, Filters};
use crate::kinematics::foldability::{degree4, min_margin, rigid_intervals};
use crate::kinematics::{DriveExpr, VertexSpec, closure_residual, flat_foldable, solve_vertex};
use crate::model::Model;
use crate::model::numeric::{Evaluated, sample_times};
use crate::pattern::Pattern;
use crate::simulate::crossval::{CrossvalOptions, G0Drive, crossval};
use crate::simulate::run::REFINE_ITERATION_BUDGET;
use crate::simulate::{Formula, PatternFile, SolverSettings, simulate};
use crate::task::Task;

/// Values of t every expression and vertex is evaluated at (inside and outside [0, π]).
const TS: [f64; 7] = [-7.0, -1.0, 0.0, 0.4, 1.5, PI, 9.0];

/// A task file: parsed, enumerated to N ≤ 2, the first models built and evaluated at the
/// middle of their bounds, verified and checked for intersections over three states.
pub fn task(text: &str) -> bool {
    let Ok(task) = Task::from_toml_str(text, "fuzz.toml") else {
        return false;
    };
    let n_max = task.n_max.min(2);
    let Ok(e) = Enumeration::run_limited(&task, n_max, Filters::all(), 300) else {
        return true;
    };
    let obstacles: Vec<_> = task.scene.cylinders().copied().collect();
    for node in e.meaningful().take(2) {
        for candidate in 0..3 {
            let Ok(model) = Model::new(&node.graph, &task, candidate) else {
                continue;
            };
            let x: Vec<f64> = model
                .free
                .iter()
                .map(|&i| {
                    let (lo, hi) = model.var_bounds(i);
                    0.5 * (lo + hi)
                })
                .collect();
            let full = model.full_vars(&x);
            let modes = vec![1.0; model.plan.n_modes];
            let _ = model.omega(&full, &modes);
            let design = Evaluated::new(&model.plan, full, modes);
            let ts = sample_times(model.t_max, 3);
            let pattern = design.pattern(&ts);
            let _ = verify_design(&design, &ts, &Tolerances::default());
            let _ = check_frames(
                &pattern,
                &MotionSettings {
                    n_states: 3,
                    stop_at_first: true,
                    obstacles: obstacles.clone(),
                },
            );
        }
    }
    true
}

/// A vertex in the notation: the PTU at several t, rigid intervals, flat foldability,
/// the degree-4 results.
pub fn vertex(text: &str) -> bool {
    let Ok(spec) = VertexSpec::parse(text) else {
        return false;
    };
    let mode = spec.mode.sign();
    for t in TS {
        let units = spec.units_at(t);
        let state = solve_vertex(&units, &mode);
        let _ = closure_residual(&units, &state.phi);
    }
    let ts: Vec<f64> = (0..9).map(|i| i as f64 * PI / 8.0).collect();
    let _ = rigid_intervals(&ts, 1e-6, |t| min_margin(&spec, t));
    let _ = flat_foldable(&spec.units_at(0.0), 1e-9);
    let _ = degree4(&spec);
    let _ = VertexSpec::parse(&spec.to_string());
    true
}

/// One expression through every expression parser (driving angles, task drives,
/// simulator formulas, task numbers), evaluated where it parses.
pub fn expr(text: &str) -> bool {
    let mut any = false;
    if let Ok(e) = DriveExpr::parse(text) {
        any = true;
        for t in TS {
            let _ = e.eval(&t);
        }
        let _ = e.to_string();
    }
    if let Ok(d) = crate::task::Drive::parse(text) {
        any = true;
        let _ = d.eval(&0.5);
    }
    if let Ok(f) = Formula::parse(text) {
        any = true;
        for t in TS {
            let _ = f.eval(t);
        }
    }
    if let Ok(e) = crate::task::number::Expr::parse(text) {
        any = true;
        let _ = e.eval();
    }
    any
}

/// The writers every pattern reaches.
fn write_pattern(p: &Pattern, meta: &DesignMeta) {
    let _ = crate::export::fold::to_fold_string(p, meta, FoldSpec::default());
    let _ = svg::crease_pattern_svg(p, &svg::SvgOptions::default());
    let last = p.frames.len().checked_sub(1);
    if let Ok(m) = mesh::state_mesh_copies(p, last, &meta.scene.copies) {
        let _ = mesh::to_obj(&m, "fuzz");
        let _ = mesh::to_stl_binary(&m);
    }
}

/// A FOLD file: `verify`, the pattern, the writers, and the simulator's drive and one
/// steps on small patterns.
pub fn fold(text: &str) -> bool {
    let Ok(f) = FoldFile::parse(text, "fuzz.fold") else {
        return false;
    };
    let report = verify(&f, &VerifyOptions::default());
    let _ = report.to_string();
    if let Ok(p) = f.to_pattern()
        && validate_pattern(&p).is_ok()
    {
        write_pattern(&p, &DesignMeta::default());
        // The simulator on one small pattern in sixteen, with a tenth of the default
        // refinement budget: a motion it cannot follow costs up to that budget (seconds),
        // which would dominate the run.
        if p.vertices.len() <= 16
            && text.len().is_multiple_of(16)
            && let Ok(drive) = G0Drive::from_frames(&p)
        {
            let _ = crossval(
                &p,
                &drive,
                &CrossvalOptions {
                    steps: Some(1),
                    solver: SolverSettings {
                        refine_budget: REFINE_ITERATION_BUDGET / 10,
                        ..CrossvalOptions::default().solver
                    },
                    ..CrossvalOptions::default()
                },
            );
        }
    }
    true
}

/// A design file: every writer and a small picture.
pub fn design(text: &str) -> bool {
    let Ok(d) = DesignFile::parse(text, "fuzz.json") else {
        return false;
    };
    write_pattern(&d.pattern, &d.meta);
    if let Ok(scene) = render::Scene::new(&d.pattern, &d.meta, render::Camera::default()) {
        let last = d.pattern.frames.len().checked_sub(1);
        let _ = scene.svg(last, (64, 48));
        let _ = scene.png(last, (16, 16));
    }
    true
}

/// A simulator pattern file, and one step of the simulation on small patterns.
pub fn pattern(text: &str) -> bool {
    let Ok(file) = PatternFile::parse(text, "fuzz.toml") else {
        return false;
    };
    if file.input.initial.len() <= 12 {
        let mut input = file.input.clone();
        input.steps = 1;
        let _ = simulate(&input);
    }
    true
}

/// `alternatives.jsonl` as `--resume` reads it: every non-empty line is reused or
/// reported, never silently dropped, and no key is reused twice.
pub fn records(text: &str) -> bool {
    let Ok((kept, report)) =
        crate::search::output::parse_records(text.as_bytes(), &|k: &str| !k.contains("drop"))
    else {
        return false;
    };
    let lines = text
        .split_inclusive('\n')
        .filter(|l| !l.trim().is_empty() || !l.ends_with('\n'))
        .count();
    assert_eq!(
        kept.len() + report.dropped.len(),
        lines,
        "a line was neither reused nor reported"
    );
    let keys: std::collections::HashSet<&str> = kept.iter().map(|r| r.key.as_str()).collect();
    assert_eq!(keys.len(), kept.len(), "a key was reused twice");
    !kept.is_empty()
}

/// Mesh bytes: read as STL (ASCII or binary) and as OBJ; each mesh read is scaled, moved,
/// bounded and walked triangle by triangle.
pub fn mesh(bytes: &[u8]) -> bool {
    use crate::scene::TriangleMesh;
    let mut accepted = false;
    for read in [TriangleMesh::from_stl(bytes), TriangleMesh::from_obj(bytes)] {
        let Ok(mut m) = read else { continue };
        accepted = true;
        let _ = m.bounding_ball();
        m.transform(2.5, [1.0, -2.0, 0.5]);
        let _ = m.bounds();
        for i in 0..m.triangles.len() {
            let _ = m.triangle(i);
        }
    }
    accepted
}
