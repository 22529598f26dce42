//! The isomorphism filter: orientation-preserving, respecting the mark on the vertex
//! extended last (SPEC §2), checked against a brute-force oracle built on petgraph's VF2.

use foldsynth::grammar::{CreaseGraph, Enumeration, Filters, Status, Vid};
use foldsynth::task::Task;
use petgraph::algo::isomorphism::{is_isomorphic, subgraph_isomorphisms_iter};

fn gripper() -> Task {
    Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap()
}

fn g(task: &Task, s: &str) -> CreaseGraph {
    CreaseGraph::from_sequence(task, s).unwrap()
}

/// Whether some digraph isomorphism a → b (VF2) also keeps every vertex's ordered
/// predecessors and slots, its type and G0 identity, and the mark.
fn oracle_isomorphic(a: &CreaseGraph, b: &CreaseGraph, ignore_mark: bool) -> bool {
    oracle(a, b, ignore_mark, false)
}

/// As [`oracle_isomorphic`], with `mirror`: to b's mirror image (every rotation reversed:
/// p_m … p_1 and s3 s2 s1; G0 of the gripper lies on the mirror axis).
fn oracle(a: &CreaseGraph, b: &CreaseGraph, ignore_mark: bool, mirror: bool) -> bool {
    let (da, db) = (a.compact_digraph(), b.compact_digraph());
    if da.node_count() != db.node_count() || da.edge_count() != db.edge_count() {
        return false;
    }
    let (ra, rb) = (&da, &db);
    let mut nm = |x: &Vid, y: &Vid| {
        let (u, v) = (a.vertex(*x).unwrap(), b.vertex(*y).unwrap());
        u.ty == v.ty && u.extended == v.extended && u.g0 == v.g0 && u.preds.len() == v.preds.len()
    };
    let mut em = |_: &_, _: &_| true;
    let Some(maps) = subgraph_isomorphisms_iter(&ra, &rb, &mut nm, &mut em) else {
        return false;
    };
    for map in maps {
        // map[i]: node i of a (vertex named i + 1) → node map[i] of b.
        let to_b = |v: Vid| db[petgraph::graph::NodeIndex::new(map[a.name(v).unwrap() - 1])];
        let ok = a.vertices().all(|u| {
            let w = b.vertex(to_b(u.vid)).unwrap();
            if u.in_g0() && !u.extended && u.ty == foldsynth::grammar::VertexType::Terminal {
                // Never touched by the rules; VF2 already keeps its creases.
                return true;
            }
            let tails = |g: &CreaseGraph, cs: &[foldsynth::grammar::Cid]| -> Vec<Vid> {
                cs.iter().map(|&c| g.crease(c).unwrap().tail).collect()
            };
            let heads =
                |g: &CreaseGraph, s: &[Option<foldsynth::grammar::Cid>; 3]| -> Vec<Option<Vid>> {
                    s.iter()
                        .map(|c| c.map(|c| g.crease(c).unwrap().head))
                        .collect()
                };
            let (mut tb, mut hb) = (tails(b, &w.preds), heads(b, &w.slots));
            if mirror {
                tb.reverse();
                hb.reverse();
            }
            tails(a, &u.preds).into_iter().map(to_b).collect::<Vec<_>>() == tb
                && heads(a, &u.slots)
                    .into_iter()
                    .map(|h| h.map(to_b))
                    .collect::<Vec<_>>()
                    == hb
        });
        let mark = ignore_mark || a.last_extended().map(to_b) == b.last_extended();
        if ok && mark {
            return true;
        }
    }
    false
}

#[test]
fn different_designs_have_different_codes() {
    let task = gripper();
    // 2, 3 and 2, 4 are isomorphic as plain digraphs, but not as embedded graphs.
    let (a, b) = (g(&task, "2, 3"), g(&task, "2, 4"));
    assert!(is_isomorphic(&a.compact_digraph(), &b.compact_digraph()));
    assert_ne!(a.canonical_code(), b.canonical_code());
    assert!(!oracle_isomorphic(&a, &b, false));
    // 2, 3, 4 and 2, 4, 3 are the same graph with different marks (gripping candidates).
    let (a, b) = (g(&task, "2, 3, 4"), g(&task, "2, 4, 3"));
    assert!(oracle_isomorphic(&a, &b, true));
    assert!(!oracle_isomorphic(&a, &b, false));
    assert_ne!(a.canonical_code(), b.canonical_code());
    // So are the thesis's meaningful 2, 3, 4, (8, 9) and 2, 4, 3, (6, 11).
    let (a, b) = (g(&task, "2, 3, 4, (8, 9)"), g(&task, "2, 4, 3, (6, 11)"));
    assert!(oracle_isomorphic(&a, &b, true));
    assert_ne!(a.canonical_code(), b.canonical_code());
}

#[test]
fn different_sequences_can_build_the_same_design() {
    let task = gripper();
    // r1 and r2 on disjoint vertices commute: the names differ, the graph and mark do not.
    let (a, b) = (g(&task, "2, 3, 5, (4, 8)"), g(&task, "2, 3, (4, 8), 5"));
    assert_eq!(a.canonical_code(), b.canonical_code());
    assert!(oracle_isomorphic(&a, &b, false));
    // Three vertices joined by two r2 in either order (and in a third sequence).
    let (a, b) = (
        g(&task, "2, 4, 7, (3, 6), (5, 8)"),
        g(&task, "2, 4, 7, (6, 9), (3, 8)"),
    );
    assert_eq!(a.canonical_code(), b.canonical_code());
    assert!(oracle_isomorphic(&a, &b, false));
    assert_eq!(
        g(&task, "2, 4, (3, 6), 6, (5, 8)").canonical_code(),
        a.canonical_code()
    );
    // And the enumeration catches the later one.
    let e = Enumeration::run(&task, 3, Filters::all());
    assert_eq!(
        e.find("2, 3, (4, 8), 5").unwrap().status,
        Status::Isomorphic
    );
    assert_eq!(
        e.find("2, 4, 7, (6, 9), (3, 8)").unwrap().status,
        Status::Isomorphic
    );
}

/// Over every pair of graphs the raw grammar generates up to N_max = 3: equal codes ⇔ an
/// orientation- and mark-preserving isomorphism exists; equal mirror codes ⇔ one exists
/// to the mirror image (checked as: the mirror code names a graph the oracle confirms).
#[test]
fn codes_agree_with_the_brute_force_oracle() {
    let task = gripper();
    let e = Enumeration::run(&task, 3, Filters::none());
    let graphs: Vec<&CreaseGraph> = e.nodes.iter().map(|n| &n.graph).collect();
    let codes: Vec<_> = graphs.iter().map(|g| g.canonical_code()).collect();
    let mirrors: Vec<_> = graphs.iter().map(|g| g.mirror_code().unwrap()).collect();
    let (mut equal, mut mirrored) = (0, 0);
    for i in 0..graphs.len() {
        for j in 0..=i {
            if graphs[i].vertex_ids().len() != graphs[j].vertex_ids().len() {
                assert!(codes[i] != codes[j] && mirrors[i] != codes[j]);
                continue;
            }
            let (gi, gj) = (graphs[i], graphs[j]);
            let same = codes[i] == codes[j];
            let mirror = mirrors[i] == codes[j];
            equal += usize::from(same && i != j);
            mirrored += usize::from(mirror);
            assert_eq!(
                same,
                oracle(gi, gj, false, false),
                "{} | {}",
                gi.sequence(),
                gj.sequence()
            );
            assert_eq!(
                mirror,
                oracle(gi, gj, false, true),
                "mirror {} | {}",
                gi.sequence(),
                gj.sequence()
            );
        }
    }
    assert!(
        equal > 50,
        "the raw language has many duplicate designs ({equal} pairs)"
    );
    assert!(mirrored > 100, "{mirrored} mirror pairs");
}

#[test]
fn mirror_images_swap_slots_one_and_three() {
    let task = gripper();
    let a = g(&task, "2, 3");
    assert!(a.is_mirror_of(&g(&task, "2, 5")));
    assert!(!a.is_mirror_of(&g(&task, "2, 4")));
    // 2, 4 extends the middle successor: its own mirror image.
    let m = g(&task, "2, 4");
    assert_eq!(m.mirror_code(), Some(m.canonical_code()));
    // Mirroring twice is the identity, and mirror images keep the mark.
    let (x, y) = (g(&task, "2, 3, 8, (7, 9)"), g(&task, "2, 5, 6, (7, 11)"));
    assert!(x.is_mirror_of(&y) && y.is_mirror_of(&x));
}
