//! `foldsynth bench numeric`: one folding motion of one design, J + 1 states, computed by
//! the compiled PTU model and by the thesis's bar-and-hinge simulation (Sec. 3), measured
//! in one run and reported as a ratio.
//!
//! The PTU side evaluates every vertex's position at t₀ … t_J with the JIT-compiled
//! forward kinematics ([`CompiledMotion`]); the plain f64 path (the same generic code,
//! not compiled) is a second row. The simulation side runs the G0 drive of
//! [`crate::simulate::crossval`] over the same J steps, once with Eq. 2's bars and the
//! simulator's default settings, as in the thesis, and once with the rigid panels and
//! settings the cross-validation uses; no intersection
//! check on either side, so both compute kinematics only. Both motions are compared at
//! the end, so the times are of the same motion.

use super::time_ns;
use crate::check::verify::{Tolerances, verify};
use crate::compile::Options;
use crate::model::Model;
use crate::model::compiled::{CompiledModel, CompiledMotion, ModelProblem, objective_target};
use crate::model::numeric::{Evaluated, sample_times};
use crate::optimize;
use crate::simulate::crossval::{
    CrossvalOptions, add_panel_apexes, branch_offsets, design_drive, g0_input,
};
use crate::simulate::{SimInput, SimReport, simulate};
use anyhow::{Result, bail};
use serde_json::json;
use std::hint::black_box;
use std::time::Duration;

/// The design being measured.
pub struct Design {
    /// Its model.
    pub model: Model,
    /// Its free variables.
    pub free: Vec<f64>,
    /// Its modes (±1 per internal vertex).
    pub modes: Vec<f64>,
    /// What to call it in the report.
    pub name: String,
}

/// The modes of assignment `bits` (bit i set: vertex i down).
fn modes_of(bits: u32, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| if bits >> i & 1 == 1 { -1.0 } else { 1.0 })
        .collect()
}

/// "up,down,…".
fn mode_names(modes: &[f64]) -> String {
    modes
        .iter()
        .map(|&m| if m > 0.0 { "up" } else { "down" })
        .collect::<Vec<_>>()
        .join(",")
}

/// Optimize a design of `model` that is rigid over its whole motion: with `modes`, or
/// with the first assignment, in binary order from all up, that gives one. `None` when
/// none does.
pub fn rigid_design(model: Model, modes: Option<Vec<f64>>) -> Result<Option<Design>> {
    let n = model.plan.n_modes;
    let tries: Vec<Vec<f64>> = match modes {
        Some(m) => vec![m],
        None => (0..1u32 << n).map(|b| modes_of(b, n)).collect(),
    };
    let compiled = CompiledModel::new(&model, &Options::default())?;
    let ts = sample_times(model.t_max, 181);
    for modes in tries {
        let problem = ModelProblem::new(&model, &compiled, &modes);
        let sol = optimize::minimize(
            &problem,
            &optimize::Options {
                starts: 16,
                target: Some(objective_target(&model)),
                ..Default::default()
            },
        );
        if !sol.feasible {
            continue;
        }
        let design = Evaluated::new(&model.plan, model.full_vars(&sol.x), modes.clone());
        if verify(&design, &ts, &Tolerances::default()).rigid_over_motion {
            let name = format!("optimized, modes {}", mode_names(&modes));
            return Ok(Some(Design {
                model,
                free: sol.x,
                modes,
                name,
            }));
        }
    }
    Ok(None)
}

/// The simulation of `design`'s motion in `steps` steps (Eq. 2's bars, or rigid panels).
fn sim_input(
    design: &Evaluated<'_>,
    model: &Model,
    steps: usize,
    panels: bool,
) -> Result<SimInput> {
    let pattern = design.pattern(&sample_times(model.t_max, steps + 1));
    let drive = design_drive(model)?;
    let mut input = g0_input(&pattern, &drive, 0.0, model.t_max, steps)?;
    let apexes = if panels {
        add_panel_apexes(&mut input)
    } else {
        Vec::new()
    };
    input.first_step_offsets = branch_offsets(&pattern, &input, &apexes);
    // Rigid panels: the cross-validation's settings. Eq. 2's bars: the simulator's own
    // defaults, as `foldsynth simulate` runs the thesis's model (its flexible quadrilaterals
    // would send the cross-validation's deep step refinement down to 2^18 substeps).
    if panels {
        input.solver = CrossvalOptions::default().solver;
    }
    Ok(input)
}

/// One simulation of the motion: its time per motion, Γ and how far its end state is from
/// the PTU's.
#[derive(Clone, Copy, Debug)]
pub struct SimFigures {
    /// Nanoseconds per motion.
    pub ns: f64,
    /// Γ, the mean δ(j).
    pub gamma: f64,
    /// Largest coordinate difference of the end state from the PTU's X(t_max).
    pub end_gap: f64,
}

/// The figures of one `bench numeric` run.
pub struct NumericBench {
    /// The design's name.
    pub design: String,
    /// Its graph's rule sequence.
    pub sequence: String,
    /// Number of vertices.
    pub vertices: usize,
    /// Folding steps J.
    pub steps: usize,
    /// End of the motion.
    pub t_max: f64,
    /// The compiled PTU model, nanoseconds per motion.
    pub ptu_jit_ns: f64,
    /// The f64 PTU path, nanoseconds per motion.
    pub ptu_f64_ns: f64,
    /// The simulation with Eq. 2's bars, as in the thesis.
    pub sim_eq2: SimFigures,
    /// The simulation with rigid panels.
    pub sim_panels: SimFigures,
    /// Milliseconds to compile the motion.
    pub compile_ms: f64,
    /// Operations of the compiled motion.
    pub ops: usize,
    /// Largest coordinate difference of the JIT from the f64 path over all states.
    pub jit_vs_f64_max: f64,
}

/// The compiled motion's positions at every state of `ts`, and the time per motion of
/// the JIT and of the f64 path.
fn time_ptu(
    design: &Evaluated<'_>,
    motion: &CompiledMotion,
    params: &[f64],
    ts: &[f64],
    budget: Duration,
) -> (Vec<f64>, f64, f64) {
    let len = motion.buffer_len();
    let mut states = vec![0.0; ts.len() * len];
    let jit = time_ns(budget, || {
        for (j, &t) in ts.iter().enumerate() {
            motion.positions(black_box(t), params, &mut states[j * len..(j + 1) * len]);
        }
    });
    let f64_path = time_ns(budget, || {
        for &t in ts {
            black_box(design.coords(&design.fold(black_box(t))));
        }
    });
    (states, jit, f64_path)
}

/// Largest coordinate difference between the compiled `states` (`len` numbers each) and
/// the f64 path.
fn jit_vs_f64(design: &Evaluated<'_>, states: &[f64], len: usize, ts: &[f64]) -> f64 {
    let mut max = 0.0_f64;
    for (j, &t) in ts.iter().enumerate() {
        let x = design.coords(&design.fold(t));
        for (v, p) in x.iter().enumerate() {
            for k in 0..3 {
                max = max.max((states[j * len + 3 * v + k] - p[k]).abs());
            }
        }
    }
    max
}

/// Largest coordinate difference of `r`'s final positions of the first `nv` vertices from
/// `end`.
fn end_gap(r: &SimReport, end: &[f64], nv: usize) -> f64 {
    r.final_positions()
        .iter()
        .take(nv)
        .enumerate()
        .map(|(v, p)| {
            (0..3)
                .map(|k| (p[k] - end[3 * v + k]).abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

/// Measure `bench numeric`: `d`'s motion in `steps` steps, `budget` per row. Fails when
/// the design is not rigid over its whole motion (the simulation would measure its
/// distortion, not its kinematics).
pub fn measure(d: &Design, steps: usize, budget: Duration) -> Result<NumericBench> {
    let model = &d.model;
    let ts = sample_times(model.t_max, steps + 1);
    let design = Evaluated::new(&model.plan, model.full_vars(&d.free), d.modes.clone());
    let v = verify(&design, &ts, &Tolerances::default());
    if !v.rigid_over_motion {
        bail!(
            "{}: the design is not rigid over its whole motion (margin {:.3e} at t = {:.4}); the bar-and-hinge simulation would measure its distortion, not its kinematics",
            d.name,
            v.min_margin,
            v.min_margin_t
        );
    }

    // (a) The compiled PTU model.
    let motion = CompiledMotion::new(model, &Options::default())?;
    let params = CompiledMotion::params(&d.free, &d.modes);
    let nv = motion.n_vertices;
    let len = motion.buffer_len();
    let (states, jit, f64_path) = time_ptu(&design, &motion, &params, &ts, budget);

    // (b) The bar-and-hinge simulation, same states.
    let thesis_input = sim_input(&design, model, steps, false)?;
    let panel_input = sim_input(&design, model, steps, true)?;
    let thesis_report = simulate(&thesis_input)?;
    let panel_report = simulate(&panel_input)?;
    let sim_thesis = time_ns(budget, || {
        black_box(simulate(black_box(&thesis_input)).ok());
    });
    let sim_panels = time_ns(budget, || {
        black_box(simulate(black_box(&panel_input)).ok());
    });

    // The same motion: compiled = f64 path at every state; simulation = PTU at t_max.
    let jit_vs_f64_max = jit_vs_f64(&design, &states, len, &ts);
    let end = &states[steps * len..];
    Ok(NumericBench {
        design: d.name.clone(),
        sequence: model.plan.sequence.clone(),
        vertices: nv,
        steps,
        t_max: model.t_max,
        ptu_jit_ns: jit,
        ptu_f64_ns: f64_path,
        sim_eq2: SimFigures {
            ns: sim_thesis,
            gamma: thesis_report.gamma,
            end_gap: end_gap(&thesis_report, end, nv),
        },
        sim_panels: SimFigures {
            ns: sim_panels,
            gamma: panel_report.gamma,
            end_gap: end_gap(&panel_report, end, nv),
        },
        compile_ms: motion.total_ms,
        ops: motion.compiled.report.simplified.ops,
        jit_vs_f64_max,
    })
}

impl NumericBench {
    /// The figures as one JSON object (times in nanoseconds per motion).
    pub fn json(&self) -> serde_json::Value {
        let (steps, jit) = (self.steps, self.ptu_jit_ns);
        let (eq2, panels) = (&self.sim_eq2, &self.sim_panels);
        json!({
            "design": self.design, "graph": self.sequence, "vertices": self.vertices, "steps": steps,
            "states": steps + 1,
            "ptu_jit_ns": jit, "ptu_f64_ns": self.ptu_f64_ns,
            "sim_eq2_bars_ns": eq2.ns, "sim_rigid_panels_ns": panels.ns,
            "ratio_sim_eq2_over_jit": eq2.ns / jit,
            "ratio_sim_panels_over_jit": panels.ns / jit,
            "compile_ms": self.compile_ms, "ops": self.ops,
            "jit_vs_f64_max": self.jit_vs_f64_max,
            "sim_eq2_gamma": eq2.gamma, "sim_eq2_end_gap": eq2.end_gap,
            "sim_panels_gamma": panels.gamma, "sim_panels_end_gap": panels.end_gap,
        })
    }
}
