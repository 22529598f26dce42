//! The symbolic handle that implements [`Scalar`].

use super::graph::ExprGraph;
use super::node::{Node, NodeId};
use crate::kinematics::Scalar;
use std::cell::{Ref, RefCell};
use std::fmt;
use std::ops::{Add, Div, Mul, Neg, Sub};
use std::rc::Rc;

/// A shared, growable expression graph that [`Sym`] handles point into.
///
/// Cloning a `Ctx` clones the handle, not the graph.
#[derive(Clone, Default)]
pub struct Ctx(Rc<RefCell<ExprGraph>>);

impl fmt::Debug for Ctx {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Ctx({} nodes)", self.0.borrow().len())
    }
}

impl Ctx {
    /// A new, empty graph.
    pub fn new() -> Self {
        Self::default()
    }

    /// Variable (optimization unknown) number `i`.
    pub fn var(&self, i: usize) -> Sym {
        let id = self.0.borrow_mut().var(i);
        Sym::Node(self.clone(), id)
    }

    /// Parameter number `i` (t, modes, task data).
    pub fn param(&self, i: usize) -> Sym {
        let id = self.0.borrow_mut().param(i);
        Sym::Node(self.clone(), id)
    }

    /// The graph as it is now.
    pub fn graph(&self) -> Ref<'_, ExprGraph> {
        self.0.borrow()
    }

    /// A copy of the graph as it is now (an owned, `Send` value for the compiler).
    pub fn to_graph(&self) -> ExprGraph {
        self.0.borrow().clone()
    }

    /// The node of `s` in this graph (constants are inserted).
    ///
    /// # Panics
    /// If `s` belongs to another graph (a programming error).
    pub fn node_id(&self, s: &Sym) -> NodeId {
        match s {
            Sym::Const(c) => self.0.borrow_mut().constant(*c),
            Sym::Node(ctx, id) => {
                assert!(self.same(ctx), "Sym from another expression graph");
                *id
            }
        }
    }

    /// Whether two handles share one graph.
    pub fn same(&self, other: &Ctx) -> bool {
        Rc::ptr_eq(&self.0, &other.0)
    }

    /// Wrap a node of this graph as a handle (constants come back as [`Sym::Const`]).
    pub fn sym(&self, id: NodeId) -> Sym {
        match self.0.borrow().node(id) {
            Node::Const(c) => Sym::Const(*c),
            _ => Sym::Node(self.clone(), id),
        }
    }

    fn add_node(&self, node: Node) -> Sym {
        let id = self.0.borrow_mut().add(node);
        self.sym(id)
    }
}

/// A symbolic real: a context-free constant or a node of a [`Ctx`] graph.
///
/// Arithmetic between handles of two different graphs is a programming error and panics.
#[derive(Clone)]
pub enum Sym {
    /// A constant that has not met a graph yet.
    Const(f64),
    /// A node of a graph.
    Node(Ctx, NodeId),
}

impl fmt::Debug for Sym {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Sym::Const(c) => write!(f, "Sym::Const({c:?})"),
            Sym::Node(ctx, id) => {
                write!(f, "Sym::Node(#{}: {:?})", id.0, ctx.graph().node(*id))
            }
        }
    }
}

impl Sym {
    /// The node id, if this handle is a node.
    pub fn node(&self) -> Option<NodeId> {
        match self {
            Sym::Const(_) => None,
            Sym::Node(_, id) => Some(*id),
        }
    }

    /// The graph, if this handle is a node.
    pub fn ctx(&self) -> Option<&Ctx> {
        match self {
            Sym::Const(_) => None,
            Sym::Node(ctx, _) => Some(ctx),
        }
    }

    fn unary(&self, make: fn(NodeId) -> Node) -> Sym {
        match self {
            Sym::Const(c) => {
                // Fold with the shared node semantics.
                Sym::Const(make(NodeId(0)).eval_with(&[*c], &[], &[]))
            }
            Sym::Node(ctx, id) => ctx.add_node(make(*id)),
        }
    }

    fn binary(a: &Sym, b: &Sym, make: fn(NodeId, NodeId) -> Node) -> Sym {
        let ctx = match (a, b) {
            (Sym::Const(x), Sym::Const(y)) => {
                return Sym::Const(make(NodeId(0), NodeId(0)).eval_with(&[*x, *y], &[], &[]));
            }
            (Sym::Node(c, _), _) | (_, Sym::Node(c, _)) => c.clone(),
        };
        let (ia, ib) = (ctx.node_id(a), ctx.node_id(b));
        ctx.add_node(make(ia, ib))
    }
}

macro_rules! sym_binop {
    ($tr:ident, $m:ident, $node:ident) => {
        impl $tr<Sym> for Sym {
            type Output = Sym;
            fn $m(self, rhs: Sym) -> Sym {
                Sym::binary(&self, &rhs, Node::$node)
            }
        }
        impl $tr<f64> for Sym {
            type Output = Sym;
            fn $m(self, rhs: f64) -> Sym {
                Sym::binary(&self, &Sym::Const(rhs), Node::$node)
            }
        }
        impl $tr<&Sym> for &Sym {
            type Output = Sym;
            fn $m(self, rhs: &Sym) -> Sym {
                Sym::binary(self, rhs, Node::$node)
            }
        }
    };
}

sym_binop!(Add, add, Add);
sym_binop!(Sub, sub, Sub);
sym_binop!(Mul, mul, Mul);
sym_binop!(Div, div, Div);

impl Neg for Sym {
    type Output = Sym;
    fn neg(self) -> Sym {
        self.unary(Node::Neg)
    }
}

impl Neg for &Sym {
    type Output = Sym;
    fn neg(self) -> Sym {
        self.unary(Node::Neg)
    }
}

impl Scalar for Sym {
    fn from_f64(v: f64) -> Self {
        Sym::Const(v)
    }
    fn sin(&self) -> Self {
        self.unary(Node::Sin)
    }
    fn cos(&self) -> Self {
        self.unary(Node::Cos)
    }
    fn acos(&self) -> Self {
        self.unary(Node::Acos)
    }
    fn sqrt(&self) -> Self {
        self.unary(Node::Sqrt)
    }
    fn atan2(&self, x: &Self) -> Self {
        Sym::binary(self, x, Node::Atan2)
    }
    fn sgn(&self) -> Self {
        self.unary(Node::Sgn)
    }
    fn to_f64(&self) -> Option<f64> {
        match self {
            Sym::Const(c) => Some(*c),
            Sym::Node(ctx, id) => ctx.graph().const_value(*id),
        }
    }
}

/// Extra operations of the symbolic handle that the [`Scalar`] trait does not need.
impl Sym {
    /// `clamp(self, -1, 1)`.
    pub fn clamp_unit(&self) -> Sym {
        self.unary(Node::Clamp)
    }

    /// `if cond > 0 { a } else { b }`.
    pub fn select(cond: &Sym, a: &Sym, b: &Sym) -> Sym {
        let ctx = [cond, a, b].into_iter().find_map(|s| s.ctx().cloned());
        match ctx {
            None => Sym::Const(super::node::select(
                cond.to_f64().unwrap_or(0.0),
                a.to_f64().unwrap_or(0.0),
                b.to_f64().unwrap_or(0.0),
            )),
            Some(ctx) => {
                let (c, x, y) = (ctx.node_id(cond), ctx.node_id(a), ctx.node_id(b));
                ctx.add_node(Node::Select(c, x, y))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generic_code_builds_graphs() {
        fn f<S: Scalar>(x: S, y: S) -> S {
            (x.clone() * y.clone() + x.sin()) / (y.cos() + 2.0)
        }
        let ctx = Ctx::new();
        let s = f(ctx.var(0), ctx.param(0));
        let id = ctx.node_id(&s);
        let v = ctx.graph().eval(&[id], &[0.3], &[1.7]);
        assert_eq!(v[0], f(0.3, 1.7));
        // Constants stay context-free and fold.
        let c = f(Sym::from_f64(0.3), Sym::from_f64(1.7));
        assert_eq!(c.to_f64(), Some(f(0.3, 1.7)));
        assert!(c.ctx().is_none());
    }

    #[test]
    #[should_panic(expected = "another expression graph")]
    fn mixing_graphs_panics() {
        let a = Ctx::new().var(0);
        let b = Ctx::new().var(0);
        let _ = a + b;
    }
}
