//! Canonical codes: equal codes ⇔ the graphs are the same design family (SPEC §2).
//!
//! The isomorphism that matters maps the embedded graph orientation-preservingly: edge
//! directions, the counter-clockwise order around every vertex, the type χ/∅, the mark on
//! the vertex extended last, and G0's vertices (they carry the task's coordinates and
//! drives, so each maps to itself). Plain digraph isomorphism would merge `2, 3` with
//! `2, 4`, which the thesis keeps apart.
//!
//! Around a vertex the rotation is not only cyclic but anchored: incoming creases are
//! contiguous and come first (p1 … pm), then the slots s1 s2 s3; for a χ vertex the open
//! sector marks where p1 starts. So once G0's vertices are labelled, a breadth-first
//! traversal that visits neighbours in that order labels every vertex canonically, and the
//! code (each vertex's ordered neighbour labels) is a complete invariant computed in linear
//! time. The mirror image reverses every rotation (p_m … p1, s3 s2 s1) and maps G0's
//! vertices through the task's mirror map.
//!
//! An r2′ sink is never a root of the traversal (it is not in G0) and is reached from one
//! of its two neighbours, so at most one of them is unlabelled when it is visited: its
//! neighbour order cannot change the labels, and its code lists them sorted.

use std::collections::VecDeque;

use super::graph::CreaseGraph;
use super::{Vertex, VertexType};

/// A canonical code of a graph (or of its mirror image).
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Code(pub Vec<u32>);

const NONE: u32 = u32::MAX;
const TAG_FIXED: u32 = u32::MAX - 1;
const TAG_OPEN: u32 = u32::MAX - 2;
const TAG_EXTENDED: u32 = u32::MAX - 3;
const TAG_MARK: u32 = u32::MAX - 4;
const TAG_SINK: u32 = u32::MAX - 5;

impl CreaseGraph {
    /// The canonical code of this graph.
    pub fn canonical_code(&self) -> Code {
        self.code(None)
    }

    /// The canonical code of this graph's mirror image about the x-axis, for tasks whose G0
    /// is mirror-symmetric (`symmetry.mirror_xz`); `None` otherwise.
    pub fn mirror_code(&self) -> Option<Code> {
        let perm = self.init.mirror.as_ref()?.vertex.clone();
        Some(self.code(Some(&perm)))
    }

    /// Whether `other` is this graph's mirror image (same task).
    pub fn is_mirror_of(&self, other: &CreaseGraph) -> bool {
        self.mirror_code() == Some(other.canonical_code())
    }

    fn code(&self, mirror: Option<&[usize]>) -> Code {
        let n_ids = self.node_of.len();
        let mut label = vec![NONE; n_ids];
        let mut by_label: Vec<&Vertex> = Vec::with_capacity(self.order.len());
        let k0 = self.init.vertices.len();
        // G0 vertex i is labelled i (its mirror image: mirror[i]).
        let mut g0: Vec<&Vertex> = vec![self.vx(self.order[0]); k0];
        for v in self.vertices().filter(|v| v.in_g0()) {
            let i = v.g0.expect("G0 vertex");
            let l = mirror.map_or(i, |m| m[i]);
            label[v.vid.ix()] = l as u32;
            g0[l] = v;
        }
        by_label.extend(g0);
        let mut queue: VecDeque<usize> = (0..k0).collect();
        let mirrored = mirror.is_some();
        let mut neighbours: Vec<u32> = Vec::with_capacity(8);
        while let Some(l) = queue.pop_front() {
            let v = by_label[l];
            if is_fixed(v) {
                // Terminal G0 vertices never change and only touch G0 vertices.
                continue;
            }
            neighbours.clear();
            let preds = v.preds.iter().map(|&c| self.cr(c).tail);
            let slots = v.slots.iter().flatten().map(|&c| self.cr(c).head);
            if mirrored {
                neighbours.extend(preds.rev().map(|u| u.0));
                neighbours.extend(slots.rev().map(|u| u.0));
            } else {
                neighbours.extend(preds.map(|u| u.0));
                neighbours.extend(slots.map(|u| u.0));
            }
            for &u in &neighbours {
                let u = super::Vid(u);
                if label[u.ix()] == NONE {
                    label[u.ix()] = by_label.len() as u32;
                    queue.push_back(by_label.len());
                    by_label.push(self.vx(u));
                }
            }
        }
        let mut code = Vec::with_capacity(by_label.len() * 6 + 2);
        for v in &by_label {
            if is_fixed(v) {
                code.push(TAG_FIXED);
                continue;
            }
            let pred = |c: &super::Cid| label[self.cr(*c).tail.ix()];
            if v.sink_between.is_some() {
                // An r2′ sink: two creases and two straight sectors. With two rays the
                // rotation reads the same both ways, so the unordered pair of its
                // neighbours is all there is (in the mirror image too).
                let mut p: Vec<u32> = v.preds.iter().map(pred).collect();
                p.sort_unstable();
                code.push(TAG_SINK);
                code.push(p.len() as u32);
                code.extend(p);
                continue;
            }
            code.push(if v.extended { TAG_EXTENDED } else { TAG_OPEN });
            code.push(v.preds.len() as u32);
            let slot = |s: &Option<super::Cid>| s.map_or(NONE, |c| label[self.cr(c).head.ix()]);
            if mirrored {
                code.extend(v.preds.iter().rev().map(pred));
                code.extend(v.slots.iter().rev().map(slot));
            } else {
                code.extend(v.preds.iter().map(pred));
                code.extend(v.slots.iter().map(slot));
            }
        }
        code.push(TAG_MARK);
        code.push(self.last_extended().map_or(NONE, |v| label[v.ix()]));
        Code(code)
    }
}

fn is_fixed(v: &Vertex) -> bool {
    v.in_g0() && v.ty == VertexType::Terminal && !v.extended
}
