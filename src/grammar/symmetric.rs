//! The grammar on a symmetric pattern (thesis Sec. 4.3; issue 46): G0 is mapped onto
//! itself by a finite group of plane isometries (`[symmetry] rotations`, `mirror_axis`),
//! and every rule applies to a whole orbit at once, so that every graph the grammar makes
//! has the same symmetry.
//!
//! - **Orbits.** Every vertex and crease is either the representative of its orbit or the
//!   image of one under a group element. G0's orbits come from the task's group (the
//!   representative is the first in file order); r1 on a representative creates the
//!   representatives of new orbits, r1 on its images their images.
//! - **r1** extends a representative `a` (the only vertex the enumeration offers, and the
//!   only name the notation accepts) with new variables, then every image `g·a`, whose new
//!   creases and vertices are the images of `a`'s: the same sector and length variables,
//!   no constraints of their own (they would repeat `a`'s).
//! - **r2** combines `c1` and `c2` (in different orbits) and with them every image pair
//!   `(g·c1, g·c2)`; a reflection reverses the rotation, so there the roles swap:
//!   `(g·c2, g·c1)`. This is the rigid flasher's "connecting two of the new crease lines to
//!   the same vertex on each of the four sides" (Sec. 4.3.1): `c1` grows from one corner of
//!   the central facet and `c2` from the next corner, an image of the first corner's other
//!   successor, so the combined vertex sits between two sectors of the pattern and its
//!   predecessors come from both. Its Eq. 34 sector is measured from the coordinates,
//!   those of the rotated copy included; the images' are equal by symmetry and not
//!   repeated.
//! - **Vertices on a mirror axis.** A vertex never combines with its own image under r2:
//!   the merged vertex would have to lie on a fixed line of the symmetry, which r1's
//!   placements do not know. The one way onto the mirror axis is r2′ of a vertex with its
//!   mirror image: the sink sits at the midpoint of their predecessors `p` and `μ·p`,
//!   which is on the axis, and the straight crease `p — sink — μ·p` crosses the axis at a
//!   right angle. Its dihedral angle comes from both ends' PTU, so the pattern is
//!   overconstrained there; by symmetry the two are equal (the chair's ρ_{5,5'} =
//!   ρ_{5',5}, Sec. 4.3.3), and the model's compatibility constraints hold with it. An
//!   r2′ of a vertex with its image under a half turn puts the sink on the centre.
//!   Extendable vertices of G0 lie off every fixed line (the task refuses them otherwise).
//! - **Modes.** Every extended vertex has its own PTU; the search gives an orbit one mode
//!   (its images fold the same way), so a pattern with N extended orbits has 2^N
//!   alternatives; `model::Plan` can also give every vertex its own (the star's 2^8).

use std::collections::HashSet;

use super::graph::CreaseGraph;
use super::rules::RuleError;
use super::step::Step;
use super::{Cid, R2Match, VertexType, Vid};
use crate::task::Group;

impl CreaseGraph {
    /// The pattern's symmetry group, if it has one.
    pub fn group(&self) -> Option<&Group> {
        self.init.group.as_ref()
    }

    /// Whether the pattern has a symmetry (its rules apply to whole orbits).
    pub fn is_symmetric(&self) -> bool {
        self.sym.is_some()
    }

    /// For a symmetric pattern: the representative of `v`'s orbit and the index of the
    /// group element taking it to `v`; `(v, 0)` without a symmetry.
    pub fn orbit_source(&self, v: Vid) -> (Vid, usize) {
        self.sym.as_ref().map_or((v, 0), |s| s.source(v))
    }

    /// As [`CreaseGraph::orbit_source`] for a crease.
    pub fn crease_orbit_source(&self, c: Cid) -> (Cid, usize) {
        self.sym.as_ref().map_or((c, 0), |s| s.crease_source(c))
    }

    /// The image of vertex `v` under group element `g` (`v` itself without a symmetry).
    pub fn image_of(&self, v: Vid, g: usize) -> Vid {
        let (Some(s), Some(group)) = (&self.sym, self.group()) else {
            return v;
        };
        let (r, h) = s.source(v);
        s.member(r, group.mul[g][h])
    }

    /// The mode an extended vertex folds in, as an index into the modes of
    /// [`CreaseGraph::internal_count`]: its orbit's place among the extended
    /// representatives (its own place in the extension order without a symmetry), and the
    /// element taking the representative to it.
    pub fn mode_slot(&self, v: Vid) -> Option<(usize, usize)> {
        let (rep, g) = self.orbit_source(v);
        let sym = self.sym.as_ref();
        self.extension_order
            .iter()
            .filter(|u| sym.is_none_or(|s| s.is_rep(**u)))
            .position(|u| *u == rep)
            .map(|k| (k, g))
    }

    /// Record a vertex and the crease into it that r1 just created: a new orbit, or the
    /// image of `source = (vertex, crease, element)`.
    pub(super) fn sym_register(&mut self, v: Vid, c: Cid, source: Option<(Vid, Cid, usize)>) {
        let s = self.sym.as_mut().expect("a symmetric graph");
        debug_assert_eq!(s.vsrc.len(), v.0 as usize);
        debug_assert_eq!(s.csrc.len(), c.0 as usize);
        match source {
            None => {
                s.vsrc.push((v, 0));
                s.vorbit.push(vec![v; s.order]);
                s.csrc.push((c, 0));
            }
            Some((sv, sc, g)) => {
                s.vsrc.push((sv, g as u8));
                s.vorbit.push(Vec::new());
                s.vorbit[sv.0 as usize][g] = v;
                s.csrc.push((sc, g as u8));
            }
        }
    }

    fn not_rep_error(&self, rule: &str, v: Vid) -> RuleError {
        let (r, _) = self.orbit_source(v);
        RuleError(format!(
            "{rule} does not match {}: it is an image of {} under the pattern's symmetry, and the grammar extends the representative of an orbit (write {})",
            self.vname(v),
            self.vname(r),
            self.name(r).unwrap_or(0)
        ))
    }

    /// r1 on the orbit of representative `a`.
    pub(super) fn extend_orbit(&mut self, a: Vid) -> Result<(), RuleError> {
        self.check_extend(a)?;
        let s = self.sym.as_ref().expect("a symmetric graph");
        if !s.is_rep(a) {
            return Err(self.not_rep_error("r1", a));
        }
        let order = s.order;
        let images: Vec<(usize, Vid)> = (1..order).map(|g| (g, self.image_of(a, g))).collect();
        self.extend_one(a, None)?;
        for (g, b) in images {
            if b != a && !self.vx(b).extended {
                self.extend_one(b, Some((a, g)))?;
            }
        }
        Ok(())
    }

    /// The pairs the orbit of pair `m` consists of, each with its roles (first occurrence
    /// of each), or `None` when `m.c2` is an image of `m.c1` under
    /// no involution (`straight`) or at all (r2).
    fn orbit_pairs(&self, m: R2Match, straight: bool) -> Option<Vec<R2Match>> {
        let group = self.group().expect("a symmetric graph");
        let same_orbit = self.orbit_source(m.c1).0 == self.orbit_source(m.c2).0;
        if same_orbit {
            if !straight {
                return None;
            }
            let h = (1..group.order()).find(|&h| self.image_of(m.c1, h) == m.c2)?;
            if group.mul[h][h] != 0 {
                return None;
            }
        }
        let mut seen: HashSet<(Vid, Vid)> = HashSet::new();
        let mut out = Vec::new();
        for g in 0..group.order() {
            let (x, y) = (self.image_of(m.c1, g), self.image_of(m.c2, g));
            let pair = if group.reflects(g) {
                R2Match { c1: y, c2: x }
            } else {
                R2Match { c1: x, c2: y }
            };
            if seen.insert((x.min(y), x.max(y))) {
                out.push(pair);
            }
        }
        Some(out)
    }

    /// The error of the first pair of an orbit that does not match, if any.
    fn orbit_check(&self, pairs: &[R2Match], straight: bool) -> Result<(), RuleError> {
        for p in pairs {
            if straight {
                self.check_combine_straight(p.c1, p.c2)?;
            } else {
                self.check_combine(p.c1, p.c2)?;
            }
        }
        Ok(())
    }

    /// Make `members[g]` the image of `members[0]` under element `g`: the orbit of a
    /// vertex that r2 or r2′ just made (a reflected pair's survivor may come from the
    /// other orbit, so the survivors are re-registered as one).
    fn set_orbit(&mut self, members: Vec<Vid>) {
        let s = self.sym.as_mut().expect("a symmetric graph");
        let rep = members[0];
        for v in &members {
            let ix = v.0 as usize;
            if s.vsrc.len() <= ix {
                s.vsrc.resize(ix + 1, (*v, 0));
                s.vorbit.resize(ix + 1, Vec::new());
            }
        }
        for (g, v) in members.iter().enumerate() {
            // A member fixed by some elements keeps the first element that reaches it.
            if *v == rep || s.vsrc[v.0 as usize].0 != rep {
                s.vsrc[v.0 as usize] = (rep, g as u8);
            }
            if *v != rep {
                s.vorbit[v.0 as usize] = Vec::new();
            }
        }
        s.vsrc[rep.0 as usize] = (rep, 0);
        s.vorbit[rep.0 as usize] = members;
    }

    /// The images `(g·c1, g·c2)` of a pair for every element, before it is combined.
    fn pair_images(&self, m: R2Match) -> Vec<(Vid, Vid)> {
        let order = self.group().expect("a symmetric graph").order();
        (0..order)
            .map(|g| (self.image_of(m.c1, g), self.image_of(m.c2, g)))
            .collect()
    }

    /// r2 on the orbit of the pair `m`.
    pub(super) fn combine_orbit(&mut self, m: R2Match) -> Result<(), RuleError> {
        self.check_combine(m.c1, m.c2)?;
        let pairs = self.orbit_pairs(m, false).ok_or_else(|| {
            RuleError(format!(
                "r2 does not match {} and {}: one is an image of the other under the pattern's symmetry, and the merged vertex would have to lie on a fixed line of it (a vertex reaches a mirror axis only as an r2′ sink: combine the two by r2′)",
                self.vname(m.c1),
                self.vname(m.c2)
            ))
        })?;
        self.orbit_check(&pairs, false)?;
        let images = self.pair_images(m);
        for (k, p) in pairs.into_iter().enumerate() {
            self.combine_one(p, k > 0)?;
        }
        // Each element's merged vertex: whichever of its pair survived.
        let members = images
            .iter()
            .map(|&(x, y)| if self.node_of[x.ix()].is_some() { x } else { y })
            .collect();
        self.set_orbit(members);
        Ok(())
    }

    /// r2′ on the orbit of the pair `m`; a sink fixed by an element (a vertex combined with
    /// its mirror image) is its own image.
    pub(super) fn straight_orbit(&mut self, m: R2Match) -> Result<(), RuleError> {
        self.check_combine_straight(m.c1, m.c2)?;
        let pairs = self.orbit_pairs(m, true).ok_or_else(|| {
            RuleError(format!(
                "r2′ does not match {} and {}: one is an image of the other under a rotation of order above 2, so all their images would meet in one sink",
                self.vname(m.c1),
                self.vname(m.c2)
            ))
        })?;
        self.orbit_check(&pairs, true)?;
        let images = self.pair_images(m);
        let mut sinks: Vec<((Vid, Vid), Vid)> = Vec::new();
        for (k, p) in pairs.iter().enumerate() {
            let v = Vid(self.node_of.len() as u32);
            self.straight_one(*p, k > 0)?;
            sinks.push(((p.c1.min(p.c2), p.c1.max(p.c2)), v));
        }
        let members = images
            .iter()
            .map(|&(x, y)| {
                let key = (x.min(y), x.max(y));
                sinks
                    .iter()
                    .find(|(k, _)| *k == key)
                    .map(|(_, v)| *v)
                    .expect("every element's pair is in the orbit")
            })
            .collect();
        self.set_orbit(members);
        Ok(())
    }

    /// The orbit matches of r2 (`straight` false) or r2′: one per orbit of pairs whose
    /// every pair matches, in increasing order of their sorted names, with the notation of
    /// a pair among them.
    pub(super) fn orbit_pair_matches(&self, straight: bool) -> Vec<(Step, R2Match)> {
        let eligible = |v: &super::Vertex| {
            v.ty == VertexType::Extendable && (!straight || (v.preds.len() == 1 && !v.in_g0()))
        };
        let chi: Vec<Vid> = self
            .vertices()
            .filter(|v| eligible(v))
            .map(|v| v.vid)
            .collect();
        let s = self.sym.as_ref().expect("a symmetric graph");
        let mut keys: HashSet<Vec<(Vid, Vid)>> = HashSet::new();
        let mut out: Vec<((usize, usize), Step, R2Match)> = Vec::new();
        for &c1 in chi.iter().filter(|v| s.is_rep(**v)) {
            for &c2 in &chi {
                if c1 == c2 {
                    continue;
                }
                let ok = if straight {
                    self.r2p_reason(c1, c2).is_ok()
                } else {
                    self.r2_reason(c1, c2).is_ok()
                };
                if !ok {
                    continue;
                }
                let m = R2Match { c1, c2 };
                let Some(pairs) = self.orbit_pairs(m, straight) else {
                    continue;
                };
                if self.orbit_check(&pairs, straight).is_err() {
                    continue;
                }
                let mut key: Vec<(Vid, Vid)> = pairs.iter().map(|p| (p.c1, p.c2)).collect();
                key.sort_unstable();
                if !keys.insert(key) {
                    continue;
                }
                let back = if straight {
                    self.r2p_reason(c2, c1).is_ok()
                } else {
                    self.r2_reason(c2, c1).is_ok()
                };
                let (n1, n2) = self.pair_names(m, back);
                let step = if straight {
                    Step::Straight(n1, n2)
                } else {
                    Step::Combine(n1, n2)
                };
                out.push(((n1.min(n2), n1.max(n2)), step, m));
            }
        }
        out.sort_by_key(|(k, step, _)| {
            (
                *k,
                matches!(step, Step::Combine(a, b) | Step::Straight(a, b) if a > b),
            )
        });
        out.into_iter().map(|(_, s, m)| (s, m)).collect()
    }
}
