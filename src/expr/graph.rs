//! The hash-consed arena.

use super::node::{Node, NodeId, Range};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A small, fast, non-cryptographic hasher (FxHash) for the hash-consing table.
#[derive(Default, Clone, Copy)]
pub(crate) struct FxHasher(u64);

impl Hasher for FxHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(b as u64);
        }
    }
    #[inline]
    fn write_u8(&mut self, i: u8) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn write_isize(&mut self, i: isize) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

pub(crate) type FxBuild = BuildHasherDefault<FxHasher>;
pub(crate) type FxHashMap<K, V> = HashMap<K, V, FxBuild>;

/// An arena of expression nodes in which equal subexpressions are one node.
///
/// [`ExprGraph::add`] folds constants and applies a few cheap identities on construction.
/// Folding never changes a computed value, with one documented exception: the sign of a
/// zero. `x + 0 → x`, `0 - x → -x`, `(-x) - y → -(x + y)` and `x * 0 → 0` may turn `-0.0`
/// into `+0.0` or back;
/// the results compare equal (`==`) and only `atan2` and division *at exactly zero* can
/// tell them apart. `x * 0 → 0` and `x - x → 0` are applied only when the range analysis
/// proves `x` finite for every finite input (otherwise `inf * 0` would be NaN).
/// `sin(-x) → -sin x` and `cos(-x) → cos x` rely on the platform's libm being odd/even,
/// which glibc's is (the interpreter-versus-f64 tests check it).
#[derive(Clone, Debug, Default)]
pub struct ExprGraph {
    nodes: Vec<Node>,
    ranges: Vec<Range>,
    index: FxHashMap<Node, NodeId>,
    n_vars: usize,
    n_params: usize,
}

/// Node and operation counts of the part of a graph reachable from a set of outputs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Counts {
    /// Reachable nodes (leaves included).
    pub nodes: usize,
    /// Reachable non-leaf nodes (operations).
    pub ops: usize,
    /// Reachable calls to transcendental functions (sin, cos, acos, atan2).
    pub calls: usize,
}

impl ExprGraph {
    /// An empty graph.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of nodes in the arena (reachable or not).
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the arena is empty.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// One more than the largest variable index in the arena.
    pub fn n_vars(&self) -> usize {
        self.n_vars
    }

    /// One more than the largest parameter index in the arena.
    pub fn n_params(&self) -> usize {
        self.n_params
    }

    /// The node with this id.
    #[inline]
    pub fn node(&self, id: NodeId) -> &Node {
        &self.nodes[id.index()]
    }

    /// All nodes, in topological order (children first).
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// What the range analysis knows about a node.
    pub fn range(&self, id: NodeId) -> Range {
        self.ranges[id.index()]
    }

    /// The constant value of a node, if it is a constant.
    pub fn const_value(&self, id: NodeId) -> Option<f64> {
        match self.nodes[id.index()] {
            Node::Const(c) => Some(c),
            _ => None,
        }
    }

    /// A constant node.
    pub fn constant(&mut self, c: f64) -> NodeId {
        self.intern(Node::Const(c))
    }

    /// Variable `i`.
    pub fn var(&mut self, i: usize) -> NodeId {
        self.intern(Node::Var(
            u32::try_from(i).expect("variable index fits u32"),
        ))
    }

    /// Parameter `i`.
    pub fn param(&mut self, i: usize) -> NodeId {
        self.intern(Node::Param(
            u32::try_from(i).expect("parameter index fits u32"),
        ))
    }

    fn is_const(&self, id: NodeId, c: f64) -> bool {
        // Numeric comparison: both zeros count as zero.
        self.const_value(id) == Some(c)
    }

    fn neg_of(&self, id: NodeId) -> Option<NodeId> {
        match self.nodes[id.index()] {
            Node::Neg(a) => Some(a),
            _ => None,
        }
    }

    /// Whether node `s` is `sgn(x)`.
    fn is_sgn_of(&self, s: NodeId, x: NodeId) -> bool {
        matches!(self.nodes[s.index()], Node::Sgn(c) if c == x)
    }

    /// Whether node `m` is `x · sgn(x)` (either operand order).
    fn is_abs_of(&self, m: NodeId, x: NodeId) -> bool {
        match self.nodes[m.index()] {
            Node::Mul(a, b) => (a == x && self.is_sgn_of(b, x)) || (b == x && self.is_sgn_of(a, x)),
            _ => false,
        }
    }

    fn finite(&self, id: NodeId) -> bool {
        self.ranges[id.index()].finite
    }

    /// Add a node, folding constants and cheap exact identities, and return the id of the
    /// equal node if one exists. Children must already be in this graph.
    pub fn add(&mut self, node: Node) -> NodeId {
        use Node::*;
        for c in node.children() {
            assert!(
                c.index() < self.nodes.len(),
                "child {c:?} not in this graph"
            );
        }
        // Every child constant: evaluate with the shared semantics.
        if !node.is_leaf() {
            let ch = node.children();
            let vals: Vec<Option<f64>> = ch.into_iter().map(|c| self.const_value(c)).collect();
            if vals.iter().all(Option::is_some) {
                let args: Vec<f64> = vals.into_iter().map(Option::unwrap).collect();
                return self.constant(node.eval_with(&args, &[], &[]));
            }
        }
        match node {
            Add(a, b) => self.fold_add(a, b),
            Sub(a, b) => self.fold_sub(a, b),
            Mul(a, b) => self.fold_mul(a, b),
            Div(a, b) => self.fold_div(a, b),
            Neg(a) => {
                if let Some(x) = self.neg_of(a) {
                    return x;
                }
                self.intern(Neg(a))
            }
            Sin(a) => {
                if let Some(x) = self.neg_of(a) {
                    let s = self.add(Sin(x));
                    return self.add(Neg(s));
                }
                self.intern(Sin(a))
            }
            Cos(a) => {
                if let Some(x) = self.neg_of(a) {
                    return self.add(Cos(x));
                }
                self.intern(Cos(a))
            }
            Acos(a) => {
                // acos already clamps.
                if let Clamp(x) = self.nodes[a.index()] {
                    return self.add(Acos(x));
                }
                self.intern(Acos(a))
            }
            Clamp(a) => {
                if matches!(self.nodes[a.index()], Clamp(_)) || self.ranges[a.index()].within_unit()
                {
                    return a;
                }
                self.intern(Clamp(a))
            }
            Sgn(a) => self.fold_sgn(a),
            Select(c, a, b) => self.fold_select(c, a, b),
            Sqrt(_) | Atan2(..) | Const(_) | Var(_) | Param(_) => self.intern(node),
        }
    }

    /// `a + b`: zeros dropped, negations turned into differences, `x + x = 2x`, operands in
    /// canonical order.
    fn fold_add(&mut self, a: NodeId, b: NodeId) -> NodeId {
        use Node::*;
        if self.is_const(b, 0.0) {
            return a;
        }
        if self.is_const(a, 0.0) {
            return b;
        }
        if let Some(nb) = self.neg_of(b) {
            return self.add(Sub(a, nb));
        }
        if let Some(na) = self.neg_of(a) {
            return self.add(Sub(b, na));
        }
        if a == b {
            // x + x = 2x exactly.
            let two = self.constant(2.0);
            return self.add(Mul(two, a));
        }
        // Commutative: canonical operand order, so a+b and b+a are one node.
        let (a, b) = if a <= b { (a, b) } else { (b, a) };
        self.intern(Add(a, b))
    }

    /// `a - b`: zeros dropped, `x - x = 0` for finite `x`, negations moved out.
    fn fold_sub(&mut self, a: NodeId, b: NodeId) -> NodeId {
        use Node::*;
        if self.is_const(b, 0.0) {
            return a;
        }
        if self.is_const(a, 0.0) {
            return self.add(Neg(b));
        }
        if a == b && self.finite(a) {
            return self.constant(0.0);
        }
        if let Some(nb) = self.neg_of(b) {
            return self.add(Add(a, nb));
        }
        if let Some(na) = self.neg_of(a) {
            // (-x) - b = -(x + b) exactly (rounding is symmetric), so that
            // -(-x - b) becomes x + b.
            let s = self.add(Add(na, b));
            return self.add(Neg(s));
        }
        self.intern(Sub(a, b))
    }

    /// `a · b`: ±1 and finite·0 folded, negations and negative constant factors moved
    /// outward, constants first.
    fn fold_mul(&mut self, a: NodeId, b: NodeId) -> NodeId {
        use Node::*;
        if self.is_const(a, 1.0) {
            return b;
        }
        if self.is_const(b, 1.0) {
            return a;
        }
        if self.is_const(a, -1.0) {
            return self.add(Neg(b));
        }
        if self.is_const(b, -1.0) {
            return self.add(Neg(a));
        }
        if (self.is_const(a, 0.0) && self.finite(b)) || (self.is_const(b, 0.0) && self.finite(a)) {
            return self.constant(0.0);
        }
        // Negations move outward (exact), so they cancel and share.
        match (self.neg_of(a), self.neg_of(b)) {
            (Some(x), Some(y)) => return self.add(Mul(x, y)),
            (Some(x), None) => {
                let m = self.add(Mul(x, b));
                return self.add(Neg(m));
            }
            (None, Some(y)) => {
                let m = self.add(Mul(a, y));
                return self.add(Neg(m));
            }
            (None, None) => {}
        }
        // A negative constant factor becomes a negation outside (exact): `-2·x`
        // and `2·x` share, and `y + (-2)·x` becomes `y - 2·x`.
        for (k, x) in [(a, b), (b, a)] {
            if let Some(c) = self.const_value(k)
                && c < 0.0
            {
                let pos = self.constant(-c);
                let m = self.add(Mul(pos, x));
                return self.add(Neg(m));
            }
        }
        // Constants first, then by id.
        let (a, b) = match (self.const_value(a), self.const_value(b)) {
            (None, Some(_)) => (b, a),
            (Some(_), None) => (a, b),
            _ if a <= b => (a, b),
            _ => (b, a),
        };
        self.intern(Mul(a, b))
    }

    /// `a / b`: ±1 folded, a power of two as a product, negations and negative constants
    /// moved outward.
    fn fold_div(&mut self, a: NodeId, b: NodeId) -> NodeId {
        use Node::*;
        if self.is_const(b, 1.0) {
            return a;
        }
        if self.is_const(b, -1.0) {
            return self.add(Neg(a));
        }
        if let Some(c) = self.const_value(b) {
            // Division by a power of two is multiplication by its exact inverse.
            let inv = 1.0 / c;
            if c.is_finite() && c != 0.0 && is_power_of_two(c.abs()) && inv.is_finite() {
                let k = self.constant(inv);
                return self.add(Mul(k, a));
            }
        }
        for (k, first) in [(a, true), (b, false)] {
            if let Some(c) = self.const_value(k)
                && c < 0.0
            {
                let pos = self.constant(-c);
                let d = if first {
                    self.add(Div(pos, b))
                } else {
                    self.add(Div(a, pos))
                };
                return self.add(Neg(d));
            }
        }
        match (self.neg_of(a), self.neg_of(b)) {
            (Some(x), Some(y)) => return self.add(Div(x, y)),
            (Some(x), None) => {
                let d = self.add(Div(x, b));
                return self.add(Neg(d));
            }
            (None, Some(y)) => {
                let d = self.add(Div(a, y));
                return self.add(Neg(d));
            }
            (None, None) => {}
        }
        self.intern(Div(a, b))
    }

    /// `sgn(a)`: constant where the range of `a` decides it; `sgn(sgn x) = sgn x`,
    /// `sgn(-x) = -sgn x`.
    fn fold_sgn(&mut self, a: NodeId) -> NodeId {
        use Node::*;
        let r = self.ranges[a.index()];
        if r.finite && r.lo > 0.0 {
            return self.constant(1.0);
        }
        if r.finite && r.hi < 0.0 {
            return self.constant(-1.0);
        }
        match self.nodes[a.index()] {
            Sgn(_) => a,
            Neg(x) => {
                let s = self.add(Sgn(x));
                self.add(Neg(s))
            }
            _ => self.intern(Sgn(a)),
        }
    }

    /// `select(c, a, b)`: one branch where the range of `c` decides it or both are equal.
    fn fold_select(&mut self, c: NodeId, a: NodeId, b: NodeId) -> NodeId {
        use Node::*;
        if a == b {
            return a;
        }
        let r = self.ranges[c.index()];
        if r.finite && r.lo > 0.0 {
            return a;
        }
        if r.finite && r.hi <= 0.0 {
            return b;
        }
        self.intern(Select(c, a, b))
    }

    /// The range of `node` (whose children are in this graph) given ranges of its children
    /// in operand order: [`Range::of`] plus the relational facts that the interval of each
    /// operand alone cannot give: `x·x ≥ 0`, `x·sgn x = |x|` and `x + x·sgn x ≥ 0` (max0,
    /// under the square roots of the PTU).
    pub fn range_of(&self, node: &Node, args: &[Range]) -> Range {
        match *node {
            Node::Select(c, a, _) if c == a => Range::select_positive(&args[0], &args[2]),
            Node::Mul(a, b) if a == b => Range::square(&args[0]),
            Node::Mul(a, b) if self.is_sgn_of(b, a) => Range::abs(&args[0]),
            Node::Mul(a, b) if self.is_sgn_of(a, b) => Range::abs(&args[1]),
            Node::Add(a, b) if self.is_abs_of(b, a) => Range::plus_abs(&args[0]),
            Node::Add(a, b) if self.is_abs_of(a, b) => Range::plus_abs(&args[1]),
            _ => Range::of(node, args),
        }
    }

    /// The id of a node equal to `node`, if the graph has one (no folding).
    pub fn lookup(&self, node: &Node) -> Option<NodeId> {
        self.index.get(node).copied()
    }

    /// Insert a node as it is (no folding), reusing an equal node.
    pub(crate) fn intern(&mut self, node: Node) -> NodeId {
        if let Some(&id) = self.index.get(&node) {
            return id;
        }
        let args: Vec<Range> = node
            .children()
            .into_iter()
            .map(|c| self.ranges[c.index()])
            .collect();
        let range = self.range_of(&node, &args);
        match node {
            Node::Var(i) => self.n_vars = self.n_vars.max(i as usize + 1),
            Node::Param(i) => self.n_params = self.n_params.max(i as usize + 1),
            _ => {}
        }
        let id = NodeId(u32::try_from(self.nodes.len()).expect("graph has < 2^32 nodes"));
        self.nodes.push(node);
        self.ranges.push(range);
        self.index.insert(node, id);
        id
    }

    /// Marks of the nodes reachable from `outputs` (indexed by node id).
    pub fn reachable(&self, outputs: &[NodeId]) -> Vec<bool> {
        let mut mark = vec![false; self.nodes.len()];
        let mut hi = 0;
        for &o in outputs {
            mark[o.index()] = true;
            hi = hi.max(o.index() + 1);
        }
        // Children precede parents, so one downward sweep marks everything (no recursion).
        for i in (0..hi).rev() {
            if mark[i] {
                for c in self.nodes[i].children() {
                    mark[c.index()] = true;
                }
            }
        }
        mark
    }

    /// Node, operation and call counts of the part reachable from `outputs`.
    pub fn counts(&self, outputs: &[NodeId]) -> Counts {
        let mark = self.reachable(outputs);
        let mut c = Counts::default();
        for (i, m) in mark.iter().enumerate() {
            if *m {
                c.nodes += 1;
                let n = &self.nodes[i];
                if !n.is_leaf() {
                    c.ops += 1;
                }
                if matches!(
                    n,
                    Node::Sin(_) | Node::Cos(_) | Node::Acos(_) | Node::Atan2(..)
                ) {
                    c.calls += 1;
                }
            }
        }
        c
    }

    /// Copy the part reachable from `outputs` into a fresh graph (re-folding on the way);
    /// returns the graph and the outputs' new ids.
    pub fn extract(&self, outputs: &[NodeId]) -> (ExprGraph, Vec<NodeId>) {
        let mark = self.reachable(outputs);
        let mut g = ExprGraph::new();
        let mut map = vec![NodeId(u32::MAX); self.nodes.len()];
        for (i, n) in self.nodes.iter().enumerate() {
            if mark[i] {
                map[i] = g.add(n.map_children(|c| map[c.index()]));
            }
        }
        let outs = outputs.iter().map(|o| map[o.index()]).collect();
        (g, outs)
    }

    /// Evaluate every node reachable from `outputs` (a convenience over
    /// [`Tape`](super::Tape) for one-off use).
    pub fn eval(&self, outputs: &[NodeId], vars: &[f64], params: &[f64]) -> Vec<f64> {
        let mark = self.reachable(outputs);
        let mut vals = vec![0.0; self.nodes.len()];
        let mut args = [0.0; 3];
        for (i, n) in self.nodes.iter().enumerate() {
            if mark[i] {
                let ch = n.children();
                for (k, c) in ch.into_iter().enumerate() {
                    args[k] = vals[c.index()];
                }
                vals[i] = n.eval_with(&args[..ch.len()], vars, params);
            }
        }
        outputs.iter().map(|o| vals[o.index()]).collect()
    }
}

fn is_power_of_two(x: f64) -> bool {
    // A normal power of two has an all-zero mantissa.
    x.is_normal() && (x.to_bits() & ((1u64 << 52) - 1)) == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hash_consing_and_folding() {
        let mut g = ExprGraph::new();
        let x = g.var(0);
        let y = g.var(1);
        let a = g.add(Node::Add(x, y));
        let b = g.add(Node::Add(y, x));
        assert_eq!(a, b);
        let two = g.constant(2.0);
        let three = g.constant(3.0);
        let five = g.add(Node::Add(two, three));
        assert_eq!(g.const_value(five), Some(5.0));
        let one = g.constant(1.0);
        assert_eq!(g.add(Node::Mul(x, one)), x);
        let zero = g.constant(0.0);
        // x * 0 folds: variables are finite by assumption.
        assert_eq!(g.const_value(g.clone().add(Node::Mul(x, zero))), Some(0.0));
        // (1/x) * 0 does not: 1/x may be infinite.
        let inv = g.add(Node::Div(one, x));
        let m = g.add(Node::Mul(inv, zero));
        assert!(matches!(g.node(m), Node::Mul(..)));
        // x / x is not folded (0/0).
        let xx = g.add(Node::Div(x, x));
        assert!(matches!(g.node(xx), Node::Div(..)));
        let nx = g.add(Node::Neg(x));
        assert_eq!(g.add(Node::Neg(nx)), x);
        let s = g.add(Node::Sin(x));
        let c = g.add(Node::Clamp(s));
        assert_eq!(c, s, "sin is within [-1, 1]");
        let half = g.constant(0.5);
        let d = g.add(Node::Div(x, half));
        assert!(matches!(g.node(d), Node::Mul(..)));
    }

    #[test]
    fn max0_under_a_square_root_is_known_finite() {
        use Node::*;
        let mut g = ExprGraph::new();
        let (x, y) = (g.var(0), g.var(1));
        let s = g.add(Sin(x));
        let p = g.add(Mul(s, y));
        // max0(p) as the kinematics writes it: (p + p·sgn p) · 0.5.
        let sg = g.add(Sgn(p));
        let abs = g.add(Mul(p, sg));
        assert!(g.range(abs).finite && g.range(abs).lo == 0.0);
        let sum = g.add(Add(p, abs));
        let half = g.constant(0.5);
        let m = g.add(Mul(sum, half));
        assert!(g.range(m).finite && g.range(m).lo == 0.0);
        let r = g.add(Sqrt(m));
        assert!(g.range(r).finite, "sqrt(max0(·)) is never NaN");
        let t = g.add(Atan2(r, x));
        assert!(g.range(t).finite);
        let zero = g.constant(0.0);
        assert_eq!(g.const_value(g.clone().add(Mul(zero, t))), Some(0.0));
        assert_eq!(g.const_value(g.clone().add(Sub(t, t))), Some(0.0));
        // The graph computes what f64 does, on both sides of zero.
        for (a, b) in [(0.7f64, 2.0), (0.7, -2.0), (-0.3, 5.0), (0.0, 1.0)] {
            let pv = a.sin() * b;
            let want = (pv + pv * crate::kinematics::sgn_f64(pv)) * 0.5;
            let got = g.eval(&[m], &[a, b], &[])[0];
            assert!((got - want).abs() <= 1e-15, "{got} {want}");
        }
        // The relation needs the same operand: p + p·sgn q may be negative.
        let q = g.add(Sin(y));
        let sq = g.add(Sgn(q));
        let other = g.add(Mul(p, sq));
        let sum2 = g.add(Add(p, other));
        let r2 = g.add(Sqrt(sum2));
        assert!(!g.range(r2).finite);
        let kept = g.add(Mul(zero, r2));
        assert!(matches!(g.node(kept), Mul(..)));
    }

    #[test]
    fn reachable_counts() {
        let mut g = ExprGraph::new();
        let x = g.var(0);
        let s = g.add(Node::Sin(x));
        let c = g.add(Node::Cos(x));
        let p = g.add(Node::Mul(s, c));
        let _unused = g.add(Node::Sqrt(x));
        let counts = g.counts(&[p]);
        assert_eq!(
            counts,
            Counts {
                nodes: 4,
                ops: 3,
                calls: 2
            }
        );
    }
}
