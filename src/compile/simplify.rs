//! Equality saturation with egg, and an extraction that costs the shared DAG.
//!
//! Pipeline: the reachable part of an [`ExprGraph`] goes into an e-graph of [`Math`]
//! (one e-node per DAG node); the rules below run under iteration, node and time limits;
//! a greedy DAG-aware extraction picks one node per e-class; the result is rebuilt
//! through [`ExprGraph::add`] (which folds again, with exact range checks). If the result
//! would cost more than the input by [`op_cost`], the input is kept.
//!
//! **Values.** Every rule is an identity of real numbers that also holds for the f64
//! values the kinematics produces, up to rounding, and never turns a finite value into
//! NaN or an infinity:
//! - `cos(acos x) → clamp(x)`: the clamp keeps the acos's domain (no assumption that
//!   `|x| ≤ 1`); `sin(acos x) → sqrt((1 - c)(1 + c))`, `c = clamp(x)`: never the square
//!   root of a negative number, and `1 - c` is exact near `c = 1` (no cancellation);
//! - `x - x → 0`, `x * 0 → 0`, `sin²x + cos²x → 1` only where the range analysis proves
//!   `x` finite; `x / x → 1` only where it also proves `x ≠ 0`;
//! - cancellation across a sum, `a + (b - a) → b`, `(a + b) - a → b`, `a - (a - b) → b`,
//!   again only where `a` is proven finite (`inf + (b - inf)` is NaN); the result is the
//!   exact value of the rounded original (never less accurate);
//! - `(-a) - b → -(a + b)` is exact (rounding is symmetric), so `-(-a - b)` becomes
//!   `a + b`;
//! - `(x + x·sgn x)/2 → select(x, x, 0)` (that is `max(0, x)`, how the kinematics
//!   writes it): exact for finite `x` (`2x/2 = x`, `x - x = 0`), so again only where `x`
//!   is proven finite;
//! - clamps are removed only at the rebuild, by the exact range check of
//!   [`ExprGraph::add`] (e-class ranges merge forms that differ by rounding, so they are
//!   not trusted for that);
//! - factoring `a·b ± a·c → a·(b ± c)` and `b/a ± c/a → (b ± c)/a` reduce operations and
//!   change results only by rounding;
//! - after the extraction, [`vanish`](super::vanish) removes the zero terms (`0·x`,
//!   `x - x`) whose `x` is not provably finite but whose NaN a sibling term carries
//!   anyway: values unchanged, NaN included.
//!
//! Rounding differences are amplified where an `acos` argument is within rounding of
//! ±1 (a vertex at the edge of its rigid range, or flat): there the simplified and the
//! original graphs agree to `~sqrt(ε)` rather than `ε`. Everywhere else the randomized
//! tests hold them to 1e-12 relative.
//!
//! **Determinism.** With the default limits the run stops on the iteration or node limit;
//! the time limit is a safety net and, if it is hit, makes the result timing-dependent
//! (the report says so).

use crate::expr::{ExprGraph, Node, NodeId, Range};
use egg::{
    Analysis, CostFunction, DidMerge, EGraph, Extractor, Id, Language, Rewrite, Runner, Subst,
    rewrite as rw,
};
use std::fmt;
use std::str::FromStr;
use std::time::{Duration, Instant};

/// An f64 constant as an egg leaf: ordered and hashed by its bits.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Debug)]
pub struct Num(u64);

impl Num {
    /// The value.
    pub fn value(self) -> f64 {
        f64::from_bits(self.0)
    }
    /// Wrap a value.
    pub fn new(v: f64) -> Num {
        Num(v.to_bits())
    }
}

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}", self.value())
    }
}

impl FromStr for Num {
    type Err = std::num::ParseFloatError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        s.parse::<f64>().map(Num::new)
    }
}

/// A variable index as an egg leaf (`x3`).
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Debug)]
pub struct VarIx(pub u32);

impl fmt::Display for VarIx {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "x{}", self.0)
    }
}

impl FromStr for VarIx {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        s.strip_prefix('x')
            .and_then(|d| d.parse().ok())
            .map(VarIx)
            .ok_or_else(|| format!("not a variable: {s}"))
    }
}

/// A parameter index as an egg leaf (`p3`).
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Debug)]
pub struct ParamIx(pub u32);

impl fmt::Display for ParamIx {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "p{}", self.0)
    }
}

impl FromStr for ParamIx {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        s.strip_prefix('p')
            .and_then(|d| d.parse().ok())
            .map(ParamIx)
            .ok_or_else(|| format!("not a parameter: {s}"))
    }
}

mod lang {
    // egg's macro cannot carry per-variant docs; the variants mirror `Node` one to one.
    #![allow(missing_docs)]
    use super::{Num, ParamIx, VarIx};
    use egg::{Id, define_language};

    define_language! {
        /// The egg mirror of [`Node`].
        pub enum Math {
            "+" = Add([Id; 2]),
            "-" = Sub([Id; 2]),
            "*" = Mul([Id; 2]),
            "/" = Div([Id; 2]),
            "neg" = Neg(Id),
            "sin" = Sin(Id),
            "cos" = Cos(Id),
            "acos" = Acos(Id),
            "sqrt" = Sqrt(Id),
            "atan2" = Atan2([Id; 2]),
            "sgn" = Sgn(Id),
            "clamp" = Clamp(Id),
            "select" = Select([Id; 3]),
            Num(Num),
            Var(VarIx),
            Param(ParamIx),
        }
    }
}
pub use lang::Math;

impl Math {
    /// The node kind with placeholder children (for the shared semantics and ranges).
    fn kind(&self) -> Node {
        let z = NodeId(0);
        match self {
            Math::Add(_) => Node::Add(z, z),
            Math::Sub(_) => Node::Sub(z, z),
            Math::Mul(_) => Node::Mul(z, z),
            Math::Div(_) => Node::Div(z, z),
            Math::Neg(_) => Node::Neg(z),
            Math::Sin(_) => Node::Sin(z),
            Math::Cos(_) => Node::Cos(z),
            Math::Acos(_) => Node::Acos(z),
            Math::Sqrt(_) => Node::Sqrt(z),
            Math::Atan2(_) => Node::Atan2(z, z),
            Math::Sgn(_) => Node::Sgn(z),
            Math::Clamp(_) => Node::Clamp(z),
            Math::Select(_) => Node::Select(z, z, z),
            Math::Num(n) => Node::Const(n.value()),
            Math::Var(v) => Node::Var(v.0),
            Math::Param(p) => Node::Param(p.0),
        }
    }

    fn from_node(node: &Node, id: impl Fn(NodeId) -> Id) -> Math {
        match *node {
            Node::Const(c) => Math::Num(Num::new(c)),
            Node::Var(i) => Math::Var(VarIx(i)),
            Node::Param(i) => Math::Param(ParamIx(i)),
            Node::Add(a, b) => Math::Add([id(a), id(b)]),
            Node::Sub(a, b) => Math::Sub([id(a), id(b)]),
            Node::Mul(a, b) => Math::Mul([id(a), id(b)]),
            Node::Div(a, b) => Math::Div([id(a), id(b)]),
            Node::Atan2(a, b) => Math::Atan2([id(a), id(b)]),
            Node::Neg(a) => Math::Neg(id(a)),
            Node::Sin(a) => Math::Sin(id(a)),
            Node::Cos(a) => Math::Cos(id(a)),
            Node::Acos(a) => Math::Acos(id(a)),
            Node::Sqrt(a) => Math::Sqrt(id(a)),
            Node::Sgn(a) => Math::Sgn(id(a)),
            Node::Clamp(a) => Math::Clamp(id(a)),
            Node::Select(a, b, c) => Math::Select([id(a), id(b), id(c)]),
        }
    }

    fn to_node(&self, id: impl Fn(Id) -> NodeId) -> Node {
        let k = self.kind();
        let ch = self.children();
        k.map_children({
            let mut i = 0;
            move |_| {
                let r = id(ch[i]);
                i += 1;
                r
            }
        })
    }
}

/// Per-e-class facts: the constant value (if folded) and the range.
#[derive(Clone, Copy, Debug)]
pub struct Data {
    konst: Option<Num>,
    range: Range,
}

/// Constant folding (with the interpreter's semantics) and range analysis.
#[derive(Default)]
pub struct Facts;

type EG = EGraph<Math, Facts>;

impl Analysis<Math> for Facts {
    type Data = Data;

    fn make(egraph: &mut EG, enode: &Math, _id: Id) -> Data {
        let kind = enode.kind();
        let ch = enode.children();
        let ranges: Vec<Range> = ch.iter().map(|c| egraph[*c].data.range).collect();
        let konst = if let Math::Num(n) = enode {
            Some(*n)
        } else if !ch.is_empty() && ch.iter().all(|c| egraph[*c].data.konst.is_some()) {
            let args: Vec<f64> = ch
                .iter()
                .map(|c| egraph[*c].data.konst.map_or(0.0, Num::value))
                .collect();
            Some(Num::new(kind.eval_with(&args, &[], &[])))
        } else {
            None
        };
        let range = match (konst, enode) {
            (Some(k), _) => Range::constant(k.value()),
            (None, Math::Select([c, a, _])) if egraph.find(*c) == egraph.find(*a) => {
                Range::select_positive(&ranges[0], &ranges[2])
            }
            (None, Math::Mul([a, b])) if egraph.find(*a) == egraph.find(*b) => {
                Range::square(&ranges[0])
            }
            // x·sgn x = |x| and x + x·sgn x ≥ 0, as in `ExprGraph`'s analysis.
            (None, Math::Mul([a, b])) if sgn_of(egraph, *b, *a) => Range::abs(&ranges[0]),
            (None, Math::Mul([a, b])) if sgn_of(egraph, *a, *b) => Range::abs(&ranges[1]),
            (None, Math::Add([a, b])) if abs_of(egraph, *b, *a) => Range::plus_abs(&ranges[0]),
            (None, Math::Add([a, b])) if abs_of(egraph, *a, *b) => Range::plus_abs(&ranges[1]),
            (None, _) => Range::of(&kind, &ranges),
        };
        Data { konst, range }
    }

    fn merge(&mut self, a: &mut Data, b: Data) -> DidMerge {
        let (mut ca, mut cb) = (false, false);
        match (a.konst, b.konst) {
            (None, Some(k)) => {
                a.konst = Some(k);
                ca = true;
            }
            (Some(_), None) => cb = true,
            // Equal up to rounding: keep the first.
            (Some(x), Some(y)) if x != y => cb = true,
            _ => {}
        }
        let r = a.range.intersect(&b.range);
        if r != a.range {
            ca = true;
        }
        if r != b.range {
            cb = true;
        }
        a.range = r;
        DidMerge(ca, cb)
    }

    fn modify(egraph: &mut EG, id: Id) {
        if let Some(k) = egraph[id].data.konst {
            let c = egraph.add(Math::Num(k));
            egraph.union(id, c);
            // A constant class needs nothing else.
            egraph[id].nodes.retain(|n| n.is_leaf());
        }
    }
}

/// Whether class `s` holds `sgn(x)`.
fn sgn_of(eg: &EG, s: Id, x: Id) -> bool {
    let x = eg.find(x);
    eg[s]
        .nodes
        .iter()
        .any(|n| matches!(n, Math::Sgn(c) if eg.find(*c) == x))
}

/// Whether class `m` holds `x · sgn(x)` (either operand order).
fn abs_of(eg: &EG, m: Id, x: Id) -> bool {
    let x = eg.find(x);
    eg[m].nodes.iter().any(|n| match n {
        Math::Mul([a, b]) => {
            let (a, b) = (eg.find(*a), eg.find(*b));
            (a == x && sgn_of(eg, b, x)) || (b == x && sgn_of(eg, a, x))
        }
        _ => false,
    })
}

fn var(s: &str) -> egg::Var {
    s.parse().expect("valid pattern variable")
}

fn is_finite(v: &str) -> impl Fn(&mut EG, Id, &Subst) -> bool + use<> {
    let v = var(v);
    move |eg, _, s| eg[s[v]].data.range.finite
}

fn is_nonzero(v: &str) -> impl Fn(&mut EG, Id, &Subst) -> bool + use<> {
    let v = var(v);
    move |eg, _, s| {
        let r = eg[s[v]].data.range;
        // A margin well above rounding, since the class's forms differ by rounding.
        let m = 1e-9 * r.lo.abs().max(r.hi.abs());
        r.bounded() && (r.lo > m || r.hi < -m)
    }
}

fn is_const(v: &str) -> impl Fn(&mut EG, Id, &Subst) -> bool + use<> {
    let v = var(v);
    move |eg, _, s| eg[s[v]].data.konst.is_some()
}

/// The rewrite rules (see the module documentation for why each preserves values).
pub fn rules() -> Vec<Rewrite<Math, Facts>> {
    vec![
        // The PTU's identities.
        rw!("cos-acos"; "(cos (acos ?x))" => "(clamp ?x)"),
        rw!("sin-acos"; "(sin (acos ?x))" => "(sqrt (* (- 1.0 (clamp ?x)) (+ 1.0 (clamp ?x))))"),
        rw!("acos-clamp"; "(acos (clamp ?x))" => "(acos ?x)"),
        rw!("clamp-clamp"; "(clamp (clamp ?x))" => "(clamp ?x)"),
        rw!("clamp-cos"; "(clamp (cos ?x))" => "(cos ?x)"),
        rw!("clamp-sin"; "(clamp (sin ?x))" => "(sin ?x)"),
        rw!("sin-neg"; "(sin (neg ?x))" => "(neg (sin ?x))"),
        rw!("cos-neg"; "(cos (neg ?x))" => "(cos ?x)"),
        rw!("pythagoras"; "(+ (* (sin ?x) (sin ?x)) (* (cos ?x) (cos ?x)))" => "1.0"
            if is_finite("?x")),
        // max(0, x) written with sgn (kinematics' `Scalar::max0`): one compare-select.
        rw!("max0"; "(* 0.5 (+ ?x (* ?x (sgn ?x))))" => "(select ?x ?x 0.0)"
            if is_finite("?x")),
        rw!("sgn-sgn"; "(sgn (sgn ?x))" => "(sgn ?x)"),
        rw!("sgn-neg"; "(sgn (neg ?x))" => "(neg (sgn ?x))"),
        // Signs.
        rw!("neg-neg"; "(neg (neg ?x))" => "?x"),
        rw!("add-neg"; "(+ ?a (neg ?b))" => "(- ?a ?b)"),
        rw!("sub-neg"; "(- ?a (neg ?b))" => "(+ ?a ?b)"),
        rw!("neg-sub"; "(neg (- ?a ?b))" => "(- ?b ?a)"),
        rw!("mul-neg"; "(* ?a (neg ?b))" => "(neg (* ?a ?b))"),
        rw!("div-neg-l"; "(/ (neg ?a) ?b)" => "(neg (/ ?a ?b))"),
        rw!("div-neg-r"; "(/ ?a (neg ?b))" => "(neg (/ ?a ?b))"),
        rw!("sub-neg-l"; "(- (neg ?a) ?b)" => "(neg (+ ?a ?b))"),
        // Units and cancellation.
        rw!("add-0"; "(+ ?a 0.0)" => "?a"),
        rw!("mul-1"; "(* ?a 1.0)" => "?a"),
        rw!("mul-0"; "(* ?a 0.0)" => "0.0" if is_finite("?a")),
        rw!("sub-self"; "(- ?a ?a)" => "0.0" if is_finite("?a")),
        rw!("div-self"; "(/ ?a ?a)" => "1.0" if is_nonzero("?a")),
        rw!("add-sub-cancel"; "(+ ?a (- ?b ?a))" => "?b" if is_finite("?a")),
        rw!("sub-add-cancel"; "(- (+ ?a ?b) ?a)" => "?b" if is_finite("?a")),
        rw!("sub-sub-cancel"; "(- ?a (- ?a ?b))" => "?b" if is_finite("?a")),
        // Commutativity (needed to find common factors); no general associativity,
        // which blows the e-graph up without shrinking the PTU's expressions.
        rw!("comm-add"; "(+ ?a ?b)" => "(+ ?b ?a)"),
        rw!("comm-mul"; "(* ?a ?b)" => "(* ?b ?a)"),
        rw!("const-mul"; "(* ?c (* ?d ?x))" => "(* (* ?c ?d) ?x)"
            if is_const("?c") if is_const("?d")),
        rw!("const-add"; "(+ ?c (+ ?d ?x))" => "(+ (+ ?c ?d) ?x)"
            if is_const("?c") if is_const("?d")),
        // Factoring: one multiplication (division) fewer.
        rw!("factor-add"; "(+ (* ?a ?b) (* ?a ?c))" => "(* ?a (+ ?b ?c))"),
        rw!("factor-sub"; "(- (* ?a ?b) (* ?a ?c))" => "(* ?a (- ?b ?c))"),
        rw!("factor-div-add"; "(+ (/ ?b ?a) (/ ?c ?a))" => "(/ (+ ?b ?c) ?a)"),
        rw!("factor-div-sub"; "(- (/ ?b ?a) (/ ?c ?a))" => "(/ (- ?b ?c) ?a)"),
        rw!("select-same"; "(select ?c ?a ?a)" => "?a"),
    ]
}

/// Approximate cost of one operation in cycles (calls dominate).
pub fn op_cost(node: &Node) -> f64 {
    match node {
        Node::Const(_) | Node::Var(_) | Node::Param(_) => 0.0,
        Node::Neg(_) => 0.5,
        Node::Add(..) | Node::Sub(..) | Node::Mul(..) => 1.0,
        Node::Clamp(_) | Node::Sgn(_) | Node::Select(..) => 2.0,
        Node::Div(..) => 4.0,
        Node::Sqrt(_) => 6.0,
        Node::Sin(_) | Node::Cos(_) => 20.0,
        Node::Acos(_) => 25.0,
        Node::Atan2(..) => 30.0,
    }
}

/// The cost of the DAG reachable from `outputs` (each shared node counted once).
pub fn dag_cost(graph: &ExprGraph, outputs: &[NodeId]) -> f64 {
    let mark = graph.reachable(outputs);
    graph
        .nodes()
        .iter()
        .zip(&mark)
        .filter(|(_, m)| **m)
        .map(|(n, _)| op_cost(n))
        .sum()
}

/// Limits of one simplification run.
#[derive(Clone, Debug)]
pub struct Limits {
    /// Rule-application iterations. Default 4: on the robotic arm's model
    /// `2, 4, 6, (3, 9), (6, 10)` four give the same 4,130 operations as eight in 16 ms
    /// of egg instead of 28 (`bench model`, one sitting); the gripper's search at N_max = 3
    /// gives the same records bit for bit, the arm's compile stage 8.7 → 7.6 CPU s with
    /// 105 designs instead of 103 (its seed spread is 103–113; 6 Dec 2026).
    pub iterations: usize,
    /// E-graph size limit in e-nodes, as a multiple of the input's node count.
    pub node_factor: usize,
    /// Absolute minimum of the node limit.
    pub min_nodes: usize,
    /// Wall-clock safety limit.
    pub time: Duration,
    /// Above this many e-classes the DAG-aware extraction (quadratic memory) gives way
    /// to egg's tree-cost extraction.
    pub dag_extract_max_classes: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            iterations: 4,
            node_factor: 6,
            min_nodes: 5_000,
            time: Duration::from_secs(2),
            dag_extract_max_classes: 20_000,
        }
    }
}

/// What a simplification run did.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Report {
    /// Operations reachable from the outputs before.
    pub ops_before: usize,
    /// Operations after.
    pub ops_after: usize,
    /// Transcendental calls before.
    pub calls_before: usize,
    /// Transcendental calls after.
    pub calls_after: usize,
    /// [`dag_cost`] before.
    pub cost_before: f64,
    /// [`dag_cost`] after.
    pub cost_after: f64,
    /// E-graph size at the end (e-nodes).
    pub egraph_nodes: usize,
    /// E-classes at the end.
    pub egraph_classes: usize,
    /// Iterations run.
    pub iterations: usize,
    /// Why the runner stopped.
    pub stop_reason: String,
    /// Which extraction produced the result ("dag", "tree" or "input" when the input
    /// was kept).
    pub extraction: &'static str,
    /// How often each rule was newly applied in the e-graph, summed over the iterations
    /// (rules that never fired are left out; commutativity is counted like the others).
    /// Applications are unions in the e-graph, not what the extraction kept.
    pub rules_fired: Vec<(String, usize)>,
    /// Terms removed after the extraction because they vanish wherever the formula has a
    /// value ([`vanish`](super::vanish): `a + 0·x → a` where `a` carries `x`'s NaN).
    pub vanishing_terms: usize,
    /// Wall-clock time of the whole call.
    pub millis: f64,
}

/// A simplified copy of `outputs` of `graph`: the new graph, the outputs' ids in it, and
/// the report.
pub fn simplify(
    graph: &ExprGraph,
    outputs: &[NodeId],
    limits: &Limits,
) -> (ExprGraph, Vec<NodeId>, Report) {
    let t0 = Instant::now();
    let before = graph.counts(outputs);
    let cost_before = dag_cost(graph, outputs);
    let mark = graph.reachable(outputs);

    let mut eg: EG = EGraph::new(Facts);
    let mut ids = vec![Id::from(0usize); graph.len()];
    let mut n_input = 0;
    for (i, node) in graph.nodes().iter().enumerate() {
        if mark[i] {
            ids[i] = eg.add(Math::from_node(node, |c| ids[c.index()]));
            n_input += 1;
        }
    }
    let roots: Vec<Id> = outputs.iter().map(|o| ids[o.index()]).collect();
    let runner = Runner::default()
        .with_egraph(eg)
        .with_iter_limit(limits.iterations)
        .with_node_limit((n_input * limits.node_factor).max(limits.min_nodes))
        .with_time_limit(limits.time)
        .run(&rules());
    let eg = runner.egraph;
    let roots: Vec<Id> = roots.iter().map(|r| eg.find(*r)).collect();

    let mut extraction = "dag";
    let mut result = if eg.number_of_classes() <= limits.dag_extract_max_classes {
        dag_extract(&eg, &roots)
    } else {
        None
    };
    if result.is_none() {
        extraction = "tree";
        result = tree_extract(&eg, &roots);
    }
    let (mut g, mut outs) = match result {
        Some((g, o)) => (g, o),
        None => {
            extraction = "input";
            graph.extract(outputs)
        }
    };
    if dag_cost(&g, &outs) > cost_before {
        extraction = "input";
        (g, outs) = graph.extract(outputs);
    }
    // Zero terms egg may not fold (their x is not provably finite) but whose NaN a
    // sibling carries anyway (see `vanish`); it only removes operations.
    let (g, outs, vanishing_terms) = super::vanish::fold_vanishing(&g, &outs);
    let cost_after = dag_cost(&g, &outs);
    let after = g.counts(&outs);
    let mut fired: Vec<(String, usize)> = Vec::new();
    for it in &runner.iterations {
        for (rule, n) in &it.applied {
            match fired.iter_mut().find(|(r, _)| r == rule.as_str()) {
                Some((_, m)) => *m += n,
                None => fired.push((rule.to_string(), *n)),
            }
        }
    }
    fired.retain(|(_, n)| *n > 0);
    let report = Report {
        ops_before: before.ops,
        ops_after: after.ops,
        calls_before: before.calls,
        calls_after: after.calls,
        cost_before,
        cost_after,
        egraph_nodes: eg.total_number_of_nodes(),
        egraph_classes: eg.number_of_classes(),
        iterations: runner.iterations.len(),
        stop_reason: runner
            .stop_reason
            .as_ref()
            .map_or_else(|| "none".to_string(), |r| format!("{r:?}")),
        extraction,
        rules_fired: fired,
        vanishing_terms,
        millis: t0.elapsed().as_secs_f64() * 1e3,
    };
    (g, outs, report)
}

/// Rebuild the choice `best[class] = node` from `roots` into an [`ExprGraph`] (iterative
/// post-order; `None` if the choice is cyclic or incomplete).
fn rebuild(
    eg: &EG,
    roots: &[Id],
    best: impl Fn(Id) -> Option<Math>,
) -> Option<(ExprGraph, Vec<NodeId>)> {
    let n = eg
        .classes()
        .map(|c| usize::from(c.id))
        .max()
        .map_or(0, |m| m + 1);
    // 0 = unvisited, 1 = on the stack, 2 = done.
    let mut state = vec![0u8; n];
    let mut done: Vec<NodeId> = vec![NodeId(0); n];
    let mut chosen: Vec<Option<Math>> = vec![None; n];
    let mut g = ExprGraph::new();
    for &root in roots {
        let mut stack: Vec<(Id, bool)> = vec![(root, false)];
        while let Some((c, expanded)) = stack.pop() {
            let ci = usize::from(c);
            if expanded {
                let node = chosen[ci].as_ref()?;
                let dag = node.to_node(|k| done[usize::from(eg.find(k))]);
                done[ci] = g.add(dag);
                state[ci] = 2;
                continue;
            }
            match state[ci] {
                2 => continue,
                1 => return None, // cycle
                _ => {}
            }
            state[ci] = 1;
            let node = best(c)?;
            stack.push((c, true));
            for &k in node.children() {
                let k = eg.find(k);
                match state[usize::from(k)] {
                    2 => {}
                    1 => return None,
                    _ => stack.push((k, false)),
                }
            }
            chosen[ci] = Some(node);
        }
    }
    let outs = roots.iter().map(|r| done[usize::from(*r)]).collect();
    Some((g, outs))
}

struct F64Cost;

impl CostFunction<Math> for F64Cost {
    type Cost = f64;
    fn cost<C>(&mut self, enode: &Math, mut costs: C) -> f64
    where
        C: FnMut(Id) -> f64,
    {
        enode.fold(op_cost(&enode.kind()), |s, c| s + costs(c))
    }
}

fn tree_extract(eg: &EG, roots: &[Id]) -> Option<(ExprGraph, Vec<NodeId>)> {
    let ex = Extractor::new(eg, F64Cost);
    rebuild(eg, roots, |c| Some(ex.find_best_node(c).clone()))
}

/// Greedy DAG-aware extraction: each e-class's cost is the summed operation cost of the
/// *set* of classes its best node needs (shared classes counted once), kept as a bitset.
/// A node whose set would contain its own class is skipped (no cycles).
fn dag_extract(eg: &EG, roots: &[Id]) -> Option<(ExprGraph, Vec<NodeId>)> {
    let classes: Vec<Id> = eg.classes().map(|c| c.id).collect();
    let n_ids = classes
        .iter()
        .map(|c| usize::from(*c))
        .max()
        .map_or(0, |m| m + 1);
    let mut dense = vec![usize::MAX; n_ids];
    for (k, c) in classes.iter().enumerate() {
        dense[usize::from(*c)] = k;
    }
    let n = classes.len();
    let words = n.div_ceil(64);
    // Per class: chosen node index, its op cost, the set's total, the set (incl. itself).
    let mut choice: Vec<Option<usize>> = vec![None; n];
    let mut own: Vec<f64> = vec![0.0; n];
    let mut total: Vec<f64> = vec![f64::INFINITY; n];
    let mut sets: Vec<u64> = vec![0; n * words];
    // Parents: which classes to revisit when a class improves.
    let mut parents: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (k, c) in classes.iter().enumerate() {
        for node in &eg[*c].nodes {
            for ch in node.children() {
                parents[dense[usize::from(eg.find(*ch))]].push(k);
            }
        }
    }
    for p in &mut parents {
        p.sort_unstable();
        p.dedup();
    }
    let mut queued = vec![true; n];
    let mut work: std::collections::VecDeque<usize> = (0..n).collect();
    let mut scratch = vec![0u64; words];
    let mut budget = 50 * n + 1000;
    while let Some(k) = work.pop_front() {
        queued[k] = false;
        if budget == 0 {
            break;
        }
        budget -= 1;
        let class = &eg[classes[k]];
        let mut best: Option<(f64, usize)> = None;
        let mut best_set: Option<Vec<u64>> = None;
        for (ni, node) in class.nodes.iter().enumerate() {
            let ch: Vec<usize> = node
                .children()
                .iter()
                .map(|c| dense[usize::from(eg.find(*c))])
                .collect();
            if ch.iter().any(|&c| choice[c].is_none()) {
                continue;
            }
            // Start from the child with the largest total, add what the others bring.
            scratch.iter_mut().for_each(|w| *w = 0);
            let mut cost = op_cost(&node.kind());
            if let Some(&base) = ch.iter().max_by(|a, b| total[**a].total_cmp(&total[**b])) {
                scratch.copy_from_slice(&sets[base * words..(base + 1) * words]);
                cost += total[base];
                for &c in &ch {
                    if c == base {
                        continue;
                    }
                    for w in 0..words {
                        let mut new = sets[c * words + w] & !scratch[w];
                        scratch[w] |= new;
                        while new != 0 {
                            let b = new.trailing_zeros() as usize;
                            cost += own[w * 64 + b];
                            new &= new - 1;
                        }
                    }
                }
            }
            if scratch[k / 64] & (1 << (k % 64)) != 0 {
                continue; // would depend on itself
            }
            if best.is_none_or(|(bc, _)| cost < bc) {
                best = Some((cost, ni));
                scratch[k / 64] |= 1 << (k % 64);
                best_set = Some(scratch.clone());
                scratch[k / 64] &= !(1 << (k % 64));
            }
        }
        if let (Some((cost, ni)), Some(set)) = (best, best_set)
            && cost < total[k]
        {
            choice[k] = Some(ni);
            own[k] = op_cost(&class.nodes[ni].kind());
            total[k] = cost;
            sets[k * words..(k + 1) * words].copy_from_slice(&set);
            for &p in &parents[k] {
                if !queued[p] {
                    queued[p] = true;
                    work.push_back(p);
                }
            }
        }
    }
    rebuild(eg, roots, |c| {
        let k = dense[usize::from(eg.find(c))];
        choice[k].map(|ni| eg[classes[k]].nodes[ni].clone())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::{Ctx, Tape};
    use crate::kinematics::Scalar;

    #[test]
    fn ptu_identities_remove_calls() {
        let ctx = Ctx::new();
        let x = ctx.var(0);
        let y = ctx.var(1);
        let u = (x.cos() * y.sin()).acos();
        // cos U and sin U of a unit angle, as the spherical law of cosines uses them.
        let f = (u.cos() - y.cos()) / (u.sin() * x.sin());
        let id = ctx.node_id(&f);
        let g = ctx.to_graph();
        let (s, outs, rep) = simplify(&g, &[id], &Limits::default());
        assert!(rep.calls_after < rep.calls_before, "{rep:?}");
        // cos x, sin y, cos y, sin x remain; the acos and its cos and sin are gone.
        assert_eq!(s.counts(&outs).calls, 4, "{rep:?}");
        let t1 = Tape::new(&g, &[id], 2, 0).unwrap();
        let t2 = Tape::new(&s, &outs, 2, 0).unwrap();
        for &(a, b) in &[(0.3, 0.8), (1.2, 2.0), (-0.4, 0.1)] {
            let (mut r1, mut r2) = ([0.0], [0.0]);
            t1.eval(&[a, b], &[], &mut r1).unwrap();
            t2.eval(&[a, b], &[], &mut r2).unwrap();
            assert!(
                (r1[0] - r2[0]).abs() <= 1e-12 * r1[0].abs().max(1.0),
                "{r1:?} {r2:?}"
            );
        }
    }
}

#[cfg(test)]
mod max0_tests {
    use super::*;
    use crate::expr::Ctx;
    use crate::kinematics::Scalar;

    #[test]
    fn max0_becomes_select() {
        let ctx = Ctx::new();
        let x = ctx.var(0).sin() * ctx.var(1);
        let y = x.max0();
        let id = ctx.node_id(&y);
        let g = ctx.to_graph();
        let (s, outs, _) = simplify(&g, &[id], &Limits::default());
        assert!(
            matches!(s.node(outs[0]), Node::Select(..)),
            "{:?}",
            s.nodes()
        );
    }
}
