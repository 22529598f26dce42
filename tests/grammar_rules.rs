//! Rules r1 (all six scenarios of Tables 1–2) and r2, and what they record for the model.

use std::f64::consts::PI;

use foldsynth::grammar::{
    Cid, ConstraintSpec, CreaseGraph, CreaseOrigin, Enumeration, Filters, StepRecord, Substitution,
    VarKind, VertexType, Vid,
};
use foldsynth::task::Task;

fn gripper() -> Task {
    Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap()
}

/// G0 = v1 → v2 (f1 | f2) plus extra vertices and creases (TOML snippets).
fn task_with(extra: &str) -> Task {
    let text = format!(
        r#"
[grammar]
n_max = 3
[[initial_graph.vertices]]
id = "v1"
xy = [0.0, 0.0]
type = "terminal"
[[initial_graph.vertices]]
id = "v2"
xy = [1.0, 0.0]
type = "extendable"
[[initial_graph.creases]]
from = "v1"
to = "v2"
left = "f1"
right = "f2"
drive = "t"
{extra}
"#
    );
    Task::from_toml_str(&text, "test.toml").unwrap_or_else(|e| panic!("{e}"))
}

fn vertex(id: &str, x: f64, y: f64, ty: &str) -> String {
    format!("[[initial_graph.vertices]]\nid = \"{id}\"\nxy = [{x}, {y}]\ntype = \"{ty}\"\n")
}

fn crease(from: &str, to: &str, left: &str, right: &str) -> String {
    format!(
        "[[initial_graph.creases]]\nfrom = \"{from}\"\nto = \"{to}\"\nleft = \"{left}\"\nright = \"{right}\"\n"
    )
}

fn labels(g: &CreaseGraph, c: Cid) -> (String, String) {
    let c = g.crease(c).unwrap();
    (
        g.facet_name(c.left).to_owned(),
        g.facet_name(c.right).to_owned(),
    )
}

fn name(g: &CreaseGraph, v: Vid) -> usize {
    g.name(v).unwrap()
}

fn var_names(g: &CreaseGraph, vars: &[foldsynth::grammar::VarId]) -> Vec<String> {
    vars.iter()
        .map(|v| g.variables()[v.0 as usize].name.clone())
        .collect()
}

/// In-plane positions from the placements (Eq. 28) with every sector variable at `alpha`
/// and every length 1: an independent check that placements and slot order agree.
fn positions(g: &CreaseGraph, alpha: f64) -> Vec<Option<[f64; 2]>> {
    let n = g.vertices().map(|v| v.vid.0 as usize + 1).max().unwrap();
    let mut x: Vec<Option<[f64; 2]>> = vec![None; n];
    let mut ids: Vec<Vid> = g.vertices().map(|v| v.vid).collect();
    ids.sort();
    for vid in ids {
        let v = g.vertex(vid).unwrap();
        x[vid.0 as usize] = Some(match (&v.g0_coords, &v.placement) {
            (Some(c), _) => *c,
            (None, Some(p)) => {
                let a = x[p.parent.0 as usize].unwrap();
                let r = x[p.reference.0 as usize].unwrap();
                let base = (r[1] - a[1]).atan2(r[0] - a[0]);
                let th = base + p.sign * alpha * p.sectors.len() as f64;
                [a[0] + th.cos(), a[1] + th.sin()]
            }
            (None, None) => unreachable!(),
        });
    }
    x
}

/// At every extended vertex with one predecessor, the creases p1, s1, s2, s3 go round
/// counter-clockwise.
fn assert_rotation_matches_geometry(g: &CreaseGraph) {
    let x = positions(g, 70f64.to_radians());
    for v in g.vertices().filter(|v| v.extended && v.preds.len() == 1) {
        let at = x[v.vid.0 as usize].unwrap();
        let dir = |c: Cid| {
            let cr = g.crease(c).unwrap();
            let o = if cr.tail == v.vid { cr.head } else { cr.tail };
            let p = x[o.0 as usize].unwrap();
            (p[1] - at[1]).atan2(p[0] - at[0])
        };
        let p1 = dir(v.preds[0]);
        let ccw: Vec<f64> = v
            .succ()
            .iter()
            .map(|&c| (dir(c) - p1).rem_euclid(2.0 * PI))
            .collect();
        assert!(
            ccw[0] > 1e-9 && ccw[0] < ccw[1] && ccw[1] < ccw[2],
            "{}: v{} {:?}",
            g.sequence(),
            name(g, v.vid),
            ccw
        );
    }
}

#[test]
fn r1_on_the_thesis_g0_follows_fig_41() {
    let task = gripper();
    let g = CreaseGraph::from_sequence(&task, "2").unwrap();
    let v2 = g.vid_by_name(2).unwrap();
    let s = g.vertex(v2).unwrap().succ();
    assert_eq!(s.len(), 3);
    // (a→s1) = (new f, F_R(pm→a)); (a→s2) = (new f', f); (a→s3) = (F_L(p1→a), f').
    assert_eq!(labels(&g, s[0]), ("f3".into(), "f2".into()));
    assert_eq!(labels(&g, s[1]), ("f4".into(), "f3".into()));
    assert_eq!(labels(&g, s[2]), ("f1".into(), "f4".into()));
    // s1, s2, s3 are appended as v3, v4, v5, type χ, predecessor v2.
    for (k, &c) in s.iter().enumerate() {
        let h = g.crease(c).unwrap().head;
        assert_eq!(name(&g, h), 3 + k);
        let hv = g.vertex(h).unwrap();
        assert_eq!(hv.ty, VertexType::Extendable);
        assert_eq!(hv.preds, vec![c]);
        assert!(!hv.in_g0());
    }
    let a = g.vertex(v2).unwrap();
    assert_eq!(a.ty, VertexType::Terminal);
    assert!(a.extended);
    assert_eq!(g.extension_order(), &[v2]);
    assert_eq!(
        g.gripping_candidates().unwrap().map(|v| name(&g, v)),
        [3, 4, 5]
    );
    // Eq. 28: s1 and s2 from p_m counter-clockwise, s3 from p_1 clockwise.
    let v1 = g.vid_by_name(1).unwrap();
    let p3 = g
        .vertex(g.vid_by_name(3).unwrap())
        .unwrap()
        .placement
        .clone()
        .unwrap();
    let p4 = g
        .vertex(g.vid_by_name(4).unwrap())
        .unwrap()
        .placement
        .clone()
        .unwrap();
    let p5 = g
        .vertex(g.vid_by_name(5).unwrap())
        .unwrap()
        .placement
        .clone()
        .unwrap();
    assert_eq!((p3.parent, p3.reference, p3.sign), (v2, v1, 1.0));
    assert_eq!((p4.reference, p4.sign, p4.sectors.len()), (v1, 1.0, 2));
    assert_eq!(p4.sectors[0], p3.sectors[0]);
    assert_eq!((p5.reference, p5.sign), (v1, -1.0));
    assert_eq!(
        var_names(
            &g,
            &[
                p3.sectors[0],
                p3.length,
                p4.sectors[1],
                p4.length,
                p5.sectors[0],
                p5.length
            ]
        ),
        ["α_3", "l_2,3", "α_4", "l_2,4", "α_5", "l_2,5"]
    );
    assert!(g.variables().iter().all(|v| v.step == 0));
    assert_eq!(
        g.variables()
            .iter()
            .filter(|v| v.kind == VarKind::Sector)
            .count(),
        3
    );
    // Eq. 31–33.
    let StepRecord::R1(r) = &g.steps()[0] else {
        panic!()
    };
    assert_eq!(r.scenario, 1);
    assert_eq!(
        r.constraints,
        vec![
            ConstraintSpec::Sector {
                vertex: v2,
                from: Cid(0),
                to: s[0],
                var: Some(p3.sectors[0])
            },
            ConstraintSpec::Sector {
                vertex: v2,
                from: s[0],
                to: s[1],
                var: Some(p4.sectors[1])
            },
            ConstraintSpec::Sector {
                vertex: v2,
                from: s[2],
                to: Cid(0),
                var: Some(p5.sectors[0])
            },
            ConstraintSpec::Remainder {
                vertex: v2,
                from: s[1],
                to: s[2]
            },
            ConstraintSpec::Length {
                crease: s[0],
                var: Some(p3.length)
            },
            ConstraintSpec::Length {
                crease: s[1],
                var: Some(p4.length)
            },
            ConstraintSpec::Length {
                crease: s[2],
                var: Some(p5.length)
            },
            ConstraintSpec::RigidFoldability { vertex: v2 },
        ]
    );
    assert_eq!(g.constraints(), r.constraints);
    // The crease's origin records its slot and variables.
    match &g.crease(s[1]).unwrap().origin {
        CreaseOrigin::Extension {
            step,
            slot,
            sector,
            length,
            created,
        } => {
            assert_eq!(
                (*step, *slot, *sector, *length),
                (0, 2, p4.sectors[1], p4.length)
            );
            assert_eq!(name(&g, *created), 4);
        }
        o => panic!("{o:?}"),
    }
    assert!(
        matches!(&g.crease(Cid(0)).unwrap().origin, CreaseOrigin::Initial { index: 0, drive: Some(d) } if d.as_str() == "t")
    );
    assert_rotation_matches_geometry(&g);
}

struct Scenario {
    number: u8,
    extra: String,
    /// Expected (slot, left, right) of the new creases.
    new: Vec<(u8, &'static str, &'static str)>,
    /// Expected (slot, reference name, sign, number of sectors) of the new vertices.
    placed: Vec<(u8, usize, f64, usize)>,
    /// The remainder sector (Eq. 31) as slots (from, to).
    remainder: (u8, u8),
}

/// Tables 1–2: the six ways G0 can already own outgoing slots of v2.
fn scenarios() -> Vec<Scenario> {
    let v = vertex;
    let c = crease;
    vec![
        Scenario {
            number: 1,
            extra: String::new(),
            new: vec![(1, "f3", "f2"), (2, "f4", "f3"), (3, "f1", "f4")],
            placed: vec![(1, 1, 1.0, 1), (2, 1, 1.0, 2), (3, 1, -1.0, 1)],
            remainder: (2, 3),
        },
        // r1,2: s3 exists, F_L(a,s3) = F_L(p1,a).
        Scenario {
            number: 2,
            extra: [v("v3", 1.0, 1.0, "terminal"), c("v2", "v3", "f1", "f3")].concat(),
            new: vec![(1, "f4", "f2"), (2, "f3", "f4")],
            placed: vec![(1, 1, 1.0, 1), (2, 1, 1.0, 2)],
            remainder: (2, 3),
        },
        // r1,3: s1 exists, F_R(a,s1) = F_R(pm,a); s2 is placed from s1.
        Scenario {
            number: 3,
            extra: [v("v3", 1.0, -1.0, "terminal"), c("v2", "v3", "f3", "f2")].concat(),
            new: vec![(2, "f4", "f3"), (3, "f1", "f4")],
            placed: vec![(2, 3, 1.0, 1), (3, 1, -1.0, 1)],
            remainder: (2, 3),
        },
        // r1,4: s2 and s3 exist; the remainder lies between s1 and s2.
        Scenario {
            number: 4,
            extra: [
                v("v3", 2.0, 0.0, "terminal"),
                v("v4", 1.0, 1.0, "terminal"),
                c("v2", "v3", "f3", "f4"),
                c("v2", "v4", "f1", "f3"),
            ]
            .concat(),
            new: vec![(1, "f4", "f2")],
            placed: vec![(1, 1, 1.0, 1)],
            remainder: (1, 2),
        },
        // r1,5: s1 and s3 exist.
        Scenario {
            number: 5,
            extra: [
                v("v3", 1.0, -1.0, "terminal"),
                v("v4", 1.0, 1.0, "terminal"),
                c("v2", "v3", "f3", "f2"),
                c("v2", "v4", "f1", "f4"),
            ]
            .concat(),
            new: vec![(2, "f4", "f3")],
            placed: vec![(2, 3, 1.0, 1)],
            remainder: (2, 3),
        },
        // r1,6: s1 and s2 exist.
        Scenario {
            number: 6,
            extra: [
                v("v3", 1.0, -1.0, "terminal"),
                v("v4", 2.0, 0.0, "terminal"),
                c("v2", "v3", "f3", "f2"),
                c("v2", "v4", "f4", "f3"),
            ]
            .concat(),
            new: vec![(3, "f1", "f4")],
            placed: vec![(3, 1, -1.0, 1)],
            remainder: (2, 3),
        },
    ]
}

#[test]
fn r1_fills_the_missing_slots_in_all_six_scenarios() {
    for sc in scenarios() {
        let task = task_with(&sc.extra);
        let mut g = CreaseGraph::initial(&task);
        let v2 = g.vid_by_name(2).unwrap();
        let before: Vec<Option<Cid>> = g.vertex(v2).unwrap().slots.to_vec();
        g.extend(v2).unwrap();
        let StepRecord::R1(r) = &g.steps()[0] else {
            panic!()
        };
        assert_eq!(r.scenario, sc.number);
        let after = g.vertex(v2).unwrap().slots;
        // Existing slots stay, missing ones are filled.
        for k in 0..3 {
            if let Some(c) = before[k] {
                assert_eq!(after[k], Some(c), "r1,{}: slot {}", sc.number, k + 1);
            }
        }
        assert_eq!(r.created.len(), sc.new.len(), "r1,{}", sc.number);
        for (cr, &(slot, left, right)) in r.created.iter().zip(&sc.new) {
            assert_eq!(cr.slot, slot, "r1,{}", sc.number);
            assert_eq!(after[slot as usize - 1], Some(cr.crease));
            assert_eq!(
                labels(&g, cr.crease),
                (left.to_owned(), right.to_owned()),
                "r1,{} slot {slot}",
                sc.number
            );
        }
        for (cr, &(slot, reference, sign, n)) in r.created.iter().zip(&sc.placed) {
            assert_eq!(cr.slot, slot);
            let p = cr
                .placement
                .as_ref()
                .expect("a representative's crease is placed");
            assert_eq!(
                (name(&g, p.reference), p.sign, p.sectors.len()),
                (reference, sign, n),
                "r1,{} slot {slot}",
                sc.number
            );
            assert_eq!(g.vertex(cr.vertex).unwrap().placement.as_ref(), Some(p));
        }
        let s = after.map(Option::unwrap);
        assert!(
            r.constraints.contains(&ConstraintSpec::Remainder {
                vertex: v2,
                from: s[sc.remainder.0 as usize - 1],
                to: s[sc.remainder.1 as usize - 1]
            }),
            "r1,{}: {:?}",
            sc.number,
            r.constraints
        );
        // One sector bound and one length bound per new crease, one remainder, Eq. 33.
        let count = |f: fn(&ConstraintSpec) -> bool| r.constraints.iter().filter(|c| f(c)).count();
        assert_eq!(
            count(|c| matches!(c, ConstraintSpec::Sector { .. })),
            sc.new.len()
        );
        assert_eq!(
            count(|c| matches!(c, ConstraintSpec::Length { .. })),
            sc.new.len()
        );
        assert_eq!(
            count(|c| matches!(c, ConstraintSpec::RigidFoldability { .. })),
            1
        );
        assert!(
            g.facet_boundaries().is_ok(),
            "r1,{}: {:?}",
            sc.number,
            g.facet_boundaries()
        );
        assert_rotation_matches_geometry(&g);
        // The new vertices extend further, consistently.
        let mut h = g.clone();
        h.extend(r.created[0].vertex).unwrap();
        assert!(h.facet_boundaries().is_ok());
        assert_rotation_matches_geometry(&h);
    }
}

#[test]
fn placements_agree_with_the_rotation_in_every_r1_only_graph() {
    let e = Enumeration::run(&gripper(), 4, Filters::none());
    let mut n = 0;
    for node in &e.nodes {
        if node
            .graph
            .steps()
            .iter()
            .all(|s| matches!(s, StepRecord::R1(_)))
        {
            assert_rotation_matches_geometry(&node.graph);
            n += 1;
        }
    }
    assert!(n > 100);
}

#[test]
fn r2_moves_the_creases_and_records_eq_34_35() {
    let task = gripper();
    let before = CreaseGraph::from_sequence(&task, "2, 3").unwrap();
    let g = CreaseGraph::from_sequence(&task, "2, 3, (4, 8)").unwrap();
    let v4 = g.vid_by_name(4).unwrap();
    let old_v8 = before.vid_by_name(8).unwrap();
    assert!(g.vertex(old_v8).is_none());
    assert_eq!(g.vertex_ids().len(), before.vertex_ids().len() - 1);
    let StepRecord::R2(r) = g.steps().last().unwrap() else {
        panic!()
    };
    // F_R(v2→v4) = f3 = F_L(v3→v8): c1 = v4, c2 = v8.
    assert_eq!(
        (r.c1, r.c2, r.survivor, r.deleted),
        (v4, old_v8, v4, old_v8)
    );
    assert_eq!(r.names, (4, 8));
    let preds = &g.vertex(v4).unwrap().preds;
    let moved = r.moved[0];
    assert_eq!(preds, &vec![before.vertex(v4).unwrap().preds[0], moved]);
    assert_eq!(g.crease(moved).unwrap().head, v4);
    assert_eq!(labels(&g, moved), labels(&before, moved));
    assert_eq!(labels(&g, moved), ("f3".into(), "f6".into()));
    // Facet f3 is now enclosed by v2 → v3 → v4 ← v2.
    let f3 = g
        .facet_boundaries()
        .unwrap()
        .into_iter()
        .find(|f| f.name == "f3")
        .unwrap();
    assert!(f3.closed);
    assert_eq!(f3.creases.len(), 3);
    // Eq. 35: the deleted vertex's sector and length leave Φ, measured from the coordinates.
    assert_eq!(var_names(&g, &r.eliminated), ["α_8", "l_3,8"]);
    let v3 = g.vid_by_name(3).unwrap();
    let v2 = g.vid_by_name(2).unwrap();
    match &r.substitutions[0] {
        Substitution::Sector {
            at,
            reference,
            crease,
            sign,
            minus,
            ..
        } => {
            assert_eq!((*at, *reference, *crease, *sign), (v3, v2, moved, -1.0));
            assert!(minus.is_empty());
        }
        s => panic!("{s:?}"),
    }
    assert!(matches!(r.substitutions[1], Substitution::Length { crease, .. } if crease == moved));
    assert!(!g.is_free(r.eliminated[0]) && !g.is_free(r.eliminated[1]));
    // Eq. 34 at the combined vertex, between v2→v4 and v3→v4.
    assert_eq!(
        r.constraint,
        ConstraintSpec::MergedSector {
            vertex: v4,
            from: preds[0],
            to: preds[1]
        }
    );
    // The final constraint set measures the moved crease's sector and length geometrically.
    let cs = g.constraints();
    assert!(cs.contains(&ConstraintSpec::Sector {
        vertex: v3,
        from: moved,
        to: g.vertex(v3).unwrap().preds[0],
        var: None
    }));
    assert!(cs.contains(&ConstraintSpec::Length {
        crease: moved,
        var: None
    }));
    assert!(cs.contains(&r.constraint));
    assert_eq!(
        cs.iter()
            .filter(|c| matches!(
                c,
                ConstraintSpec::Sector { var: None, .. } | ConstraintSpec::Length { var: None, .. }
            ))
            .count(),
        2
    );
}

#[test]
fn r2_keeps_a_sector_a_sibling_placement_still_uses() {
    // 2, 4, (3, 6): v3 (s1 of v2) is deleted, but v4 (s2 of v2) is placed by α_3 + α_4.
    let g = CreaseGraph::from_sequence(&gripper(), "2, 4, (3, 6)").unwrap();
    let StepRecord::R2(r) = g.steps().last().unwrap() else {
        panic!()
    };
    assert_eq!(r.names, (3, 6));
    assert_eq!(var_names(&g, &r.eliminated), ["l_2,3"]);
    let a3 = g.variables().iter().find(|v| v.name == "α_3").unwrap().id;
    assert!(g.is_free(a3));
    // Names shift down: the old v4 is now v3, the combined vertex (old v6) is v5.
    let v2 = g.vid_by_name(2).unwrap();
    let s = g.vertex(v2).unwrap().succ();
    assert_eq!(
        s.iter()
            .map(|&c| name(&g, g.crease(c).unwrap().head))
            .collect::<Vec<_>>(),
        [5, 3, 4]
    );
    // The sectors at v2 next to the moved s1 crease are now geometric; α_3 still bounds
    // itself as a variable of v4's placement.
    let cs = g.constraints();
    assert!(cs.contains(&ConstraintSpec::Sector {
        vertex: v2,
        from: Cid(0),
        to: s[0],
        var: None
    }));
    assert!(cs.contains(&ConstraintSpec::Sector {
        vertex: v2,
        from: s[0],
        to: s[1],
        var: None
    }));
    assert!(cs.iter().any(
        |c| matches!(c, ConstraintSpec::Sector { vertex, var: Some(_), .. } if *vertex == v2)
    ));
}

#[test]
fn r2_match_conditions_are_enforced() {
    let task = gripper();
    let g = CreaseGraph::from_sequence(&task, "2, 3").unwrap();
    let v = |n: usize| g.vid_by_name(n).unwrap();
    // Both must be χ.
    assert!(
        g.check_combine(v(3), v(4))
            .unwrap_err()
            .0
            .contains("not extendable")
    );
    // Shared predecessor (the siblings of one extension).
    let e = g.check_combine(v(5), v(4)).unwrap_err().0;
    assert!(e.contains("both have predecessor v2"), "{e}");
    // Facets: v4 (f4 | f3) and v6 (f5 | f2) share no facet in either role.
    assert!(
        g.check_combine(v(4), v(6))
            .unwrap_err()
            .0
            .contains("do not share a facet")
    );
    assert!(
        g.check_combine(v(6), v(4))
            .unwrap_err()
            .0
            .contains("do not share a facet")
    );
    assert!(g.check_combine(v(4), v(8)).is_ok());
    // The sequence parser reports the step that fails.
    let err = CreaseGraph::from_sequence(&task, "2, 3, (4, 6)")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("step 3 `(4, 6)`") && err.contains("do not share a facet"),
        "{err}"
    );
    let err = CreaseGraph::from_sequence(&task, "2, 3, 3")
        .unwrap_err()
        .to_string();
    assert!(err.contains("already extended"), "{err}");
    let err = CreaseGraph::from_sequence(&task, "2, 12")
        .unwrap_err()
        .to_string();
    assert!(err.contains("no vertex v12"), "{err}");
    let err = CreaseGraph::from_sequence(&task, "1")
        .unwrap_err()
        .to_string();
    assert!(err.contains("a source"), "{err}");
}

/// G0 with two χ vertices on one facet: v1 → v2 and v3 → v4, joined by v1 → v3.
fn two_chi() -> Task {
    task_with(
        &[
            vertex("v3", 0.0, 2.0, "terminal"),
            vertex("v4", 1.0, 1.0, "extendable"),
            crease("v1", "v3", "f4", "f1"),
            "drive = \"t\"\n".to_string(),
            crease("v3", "v4", "f3", "f1"),
            "drive = \"t\"\n".to_string(),
        ]
        .concat(),
    )
}

#[test]
fn r2_never_deletes_a_g0_vertex() {
    let task = two_chi();
    let g = CreaseGraph::initial(&task);
    let (v2, v4) = (g.vid_by_name(2).unwrap(), g.vid_by_name(4).unwrap());
    // F_R(v3→v4) = f1 = F_L(v1→v2), but both are in G0.
    assert!(
        g.check_combine(v4, v2)
            .unwrap_err()
            .0
            .contains("both belong to the initial graph")
    );
    // c1 in G0: c2 (s3 of v2, F_L = f1) is deleted.
    let mut h = g.clone();
    h.extend(v2).unwrap();
    let s3 = h.vid_by_name(7).unwrap();
    h.combine(foldsynth::grammar::R2Match { c1: v4, c2: s3 })
        .unwrap();
    assert!(h.vertex(s3).is_none() && h.vertex(v4).is_some());
    assert!(h.facet_boundaries().is_ok());
    // Only c2 in G0: c1 (s1 of v4, F_R = f1) is deleted and v2 survives with preds(c1) first.
    let mut k = g.clone();
    k.extend(v4).unwrap();
    let s1 = k.vid_by_name(5).unwrap();
    let c1_pred = k.vertex(s1).unwrap().preds[0];
    k.combine(foldsynth::grammar::R2Match { c1: s1, c2: v2 })
        .unwrap();
    assert!(k.vertex(s1).is_none());
    assert_eq!(k.vertex(v2).unwrap().preds, vec![c1_pred, Cid(0)]);
    let StepRecord::R2(r) = k.steps().last().unwrap() else {
        panic!()
    };
    assert_eq!((r.survivor, r.deleted, r.names), (v2, s1, (2, 5)));
    assert!(k.facet_boundaries().is_ok());
    assert!(k.is_acyclic());
    // The combined G0 vertex extends with two predecessors.
    k.extend(v2).unwrap();
    assert!(k.facet_boundaries().is_ok());
}

#[test]
fn a_combined_vertex_extends_with_all_its_predecessors() {
    let g = CreaseGraph::from_sequence(&gripper(), "2, 3, (4, 8), 4").unwrap();
    let v4 = g.vertex(g.vid_by_name(4).unwrap()).unwrap();
    assert_eq!(v4.preds.len(), 2);
    let s = v4.succ();
    // s1 continues F_R of the last predecessor (v3 → v4: f3 | f6), s3 F_L of the first
    // (v2 → v4: f4 | f3).
    assert_eq!(g.facet_name(g.crease(s[0]).unwrap().right), "f6");
    assert_eq!(g.facet_name(g.crease(s[2]).unwrap().left), "f4");
    let p = g
        .vertex(g.crease(s[0]).unwrap().head)
        .unwrap()
        .placement
        .clone()
        .unwrap();
    assert_eq!(name(&g, p.reference), 3);
    let p = g
        .vertex(g.crease(s[2]).unwrap().head)
        .unwrap()
        .placement
        .clone()
        .unwrap();
    assert_eq!(name(&g, p.reference), 2);
    assert!(g.facet_boundaries().is_ok());
}

#[test]
fn semantic_validity_follows_fig_47b() {
    let task = gripper();
    let g = CreaseGraph::from_sequence(&task, "2, 4, 3").unwrap();
    assert_eq!(
        g.gripping_candidates().unwrap().map(|v| name(&g, v)),
        [9, 10, 11]
    );
    assert!(!g.is_semantically_valid());
    let g = CreaseGraph::from_sequence(&task, "2, 4, 3, (6, 11)").unwrap();
    // v3's s3 crease now ends at the combined v6, a successor of v4.
    assert_eq!(
        g.gripping_candidates().unwrap().map(|v| name(&g, v)),
        [9, 10, 6]
    );
    assert!(g.is_semantically_valid());
    assert!(!CreaseGraph::initial(&task).is_semantically_valid());
    assert_eq!(CreaseGraph::initial(&task).alternatives(), 0);
    assert_eq!(g.alternatives(), 24);
}
