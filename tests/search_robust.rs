//! Feasible and robust by construction (issue 12), end to end on the gripper task with
//! N_max = 2, both ways on the same alternatives:
//! - an alternative that meets the target but whose optimum self-intersects without the
//!   clearance constraints (`--post-check-only`) becomes feasible with them, and the
//!   independent post-checks (Möller, cylinder, rigidity, `verify`, on the dense sweep)
//!   agree;
//! - every design keeps its margins (rigid margin, self, arm and obstacle clearance, the
//!   flat layout's smallest feature) at least at the task's settings on the search's sweep
//!   (alternatives short of one are not designs), and every design the constrained
//!   optimizer accepts on a 721-state sweep, measured by `check::robustness` (exact
//!   distances, no code shared with the constraints);
//! - designs are ranked most robust first in `summary.json` and `designs/<id>.json`.

use foldsynth::grammar::{Enumeration, Filters};
use foldsynth::search::{AlternativeRecord, remeasure};
use foldsynth::task::Task;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

#[path = "common/runs.rs"]
#[allow(dead_code)] // only the runner is used here
mod runs;
use runs::foldsynth_ok;

const GRIPPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml");

fn synthesize(out: &Path, extra: &[&str]) -> Value {
    let mut args = vec![
        "synthesize",
        GRIPPER,
        "--n-max",
        "2",
        "--out",
        out.to_str().unwrap(),
        "--json",
        "--no-export",
    ];
    args.extend_from_slice(extra);
    serde_json::from_slice(&foldsynth_ok(&args)).unwrap()
}

fn records(out: &Path) -> BTreeMap<String, AlternativeRecord> {
    std::fs::read_to_string(out.join("alternatives.jsonl"))
        .unwrap()
        .lines()
        .map(|l| {
            let r: AlternativeRecord = serde_json::from_str(l).unwrap();
            (r.key.clone(), r)
        })
        .collect()
}

#[test]
fn constraints_make_self_intersecting_optima_feasible_and_margins_hold_on_a_dense_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let (plain, robust) = (dir.path().join("plain"), dir.path().join("robust"));
    let sp = synthesize(&plain, &["--post-check-only"]);
    let sr = synthesize(&robust, &[]);
    assert_eq!(sp["alternatives"], sr["alternatives"]);
    assert_eq!(sr["verification_failures"], 0);
    let (rp, rr) = (records(&plain), records(&robust));

    // Alternatives the plain optimizer brings to the target with self-intersecting facets,
    // which the constrained one makes feasible: the post-checks judge them free of
    // intersection on the dense sweep, clear of the cylinder, rigid and verified.
    let rescued: Vec<&str> = rp
        .values()
        .filter(|p| p.meets_target && p.self_intersection_free == Some(false))
        .filter(|p| rr[&p.key].feasible_design())
        .map(|p| p.key.as_str())
        .collect();
    assert!(
        !rescued.is_empty(),
        "no self-intersecting optimum was made feasible"
    );
    for k in &rescued {
        let r = &rr[*k];
        assert_eq!(r.self_intersection_free, Some(true), "{k}");
        assert!(r.self_intersection.is_none(), "{k}");
        assert_eq!(r.robust_accepted, Some(true), "{k}");
    }
    // The constrained run finds more designs than the plain one.
    let feasible = |s: &Value| s["feasible"].as_u64().unwrap();
    assert!(
        feasible(&sr) > feasible(&sp),
        "{} vs {}",
        feasible(&sr),
        feasible(&sp)
    );

    // Every design meets the settings on a 721-state sweep, remeasured independently.
    let task = Task::load(GRIPPER).unwrap();
    let enumeration = Enumeration::run(&task, 2, Filters::all());
    let graphs: Vec<_> = enumeration.meaningful().map(|n| &n.graph).collect();
    let designs: Vec<&AlternativeRecord> = rr.values().filter(|r| r.feasible_design()).collect();
    assert_eq!(designs.len() as u64, feasible(&sr));
    // With the margins on, a design is one that keeps them on the search's sweep: every
    // design meets its settings, none is near a rigid limit, and the alternatives that pass
    // every check short of a margin are not designs and say which margin.
    let meets = designs
        .iter()
        .filter(|r| r.robustness.as_ref().is_some_and(|m| m.meets_settings()))
        .count();
    assert_eq!(meets, designs.len());
    assert_eq!(sr["meets_margins"].as_u64().unwrap(), meets as u64);
    assert_eq!(sr["near_rigid_limit"], 0);
    let short: Vec<&AlternativeRecord> = rr
        .values()
        .filter(|r| r.passes_checks() && !r.feasible_design())
        .collect();
    assert_eq!(sr["short_of_margins"].as_u64().unwrap(), short.len() as u64);
    for r in &short {
        assert!(
            !r.robustness.as_ref().is_some_and(|m| m.meets_settings()),
            "{}",
            r.key
        );
        assert!(!r.short_of_margins.is_empty(), "{}", r.key);
    }
    // With --post-check-only the margins are reported, not required.
    assert_eq!(sp["short_of_margins"], 0);
    let accepted: Vec<&&AlternativeRecord> = designs
        .iter()
        .filter(|r| r.robust_accepted == Some(true))
        .collect();
    assert!(!accepted.is_empty());
    for r in accepted {
        let m = remeasure(&task, graphs[r.graph], r, 721).unwrap();
        let s = &task.robustness;
        assert!(m.rigid_margin.value >= s.rigid_margin, "{}: {:?}", r.key, m);
        assert!(m.rigid_margin.setting == s.rigid_margin);
        let selfc = m.self_clearance.as_ref().expect("self clearance measured");
        assert!(selfc.value >= s.clearance, "{}: {:?}", r.key, selfc);
        let arm = m.arm_clearance.as_ref().expect("a two-armed task");
        assert!(arm.value >= s.clearance, "{}: {:?}", r.key, arm);
        let obs = m.obstacle_clearance.as_ref().expect("the cylinder");
        assert!(obs.value >= s.obstacle_clearance, "{}: {:?}", r.key, obs);
        // The flat layout's smallest feature (issue 20), measured by check::features.
        let mf = m.min_feature.as_ref().expect("min feature measured");
        assert!(s.min_feature > 0.0 && mf.setting == s.min_feature);
        assert!(mf.value >= s.min_feature, "{}: {:?}", r.key, mf);
        assert!(m.meets_settings() && m.score >= 1.0, "{}: {:?}", r.key, m);
    }

    // Ranked most robust first, in summary.json and in each design file.
    let ranking = sr["ranking"].as_array().unwrap();
    assert_eq!(ranking.len(), designs.len());
    let scores: Vec<f64> = ranking
        .iter()
        .map(|e| e["score"].as_f64().unwrap())
        .collect();
    assert!(scores.windows(2).all(|w| w[0] >= w[1]), "{scores:?}");
    for (i, e) in ranking.iter().enumerate() {
        let id = e["id"].as_str().unwrap();
        let d: Value = serde_json::from_str(
            &std::fs::read_to_string(robust.join("designs").join(format!("{id}.json"))).unwrap(),
        )
        .unwrap();
        assert_eq!(d["rank"], i + 1);
        assert_eq!(d["robustness"]["score"], e["score"]);
        for k in [
            "rigid_margin",
            "self_clearance",
            "arm_clearance",
            "obstacle_clearance",
            "min_feature",
        ] {
            let m = &d["robustness"][k];
            assert!(m["value"].is_f64() && m["setting"].is_f64() && m["where"].is_string());
        }
    }
}
