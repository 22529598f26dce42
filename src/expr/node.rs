//! Node kinds, their f64 semantics and a conservative range analysis.

use crate::kinematics::{acos_clamped, sgn_f64};
use crate::trig;
use std::hash::{Hash, Hasher};

/// Index of a node in an [`ExprGraph`](super::ExprGraph) arena.
///
/// Children always have smaller ids than their parents, so increasing id order is a
/// topological order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(pub(crate) u32);

impl NodeId {
    /// The position in the arena.
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// One node of the expression DAG.
///
/// `Acos` clamps its argument to `[-1, 1]` (as [`acos_clamped`]); `Clamp` is that clamp on
/// its own (it appears when the simplifier rewrites `cos(acos x)`); `Select(c, a, b)` is
/// `a` where `c > 0` and `b` otherwise (NaN selects `b`): the differentiator uses it to
/// guard derivatives that would otherwise be infinite or NaN.
#[derive(Clone, Copy, Debug)]
pub enum Node {
    /// A constant.
    Const(f64),
    /// Optimization unknown number `i` (differentiated).
    Var(u32),
    /// Parameter number `i`: t, modes, task data (not differentiated).
    Param(u32),
    /// `a + b`.
    Add(NodeId, NodeId),
    /// `a - b`.
    Sub(NodeId, NodeId),
    /// `a * b`.
    Mul(NodeId, NodeId),
    /// `a / b`.
    Div(NodeId, NodeId),
    /// `-a`.
    Neg(NodeId),
    /// `sin a`.
    Sin(NodeId),
    /// `cos a`.
    Cos(NodeId),
    /// `acos(clamp(a, -1, 1))`.
    Acos(NodeId),
    /// `sqrt a`.
    Sqrt(NodeId),
    /// `atan2(y, x)`.
    Atan2(NodeId, NodeId),
    /// Sign: -1, 0, +1 (NaN gives 0).
    Sgn(NodeId),
    /// `clamp(a, -1, 1)` (NaN stays NaN).
    Clamp(NodeId),
    /// `if c > 0 { a } else { b }`.
    Select(NodeId, NodeId, NodeId),
}

impl PartialEq for Node {
    fn eq(&self, other: &Self) -> bool {
        use Node::*;
        match (self, other) {
            // Bitwise, so that -0.0 and 0.0 stay distinct and NaN equals itself.
            (Const(a), Const(b)) => a.to_bits() == b.to_bits(),
            (Var(a), Var(b)) | (Param(a), Param(b)) => a == b,
            (Add(a, b), Add(c, d))
            | (Sub(a, b), Sub(c, d))
            | (Mul(a, b), Mul(c, d))
            | (Div(a, b), Div(c, d))
            | (Atan2(a, b), Atan2(c, d)) => a == c && b == d,
            (Neg(a), Neg(b))
            | (Sin(a), Sin(b))
            | (Cos(a), Cos(b))
            | (Acos(a), Acos(b))
            | (Sqrt(a), Sqrt(b))
            | (Sgn(a), Sgn(b))
            | (Clamp(a), Clamp(b)) => a == b,
            (Select(a, b, c), Select(d, e, f)) => a == d && b == e && c == f,
            _ => false,
        }
    }
}

impl Eq for Node {}

impl Hash for Node {
    fn hash<H: Hasher>(&self, state: &mut H) {
        std::mem::discriminant(self).hash(state);
        match *self {
            Node::Const(c) => c.to_bits().hash(state),
            Node::Var(i) | Node::Param(i) => i.hash(state),
            _ => {
                for c in self.children() {
                    c.0.hash(state);
                }
            }
        }
    }
}

/// The children of a node (at most three), in operand order.
#[derive(Clone, Copy, Debug)]
pub struct Children {
    ids: [NodeId; 3],
    len: u8,
}

impl Children {
    /// Number of children.
    pub fn len(&self) -> usize {
        self.len as usize
    }
    /// Whether the node is a leaf.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// The children as a slice.
    pub fn as_slice(&self) -> &[NodeId] {
        &self.ids[..self.len as usize]
    }
}

impl IntoIterator for Children {
    type Item = NodeId;
    type IntoIter = std::iter::Take<std::array::IntoIter<NodeId, 3>>;
    fn into_iter(self) -> Self::IntoIter {
        self.ids.into_iter().take(self.len as usize)
    }
}

impl Node {
    /// The children in operand order.
    pub fn children(&self) -> Children {
        use Node::*;
        let z = NodeId(0);
        let (ids, len) = match *self {
            Const(_) | Var(_) | Param(_) => ([z; 3], 0),
            Neg(a) | Sin(a) | Cos(a) | Acos(a) | Sqrt(a) | Sgn(a) | Clamp(a) => ([a, z, z], 1),
            Add(a, b) | Sub(a, b) | Mul(a, b) | Div(a, b) | Atan2(a, b) => ([a, b, z], 2),
            Select(a, b, c) => ([a, b, c], 3),
        };
        Children { ids, len }
    }

    /// The same node kind with every child replaced by `f(child)`.
    pub fn map_children(&self, mut f: impl FnMut(NodeId) -> NodeId) -> Node {
        use Node::*;
        match *self {
            Const(_) | Var(_) | Param(_) => *self,
            Add(a, b) => Add(f(a), f(b)),
            Sub(a, b) => Sub(f(a), f(b)),
            Mul(a, b) => Mul(f(a), f(b)),
            Div(a, b) => Div(f(a), f(b)),
            Atan2(a, b) => Atan2(f(a), f(b)),
            Neg(a) => Neg(f(a)),
            Sin(a) => Sin(f(a)),
            Cos(a) => Cos(f(a)),
            Acos(a) => Acos(f(a)),
            Sqrt(a) => Sqrt(f(a)),
            Sgn(a) => Sgn(f(a)),
            Clamp(a) => Clamp(f(a)),
            Select(a, b, c) => Select(f(a), f(b), f(c)),
        }
    }

    /// Constants, variables and parameters.
    pub fn is_leaf(&self) -> bool {
        matches!(self, Node::Const(_) | Node::Var(_) | Node::Param(_))
    }

    /// A short name of the node kind (used by the DOT printer and in messages).
    pub fn kind_name(&self) -> &'static str {
        use Node::*;
        match self {
            Const(_) => "const",
            Var(_) => "var",
            Param(_) => "param",
            Add(..) => "+",
            Sub(..) => "-",
            Mul(..) => "*",
            Div(..) => "/",
            Neg(_) => "neg",
            Sin(_) => "sin",
            Cos(_) => "cos",
            Acos(_) => "acos",
            Sqrt(_) => "sqrt",
            Atan2(..) => "atan2",
            Sgn(_) => "sgn",
            Clamp(_) => "clamp",
            Select(..) => "select",
        }
    }

    /// Evaluate this node given its children's values in operand order (`args`), the
    /// variables and the parameters. Every backend (interpreter, JIT, constant folding)
    /// follows exactly these semantics.
    #[inline]
    pub fn eval_with(&self, args: &[f64], vars: &[f64], params: &[f64]) -> f64 {
        use Node::*;
        match *self {
            Const(c) => c,
            Var(i) => vars[i as usize],
            Param(i) => params[i as usize],
            Add(..) => args[0] + args[1],
            Sub(..) => args[0] - args[1],
            Mul(..) => args[0] * args[1],
            Div(..) => args[0] / args[1],
            Neg(_) => -args[0],
            Sin(_) => trig::sin(args[0]),
            Cos(_) => trig::cos(args[0]),
            Acos(_) => acos_clamped(args[0]),
            Sqrt(_) => args[0].sqrt(),
            Atan2(..) => trig::atan2(args[0], args[1]),
            Sgn(_) => sgn_f64(args[0]),
            Clamp(_) => clamp_unit(args[0]),
            Select(..) => select(args[0], args[1], args[2]),
        }
    }
}

/// `x` clamped to `[-1, 1]`; NaN stays NaN (as `f64::clamp`).
#[inline]
pub fn clamp_unit(x: f64) -> f64 {
    x.clamp(-1.0, 1.0)
}

/// `a` where `c > 0`, else `b` (NaN selects `b`).
#[inline]
pub fn select(c: f64, a: f64, b: f64) -> f64 {
    if c > 0.0 { a } else { b }
}

/// What is known about a node's f64 value for every input whose variables and parameters
/// are finite with magnitude at most [`INPUT_BOUND`]: if `finite`, the value is finite and
/// lies in `[lo, hi]`; otherwise nothing is known (it may be NaN or infinite).
///
/// The bounds are sound for the *computed* (rounded) values: round-to-nearest is monotone,
/// so evaluating interval endpoints with the same f64 operations bounds every result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// Lower bound (may be `-inf` for a finite but unbounded value).
    pub lo: f64,
    /// Upper bound (may be `+inf`).
    pub hi: f64,
    /// Whether the value is finite whenever all inputs are finite.
    pub finite: bool,
}

/// The magnitude assumed of every variable and parameter (angles, lengths, ±1 modes and
/// task data are many orders below it). Without a bound, `α6 + α7` could overflow and
/// nothing derived from two inputs would be known finite; with it, the analysis can prove
/// e.g. `sin(α6 + α7 - U)` finite and fold `0 · that` to 0.
pub const INPUT_BOUND: f64 = 1e150;

/// The largest magnitude that, added to any finite f64, cannot overflow.
const SAFE_ADD: f64 = 1e290;
/// Upper bound of `acos` and `atan2` results in f64 (π rounded up by one ulp, for safety).
const PI_UP: f64 = 3.1415926535897936;

impl Range {
    /// Nothing known.
    pub const UNKNOWN: Range = Range {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
        finite: false,
    };
    /// Finite but unbounded (variables and parameters).
    pub const FINITE: Range = Range {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
        finite: true,
    };

    /// A finite interval.
    pub fn interval(lo: f64, hi: f64) -> Range {
        if lo.is_nan() || hi.is_nan() {
            return Range::UNKNOWN;
        }
        Range {
            lo,
            hi,
            finite: true,
        }
    }

    /// The range of a constant.
    pub fn constant(c: f64) -> Range {
        if c.is_finite() {
            Range::interval(c, c)
        } else {
            Range::UNKNOWN
        }
    }

    /// Both bounds finite.
    pub fn bounded(&self) -> bool {
        self.finite && self.lo.is_finite() && self.hi.is_finite()
    }

    /// The value is known to be exactly `c` (up to the sign of zero).
    pub fn is_exactly(&self, c: f64) -> bool {
        self.finite && self.lo == c && self.hi == c
    }

    /// Largest possible magnitude.
    fn mag(&self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// The intersection of two facts about one value (both hold).
    pub fn intersect(&self, other: &Range) -> Range {
        match (self.finite, other.finite) {
            (false, false) => Range::UNKNOWN,
            (true, false) => *self,
            (false, true) => *other,
            (true, true) => {
                let lo = self.lo.max(other.lo);
                let hi = self.hi.min(other.hi);
                if lo <= hi {
                    Range {
                        lo,
                        hi,
                        finite: true,
                    }
                } else {
                    // Contradictory facts (rounding-level disagreement between equal
                    // forms): keep the first rather than invent an empty set.
                    *self
                }
            }
        }
    }

    fn hull(a: &Range, b: &Range) -> Range {
        if a.finite && b.finite {
            Range {
                lo: a.lo.min(b.lo),
                hi: a.hi.max(b.hi),
                finite: true,
            }
        } else {
            Range::UNKNOWN
        }
    }

    fn from_corners(c: [f64; 4]) -> Range {
        let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = c.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if lo.is_finite() && hi.is_finite() {
            Range::interval(lo, hi)
        } else {
            Range::UNKNOWN
        }
    }

    /// The range of `node` given its children's ranges in operand order.
    pub fn of(node: &Node, args: &[Range]) -> Range {
        use Node::*;
        let unit = Range::interval(-1.0, 1.0);
        match *node {
            Const(c) => Range::constant(c),
            Var(_) | Param(_) => Range::interval(-INPUT_BOUND, INPUT_BOUND),
            Add(..) | Sub(..) => {
                let (a, b) = (args[0], args[1]);
                let b = if matches!(node, Sub(..)) {
                    Range {
                        lo: -b.hi,
                        hi: -b.lo,
                        finite: b.finite,
                    }
                } else {
                    b
                };
                if !(a.finite && b.finite) {
                    Range::UNKNOWN
                } else if a.bounded() && b.bounded() {
                    Range::interval(a.lo + b.lo, a.hi + b.hi)
                        .with_finite_check(a.lo + b.lo, a.hi + b.hi)
                } else if (a.bounded() && a.mag() <= SAFE_ADD)
                    || (b.bounded() && b.mag() <= SAFE_ADD)
                {
                    Range {
                        lo: a.lo + b.lo,
                        hi: a.hi + b.hi,
                        finite: true,
                    }
                } else {
                    Range::UNKNOWN
                }
            }
            Mul(..) => {
                let (a, b) = (args[0], args[1]);
                if !(a.finite && b.finite) {
                    Range::UNKNOWN
                } else if a.bounded() && b.bounded() {
                    Range::from_corners([a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi])
                } else if (a.bounded() && a.mag() <= 1.0) || (b.bounded() && b.mag() <= 1.0) {
                    Range::FINITE
                } else {
                    Range::UNKNOWN
                }
            }
            Div(..) => {
                let (a, b) = (args[0], args[1]);
                if a.bounded() && b.bounded() && (b.lo > 0.0 || b.hi < 0.0) {
                    Range::from_corners([a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi])
                } else {
                    Range::UNKNOWN
                }
            }
            Neg(_) => {
                let a = args[0];
                if a.finite {
                    Range {
                        lo: -a.hi,
                        hi: -a.lo,
                        finite: true,
                    }
                } else {
                    Range::UNKNOWN
                }
            }
            Sin(_) | Cos(_) => {
                if args[0].finite {
                    unit
                } else {
                    Range::UNKNOWN
                }
            }
            Acos(_) => {
                if args[0].finite {
                    Range::interval(0.0, PI_UP)
                } else {
                    Range::UNKNOWN
                }
            }
            Sqrt(_) => {
                let a = args[0];
                if a.finite && a.lo >= 0.0 {
                    Range {
                        lo: a.lo.sqrt(),
                        hi: a.hi.sqrt(),
                        finite: true,
                    }
                } else {
                    Range::UNKNOWN
                }
            }
            Atan2(..) => {
                if args[0].finite && args[1].finite {
                    Range::interval(-PI_UP, PI_UP)
                } else {
                    Range::UNKNOWN
                }
            }
            Sgn(_) => {
                let a = args[0];
                if a.finite && a.lo > 0.0 {
                    Range::constant(1.0)
                } else if a.finite && a.hi < 0.0 {
                    Range::constant(-1.0)
                } else {
                    unit
                }
            }
            Clamp(_) => {
                let a = args[0];
                if a.finite {
                    Range::interval(a.lo.clamp(-1.0, 1.0), a.hi.clamp(-1.0, 1.0))
                } else {
                    Range::UNKNOWN
                }
            }
            Select(..) => Range::hull(&args[1], &args[2]),
        }
    }

    /// The range of `x * x` (never negative, unlike a general product of two `x` ranges).
    pub fn square(x: &Range) -> Range {
        if !x.bounded() {
            return Range::of(&Node::Mul(NodeId(0), NodeId(0)), &[*x, *x]);
        }
        let (a, b) = (x.lo * x.lo, x.hi * x.hi);
        let lo = if x.lo <= 0.0 && x.hi >= 0.0 {
            0.0
        } else {
            a.min(b)
        };
        Range::interval(lo, a.max(b)).with_finite_check(lo, a.max(b))
    }

    /// The range of `x * sgn(x)`: exactly `|x|` for finite `x` (`sgn x` is exactly ±1, or 0
    /// where `x = 0`), so never negative, unlike a general product of the two ranges.
    pub fn abs(x: &Range) -> Range {
        if !x.finite {
            // inf · 1 = inf and NaN · 0 = NaN: nothing known.
            return Range::UNKNOWN;
        }
        let lo = if x.lo <= 0.0 && x.hi >= 0.0 {
            0.0
        } else {
            x.lo.abs().min(x.hi.abs())
        };
        Range {
            lo,
            hi: x.mag(),
            finite: true,
        }
    }

    /// The range of `x + x * sgn(x)` (twice `max(0, x)`, how [`Scalar::max0`] writes it):
    /// `2x` where `x > 0` (exact, but it may overflow), exactly 0 otherwise. This is
    /// what proves `sqrt(max0(·))` finite, which a range of the sum alone cannot.
    ///
    /// [`Scalar::max0`]: crate::kinematics::Scalar::max0
    pub fn plus_abs(x: &Range) -> Range {
        if !x.finite {
            return Range::UNKNOWN;
        }
        let lo = 2.0 * x.lo.max(0.0);
        let hi = 2.0 * x.hi.max(0.0);
        Range::interval(lo, hi).with_finite_check(lo, hi)
    }

    /// The range of `select(x, x, b)` (`x` where `x > 0`, else `b`): like the hull, but
    /// only the positive part of `x` survives (so `select(x, x, 0) ≥ 0`).
    pub fn select_positive(x: &Range, b: &Range) -> Range {
        if !(x.finite && b.finite) {
            return Range::UNKNOWN;
        }
        let pos = Range {
            lo: x.lo.max(0.0),
            hi: x.hi.max(0.0),
            finite: true,
        };
        Range::hull(&pos, b)
    }

    fn with_finite_check(self, lo: f64, hi: f64) -> Range {
        if lo.is_finite() && hi.is_finite() {
            self
        } else {
            Range::UNKNOWN
        }
    }

    /// Whether every value lies in `[-1, 1]` (so a clamp to it is the identity).
    pub fn within_unit(&self) -> bool {
        self.finite && self.lo >= -1.0 && self.hi <= 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges() {
        let v = Range::FINITE;
        let s = Range::of(&Node::Sin(NodeId(0)), &[v]);
        assert!(s.within_unit());
        let p = Range::of(&Node::Mul(NodeId(0), NodeId(0)), &[s, s]);
        assert!(p.within_unit());
        let sum = Range::of(&Node::Add(NodeId(0), NodeId(0)), &[p, p]);
        assert!(!sum.within_unit() && sum.bounded());
        let vv = Range::of(&Node::Add(NodeId(0), NodeId(0)), &[v, v]);
        assert!(!vv.finite, "var + var may overflow");
        let vs = Range::of(&Node::Add(NodeId(0), NodeId(0)), &[v, s]);
        assert!(vs.finite && !vs.bounded());
        let d = Range::of(&Node::Div(NodeId(0), NodeId(0)), &[s, s]);
        assert!(!d.finite);
        let sq = Range::of(&Node::Sqrt(NodeId(0)), &[sum]);
        assert!(!sq.finite, "sqrt of a possibly negative value may be NaN");
    }

    #[test]
    fn abs_and_plus_abs() {
        let x = Range::interval(-3.0, 2.0);
        assert_eq!(Range::abs(&x), Range::interval(0.0, 3.0));
        assert_eq!(
            Range::abs(&Range::interval(-3.0, -0.5)),
            Range::interval(0.5, 3.0)
        );
        assert_eq!(Range::plus_abs(&x), Range::interval(0.0, 4.0));
        assert_eq!(
            Range::plus_abs(&Range::interval(1.0, 2.0)),
            Range::interval(2.0, 4.0)
        );
        assert_eq!(
            Range::plus_abs(&Range::interval(-2.0, -1.0)),
            Range::interval(0.0, 0.0)
        );
        // Every value of x + x·sgn x at sample points lies in the range.
        for v in [-3.0, -1e-300, -0.0, 0.0, 1e-300, 1.5, 2.0] {
            let got = v + v * sgn_f64(v);
            let r = Range::plus_abs(&x);
            assert!(got >= r.lo && got <= r.hi, "{v}: {got}");
            let a = v * sgn_f64(v);
            assert!((0.0..=3.0).contains(&a), "{v}: {a}");
        }
        // 2x may overflow: finite but unbounded x gives nothing, nor does an unknown x.
        assert!(!Range::plus_abs(&Range::FINITE).finite);
        assert!(!Range::plus_abs(&Range::interval(0.0, f64::MAX)).finite);
        assert!(!Range::abs(&Range::UNKNOWN).finite);
        let a = Range::abs(&Range::FINITE);
        assert!(a.finite && a.lo == 0.0);
    }
}
