//! `foldsynth enumerate`: generate every crease pattern graph of a task (thesis Table 3)
//! and report the search tree.

use std::path::PathBuf;

use std::io::{BufWriter, Write};

use anyhow::Context;
use serde::Serialize;

use crate::grammar::{
    DOT_FOOTER, Enumeration, Filters, LevelCounts, Rules, Status, dot_header, dot_node,
};
use crate::limits::N_MAX;
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
    /// The grammar's rules: r1,r2 (the thesis's, default) or r1,r2,r2p (with r2′).
    #[arg(long, default_value = "r1,r2", value_name = "RULES")]
    pub rules: Rules,
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
    /// Closed a cycle by r2′ (only listed with r2′ enabled).
    #[serde(skip_serializing_if = "Option::is_none")]
    cyclic: Option<bool>,
}

/// One meaningful graph for the text report.
struct Meaningful {
    sequence: String,
    n: usize,
    alternatives: u64,
}

/// With r2′: the cyclic share of the language.
#[derive(Default, Serialize)]
struct CyclicSummary {
    generated: usize,
    meaningful: usize,
    alternatives: u64,
}

/// Run `foldsynth enumerate`. The graphs stream: each is written (JSON, DOT) or counted
/// as it is generated and then dropped, so N_max = 5 and 6 run in bounded memory.
pub fn run(args: EnumerateArgs) -> anyhow::Result<()> {
    let task = Task::load(&args.task)?;
    let n_max = args.n_max.unwrap_or(task.n_max);
    let filters = Filters {
        isomorphism: !args.no_iso,
        mirror: !args.no_mirror,
        validity: !args.no_validity,
    };
    let mut dot = match &args.tree {
        Some(path) => {
            let f = std::fs::File::create(path)
                .with_context(|| format!("cannot write the search tree to {}", path.display()))?;
            let mut w = BufWriter::new(f);
            w.write_all(dot_header(n_max).as_bytes())?;
            Some((path, w))
        }
        None => None,
    };
    let json = args.format == Format::Json;
    let mut out = BufWriter::new(std::io::stdout().lock());
    if json {
        // The graphs first (streamed), the totals after them.
        out.write_all(b"{\n  \"graphs\": [")?;
    }
    let mut levels: Vec<LevelCounts> = Vec::new();
    let mut meaningful: Vec<Meaningful> = Vec::new();
    let mut alternatives = 0u64;
    let mut failed: Option<std::io::Error> = None;
    let rules = args.rules;
    let mut cyclic = CyclicSummary::default();
    let streamed = Enumeration::stream_with(&task, n_max, filters, rules, |g| {
        LevelCounts::count(&mut levels, g.level, g.status);
        let alt = if g.status == Status::Meaningful {
            g.graph.alternatives()
        } else {
            0
        };
        alternatives += alt;
        let is_cyclic = rules.r2p && g.graph.is_cyclic_pattern();
        if is_cyclic {
            cyclic.generated += 1;
            cyclic.meaningful += usize::from(g.status == Status::Meaningful);
            cyclic.alternatives += alt;
        }
        if failed.is_some() {
            return;
        }
        let written = (|| -> std::io::Result<()> {
            if let Some((_, w)) = &mut dot {
                w.write_all(dot_node(&g).as_bytes())?;
            }
            if json {
                let entry = GraphEntry {
                    sequence: g.graph.sequence(),
                    level: g.level,
                    internal_vertices: g.graph.internal_count(),
                    status: g.status,
                    parent: g.parent,
                    alternatives: alt,
                    cyclic: rules.r2p.then_some(is_cyclic),
                };
                let sep = if g.index == 0 { "" } else { "," };
                write!(out, "{sep}\n    {}", serde_json::to_string(&entry)?)?;
            } else if g.status == Status::Meaningful {
                meaningful.push(Meaningful {
                    sequence: g.graph.sequence(),
                    n: g.graph.internal_count(),
                    alternatives: alt,
                });
            }
            Ok(())
        })();
        if let Err(e) = written {
            failed = Some(e);
        }
    });
    if let Some(e) = failed {
        return Err(e).context("cannot write the enumeration");
    }
    if let Some((path, mut w)) = dot {
        w.write_all(DOT_FOOTER.as_bytes())
            .and_then(|_| w.flush())
            .with_context(|| format!("cannot write the search tree to {}", path.display()))?;
    }
    let total = |f: fn(&LevelCounts) -> usize| levels.iter().map(f).sum::<usize>();
    if json {
        let mut tail = serde_json::json!({
            "generated": streamed.generated,
            "filtered": {
                "isomorphic": total(|c| c.isomorphic),
                "mirror": total(|c| c.mirror),
                "invalid": total(|c| c.invalid),
            },
            "alternatives": alternatives,
        });
        if rules.r2p {
            tail["rules"] = serde_json::json!(rules.names());
            tail["cyclic"] = serde_json::to_value(&cyclic)?;
        }
        let tail = serde_json::to_string_pretty(&tail)?;
        // The totals' fields, after the graphs, in the same object.
        let fields = tail
            .trim()
            .trim_start_matches('{')
            .trim_end_matches('}')
            .trim_end();
        writeln!(out, "\n  ],{fields}\n}}")?;
    } else {
        let report = text_report(
            &task,
            &args,
            n_max,
            filters,
            streamed.mirror_applied,
            &levels,
            &meaningful,
            alternatives,
            rules.r2p.then_some(&cyclic),
        );
        out.write_all(report.as_bytes())?;
    }
    out.flush()?;
    Ok(())
}

fn on(b: bool) -> &'static str {
    if b { "on" } else { "off" }
}

#[allow(clippy::too_many_arguments)]
fn text_report(
    task: &Task,
    args: &EnumerateArgs,
    n_max: usize,
    filters: Filters,
    mirror_applied: bool,
    levels: &[LevelCounts],
    meaningful: &[Meaningful],
    alternatives: u64,
    cyclic: Option<&CyclicSummary>,
) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "task: {} ({}), N_max = {}",
        task.name,
        args.task.display(),
        n_max
    );
    let mirror = if filters.mirror && !mirror_applied {
        "off (task not mirror-symmetric)"
    } else {
        on(mirror_applied)
    };
    let _ = writeln!(
        s,
        "filters: isomorphism {}, mirror {}, semantic validity {}",
        on(filters.isomorphism),
        mirror,
        on(filters.validity)
    );
    if args.rules != Rules::default() {
        let _ = writeln!(s, "rules: {}", args.rules.names().replace("r2p", "r2′"));
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "level  generated  isomorphic  mirror  invalid  meaningful"
    );
    let mut total = LevelCounts::default();
    for c in levels {
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
    for m in meaningful {
        let _ = writeln!(
            s,
            "  {:<28} N = {}  alternatives = {}",
            m.sequence, m.n, m.alternatives
        );
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "design alternatives: {alternatives} (sum over meaningful graphs of 2^N RBM assignments x 3 gripping candidates)"
    );
    if let Some(c) = cyclic {
        let _ = writeln!(
            s,
            "cyclic graphs (closed by r2′): {} generated, {} meaningful, {} alternatives",
            c.generated, c.meaningful, c.alternatives
        );
    }
    if let Some(t) = &args.tree {
        let _ = writeln!(s, "search tree written to {}", t.display());
    }
    s
}
