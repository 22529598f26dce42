//! Random rule sequences deeper than the exhaustive tests reach (N up to 6): the
//! structural invariants hold and every sequence rebuilds its graph.

use foldsynth::grammar::{ConstraintSpec, CreaseGraph, StepRecord};
use foldsynth::task::Task;
use proptest::prelude::*;

fn gripper() -> Task {
    Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn random_walks_stay_well_formed(choices in proptest::collection::vec(0usize..1000, 1..14)) {
        let task = gripper();
        let mut g = CreaseGraph::initial(&task);
        for c in choices {
            let r1 = g.r1_matches(6);
            let r2 = g.r2_matches();
            let n = r1.len() + r2.len();
            if n == 0 {
                break;
            }
            let k = c % n;
            if k < r1.len() {
                g.extend(r1[k]).unwrap();
            } else {
                g.combine(r2[k - r1.len()].1).unwrap();
            }
        }
        prop_assert!(g.is_acyclic());
        prop_assert!(g.facet_boundaries().is_ok(), "{}: {:?}", g.sequence(), g.facet_boundaries());
        for v in g.vertices() {
            if v.extended {
                prop_assert_eq!(v.succ().len(), 3);
            }
        }
        // Every constraint refers to living vertices and creases that meet there.
        for c in g.constraints() {
            match c {
                ConstraintSpec::Sector { vertex, from, to, .. }
                | ConstraintSpec::Remainder { vertex, from, to }
                | ConstraintSpec::MergedSector { vertex, from, to } => {
                    for cr in [from, to] {
                        let cr = g.crease(cr).unwrap();
                        prop_assert!(cr.tail == vertex || cr.head == vertex, "{}", g.sequence());
                    }
                }
                ConstraintSpec::Length { crease, var } => {
                    prop_assert!(g.crease(crease).is_some());
                    if let Some(v) = var {
                        prop_assert!(g.is_free(v));
                    }
                }
                ConstraintSpec::RigidFoldability { vertex } => {
                    prop_assert!(g.vertex(vertex).unwrap().extended);
                }
            }
        }
        // Eliminated variables are exactly those no living placement uses.
        let eliminated: Vec<_> = g.steps().iter().filter_map(|s| match s {
            StepRecord::R2(r) => Some(r.eliminated.clone()),
            StepRecord::R1(_) => None,
        }).flatten().collect();
        for v in g.variables() {
            prop_assert_eq!(g.is_free(v.id), !eliminated.contains(&v.id), "{} {}", g.sequence(), v.name);
        }
        let h = CreaseGraph::from_sequence(&task, &g.sequence()).unwrap();
        prop_assert_eq!(h.canonical_code(), g.canonical_code());
    }
}
