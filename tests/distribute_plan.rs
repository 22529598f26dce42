//! The plan of a search and the deal of its units into shards (issue 15), on the gripper
//! at N_max = 3 and 4: alternatives are numbered one to one by their keys; the streamed
//! enumeration's graphs are the graphs their rule sequences build; every deal is a
//! partition of the units, the same every time, and within the list-scheduling bound
//! (no shard's estimated cost exceeds the average by more than the costliest unit).

use foldsynth::distribute::shard::{assign, share};
use foldsynth::grammar::{CreaseGraph, Enumeration, Filters, Status};
use foldsynth::search::Plan;
use foldsynth::search::output::ShardSpec;
use foldsynth::task::Task;

fn gripper() -> Task {
    Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap()
}

#[test]
fn every_alternative_is_numbered_once_and_found_by_its_key() {
    let task = gripper();
    let plan = Plan::new(&task, 3);
    assert_eq!(plan.graphs.len(), 53);
    assert_eq!(plan.units.len(), 3 * 53);
    assert_eq!(plan.alternatives, 1194);
    let mut next = 0u64;
    for (u, unit) in plan.units.iter().enumerate() {
        // Units in record order, their alternatives numbered consecutively.
        assert_eq!(unit.first, next);
        assert_eq!(unit.count, 1 << plan.graphs[unit.graph].n);
        next += unit.count;
        for m in 0..unit.count as u32 {
            let alt = plan.alternative(u, m);
            let place = plan.locate(&alt.key()).expect("a key of the plan");
            assert_eq!((place.unit, place.modes), (u, m));
            assert_eq!(place.index, unit.first + u64::from(m));
        }
    }
    assert_eq!(next, plan.alternatives);
    for bad in [
        "",
        "2|1",
        "2|4|up",
        "2|0|up",
        "2|1|up,up",
        "2|1|sideways",
        "9, 9|1|up",
    ] {
        assert_eq!(plan.locate(bad), None, "{bad}");
    }
    // The small tree is kept for the report, with every generated graph.
    assert_eq!(plan.tree.len(), plan.generated);
}

#[test]
fn streamed_graphs_are_what_their_sequences_build() {
    // The stream keeps only rule sequences of the graphs it still expands and rebuilds
    // them; each graph it hands out must be the graph its own sequence builds from G0.
    let task = gripper();
    let mut n = 0;
    let mut meaningful = 0;
    Enumeration::stream(&task, 3, Filters::all(), |g| {
        let rebuilt = CreaseGraph::from_sequence(&task, &g.graph.sequence()).unwrap();
        assert_eq!(rebuilt.canonical_code(), g.graph.canonical_code());
        assert_eq!(g.index, n);
        n += 1;
        meaningful += usize::from(g.status == Status::Meaningful);
    });
    // Thesis Sec. 5.5.2 with all filters: the counts of Table 3 as this crate reads it.
    assert_eq!((n, meaningful), (101, 53));
}

#[test]
fn shards_partition_the_units_within_the_list_scheduling_bound() {
    let task = gripper();
    let plan = Plan::new(&task, 4);
    let total: u64 = plan.units.iter().map(|u| u.cost).sum();
    let largest = plan.units.iter().map(|u| u.cost).max().unwrap();
    for count in [1, 2, 3, 4, 7, 16, 64, 128] {
        let deal = assign(&plan, count);
        assert_eq!(deal.len(), count);
        let mut seen = vec![0u32; plan.units.len()];
        for (k, units) in deal.iter().enumerate() {
            assert!(
                units.windows(2).all(|w| w[0] < w[1]),
                "shard {k} not in order"
            );
            for &u in units {
                seen[u] += 1;
            }
            // Greedy list scheduling: when a unit was added to a shard, that shard had the
            // least load, at most the average of what was dealt so far.
            let load = plan.cost(units);
            assert!(
                load * count as u64 <= total + largest * count as u64,
                "{count} shards: shard {k} has {load}, average {}",
                total as f64 / count as f64
            );
            let spec = ShardSpec {
                index: k + 1,
                count,
            };
            assert_eq!(&share(&plan, spec), units);
        }
        assert!(
            seen.iter().all(|&s| s == 1),
            "{count} shards: not a partition"
        );
        assert_eq!(assign(&plan, count), deal, "not deterministic");
    }
}
