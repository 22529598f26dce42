//! Alternatives that are one optimization problem (issue 14): the alternatives of a model
//! whose modes differ only at vertices whose mode reaches no output (no constraint sees it
//! and the gripping vertex does not depend on it) have the same compiled function, bit for
//! bit, so the search optimizes them once (`optimize::SharedStarts`) with one seed. End to
//! end on the gripper task at N_max = 3:
//! - the compiled function of every such class is the same at the members' optimum, for
//!   every member's modes;
//! - with `--post-check-only` every member has the same optimum (variables, objective,
//!   feasibility, starts, evaluations: a replayed start counts those it stands for, so a
//!   record does not depend on which member ran first or on what a resumed run had done);
//! - with the constraints of issue 12, members for which phase B never ran (phase A only)
//!   have the same optimum too.

use foldsynth::grammar::Rules;
use foldsynth::model::Model;
use foldsynth::model::compiled::CompiledModel;
use foldsynth::optimize::{Evaluation, Problem};
use foldsynth::search::AlternativeRecord;
use foldsynth::task::Task;
use std::collections::BTreeMap;
use std::path::Path;

#[path = "common/runs.rs"]
#[allow(dead_code)] // only the runner is used here
mod runs;
use runs::foldsynth_ok;

const GRIPPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml");

fn synthesize(out: &Path, extra: &[&str]) -> Vec<AlternativeRecord> {
    let mut args = vec![
        "synthesize",
        GRIPPER,
        "--n-max",
        "3",
        "--out",
        out.to_str().unwrap(),
        "--no-export",
    ];
    args.extend_from_slice(extra);
    foldsynth_ok(&args);
    std::fs::read_to_string(out.join("alternatives.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// Mode bits of a record (bit i set: vertex i folds down), as the search numbers them.
fn mode_bits(r: &AlternativeRecord) -> u32 {
    r.modes
        .iter()
        .enumerate()
        .filter(|(_, m)| m.as_str() == "down")
        .fold(0, |acc, (i, _)| acc | 1 << i)
}

/// The records grouped by class: (graph, candidate, modes with the unused ones up), each
/// class's members in mode order, with the model's compiled function.
type Classes<'a> = BTreeMap<(usize, usize, u32), Vec<&'a AlternativeRecord>>;

fn classes<'a>(
    task: &Task,
    records: &'a [AlternativeRecord],
    models: &mut BTreeMap<(usize, usize), (Model, CompiledModel)>,
) -> Classes<'a> {
    let plan = foldsynth::search::plan(task, 3, Rules::default(), &[]).unwrap();
    let mut classes: Classes = BTreeMap::new();
    for r in records {
        let (g, c) = (r.graph, r.candidate - 1);
        let (_, compiled) = models.entry((g, c)).or_insert_with(|| {
            let model = Model::new(&plan.graph(task, g), task, c).unwrap();
            let compiled = CompiledModel::new(&model, &Default::default()).unwrap();
            (model, compiled)
        });
        let unused = compiled
            .modes_used
            .iter()
            .enumerate()
            .filter(|(_, u)| !**u)
            .fold(0u32, |acc, (i, _)| acc | 1 << i);
        classes
            .entry((g, c, mode_bits(r) & !unused))
            .or_default()
            .push(r);
    }
    for members in classes.values_mut() {
        members.sort_by_key(|r| mode_bits(r));
    }
    classes
}

fn signs(r: &AlternativeRecord) -> Vec<f64> {
    r.modes
        .iter()
        .map(|m| if m == "up" { 1.0 } else { -1.0 })
        .collect()
}

fn same_optimum(a: &AlternativeRecord, b: &AlternativeRecord) -> bool {
    a.variables == b.variables
        && a.objective.to_bits() == b.objective.to_bits()
        && a.feasible == b.feasible
        && a.meets_target == b.meets_target
        && a.starts_run == b.starts_run
}

#[test]
fn alternatives_of_one_problem_are_optimized_once() {
    let task = Task::load(GRIPPER).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let plain = synthesize(&dir.path().join("plain"), &["--post-check-only"]);
    let mut models = BTreeMap::new();
    let classes_plain = classes(&task, &plain, &mut models);
    let (mut shared_classes, mut replayed) = (0, 0);
    for members in classes_plain.values().filter(|m| m.len() > 1) {
        shared_classes += 1;
        let first = members[0];
        let (model, compiled) = &models[&(first.graph, first.candidate - 1)];
        // The same function for every member's modes, at the optimum.
        let x: Vec<f64> = model
            .free
            .iter()
            .map(|&i| first.variables[&model.plan.variables[i].name])
            .collect();
        let eval = |r: &AlternativeRecord| {
            let p = foldsynth::model::compiled::ModelProblem::new(model, compiled, &signs(r));
            let mut e = Evaluation::new(p.n_vars(), p.n_constraints());
            p.eval(&x, &mut e);
            let bits: Vec<u64> = std::iter::once(e.f)
                .chain(e.df)
                .chain(e.g)
                .chain(e.dg)
                .map(f64::to_bits)
                .collect();
            bits
        };
        let reference = eval(first);
        for r in &members[1..] {
            assert_eq!(eval(r), reference, "{} vs {}", r.key, first.key);
            assert!(same_optimum(r, first), "{} vs {}", r.key, first.key);
            // A replayed start counts the evaluations it stands for.
            assert_eq!(r.evaluations, first.evaluations, "{}", r.key);
            replayed += 1;
        }
    }
    // Not vacuous: the gripper at N_max = 3 has such classes (1,194 alternatives, 756
    // problems on 2 Dec 2026).
    assert!(
        shared_classes > 50 && replayed > 100,
        "{shared_classes} {replayed}"
    );

    // With the constraints of issue 12: phase A is shared, phase B is each member's.
    let robust = synthesize(&dir.path().join("robust"), &[]);
    let classes_robust = classes(&task, &robust, &mut models);
    let mut compared = 0;
    for members in classes_robust.values().filter(|m| m.len() > 1) {
        // Phase B ran for none of them (it starts from a phase-A point that met the target,
        // and ends where the member's own constraints leave it).
        if members
            .iter()
            .any(|r| r.meets_target || r.robust_attempts > 0)
        {
            continue;
        }
        for r in &members[1..] {
            assert!(
                same_optimum(r, members[0]),
                "{} vs {}",
                r.key,
                members[0].key
            );
            compared += 1;
        }
    }
    assert!(compared > 0);
}
