use foldsynth::grammar::*;
use foldsynth::task::Task;
use std::collections::HashSet;
fn strip(c: &Code) -> Code { let mut v = c.0.clone(); v.truncate(v.len()-2); Code(v) }

// variant flags: iso_nomark, mirror_nomark, refl_iso, mirror_vs_meaningful_only, mirror_before_iso
fn run(task: &Task, n_max: usize, f: [bool;5]) -> (usize, u64, Vec<String>) {
    let root = CreaseGraph::initial(task);
    let mut nodes: Vec<(CreaseGraph, Status)> = vec![];
    let mut seen = HashSet::new(); let mut kept = HashSet::new();
    let mut frontier: Vec<Option<usize>> = vec![None];
    while !frontier.is_empty() {
        let mut next = vec![];
        for p in frontier {
            let g = p.map_or(root.clone(), |i| nodes[i].0.clone());
            let mut ch = vec![];
            for v in g.r1_matches(n_max) { let mut c = g.clone(); c.extend(v).unwrap(); ch.push(c); }
            for (_, m) in g.r2_matches() { let mut c = g.clone(); c.combine(m).unwrap(); ch.push(c); }
            for c in ch {
                let mut code = c.canonical_code(); let mut mc = c.mirror_code().unwrap();
                if f[0] { code = strip(&code); mc = strip(&mc); }
                let isokey = if f[2] { code.clone().min(mc.clone()) } else { code.clone() };
                let mkey = if f[1] { strip(&mc) } else { mc.clone() };
                let ckey = if f[1] { strip(&code) } else { code.clone() };
                let valid = c.is_semantically_valid();
                let st = if !f[4] {
                    if !seen.insert(isokey.clone()) { Status::Isomorphic }
                    else if mkey != ckey && kept.contains(&mkey) { Status::Mirror }
                    else { if !f[3] || valid { kept.insert(ckey.clone()); } if valid { Status::Meaningful } else { Status::Invalid } }
                } else {
                    if mkey != ckey && kept.contains(&mkey) { Status::Mirror }
                    else if !seen.insert(isokey.clone()) { Status::Isomorphic }
                    else { if !f[3] || valid { kept.insert(ckey.clone()); } if valid { Status::Meaningful } else { Status::Invalid } }
                };
                if matches!(st, Status::Meaningful | Status::Invalid) { next.push(Some(nodes.len())); }
                nodes.push((c, st));
            }
        }
        frontier = next;
    }
    let m: Vec<_> = nodes.iter().filter(|n| n.1 == Status::Meaningful).collect();
    (m.len(), m.iter().map(|n| n.0.alternatives()).sum(), m.iter().map(|n| n.0.sequence()).collect())
}
fn main() {
    let task = Task::load("grammar/gripper.toml").unwrap();
    let (_, _, base) = run(&task, 3, [false;5]);
    for f in [[false;5],[true,false,false,false,false],[false,true,false,false,false],[false,false,true,false,false],[false,false,false,true,false],[false,false,false,false,true],[true,true,false,false,false]] {
        let (n, a, l) = run(&task, 3, f);
        let diff: Vec<_> = base.iter().filter(|s| !l.contains(s)).cloned().collect();
        let diff2: Vec<_> = l.iter().filter(|s| !base.contains(s)).cloned().collect();
        println!("{:?}: {} {} -{:?} +{:?}", f, n, a, diff, diff2);
    }
}
