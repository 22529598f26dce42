//! Symmetric patterns from a driven central facet (issue 46): the grammar grows one
//! orbit representative and its rotations follow, r2 joins a vertex with one of the
//! neighbouring sector's, and the model folds every corner (two driven creases each) by
//! its own PTU. Facts checked: the folded pattern is the representative's turned by the
//! symmetry at every t (its images' folded positions are the rotations of its
//! own, computed independently), every facet map is a rigid motion that keeps shared
//! vertices together (closure); the compiled model equals these f64 kinematics (≤ 1e-12)
//! and its gradients agree with central differences.

#![allow(clippy::needless_range_loop)] // coordinates by index read as the formulas

mod common;
#[path = "common/designs.rs"]
mod designs;
use common::{assert_gradients, smooth};
use foldsynth::grammar::CreaseGraph;
use foldsynth::model::geometry;
use foldsynth::model::plan::{Plan, Position};
use foldsynth::task::Task;

const FLASHER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/flasher_layer.toml");

/// Deterministic pseudo-random numbers in [0, 1).
fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// Variables inside their boxes, the sectors small enough for a convex corner.
fn variables(plan: &Plan, seed: u64) -> Vec<f64> {
    let mut s = seed;
    plan.variables
        .iter()
        .map(|v| match v.kind {
            foldsynth::grammar::VarKind::Length => 0.8 + lcg(&mut s),
            _ => 0.6 + 0.5 * lcg(&mut s),
        })
        .collect()
}

/// Free variables of `m` strictly inside their bounds (20–80 % of each range).
fn interior(m: &foldsynth::model::Model, s: &mut u64) -> Vec<f64> {
    m.free
        .iter()
        .map(|&i| {
            let (lo, hi) = m.var_bounds(i);
            lo + (0.2 + 0.6 * lcg(s)) * (hi - lo)
        })
        .collect()
}

/// Every assignment of ±1 to `n` modes.
fn mode_assignments(n: usize) -> impl Iterator<Item = Vec<f64>> {
    (0..1u32 << n).map(move |bits| {
        (0..n)
            .map(|k| if bits >> k & 1 == 1 { -1.0 } else { 1.0 })
            .collect()
    })
}

/// Whether every vertex folds within its rigid range (Eq. 25) in `folded`: the PTU folds a
/// vertex only there.
fn rigid(folded: &geometry::Folded<f64>) -> bool {
    !folded
        .states
        .iter()
        .flatten()
        .any(|s| s.margins.iter().any(|m| m.is_nan() || *m < 0.0))
}

/// Every image's 3D position is its representative's under the image's isometry (in the
/// plane of the fixed facet, z kept), computed independently by the plan.
fn assert_images(
    plan: &Plan,
    flat: &geometry::Flat<f64>,
    folded: &geometry::Folded<f64>,
    what: &str,
) {
    for (i, &(rep, g)) in plan.orbit.iter().enumerate() {
        let a = geometry::position(plan, flat, folded, rep);
        let b = geometry::position(plan, flat, folded, i);
        let m = &plan.isometries[g].m;
        let image = [
            m[0][0] * a[0] + m[0][1] * a[1],
            m[1][0] * a[0] + m[1][1] * a[1],
            a[2],
        ];
        for k in 0..3 {
            assert!(
                (image[k] - b[k]).abs() < 1e-9,
                "{what}: v{} is not the image of v{}: {b:?} vs {image:?}",
                i + 1,
                rep + 1
            );
        }
    }
}

#[test]
fn flasher_layer_is_rotationally_symmetric_rigid_and_closed_at_every_t() {
    let task = Task::load(FLASHER).unwrap();
    for seq in ["1", "1, (9, 20)", "1, (9, 20), 9"] {
        let graph = CreaseGraph::from_sequence(&task, seq).unwrap();
        let plan = Plan::new(&graph).unwrap();
        assert_eq!(plan.isometries.len(), 4, "{seq}");
        assert_eq!(
            plan.actuation.driven.len(),
            8,
            "four sides, two halves each"
        );
        assert!(plan.actuation.fixed.is_some(), "the central facet stays");
        let images = plan
            .vertices
            .iter()
            .filter(|v| matches!(v.position, Position::Image { .. }))
            .count();
        assert!(
            images >= 6,
            "{seq}: three images of each vertex r1 made (less those r2 merged), got {images}"
        );
        let mut checked = 0;
        for seed in 1..12 {
            let vars = variables(&plan, seed);
            let flat = geometry::flat(&plan, &vars);
            for (i, &(rep, g)) in plan.orbit.iter().enumerate() {
                let iso = &plan.isometries[g];
                let p = iso.apply([flat.pos[rep][0], flat.pos[rep][1]]);
                for k in 0..2 {
                    assert!(
                        (p[k] - flat.pos[i][k]).abs() < 1e-12,
                        "{seq}: flat v{}",
                        i + 1
                    );
                }
            }
            let modes = vec![1.0; plan.n_modes];
            // From t > 0: at the flat state the PTU is at a branch point (θ = π, φ of √ε noise).
            for step in 1..=6 {
                let t = step as f64 * 0.25;
                let folded = geometry::fold(&plan, &flat, &modes, &t);
                if !rigid(&folded) {
                    continue;
                }
                checked += 1;
                // Closure: every vertex at one place through each of its facets.
                for (f, (poly, _)) in plan.polygons.iter().enumerate() {
                    for &v in poly {
                        let a = geometry::position(&plan, &flat, &folded, v);
                        let b = geometry::position_on(&flat, &folded, v, f);
                        for k in 0..3 {
                            assert!((a[k] - b[k]).abs() < 1e-9, "{seq}: closure at v{}", v + 1);
                        }
                    }
                }
                // Symmetry: an image's 3D position is its representative's turned about z
                // (the central facet, fixed, is centred on the origin).
                assert_images(&plan, &flat, &folded, &format!("{seq} at t {t}"));
                // Every facet map is a rotation.
                for r in &folded.rot {
                    for a in 0..3 {
                        for b in 0..3 {
                            let d: f64 = (0..3).map(|k| r[k][a] * r[k][b]).sum();
                            let e = if a == b { 1.0 } else { 0.0 };
                            assert!((d - e).abs() < 1e-12);
                        }
                    }
                }
            }
            assert!(
                checked >= 2,
                "{seq}: seed {seed} folds rigidly at {checked} states"
            );
        }
        assert!(
            checked >= 6,
            "{seq}: rigid at only {checked} sampled states"
        );
    }
}

#[test]
fn side_vertex_joins_two_sectors() {
    let task = Task::load(FLASHER).unwrap();
    let graph = CreaseGraph::from_sequence(&task, "1, (9, 20)").unwrap();
    let plan = Plan::new(&graph).unwrap();
    // Four merged side vertices, each with two incoming creases from two corners.
    let sides: Vec<usize> = (0..plan.vertices.len())
        .filter(|&v| plan.vertices[v].preds == 2 && !plan.vertices[v].internal)
        .collect();
    assert_eq!(sides.len(), 4, "one side vertex per side");
    for &v in &sides {
        let tails: Vec<usize> = plan.vertices[v].rays[..2].iter().map(|r| r.other).collect();
        assert_ne!(
            plan.orbit[tails[0]].1, plan.orbit[tails[1]].1,
            "from two sectors"
        );
    }
}

#[test]
fn corners_with_two_driven_creases_compile_to_the_f64_kinematics_and_their_gradients() {
    use foldsynth::compile::Options;
    use foldsynth::model::Model;
    use foldsynth::model::compiled::{CompiledModel, ModelProblem, outputs_f64};
    use foldsynth::optimize::{self, Evaluation, Problem};
    let task = Task::load(FLASHER).unwrap();
    let (mut compared, mut differentiated) = (0, 0);
    for seq in ["1", "1, 9", "1, (9, 20)", "1, 11, (9, 32)"] {
        let graph = CreaseGraph::from_sequence(&task, seq).unwrap();
        let model = Model::new(&graph, &task, 0).unwrap();
        let compiled = CompiledModel::new(&model, &Options::default()).unwrap();
        let mut buf = vec![0.0; compiled.buffer_len()];
        for bits in 0..(1u32 << model.plan.n_modes) {
            let modes: Vec<f64> = (0..model.plan.n_modes)
                .map(|i| if bits >> i & 1 == 1 { -1.0 } else { 1.0 })
                .collect();
            let problem = ModelProblem::new(&model, &compiled, &modes);
            let mut e = Evaluation::new(problem.n_vars(), problem.n_constraints());
            let points = optimize::quasi_random_points(model.free.len(), 60, 5 + bits as u64);
            for u in &points {
                let x: Vec<f64> = u
                    .iter()
                    .zip(&model.free)
                    .map(|(u, &i)| {
                        let (lo, hi) = model.var_bounds(i);
                        lo + (hi - lo) * u
                    })
                    .collect();
                // The compiled model is the f64 kinematics, every output (≤ 1e-12 relative).
                compiled.call(&x, &compiled.params(&model, &modes), &mut buf);
                let (f, g) = outputs_f64(&model, &x, &modes);
                let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0);
                assert!(close(buf[0], f), "{seq}: objective {} vs {f}", buf[0]);
                for (k, gk) in g.iter().enumerate() {
                    assert!(
                        close(buf[k + 1], *gk) || (gk.is_nan() && buf[k + 1].is_nan()),
                        "{seq}: {}: {} vs {gk}",
                        model.constraint_label(k),
                        buf[k + 1]
                    );
                }
                compared += 1;
                problem.eval(&x, &mut e);
                if e.g.iter().any(|g| g.abs() < 1e-2) || !smooth(&model, &x, &modes) {
                    continue;
                }
                differentiated += 1;
                assert_gradients(&model, &e, &x, &modes, seq);
            }
        }
    }
    assert!(compared >= 400, "{compared} points compared");
    assert!(
        differentiated >= 20,
        "only {differentiated} smooth points differentiated"
    );
}

/// The rigid flasher of Fig. 32c in the thesis's own construction (Sec. 4.3.1): every
/// corner of the central facet extended by three creases, two of them from neighbouring
/// corners joined at one side vertex on each side (v1 of Fig. 32), then v1 and the
/// diagonal's end v2 extended with their rotations, whose new creases meet in the second
/// layer's vertices, each joined to one side vertex and one diagonal end (the adapted
/// flasher's v4 and v5, Sec. 3.5.3).
const RIGID_FLASHER: &str = "1, (9, 20), 9, 10, (17, 40), (19, 29)";

#[test]
fn the_rigid_flasher_is_a_meaningful_graph_of_the_cuboid_task() {
    use foldsynth::grammar::{Enumeration, Filters};
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/flasher_cuboid.toml");
    let task = Task::load(file).unwrap();
    let e = Enumeration::run(&task, 3, Filters::all());
    let node = e
        .meaningful()
        .find(|n| n.graph.sequence() == RIGID_FLASHER)
        .expect("the rigid flasher is enumerated");
    let plan = Plan::new(&node.graph).unwrap();
    // Three extended orbits of four: corners, side vertices, diagonal ends.
    assert_eq!(plan.internal.len(), 12);
    let corners: Vec<usize> = (0..4).collect();
    for &c in &corners {
        // Degree 5: two driven creases of the central facet, three from the grammar.
        assert_eq!(plan.vertices[c].rays.len(), 5, "corner v{}", c + 1);
    }
    let sector_of = |v: usize| plan.orbit[v].1;
    // Every vertex with two incoming creases, with their tails.
    let pred_sets: Vec<(usize, Vec<usize>)> = (0..plan.vertices.len())
        .filter(|&v| plan.vertices[v].preds == 2)
        .map(|v| {
            (
                v,
                plan.vertices[v].rays[..2].iter().map(|r| r.other).collect(),
            )
        })
        .collect();
    // Side vertices: two corners of the central facet from neighbouring sectors.
    let side_vertices: Vec<usize> = pred_sets
        .iter()
        .filter(|(_, p)| p.iter().all(|v| corners.contains(v)))
        .map(|(v, p)| {
            assert_ne!(sector_of(p[0]), sector_of(p[1]));
            *v
        })
        .collect();
    assert_eq!(side_vertices.len(), 4, "one side vertex per side");
    // Second layer: 8 vertices, each joined to one side vertex and one diagonal end (a
    // corner's successor that is not a side vertex).
    let layer2: Vec<&Vec<usize>> = pred_sets
        .iter()
        .map(|(_, p)| p)
        .filter(|p| p.iter().any(|v| side_vertices.contains(v)))
        .collect();
    assert_eq!(layer2.len(), 8, "{pred_sets:?}");
    for p in &layer2 {
        let diagonal_end = p.iter().find(|v| !side_vertices.contains(v)).unwrap();
        let from = plan.vertices[*diagonal_end].rays[0].other;
        assert!(
            corners.contains(&from),
            "v{} grows from a corner",
            diagonal_end + 1
        );
    }
}

#[test]
fn one_mode_per_vertex_folds_each_image_by_its_own_choice() {
    let task = Task::load(FLASHER).unwrap();
    let graph = CreaseGraph::from_sequence(&task, "1, 9").unwrap();
    let plan = Plan::new(&graph).unwrap().with_vertex_modes();
    assert_eq!(
        plan.n_modes, 8,
        "four corners and four vertices of the first layer"
    );
    // The 54.8 design of this graph, rigid over its motion.
    let design = designs::FLASHER_1_9;
    let vars: Vec<f64> = plan
        .variables
        .iter()
        .map(|v| design.iter().find(|d| d.0 == v.name).unwrap().1)
        .collect();
    let flat = geometry::flat(&plan, &vars);
    let t = 0.6;
    let up = geometry::fold(&plan, &flat, &[1.0; 8], &t);
    assert!(
        up.states
            .iter()
            .flatten()
            .all(|s| s.margins.iter().all(|m| *m > 0.0))
    );
    let pos = |f: &geometry::Folded<f64>, v: usize| geometry::position(&plan, &flat, f, v);
    for k in 0..8 {
        let mut modes = vec![1.0; 8];
        modes[k] = -1.0;
        let one = geometry::fold(&plan, &flat, &modes, &t);
        let v = plan.internal[k];
        // The vertex itself stays where its predecessors put it; at least one successor
        // moves (the other PTU solution), and a vertex of another sector that does not
        // descend from it stays.
        let moved: Vec<usize> = (0..plan.vertices.len())
            .filter(|&w| {
                let (a, b) = (pos(&up, w), pos(&one, w));
                (0..3).any(|i| (a[i] - b[i]).abs() > 1e-6)
            })
            .collect();
        assert!(!moved.is_empty(), "flipping v{} moves nothing", v + 1);
        assert!(!moved.contains(&v), "v{} moved by its own mode", v + 1);
        assert!(
            moved.len() < plan.vertices.len() / 2,
            "flipping v{} moved {} of {} vertices",
            v + 1,
            moved.len(),
            plan.vertices.len()
        );
    }
}

/// The flasher test task with every `(from, to)` edit applied (each must occur), loaded.
fn flasher_edited(edits: &[(&str, &str)]) -> foldsynth::task::TaskError {
    let mut text = std::fs::read_to_string(FLASHER).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{from}");
        text = text.replacen(from, to, 1);
    }
    match Task::from_toml_str(&text, "bad.toml") {
        Ok(_) => panic!("accepted with {edits:?}"),
        Err(e) => e,
    }
}

#[test]
fn driven_polygons_that_cannot_work_are_refused_naming_the_field() {
    let refused = |e: foldsynth::task::TaskError, field: &str, words: &str| {
        assert_eq!(e.file, "bad.toml");
        assert_eq!(e.field, field, "{e}");
        assert!(e.message.contains(words), "`{words}` not in: {e}");
        assert!(
            e.to_string().starts_with(&format!("bad.toml: {field}: ")),
            "{e}"
        );
    };
    // Not simple: b and c swapped, the chain a → b → c → d is a bow tie.
    refused(
        flasher_edited(&[
            ("xy = [-1.0, 1.0]", "xy = [-1.0, -9.0]"),
            ("xy = [-1.0, -1.0]", "xy = [-1.0, 1.0]"),
            ("xy = [-1.0, -9.0]", "xy = [-1.0, -1.0]"),
        ]),
        "initial_graph.creases[2]",
        "must be a simple polygon",
    );
    // Not convex: corner b pushed onto the diagonal, its two driven creases no longer
    // spanning a sector below 180° (no Euler triangle).
    refused(
        flasher_edited(&[("xy = [-1.0, 1.0]", "xy = [0.2, 0.2]")]),
        "initial_graph.vertices[1]",
        "convex at every corner",
    );
    // A side labelled from the other facet: the central facet's chain no longer leaves
    // every corner one open sector for the grammar's creases.
    const NO_SYMMETRY: (&str, &str) = ("[symmetry]\nrotations = 4\ncenter = [0.0, 0.0]", "");
    refused(
        flasher_edited(&[
            NO_SYMMETRY,
            (
                "left = \"center\"\nright = \"west\"",
                "left = \"west\"\nright = \"center\"",
            ),
        ]),
        "initial_graph.creases",
        "exactly one open sector",
    );
}

const CHAIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/mirror_chair.toml");
const CHAIR_PLAIN: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/mirror_chair_plain.toml"
);

/// The cycle sweeps of `seq` on `task` at `draws` random interior geometries, every mode
/// assignment: only those where the r2′ crease really folds (> 0.05 rad) on some checked
/// state, where the sweep has something to say.
fn folding_cycles(task: &str, seq: &str, draws: u64) -> Vec<foldsynth::check::cycle::CycleReport> {
    use foldsynth::model::Model;
    use foldsynth::model::numeric::{Evaluated, sample_times};
    let task = Task::load(task).unwrap();
    let graph = CreaseGraph::from_sequence(&task, seq).unwrap();
    assert!(graph.is_cyclic_pattern(), "{seq}");
    let m = Model::new(&graph, &task, 0).unwrap();
    let ts = sample_times(m.t_max, 91);
    let mut out = Vec::new();
    let mut s = 46;
    for _ in 0..draws {
        let x = interior(&m, &mut s);
        for modes in mode_assignments(m.plan.n_modes) {
            let d = Evaluated::new(&m.plan, m.full_vars(&x), modes);
            let r = foldsynth::check::cycle::verify_cycles(&d, &ts, 1e-12);
            if r.checked_states > 0 && r.shared_fold_max > 0.05 {
                out.push(r);
            }
        }
    }
    out
}

#[test]
fn a_crease_across_the_mirror_axis_is_overconstrained_yet_compatible() {
    // Sec. 4.3.3: the chair's crease v5–v5' crosses the axis; both ends' PTU give its
    // dihedral angle, and by symmetry they agree (ρ_{5,5'} = ρ_{5',5}) at every geometry
    // and every state, so the overconstrained pattern folds rigidly. Here v4 (a successor
    // of G0's end a) is extended and a successor of it joins its mirror image's on the
    // axis; in the second graph a second crease crosses the axis further out.
    for seq in ["1, 4, (10, 15)'", "1, 4, (5, 12), (9, 13)'"] {
        let rs = folding_cycles(CHAIR, seq, 60);
        assert!(rs.len() >= 5, "{seq}: {} folding draws", rs.len());
        for r in &rs {
            assert!(r.compatibility_max <= 1e-9, "{seq}: {r:?}");
            assert!(r.position_max <= 1e-9, "{seq}: {r:?}");
        }
    }
    // The same pattern without the symmetry (a, b, v4 and its mirror image v9 extended by
    // variables of their own): the thesis's "if any of the vertices were to change location, any deviation
    // of ρ_d would lead to a non-rigid motion". Almost no geometry is compatible.
    let rs = folding_cycles(CHAIR_PLAIN, "1, 2, 4, 9, (10, 15)'", 60);
    assert!(rs.len() >= 5, "{} folding draws", rs.len());
    let compatible = rs.iter().filter(|r| r.compatibility_max <= 1e-6).count();
    assert!(
        compatible * 10 <= rs.len(),
        "{compatible} of {} asymmetric draws compatible",
        rs.len()
    );
}

#[test]
fn a_mirrored_pattern_folds_into_its_own_mirror_image() {
    // The chair's G0 with mirror_axis x = 0: every image of a vertex lies, flat and folded
    // at every rigid state, at its representative's mirror image (x → −x; the driven
    // crease crosses the axis at a right angle), with the seat fixed and with the crease
    // folded symmetrically (±ρ/2: the split crease's two halves turn the same two facets).
    let text = std::fs::read_to_string(CHAIR).unwrap();
    let symmetric = text.replace("[initial_graph]\nfixed = \"seat\"\n", "");
    assert_ne!(symmetric, text);
    let fixed = Task::load(CHAIR).unwrap();
    let folded_both_ways = Task::from_toml_str(&symmetric, "mirror_chair.toml").unwrap();
    for (task, seq) in ["1", "1, 4", "1, 4, (10, 15)'"]
        .into_iter()
        .flat_map(|s| [(&fixed, s), (&folded_both_ways, s)])
    {
        let graph = CreaseGraph::from_sequence(task, seq).unwrap();
        let m = foldsynth::model::Model::new(&graph, task, 0).unwrap();
        let plan = &m.plan;
        assert_eq!(plan.isometries.len(), 2, "{seq}");
        // Both facets of the one driven crease bound it; the one the task names stays.
        let stays = plan.actuation.fixed.map(|f| plan.facet_names[f].as_str());
        let named = matches!(
            task.initial.actuation,
            foldsynth::task::G0Actuation::Fixed { .. }
        )
        .then_some("seat");
        assert_eq!(stays, named, "{seq}");
        let mut checked = 0;
        let mut s = 37;
        for _ in 1..40 {
            let flat = geometry::flat(plan, &m.full_vars(&interior(&m, &mut s)));
            for (i, &(rep, _)) in plan.orbit.iter().enumerate() {
                let (p, q) = (flat.pos[rep], flat.pos[i]);
                let mirrored = (p[0] + q[0]).abs() < 1e-12 && (p[1] - q[1]).abs() < 1e-12;
                let same = (p[0] - q[0]).abs() < 1e-12 && (p[1] - q[1]).abs() < 1e-12;
                assert!(mirrored || same, "{seq}: flat v{} vs v{}", i + 1, rep + 1);
            }
            for modes in mode_assignments(plan.n_modes) {
                for step in 1..=6 {
                    let t = step as f64 * 0.25;
                    let folded = geometry::fold(plan, &flat, &modes, &t);
                    if !rigid(&folded) {
                        continue;
                    }
                    checked += 1;
                    assert_images(
                        plan,
                        &flat,
                        &folded,
                        &format!("{seq} modes {modes:?} at t {t}"),
                    );
                }
            }
        }
        assert!(
            checked >= 6,
            "{seq}: rigid at only {checked} sampled states"
        );
    }
}
