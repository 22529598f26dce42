//! The interpreter: a flat, topologically ordered tape (no recursion, so deep DAGs are
//! fine) over the nodes reachable from a set of outputs.

use super::graph::ExprGraph;
use super::node::{Node, NodeId, clamp_unit, select};
use crate::kinematics::{acos_clamped, sgn_f64};
use crate::trig;

/// Wrong input or output lengths, or an index out of the declared range.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ShapeError {
    /// A slice has the wrong length.
    #[error("{what}: expected length {expected}, got {got}")]
    Length {
        /// Which argument.
        what: &'static str,
        /// The declared length.
        expected: usize,
        /// The length passed.
        got: usize,
    },
    /// The graph uses a variable or parameter beyond the declared count.
    #[error("the expression uses {what} {index}, but only {declared} are declared")]
    Index {
        /// "variable" or "parameter".
        what: &'static str,
        /// The offending index.
        index: usize,
        /// The declared count.
        declared: usize,
    },
    /// An output id is not a node of the graph.
    #[error("output {0} is not a node of the graph")]
    Output(usize),
}

impl ShapeError {
    /// Check the lengths of a call's buffers against `[n_vars, n_params, n_outputs]`.
    pub fn check_lengths(
        expected: [usize; 3],
        vars: &[f64],
        params: &[f64],
        out: &[f64],
    ) -> Result<(), ShapeError> {
        for (what, expected, got) in [
            ("vars", expected[0], vars.len()),
            ("params", expected[1], params.len()),
            ("out", expected[2], out.len()),
        ] {
            if expected != got {
                return Err(ShapeError::Length {
                    what,
                    expected,
                    got,
                });
            }
        }
        Ok(())
    }
}

/// One tape instruction; operands are slot indices (slot `k` holds instruction `k`).
#[derive(Clone, Copy, Debug)]
enum Instr {
    Const(f64),
    Var(u32),
    Param(u32),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Div(u32, u32),
    Neg(u32),
    Sin(u32),
    Cos(u32),
    Acos(u32),
    Sqrt(u32),
    Atan2(u32, u32),
    Sgn(u32),
    Clamp(u32),
    Select(u32, u32, u32),
}

/// A compiled-for-interpretation set of outputs over declared numbers of variables and
/// parameters.
#[derive(Clone, Debug)]
pub struct Tape {
    instrs: Vec<Instr>,
    outputs: Vec<u32>,
    n_vars: usize,
    n_params: usize,
}

/// Check that `outputs` are nodes of `graph` and every reachable variable/parameter index
/// is below the declared counts.
pub(crate) fn check_indices(
    graph: &ExprGraph,
    outputs: &[NodeId],
    n_vars: usize,
    n_params: usize,
) -> Result<Vec<bool>, ShapeError> {
    for &o in outputs {
        if o.index() >= graph.len() {
            return Err(ShapeError::Output(o.index()));
        }
    }
    let mark = graph.reachable(outputs);
    for (i, m) in mark.iter().enumerate() {
        if !*m {
            continue;
        }
        match *graph.node(NodeId(i as u32)) {
            Node::Var(k) if k as usize >= n_vars => {
                return Err(ShapeError::Index {
                    what: "variable",
                    index: k as usize,
                    declared: n_vars,
                });
            }
            Node::Param(k) if k as usize >= n_params => {
                return Err(ShapeError::Index {
                    what: "parameter",
                    index: k as usize,
                    declared: n_params,
                });
            }
            _ => {}
        }
    }
    Ok(mark)
}

impl Tape {
    /// The tape of `outputs` over `n_vars` variables and `n_params` parameters.
    pub fn new(
        graph: &ExprGraph,
        outputs: &[NodeId],
        n_vars: usize,
        n_params: usize,
    ) -> Result<Tape, ShapeError> {
        let mark = check_indices(graph, outputs, n_vars, n_params)?;
        let mut slot = vec![u32::MAX; graph.len()];
        let mut instrs = Vec::new();
        for (i, node) in graph.nodes().iter().enumerate() {
            if !mark[i] {
                continue;
            }
            let s = |id: NodeId| slot[id.index()];
            let ins = match *node {
                Node::Const(c) => Instr::Const(c),
                Node::Var(k) => Instr::Var(k),
                Node::Param(k) => Instr::Param(k),
                Node::Add(a, b) => Instr::Add(s(a), s(b)),
                Node::Sub(a, b) => Instr::Sub(s(a), s(b)),
                Node::Mul(a, b) => Instr::Mul(s(a), s(b)),
                Node::Div(a, b) => Instr::Div(s(a), s(b)),
                Node::Neg(a) => Instr::Neg(s(a)),
                Node::Sin(a) => Instr::Sin(s(a)),
                Node::Cos(a) => Instr::Cos(s(a)),
                Node::Acos(a) => Instr::Acos(s(a)),
                Node::Sqrt(a) => Instr::Sqrt(s(a)),
                Node::Atan2(a, b) => Instr::Atan2(s(a), s(b)),
                Node::Sgn(a) => Instr::Sgn(s(a)),
                Node::Clamp(a) => Instr::Clamp(s(a)),
                Node::Select(a, b, c) => Instr::Select(s(a), s(b), s(c)),
            };
            slot[i] = instrs.len() as u32;
            instrs.push(ins);
        }
        let outputs = outputs.iter().map(|o| slot[o.index()]).collect();
        Ok(Tape {
            instrs,
            outputs,
            n_vars,
            n_params,
        })
    }

    /// Number of instructions (reachable nodes).
    pub fn len(&self) -> usize {
        self.instrs.len()
    }

    /// Whether the tape is empty (no outputs).
    pub fn is_empty(&self) -> bool {
        self.instrs.is_empty()
    }

    /// Number of outputs.
    pub fn n_outputs(&self) -> usize {
        self.outputs.len()
    }

    /// Declared number of variables.
    pub fn n_vars(&self) -> usize {
        self.n_vars
    }

    /// Declared number of parameters.
    pub fn n_params(&self) -> usize {
        self.n_params
    }

    fn check(&self, vars: &[f64], params: &[f64], out: &[f64]) -> Result<(), ShapeError> {
        ShapeError::check_lengths(
            [self.n_vars, self.n_params, self.outputs.len()],
            vars,
            params,
            out,
        )
    }

    /// Evaluate into `out`, allocating scratch space.
    pub fn eval(&self, vars: &[f64], params: &[f64], out: &mut [f64]) -> Result<(), ShapeError> {
        let mut scratch = Vec::new();
        self.eval_with(&mut scratch, vars, params, out)
    }

    /// Evaluate into `out`, reusing `scratch` (no allocation after the first call).
    pub fn eval_with(
        &self,
        scratch: &mut Vec<f64>,
        vars: &[f64],
        params: &[f64],
        out: &mut [f64],
    ) -> Result<(), ShapeError> {
        self.check(vars, params, out)?;
        scratch.clear();
        scratch.reserve(self.instrs.len());
        for ins in &self.instrs {
            let v = |k: u32| scratch[k as usize];
            let x = match *ins {
                Instr::Const(c) => c,
                Instr::Var(k) => vars[k as usize],
                Instr::Param(k) => params[k as usize],
                Instr::Add(a, b) => v(a) + v(b),
                Instr::Sub(a, b) => v(a) - v(b),
                Instr::Mul(a, b) => v(a) * v(b),
                Instr::Div(a, b) => v(a) / v(b),
                Instr::Neg(a) => -v(a),
                Instr::Sin(a) => trig::sin(v(a)),
                Instr::Cos(a) => trig::cos(v(a)),
                Instr::Acos(a) => acos_clamped(v(a)),
                Instr::Sqrt(a) => v(a).sqrt(),
                Instr::Atan2(a, b) => trig::atan2(v(a), v(b)),
                Instr::Sgn(a) => sgn_f64(v(a)),
                Instr::Clamp(a) => clamp_unit(v(a)),
                Instr::Select(c, a, b) => select(v(c), v(a), v(b)),
            };
            scratch.push(x);
        }
        for (o, &s) in out.iter_mut().zip(&self.outputs) {
            *o = scratch[s as usize];
        }
        Ok(())
    }
}
