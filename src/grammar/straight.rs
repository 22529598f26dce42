//! Rule r2′ (thesis Sec. 5.7, Fig. 52b): combine two vertices like r2, but put the combined
//! vertex v′ on the straight segment between their predecessors and make it a sink.
//!
//! The two creases p1 → v′ ← p2 then form one straight crease folded from both ends: the
//! pattern has a cycle that the PTU's acyclic propagation cannot close by itself, and the
//! model adds the compatibility of that crease (`model::cycle`).
//!
//! **Match** — r2's four conditions with c1 and c2 in their roles (both χ, c1's last
//! incoming crease and c2's first bound the same facet, no common predecessor, not both in
//! G0), and in addition, so that "the segment between the predecessors" is one segment
//! and the sink closes a real facet:
//! - each has exactly one predecessor (p1 of c1, p2 of c2);
//! - neither is in G0 (a G0 vertex has fixed coordinates, not the midpoint);
//! - p1 and p2 are not joined by a crease, nor by an earlier sink's straight crease, nor
//!   by a driven G0 side split at its midpoint (the shared facet would collapse onto the
//!   segment, or two creases would coincide, or the sink would sit on the side's source);
//! - merging the two far-side facets does not put one facet on both sides of a crease.
//!
//! **Transformation** — a new sink v′ (type ∅, no outgoing creases, predecessors p1, p2)
//! takes c1's name; c1 and c2 are deleted (c2's later names shift down, as in r2); both
//! incoming creases move to v′ with their labels; the facet left of p1 → v′ and the facet
//! right of p2 → v′ (the two far sides) become one facet: the one with the smaller id
//! stays, the other is removed and later ids shift down. v′ is placed at the midpoint of
//! p1 and p2, so it introduces no variable; the variables that placed c1 and c2 leave Φ
//! unless a surviving placement still uses them, and their constraints stay, measured
//! from the coordinates (Eq. 35), exactly as for r2.

use super::graph::CreaseGraph;
use super::rules::NoR2;
use super::step::Step;
use super::{
    ConstraintSpec, FacetId, R2Match, R2Record, RuleError, StepRecord, Straight, Vertex,
    VertexType, Vid,
};

/// A match of r2′ found by [`CreaseGraph::r2p_matches`]: the roles as for r2.
pub type StraightSink = R2Match;

/// Why r2′ does not match.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum NoR2p {
    /// r2's own condition fails.
    R2(NoR2),
    /// One vertex is a predecessor of the other (it is extended, hence ∅).
    Predecessor(Vid, Vid),
    /// A vertex has more than one predecessor.
    SeveralPreds(Vid, usize),
    /// A vertex is in G0.
    InG0(Vid),
    /// The predecessors are joined by a crease.
    Joined(Vid, Vid),
    /// Merging the far-side facets would put one facet on both sides of a crease.
    FacetLoop(FacetId, FacetId),
}

impl CreaseGraph {
    pub(super) fn r2p_reason(&self, c1: Vid, c2: Vid) -> Result<(), NoR2p> {
        // "r2′ on a predecessor": name it before r2's generic "not extendable".
        for (x, y) in [(c1, c2), (c2, c1)] {
            if x != y && self.vx(y).preds.iter().any(|&c| self.cr(c).tail == x) {
                return Err(NoR2p::Predecessor(x, y));
            }
        }
        self.r2_reason(c1, c2).map_err(NoR2p::R2)?;
        let (a, b) = (self.vx(c1), self.vx(c2));
        for v in [a, b] {
            if v.preds.len() != 1 {
                return Err(NoR2p::SeveralPreds(v.vid, v.preds.len()));
            }
            if v.in_g0() {
                return Err(NoR2p::InG0(v.vid));
            }
        }
        let (e1, e2) = (self.cr(a.preds[0]), self.cr(b.preds[0]));
        let (p1, p2) = (e1.tail, e2.tail);
        // A crease p1–p2, an earlier sink's straight crease between them, or a driven G0
        // side between them split at its midpoint (the chair's seat crease): a second
        // crease would lie on top of it, and the sink on the side's midpoint source.
        let pair = |a: Vid, b: Vid| (a == p1 && b == p2) || (a == p2 && b == p1);
        if self.creases().any(|c| pair(c.tail, c.head))
            || self
                .sinks()
                .any(|v| v.sink_between.is_some_and(|[a, b]| pair(a, b)))
            || self.init.split.iter().any(|s| {
                let [a, b] = s.ends;
                pair(Vid(a as u32), Vid(b as u32))
            })
        {
            return Err(NoR2p::Joined(p1, p2));
        }
        // After the merge every crease must still have two different facets.
        let (outer_a, outer_b) = (e1.left, e2.right);
        if outer_a != outer_b {
            let merged = |f: FacetId| if f == outer_b { outer_a } else { f };
            if let Some(c) = self.creases().find(|c| merged(c.left) == merged(c.right)) {
                return Err(NoR2p::FacetLoop(c.left, c.right));
            }
        }
        Ok(())
    }

    /// Whether r2′ matches with these roles; the error says why not.
    pub fn check_combine_straight(&self, c1: Vid, c2: Vid) -> Result<(), RuleError> {
        for v in [c1, c2] {
            if self.vertex(v).is_none() {
                return Err(RuleError(format!("vertex {} does not exist", v.0)));
            }
        }
        self.r2p_reason(c1, c2)
            .map_err(|why| RuleError(self.r2p_message(c1, c2, why)))
    }

    fn r2p_message(&self, c1: Vid, c2: Vid, why: NoR2p) -> String {
        let head = format!(
            "r2′ does not match {} and {}",
            self.vname(c1),
            self.vname(c2)
        );
        match why {
            NoR2p::R2(w) => self.r2_message("r2′", c1, c2, w),
            NoR2p::Predecessor(x, y) => format!(
                "{head}: {} is a predecessor of {} (r2′ combines two extendable vertices into a sink between their predecessors)",
                self.vname(x),
                self.vname(y)
            ),
            NoR2p::SeveralPreds(v, n) => format!(
                "{head}: {} has {n} predecessors; r2′ puts the sink on the segment between exactly two, one of each vertex",
                self.vname(v)
            ),
            NoR2p::InG0(v) => format!(
                "{head}: {} belongs to the initial graph (its coordinates are fixed, the sink lies between the predecessors)",
                self.vname(v)
            ),
            NoR2p::Joined(p, q) => format!(
                "{head}: their predecessors {} and {} are joined by a crease already (the shared facet would collapse onto it)",
                self.vname(p),
                self.vname(q)
            ),
            NoR2p::FacetLoop(f, g) => format!(
                "{head}: merging the facets on the far side would put one facet on both sides of the crease between {} and {}",
                self.facet_name(f),
                self.facet_name(g)
            ),
        }
    }

    /// Rule r2′: replace c1 and c2 by a sink v′ at the midpoint of their predecessors (see
    /// the module docs). Records the step as an [`R2Record`] with [`Straight`] set.
    pub fn combine_straight(&mut self, m: StraightSink) -> Result<(), RuleError> {
        if self.sym.is_some() {
            return self.straight_orbit(m);
        }
        self.straight_one(m, false)
    }

    /// r2′ on one pair; `image`: an image of a representative pair just combined.
    pub(super) fn straight_one(&mut self, m: StraightSink, image: bool) -> Result<(), RuleError> {
        self.check_combine_straight(m.c1, m.c2)?;
        let names = self.pair_names(m, self.r2p_reason(m.c2, m.c1).is_ok());
        let a = self.vx(m.c1).clone();
        let b = self.vx(m.c2).clone();
        let (e1, e2) = (a.preds[0], b.preds[0]);
        let (p1, p2) = (self.cr(e1).tail, self.cr(e2).tail);
        let inner = self.cr(e1).right;
        let (outer_a, outer_b) = (self.cr(e1).left, self.cr(e2).right);

        // The sink, at c1's place in the name order.
        let sink = Vid(self.node_of.len() as u32);
        let sn = self.g.add_node(Vertex {
            vid: sink,
            preds: vec![e1, e2],
            slots: [None; 3],
            ty: VertexType::Terminal,
            extended: false,
            g0: None,
            g0_coords: None,
            placement: None,
            sink_between: Some([p1, p2]),
        });
        self.node_of.push(Some(sn));
        for c in [e1, e2] {
            let e = self.edge_of[c.0 as usize];
            let (tail, _) = self.g.edge_endpoints(e).expect("edge exists");
            let mut w = self.g.remove_edge(e).expect("edge exists");
            w.head = sink;
            self.edge_of[c.0 as usize] = self.g.add_edge(tail, sn, w);
        }
        for v in [m.c1, m.c2] {
            let n = self.node_of[v.0 as usize].take().expect("living");
            self.g.remove_node(n);
        }
        let at = self.order.iter().position(|&v| v == m.c1).expect("living");
        self.order[at] = sink;
        self.order.retain(|&v| v != m.c2);

        // One facet on the far side.
        let (keep, gone) = if outer_a <= outer_b {
            (outer_a, outer_b)
        } else {
            (outer_b, outer_a)
        };
        let merged_name = self.facet_names[gone.0 as usize].clone();
        let (inner, outer) = if keep != gone {
            self.remove_facet(gone, keep);
            let shift = |f: FacetId| {
                if f.0 > gone.0 { FacetId(f.0 - 1) } else { f }
            };
            (shift(inner), shift(keep))
        } else {
            (inner, keep)
        };

        let mut eliminated = Vec::new();
        let mut substitutions = Vec::new();
        for p in [&a.placement, &b.placement].into_iter().flatten() {
            for var in p.sectors.iter().chain([&p.length]).copied() {
                if self.is_free(var) || eliminated.contains(&var) {
                    continue;
                }
                eliminated.push(var);
                substitutions.push(self.substitute(var));
            }
        }
        self.steps.push(StepRecord::R2(R2Record {
            c1: m.c1,
            c2: m.c2,
            names,
            survivor: sink,
            deleted: m.c2,
            moved: vec![e1, e2],
            removed_placement: b.placement.clone(),
            eliminated,
            substitutions,
            constraint: ConstraintSpec::MergedSector {
                vertex: sink,
                from: e1,
                to: e2,
            },
            straight: Some(Straight {
                sink,
                replaced: m.c1,
                replaced_placement: a.placement.clone(),
                between: [p1, p2],
                inner,
                outer,
                merged_name,
            }),
            image,
        }));
        Ok(())
    }

    /// Relabel facet `gone` as `keep` on every crease, then drop `gone` from the facet list
    /// (later ids shift down by one).
    fn remove_facet(&mut self, gone: FacetId, keep: FacetId) {
        let fix = |f: FacetId| {
            let f = if f == gone { keep } else { f };
            if f.0 > gone.0 { FacetId(f.0 - 1) } else { f }
        };
        for &e in &self.edge_of {
            let c = &mut self.g[e];
            c.left = fix(c.left);
            c.right = fix(c.right);
        }
        self.facet_names.remove(gone.0 as usize);
    }

    /// The r2′ matches in increasing order of their sorted name pairs, with their notation
    /// (r2′ off: the enumeration does not ask).
    pub fn r2p_matches(&self) -> Vec<(Step, StraightSink)> {
        if self.sym.is_some() {
            return self.orbit_pair_matches(true);
        }
        self.pair_matches(
            |v| v.ty == VertexType::Extendable && v.preds.len() == 1 && !v.in_g0(),
            |a, b| self.r2p_reason(a, b).is_ok(),
            Step::Straight,
        )
    }

    /// Apply `(x, y)'` with the names as they are now.
    pub(super) fn apply_straight(&mut self, x: usize, y: usize) -> Result<(), RuleError> {
        let vx = self.vid_by_name(x).ok_or_else(|| self.no_vertex(x))?;
        let vy = self.vid_by_name(y).ok_or_else(|| self.no_vertex(y))?;
        let (lo, hi) = if x < y { (vx, vy) } else { (vy, vx) };
        let fwd = self.r2p_reason(lo, hi);
        let back = self.r2p_reason(hi, lo);
        let m = match (fwd, back) {
            (Ok(()), Ok(())) if x > y => R2Match { c1: hi, c2: lo },
            (Ok(()), _) => R2Match { c1: lo, c2: hi },
            (Err(_), Ok(())) => R2Match { c1: hi, c2: lo },
            (Err(e1), Err(e2)) => {
                // Report the reason for the role whose facets agree, if any.
                let facet = |e: &NoR2p| matches!(e, NoR2p::R2(NoR2::Facets));
                let (c1, c2, why) = if facet(&e1) && !facet(&e2) {
                    (hi, lo, e2)
                } else {
                    (lo, hi, e1)
                };
                return Err(RuleError(self.r2p_message(c1, c2, why)));
            }
        };
        self.combine_straight(m)
    }

    /// The r2′ sinks of this graph (each closes one cycle of the pattern).
    pub fn sinks(&self) -> impl Iterator<Item = &Vertex> + '_ {
        self.vertices().filter(|v| v.sink_between.is_some())
    }

    /// Whether r2′ closed a cycle in this pattern (the PTU alone does not certify it).
    pub fn is_cyclic_pattern(&self) -> bool {
        self.sinks().next().is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::task::Task;

    fn gripper() -> Task {
        Task::load(concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml")).unwrap()
    }

    #[test]
    fn merged_facet_ids_stay_dense() {
        let task = gripper();
        let g = CreaseGraph::from_sequence(&task, "2, 3, 4, 8, (9, 14)'").unwrap();
        let used: std::collections::BTreeSet<u32> =
            g.creases().flat_map(|c| [c.left.0, c.right.0]).collect();
        assert_eq!(used.len(), g.facet_count());
        assert_eq!(used.iter().copied().max(), Some(g.facet_count() as u32 - 1));
        assert!(g.facet_boundaries().is_ok());
    }
}
