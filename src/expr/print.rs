//! Printers for a set of named outputs: plain infix, LaTeX, Mathematica, Python (NumPy)
//! and Graphviz DOT.
//!
//! Every non-leaf node used more than once becomes a numbered temporary, so the output
//! stays linear in the size of the DAG (a tree expansion can be exponential). Operands of
//! equal precedence on the right are parenthesized, so the printed text evaluates in the
//! graph's order (floating-point `+` and `*` are not associative).

use super::graph::ExprGraph;
use super::node::{Node, NodeId};
use std::fmt::Write as _;
use std::str::FromStr;

/// An output format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Plain infix, one assignment per line.
    Plain,
    /// LaTeX `aligned` environment.
    Latex,
    /// Mathematica assignments (`ArcCos[...]`, `ArcTan[x, y]`).
    Mathematica,
    /// A Python module with `def f(vars, params)` using NumPy.
    Python,
    /// Graphviz DOT.
    Dot,
}

impl FromStr for Format {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "plain" => Ok(Format::Plain),
            "latex" => Ok(Format::Latex),
            "mathematica" => Ok(Format::Mathematica),
            "python" => Ok(Format::Python),
            "dot" => Ok(Format::Dot),
            _ => Err(format!(
                "unknown format {s:?} (expected plain, latex, mathematica, python or dot)"
            )),
        }
    }
}

/// Names of the variables and parameters (index `i` → name); missing ones print as
/// `x{i}` and `p{i}`.
#[derive(Clone, Debug, Default)]
pub struct Names {
    /// Variable names.
    pub vars: Vec<String>,
    /// Parameter names.
    pub params: Vec<String>,
}

impl Names {
    fn var(&self, i: u32) -> String {
        self.vars
            .get(i as usize)
            .cloned()
            .unwrap_or_else(|| format!("x{i}"))
    }
    fn param(&self, i: u32) -> String {
        self.params
            .get(i as usize)
            .cloned()
            .unwrap_or_else(|| format!("p{i}"))
    }
}

// Precedence levels of printed expressions.
const SUM: u8 = 1;
const PROD: u8 = 2;
const UNARY: u8 = 3;
const ATOM: u8 = 4;

/// Print `outputs` (name, node) of `graph` in `format`.
pub fn print(
    graph: &ExprGraph,
    outputs: &[(String, NodeId)],
    names: &Names,
    format: Format,
) -> String {
    if format == Format::Dot {
        return print_dot(graph, outputs, names);
    }
    let p = Printer::new(format, names, outputs);
    p.run(graph, outputs)
}

struct Printer {
    format: Format,
    var_names: Vec<String>,
    param_names: Vec<String>,
    temp_prefix: String,
}

impl Printer {
    fn new(format: Format, names: &Names, outputs: &[(String, NodeId)]) -> Printer {
        let n_v = names.vars.len();
        let n_p = names.params.len();
        let var_names: Vec<String> = (0..n_v as u32)
            .map(|i| ident(format, &names.var(i)))
            .collect();
        let param_names: Vec<String> = (0..n_p as u32)
            .map(|i| ident(format, &names.param(i)))
            .collect();
        // A temporary prefix that no user name can collide with.
        let mut temp_prefix = "w".to_string();
        let taken = |p: &str| {
            var_names
                .iter()
                .chain(&param_names)
                .chain(outputs.iter().map(|(n, _)| n))
                .any(|n| {
                    n.strip_prefix(p)
                        .is_some_and(|r| r.chars().all(|c| c.is_ascii_digit()))
                })
        };
        while taken(&temp_prefix) {
            temp_prefix.push('w');
        }
        Printer {
            format,
            var_names,
            param_names,
            temp_prefix,
        }
    }

    fn var(&self, i: u32) -> String {
        self.var_names
            .get(i as usize)
            .cloned()
            .unwrap_or_else(|| ident(self.format, &format!("x{i}")))
    }

    fn param(&self, i: u32) -> String {
        self.param_names
            .get(i as usize)
            .cloned()
            .unwrap_or_else(|| ident(self.format, &format!("p{i}")))
    }

    fn temp(&self, k: usize) -> String {
        match self.format {
            Format::Latex => format!("{}_{{{k}}}", self.temp_prefix),
            _ => format!("{}{k}", self.temp_prefix),
        }
    }

    fn run(&self, graph: &ExprGraph, outputs: &[(String, NodeId)]) -> String {
        let ids: Vec<NodeId> = outputs.iter().map(|(_, id)| *id).collect();
        let mark = graph.reachable(&ids);
        let n = graph.len();
        let mut uses = vec![0u32; n];
        for (i, m) in mark.iter().enumerate() {
            if *m {
                for c in graph.nodes()[i].children() {
                    uses[c.index()] += 1;
                }
            }
        }
        for id in &ids {
            uses[id.index()] += 1;
        }
        let mut repr: Vec<(String, u8)> = vec![(String::new(), ATOM); n];
        let mut stmts: Vec<(String, String)> = Vec::new();
        let mut args: Vec<(String, u8)> = Vec::with_capacity(3);
        for i in 0..n {
            if !mark[i] {
                continue;
            }
            let node = &graph.nodes()[i];
            let r = if node.is_leaf() {
                self.leaf(node)
            } else {
                args.clear();
                for c in node.children() {
                    args.push(take_or_clone(&mut repr, &uses, graph, c));
                }
                self.render(node, &args)
            };
            if !node.is_leaf() && uses[i] > 1 {
                let name = self.temp(stmts.len() + 1);
                stmts.push((name.clone(), r.0));
                repr[i] = (name, ATOM);
            } else {
                repr[i] = r;
            }
        }
        let outs: Vec<(String, String)> = outputs
            .iter()
            .map(|(name, id)| {
                let e = take_or_clone(&mut repr, &uses, graph, *id).0;
                (name.clone(), e)
            })
            .collect();
        self.assemble(&stmts, &outs)
    }

    fn assemble(&self, stmts: &[(String, String)], outs: &[(String, String)]) -> String {
        let mut s = String::new();
        match self.format {
            Format::Plain => {
                let _ = writeln!(
                    s,
                    "# acos(x) clamps x to [-1, 1]; select(c, a, b) = a if c > 0 else b"
                );
                for (n, e) in stmts {
                    let _ = writeln!(s, "{n} = {e}");
                }
                for (n, e) in outs {
                    let _ = writeln!(s, "{n} = {e}");
                }
            }
            Format::Mathematica => {
                for (n, e) in stmts {
                    let _ = writeln!(s, "{n} = {e};");
                }
                for (n, e) in outs {
                    let _ = writeln!(s, "{} = {e};", ident(Format::Mathematica, n));
                }
            }
            Format::Latex => {
                let _ = writeln!(s, "\\begin{{aligned}}");
                let all: Vec<(String, &String)> = stmts
                    .iter()
                    .map(|(n, e)| (n.clone(), e))
                    .chain(outs.iter().map(|(n, e)| (latex_name(n), e)))
                    .collect();
                for (k, (n, e)) in all.iter().enumerate() {
                    let end = if k + 1 < all.len() { " \\\\" } else { "" };
                    let _ = writeln!(s, "{n} &= {e}{end}");
                }
                let _ = writeln!(s, "\\end{{aligned}}");
            }
            Format::Python => {
                let _ = writeln!(s, "import numpy as np\n");
                let names: Vec<String> = outs.iter().map(|(n, _)| format!("{n:?}")).collect();
                let _ = writeln!(s, "OUTPUTS = [{}]\n", names.join(", "));
                let _ = writeln!(s, "\ndef f(vars, params):");
                let _ = writeln!(
                    s,
                    "    \"\"\"The outputs listed in OUTPUTS, in that order. acos clamps its argument.\"\"\""
                );
                for (i, v) in self.var_names.iter().enumerate() {
                    let _ = writeln!(s, "    {v} = vars[{i}]");
                }
                for (i, p) in self.param_names.iter().enumerate() {
                    let _ = writeln!(s, "    {p} = params[{i}]");
                }
                let _ = writeln!(s, "    out = [None] * {}", outs.len());
                // Guarded derivatives evaluate both branches of np.where: silence warnings.
                let _ = writeln!(s, "    with np.errstate(all=\"ignore\"):");
                for (n, e) in stmts {
                    let _ = writeln!(s, "        {n} = {e}");
                }
                for (k, (n, e)) in outs.iter().enumerate() {
                    let _ = writeln!(s, "        out[{k}] = {e}  # {n}");
                }
                let _ = writeln!(s, "    return out");
            }
            Format::Dot => unreachable!("DOT has its own printer"),
        }
        s
    }

    fn leaf(&self, node: &Node) -> (String, u8) {
        match *node {
            Node::Const(c) => self.number(c),
            Node::Var(i) => (self.var(i), ATOM),
            Node::Param(i) => (self.param(i), ATOM),
            _ => unreachable!("not a leaf"),
        }
    }

    fn number(&self, c: f64) -> (String, u8) {
        let f = self.format;
        let neg = c.is_sign_negative() && !c.is_nan();
        let a = c.abs();
        let body = if a == std::f64::consts::PI {
            match f {
                Format::Plain => "pi".to_string(),
                Format::Latex => "\\pi".to_string(),
                Format::Mathematica => "Pi".to_string(),
                _ => "np.pi".to_string(),
            }
        } else if a.is_infinite() {
            match f {
                Format::Plain => "inf".to_string(),
                Format::Latex => "\\infty".to_string(),
                Format::Mathematica => "Infinity".to_string(),
                _ => "np.inf".to_string(),
            }
        } else if c.is_nan() {
            match f {
                Format::Plain => "NaN".to_string(),
                Format::Latex => "\\mathrm{NaN}".to_string(),
                Format::Mathematica => "Indeterminate".to_string(),
                _ => "np.nan".to_string(),
            }
        } else {
            // Shortest text that reads back to the same f64.
            let t = format!("{a:?}");
            match (f, t.split_once('e')) {
                (Format::Mathematica, Some((m, e))) => {
                    let m = if m.contains('.') {
                        m.to_string()
                    } else {
                        format!("{m}.")
                    };
                    format!("{m}*^{e}")
                }
                (Format::Latex, Some((m, e))) => format!("{m} \\times 10^{{{e}}}"),
                _ => t,
            }
        };
        if neg {
            (format!("-{body}"), UNARY)
        } else {
            (body, ATOM)
        }
    }

    fn call(&self, f: &str, args: &[&str]) -> (String, u8) {
        let s = match self.format {
            Format::Mathematica => format!("{f}[{}]", args.join(", ")),
            Format::Latex => format!("{f}\\left({}\\right)", args.join(", ")),
            _ => format!("{f}({})", args.join(", ")),
        };
        (s, ATOM)
    }

    fn render(&self, node: &Node, a: &[(String, u8)]) -> (String, u8) {
        use Format::*;
        let f = self.format;
        let binary = |op: &str, prec: u8| -> (String, u8) {
            let l = paren(f, &a[0], a[0].1 < prec);
            let r = paren(f, &a[1], a[1].1 <= prec || a[1].1 == UNARY);
            (format!("{l} {op} {r}"), prec)
        };
        match *node {
            Node::Add(..) => binary("+", SUM),
            Node::Sub(..) => binary("-", SUM),
            Node::Mul(..) => binary(if f == Latex { "\\cdot" } else { "*" }, PROD),
            Node::Div(..) => {
                if f == Latex {
                    (format!("\\frac{{{}}}{{{}}}", a[0].0, a[1].0), ATOM)
                } else {
                    binary("/", PROD)
                }
            }
            Node::Neg(_) => {
                let x = paren(f, &a[0], a[0].1 < ATOM);
                (format!("-{x}"), UNARY)
            }
            Node::Sin(_) => self.call(fname(f, "sin"), &[&a[0].0]),
            Node::Cos(_) => self.call(fname(f, "cos"), &[&a[0].0]),
            Node::Sqrt(_) => match f {
                Latex => (format!("\\sqrt{{{}}}", a[0].0), ATOM),
                _ => self.call(fname(f, "sqrt"), &[&a[0].0]),
            },
            Node::Acos(_) => match f {
                Mathematica => (format!("ArcCos[Clip[{}, {{-1, 1}}]]", a[0].0), ATOM),
                Python => (format!("np.arccos(np.clip({}, -1.0, 1.0))", a[0].0), ATOM),
                _ => self.call(fname(f, "acos"), &[&a[0].0]),
            },
            Node::Clamp(_) => match f {
                Mathematica => (format!("Clip[{}, {{-1, 1}}]", a[0].0), ATOM),
                Python => (format!("np.clip({}, -1.0, 1.0)", a[0].0), ATOM),
                Latex => self.call("\\operatorname{clamp}_{[-1,1]}", &[&a[0].0]),
                _ => self.call("clamp", &[&a[0].0]),
            },
            // atan2(y, x): Mathematica's ArcTan takes x first.
            Node::Atan2(..) => match f {
                Mathematica => self.call("ArcTan", &[&a[1].0, &a[0].0]),
                _ => self.call(fname(f, "atan2"), &[&a[0].0, &a[1].0]),
            },
            Node::Sgn(_) => self.call(fname(f, "sgn"), &[&a[0].0]),
            Node::Select(..) => {
                let (c, x, y) = (&a[0].0, &a[1].0, &a[2].0);
                match f {
                    Mathematica => (format!("If[{c} > 0, {x}, {y}]"), ATOM),
                    Python => (format!("np.where({c} > 0, {x}, {y})"), ATOM),
                    Latex => (
                        format!(
                            "\\begin{{cases}} {x} & {c} > 0 \\\\ {y} & \\text{{otherwise}} \\end{{cases}}"
                        ),
                        ATOM,
                    ),
                    _ => (format!("select({c}, {x}, {y})"), ATOM),
                }
            }
            Node::Const(_) | Node::Var(_) | Node::Param(_) => unreachable!("leaves"),
        }
    }
}

fn take_or_clone(
    repr: &mut [(String, u8)],
    uses: &[u32],
    graph: &ExprGraph,
    id: NodeId,
) -> (String, u8) {
    let i = id.index();
    if uses[i] == 1 && !graph.node(id).is_leaf() {
        // Used exactly once: move the text instead of copying it (keeps output linear).
        std::mem::take(&mut repr[i])
    } else {
        repr[i].clone()
    }
}

fn paren(f: Format, x: &(String, u8), need: bool) -> String {
    if !need {
        x.0.clone()
    } else if f == Format::Latex {
        format!("\\left({}\\right)", x.0)
    } else {
        format!("({})", x.0)
    }
}

fn fname(f: Format, op: &'static str) -> &'static str {
    match (f, op) {
        (Format::Mathematica, "sin") => "Sin",
        (Format::Mathematica, "cos") => "Cos",
        (Format::Mathematica, "sqrt") => "Sqrt",
        (Format::Mathematica, "sgn") => "Sign",
        (Format::Python, "sin") => "np.sin",
        (Format::Python, "cos") => "np.cos",
        (Format::Python, "sqrt") => "np.sqrt",
        (Format::Python, "atan2") => "np.arctan2",
        (Format::Python, "sgn") => "np.sign",
        (Format::Latex, "sin") => "\\sin",
        (Format::Latex, "cos") => "\\cos",
        (Format::Latex, "acos") => "\\arccos",
        (Format::Latex, "atan2") => "\\operatorname{atan2}",
        (Format::Latex, "sgn") => "\\operatorname{sgn}",
        (_, op) => op,
    }
}

const PY_RESERVED: &[&str] = &[
    "np", "vars", "params", "out", "f", "False", "None", "True", "and", "as", "assert", "async",
    "await", "break", "class", "continue", "def", "del", "elif", "else", "except", "finally",
    "for", "from", "global", "if", "import", "in", "is", "lambda", "nonlocal", "not", "or", "pass",
    "raise", "return", "try", "while", "with", "yield",
];

// Single capital letters that are Mathematica built-ins.
const MMA_RESERVED: &[&str] = &["C", "D", "E", "I", "K", "N", "O"];

/// A user name made valid in the target syntax.
fn ident(f: Format, name: &str) -> String {
    match f {
        Format::Python => {
            let mut s: String = name
                .chars()
                .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
                .collect();
            if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
                s.insert(0, '_');
            }
            if PY_RESERVED.contains(&s.as_str()) {
                s.push('_');
            }
            s
        }
        Format::Mathematica => {
            let mut s: String = name.chars().filter(|c| c.is_ascii_alphanumeric()).collect();
            if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
                s.insert(0, 'x');
            }
            if MMA_RESERVED.contains(&s.as_str()) {
                s.insert(0, 'v');
            }
            s
        }
        Format::Latex => latex_name(name),
        Format::Plain | Format::Dot => name.to_string(),
    }
}

const GREEK: &[&str] = &[
    "alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta", "iota", "kappa",
    "lambda", "mu", "nu", "xi", "pi", "rho", "sigma", "tau", "upsilon", "phi", "chi", "psi",
    "omega",
];

/// `alpha1` → `\alpha_{1}`, `U2` → `U_{2}`, other names as `\mathit{...}`.
fn latex_name(name: &str) -> String {
    let stem = name.trim_end_matches(|c: char| c.is_ascii_digit());
    let digits = &name[stem.len()..];
    let stem_tex = if GREEK.contains(&stem) {
        format!("\\{stem}")
    } else if stem.len() == 1 && stem.chars().all(|c| c.is_ascii_alphabetic()) {
        stem.to_string()
    } else {
        format!("\\mathit{{{}}}", stem.replace('_', "\\_"))
    };
    if digits.is_empty() {
        stem_tex
    } else {
        format!("{stem_tex}_{{{digits}}}")
    }
}

fn print_dot(graph: &ExprGraph, outputs: &[(String, NodeId)], names: &Names) -> String {
    let ids: Vec<NodeId> = outputs.iter().map(|(_, id)| *id).collect();
    let mark = graph.reachable(&ids);
    let mut s = String::from("digraph expr {\n  rankdir=BT;\n  node [fontname=\"Helvetica\"];\n");
    for (i, node) in graph.nodes().iter().enumerate() {
        if !mark[i] {
            continue;
        }
        let (label, shape) = match *node {
            Node::Const(c) => (format!("{c:?}"), "plaintext"),
            Node::Var(k) => (names.var(k), "ellipse"),
            Node::Param(k) => (names.param(k), "diamond"),
            _ => (node.kind_name().to_string(), "circle"),
        };
        let _ = writeln!(s, "  n{i} [label={label:?}, shape={shape}];");
        let ordered = matches!(
            node,
            Node::Sub(..) | Node::Div(..) | Node::Atan2(..) | Node::Select(..)
        );
        for (k, c) in node.children().into_iter().enumerate() {
            if ordered {
                let _ = writeln!(s, "  n{} -> n{i} [label=\"{k}\"];", c.index());
            } else {
                let _ = writeln!(s, "  n{} -> n{i};", c.index());
            }
        }
    }
    for (k, (name, id)) in outputs.iter().enumerate() {
        let _ = writeln!(s, "  o{k} [label={name:?}, shape=box];");
        let _ = writeln!(s, "  n{} -> o{k};", id.index());
    }
    s.push_str("}\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> (ExprGraph, Vec<(String, NodeId)>, Names) {
        let mut g = ExprGraph::new();
        let x = g.var(0);
        let t = g.param(0);
        let s = g.add(Node::Sin(x));
        let p = g.add(Node::Mul(s, t));
        let q = g.add(Node::Add(p, s));
        let a = g.add(Node::Atan2(q, x));
        let acos = g.add(Node::Acos(p));
        let names = Names {
            vars: vec!["alpha1".into()],
            params: vec!["t".into()],
        };
        (g, vec![("y".into(), a), ("z".into(), acos)], names)
    }

    #[test]
    fn mathematica_argument_order_and_names() {
        let (g, outs, names) = sample();
        let m = print(&g, &outs, &names, Format::Mathematica);
        assert!(m.contains("ArcTan[alpha1, "), "{m}");
        assert!(m.contains("ArcCos[Clip["), "{m}");
        assert!(m.contains("w1 = Sin[alpha1];"), "{m}");
    }

    #[test]
    fn shared_nodes_become_temporaries() {
        let (g, outs, names) = sample();
        let p = print(&g, &outs, &names, Format::Plain);
        assert_eq!(p.matches("sin(alpha1)").count(), 1, "{p}");
        let l = print(&g, &outs, &names, Format::Latex);
        assert!(l.contains("\\sin\\left(\\alpha_{1}\\right)"), "{l}");
    }

    #[test]
    fn right_operands_keep_evaluation_order() {
        let mut g = ExprGraph::new();
        let a = g.var(0);
        let b = g.var(1);
        let c = g.var(2);
        let bc = g.add(Node::Sub(b, c));
        let e = g.add(Node::Sub(a, bc));
        let p = print(&g, &[("e".into(), e)], &Names::default(), Format::Plain);
        assert!(p.contains("e = x0 - (x1 - x2)"), "{p}");
    }

    #[test]
    fn numbers() {
        let mut g = ExprGraph::new();
        let x = g.var(0);
        let k = g.constant(1e-7);
        let m = g.add(Node::Mul(k, x));
        let s = print(
            &g,
            &[("m".into(), m)],
            &Names::default(),
            Format::Mathematica,
        );
        assert!(s.contains("1.*^-7 * x0"), "{s}");
    }
}
