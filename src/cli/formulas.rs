//! `foldsynth formulas SPEC [--format …] [--simplify] [--gradient] [--symbolic-sectors]`:
//! the symbolic U, θ, φ of a vertex, with node and operation counts.

use crate::compile::simplify::{self, Limits};
use crate::compile::{gradients, vertex::VertexModel};
use crate::expr::{Counts, ExprGraph, Format, Names, NodeId, print::print};
use crate::kinematics::VertexSpec;
use anyhow::{Context, Result};

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

/// Arguments of `foldsynth formulas`.
#[derive(Debug, clap::Args)]
pub struct FormulasArgs {
    /// The vertex in the thesis's notation, e.g. "v(up, ((80,40,40),(t,-t)), ((90,40,50),(t,-t)), (20))".
    pub spec: String,
    /// Output format.
    #[arg(long, value_enum, default_value = "plain")]
    pub format: FormatArg,
    /// Print the formulas after egg simplification.
    #[arg(long)]
    pub simplify: bool,
    /// Also print the gradients of φ1, φ2, φ3 with respect to the variables.
    #[arg(long)]
    pub gradient: bool,
    /// Make the sector angles symbols alpha1…alphan (otherwise they are the spec's numbers
    /// and t is the only variable).
    #[arg(long)]
    pub symbolic_sectors: bool,
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
    if args.gradient {
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

/// The formulas (and counts, as comments) as text in the requested format.
pub fn render(args: &FormulasArgs) -> Result<String> {
    let f = formulas(args)?;
    let format: Format = args.format.into();
    let body = print(&f.graph, &f.outputs, &f.names, format);
    let (spec, before, after, values, report) = (&f.spec, f.before, f.after, f.values, &f.report);
    let model_names = &f.names;
    let comment = match format {
        Format::Plain | Format::Python => "# ",
        Format::Latex => "% ",
        Format::Mathematica => "(* ",
        Format::Dot => "// ",
    };
    let end = if format == Format::Mathematica {
        " *)"
    } else {
        ""
    };
    let pct = |a: usize, b: usize| 100.0 * (a as f64 - b as f64) / a.max(1) as f64;
    let mut head = vec![
        format!("vertex {spec}"),
        format!(
            "variables: {}; parameters: {}",
            model_names.vars.join(", "),
            model_names.params.join(", ")
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
    ];
    if let Some(c) = f.with_gradients {
        head.push(format!(
            "with the gradients of phi1..3: {} nodes, {} operations",
            c.nodes, c.ops
        ));
    }
    let mut s = String::new();
    for h in head {
        s.push_str(comment);
        s.push_str(&h);
        s.push_str(end);
        s.push('\n');
    }
    s.push_str(&body);
    Ok(s)
}

/// Run `foldsynth formulas`.
pub fn run(args: FormulasArgs) -> Result<()> {
    print!("{}", render(&args)?);
    Ok(())
}
