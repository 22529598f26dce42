//! The robustness block compiled on first use (issue 14): an alternative optimized with a
//! [`LazyBlock`] gets the solution it gets with the block compiled up front, bit for bit,
//! and the block is compiled only when a start's phase A meets the target (the only time
//! the optimizer asks the block anything).

use foldsynth::compile::Options as CompileOptions;
use foldsynth::grammar::{Enumeration, Filters};
use foldsynth::model::Model;
use foldsynth::model::compiled::{CompiledModel, ModelProblem, objective_target};
use foldsynth::model::robust::{Deferred, LazyBlock, RobustModel, RobustProblem, RobustSpec};
use foldsynth::optimize::{Acceptance, Options, Robust, Solution, minimize_robust};
use foldsynth::task::Task;
use std::cell::Cell;

const ARM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/robotic_arm.toml");

/// A block built up front that notes whether the optimizer asked it anything.
struct Spy<'a> {
    block: RobustProblem<'a>,
    asked: Cell<bool>,
}

impl Robust for Spy<'_> {
    fn reset(&self) {
        self.asked.set(true);
        self.block.reset()
    }
    fn update(&self, x: &[f64], mu: Option<f64>) -> f64 {
        self.asked.set(true);
        self.block.update(x, mu)
    }
    fn variables(&self) -> Vec<f64> {
        self.asked.set(true);
        self.block.variables()
    }
    fn set_variables(&self, z: &[f64]) {
        self.asked.set(true);
        self.block.set_variables(z)
    }
    fn merit(&self, x: &[f64], z: &[f64], mu: f64, gx: &mut [f64], gz: &mut [f64]) -> f64 {
        self.asked.set(true);
        self.block.merit(x, z, mu, gx, gz)
    }
    fn accept(&self, x: &[f64]) -> Acceptance {
        self.asked.set(true);
        self.block.accept(x)
    }
}

fn bits(s: &Solution) -> (Vec<u64>, u64, Option<bool>, usize, usize) {
    (
        s.x.iter().map(|x| x.to_bits()).collect(),
        s.f.to_bits(),
        s.robust,
        s.robust_attempts,
        s.evaluations,
    )
}

#[test]
fn a_block_compiled_on_first_use_gives_the_same_solutions_and_is_compiled_only_when_needed() {
    let task = Task::load(ARM).unwrap();
    let spec = RobustSpec::from_task(&task, 181);
    let enumeration = Enumeration::run(&task, 3, Filters::all());
    let (mut needed, mut not_needed) = (0, 0);
    'models: for node in enumeration.meaningful() {
        let n = node.graph.internal_count();
        for candidate in 0..3 {
            let Ok(model) = Model::new(&node.graph, &task, candidate) else {
                continue;
            };
            let compiled = CompiledModel::new(&model, &CompileOptions::default()).unwrap();
            let eager = RobustModel::new(&model, spec.clone()).unwrap();
            let lazy = LazyBlock::new(spec.clone());
            let (mut asked, mut met) = (false, false);
            for m in 0..(1u32 << n) {
                let modes: Vec<f64> = (0..n)
                    .map(|i| if m >> i & 1 == 1 { -1.0 } else { 1.0 })
                    .collect();
                let problem = ModelProblem::new(&model, &compiled, &modes);
                let opts = Options {
                    starts: 4,
                    seed: 7,
                    target: Some(objective_target(&model)),
                    ..Default::default()
                };
                let up_front = Spy {
                    block: RobustProblem::new(&model, &eager, &modes),
                    asked: Cell::new(false),
                };
                let a = minimize_robust(&problem, Some(&up_front), &opts);
                let deferred = Deferred::new(&model, &lazy, &modes);
                let b = minimize_robust(&problem, Some(&deferred), &opts);
                assert_eq!(
                    bits(&a),
                    bits(&b),
                    "{} candidate {candidate} modes {m}",
                    node.graph.sequence()
                );
                assert!(deferred.error().is_none());
                asked |= up_front.asked.get();
                met |= a.met_target;
            }
            // Compiled exactly when the optimizer asked the block something, which it does
            // for every start whose phase A met the target.
            let what = format!("{} candidate {candidate}", node.graph.sequence());
            assert_eq!(lazy.is_compiled(), asked, "{what}");
            assert!(
                !met || asked,
                "{what}: met the target without asking the block"
            );
            if asked {
                needed += 1;
            } else {
                not_needed += 1;
            }
            if needed >= 2 && not_needed >= 2 {
                break 'models;
            }
        }
    }
    assert!(
        needed > 0 && not_needed > 0,
        "{needed} models needed their block, {not_needed} did not"
    );
}
