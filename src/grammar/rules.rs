//! Rule r1 (extend a vertex, Sec. 5.2.1, Tables 1–2) and rule r2 (combine two vertices,
//! Sec. 5.2.2), with their matches in the order of SPEC §2.

use petgraph::algo::has_path_connecting;

use super::graph::CreaseGraph;
use super::step::Step;
use super::{
    Cid, ConstraintSpec, Crease, CreaseOrigin, Created, FacetId, Placement, R1Record, R2Record,
    StepRecord, Substitution, VarId, VarKind, Variable, Vertex, VertexType, Vid,
};

/// A rule that does not apply, with the reason.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct RuleError(pub String);

/// A match of r2: `c1`'s last incoming crease and `c2`'s first bound the same facet
/// (F_R(p_m(c1) → c1) = F_L(p_1(c2) → c2)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct R2Match {
    /// Contributes the facet on the right of its last incoming crease; its predecessors
    /// come first in the result.
    pub c1: Vid,
    /// Contributes the facet on the left of its first incoming crease.
    pub c2: Vid,
}

/// Why r2 does not match (kept allocation-free: the enumeration tests every pair).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum NoR2 {
    Same,
    NotExtendable(Vid),
    HasS1(Vid),
    HasS3(Vid),
    Facets,
    SharedPred(Vid),
    BothG0,
    Ancestor(Vid, Vid),
}

/// The vertex r1 extends and what every crease it adds is placed from.
struct R1Parent {
    /// The extended vertex.
    a: Vid,
    /// Its name when extended.
    aname: usize,
    /// Index of this r1 step.
    step: usize,
    /// The tail of its last incoming crease p_m.
    ref_pm: Vid,
    /// The tail of its first incoming crease p_1.
    ref_p1: Vid,
    /// Its s1, when G0 gave it one.
    s1: Option<Cid>,
}

/// Eq. 31–33 for r1 at `a` with incoming creases p1 … pm and slots `s`. The sectors next to
/// new creases are variables, except the one no placement measures: the remainder (between
/// s2 and s3, or between s1 and s2 when only s1 is new and s2 existed: `remainder_s1_s2`).
fn r1_constraints(
    a: Vid,
    (p1, pm): (Cid, Cid),
    s: [Cid; 3],
    sector_of: [Option<VarId>; 3],
    remainder_s1_s2: bool,
    created: &[Created],
) -> Vec<ConstraintSpec> {
    let mut constraints = Vec::new();
    if let Some(var) = sector_of[0] {
        constraints.push(ConstraintSpec::Sector {
            vertex: a,
            from: pm,
            to: s[0],
            var: Some(var),
        });
    }
    if let Some(var) = sector_of[1] {
        constraints.push(ConstraintSpec::Sector {
            vertex: a,
            from: s[0],
            to: s[1],
            var: Some(var),
        });
    }
    if let Some(var) = sector_of[2] {
        constraints.push(ConstraintSpec::Sector {
            vertex: a,
            from: s[2],
            to: p1,
            var: Some(var),
        });
    }
    let (rf, rt) = if remainder_s1_s2 {
        (s[0], s[1])
    } else {
        (s[1], s[2])
    };
    constraints.push(ConstraintSpec::Remainder {
        vertex: a,
        from: rf,
        to: rt,
    });
    for c in created {
        if let Some(p) = &c.placement {
            constraints.push(ConstraintSpec::Length {
                crease: c.crease,
                var: Some(p.length),
            });
        }
    }
    constraints.push(ConstraintSpec::RigidFoldability { vertex: a });
    constraints
}

impl CreaseGraph {
    pub(super) fn vname(&self, v: Vid) -> String {
        self.name(v)
            .map_or_else(|| format!("(deleted {})", v.0), |n| format!("v{n}"))
    }

    /// Whether r1 matches `a` (type χ). N_max is the enumeration's business.
    pub fn check_extend(&self, a: Vid) -> Result<(), RuleError> {
        let Some(v) = self.vertex(a) else {
            return Err(RuleError(format!("vertex {} does not exist", a.0)));
        };
        if v.ty != VertexType::Extendable {
            return Err(RuleError(format!(
                "r1 does not match {}: it is not extendable (type ∅: {})",
                self.vname(a),
                if v.extended {
                    "already extended"
                } else if v.preds.is_empty() {
                    "a source"
                } else {
                    "terminal in G0"
                }
            )));
        }
        Ok(())
    }

    /// Rule r1: give χ vertex `a` its missing outgoing creases s1, s2, s3 (all six scenarios
    /// of Tables 1–2: the slots G0 already filled stay), place the new vertices (Eq. 28) with
    /// new sector and length variables, record the constraints (Eq. 31–33), and make `a`
    /// internal (type ∅). With a pattern symmetry, `a` must represent its orbit, and every
    /// image of `a` is extended with it (`grammar::symmetric`).
    pub fn extend(&mut self, a: Vid) -> Result<(), RuleError> {
        if self.sym.is_some() {
            return self.extend_orbit(a);
        }
        self.extend_one(a, None)
    }

    /// r1 on `a` alone. `image`: `a` is the image under element `g` of `source`, which was
    /// just extended: every new crease and vertex is the image of `source`'s (same
    /// variables, no new ones, no constraints of its own).
    pub(super) fn extend_one(
        &mut self,
        a: Vid,
        image: Option<(Vid, usize)>,
    ) -> Result<(), RuleError> {
        self.check_extend(a)?;
        let step = self.steps.len();
        let aname = self.name(a).expect("living");
        let v = self.vx(a).clone();
        let scenario = self.r1_scenario(a, &v)?;
        let missing: Vec<usize> = (0..3).filter(|&k| v.slots[k].is_none()).collect();
        let (first, last) = (missing[0], missing[missing.len() - 1]);
        let (p1, pm) = (v.preds[0], v.preds[v.preds.len() - 1]);
        let slot = |k: usize| v.slots[k].expect("existing slot");
        // The facets on either side of the open sector continue onto the outermost new creases.
        let mut right_facet = if first == 0 {
            self.ccw_side(a, pm)
        } else {
            self.ccw_side(a, slot(first - 1))
        };
        let after_facet = if last == 2 {
            self.cw_side(a, p1)
        } else {
            self.cw_side(a, slot(last + 1))
        };
        let at = R1Parent {
            a,
            aname,
            step,
            ref_pm: self.cr(pm).tail,
            ref_p1: self.cr(p1).tail,
            s1: v.slots[0],
        };

        let mut slots = v.slots;
        let mut created = Vec::new();
        let mut variables = Vec::new();
        let mut sector_of = [None::<VarId>; 3];
        for (i, &k) in missing.iter().enumerate() {
            let last_new = i + 1 == missing.len();
            // The crease of the source this one is the image of: a reflection reverses the
            // rotation, so slot s1 is the image of the source's s3.
            let mirrored = image.map(|(src, g)| {
                let ks = if self.group().expect("symmetric").reflects(g) {
                    2 - k
                } else {
                    k
                };
                let sc = self.vx(src).slots[ks].expect("the source was extended first");
                (sc, g)
            });
            let (c, left) = self.r1_crease(
                &at,
                k,
                sector_of[0],
                last_new.then_some(after_facet),
                right_facet,
                mirrored,
            );
            if let Some(p) = &c.placement {
                // The crease's own sector is the last its placement sums.
                let sector = *p.sectors.last().expect("a sector");
                variables.extend([sector, p.length]);
                sector_of[k] = Some(sector);
            }
            right_facet = left;
            slots[k] = Some(c.crease);
            created.push(c);
        }
        let s = slots.map(|c| c.expect("all slots filled"));
        let remainder_s1_s2 = sector_of[0].is_some() && v.slots[1].is_some();
        let constraints = if image.is_some() {
            Vec::new()
        } else {
            r1_constraints(a, (p1, pm), s, sector_of, remainder_s1_s2, &created)
        };

        let va = self.vx_mut(a);
        va.slots = slots;
        va.ty = VertexType::Terminal;
        va.extended = true;
        self.extension_order.push(a);
        self.steps.push(StepRecord::R1(R1Record {
            vertex: a,
            name: aname,
            scenario,
            created,
            variables,
            constraints,
            image: image.is_some(),
        }));
        Ok(())
    }

    /// Scenario r1,1 … r1,6 (Tables 1–2) from the slots G0 already filled at `a`.
    fn r1_scenario(&self, a: Vid, v: &Vertex) -> Result<u8, RuleError> {
        Ok(match v.slots.map(|s| s.is_some()) {
            [false, false, false] => 1,
            [false, false, true] => 2,
            [true, false, false] => 3,
            [false, true, true] => 4,
            [true, false, true] => 5,
            [true, true, false] => 6,
            _ => {
                return Err(RuleError(format!(
                    "r1 does not match {}: its existing outgoing creases leave no single open sector",
                    self.vname(a)
                )));
            }
        })
    }

    /// r1's new crease in slot `k` (0-based) of `at.a`, with its new vertex, its sector and
    /// length variables and its placement (Eq. 28). `s1_sector`: the sector variable of an
    /// s1 created in the same application; `left`: the facet on its left, `None` for a new
    /// one; `image`: the crease this one is the image of under a symmetry element (then it
    /// takes that crease's variables and has no placement). Returns what was created and
    /// the facet on its left.
    fn r1_crease(
        &mut self,
        at: &R1Parent,
        k: usize,
        s1_sector: Option<VarId>,
        left: Option<FacetId>,
        right: FacetId,
        image: Option<(Cid, usize)>,
    ) -> (Created, FacetId) {
        let (a, step) = (at.a, at.step);
        let vid = Vid(self.node_of.len() as u32);
        let vname = self.order.len() + 1;
        let cid = Cid(self.edge_of.len() as u32);
        let (sector, length, placement) = match image {
            Some((sc, _)) => match self.cr(sc).origin {
                CreaseOrigin::Extension { sector, length, .. } => (sector, length, None),
                CreaseOrigin::Initial { .. } => unreachable!("r1 images r1's creases"),
            },
            None => {
                let sector = self.new_var(VarKind::Sector, format!("α_{vname}"), step, cid, vid);
                let length = self.new_var(
                    VarKind::Length,
                    format!("l_{},{vname}", at.aname),
                    step,
                    cid,
                    vid,
                );
                let placement = match k {
                    0 => Placement {
                        parent: a,
                        reference: at.ref_pm,
                        sign: 1.0,
                        sectors: vec![sector],
                        length,
                    },
                    1 => match at.s1 {
                        Some(s1) => Placement {
                            parent: a,
                            reference: self.cr(s1).head,
                            sign: 1.0,
                            sectors: vec![sector],
                            length,
                        },
                        None => Placement {
                            parent: a,
                            reference: at.ref_pm,
                            sign: 1.0,
                            sectors: vec![s1_sector.expect("s1 created first"), sector],
                            length,
                        },
                    },
                    _ => Placement {
                        parent: a,
                        reference: at.ref_p1,
                        sign: -1.0,
                        sectors: vec![sector],
                        length,
                    },
                };
                (sector, length, Some(placement))
            }
        };
        let left = match left {
            Some(f) => f,
            None => self.new_facet(),
        };
        let node = self.g.add_node(Vertex {
            vid,
            preds: vec![cid],
            slots: [None; 3],
            ty: VertexType::Extendable,
            extended: false,
            g0: None,
            g0_coords: None,
            placement: placement.clone(),
            sink_between: None,
        });
        self.node_of.push(Some(node));
        self.order.push(vid);
        let e = self.g.add_edge(
            self.node_of[a.ix()].expect("living"),
            node,
            Crease {
                cid,
                tail: a,
                head: vid,
                left,
                right,
                origin: CreaseOrigin::Extension {
                    step,
                    slot: k as u8 + 1,
                    sector,
                    length,
                    created: vid,
                },
            },
        );
        self.edge_of.push(e);
        if self.sym.is_some() {
            let source = image.map(|(sc, g)| {
                let sv = match self.cr(sc).origin {
                    CreaseOrigin::Extension { created, .. } => created,
                    CreaseOrigin::Initial { .. } => unreachable!("r1 images r1's creases"),
                };
                (sv, sc, g)
            });
            self.sym_register(vid, cid, source);
        }
        let created = Created {
            slot: k as u8 + 1,
            vertex: vid,
            crease: cid,
            placement,
        };
        (created, left)
    }

    fn new_var(
        &mut self,
        kind: VarKind,
        base: String,
        step: usize,
        crease: Cid,
        vertex: Vid,
    ) -> VarId {
        let mut name = base;
        while self.variables.iter().any(|v| v.name == name) {
            name.push('\'');
        }
        let id = VarId(self.variables.len() as u32);
        self.variables.push(Variable {
            id,
            kind,
            name,
            step,
            crease,
            vertex,
        });
        id
    }

    fn new_facet(&mut self) -> FacetId {
        let id = self.facet_names.len();
        let mut name = format!("f{}", id + 1);
        while self.facet_names.contains(&name) {
            name.push('\'');
        }
        self.facet_names.push(name);
        FacetId(id as u32)
    }

    pub(super) fn r2_reason(&self, c1: Vid, c2: Vid) -> Result<(), NoR2> {
        if c1 == c2 {
            return Err(NoR2::Same);
        }
        let (a, b) = (self.vx(c1), self.vx(c2));
        for v in [a, b] {
            if v.ty != VertexType::Extendable {
                return Err(NoR2::NotExtendable(v.vid));
            }
        }
        // Both facets compared must be the open ones (they are whenever s1 of c1 and s3 of
        // c2 are still missing, as for every vertex r1 created).
        if a.slots[0].is_some() {
            return Err(NoR2::HasS1(c1));
        }
        if b.slots[2].is_some() {
            return Err(NoR2::HasS3(c2));
        }
        let pm = a.preds[a.preds.len() - 1];
        let p1 = b.preds[0];
        if self.cr(pm).right != self.cr(p1).left {
            return Err(NoR2::Facets);
        }
        for &p in &a.preds {
            let t = self.cr(p).tail;
            if b.preds.iter().any(|&q| self.cr(q).tail == t) {
                return Err(NoR2::SharedPred(t));
            }
        }
        if a.in_g0() && b.in_g0() {
            return Err(NoR2::BothG0);
        }
        // Only G0 vertices can be χ and have successors; combining one with a descendant
        // would close a cycle.
        if a.slots.iter().any(Option::is_some) || b.slots.iter().any(Option::is_some) {
            let (na, nb) = (
                self.node_of[c1.ix()].expect("living"),
                self.node_of[c2.ix()].expect("living"),
            );
            if has_path_connecting(&self.g, na, nb, None) {
                return Err(NoR2::Ancestor(c1, c2));
            }
            if has_path_connecting(&self.g, nb, na, None) {
                return Err(NoR2::Ancestor(c2, c1));
            }
        }
        Ok(())
    }

    /// Whether r2 matches with these roles; the error says why not.
    pub fn check_combine(&self, c1: Vid, c2: Vid) -> Result<(), RuleError> {
        for v in [c1, c2] {
            if self.vertex(v).is_none() {
                return Err(RuleError(format!("vertex {} does not exist", v.0)));
            }
        }
        self.r2_reason(c1, c2)
            .map_err(|why| RuleError(self.r2_message("r2", c1, c2, why)))
    }

    /// Why r2's match fails, in words (`rule` names the rule: r2 or r2′).
    pub(super) fn r2_message(&self, rule: &str, c1: Vid, c2: Vid, why: NoR2) -> String {
        let head = format!(
            "{rule} does not match {} and {}",
            self.vname(c1),
            self.vname(c2)
        );
        match why {
            NoR2::Same => format!("{head}: a vertex cannot be combined with itself"),
            NoR2::NotExtendable(v) => {
                format!("{head}: {} is not extendable (type ∅)", self.vname(v))
            }
            NoR2::HasS1(v) => format!(
                "{head}: {} already has an outgoing crease s1 next to its last incoming crease",
                self.vname(v)
            ),
            NoR2::HasS3(v) => format!(
                "{head}: {} already has an outgoing crease s3 next to its first incoming crease",
                self.vname(v)
            ),
            NoR2::Facets => format!(
                "{head}: they do not share a facet (F_R of {}'s last incoming crease is {}, F_L of {}'s first is {})",
                self.vname(c1),
                self.facet_name(
                    self.cr(*self.vx(c1).preds.last().expect("χ has preds"))
                        .right
                ),
                self.vname(c2),
                self.facet_name(self.cr(self.vx(c2).preds[0]).left),
            ),
            NoR2::SharedPred(p) => format!("{head}: both have predecessor {}", self.vname(p)),
            NoR2::BothG0 => format!("{head}: both belong to the initial graph"),
            NoR2::Ancestor(x, y) => format!(
                "{head}: {} is an ancestor of {} (a cycle would form)",
                self.vname(x),
                self.vname(y)
            ),
        }
    }

    /// How a pair is written: sorted, except when both roles match and the second one
    /// (c1 with the larger name) is meant, so that the notation stays unambiguous.
    pub(super) fn pair_names(&self, m: R2Match, both_roles: bool) -> (usize, usize) {
        let (n1, n2) = (
            self.name(m.c1).expect("living"),
            self.name(m.c2).expect("living"),
        );
        if n1 > n2 && both_roles {
            (n1, n2)
        } else {
            (n1.min(n2), n1.max(n2))
        }
    }

    /// Rule r2: combine `m.c2` into `m.c1` (or `m.c1` into `m.c2` when only `m.c2` is in G0):
    /// the deleted vertex's incoming creases move to the survivor with their labels, the
    /// survivor's predecessors become preds(c1) then preds(c2), later names shift down.
    /// Records Eq. 34 and the variables eliminated with their substitutes (Eq. 35).
    pub fn combine(&mut self, m: R2Match) -> Result<(), RuleError> {
        if self.sym.is_some() {
            return self.combine_orbit(m);
        }
        self.combine_one(m, false)
    }

    /// r2 on one pair; `image`: the pair is an image of a representative pair just
    /// combined (recorded, not written in the sequence).
    pub(super) fn combine_one(&mut self, m: R2Match, image: bool) -> Result<(), RuleError> {
        self.check_combine(m.c1, m.c2)?;
        let names = self.pair_names(m, self.r2_reason(m.c2, m.c1).is_ok());
        let a = self.vx(m.c1).clone();
        let b = self.vx(m.c2).clone();
        let (survivor, deleted) = if b.in_g0() && !a.in_g0() {
            (m.c2, m.c1)
        } else {
            (m.c1, m.c2)
        };
        let dv = if deleted == m.c2 { &b } else { &a };
        if dv.slots.iter().any(Option::is_some) {
            return Err(RuleError(format!(
                "r2 cannot delete {}: it has outgoing creases",
                self.vname(deleted)
            )));
        }
        let moved = dv.preds.clone();
        let removed_placement = dv.placement.clone();
        let from = a.preds[a.preds.len() - 1];
        let to = b.preds[0];
        let preds: Vec<Cid> = a.preds.iter().chain(&b.preds).copied().collect();

        let sn = self.node_of[survivor.ix()].expect("living");
        for &c in &moved {
            let e = self.edge_of[c.ix()];
            let (tail, _) = self.g.edge_endpoints(e).expect("edge exists");
            let mut w = self.g.remove_edge(e).expect("edge exists");
            w.head = survivor;
            self.edge_of[c.ix()] = self.g.add_edge(tail, sn, w);
        }
        self.vx_mut(survivor).preds = preds;
        let dn = self.node_of[deleted.ix()].take().expect("living");
        self.g.remove_node(dn);
        self.order.retain(|&v| v != deleted);

        // The deleted vertex's variables leave Φ unless a surviving placement still uses
        // them (s2 is placed by α_s1 + α_s2, so α_s1 outlives a deleted s1).
        let mut eliminated = Vec::new();
        let mut substitutions = Vec::new();
        if let Some(p) = &removed_placement {
            for var in p.sectors.iter().chain([&p.length]).copied() {
                if self.is_free(var) {
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
            survivor,
            deleted,
            moved,
            removed_placement,
            eliminated,
            substitutions,
            constraint: ConstraintSpec::MergedSector {
                vertex: survivor,
                from,
                to,
            },
            straight: None,
            image,
        }));
        Ok(())
    }

    /// Eq. 35: an eliminated variable in terms of the coordinates, from the placement of the
    /// crease it was created for.
    pub(super) fn substitute(&self, var: VarId) -> Substitution {
        let v = &self.variables[var.0 as usize];
        if v.kind == VarKind::Length {
            return Substitution::Length {
                var,
                crease: v.crease,
            };
        }
        let placement = match &self.steps[v.step] {
            StepRecord::R1(r) => r
                .created
                .iter()
                .find(|c| c.crease == v.crease)
                .and_then(|c| c.placement.clone())
                .expect("the r1 step created the variable's crease"),
            StepRecord::R2(_) => unreachable!("variables come from r1 steps"),
        };
        Substitution::Sector {
            var,
            at: placement.parent,
            reference: placement.reference,
            crease: v.crease,
            sign: placement.sign,
            minus: placement
                .sectors
                .iter()
                .copied()
                .filter(|&s| s != var)
                .collect(),
        }
    }

    /// The r1 matches in increasing vertex name; none once N = `n_max`.
    pub fn r1_matches(&self, n_max: usize) -> Vec<Vid> {
        if self.internal_count() >= n_max {
            return Vec::new();
        }
        self.vertices()
            .filter(|v| v.ty == VertexType::Extendable)
            .filter(|v| self.sym.as_ref().is_none_or(|s| s.is_rep(v.vid)))
            .map(|v| v.vid)
            .collect()
    }

    /// The r2 matches in increasing order of their sorted name pairs, with their notation.
    pub fn r2_matches(&self) -> Vec<(Step, R2Match)> {
        if self.sym.is_some() {
            return self.orbit_pair_matches(false);
        }
        self.pair_matches(
            |v| v.ty == VertexType::Extendable,
            |a, b| self.r2_reason(a, b).is_ok(),
            Step::Combine,
        )
    }

    /// The matches of a combining rule (r2 or r2′) over the vertices `eligible` admits,
    /// in increasing order of their sorted name pairs; `ok(c1, c2)` says whether the rule
    /// applies with those roles, `step` writes its notation. Both roles of one pair may
    /// match: the second is written with the names swapped.
    pub(super) fn pair_matches(
        &self,
        eligible: impl Fn(&Vertex) -> bool,
        ok: impl Fn(Vid, Vid) -> bool,
        step: fn(usize, usize) -> Step,
    ) -> Vec<(Step, R2Match)> {
        let chi: Vec<(usize, Vid)> = self
            .vertices()
            .enumerate()
            .filter(|(_, v)| eligible(v))
            .map(|(i, v)| (i + 1, v.vid))
            .collect();
        let mut out = Vec::new();
        for (x, &(ni, vi)) in chi.iter().enumerate() {
            for &(nj, vj) in &chi[x + 1..] {
                let first = ok(vi, vj);
                if first {
                    out.push((step(ni, nj), R2Match { c1: vi, c2: vj }));
                }
                if ok(vj, vi) {
                    let s = if first { step(nj, ni) } else { step(ni, nj) };
                    out.push((s, R2Match { c1: vj, c2: vi }));
                }
            }
        }
        out
    }

    /// Apply one step written in the thesis's notation (names as they are now).
    pub fn apply_step(&mut self, step: Step) -> Result<(), RuleError> {
        match step {
            Step::Extend(n) => {
                let v = self.vid_by_name(n).ok_or_else(|| self.no_vertex(n))?;
                self.extend(v)
            }
            Step::Combine(x, y) => {
                let vx = self.vid_by_name(x).ok_or_else(|| self.no_vertex(x))?;
                let vy = self.vid_by_name(y).ok_or_else(|| self.no_vertex(y))?;
                let (lo, hi) = if x < y { (vx, vy) } else { (vy, vx) };
                let fwd = self.r2_reason(lo, hi).is_ok();
                let back = self.r2_reason(hi, lo).is_ok();
                let m = match (fwd, back) {
                    (true, true) if x > y => R2Match { c1: hi, c2: lo },
                    (true, _) => R2Match { c1: lo, c2: hi },
                    (false, true) => R2Match { c1: hi, c2: lo },
                    (false, false) => {
                        // Report the reason for the role whose facets agree, if any.
                        let e1 = self.check_combine(lo, hi).unwrap_err();
                        let e2 = self.check_combine(hi, lo).unwrap_err();
                        let facet = |e: &RuleError| e.0.contains("do not share a facet");
                        return Err(if facet(&e1) && !facet(&e2) { e2 } else { e1 });
                    }
                };
                self.combine(m)
            }
            Step::Straight(x, y) => self.apply_straight(x, y),
        }
    }

    pub(super) fn no_vertex(&self, n: usize) -> RuleError {
        RuleError(format!(
            "there is no vertex v{n} (the graph has v1 … v{})",
            self.order.len()
        ))
    }
}
