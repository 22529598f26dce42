//! The bundled tasks of the task language (issue 31), each run for real: every design the
//! search reports meets every requirement on the dense sweep as `check::requirements`
//! judges it (code that shares nothing with the optimizer's constraints), read here from
//! the figures themselves rather than from the verdict alone: each orientation's worst
//! error within its tolerance, each obstacle's least clearance at least
//! `obstacle_clearance`, each containment box's walls kept, no crossing between copies, Ω
//! within the threshold, the area at least `at_least`.
//!
//! The two grippers run with N_max = 2 (the full N_max = 3 runs are in docs/tasks.md); the
//! arm tasks and the cuboid need N_max = 3 for any design.

use serde_json::Value;
use std::path::Path;

#[path = "common/runs.rs"]
#[allow(dead_code)] // only the runner is used here
mod runs;
use runs::foldsynth_ok;

/// Run `task` (a file in `grammar/`) with N_max = `n_max`; its design JSONs.
fn designs(task: &str, n_max: &str) -> Vec<Value> {
    let dir = tempfile::tempdir().unwrap();
    let file = format!("{}/grammar/{task}.toml", env!("CARGO_MANIFEST_DIR"));
    let out = dir.path().join("run");
    foldsynth_ok(&[
        "synthesize",
        &file,
        "--n-max",
        n_max,
        "--no-export",
        "--out",
        out.to_str().unwrap(),
    ]);
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
    let ds = designs(task, n_max);
    assert!(!ds.is_empty(), "{task}: no design with N_max = {n_max}");
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
