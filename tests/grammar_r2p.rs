//! Rule r2′ (thesis Sec. 5.7, Fig. 52b; issue 19): its match, its transformation, the
//! primed notation, the filters on the new graphs, and bad input.

use std::collections::HashSet;

use foldsynth::grammar::{
    Cid, CreaseGraph, Enumeration, Filters, Rules, Status, StepRecord, VertexType, Vid,
    format_sequence, parse_sequence,
};
use foldsynth::task::Task;
use petgraph::algo::isomorphism::subgraph_isomorphisms_iter;
use proptest::prelude::*;

fn gripper() -> Task {
    Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap()
}

fn g(task: &Task, s: &str) -> CreaseGraph {
    CreaseGraph::from_sequence(task, s).unwrap()
}

fn named(g: &CreaseGraph, n: usize) -> Vid {
    g.vid_by_name(n).unwrap()
}

fn tails(g: &CreaseGraph, v: Vid) -> Vec<Vid> {
    g.vertex(v)
        .unwrap()
        .preds
        .iter()
        .map(|&c| g.crease(c).unwrap().tail)
        .collect()
}

#[test]
fn fig52b_is_a_miura_ori_cell_with_a_sink_on_the_straight_crease() {
    let task = gripper();
    let before = g(&task, "2, 3, 4, 8");
    let cell = g(&task, "2, 3, 4, 8, (9, 14)'");
    assert_eq!(cell.sequence(), "2, 3, 4, 8, (9, 14)'");
    // v9 (s1 of v4) and v14 (s3 of v8) give way to the sink v9′ between v4 and v8.
    let sink = named(&cell, 9);
    let v = cell.vertex(sink).unwrap();
    assert_eq!(v.sink_between, Some([named(&cell, 4), named(&cell, 8)]));
    assert_eq!(tails(&cell, sink), vec![named(&cell, 4), named(&cell, 8)]);
    assert_eq!(v.ty, VertexType::Terminal);
    assert!(!v.extended && v.succ().is_empty() && v.placement.is_none());
    assert_eq!(cell.vertex_ids().len(), before.vertex_ids().len() - 1);
    assert_eq!(cell.internal_count(), 4);
    assert!(cell.is_cyclic_pattern() && !before.is_cyclic_pattern());
    // Still a DAG: both creases run into the sink.
    assert!(cell.is_acyclic());
    // The two far-side facets became one: one facet fewer, and every facet one chain.
    assert_eq!(cell.facet_count(), before.facet_count() - 1);
    let facets = cell.facet_boundaries().unwrap();
    // The central facet is closed: v2 → v3 → v8 → v9′ ← v4 ← v2 (five corners).
    let central = facets
        .iter()
        .find(|f| f.closed)
        .expect("the cycle closes a facet");
    let mut corners: Vec<usize> = central
        .vertices
        .iter()
        .map(|&v| cell.name(v).unwrap())
        .collect();
    corners.sort_unstable();
    assert_eq!(corners, vec![2, 3, 4, 8, 9]);
    // The merged facet runs v10 ← v4 → v9′ ← v8 → v13 (open: the paper's edge closes it).
    let outer = facets
        .iter()
        .find(|f| !f.closed && f.vertices.contains(&sink))
        .unwrap();
    let names: Vec<usize> = outer
        .vertices
        .iter()
        .map(|&v| cell.name(v).unwrap())
        .collect();
    assert_eq!(names, vec![10, 4, 9, 8, 13]);
    // The record: r2 with the straight flag, both placements gone, no free variable left
    // for the sink; v4's α_9 survives because it places v10 (α_9 + α_10).
    let Some(StepRecord::R2(r)) = cell.steps().last() else {
        panic!("r2′ is recorded as an r2 step");
    };
    let s = r.straight.as_ref().unwrap();
    assert_eq!(s.sink, sink);
    assert_eq!(r.names, (9, 14));
    let names: HashSet<&str> = r
        .eliminated
        .iter()
        .map(|v| cell.variables()[v.0 as usize].name.as_str())
        .collect();
    assert_eq!(names, HashSet::from(["l_4,9", "α_14", "l_8,14"]));
    // No constraint bounds the straight angle at the sink.
    assert!(cell.constraints().iter().all(|c| !matches!(
        c,
        foldsynth::grammar::ConstraintSpec::MergedSector { vertex, .. } if *vertex == sink
    )));
}

/// r2′'s conditions, stated from the graph's public data (not from the rule's code).
fn should_match(g: &CreaseGraph, c1: Vid, c2: Vid) -> bool {
    let (a, b) = (g.vertex(c1).unwrap(), g.vertex(c2).unwrap());
    if g.check_combine(c1, c2).is_err() || a.preds.len() != 1 || b.preds.len() != 1 {
        return false;
    }
    if a.in_g0() || b.in_g0() {
        return false;
    }
    let (e1, e2) = (g.crease(a.preds[0]).unwrap(), g.crease(b.preds[0]).unwrap());
    let (p1, p2) = (e1.tail, e2.tail);
    let joined = g
        .creases()
        .any(|c| (c.tail == p1 && c.head == p2) || (c.tail == p2 && c.head == p1))
        || g.sinks().any(|v| {
            let [a, b] = v.sink_between.unwrap();
            (a, b) == (p1, p2) || (a, b) == (p2, p1)
        });
    let (fa, fb) = (e1.left, e2.right);
    let merge = |f| if f == fb { fa } else { f };
    let looped = g.creases().any(|c| merge(c.left) == merge(c.right));
    !joined && !looped
}

#[test]
fn r2p_applies_exactly_where_its_match_holds() {
    let task = gripper();
    let e = Enumeration::run_with(&task, 3, Filters::none(), Rules::all());
    let (mut yes, mut no) = (0, 0);
    for node in &e.nodes {
        let gr = &node.graph;
        let matches: HashSet<(Vid, Vid)> =
            gr.r2p_matches().iter().map(|(_, m)| (m.c1, m.c2)).collect();
        for a in gr.vertices() {
            for b in gr.vertices() {
                if a.vid == b.vid {
                    continue;
                }
                let want = should_match(gr, a.vid, b.vid);
                assert_eq!(
                    gr.check_combine_straight(a.vid, b.vid).is_ok(),
                    want,
                    "{}: v{} v{}",
                    gr.sequence(),
                    gr.name(a.vid).unwrap(),
                    gr.name(b.vid).unwrap()
                );
                assert_eq!(matches.contains(&(a.vid, b.vid)), want);
                if want {
                    yes += 1;
                } else {
                    no += 1;
                }
            }
        }
    }
    assert!(
        yes >= 20 && no > 100 * yes,
        "{yes} matches, {no} non-matches"
    );
}

#[test]
fn primed_pairs_round_trip() {
    let task = gripper();
    for text in [
        "2, 3, 4, 8, (9, 14)'",
        "2, 3, 4, (8, 9)'",
        "2, 3, 4, (8, 9)', (7, 9)",
        "2, 3, 8, (7, 9), (4, 10)', (5, 9)",
    ] {
        let steps = parse_sequence(text).unwrap();
        assert_eq!(format_sequence(&steps), text);
        let gr = g(&task, text);
        assert_eq!(gr.sequence(), text);
        assert_eq!(
            g(&task, &gr.sequence()).canonical_code(),
            gr.canonical_code()
        );
    }
    // The typographic prime and missing spaces read the same.
    assert_eq!(
        parse_sequence("2,3,4,8,(9,14)′").unwrap(),
        parse_sequence("2, 3, 4, 8, (9, 14)'").unwrap()
    );
    // Every graph of the enumeration (r2′ on) rebuilds from its sequence.
    let e = Enumeration::run_with(&task, 3, Filters::all(), Rules::all());
    for n in &e.nodes {
        let h = g(&task, &n.graph.sequence());
        assert_eq!(h.canonical_code(), n.graph.canonical_code());
    }
}

#[test]
fn malformed_primes_are_rejected_with_the_reason() {
    for (text, needle) in [
        ("2, 3, 4, 8, (9, 14)''", "one prime marks r2′"),
        ("2, 3, 4, 8'", "a single name is r1"),
        ("2, 3, (9)'", "expected `,`"),
        ("2, 3, (9, 14'", "expected `)`"),
        ("2, 3, (9, 14)x", "expected `,` between steps"),
        ("2, 3, (9, 9)'", "two different vertices"),
        ("'", "expected a vertex name"),
    ] {
        let e = parse_sequence(text).unwrap_err().to_string();
        assert!(e.contains(needle), "{text}: {e}");
        assert!(e.contains(text), "{text}: {e}");
    }
}

#[test]
fn bad_r2p_steps_say_why() {
    let task = gripper();
    for (text, needle) in [
        // v9 (s1 of v4) and v12 (s1 of v8): no facet in common.
        ("2, 3, 4, 8, (9, 12)'", "do not share a facet"),
        // v4 is v9's predecessor.
        ("2, 3, 4, 8, (4, 9)'", "v4 is a predecessor of v9"),
        // v5 was already combined by r2: two predecessors.
        ("2, 4, 7, (3, 6), (5, 8)'", "v5 has 2 predecessors"),
        // v1 is G0's source.
        ("2, 3, (1, 4)'", "v1 is not extendable"),
        // v4 and v8: their predecessors v2 and v3 are joined by the crease v2 → v3.
        ("2, 3, (4, 8)'", "joined by a crease"),
        // A second sink between v3 and v4 would lie on the first one's straight crease.
        (
            "2, 3, 4, (8, 9)', (7, 9)'",
            "v4 and v3 are joined by a crease already",
        ),
        ("2, 3, (4, 99)'", "there is no vertex v99"),
    ] {
        let err = CreaseGraph::from_sequence(&task, text)
            .unwrap_err()
            .to_string();
        assert!(err.contains(needle), "{text}: {err}");
        assert!(
            err.contains("r2′") || needle.starts_with("there"),
            "{text}: {err}"
        );
    }
    // Through the binary: a clear message and a non-zero exit.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args([
            "model",
            "grammar/gripper.toml",
            "--graph",
            "2, 3, 4, 8, (4, 9)'",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("v4 is a predecessor of v9"), "{err}");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(["enumerate", "grammar/gripper.toml", "--rules", "r1,r2,r3"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("\"r3\" is not a rule"), "{err}");
}

#[test]
fn r2p_is_off_by_default_and_the_thesis_counts_stay() {
    let task = gripper();
    let plain = Enumeration::run(&task, 3, Filters::all());
    let with = Enumeration::run_with(&task, 3, Filters::all(), Rules::default());
    assert_eq!(plain.meaningful().count(), 53);
    assert_eq!(plain.alternatives(), 1194);
    assert_eq!(with.meaningful().count(), 53);
    assert!(plain.nodes.iter().all(|n| !n.graph.is_cyclic_pattern()));
    // With r2′ the acyclic part of the language is unchanged: r2′ only adds graphs.
    let all = Enumeration::run_with(&task, 3, Filters::all(), Rules::all());
    let acyclic: HashSet<String> = all
        .meaningful()
        .filter(|n| !n.graph.is_cyclic_pattern())
        .map(|n| n.graph.sequence())
        .collect();
    let old: HashSet<String> = plain.meaningful().map(|n| n.graph.sequence()).collect();
    assert_eq!(acyclic, old);
    assert!(all.meaningful().any(|n| n.graph.is_cyclic_pattern()));
    assert!(all.find("2, 3, 4, (8, 9)'").is_some());
    assert_eq!(Rules::parse("r1,r2").unwrap(), Rules::default());
    assert_eq!(Rules::parse("r1, r2, r2′").unwrap(), Rules::all());
    assert!(Rules::parse("r2,r2p").unwrap_err().contains("r1 must be"));
}

/// An orientation- and mark-preserving isomorphism a → b (or to b's mirror image) exists:
/// the brute-force oracle of `grammar_isomorphism.rs`, where a sink's two creases are an
/// unordered pair (two rays read the same both ways round).
fn oracle(a: &CreaseGraph, b: &CreaseGraph, mirror: bool) -> bool {
    let (da, db) = (a.compact_digraph(), b.compact_digraph());
    if da.node_count() != db.node_count() || da.edge_count() != db.edge_count() {
        return false;
    }
    let mut nm = |x: &Vid, y: &Vid| {
        let (u, v) = (a.vertex(*x).unwrap(), b.vertex(*y).unwrap());
        u.ty == v.ty
            && u.extended == v.extended
            && u.g0 == v.g0
            && u.preds.len() == v.preds.len()
            && u.sink_between.is_some() == v.sink_between.is_some()
    };
    let mut em = |_: &_, _: &_| true;
    let (ra, rb) = (&da, &db);
    let Some(maps) = subgraph_isomorphisms_iter(&ra, &rb, &mut nm, &mut em) else {
        return false;
    };
    for map in maps {
        let to_b = |v: Vid| db[petgraph::graph::NodeIndex::new(map[a.name(v).unwrap() - 1])];
        let ends = |g: &CreaseGraph, cs: &[Cid]| -> Vec<Vid> {
            cs.iter().map(|&c| g.crease(c).unwrap().tail).collect()
        };
        let heads = |g: &CreaseGraph, s: &[Option<Cid>; 3]| -> Vec<Option<Vid>> {
            s.iter()
                .map(|c| c.map(|c| g.crease(c).unwrap().head))
                .collect()
        };
        let ok = a.vertices().all(|u| {
            let w = b.vertex(to_b(u.vid)).unwrap();
            if u.in_g0() && !u.extended && u.ty == VertexType::Terminal {
                return true;
            }
            let mut pa: Vec<Vid> = ends(a, &u.preds).into_iter().map(to_b).collect();
            let (mut pb, mut hb) = (ends(b, &w.preds), heads(b, &w.slots));
            if u.sink_between.is_some() {
                pa.sort();
                pb.sort();
                return pa == pb;
            }
            if mirror {
                pb.reverse();
                hb.reverse();
            }
            pa == pb
                && heads(a, &u.slots)
                    .into_iter()
                    .map(|h| h.map(to_b))
                    .collect::<Vec<_>>()
                    == hb
        });
        if ok && a.last_extended().map(to_b) == b.last_extended() {
            return true;
        }
    }
    false
}

/// The filters on cyclic graphs: over every pair of raw graphs (r2′ on, N_max = 3) with a
/// cyclic one among them, equal codes ⇔ the oracle finds an isomorphism, equal mirror
/// codes ⇔ it finds one to the mirror image; and the filtered enumeration (N_max = 4) keeps
/// one graph per code, drops mirror images with their descendants, and marks invalid graphs
/// as the old grammar does.
#[test]
fn filters_treat_cyclic_graphs_as_the_old_ones() {
    let task = gripper();
    let e = Enumeration::run_with(&task, 3, Filters::none(), Rules::all());
    let graphs: Vec<&CreaseGraph> = e.nodes.iter().map(|n| &n.graph).collect();
    let codes: Vec<_> = graphs.iter().map(|g| g.canonical_code()).collect();
    let mirrors: Vec<_> = graphs.iter().map(|g| g.mirror_code().unwrap()).collect();
    let (mut equal, mut mirrored, mut pairs) = (0, 0, 0);
    for i in 0..graphs.len() {
        for j in 0..=i {
            if !graphs[i].is_cyclic_pattern() && !graphs[j].is_cyclic_pattern() {
                continue;
            }
            if graphs[i].vertex_ids().len() != graphs[j].vertex_ids().len() {
                assert!(codes[i] != codes[j] && mirrors[i] != codes[j]);
                continue;
            }
            pairs += 1;
            let same = codes[i] == codes[j];
            let mirror = mirrors[i] == codes[j];
            equal += usize::from(same && i != j);
            mirrored += usize::from(mirror);
            let (a, b) = (graphs[i], graphs[j]);
            assert_eq!(
                same,
                oracle(a, b, false),
                "{} | {}",
                a.sequence(),
                b.sequence()
            );
            assert_eq!(
                mirror,
                oracle(a, b, true),
                "mirror {} | {}",
                a.sequence(),
                b.sequence()
            );
        }
    }
    assert!(
        pairs > 1000 && equal > 10 && mirrored > 10,
        "{pairs} {equal} {mirrored}"
    );

    // Every graph, cyclic or not, gives a model plan (its facets are simple polygons).
    for gr in &graphs {
        assert!(
            foldsynth::model::Plan::new(gr).is_ok(),
            "{}: {:?}",
            gr.sequence(),
            foldsynth::model::Plan::new(gr).err()
        );
    }
    // N_max = 4: the first level where cyclic graphs fall to every filter.
    let f = Enumeration::run_with(&task, 4, Filters::all(), Rules::all());
    let mut kept = HashSet::new();
    for n in &f.nodes {
        let code = n.graph.canonical_code();
        match n.status {
            Status::Isomorphic => assert!(
                kept.contains(&code)
                    || f.nodes.iter().any(|m| {
                        m.status != Status::Isomorphic && m.graph.canonical_code() == code
                    })
            ),
            Status::Mirror => {
                let m = n.graph.mirror_code().unwrap();
                assert_ne!(m, code);
                assert!(kept.contains(&m), "{}", n.graph.sequence());
            }
            Status::Invalid => assert!(!n.graph.is_semantically_valid()),
            Status::Meaningful => assert!(n.graph.is_semantically_valid()),
        }
        if matches!(n.status, Status::Meaningful | Status::Invalid) {
            assert!(kept.insert(code), "kept twice: {}", n.graph.sequence());
        }
        // A mirror image's descendants are never generated.
        let mut p = n.parent;
        while let Some(k) = p {
            assert_ne!(f.nodes[k].status, Status::Mirror);
            p = f.nodes[k].parent;
        }
    }
    // Some cyclic graphs fall to each filter.
    for s in [
        Status::Isomorphic,
        Status::Mirror,
        Status::Invalid,
        Status::Meaningful,
    ] {
        assert!(
            f.nodes
                .iter()
                .any(|n| n.status == s && n.graph.is_cyclic_pattern()),
            "{s:?}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(150))]

    /// Random walks with r1, r2 and r2′: the graphs stay well formed (every facet one
    /// chain, every extended vertex three creases, sinks fed by two creases from their
    /// ends), eliminated variables are exactly those no placement uses, and the sequence
    /// rebuilds the graph.
    #[test]
    fn random_walks_with_r2p_stay_well_formed(choices in proptest::collection::vec(0usize..1000, 1..14)) {
        let task = gripper();
        let mut gr = CreaseGraph::initial(&task);
        for c in choices {
            let r1 = gr.r1_matches(6);
            let r2 = gr.r2_matches();
            let r2p = gr.r2p_matches();
            let n = r1.len() + r2.len() + r2p.len();
            if n == 0 {
                break;
            }
            let k = c % n;
            if k < r1.len() {
                gr.extend(r1[k]).unwrap();
            } else if k < r1.len() + r2.len() {
                gr.combine(r2[k - r1.len()].1).unwrap();
            } else {
                gr.combine_straight(r2p[k - r1.len() - r2.len()].1).unwrap();
            }
        }
        prop_assert!(gr.is_acyclic());
        prop_assert!(gr.facet_boundaries().is_ok(), "{}: {:?}", gr.sequence(), gr.facet_boundaries());
        for v in gr.vertices() {
            if v.extended {
                prop_assert_eq!(v.succ().len(), 3);
            }
            if let Some(ends) = v.sink_between {
                prop_assert_eq!(tails(&gr, v.vid), ends.to_vec());
                prop_assert!(v.succ().is_empty());
            }
        }
        let used: HashSet<u32> = gr.creases().flat_map(|c| [c.left.0, c.right.0]).collect();
        prop_assert_eq!(used.len(), gr.facet_count());
        let eliminated: Vec<_> = gr.steps().iter().filter_map(|s| match s {
            StepRecord::R2(r) => Some(r.eliminated.clone()),
            StepRecord::R1(_) => None,
        }).flatten().collect();
        for v in gr.variables() {
            prop_assert_eq!(gr.is_free(v.id), !eliminated.contains(&v.id), "{} {}", gr.sequence(), v.name);
        }
        prop_assert!(foldsynth::model::Plan::new(&gr).is_ok(), "{}: {:?}", gr.sequence(), foldsynth::model::Plan::new(&gr).err());
        let h = CreaseGraph::from_sequence(&task, &gr.sequence()).unwrap();
        prop_assert_eq!(h.canonical_code(), gr.canonical_code());
    }
}
