//! Our expression DAG as Symbolica expressions, and Symbolica's derivatives of them.
//!
//! Symbolica's expressions are trees; ours share subexpressions, and the gripper model's
//! tree would have ~5·10⁷ nodes. So every node used more than once becomes an *alias*
//! `w{k}` (a symbol standing for its body, as Symbolica's own `AliasedAtom` and the
//! evaluator's `add_aliases` do), and each body is a small tree over variables,
//! parameters and earlier aliases. Symbolica normalizes every body to its canonical form.
//!
//! Derivatives: Symbolica differentiates every body with respect to the variables and to
//! the aliases it contains; the chain rule through the aliases is assembled forward
//! (`dw_k/dx = ∂b_k/∂x + Σ_j ∂b_k/∂w_j · dw_j/dx`), each total derivative again an alias.
//!
//! Our `acos` is Symbolica's own `acos` of our clamp. The others (`atan2`, `sgn`,
//! `clamp`, `select`) are symbols with a numeric implementation (for its evaluator and
//! JIT), a derivative rule and a Mathematica/LaTeX spelling. `atan2` is ours, not
//! Symbolica's two-argument `atan(x, y)`, because SymJIT 2.28 (under Symbolica 3.0.0)
//! maps `atan` to its one-argument `arctan` whatever the argument count, so the JIT
//! computes `atan(x)` where Symbolica's evaluator computes `atan2(y, x)` (symjit's
//! `Config::symbolica_fun` and `translate_external_fun`). All derivatives are the plain
//! mathematical ones (no guards): they agree with ours wherever the function is smooth.

use crate::expr::{ExprGraph, Names, Node, NodeId, clamp_unit, select};
use crate::kinematics::sgn_f64;
use ::symbolica::atom::{Atom, AtomCore, AtomView, EvaluationInfo, Symbol, SymbolBuilder};
use ::symbolica::{function, try_parse, wrap_symbol};
use numerica_print::{PrintOptions, PrintState};
use std::collections::BTreeSet;
use std::sync::OnceLock;

/// The printer types, re-exported by Symbolica from its numerics crate.
mod numerica_print {
    pub use ::symbolica::printer::{PrintOptions, PrintState};
}

/// The custom function symbols (built once per process, on the Symbolica thread).
#[derive(Clone, Copy)]
pub(super) struct Funcs {
    /// Symbolica's own `acos` (its derivative, its Mathematica name); ours clamps its
    /// argument, so our `acos(x)` is its `acos(clamp(x))`.
    acos: Symbol,
    /// `atan2(y, x)`.
    atan2: Symbol,
    sgn: Symbol,
    clamp: Symbol,
    select: Symbol,
}

fn args(view: AtomView) -> Vec<Atom> {
    match view {
        AtomView::Fun(f) => f.iter().map(|a| a.to_owned()).collect(),
        _ => Vec::new(),
    }
}

fn show(a: &Atom, opts: &PrintOptions) -> String {
    format!("{}", a.printer(opts.clone()))
}

/// A print hook: `math` and `latex` spell the call from its printed arguments.
type Spell = fn(&[String]) -> String;

fn spelled(b: SymbolBuilder, math: Spell, latex: Spell) -> SymbolBuilder {
    b.with_print_function(move |view, opts, _state: &PrintState| {
        let f: Spell = if opts.mode.is_mathematica() {
            math
        } else if opts.mode.is_latex() {
            latex
        } else {
            return None;
        };
        let a: Vec<String> = args(view).iter().map(|x| show(x, opts)).collect();
        Some(f(&a))
    })
}

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// The `select` symbol, for the derivative rules that produce selects (set once, by
/// [`Funcs::new`], before any derivative is taken).
static SELECT: OnceLock<Symbol> = OnceLock::new();

/// `select(c, a, b)`.
fn sel(c: &Atom, a: Atom, b: Atom) -> Atom {
    let s = *SELECT
        .get()
        .expect("Funcs::new sets the select symbol before any derivative");
    function!(s, c, a, b)
}

impl Funcs {
    pub(super) fn new() -> Result<Funcs, String> {
        let one = || Atom::num(1);
        let zero = || Atom::num(0);
        let select = spelled(
            SymbolBuilder::new(wrap_symbol!("select")),
            |a| format!("If[{} > 0, {}, {}]", a[0], a[1], a[2]),
            |a| {
                format!(
                    "\\begin{{cases}} {} & {} > 0 \\\\ {} & \\text{{otherwise}} \\end{{cases}}",
                    a[1], a[0], a[2]
                )
            },
        )
        .with_evaluation_info(EvaluationInfo::new().register(|x: &[f64]| select(x[0], x[1], x[2])))
        // d select(c, a, b) = select(c, da, db): c is not differentiated.
        .with_derivative_function(move |view, arg, out| {
            let x = args(view);
            **out = match arg {
                1 => sel(&x[0], one(), zero()),
                2 => sel(&x[0], zero(), one()),
                _ => zero(),
            };
        })
        .build()
        .map_err(err)?;
        let _ = SELECT.set(select);
        // Not Symbolica's two-argument `atan`: SymJIT (symjit 2.28.3) evaluates `atan(x, y)`
        // as the one-argument `atan(x)` (Symbolica's evaluator without JIT is right). The
        // JIT calls this one back through its f64 implementation.
        let atan2 = spelled(
            SymbolBuilder::new(wrap_symbol!("atan2")),
            // Mathematica's ArcTan takes x first.
            |a| format!("ArcTan[{}, {}]", a[1], a[0]),
            |a| format!("\\operatorname{{atan2}}\\left({}, {}\\right)", a[0], a[1]),
        )
        .with_evaluation_info(EvaluationInfo::new().register(|x: &[f64]| x[0].atan2(x[1])))
        .with_derivative_function(move |view, arg, out| {
            let a = args(view);
            let (y, x) = (&a[0], &a[1]);
            let r = x * x + y * y;
            **out = if arg == 0 { x / &r } else { -(y / &r) };
        })
        .build()
        .map_err(err)?;
        let sgn = spelled(
            SymbolBuilder::new(wrap_symbol!("sgn")),
            |a| format!("Sign[{}]", a[0]),
            |a| format!("\\operatorname{{sgn}}\\left({}\\right)", a[0]),
        )
        .with_evaluation_info(EvaluationInfo::new().register(|x: &[f64]| sgn_f64(x[0])))
        .with_derivative_function(move |_, _, out| **out = zero())
        .build()
        .map_err(err)?;
        let clamp = spelled(
            SymbolBuilder::new(wrap_symbol!("clamp")),
            |a| format!("Clip[{}, {{-1, 1}}]", a[0]),
            |a| format!("\\operatorname{{clamp}}_{{[-1,1]}}\\left({}\\right)", a[0]),
        )
        .with_evaluation_info(EvaluationInfo::new().register(|x: &[f64]| clamp_unit(x[0])))
        .with_derivative_function(move |view, _arg, out| {
            let x = &args(view)[0];
            // 1 inside (-1, 1), 0 outside.
            **out = sel(&((one() - x) * (one() + x)), one(), zero());
        })
        .build()
        .map_err(err)?;
        Ok(Funcs {
            acos: ::symbolica::transcendental::acos(),
            atan2,
            sgn,
            clamp,
            select,
        })
    }
}

/// An f64 constant as a Symbolica number: an integer, a small dyadic fraction or a
/// rational multiple of π (the sector bounds 10°, 170°, 2π), anything else as the exact
/// rational of its shortest decimal text (`1e-8` is `1/100000000`). Non-finite constants
/// have no Symbolica number.
fn number(c: f64) -> Result<Atom, String> {
    use std::f64::consts::PI;
    if !c.is_finite() {
        return Err(format!("the constant {c} has no Symbolica number"));
    }
    const EXACT: f64 = 9007199254740992.0; // 2^53
    for k in 0..=10 {
        let d = (1u64 << k) as f64;
        let m = c * d;
        if m == m.trunc() && m.abs() < EXACT {
            return Ok(Atom::num((m as i64, 1i64 << k)));
        }
    }
    const DENOMINATORS: [i64; 22] = [
        1, 2, 3, 4, 5, 6, 8, 9, 10, 12, 15, 18, 20, 24, 30, 36, 45, 60, 72, 90, 180, 360,
    ];
    for q in DENOMINATORS {
        let p = (c * q as f64 / PI).round();
        if p == 0.0 || p.abs() > 8.0 * q as f64 {
            continue;
        }
        let (pf, qf) = (p, q as f64);
        let forms = [
            pf * PI / qf,
            pf / qf * PI,
            pf * (PI / qf),
            (pf * 180.0 / qf).to_radians(),
        ];
        if forms.contains(&c) {
            return Ok(Atom::num((p as i64, q)) * Atom::var(Symbol::PI));
        }
    }
    // The exact rational of the shortest decimal text that reads back as `c`, e.g.
    // 1.7453292519943295e-1 → 17453292519943295/10^17. (Not a Symbolica float: with the
    // pure-Rust float backend, Symbolica 3.0.0 prints floats without their exponent.)
    let text = format!("{c:e}");
    let (mant, exp) = text.split_once('e').ok_or("float formatting")?;
    let exp: i64 = exp.parse().map_err(err)?;
    let (int, frac) = mant.split_once('.').unwrap_or((mant, ""));
    let digits = format!("{int}{frac}");
    let shift = exp - frac.len() as i64;
    let expr = if shift >= 0 {
        format!("{digits}*10^{shift}")
    } else {
        format!("{digits}/10^{}", -shift)
    };
    try_parse!(&expr).map_err(err)
}

/// Our graph as Symbolica expressions with aliases for the shared nodes.
pub(super) struct Converted {
    /// The symbols of the variables, then of the parameters (the evaluator's inputs).
    pub inputs: Vec<Atom>,
    /// Variable symbols.
    pub vars: Vec<Symbol>,
    /// Names of the variables as printed (for derivative names).
    pub var_names: Vec<String>,
    /// The aliases in dependency order: symbol, body.
    pub aliases: Vec<(Atom, Atom)>,
    /// Per alias, the earlier aliases its body contains (indices into `aliases`).
    alias_refs: Vec<Vec<usize>>,
    /// The outputs: name, expression.
    pub outputs: Vec<(String, Atom)>,
    /// Per output, the aliases its expression contains.
    output_refs: Vec<Vec<usize>>,
    /// Alias symbol names are this prefix plus a number.
    prefix: String,
}

/// A name that is a valid identifier in Symbolica, Mathematica and LaTeX text alike, and
/// not one of Symbolica's built-in functions or constants.
fn ident(name: &str) -> String {
    let mut s: String = name.chars().filter(|c| c.is_ascii_alphanumeric()).collect();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert(0, 'x');
    }
    // Single capitals that are Mathematica built-ins, and Symbolica's built-in names.
    if ["C", "D", "E", "I", "K", "N", "O"].contains(&s.as_str())
        || ::symbolica::state::State::is_builtin(&s)
        || ["acos", "atan2", "sgn", "clamp", "select", "pi"].contains(&s.as_str())
    {
        s.insert(0, 'v');
    }
    s
}

fn symbol(name: &str) -> Result<Symbol, String> {
    SymbolBuilder::new(wrap_symbol!(name)).build().map_err(err)
}

/// Convert `outputs` of `graph` (names from `names`, missing ones `x{i}`, `p{i}`).
pub(super) fn convert(
    funcs: &Funcs,
    graph: &ExprGraph,
    outputs: &[(String, NodeId)],
    names: &Names,
    n_vars: usize,
    n_params: usize,
) -> Result<Converted, String> {
    let var_names: Vec<String> = (0..n_vars)
        .map(|i| ident(names.vars.get(i).map_or(&format!("x{i}"), |s| s)))
        .collect();
    let param_names: Vec<String> = (0..n_params)
        .map(|i| ident(names.params.get(i).map_or(&format!("p{i}"), |s| s)))
        .collect();
    let vars = var_names
        .iter()
        .map(|n| symbol(n))
        .collect::<Result<Vec<_>, _>>()?;
    let params = param_names
        .iter()
        .map(|n| symbol(n))
        .collect::<Result<Vec<_>, _>>()?;
    // An alias prefix that no input name can collide with.
    let mut prefix = "w".to_string();
    while var_names.iter().chain(&param_names).any(|n| {
        n.strip_prefix(prefix.as_str())
            .is_some_and(|r| r.chars().all(|c| c.is_ascii_digit() || c == '_'))
    }) {
        prefix.push('w');
    }

    let ids: Vec<NodeId> = outputs.iter().map(|(_, id)| *id).collect();
    let mark = graph.reachable(&ids);
    let mut uses = vec![0u32; graph.len()];
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
    // Per node: its expression (an alias symbol for shared nodes) and the aliases in it.
    let mut repr: Vec<Option<Atom>> = vec![None; graph.len()];
    let mut refs: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); graph.len()];
    let mut aliases: Vec<(Atom, Atom)> = Vec::new();
    let mut alias_refs: Vec<Vec<usize>> = Vec::new();
    for i in 0..graph.len() {
        if !mark[i] {
            continue;
        }
        let node = &graph.nodes()[i];
        let mut r = BTreeSet::new();
        let mut a: Vec<Atom> = Vec::with_capacity(3);
        for c in node.children() {
            r.extend(refs[c.index()].iter().copied());
            let e = if uses[c.index()] > 1 {
                // An alias symbol or a leaf.
                repr[c.index()].clone()
            } else {
                // Used once: move it.
                repr[c.index()].take()
            };
            a.push(e.ok_or("a node's operand was not converted")?);
        }
        let e = match *node {
            Node::Const(c) => number(c)?,
            Node::Var(k) => Atom::var(vars[k as usize]),
            Node::Param(k) => Atom::var(params[k as usize]),
            Node::Add(..) => &a[0] + &a[1],
            Node::Sub(..) => &a[0] - &a[1],
            Node::Mul(..) => &a[0] * &a[1],
            Node::Div(..) => &a[0] / &a[1],
            Node::Neg(_) => -&a[0],
            Node::Sin(_) => function!(Symbol::SIN, &a[0]),
            Node::Cos(_) => function!(Symbol::COS, &a[0]),
            Node::Sqrt(_) => function!(Symbol::SQRT, &a[0]),
            Node::Acos(_) => function!(funcs.acos, function!(funcs.clamp, &a[0])),
            Node::Atan2(..) => function!(funcs.atan2, &a[0], &a[1]),
            Node::Sgn(_) => function!(funcs.sgn, &a[0]),
            Node::Clamp(_) => function!(funcs.clamp, &a[0]),
            Node::Select(..) => function!(funcs.select, &a[0], &a[1], &a[2]),
        };
        if uses[i] > 1 && !node.is_leaf() {
            let k = aliases.len();
            let w = Atom::var(symbol(&format!("{prefix}{}", k + 1))?);
            aliases.push((w.clone(), e));
            alias_refs.push(r.into_iter().collect());
            repr[i] = Some(w);
            refs[i] = BTreeSet::from([k]);
        } else {
            repr[i] = Some(e);
            refs[i] = r;
        }
    }
    let mut outs = Vec::with_capacity(outputs.len());
    let mut output_refs = Vec::with_capacity(outputs.len());
    for (name, id) in outputs {
        let e = repr[id.index()]
            .clone()
            .ok_or("an output was not converted")?;
        outs.push((name.clone(), e));
        output_refs.push(refs[id.index()].iter().copied().collect());
    }
    let mut inputs: Vec<Atom> = vars.iter().map(|s| Atom::var(*s)).collect();
    inputs.extend(params.iter().map(|s| Atom::var(*s)));
    Ok(Converted {
        inputs,
        vars,
        var_names,
        aliases,
        alias_refs,
        outputs: outs,
        output_refs,
        prefix,
    })
}

/// Symbolica's gradients of the outputs: per output, one expression per variable, with the
/// aliases of the total derivatives of the aliases (in dependency order).
pub(super) struct Gradients {
    /// `d{w}_{x}` → the total derivative of alias `w` with respect to `x`.
    pub aliases: Vec<(Atom, Atom)>,
    /// Per output, its partial derivatives with respect to every variable.
    pub outputs: Vec<Vec<Atom>>,
}

/// Differentiate the converted outputs with Symbolica, the chain rule through the aliases
/// assembled forward (see the module documentation).
pub(super) fn gradients(c: &Converted) -> Result<Gradients, String> {
    let n = c.vars.len();
    let alias_syms: Vec<Symbol> = c
        .aliases
        .iter()
        .map(|(w, _)| match w.as_view() {
            AtomView::Var(v) => Ok(v.get_symbol()),
            _ => Err("an alias is not a symbol".to_string()),
        })
        .collect::<Result<_, _>>()?;
    // The total derivative of alias k with respect to variable i, if it is not zero.
    let mut total: Vec<Vec<Option<Atom>>> = Vec::with_capacity(c.aliases.len());
    let mut out_aliases = Vec::new();
    let chain = |body: &Atom, refs: &[usize], total: &[Vec<Option<Atom>>]| -> Vec<Atom> {
        // Partials with respect to the aliases, once for all variables.
        let partials: Vec<(usize, Atom)> = refs
            .iter()
            .filter(|&&j| total[j].iter().any(Option::is_some))
            .map(|&j| (j, body.derivative(alias_syms[j])))
            .filter(|(_, d)| !d.is_zero())
            .collect();
        (0..n)
            .map(|i| {
                let mut d = body.derivative(c.vars[i]);
                for (j, p) in &partials {
                    if let Some(dw) = &total[*j][i] {
                        d += p * dw;
                    }
                }
                d
            })
            .collect()
    };
    for (k, (_, body)) in c.aliases.iter().enumerate() {
        let ds = chain(body, &c.alias_refs[k], &total);
        let mut row = Vec::with_capacity(n);
        for (i, d) in ds.into_iter().enumerate() {
            if d.is_zero() {
                row.push(None);
            } else {
                let name = format!("d{}{}_{}", c.prefix, k + 1, c.var_names[i]);
                let s = Atom::var(symbol(&name)?);
                out_aliases.push((s.clone(), d));
                row.push(Some(s));
            }
        }
        total.push(row);
    }
    let outputs = c
        .outputs
        .iter()
        .zip(&c.output_refs)
        .map(|((_, e), refs)| chain(e, refs, &total))
        .collect();
    Ok(Gradients {
        aliases: out_aliases,
        outputs,
    })
}
