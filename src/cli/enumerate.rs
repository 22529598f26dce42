//! `foldsynth enumerate`: generate every crease pattern graph of a task (thesis Table 3)
//! and report the search tree.

use std::path::PathBuf;

use std::io::{BufWriter, Write};

use anyhow::Context;
use serde::Serialize;

use crate::grammar::{
    DOT_FOOTER, Enumeration, Filters, Generated, LevelCounts, Rules, Status, Streamed, dot_header,
    dot_node,
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

/// What the stream counts and keeps for the report.
#[derive(Default)]
struct Tally {
    levels: Vec<LevelCounts>,
    meaningful: Vec<Meaningful>,
    alternatives: u64,
    cyclic: CyclicSummary,
}

impl Tally {
    /// Count `g`; its alternatives (0 unless meaningful) and whether it is cyclic.
    fn count(&mut self, g: &Generated<'_>, rules: Rules) -> (u64, bool) {
        LevelCounts::count(&mut self.levels, g.level, g.status);
        let alt = if g.status == Status::Meaningful {
            g.graph.alternatives()
        } else {
            0
        };
        self.alternatives += alt;
        let is_cyclic = rules.r2p && g.graph.is_cyclic_pattern();
        if is_cyclic {
            self.cyclic.generated += 1;
            self.cyclic.meaningful += usize::from(g.status == Status::Meaningful);
            self.cyclic.alternatives += alt;
        }
        (alt, is_cyclic)
    }
}

/// Where the graphs go as they stream: the DOT tree, the JSON list on stdout, or the
/// text report's list of meaningful graphs.
struct Sinks<'a, W: Write> {
    dot: Option<(&'a PathBuf, BufWriter<std::fs::File>)>,
    out: W,
    json: bool,
    rules: Rules,
}

impl<W: Write> Sinks<'_, W> {
    /// Write `g` (with `alt` alternatives) to the tree and the JSON list, or keep it for
    /// the text report.
    fn write(
        &mut self,
        g: &Generated<'_>,
        (alt, is_cyclic): (u64, bool),
        meaningful: &mut Vec<Meaningful>,
    ) -> std::io::Result<()> {
        if let Some((_, w)) = &mut self.dot {
            w.write_all(dot_node(g).as_bytes())?;
        }
        if self.json {
            let entry = GraphEntry {
                sequence: g.graph.sequence(),
                level: g.level,
                internal_vertices: g.graph.internal_count(),
                status: g.status,
                parent: g.parent,
                alternatives: alt,
                cyclic: self.rules.r2p.then_some(is_cyclic),
            };
            let sep = if g.index == 0 { "" } else { "," };
            write!(self.out, "{sep}\n    {}", serde_json::to_string(&entry)?)?;
        } else if g.status == Status::Meaningful {
            meaningful.push(Meaningful {
                sequence: g.graph.sequence(),
                n: g.graph.internal_count(),
                alternatives: alt,
            });
        }
        Ok(())
    }
}

/// `--tree`: the DOT file, its header written.
fn open_tree(
    path: Option<&PathBuf>,
    n_max: usize,
) -> anyhow::Result<Option<(&PathBuf, BufWriter<std::fs::File>)>> {
    let Some(path) = path else { return Ok(None) };
    let f = std::fs::File::create(path)
        .with_context(|| format!("cannot write the search tree to {}", path.display()))?;
    let mut w = BufWriter::new(f);
    w.write_all(dot_header(n_max).as_bytes())?;
    Ok(Some((path, w)))
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
    let rules = args.rules;
    let mut sinks = Sinks {
        dot: open_tree(args.tree.as_ref(), n_max)?,
        out: BufWriter::new(std::io::stdout().lock()),
        json: args.format == Format::Json,
        rules,
    };
    if sinks.json {
        // The graphs first (streamed), the totals after them.
        sinks.out.write_all(b"{\n  \"graphs\": [")?;
    }
    let mut tally = Tally::default();
    let mut failed: Option<std::io::Error> = None;
    let streamed = Enumeration::stream_with(&task, n_max, filters, rules, |g| {
        let counted = tally.count(&g, rules);
        if failed.is_some() {
            return;
        }
        if let Err(e) = sinks.write(&g, counted, &mut tally.meaningful) {
            failed = Some(e);
        }
    });
    if let Some(e) = failed {
        return Err(e).context("cannot write the enumeration");
    }
    if let Some((path, mut w)) = sinks.dot {
        w.write_all(DOT_FOOTER.as_bytes())
            .and_then(|_| w.flush())
            .with_context(|| format!("cannot write the search tree to {}", path.display()))?;
    }
    let mut out = sinks.out;
    if sinks.json {
        let fields = json_totals(&streamed, &tally, rules)?;
        writeln!(out, "\n  ],{fields}\n}}")?;
    } else {
        let report = text_report(
            &task,
            &args,
            n_max,
            filters,
            streamed.mirror_applied,
            &tally,
        );
        out.write_all(report.as_bytes())?;
    }
    out.flush()?;
    Ok(())
}

/// The totals' fields, to follow the graphs in the same JSON object.
fn json_totals(streamed: &Streamed, tally: &Tally, rules: Rules) -> anyhow::Result<String> {
    let total = |f: fn(&LevelCounts) -> usize| tally.levels.iter().map(f).sum::<usize>();
    let mut tail = serde_json::json!({
        "generated": streamed.generated,
        "filtered": {
            "isomorphic": total(|c| c.isomorphic),
            "mirror": total(|c| c.mirror),
            "invalid": total(|c| c.invalid),
        },
        "alternatives": tally.alternatives,
    });
    if rules.r2p {
        tail["rules"] = serde_json::json!(rules.names());
        tail["cyclic"] = serde_json::to_value(&tally.cyclic)?;
    }
    let tail = serde_json::to_string_pretty(&tail)?;
    Ok(tail
        .trim()
        .trim_start_matches('{')
        .trim_end_matches('}')
        .trim_end()
        .to_string())
}

fn on(b: bool) -> &'static str {
    if b { "on" } else { "off" }
}

fn text_report(
    task: &Task,
    args: &EnumerateArgs,
    n_max: usize,
    filters: Filters,
    mirror_applied: bool,
    tally: &Tally,
) -> String {
    let (levels, meaningful, alternatives) = (&tally.levels, &tally.meaningful, tally.alternatives);
    let cyclic = args.rules.r2p.then_some(&tally.cyclic);
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
