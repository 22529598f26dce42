//! `foldsynth formulas SPEC [--format …] [--simplify] [--gradient] [--symbolic-sectors]
//! [--backend egg|symbolica] [--output FILE]`: the symbolic U, θ, φ of a vertex, with node
//! and operation counts; and the model formulas that `foldsynth model --formulas` prints
//! ([`model_formulas`]).

pub use crate::bench::symbolica::NO_SYMBOLICA;
use crate::compile::simplify::{self, Limits};
use crate::compile::{gradients, vertex::VertexModel};
use crate::expr::{Counts, ExprGraph, Format, Names, NodeId, print::print};
use crate::kinematics::VertexSpec;
use crate::model::Model;
use crate::model::compiled::symbolic;
use anyhow::{Context, Result, bail};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Output formats of `foldsynth formulas`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FormatArg {
    /// Plain infix.
    Plain,
    /// LaTeX (`aligned`).
    Latex,
    /// Mathematica.
    Mathematica,
    /// Python (NumPy) module with `def f(vars, params)`.
    Python,
    /// Graphviz DOT.
    Dot,
}

impl From<FormatArg> for Format {
    fn from(f: FormatArg) -> Format {
        match f {
            FormatArg::Plain => Format::Plain,
            FormatArg::Latex => Format::Latex,
            FormatArg::Mathematica => Format::Mathematica,
            FormatArg::Python => Format::Python,
            FormatArg::Dot => Format::Dot,
        }
    }
}

/// Who simplifies and prints the formulas.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Backend {
    /// foldsynth's own: construction folding, egg, the DAG printers.
    #[default]
    Egg,
    /// Symbolica's canonical form and printer (needs the `symbolica` cargo feature).
    Symbolica,
}

/// Arguments of `foldsynth formulas`.
#[derive(Debug, clap::Args)]
pub struct FormulasArgs {
    /// The vertex in the thesis's notation, e.g. "v(up, ((80,40,40),(t,-t)), ((90,40,50),(t,-t)), (20))".
    pub spec: String,
    /// Output format.
    #[arg(long, value_enum, default_value = "plain")]
    pub format: FormatArg,
    /// Print the formulas after egg simplification (with `--backend symbolica`: hand
    /// Symbolica the egg-simplified graph instead of the graph as built).
    #[arg(long)]
    pub simplify: bool,
    /// Also print the gradients of φ1, φ2, φ3 with respect to the variables (with
    /// `--backend symbolica`: Symbolica's derivatives).
    #[arg(long)]
    pub gradient: bool,
    /// Make the sector angles symbols alpha1…alphan (otherwise they are the spec's numbers
    /// and t is the only variable).
    #[arg(long)]
    pub symbolic_sectors: bool,
    /// Who simplifies and prints: foldsynth (egg) or Symbolica (canonical form; plain,
    /// latex or mathematica; operation counts before and after beside ours).
    #[arg(long, value_enum, default_value = "egg")]
    pub backend: Backend,
    /// Write the formulas to this file instead of standard output.
    #[arg(long, value_name = "FILE")]
    pub output: Option<PathBuf>,
}

/// What `foldsynth formulas` prints: the graph, its named outputs and the counts.
#[derive(Debug)]
pub struct Formulas {
    /// The vertex.
    pub spec: VertexSpec,
    /// The graph holding the printed outputs.
    pub graph: ExprGraph,
    /// The printed outputs: U1…3, theta1…3, phi1…3, then (with `--gradient`)
    /// `dphi{k}_d{var}` for k = 1…3 and every variable.
    pub outputs: Vec<(String, NodeId)>,
    /// Variable and parameter names.
    pub names: Names,
    /// Number of variables.
    pub n_vars: usize,
    /// Number of parameters.
    pub n_params: usize,
    /// Counts of U, θ, φ as built.
    pub before: Counts,
    /// Counts of U, θ, φ after simplification.
    pub after: Counts,
    /// Counts of the printed values.
    pub values: Counts,
    /// Counts of the printed values and gradients (with `--gradient`).
    pub with_gradients: Option<Counts>,
    /// The simplifier's report.
    pub report: simplify::Report,
}

/// Build the formulas `args` asks for.
pub fn formulas(args: &FormulasArgs) -> Result<Formulas> {
    let spec = VertexSpec::parse(&args.spec).context("invalid vertex")?;
    let model = VertexModel::build(&spec, args.symbolic_sectors);
    let named = model.outputs();
    let ids: Vec<NodeId> = named.iter().map(|(_, id)| *id).collect();
    let graph = model.ctx.to_graph();
    let before = graph.counts(&ids);

    let (simplified, s_ids, report) = simplify::simplify(&graph, &ids, &Limits::default());
    let after = simplified.counts(&s_ids);

    let (mut g, mut outs): (ExprGraph, Vec<NodeId>) = if args.simplify {
        (simplified, s_ids)
    } else {
        graph.extract(&ids)
    };
    let mut names: Vec<String> = named.iter().map(|(n, _)| n.clone()).collect();
    let values = g.counts(&outs);
    let mut with_gradients: Option<Counts> = None;
    // Symbolica differentiates on its own side.
    if args.gradient && args.backend == Backend::Egg {
        let phis: Vec<NodeId> = outs[6..9].to_vec();
        let grads = gradients(&mut g, &phis, model.n_vars)?;
        for (k, grad) in grads.into_iter().enumerate() {
            for (i, d) in grad.into_iter().enumerate() {
                names.push(format!("dphi{}_d{}", k + 1, model.names.vars[i]));
                outs.push(d);
            }
        }
        with_gradients = Some(g.counts(&outs));
    }
    Ok(Formulas {
        spec,
        graph: g,
        outputs: names.into_iter().zip(outs).collect(),
        names: model.names,
        n_vars: model.n_vars,
        n_params: model.n_params,
        before,
        after,
        values,
        with_gradients,
        report,
    })
}

/// The comment delimiters of a format (start, end).
fn comment_marks(format: Format) -> (&'static str, &'static str) {
    match format {
        Format::Plain | Format::Python => ("# ", ""),
        Format::Latex => ("% ", ""),
        Format::Mathematica => ("(* ", " *)"),
        Format::Dot => ("// ", ""),
    }
}

/// Header lines as comments of `format`, then `body`.
pub fn with_header(format: Format, head: &[String], body: &str) -> String {
    let (start, end) = comment_marks(format);
    let mut s = String::new();
    for h in head {
        for line in h.lines() {
            s.push_str(start);
            s.push_str(line);
            s.push_str(end);
            s.push('\n');
        }
    }
    s.push_str(body);
    s
}

fn pct(a: usize, b: usize) -> f64 {
    100.0 * (a as f64 - b as f64) / a.max(1) as f64
}

/// The formulas (and counts, as comments) as text in the requested format.
pub fn render(args: &FormulasArgs) -> Result<String> {
    if args.backend == Backend::Symbolica {
        return render_symbolica(args);
    }
    let f = formulas(args)?;
    let format: Format = args.format.into();
    let body = print(&f.graph, &f.outputs, &f.names, format);
    let mut head = vertex_head(&f, args);
    if let Some(c) = f.with_gradients {
        head.push(format!(
            "with the gradients of phi1..3: {} nodes, {} operations",
            c.nodes, c.ops
        ));
    }
    Ok(with_header(format, &head, &body))
}

/// The header lines shared by both backends: the vertex, the names, our counts.
fn vertex_head(f: &Formulas, args: &FormulasArgs) -> Vec<String> {
    let (before, after, values, report) = (f.before, f.after, f.values, &f.report);
    vec![
        format!("vertex {}", f.spec),
        format!(
            "variables: {}; parameters: {}",
            f.names.vars.join(", "),
            f.names.params.join(", ")
        ),
        format!(
            "U, theta, phi as built: {} nodes, {} operations ({} calls)",
            before.nodes, before.ops, before.calls
        ),
        format!(
            "after simplification: {} nodes, {} operations ({} calls), {:.1}% fewer operations ({} e-nodes, {} iterations, {:.1} ms)",
            after.nodes,
            after.ops,
            after.calls,
            pct(before.ops, after.ops),
            report.egraph_nodes,
            report.iterations,
            report.millis
        ),
        format!(
            "printed ({}): {} nodes, {} operations",
            if args.simplify {
                "simplified"
            } else {
                "as built"
            },
            values.nodes,
            values.ops
        ),
    ]
}

#[cfg(feature = "symbolica")]
fn render_symbolica(args: &FormulasArgs) -> Result<String> {
    use crate::compile::symbolica::{self as sym, PrintFormat};
    let format = match args.format {
        FormatArg::Plain => PrintFormat::Plain,
        FormatArg::Latex => PrintFormat::Latex,
        FormatArg::Mathematica => PrintFormat::Mathematica,
        FormatArg::Python | FormatArg::Dot => bail!(
            "--backend symbolica prints plain, latex or mathematica (python and dot come from --backend egg)"
        ),
    };
    let f = formulas(args)?;
    let job = sym::Job {
        graph: f.graph.clone(),
        outputs: f.outputs.clone(),
        names: f.names.clone(),
        n_vars: f.n_vars,
        n_params: f.n_params,
    };
    let printed = sym::print(job, format, args.gradient)?;
    let mut head = vertex_head(&f, args);
    head.extend(printed.header());
    Ok(with_header(args.format.into(), &head, &printed.text))
}

#[cfg(not(feature = "symbolica"))]
fn render_symbolica(_: &FormulasArgs) -> Result<String> {
    bail!("{}", NO_SYMBOLICA)
}

/// Write `text` to `path` (saying so on stderr), or to standard output.
pub fn emit(text: &str, path: Option<&Path>) -> Result<()> {
    match path {
        None => print!("{text}"),
        Some(p) => {
            std::fs::write(p, text)
                .with_context(|| format!("--output: cannot write {}", p.display()))?;
            eprintln!("wrote {} ({} lines)", p.display(), text.lines().count());
        }
    }
    Ok(())
}

/// Run `foldsynth formulas`.
pub fn run(args: FormulasArgs) -> Result<()> {
    emit(&render(&args)?, args.output.as_deref())
}

/// What `foldsynth model --formulas` prints.
#[derive(Clone, Copy, Debug)]
pub struct ModelFormulaOptions {
    /// Output format.
    pub format: Format,
    /// Print the egg-simplified graph (otherwise the graph as built).
    pub simplify: bool,
    /// Also print the gradient of the objective and of every constraint.
    pub gradient: bool,
}

/// Variable names for printers that need identifiers (α_5 → alpha_5, l_2,5 → l_2_5).
pub fn ascii_name(name: &str) -> String {
    name.replace('α', "alpha").replace([',', '\''], "_")
}

/// A model's variable names (ASCII) and parameter names: the modes `M1…`, then the times
/// `t0` (t_max) and the targets' `t1…`.
pub fn model_names(model: &Model) -> Names {
    Names {
        vars: model
            .free
            .iter()
            .map(|&i| ascii_name(&model.plan.variables[i].name))
            .collect(),
        params: (0..model.plan.n_modes)
            .map(|k| format!("M{}", k + 1))
            .chain((0..model.times.len()).map(|k| format!("t{k}")))
            .collect(),
    }
}

/// How many reachable nodes of each kind (`+`, `sin`, …) a graph has.
fn kinds(graph: &ExprGraph, outputs: &[NodeId]) -> BTreeMap<&'static str, usize> {
    let mark = graph.reachable(outputs);
    let mut k = BTreeMap::new();
    for (n, m) in graph.nodes().iter().zip(&mark) {
        if *m && !n.is_leaf() {
            *k.entry(n.kind_name()).or_insert(0) += 1;
        }
    }
    k
}

/// "3 ×, 2 neg" style list of the operations one graph has more of than the other.
fn kind_diff(more: &BTreeMap<&'static str, usize>, less: &BTreeMap<&'static str, usize>) -> String {
    let parts: Vec<String> = more
        .iter()
        .filter_map(|(k, &n)| {
            let m = less.get(k).copied().unwrap_or(0);
            (n > m).then(|| format!("{} {k}", n - m))
        })
        .collect();
    if parts.is_empty() {
        "nothing".to_string()
    } else {
        parts.join(", ")
    }
}

/// Append the gradient of every printed output with respect to the free variables
/// (`names`: the outputs' and the variables'), leaving out the partial derivatives that
/// are identically 0; the header line that says so.
fn add_gradients(
    g: &mut ExprGraph,
    outs: &mut Vec<NodeId>,
    printed: &mut Vec<(String, NodeId)>,
    n_vars: usize,
    (out_names, var_names): (&[String], &[String]),
) -> Result<String> {
    let grads = gradients(g, outs, n_vars)?;
    let mut zeros = 0;
    for (k, grad) in grads.into_iter().enumerate() {
        for (i, d) in grad.into_iter().enumerate() {
            if g.const_value(d) == Some(0.0) {
                zeros += 1;
                continue;
            }
            printed.push((format!("d{}_d{}", out_names[k], var_names[i]), d));
            outs.push(d);
        }
    }
    let c = g.counts(outs);
    Ok(format!(
        "with the gradients (reverse mode on the printed graph): {} operations ({} calls); {zeros} partial derivatives that are identically 0 are left out",
        c.ops, c.calls
    ))
}

/// The header's first lines: the model, its variables, parameters and constraints.
fn model_head(model: &Model, task: &str, names: &Names, n_constraints: usize) -> Vec<String> {
    let n_modes = model.plan.n_modes;
    let labels: Vec<String> = (0..n_constraints)
        .map(|k| format!("  g{} = {}", k + 1, model.constraint_label(k)))
        .collect();
    let times: Vec<String> = model
        .times
        .iter()
        .enumerate()
        .map(|(k, t)| {
            format!(
                "t{k} = {t:?}{}",
                if k == 0 { " (t_max)" } else { " (target)" }
            )
        })
        .collect();
    let mut head = vec![
        format!(
            "model {} of task '{task}', gripping vertex v{} (candidate {}): objective and {} constraints g >= 0",
            model.plan.sequence,
            model.plan.vertices[model.gripping].name,
            model.candidate + 1,
            n_constraints
        ),
        format!("variables: {}", names.vars.join(", ")),
        format!(
            "parameters: {} (rigid body modes, +1 up, -1 down); {}",
            names.params[..n_modes].join(", "),
            times.join(", ")
        ),
        "constraints:".to_string(),
    ];
    head.extend(labels);
    head
}

/// Sizes of the model's graph at each stage.
struct Stages {
    /// As built.
    before: Counts,
    /// After egg.
    after: Counts,
    /// As printed (before or after egg, without gradients).
    printed: Counts,
    /// Operations by kind, as built.
    kinds_before: BTreeMap<&'static str, usize>,
    /// Operations by kind, after egg.
    kinds_after: BTreeMap<&'static str, usize>,
}

/// The header's lines on what construction and egg removed, and what is printed.
fn stage_lines(s: &Stages, rep: &simplify::Report, simplified: bool) -> [String; 7] {
    let mut fired: Vec<String> = rep
        .rules_fired
        .iter()
        .filter(|(r, _)| !r.starts_with("comm-"))
        .map(|(r, n)| format!("{r} {n}"))
        .collect();
    if fired.is_empty() {
        fired.push("none".to_string());
    }
    [
        format!(
            "as built: {} operations ({} calls); construction already folds constants and exact identities (x*1, x+0, -(-x), (-x)-y = -(x+y), x*0 and x-x where x is proven finite)",
            s.before.ops, s.before.calls
        ),
        format!(
            "egg: {} operations ({} calls), {:.1}% fewer; {} e-nodes, {} iterations ({}), {:.1} ms",
            s.after.ops,
            s.after.calls,
            pct(s.before.ops, s.after.ops),
            rep.egraph_nodes,
            rep.iterations,
            rep.stop_reason,
            rep.millis
        ),
        format!(
            "  then {} zero terms (0*x, x-x) removed beside a term that is NaN wherever they are (x not provably finite)",
            rep.vanishing_terms
        ),
        format!(
            "  egg removed: {}",
            kind_diff(&s.kinds_before, &s.kinds_after)
        ),
        format!(
            "  egg added: {}",
            kind_diff(&s.kinds_after, &s.kinds_before)
        ),
        format!(
            "  rules that fired (e-graph applications, commutativity left out): {}",
            fired.join(", ")
        ),
        format!(
            "printed: the graph {} ({} operations){}",
            if simplified {
                "after egg"
            } else {
                "as built (--no-simplify)"
            },
            s.printed.ops,
            if simplified {
                "; --no-simplify prints it as built"
            } else {
                ""
            }
        ),
    ]
}

/// The objective and constraint formulas of `model` (task `task`), with a header that says
/// what every simplification stage removed.
pub fn model_formulas(model: &Model, task: &str, opts: ModelFormulaOptions) -> Result<String> {
    let (ctx, outputs) = symbolic(model);
    let ids: Vec<NodeId> = outputs.iter().map(|o| ctx.node_id(o)).collect();
    let graph = ctx.to_graph();
    let mut out_names = vec!["objective".to_string()];
    out_names.extend((1..ids.len()).map(|k| format!("g{k}")));
    let names = model_names(model);

    let before = graph.counts(&ids);
    let (simplified, s_ids, rep) = simplify::simplify(&graph, &ids, &Limits::default());
    let (mut g, mut outs) = if opts.simplify {
        (simplified.clone(), s_ids.clone())
    } else {
        graph.extract(&ids)
    };
    let values = g.counts(&outs);
    let mut printed: Vec<(String, NodeId)> = out_names.iter().cloned().zip(outs.clone()).collect();
    let gradient_line = if opts.gradient {
        let n_vars = model.free.len();
        let named = (&out_names[..], &names.vars[..]);
        Some(add_gradients(
            &mut g,
            &mut outs,
            &mut printed,
            n_vars,
            named,
        )?)
    } else {
        None
    };
    let stages = Stages {
        before,
        after: simplified.counts(&s_ids),
        printed: values,
        kinds_before: kinds(&graph, &ids),
        kinds_after: kinds(&simplified, &s_ids),
    };
    let mut head = model_head(model, task, &names, ids.len() - 1);
    head.extend(stage_lines(&stages, &rep, opts.simplify));
    head.extend(gradient_line);
    let body = print(&g, &printed, &names, opts.format);
    Ok(with_header(opts.format, &head, &body))
}
