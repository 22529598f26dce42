//! The bundled tasks of the task language (issue 31), each run for real: every design the
//! search reports meets every requirement on the dense sweep as `check::requirements`
//! judges it (code that shares nothing with the optimizer's constraints), read here from
//! the figures themselves rather than from the verdict alone: each orientation's worst
//! error within its tolerance, each obstacle's least clearance at least
//! `obstacle_clearance`, each containment box's walls kept, no crossing between copies, Ω
//! within the threshold, the area at least `at_least`.
//!
//! The two grippers run with N_max = 2 (the full N_max = 3 runs are in docs/tasks.md); the
//! arm tasks and the cuboid need N_max = 3 for any design; the flasher cuboid runs with
//! N_max = 2 (its N_max = 3 figures are in docs/pattern_families.md), the rigid flasher
//! its one topology (`--graph`).

use serde_json::Value;
use std::path::Path;

#[path = "common/runs.rs"]
#[allow(dead_code)] // only the runner is used here
mod runs;
use runs::foldsynth_ok;

/// Run `task` (a file in `grammar/`) with the options `args`; its design JSONs.
fn designs(task: &str, args: &[&str]) -> Vec<Value> {
    let dir = tempfile::tempdir().unwrap();
    let file = format!("{}/grammar/{task}.toml", env!("CARGO_MANIFEST_DIR"));
    let out = dir.path().join("run");
    let mut all_args = vec![
        "synthesize",
        &file,
        "--no-export",
        "--out",
        out.to_str().unwrap(),
    ];
    all_args.extend_from_slice(args);
    foldsynth_ok(&all_args);
    let mut all = Vec::new();
    for e in std::fs::read_dir(out.join("designs")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "json") {
            all.push(serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap());
        }
    }
    all
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// Every figure of one design's requirements report meets its requirement.
fn assert_meets_everything(task: &str, d: &Value) {
    let id = d["id"].as_str().unwrap();
    let r = &d["requirements"];
    assert!(r.is_object(), "{task} {id}: no requirements report");
    assert_eq!(r["holds"], true, "{task} {id}: {}", r["failed"]);
    for o in r["orientations"].as_array().unwrap() {
        assert!(
            num(&o["worst_error"]) <= num(&o["tolerance"]),
            "{task} {id}: {o}"
        );
        assert!(
            o["missing"].as_array().unwrap().is_empty(),
            "{task} {id}: {o}"
        );
    }
    for o in r["obstacles"].as_array().unwrap() {
        assert!(num(&o["least"]) >= num(&o["clearance"]), "{task} {id}: {o}");
    }
    for c in r["containment"].as_array().unwrap() {
        assert!(num(&c["least"]) >= num(&c["clearance"]), "{task} {id}: {c}");
    }
    if let Some(c) = r["copies"].as_object() {
        assert_eq!(c["crossings"], 0, "{task} {id}: copies cross");
    }
    if let Some(t) = r["targets"].as_object() {
        assert!(
            num(&t["omega"]) <= num(&t["threshold"]),
            "{task} {id}: Ω {t:?}"
        );
    }
    if let Some(a) = r["area"].as_object() {
        assert!(
            num(&a["value"]) >= num(&a["at_least"]),
            "{task} {id}: area {a:?}"
        );
    }
}

fn check_task(task: &str, n_max: &str, what: &[&str]) -> Vec<Value> {
    check_task_with(task, &["--n-max", n_max], what)
}

/// As [`check_task`], with the search's options `args`.
fn check_task_with(task: &str, args: &[&str], what: &[&str]) -> Vec<Value> {
    let ds = designs(task, args);
    assert!(!ds.is_empty(), "{task}: no design with {args:?}");
    for d in &ds {
        assert_meets_everything(task, d);
        // The terms the task states are the ones judged.
        for w in what {
            let r = &d["requirements"][w];
            let stated = r.as_array().map_or(!r.is_null(), |a| !a.is_empty());
            assert!(stated, "{task}: {w} not judged");
        }
    }
    ds
}

#[test]
fn gripper_with_fingertips_down_over_a_plate() {
    check_task(
        "gripper_down",
        "2",
        &["orientations", "obstacles", "copies"],
    );
}

#[test]
fn gripper_around_a_part_from_an_stl_mesh() {
    let ds = check_task("gripper_part", "2", &["obstacles", "copies"]);
    assert_eq!(ds[0]["requirements"]["obstacles"][0]["kind"], "mesh");
}

#[test]
fn robotic_arm_past_a_box_above_a_table() {
    let ds = check_task("robotic_arm_obstacles", "3", &["obstacles", "targets"]);
    // The path of 11 samples is judged at each of its states.
    assert_eq!(
        ds[0]["requirements"]["targets"]["targets"]
            .as_array()
            .unwrap()
            .len(),
        11
    );
}

#[test]
fn drawing_arm_keeps_its_tip_on_the_plane() {
    let ds = check_task("drawing_arm", "3", &["orientations", "targets"]);
    for d in &ds {
        // 10 plane samples and the end point, each within the threshold on its own.
        let t = d["requirements"]["targets"]["targets"].as_array().unwrap();
        assert_eq!(t.len(), 11);
        for x in t {
            assert!(num(&x["distance"]) <= 0.05, "{x}");
        }
    }
}

#[test]
fn cuboid_four_copies_with_flat_area_inside_the_box() {
    let ds = check_task("cuboid_area", "3", &["containment", "copies", "area"]);
    for d in &ds {
        let area = num(&d["requirements"]["area"]["value"]);
        // Four copies of an arm with G0's crease 0.5 and lengths ≤ 1 cannot exceed the
        // flat area of four discs of radius 2.5 (a loose bound; the area is a real sum).
        assert!(area > 0.0 && area < 4.0 * std::f64::consts::PI * 2.5 * 2.5);
    }
}

#[test]
fn flasher_cuboid_beats_the_thesis_simulated_annealing() {
    // Sec. 3.4 with the driven central facet of Fig. 32: the thesis's SA reached a flat
    // area of 44.0 (Fig. 17) on one fixed topology; the grammar's first two layers do better.
    let ds = check_task("flasher_cuboid", "2", &["containment", "area"]);
    let best = ds
        .iter()
        .map(|d| num(&d["requirements"]["area"]["value"]))
        .fold(0.0, f64::max);
    // The box is the thesis's cuboid grown by the clearance the check keeps, so every
    // vertex of the sheet lies in the thesis's cuboid (asserted by check_task).
    assert!(best >= 44.0, "best flat area {best} < the thesis's 44.0");
    assert_one_sheet(&ds[0]);
    ds.iter().for_each(assert_simulated);
}

/// The search cross-checked `d` (driven as its central facet drives it, several creases at
/// once) with the bar-and-hinge simulation of thesis Sec. 3, and the two motions agree.
fn assert_simulated(d: &Value) {
    let s = &d["simulation"];
    assert_eq!(s["agrees"], true, "{}: {s}", d["id"]);
    assert!(num(&s["gamma"]) <= 1e-8, "{}: {s}", d["id"]);
    assert!(num(&s["max_position_error"]) <= 1e-3, "{}: {s}", d["id"]);
}

/// `d`'s FOLD file is the whole sheet, every sector, as one piece of paper: a disc
/// (V − E + F = 1) of the central facet and four equal sectors, which `foldsynth verify`
/// accepts frame by frame.
fn assert_one_sheet(d: &Value) {
    let dir = tempfile::tempdir().unwrap();
    let (json, fold) = (dir.path().join("d.json"), dir.path().join("d.fold"));
    std::fs::write(&json, serde_json::to_vec(d).unwrap()).unwrap();
    foldsynth_ok(&[
        "export",
        json.to_str().unwrap(),
        "--format",
        "fold",
        "--out",
        fold.to_str().unwrap(),
    ]);
    let f: Value = serde_json::from_slice(&std::fs::read(&fold).unwrap()).unwrap();
    let count = |k: &str| f[k].as_array().unwrap().len() as i64;
    let (v, e, faces) = (
        count("vertices_coords"),
        count("edges_vertices"),
        count("faces_vertices"),
    );
    assert_eq!(v - e + faces, 1, "V {v}, E {e}, F {faces}");
    assert_eq!(
        (faces - 1) % 4,
        0,
        "the central facet and four equal sectors"
    );
    foldsynth_ok(&["verify", fold.to_str().unwrap()]);
}

/// The rule sequence of the rigid flasher, Fig. 32c (tests/pattern_families.rs checks its
/// structure).
const RIGID_FLASHER: &str = "1, (9, 20), 9, 10, (17, 40), (19, 29)";

#[test]
fn the_rigid_flasher_folds_into_the_cuboid() {
    // Sec. 4.3.1: "the rigid flasher folds perfectly onto the prescribed cuboid surface".
    // A search of its one topology (all 8 mode assignments) with the Sec. 3.4 cuboid and
    // margins finds a design; the seed and starts are those docs/pattern_families.md
    // reports (seed 1 with as many starts finds none: the feasible set is narrow).
    let ds = check_task_with(
        "rigid_flasher",
        &["--graph", RIGID_FLASHER, "--starts", "300", "--seed", "2"],
        &["containment", "area"],
    );
    for d in &ds {
        assert_eq!(d["sequence"], RIGID_FLASHER);
        // Every facet of every sector clear of every other over the whole motion, every
        // vertex rigid over it, and the sheet one piece of paper.
        assert_eq!(d["self_intersection_free"], true);
        assert_one_sheet(d);
        assert_simulated(d);
    }
    let best = ds
        .iter()
        .map(|d| num(&d["requirements"]["area"]["value"]))
        .fold(0.0, f64::max);
    assert!(best >= 44.0, "best flat area {best} < the thesis's 44.0");
}

#[test]
fn star_pattern_and_its_256_mode_assignments() {
    // Sec. 4.3.2: the first layer of the rigid flasher, each side vertex extended with two
    // creases to the pattern's corners; eight internal vertices.
    const STAR: &str = "1, (9, 20), 9, (10, 19), (16, 17)";
    let ds = check_task("star", "2", &["area"]);
    let star = ds
        .iter()
        .find(|d| d["sequence"] == STAR)
        .expect("the search finds a star design");
    ds.iter().for_each(assert_simulated);
    let dir = tempfile::tempdir().unwrap();
    let at = dir.path().join("star.json");
    std::fs::write(&at, serde_json::to_vec(star).unwrap()).unwrap();
    let task = format!("{}/grammar/star.toml", env!("CARGO_MANIFEST_DIR"));
    let out = foldsynth_ok(&[
        "model",
        &task,
        "--graph",
        STAR,
        "--at",
        at.to_str().unwrap(),
        "--vertex-modes",
        "--json",
    ]);
    let census: Value = serde_json::from_slice(&out).unwrap();
    assert_eq!(census["assignments"], 256);
    // Eq. 25 does not depend on the modes (the thesis, Sec. 4.3.2: they change the unknown
    // angles symmetrically about the flat plane), so a rigid design is rigid in all 256.
    assert_eq!(census["rigid_over_motion"], 256, "{}", census["verdicts"]);
    // The search's own assignment (one mode per orbit, repeated over the four sectors)
    // folds, as the search judged it.
    let own: Vec<String> = star["modes"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|m| std::iter::repeat_n(m.as_str().unwrap().to_string(), 4))
        .collect();
    let verdict = census["verdicts"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| {
            v["modes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|m| m.as_str().unwrap())
                .eq(own.iter().map(String::as_str))
        })
        .unwrap();
    assert_eq!(verdict["self_intersection_free"], true, "{verdict}");
}

#[test]
fn bundled_tasks_load_and_name_their_parts() {
    // The mesh the STL task names is the one its script writes (closed, 256 triangles).
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("grammar/gripper_part.toml");
    let task = foldsynth::task::Task::load(&file).unwrap();
    let mesh = task
        .scene
        .obstacles
        .iter()
        .find_map(|o| match &o.shape {
            foldsynth::scene::Shape::Mesh(m) => m.mesh.clone(),
            _ => None,
        })
        .expect("a loaded mesh");
    assert_eq!(mesh.triangles.len(), 256);
    assert!(mesh.closed);
}

#[test]
fn the_chair_is_its_own_mirror_image_and_stands_on_four_feet() {
    // Sec. 4.3.3: the chair pattern is mirror-symmetric about the vertical axis of the
    // paper and its folded state too: the seat fixed in z = 0, the backrest driven upright,
    // the vertex extended last's outer successors and their mirror images on the floor.
    let ds = check_task("chair", "2", &["containment", "targets", "area"]);
    for d in &ds {
        let id = d["id"].as_str().unwrap();
        let frames = d["pattern"]["frames"].as_array().unwrap();
        let last = frames.last().unwrap();
        assert!((num(&last["t"]) - std::f64::consts::FRAC_PI_2).abs() < 1e-8);
        let pts: Vec<[f64; 3]> = last["coords"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| {
                let p = p.as_array().unwrap();
                [num(&p[0]), num(&p[1]), num(&p[2])]
            })
            .collect();
        // Every folded vertex has its mirror image (x → −x) among the folded vertices (the
        // design file keeps 9 decimals).
        for p in &pts {
            assert!(
                pts.iter().any(|q| (q[0] + p[0]).abs() < 1e-7
                    && (q[1] - p[1]).abs() < 1e-7
                    && (q[2] - p[2]).abs() < 1e-7),
                "{id}: {p:?} has no mirror image"
            );
        }
        // Four feet on the floor z = -1 (the targets' threshold is 1e-4 on Ω), nothing
        // below it, and the backrest standing in the plane of its crease (y = 0).
        let feet = pts.iter().filter(|p| (p[2] + 1.0).abs() < 1e-2).count();
        assert!(feet >= 4, "{id}: {feet} vertices on the floor");
        assert!(pts.iter().all(|p| p[2] >= -1.0102), "{id}: below the floor");
        let upright = pts.iter().any(|p| p[2] > 0.5 && p[1].abs() < 1e-7);
        assert!(
            upright,
            "{id}: no backrest vertex above the seat's back edge"
        );
    }
}
