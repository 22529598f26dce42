//! The bar-and-hinge simulator against the PTU on designs driven by a central facet
//! (thesis Sec. 3.4, 4.3): the 2 × 2 facet stays fixed, each of its four sides (two driven
//! halves each) turns its outer facet by the drive, every other vertex is placed by the
//! bars alone. Facts checked: a rigid design of `grammar/flasher_cuboid.toml` and one of
//! `grammar/star.toml` simulate with Γ ≤ 1e-8 and every state within the position
//! tolerance of the PTU's X(t), whether the drive comes from the model or is read back from
//! the pattern's marked creases and frames (as `foldsynth simulate` reads a design file);
//! the flasher's flat layout with one free vertex of one sector moved by 1e-2 no longer
//! reproduces the PTU's motion; and a side whose midpoint left the side's line (two halves
//! turning one facet about two lines) is refused, not simulated.

#[path = "common/designs.rs"]
mod designs;
use designs::FLASHER_1_9;
use foldsynth::grammar::CreaseGraph;
use foldsynth::model::Model;
use foldsynth::model::numeric::{Evaluated, sample_times};
use foldsynth::simulate::Drive;
use foldsynth::simulate::crossval::{
    CrossvalOptions, CrossvalReport, G0Drive, GAMMA_TOL, POSITION_TOL, crossval, crossval_design,
    design_drive, g0_input,
};
use foldsynth::task::Task;

/// Steps of every simulation here (the thesis's 30).
const STEPS: usize = 30;

/// The model of `graph` of the bundled task `name`, and its full variable vector from
/// `design` (every free variable by name).
fn model(name: &str, graph: &str, design: &[(&str, f64)]) -> (Model, Vec<f64>) {
    let path = format!("{}/grammar/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let task = Task::load(std::path::Path::new(&path)).unwrap();
    let graph = CreaseGraph::from_sequence(&task, graph).unwrap();
    let model = Model::new(&graph, &task, 0).unwrap();
    let free: Vec<f64> = model
        .free
        .iter()
        .map(|&i| {
            let name = &model.plan.variables[i].name;
            design
                .iter()
                .find(|d| d.0 == name)
                .unwrap_or_else(|| panic!("no value for {name}"))
                .1
        })
        .collect();
    assert_eq!(
        free.len(),
        design.len(),
        "{name}: every value names a free variable"
    );
    let vars = model.full_vars(&free);
    (model, vars)
}

/// The star's design of graph "1, (9, 20), 9, (10, 19), (16, 17)", modes up, up (flat area
/// 34.41), printed by `foldsynth model grammar/star.toml --graph "1, (9, 20), 9, (10, 19),
/// (16, 17)" --optimize --json` (32 starts, seed 0).
const STAR: [(&str, f64); 6] = [
    ("α_9", 0.8201520610108083),
    ("l_1,9", 2.0),
    ("α_17", 0.7232110934457249),
    ("l_9,17", 2.0),
    ("α_18", 1.8614637283800162),
    ("l_9,18", 2.0),
];

fn describe(r: &CrossvalReport) -> String {
    format!(
        "Γ {:e}, max |x − X| {:e}, drive {:e}, {} compared, {} widened",
        r.gamma, r.max_position_error, r.drive_error, r.compared_states, r.widened_states
    )
}

/// The design agrees with the PTU driven by the model's actuation, and by the actuation
/// read back from its pattern.
fn agrees(name: &str, graph: &str, design: &[(&str, f64)]) {
    let (model, vars) = model(name, graph, design);
    let modes = vec![1.0; model.plan.n_modes];
    let start = std::time::Instant::now();
    let r = crossval_design(
        &model,
        vars.clone(),
        modes.clone(),
        STEPS,
        &CrossvalOptions::default(),
    )
    .unwrap();
    let iterations: usize = r.sim.steps.iter().map(|s| s.iterations).sum();
    eprintln!(
        "{name}: {}; {iterations} solver iterations in {:.2} s",
        describe(&r),
        start.elapsed().as_secs_f64()
    );
    let fixed = r.fixed_face.expect("a central facet stays fixed");
    assert_eq!(r.driven_edges.len(), 8, "four sides, two halves each");
    assert_eq!(r.compared_states, STEPS);
    assert!(
        r.agrees(GAMMA_TOL, POSITION_TOL) && r.max_position_error <= POSITION_TOL,
        "{name}: {}",
        describe(&r)
    );
    assert!(r.rigid && r.max_delta <= GAMMA_TOL);
    // The prescribed facets are the PTU's own maps of those facets.
    assert!(r.drive_error <= 1e-12, "{name}: {}", describe(&r));

    // A design file carries the marked creases and the frames only: the same fixed facet
    // and the same agreement, the drive's "-t" read from the frames.
    let design = Evaluated::new(&model.plan, vars, modes);
    let pattern = design.pattern(&sample_times(model.t_max, STEPS + 1));
    let drive = G0Drive::from_frames(&pattern).unwrap();
    assert_eq!(drive.fixed_face(), Some(fixed));
    let r = crossval(&pattern, &drive, &CrossvalOptions::default()).unwrap();
    assert!(
        r.agrees(GAMMA_TOL, POSITION_TOL),
        "{name}, from its pattern: {}",
        describe(&r)
    );
}

#[test]
fn a_flasher_cuboid_design_agrees_with_the_ptu() {
    agrees("flasher_cuboid", "1, 9", &FLASHER_1_9);
}

#[test]
fn a_star_design_agrees_with_the_ptu() {
    agrees("star", "1, (9, 20), 9, (10, 19), (16, 17)", &STAR);
}

/// The flasher design's pattern with its PTU frames, its drive, and the vertices that
/// drive fixes or moves (the rest are free).
fn flasher_pattern() -> (Model, foldsynth::pattern::Pattern, G0Drive, Vec<usize>) {
    let (model, vars) = model("flasher_cuboid", "1, 9", &FLASHER_1_9);
    let modes = vec![1.0; model.plan.n_modes];
    let design = Evaluated::new(&model.plan, vars, modes);
    let pattern = design.pattern(&sample_times(model.t_max, STEPS + 1));
    let drive = design_drive(&model).unwrap();
    let input = g0_input(&pattern, &drive, 0.0, model.t_max, STEPS).unwrap();
    let mut prescribed = input.fixed.clone();
    prescribed.extend(input.drives.iter().filter_map(|d| match d {
        Drive::Trajectory { vertex, .. } => Some(*vertex),
        Drive::Crease { .. } => None,
    }));
    (model, pattern, drive, prescribed)
}

#[test]
fn the_flasher_with_one_free_vertex_moved_disagrees() {
    let (model, mut pattern, drive, prescribed) = flasher_pattern();
    // The free vertices are the sectors' outer ones (the first layer's vertices lie on the
    // driven sides' outer facets): move the first by 1e-2 in one sector only.
    let v = (0..pattern.vertices.len())
        .find(|v| !prescribed.contains(v))
        .expect("a free vertex");
    pattern.vertices[v][0] += 1e-2;
    let r = crossval(&pattern, &drive, &CrossvalOptions::default()).unwrap();
    eprintln!(
        "v{} moved by 1e-2: {}",
        model.plan.vertices[v].name,
        describe(&r)
    );
    assert!(!r.agrees(GAMMA_TOL, POSITION_TOL), "{}", describe(&r));
    assert!(r.max_position_error > 1e-3, "{}", describe(&r));
    // Still rigid: its sectors are trees of degree-4 vertices, so the bars fold it without
    // distortion; what gives it away is that it no longer moves as the PTU's design does.
    assert!(r.gamma <= GAMMA_TOL, "{}", describe(&r));
}

#[test]
fn a_side_broken_at_its_midpoint_is_refused() {
    let (model, mut pattern, drive, _) = flasher_pattern();
    let face = drive.fixed_face().unwrap();
    // A side's midpoint (a vertex of the central facet that no PTU folds) moved off its
    // side: the two halves no longer lie on one line, so they would turn the outer facet
    // about two different lines.
    let m = *pattern.faces[face]
        .iter()
        .find(|v| !model.plan.internal.contains(v))
        .expect("a midpoint on the central facet");
    let [x, y] = pattern.vertices[m];
    let r = x.hypot(y);
    pattern.vertices[m] = [x * (1.0 + 1e-2 / r), y * (1.0 + 1e-2 / r)];
    let e = crossval(&pattern, &drive, &CrossvalOptions::default()).unwrap_err();
    assert!(
        matches!(
            e,
            foldsynth::simulate::crossval::CrossvalError::ConflictingPrescription { gap, .. }
                if gap > 1e-3
        ),
        "{e}"
    );
}
