//! Terms that vanish wherever the formula has a value: `a + 0·x → a` and `a - (x - x) → a`
//! where `x` can only fail to be finite when `a` is NaN anyway.
//!
//! **Why a second pass.** `0·x → 0` and `x - x → 0` hold only for finite `x` (`0·∞` and
//! `∞ - ∞` are NaN), and a model's `x` is often not finite everywhere: a crease's in-plane
//! direction is its vector divided by its length, NaN where two vertices coincide (or the
//! length underflows), and every angle, rotation and fold angle downstream inherits it.
//! No range analysis can prove such an `x` finite, because it is not. But it is *finite
//! unless a NaN arises* at a few nodes (the `atan2` of that direction: bounded, so never
//! infinite), and the formulas that hold `0·x` as a term hold the same NaN in a sibling
//! term (`sin φ · y + 0 · cos φ`). So the term can go: where it is 0 the sum is unchanged,
//! and where it is NaN so is the sibling, and so the sum.
//!
//! **The facts, per node of the rebuilt graph**, over *origins*: nodes that are bounded or
//! NaN, never infinite (`sin`, `cos`, `atan2`, `acos`, `clamp` of anything):
//! - `fin`: the node is finite, within `range`, whenever no origin in the set is NaN
//!   (computed with [`ExprGraph::range_of`] on the children's conditional ranges; an
//!   unbounded `sin`/`atan2`/… that it cannot place becomes an origin itself);
//! - `strict`: origins whose NaN makes the node NaN (NaN propagates through every
//!   operation but `sgn`, and through a `select` only if both branches carry it);
//! - `zero`: the node is ±0 whenever no origin in the set is NaN (`0·x` with `x` under
//!   `fin`, `x - x`, sums, products and negations of such terms).
//!
//! A sum `a ± b` with `zero(b) ⊆ strict(a)` becomes `a` (and `b - a` becomes `-a`): if
//! every origin of `zero(b)` is a number, `b` is ±0; otherwise one of them is NaN, hence
//! `a`, hence both forms. So values are unchanged for every input, NaN included; only the
//! sign of a zero may change, as with [`ExprGraph::add`]'s `x + 0 → x`.

use crate::expr::{ExprGraph, Node, NodeId, Range};

/// Above this many origins a set is given up (`fin`, `zero`: unknown) or cut (`strict`: a
/// subset is still true), which keeps the pass linear on large models.
const MAX_SET: usize = 64;

/// Sorted origin ids.
type Set = Vec<u32>;

#[derive(Clone, Debug)]
struct Info {
    fin: Option<Set>,
    range: Range,
    strict: Set,
    zero: Option<Set>,
}

fn union(a: &[u32], b: &[u32]) -> Set {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => {
                out.push(a[i]);
                i += 1;
            }
            std::cmp::Ordering::Greater => {
                out.push(b[j]);
                j += 1;
            }
            std::cmp::Ordering::Equal => {
                out.push(a[i]);
                i += 1;
                j += 1;
            }
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
}

fn intersection(a: &[u32], b: &[u32]) -> Set {
    a.iter()
        .copied()
        .filter(|x| b.binary_search(x).is_ok())
        .collect()
}

fn subset(a: &[u32], b: &[u32]) -> bool {
    a.iter().all(|x| b.binary_search(x).is_ok())
}

/// A union that gives up beyond [`MAX_SET`].
fn join(a: Option<&Set>, b: Option<&Set>) -> Option<Set> {
    let u = union(a?, b?);
    (u.len() <= MAX_SET).then_some(u)
}

/// The facts of node `id` of `g`, its children's facts being in `info`.
fn facts(g: &ExprGraph, id: NodeId, info: &[Info]) -> Info {
    use Node::*;
    let node = *g.node(id);
    let ch = node.children();
    let of = |c: NodeId| &info[c.index()];
    let known = g.range(id);
    // fin and range.
    let (fin, range) = if known.finite {
        (Some(Set::new()), known)
    } else if node.is_leaf() {
        (None, Range::UNKNOWN)
    } else {
        let args: Vec<Range> = ch
            .into_iter()
            .map(|c| match of(c).fin {
                Some(_) => of(c).range,
                None => Range::UNKNOWN,
            })
            .collect();
        let r = g.range_of(&node, &args);
        if r.finite {
            // Children the range did not need are UNKNOWN above; the others' conditions
            // all apply (a superset of conditions is still true).
            let mut s = Some(Set::new());
            for c in ch {
                if let Some(f) = &of(c).fin {
                    s = join(s.as_ref(), Some(f));
                }
            }
            (s, r)
        } else {
            let bound = match node {
                Sin(_) | Cos(_) | Clamp(_) => Some(Range::interval(-1.0, 1.0)),
                Acos(_) => Some(Range::of(&Acos(id), &[Range::FINITE])),
                Atan2(..) => Some(Range::of(&Atan2(id, id), &[Range::FINITE; 2])),
                _ => None,
            };
            match bound {
                // Bounded or NaN: an origin.
                Some(b) => (Some(vec![id.0]), b),
                None => (None, Range::UNKNOWN),
            }
        }
    };
    // strict.
    let mut strict = match node {
        Const(_) | Var(_) | Param(_) | Sgn(_) => Set::new(),
        Select(_, a, b) => intersection(&of(a).strict, &of(b).strict),
        _ => ch
            .into_iter()
            .fold(Set::new(), |s, c| union(&s, &of(c).strict)),
    };
    if fin.as_deref() == Some(&[id.0][..]) {
        strict = union(&strict, &[id.0]);
    }
    strict.truncate(MAX_SET);
    // zero.
    let z = |c: NodeId| of(c).zero.as_ref();
    let f = |c: NodeId| of(c).fin.as_ref();
    let zero = match node {
        Const(c) => (c == 0.0).then(Set::new),
        Mul(a, b) => join(z(a), f(b)).or_else(|| join(z(b), f(a))),
        Sub(a, b) if a == b => f(a).cloned(),
        Add(a, b) | Sub(a, b) => join(z(a), z(b)),
        Div(a, b) => {
            let rb = of(b).range;
            if rb.finite && (rb.lo > 0.0 || rb.hi < 0.0) {
                join(z(a), f(b))
            } else {
                None
            }
        }
        Neg(a) | Sqrt(a) => z(a).cloned(),
        Select(_, a, b) => join(z(a), z(b)),
        _ => None,
    };
    Info {
        fin,
        range,
        strict,
        zero,
    }
}

/// A copy of `outputs` of `graph` with the vanishing terms removed; the new graph, the
/// outputs' ids in it, and how many terms were removed.
pub fn fold_vanishing(graph: &ExprGraph, outputs: &[NodeId]) -> (ExprGraph, Vec<NodeId>, usize) {
    let mark = graph.reachable(outputs);
    let mut g = ExprGraph::new();
    let mut info: Vec<Info> = Vec::new();
    let mut map = vec![NodeId(u32::MAX); graph.len()];
    let mut removed = 0;
    // The facts of every node `g` has gained since the last call, in order.
    fn sync(g: &ExprGraph, info: &mut Vec<Info>) {
        for i in info.len()..g.len() {
            let id = NodeId(u32::try_from(i).expect("graph has < 2^32 nodes"));
            let f = facts(g, id, info);
            info.push(f);
        }
    }
    let vanishes = |info: &[Info], term: NodeId, other: NodeId| {
        info[term.index()]
            .zero
            .as_ref()
            .is_some_and(|z| subset(z, &info[other.index()].strict))
    };
    for (i, n) in graph.nodes().iter().enumerate() {
        if !mark[i] {
            continue;
        }
        let node = n.map_children(|c| map[c.index()]);
        // `a ± b` with a vanishing `b` is `a`; `b - a` with a vanishing `b` is `-a`.
        let kept = match node {
            Node::Add(a, b) if vanishes(&info, b, a) => Some(a),
            Node::Add(a, b) if vanishes(&info, a, b) => Some(b),
            Node::Sub(a, b) if vanishes(&info, b, a) => Some(a),
            Node::Sub(a, b) if vanishes(&info, a, b) => Some(g.add(Node::Neg(b))),
            _ => None,
        };
        if kept.is_some() {
            removed += 1;
        }
        map[i] = kept.unwrap_or_else(|| g.add(node));
        sync(&g, &mut info);
    }
    let outs: Vec<NodeId> = outputs.iter().map(|o| map[o.index()]).collect();
    // Compact: drop what the removed terms left unreachable.
    let (g, outs) = g.extract(&outs);
    (g, outs, removed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::{Ctx, Sym};
    use crate::kinematics::Scalar;

    /// `x / |(x, y)|`, NaN at the origin: nothing proves it finite.
    fn direction(ctx: &Ctx) -> Sym {
        let (x, y) = (ctx.var(0), ctx.var(1));
        let len = (x.clone() * x.clone() + y.clone() * y.clone()).sqrt();
        x / len
    }

    fn same(a: f64, b: f64) -> bool {
        a == b || (a.is_nan() && b.is_nan())
    }

    #[test]
    fn a_zero_term_goes_where_its_sibling_carries_the_nan() {
        let ctx = Ctx::new();
        let phi = direction(&ctx).atan2(&ctx.var(2));
        let zero = Sym::Const(0.0);
        // sin φ · z + 0 · cos φ, as a rotation with a zero entry writes it.
        let f = phi.sin() * ctx.var(2) + zero * phi.cos();
        let id = ctx.node_id(&f);
        let g = ctx.to_graph();
        assert!(
            matches!(g.node(id), Node::Add(..)),
            "construction cannot fold it"
        );
        let (h, outs, removed) = fold_vanishing(&g, &[id]);
        assert_eq!(removed, 1);
        assert!(matches!(h.node(outs[0]), Node::Mul(..)), "{:?}", h.nodes());
        for v in [
            [0.3, 0.4, 0.5],
            [0.0, 0.0, 1.0], // 0/0: NaN in both
            [-1.0, 2.0, -0.5],
            [1e-170, 0.0, 1.0], // the length underflows: x/0 = inf
        ] {
            let (a, b) = (g.eval(&[id], &v, &[])[0], h.eval(&outs, &v, &[])[0]);
            assert!(same(a, b), "{v:?}: {a} vs {b}");
        }
    }

    #[test]
    fn a_zero_term_stays_where_nothing_else_carries_the_nan() {
        let ctx = Ctx::new();
        let phi = direction(&ctx).atan2(&ctx.var(2));
        let zero = Sym::Const(0.0);
        // z + 0 · cos φ: at x = y = 0 this is NaN, z alone is not.
        let f = ctx.var(2) + zero.clone() * phi.cos();
        let id = ctx.node_id(&f);
        let g = ctx.to_graph();
        let (h, outs, removed) = fold_vanishing(&g, &[id]);
        assert_eq!(removed, 0);
        let v = [0.0, 0.0, 1.0];
        assert!(h.eval(&outs, &v, &[])[0].is_nan());
        // Nor through a sgn (NaN gives 0) or one branch of a select.
        let f2 = phi.sin().sgn() + zero.clone() * phi.cos();
        let f3 = Sym::select(&ctx.var(2), &phi.sin(), &ctx.var(2)) + zero * phi.cos();
        let (i2, i3) = (ctx.node_id(&f2), ctx.node_id(&f3));
        let g = ctx.to_graph();
        let (_, _, removed) = fold_vanishing(&g, &[i2, i3]);
        assert_eq!(removed, 0);
    }

    #[test]
    fn differences_and_products_of_zero_terms() {
        let ctx = Ctx::new();
        let phi = direction(&ctx).atan2(&ctx.var(2));
        let (s, c) = (phi.sin(), phi.cos());
        let zero = Sym::Const(0.0);
        let w = s.clone() * c.clone();
        // (w - w) and 0·c·s vanish beside s; c - 0·s becomes c; 0·c - s becomes -s.
        let f1 = s.clone() + (w.clone() - w.clone());
        let f2 = s.clone() - zero.clone() * c.clone() * s.clone();
        let f3 = c.clone() - zero.clone() * s.clone();
        let f4 = zero * c - s.clone();
        let ids: Vec<NodeId> = [f1, f2, f3, f4].iter().map(|f| ctx.node_id(f)).collect();
        let g = ctx.to_graph();
        let (h, outs, removed) = fold_vanishing(&g, &ids);
        assert_eq!(removed, 4, "{:?}", h.nodes());
        assert!(matches!(h.node(outs[0]), Node::Sin(_)));
        assert!(matches!(h.node(outs[1]), Node::Sin(_)));
        assert!(matches!(h.node(outs[2]), Node::Cos(_)));
        assert!(matches!(h.node(outs[3]), Node::Neg(_)));
        for v in [[0.3, 0.4, 0.5], [0.0, 0.0, 1.0], [2.0, -1.0, -3.0]] {
            let (a, b) = (g.eval(&ids, &v, &[]), h.eval(&outs, &v, &[]));
            for k in 0..ids.len() {
                assert!(same(a[k], b[k]), "{v:?} output {k}: {} vs {}", a[k], b[k]);
            }
        }
    }
}
