//! Thickness inside the search (issue 32, part 2).
//!
//! - the robustness block of a task with `[fabrication]` imposes, constraint by constraint,
//!   the zero-thickness task's values lowered by the panels' reach: `reach` per vertex of two
//!   facets apart (their plane keeps `clearance/2 + reach` each side), `reach·|x − apex|`
//!   for facets meeting at a point, `reach` on an obstacle's side, none on the margins; every
//!   crease bounded by the tapered setback limit `2 atan(MAX_SETBACK / reach)`;
//! - that limit is where `reach · tan(ρ/2)` equals `MAX_SETBACK`;
//! - a real run of `grammar/gripper_thick.toml` (N_max = 2): every design's thick panels,
//!   tested as triangle meshes on the dense sweep by `check::thick`, keep the clearance from
//!   each other, the other arm and the cylinder, every design JSON carries the bill, and every
//!   alternative that passes the other checks but not this one says why.

use foldsynth::grammar::{Enumeration, Filters};
use foldsynth::model::Model;
use foldsynth::model::clearance::{Buffers, Effort, PairKind, Plane};
use foldsynth::model::robust::{
    CLEARANCE_FLOOR, Dep, Level, MAX_SETBACK, RobustModel, RobustSpec, SlotOwner, thick_fold_limit,
};
use foldsynth::task::Task;
use std::collections::HashMap;

#[path = "common/runs.rs"]
#[allow(dead_code)] // only the runner is used here
mod runs;

#[path = "common/fab_files.rs"]
mod fab_files;

const GRIPPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml");

const FULL: Effort = Effort {
    enough: f64::INFINITY,
    iters: 64,
    tol: 1e-13,
    axes: true,
};

fn thick_task() -> (Task, Task) {
    let text = std::fs::read_to_string(GRIPPER).unwrap();
    let plain = Task::from_toml_str(&text, GRIPPER).unwrap();
    let thick = Task::from_toml_str(
        &(text + "\n[fabrication]\nthickness = 2\nscale = 100\n"),
        GRIPPER,
    )
    .unwrap();
    (plain, thick)
}

/// Every slot's value at `t` with the given planes: slot → (h, the first vertex's position
/// when the constraint depends on positions).
fn values(
    block: &RobustModel,
    x: &[f64],
    modes: &[f64],
    t: f64,
    planes: &[Option<Plane>],
) -> HashMap<usize, f64> {
    let mut work = block.work();
    block.eval(x, modes, t, &mut work);
    let mut out = HashMap::new();
    block.visit(
        t,
        &work.values,
        planes,
        Level::Imposed,
        |slot, _, h, _: Dep<'_>| {
            out.insert(slot, h);
        },
    );
    out
}

#[test]
fn thick_constraints_are_the_thin_ones_lowered_by_the_reach() {
    let (plain, thick) = thick_task();
    let reach = thick.fabrication.unwrap().reach_units();
    assert_eq!(reach, 0.02);
    let limit = thick_fold_limit(&thick.fabrication.unwrap());
    let enumeration = Enumeration::run(&plain, 2, Filters::all());
    let mut checked = [0usize; 4];
    for node in enumeration.meaningful().take(6) {
        let Ok(model) = Model::new(&node.graph, &plain, 0) else {
            continue;
        };
        let x: Vec<f64> = (0..model.free.len())
            .map(|i| {
                let (lo, hi) = model.var_bounds(model.free[i]);
                lo + (hi - lo) * (0.25 + 0.5 * (0.618_034 * (i + 1) as f64).fract())
            })
            .collect();
        let modes = vec![1.0; model.plan.internal.len()];
        let old = RobustModel::new(&model, RobustSpec::from_task(&plain, 181)).unwrap();
        let new = RobustModel::new(&model, RobustSpec::from_task(&thick, 181)).unwrap();
        assert_eq!(old.pairs.slots, new.pairs.slots);
        assert_eq!(
            new.wall_gap(Level::Setting),
            old.wall_gap(Level::Setting) + reach
        );
        for t in new.base_times().into_iter().filter(|t| *t > 0.0) {
            let mut work = new.work();
            new.eval(&x, &modes, t, &mut work);
            let mut planes = vec![None; new.pairs.pairs.len()];
            new.fit(
                &work.values,
                &mut planes,
                |_| false,
                Level::Imposed,
                FULL,
                &mut Buffers::default(),
            );
            let a = values(&old, &x, &modes, t, &planes);
            let b = values(&new, &x, &modes, t, &planes);
            assert_eq!(a.len(), b.len());
            let scene = &work.values.scene;
            for (slot, &h_old) in &a {
                let h_new = b[slot];
                let expected = match new.slot_owner(*slot) {
                    SlotOwner::Pair(p) => {
                        let pair = &new.pairs.pairs[p];
                        let k = slot - pair.slot;
                        checked[0] += 1;
                        match pair.kind {
                            PairKind::Apart => h_old - reach,
                            PairKind::Obstacle { .. } if k < pair.a_verts.len() => h_old,
                            PairKind::Obstacle { .. } => h_old - reach,
                            PairKind::Cone { a, b } => {
                                let r = *pair.a_verts.iter().chain(&pair.b_verts).nth(k).unwrap();
                                if r == a || r == b {
                                    h_old
                                } else {
                                    let (pa, pb, pr) = (scene.at(a), scene.at(b), scene.at(r));
                                    let d: f64 = (0..3)
                                        .map(|i| (pr[i] - 0.5 * (pa[i] + pb[i])).powi(2))
                                        .sum::<f64>()
                                        .sqrt();
                                    h_old - reach * d
                                }
                            }
                        }
                    }
                    SlotOwner::Crease(c) => {
                        checked[1] += 1;
                        // |ρ| = lim_old − h_old; the new limit is the smaller one.
                        let lim_old = old.crease_limit(c, Level::Imposed);
                        let rho = lim_old - h_old;
                        let lim = lim_old.min(limit / 1.01 - CLEARANCE_FLOOR);
                        assert_eq!(new.crease_limit(c, Level::Imposed), lim);
                        lim - rho
                    }
                    SlotOwner::Margin(_) => {
                        checked[2] += 1;
                        h_old
                    }
                    _ => {
                        checked[3] += 1;
                        h_old - reach
                    }
                };
                assert!(
                    (h_new - expected).abs() <= 1e-12,
                    "slot {slot} ({:?}) at t = {t}: {h_new} vs {expected}",
                    new.slot_owner(*slot)
                );
            }
        }
    }
    assert!(
        checked[0] > 0 && checked[1] > 0 && checked[2] > 0,
        "{checked:?}"
    );
}

#[test]
fn the_fold_limit_is_where_the_setback_reaches_its_bound() {
    let (_, thick) = thick_task();
    let fab = thick.fabrication.unwrap();
    let rho = thick_fold_limit(&fab);
    assert!((fab.reach_units() * (rho / 2.0).tan() - MAX_SETBACK).abs() < 1e-15);
    assert!(rho < std::f64::consts::PI);
    // 2 mm at 100 mm per unit, one side: reach 0.02, 2·atan(5) ≈ 157.4°.
    assert!(
        (rho.to_degrees() - 157.380_135).abs() < 1e-5,
        "{}",
        rho.to_degrees()
    );
}

#[test]
fn a_thick_gripper_run_keeps_every_panel_clear_on_the_dense_sweep() {
    use foldsynth::search::AlternativeRecord;
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper_thick.toml");
    let task = Task::load(file).unwrap();
    let fab = task.fabrication.unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    runs::foldsynth_ok(&[
        "synthesize",
        file,
        "--n-max",
        "2",
        "--no-export",
        "--out",
        out.to_str().unwrap(),
    ]);
    let records: Vec<AlternativeRecord> = std::fs::read_to_string(out.join("alternatives.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let designs: Vec<&AlternativeRecord> = records.iter().filter(|r| r.feasible_design()).collect();
    assert!(!designs.is_empty(), "no design kept");
    for r in &designs {
        let f = r
            .fabrication
            .as_ref()
            .expect("a design of a thick task is built");
        assert!(f.refused.is_none(), "{}", r.key);
        let c = f.check.as_ref().unwrap();
        assert!(c.passes(), "{}: {:?}", r.key, f.failure());
        assert!(c.states >= 181 && c.pairs > 0, "{}", r.key);
        assert!(
            c.least_apart.unwrap() >= task.robustness.clearance,
            "{}",
            r.key
        );
        // The gripper's task has its cylinder: every panel's clearance from it is measured.
        assert!(
            c.least_obstacle.unwrap() >= task.robustness.obstacle_clearance,
            "{}",
            r.key
        );
    }
    // Every alternative that passes the other checks and is not a design because of its
    // thick panels says why.
    for r in records
        .iter()
        .filter(|r| r.fabrication.as_ref().is_some_and(|f| !f.passes()))
    {
        assert!(!r.feasible_design());
        assert!(
            r.fabrication.as_ref().unwrap().failure().is_some(),
            "{}",
            r.key
        );
    }
    // The design JSONs: the bill of the build and the hinge axes.
    let limit = thick_fold_limit(&fab).to_degrees();
    let mut jsons = 0;
    for e in std::fs::read_dir(out.join("designs")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "json") {
            continue;
        }
        jsons += 1;
        let d: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
        let bill = &d["fabrication"]["bill"];
        assert_eq!(bill["thickness_mm"], 2.0);
        let faces = d["pattern"]["faces"].as_array().unwrap().len();
        // Both arms are built: the pattern of the JSON is the arm.
        assert_eq!(
            bill["panels"].as_array().unwrap().len(),
            2 * faces,
            "{}",
            p.display()
        );
        for c in bill["creases"].as_array().unwrap() {
            let deg = c["largest_fold_deg"].as_f64().unwrap();
            // Driven creases fold to t_max = 90°; the others stay within the setback bound
            // (with the optimizer's 0.5 % acceptance safety).
            assert!(deg <= limit + 1e-6, "{}: {c}", p.display());
            let [a, b] = [0, 1].map(|k| c["axis_mm"][k].as_array().unwrap().clone());
            let len = (a[0].as_f64().unwrap() - b[0].as_f64().unwrap())
                .hypot(a[1].as_f64().unwrap() - b[1].as_f64().unwrap());
            assert!((len - c["hinge_length_mm"].as_f64().unwrap()).abs() < 1e-9);
        }
        assert_eq!(
            d["fabrication"]["hinges"].as_array().unwrap().len(),
            bill["creases"].as_array().unwrap().len()
        );
    }
    assert_eq!(jsons, designs.len());
}

/// Issue 50: a thick task hands over its files. The two most robust designs of a small
/// thick gripper run get their plies, panel solids, assemblies and `fabrication.json` in
/// their folders, listed in the run's manifest and in the design JSON's
/// `fabrication.files`, and they read back with the same independent readers as
/// `foldsynth fabricate`'s; the others get none.
#[test]
fn a_thick_run_writes_the_fabrication_files_of_its_top_designs() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper_thick.toml");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    runs::foldsynth_ok(&[
        "synthesize",
        file,
        "--n-max",
        "2",
        "--export",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap();
    let listed: Vec<&str> = manifest["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    let mut with_files = 0;
    for e in std::fs::read_dir(out.join("designs")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "json") {
            continue;
        }
        let d: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
        let id = d["id"].as_str().unwrap();
        let folder = out.join("designs").join(id);
        let Some(files) = d["fabrication"]["files"].as_array() else {
            assert!(!folder.join("fabrication.json").exists(), "{id}");
            continue;
        };
        with_files += 1;
        assert!(d["rank"].as_u64().unwrap() <= 2, "{id}");
        for f in files {
            let f = f.as_str().unwrap();
            assert!(out.join("designs").join(f).is_file(), "{id}: {f} missing");
            assert!(
                listed.contains(&format!("designs/{f}").as_str()),
                "{f} not in the manifest"
            );
        }
        for name in [
            "ply-rigid.dxf",
            "ply-hinge.svg",
            "assembly-half.3mf",
            "fabrication.json",
        ] {
            assert!(
                files.iter().any(|f| f == format!("{id}/{name}").as_str()),
                "{id}: {name}"
            );
        }
        let rec = fab_files::record(&folder);
        // The bill of the files is the design JSON's, the check the search's.
        assert_eq!(rec["fabrication"], d["fabrication"]["bill"], "{id}");
        assert_eq!(rec["check"], d["fabrication"]["check"], "{id}");
        assert_eq!(rec["material_from"], "task");
        assert_eq!(rec["design"], format!("designs/{id}.json"));
        assert_eq!(
            rec["states"][2]["frame"], 180,
            "{id}: the dense sweep's last state"
        );
        fab_files::independent_readers(&folder);
    }
    assert_eq!(with_files, 2);
}
