//! Rule r2′ and the model of cyclic patterns against the Miura-ori (thesis Sec. 4.3.3,
//! 5.7, Fig. 52b; issue 19).
//!
//! The graph `2, 3, 4, 8, (9, 14)'` of the gripper task's G0 is the Miura-ori unit cell:
//! four degree-4 vertices v2, v3, v8, v4 around a central facet, the sink v9′ on the
//! straight crease v4–v8. Built by hand with parallelogram facets (the classic Miura-ori:
//! straight crease lines v1–v2–v4–v10 and v6–v3–v8–v13, zigzag lines v5–v2–v3–v7 and
//! v11–v4–v8–v12 mirror-symmetric about the straight ones at every vertex), the dihedral
//! angle of v4–v8 agrees from both ends over the whole motion and the bar-and-hinge
//! simulation follows the PTU; one sector moved by 1° breaks both.

use foldsynth::check::cycle::{CYCLE_TOL, verify_cycles};
use foldsynth::check::verify::{Tolerances, verify};
use foldsynth::grammar::CreaseGraph;
use foldsynth::kinematics::wrap_angle;
use foldsynth::model::Model;
use foldsynth::model::cycle::residual;
use foldsynth::model::geometry;
use foldsynth::model::numeric::Evaluated;
use foldsynth::simulate::crossval::{
    CrossvalOptions, GAMMA_TOL, POSITION_TOL, crossval_design, verify_cyclic,
};
use foldsynth::task::Task;
use std::f64::consts::PI;

const FIG52B: &str = "2, 3, 4, 8, (9, 14)'";

fn task() -> Task {
    Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap()
}

fn model() -> Model {
    let task = task();
    let g = CreaseGraph::from_sequence(&task, FIG52B).unwrap();
    Model::new(&g, &task, 0).unwrap()
}

/// The Miura-ori cell with zigzag angle φ (the direction of v2 → v3 below the straight
/// line v1–v2–v4), straight creases of length `a`, zigzag creases of length `b`, as the
/// grammar's variables (r1 measures each new crease counter-clockwise from the parent's
/// last predecessor, s3 clockwise from its first). `bump` is added to α_13 (a sector at v8).
fn miura(model: &Model, phi: f64, a: f64, b: f64, bump: f64) -> Vec<f64> {
    let s = PI + phi; // the sector between the straight and the zigzag crease, > π/2
    let values = [
        ("α_3", s),
        ("l_2,3", b),
        ("α_4", PI - s),
        ("l_2,4", a),
        ("α_5", s),
        ("α_6", PI - s),
        ("α_7", PI - s),
        ("α_8", s),
        ("l_3,8", a),
        // α_9 and α_10 together place v10 (α_9 is no longer v4's sector: r2′ moved v9).
        ("α_9", s),
        ("α_10", PI - s),
        ("α_11", s),
        ("α_12", PI - s),
        ("l_8,12", 0.8),
        ("α_13", s + bump),
        ("l_8,13", 0.8),
    ];
    let mut full: Vec<f64> = (0..model.plan.variables.len())
        .map(|i| model.var_bounds(i).0)
        .collect();
    for (name, x) in values {
        let i = model
            .plan
            .variables
            .iter()
            .position(|v| v.name == name)
            .unwrap_or_else(|| panic!("no variable {name}"));
        full[i] = x;
    }
    full
}

fn modes_of(bits: u32) -> Vec<f64> {
    (0..4)
        .map(|i| if bits >> i & 1 == 1 { -1.0 } else { 1.0 })
        .collect()
}

/// t over [0, π): 180 states, the last 1° short of the flat-folded state.
fn sweep() -> Vec<f64> {
    (0..180).map(|k| PI * k as f64 / 180.0).collect()
}

/// Every crease folds (no crease stays flat) at t = π/2: the Miura motion, not the
/// trivial fold about the straight line v1–v2–v4 that the flat state also branches into.
fn all_creases_fold(model: &Model, full: &[f64], modes: &[f64]) -> bool {
    let design = Evaluated::new(&model.plan, full.to_vec(), modes.to_vec());
    let f = design.fold(PI / 2.0);
    f.rho.iter().all(|r| wrap_angle(*r).abs() > 0.1)
}

/// The Miura-ori's rigid body modes: v2 down, v3 up, v4 up, v8 down (extension order).
/// The other compatible assignments fold some vertex only about its straight line.
const MIURA_MODES: u32 = 0b1001;

#[test]
fn the_miura_cell_folds_compatibly_over_the_whole_motion() {
    let m = model();
    let ts = sweep();
    let mut miura_like = Vec::new();
    for bits in 0..16 {
        let modes = modes_of(bits);
        let full = miura(&m, -PI / 3.0, 1.0, 0.8, 0.0);
        let design = Evaluated::new(&m.plan, full.clone(), modes.clone());
        let r = verify_cycles(&design, &ts, 1e-12);
        if r.checked_states + 1 >= ts.len()
            && r.compatibility_max <= CYCLE_TOL
            && all_creases_fold(&m, &full, &modes)
        {
            miura_like.push(bits);
        }
    }
    assert_eq!(miura_like, vec![MIURA_MODES]);

    // Any parallelogram cell: zigzag angle, straight and zigzag lengths.
    for (phi, a, b) in [
        (-PI / 3.0, 1.0, 0.8),
        (-PI / 4.0, 0.6, 1.2),
        (-0.4 * PI, 1.4, 0.5),
        (-0.2 * PI, 0.9, 0.9),
    ] {
        let full = miura(&m, phi, a, b, 0.0);
        let modes = modes_of(MIURA_MODES);
        let design = Evaluated::new(&m.plan, full.clone(), modes.clone());
        // Over [0, π): every state but the flat one (a degenerate vertex triangle at every
        // flat-foldable vertex) is rigid and checked.
        let r = verify_cycles(&design, &ts, 1e-12);
        assert_eq!(r.checked_states, ts.len() - 1, "φ = {phi}: {r:?}");
        assert!(r.passes(CYCLE_TOL), "φ = {phi}: {r:?}");
        // The model's own constraints vanish at its states; the geometry is a real folding.
        let flat = geometry::flat(&m.plan, &full);
        for t in [0.3, 1.0, 2.0, 3.0] {
            let folded = geometry::fold(&m.plan, &flat, &modes, &t);
            let res = residual(&m.plan, &flat, &folded, &m.plan.sinks[0]);
            assert!(res.dihedral.abs() < 1e-12, "{res:?}");
            assert!(res.position.iter().all(|x| x.abs() < 1e-12), "{res:?}");
        }
        let v = verify(&design, &ts[1..], &Tolerances::default());
        assert!(v.geometry_passes(&Tolerances::default()), "{v:?}");
        assert!(v.rigid_over_motion, "{v:?}");
    }
}

#[test]
fn the_simulation_follows_the_miura_cell() {
    let mut m = model();
    let modes = modes_of(MIURA_MODES);
    let full = miura(&m, -PI / 3.0, 1.0, 0.8, 0.0);
    // The gripper's motion, [0, π/2], as a search verifies it.
    let v = verify_cyclic(&m, &full, &modes, 181, 1e-12);
    assert!(v.passes, "{v:?}");
    // Further, to 0.9 π (the flat-folded state at π is singular for both kinematics).
    m.t_max = 0.9 * PI;
    let r = crossval_design(&m, full, modes, 60, &CrossvalOptions::default()).unwrap();
    eprintln!(
        "Miura cell to 0.9π: Γ = {:.3e}, max δ = {:.3e}, max |x − X_PTU| = {:.3e}",
        r.gamma, r.max_delta, r.max_position_error
    );
    assert!(r.agrees(GAMMA_TOL, POSITION_TOL), "{r:?}");
}

#[test]
fn a_sector_moved_by_one_degree_breaks_the_cell() {
    let mut m = model();
    let modes = modes_of(MIURA_MODES);
    let full = miura(&m, -PI / 3.0, 1.0, 0.8, 1f64.to_radians());
    let design = Evaluated::new(&m.plan, full.clone(), modes.clone());
    let r = verify_cycles(&design, &sweep()[..91], 1e-12);
    assert!(r.compatibility_max > 1e-4, "{r:?}");
    assert!(r.position_max > 1e-4, "{r:?}");
    let v = verify_cyclic(&m, &full, &modes, 181, 1e-12);
    assert!(!v.passes);
    // The simulation, run regardless of the sweep: the bars cannot follow past the start.
    m.t_max = PI / 2.0;
    match crossval_design(&m, full, modes, 30, &CrossvalOptions::default()) {
        Ok(r) => {
            eprintln!(
                "perturbed cell: Γ = {:.3e}, max δ = {:.3e}, max |x − X_PTU| = {:.3e}",
                r.gamma, r.max_delta, r.max_position_error
            );
            assert!(r.gamma > 1e-4 || !r.rigid, "{r:?}");
            assert!(!r.agrees(GAMMA_TOL, POSITION_TOL));
        }
        Err(e) => eprintln!("perturbed cell: no rigid path ({e})"),
    }
}
