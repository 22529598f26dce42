//! The orbits of a symmetric graph's vertices and creases (`grammar::symmetric` applies
//! the rules to them).

use super::{Cid, Vid};
use crate::task::Group;

/// The orbit structure of a symmetric graph.
#[derive(Clone, Debug)]
pub(crate) struct SymState {
    /// Group order.
    pub(super) order: usize,
    /// For every vertex id: its orbit's representative and the element taking it there.
    pub(super) vsrc: Vec<(Vid, u8)>,
    /// For every representative: the member of its orbit for each element (empty for
    /// images).
    pub(super) vorbit: Vec<Vec<Vid>>,
    /// For every crease id: its orbit's representative and the element.
    pub(super) csrc: Vec<(Cid, u8)>,
}

impl SymState {
    /// The orbits of G0 under `group`.
    pub(crate) fn of_initial(group: &Group) -> SymState {
        let nv = group.vertex[0].len();
        let nc = group.crease[0].len();
        let mut vsrc = Vec::with_capacity(nv);
        let mut vorbit = Vec::with_capacity(nv);
        for v in 0..nv {
            let (rep, g) = group.g0_source(v);
            vsrc.push((Vid(rep as u32), g as u8));
            vorbit.push(if rep == v {
                (0..group.order())
                    .map(|g| Vid(group.vertex[g][v] as u32))
                    .collect()
            } else {
                Vec::new()
            });
        }
        let csrc = (0..nc)
            .map(|c| {
                let (rep, g) = group.g0_crease_source(c);
                (Cid(rep as u32), g as u8)
            })
            .collect();
        SymState {
            order: group.order(),
            vsrc,
            vorbit,
            csrc,
        }
    }

    /// Whether `v` represents its orbit.
    pub(crate) fn is_rep(&self, v: Vid) -> bool {
        self.vsrc[v.0 as usize].0 == v
    }

    /// The representative of `v`'s orbit and the element taking it to `v`.
    pub(crate) fn source(&self, v: Vid) -> (Vid, usize) {
        let (r, g) = self.vsrc[v.0 as usize];
        (r, g as usize)
    }

    /// The representative of crease `c`'s orbit and the element taking it to `c`.
    pub(crate) fn crease_source(&self, c: Cid) -> (Cid, usize) {
        let (r, g) = self.csrc[c.0 as usize];
        (r, g as usize)
    }

    /// The member of `rep`'s orbit for element `g`.
    pub(super) fn member(&self, rep: Vid, g: usize) -> Vid {
        self.vorbit[rep.0 as usize][g]
    }

    /// Every member of `v`'s orbit (a member fixed by some elements appears once).
    pub(crate) fn orbit(&self, v: Vid) -> Vec<Vid> {
        let (r, _) = self.source(v);
        let mut out: Vec<Vid> = self.vorbit[r.0 as usize].clone();
        out.sort_unstable();
        out.dedup();
        out
    }
}
