//! The enumeration of Table 3 and its filters on the thesis's gripper task (Sec. 5.5–5.6).

use std::collections::{HashMap, HashSet};

use foldsynth::grammar::{CreaseGraph, Enumeration, Filters, Status, StepRecord, VertexType};
use foldsynth::task::Task;
use petgraph::algo::has_path_connecting;

fn gripper() -> Task {
    Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap()
}

/// The thesis's 291 (Sec. 5.6; SPEC §2): every graph the rules generate from G0 with
/// N_max = 3 and no de-duplication. G0 itself is the root and not among them.
#[test]
fn without_filters_the_grammar_yields_291_graphs() {
    let e = Enumeration::run(&gripper(), 3, Filters::none());
    assert_eq!(e.nodes.len(), 291);
    assert_eq!(e.root.level(), 0);
    assert!(
        e.nodes
            .iter()
            .all(|n| n.level >= 1 && n.status == Status::Meaningful)
    );
    // Every node's level is its number of rule applications, one more than its parent's.
    for n in &e.nodes {
        assert_eq!(n.graph.level(), n.level);
        let parent_level = n.parent.map_or(0, |p| e.nodes[p].level);
        assert_eq!(n.level, parent_level + 1);
    }
    // With filters off, distinct rule sequences are distinct nodes.
    let seqs: HashSet<String> = e.nodes.iter().map(|n| n.graph.sequence()).collect();
    assert_eq!(seqs.len(), 291);
}

#[test]
fn the_thesis_named_graphs_are_meaningful() {
    let e = Enumeration::run(&gripper(), 3, Filters::all());
    for s in [
        "2, 3, 4, (8, 9)",
        "2, 3, 8, (7, 9)",
        "2, 3, (4, 8), 4, (7, 8)",
        "2, 4, 7, (6, 9)",
        "2, 4, 3, (6, 11)",
        "2, 3, 8",
    ] {
        let n = e.find(s).unwrap_or_else(|| panic!("{s} not generated"));
        assert_eq!(n.status, Status::Meaningful, "{s}");
    }
    let inv = e.find("2, 4, 3").unwrap();
    assert_eq!(inv.status, Status::Invalid);
    // Fig. 47a: 2, 5 is the mirror image of 2, 3, which comes first and stays.
    let g23 = e.find("2, 3").unwrap();
    let g25 = e.find("2, 5").unwrap();
    assert_eq!(g23.status, Status::Meaningful);
    assert_eq!(g25.status, Status::Mirror);
    assert!(g25.graph.is_mirror_of(&g23.graph));
    assert!(g23.graph.is_mirror_of(&g25.graph));
    // Mirror images are dropped with all their descendants.
    let mirror_ix: HashSet<usize> = (0..e.nodes.len())
        .filter(|&i| e.nodes[i].status == Status::Mirror)
        .collect();
    assert!(
        e.nodes
            .iter()
            .all(|n| n.parent.is_none_or(|p| !mirror_ix.contains(&p)))
    );
    // Descendants of invalid graphs still grow (Fig. 48: 2, 4, 3 → 2, 4, 3, (6, 11)).
    assert_eq!(
        e.nodes[e.find("2, 4, 3, (6, 11)").unwrap().parent.unwrap()]
            .graph
            .sequence(),
        "2, 4, 3"
    );
}

/// The thesis finds 52 meaningful graphs and 1170 alternatives; we find 53 and 1194: one
/// graph with N = 3 more (1194 − 1170 = 24 = 2³ × 3). See the grammar module docs.
#[test]
fn meaningful_count_at_n_max_3_is_within_one_of_the_thesis() {
    let e = Enumeration::run(&gripper(), 3, Filters::all());
    let meaningful: Vec<_> = e.meaningful().collect();
    assert!((51..=53).contains(&meaningful.len()));
    assert_eq!(meaningful.len(), 53);
    let by_n = meaningful.iter().fold(HashMap::new(), |mut m, n| {
        *m.entry(n.graph.internal_count()).or_insert(0u64) += 1;
        m
    });
    assert_eq!(by_n[&1], 1);
    assert_eq!(by_n[&2], 5);
    assert_eq!(by_n[&3], 47);
    assert_eq!(
        e.alternatives(),
        3 * (2 * by_n[&1] + 4 * by_n[&2] + 8 * by_n[&3])
    );
    assert_eq!(e.alternatives(), 1194);
    // Same count for the robotic arm: its G0, N_max and symmetry are the gripper's.
    let arm = Task::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/grammar/robotic_arm.toml"
    ))
    .unwrap();
    assert_eq!(
        Enumeration::run(&arm, 3, Filters::all())
            .meaningful()
            .count(),
        53
    );
}

#[test]
fn filters_can_be_switched_off_one_by_one() {
    let task = gripper();
    let all = Enumeration::run(&task, 3, Filters::all());
    let no_iso = Enumeration::run(
        &task,
        3,
        Filters {
            isomorphism: false,
            ..Filters::all()
        },
    );
    let no_mirror = Enumeration::run(
        &task,
        3,
        Filters {
            mirror: false,
            ..Filters::all()
        },
    );
    let no_validity = Enumeration::run(
        &task,
        3,
        Filters {
            validity: false,
            ..Filters::all()
        },
    );
    assert_eq!(no_iso.count(Status::Isomorphic), 0);
    assert_eq!(no_mirror.count(Status::Mirror), 0);
    assert!(!no_mirror.mirror_applied);
    assert_eq!(no_validity.count(Status::Invalid), 0);
    assert!(no_iso.meaningful().count() > all.meaningful().count());
    assert!(no_mirror.meaningful().count() > all.meaningful().count());
    // Without the validity filter the invalid graphs count as meaningful; nothing else changes.
    assert_eq!(no_validity.nodes.len(), all.nodes.len());
    assert_eq!(
        no_validity.meaningful().count(),
        all.meaningful().count() + all.count(Status::Invalid)
    );
    // Without the mirror filter every kept graph's mirror image is also kept (the task is
    // symmetric): meaningful graphs come in mirror pairs or are their own mirror image.
    let codes: HashSet<_> = no_mirror
        .meaningful()
        .map(|n| n.graph.canonical_code())
        .collect();
    for n in no_mirror.meaningful() {
        assert!(
            codes.contains(&n.graph.mirror_code().unwrap()),
            "{}",
            n.graph.sequence()
        );
    }
    // The mirror filter keeps exactly one of each pair.
    let pairs = no_mirror
        .meaningful()
        .filter(|n| n.graph.mirror_code().unwrap() != n.graph.canonical_code())
        .count();
    assert_eq!(
        no_mirror.meaningful().count() - pairs / 2,
        all.meaningful().count()
    );
}

#[test]
fn counts_per_level_add_up() {
    let e = Enumeration::run(&gripper(), 4, Filters::all());
    let levels = e.level_counts();
    assert_eq!(
        levels.iter().map(|l| l.generated).sum::<usize>(),
        e.nodes.len()
    );
    for l in &levels {
        assert_eq!(
            l.generated,
            l.isomorphic + l.mirror + l.invalid + l.meaningful
        );
    }
    // Isomorphic graphs are not expanded, so no node has an isomorphic parent.
    assert!(e.nodes.iter().all(|n| {
        n.parent
            .is_none_or(|p| !matches!(e.nodes[p].status, Status::Isomorphic | Status::Mirror))
    }));
    // No two kept graphs are isomorphic.
    let mut seen = HashSet::new();
    for n in e
        .nodes
        .iter()
        .filter(|n| matches!(n.status, Status::Meaningful | Status::Invalid))
    {
        assert!(
            seen.insert(n.graph.canonical_code()),
            "{}",
            n.graph.sequence()
        );
    }
}

/// Structural invariants of every graph the rules generate (raw language, N_max = 4).
#[test]
fn every_generated_graph_is_well_formed() {
    let task = gripper();
    let e = Enumeration::run(&task, 4, Filters::none());
    assert!(e.nodes.len() > 20_000);
    for n in &e.nodes {
        let g = &n.graph;
        let seq = g.sequence();
        assert!(g.is_acyclic(), "{seq}: cycle");
        assert!(
            g.facet_boundaries().is_ok(),
            "{seq}: {:?}",
            g.facet_boundaries()
        );
        for v in g.vertices() {
            let name = g.name(v.vid).unwrap();
            assert_eq!(g.vid_by_name(name), Some(v.vid));
            // Predecessor lists are exactly the incoming creases.
            assert_eq!(v.preds.len(), g.in_degree(v.vid), "{seq}: v{name}");
            for &c in &v.preds {
                assert_eq!(g.crease(c).unwrap().head, v.vid);
            }
            for &c in &v.succ() {
                assert_eq!(g.crease(c).unwrap().tail, v.vid);
            }
            if v.extended {
                assert_eq!(
                    v.succ().len(),
                    3,
                    "{seq}: v{name} internal without 3 successors"
                );
                assert_eq!(v.ty, VertexType::Terminal);
            }
            if v.ty == VertexType::Extendable {
                assert!(!v.preds.is_empty());
                assert!(
                    v.succ().is_empty(),
                    "{seq}: χ vertex with successors (G0 has none here)"
                );
            }
            // Placements refer to vertices that still exist.
            if let Some(p) = &v.placement {
                assert!(
                    g.vertex(p.parent).is_some() && g.vertex(p.reference).is_some(),
                    "{seq}"
                );
                assert!(p.sectors.iter().chain([&p.length]).all(|&x| g.is_free(x)));
            }
        }
        assert_eq!(
            g.internal_count(),
            g.vertices().filter(|v| v.extended).count()
        );
        if let Some(c) = g.gripping_candidates() {
            assert!(c[0] != c[1] && c[1] != c[2] && c[0] != c[2], "{seq}");
        }
        // r2 never combines a vertex with one of its ancestors.
        if let Some(StepRecord::R2(r)) = g.steps().last() {
            let parent = n.parent.map_or(&e.root, |p| &e.nodes[p].graph);
            let (a, b) = (
                parent.node_index(r.c1).unwrap(),
                parent.node_index(r.c2).unwrap(),
            );
            assert!(!has_path_connecting(parent.petgraph(), a, b, None), "{seq}");
            assert!(!has_path_connecting(parent.petgraph(), b, a, None), "{seq}");
        }
    }
}

/// The language is closed under the mirror image (G0 is symmetric): the mirror image of
/// every generated graph is generated too.
#[test]
fn the_raw_language_is_closed_under_mirroring() {
    let e = Enumeration::run(&gripper(), 3, Filters::none());
    let codes: HashSet<_> = e.nodes.iter().map(|n| n.graph.canonical_code()).collect();
    for n in &e.nodes {
        assert!(
            codes.contains(&n.graph.mirror_code().unwrap()),
            "{}",
            n.graph.sequence()
        );
    }
}

#[test]
fn every_sequence_rebuilds_its_graph() {
    let task = gripper();
    let e = Enumeration::run(&task, 3, Filters::none());
    for n in &e.nodes {
        let g = CreaseGraph::from_sequence(&task, &n.graph.sequence()).unwrap();
        assert_eq!(g.canonical_code(), n.graph.canonical_code());
        assert_eq!(g.sequence(), n.graph.sequence());
    }
}

#[test]
fn the_search_tree_is_written_as_dot() {
    let e = Enumeration::run(&gripper(), 3, Filters::all());
    let dot = e.to_dot();
    assert!(dot.starts_with("digraph search_tree {"));
    assert_eq!(dot.matches(" -> ").count(), e.nodes.len());
    assert_eq!(dot.matches("fillcolor=\"#ffd84d\"").count(), 53);
    assert!(dot.contains("label=\"2, 3, (4, 8), 4, (7, 8)\""));
}
