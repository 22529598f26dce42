//! `foldsynth enumerate`: generate every crease pattern graph of a task (thesis Table 3)
//! and report the search tree.

use std::path::PathBuf;

use anyhow::Context;
use serde::Serialize;

use crate::grammar::{Enumeration, Filters, Status};
use crate::limits::{GRAPHS_MAX, N_MAX};
use crate::task::Task;

/// Output format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// A table per level and the meaningful sequences.
    Text,
    /// One JSON object listing every generated graph.
    Json,
}

/// Arguments of `foldsynth enumerate`.
#[derive(Debug, clap::Args)]
pub struct EnumerateArgs {
    /// The task file (e.g. grammar/gripper.toml).
    pub task: PathBuf,
    /// Maximum number of internal vertices (default: the task's grammar.n_max), 0 to 6.
    #[arg(long, value_parser = crate::limits::count::<0, { N_MAX as u64 }>)]
    pub n_max: Option<usize>,
    /// Keep graphs isomorphic to earlier ones.
    #[arg(long)]
    pub no_iso: bool,
    /// Keep mirror images (for tasks symmetric about the xz-plane).
    #[arg(long)]
    pub no_mirror: bool,
    /// Count semantically invalid graphs as meaningful.
    #[arg(long)]
    pub no_validity: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    pub format: Format,
    /// Write the search tree (Fig. 48) as Graphviz DOT to this file.
    #[arg(long, value_name = "FILE.dot")]
    pub tree: Option<PathBuf>,
}

#[derive(Serialize)]
struct Filtered {
    isomorphic: usize,
    mirror: usize,
    invalid: usize,
}

#[derive(Serialize)]
struct GraphEntry {
    sequence: String,
    level: usize,
    internal_vertices: usize,
    status: Status,
    /// Index of the parent in `graphs`; null for children of G0.
    parent: Option<usize>,
    /// 2^N × 3 for meaningful graphs, else 0.
    alternatives: u64,
}

#[derive(Serialize)]
struct Report {
    generated: usize,
    filtered: Filtered,
    alternatives: u64,
    graphs: Vec<GraphEntry>,
}

/// Run `foldsynth enumerate`.
pub fn run(args: EnumerateArgs) -> anyhow::Result<()> {
    let task = Task::load(&args.task)?;
    let n_max = args.n_max.unwrap_or(task.n_max);
    let filters = Filters {
        isomorphism: !args.no_iso,
        mirror: !args.no_mirror,
        validity: !args.no_validity,
    };
    // Every generated graph is kept (about 15 kB each): what does not fit the budget is
    // refused with its estimated size, before memory runs out.
    let e = Enumeration::run_within(&task, n_max, filters, GRAPHS_MAX)
        .map_err(|est| anyhow::anyhow!("{}", est.refusal(&task.name, n_max, filters)))?;
    if let Some(path) = &args.tree {
        std::fs::write(path, e.to_dot())
            .with_context(|| format!("cannot write the search tree to {}", path.display()))?;
    }
    match args.format {
        Format::Json => {
            let report = Report {
                generated: e.nodes.len(),
                filtered: Filtered {
                    isomorphic: e.count(Status::Isomorphic),
                    mirror: e.count(Status::Mirror),
                    invalid: e.count(Status::Invalid),
                },
                alternatives: e.alternatives(),
                graphs: e
                    .nodes
                    .iter()
                    .map(|n| GraphEntry {
                        sequence: n.graph.sequence(),
                        level: n.level,
                        internal_vertices: n.graph.internal_count(),
                        status: n.status,
                        parent: n.parent,
                        alternatives: if n.status == Status::Meaningful {
                            n.graph.alternatives()
                        } else {
                            0
                        },
                    })
                    .collect(),
            };
            println!("{}", serde_json::to_string_pretty(&report)?);
        }
        Format::Text => print!("{}", text_report(&task, &e, &args)),
    }
    Ok(())
}

fn on(b: bool) -> &'static str {
    if b { "on" } else { "off" }
}

fn text_report(task: &Task, e: &Enumeration, args: &EnumerateArgs) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "task: {} ({}), N_max = {}",
        task.name,
        args.task.display(),
        e.n_max
    );
    let mirror = if e.filters.mirror && !e.mirror_applied {
        "off (task not mirror-symmetric)"
    } else {
        on(e.mirror_applied)
    };
    let _ = writeln!(
        s,
        "filters: isomorphism {}, mirror {}, semantic validity {}",
        on(e.filters.isomorphism),
        mirror,
        on(e.filters.validity)
    );
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "level  generated  isomorphic  mirror  invalid  meaningful"
    );
    let mut total = crate::grammar::LevelCounts::default();
    for c in e.level_counts() {
        let _ = writeln!(
            s,
            "{:>5}  {:>9}  {:>10}  {:>6}  {:>7}  {:>10}",
            c.level, c.generated, c.isomorphic, c.mirror, c.invalid, c.meaningful
        );
        total.generated += c.generated;
        total.isomorphic += c.isomorphic;
        total.mirror += c.mirror;
        total.invalid += c.invalid;
        total.meaningful += c.meaningful;
    }
    let _ = writeln!(
        s,
        "total  {:>9}  {:>10}  {:>6}  {:>7}  {:>10}",
        total.generated, total.isomorphic, total.mirror, total.invalid, total.meaningful
    );
    let _ = writeln!(s);
    let _ = writeln!(s, "meaningful graphs ({}):", total.meaningful);
    for n in e.meaningful() {
        let _ = writeln!(
            s,
            "  {:<28} N = {}  alternatives = {}",
            n.graph.sequence(),
            n.graph.internal_count(),
            n.graph.alternatives()
        );
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "design alternatives: {} (sum over meaningful graphs of 2^N RBM assignments x 3 gripping candidates)",
        e.alternatives()
    );
    if let Some(t) = &args.tree {
        let _ = writeln!(s, "search tree written to {}", t.display());
    }
    s
}
