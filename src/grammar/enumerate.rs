//! The automated generation of Table 3 with the filters of SPEC §2 / thesis Sec. 5.5.2.
//!
//! Breadth-first by number of rule applications. From every graph that is expanded, the
//! r1 matches (while N < N_max) in increasing vertex name, then the r2 matches in
//! increasing sorted name pairs, each give one child. Every child gets one status:
//!
//! - `isomorphic`: the same design family as an earlier graph (canonical code, see
//!   [`Code`](super::Code)); not expanded.
//! - `mirror`: its mirror image is an earlier kept graph (tasks symmetric about the
//!   xz-plane); dropped with all its descendants. A graph equal to its own mirror image is
//!   kept.
//! - `invalid`: some internal vertex is no ancestor of a gripping candidate; not a design,
//!   but expanded (its descendants can be meaningful).
//! - `meaningful`: a design to optimize; expanded.

use std::collections::HashSet;
use std::fmt::Write as _;

use serde::Serialize;

use super::canon::Code;
use super::graph::CreaseGraph;
use super::notation::parse_sequence;
use crate::task::Task;

/// Which filters run. Each can be switched off.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Filters {
    /// Drop graphs isomorphic to an earlier one (and do not expand them).
    pub isomorphism: bool,
    /// Drop mirror images of earlier graphs and their descendants (only for tasks with
    /// `symmetry.mirror_xz`).
    pub mirror: bool,
    /// Mark semantically invalid graphs as not meaningful.
    pub validity: bool,
}

impl Filters {
    /// Every filter on (the thesis's setting).
    pub fn all() -> Filters {
        Filters {
            isomorphism: true,
            mirror: true,
            validity: true,
        }
    }
    /// No filter: the raw language of the grammar.
    pub fn none() -> Filters {
        Filters {
            isomorphism: false,
            mirror: false,
            validity: false,
        }
    }
}

/// What the enumeration decided about a generated graph.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// A design to optimize.
    Meaningful,
    /// Semantically invalid: not a design, descendants still generated.
    Invalid,
    /// The mirror image of an earlier graph: dropped with its descendants.
    Mirror,
    /// Isomorphic to an earlier graph: not expanded.
    Isomorphic,
}

impl Status {
    /// The lower-case name used in reports.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Meaningful => "meaningful",
            Status::Invalid => "invalid",
            Status::Mirror => "mirror",
            Status::Isomorphic => "isomorphic",
        }
    }
}

/// One generated graph in the search tree.
#[derive(Clone, Debug)]
pub struct Node {
    /// The graph.
    pub graph: CreaseGraph,
    /// Index of the parent in [`Enumeration::nodes`]; `None` for children of G0.
    pub parent: Option<usize>,
    /// Number of rule applications.
    pub level: usize,
    /// The filters' verdict.
    pub status: Status,
}

/// Counts for one level of the search tree.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct LevelCounts {
    /// Number of rule applications.
    pub level: usize,
    /// Graphs generated.
    pub generated: usize,
    /// Filtered as isomorphic.
    pub isomorphic: usize,
    /// Filtered as mirror images.
    pub mirror: usize,
    /// Filtered as semantically invalid.
    pub invalid: usize,
    /// Kept as meaningful.
    pub meaningful: usize,
}

/// The search tree of one task (Fig. 48).
#[derive(Clone, Debug)]
pub struct Enumeration {
    /// G0 (level 0, the root; not counted among the generated graphs).
    pub root: CreaseGraph,
    /// Every generated graph, breadth-first in generation order.
    pub nodes: Vec<Node>,
    /// The N_max used.
    pub n_max: usize,
    /// The filters requested.
    pub filters: Filters,
    /// Whether the mirror filter actually ran (requested and the task is mirror-symmetric).
    pub mirror_applied: bool,
}

/// The search tree grew past the graph budget given to [`Enumeration::run_limited`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the search tree exceeded {limit} graphs at level {level} (N_max = {n_max})")]
pub struct TooLarge {
    /// The budget.
    pub limit: usize,
    /// The level being generated.
    pub level: usize,
    /// The N_max requested.
    pub n_max: usize,
}

/// How many graphs an enumeration would generate: counted at smaller N_max as far as
/// they fit the budget, then extrapolated by the last growth ratio per internal vertex.
#[derive(Clone, Debug, PartialEq)]
pub struct GraphEstimate {
    /// (N_max, graphs generated) for every smaller N_max that fits the budget.
    pub measured: Vec<(usize, usize)>,
    /// Growth per internal vertex used to extrapolate.
    pub ratio: f64,
    /// The estimate at the requested N_max.
    pub graphs: f64,
}

impl GraphEstimate {
    /// Extrapolate `measured` (N_max, graphs) to `n_max` by the last growth ratio.
    pub fn extrapolate(measured: Vec<(usize, usize)>, n_max: usize) -> GraphEstimate {
        let ratio = match measured.as_slice() {
            [.., (_, a), (_, b)] if *a > 0 && *b > *a => *b as f64 / *a as f64,
            // Too little to measure: the growth seen on the bundled tasks.
            _ => 20.0,
        };
        let (k, g) = measured.last().copied().unwrap_or((0, 1));
        GraphEstimate {
            graphs: g as f64 * ratio.powi(n_max.saturating_sub(k) as i32),
            measured,
            ratio,
        }
    }

    /// Why an enumeration at `n_max` with `filters` is refused, for the user: the
    /// estimate, what it would take, what fits, and which switch would help.
    pub fn refusal(&self, task: &str, n_max: usize, filters: Filters) -> String {
        use crate::limits::{GRAPH_BYTES, GRAPHS_MAX};
        let gb = |graphs: f64| graphs * GRAPH_BYTES as f64 / 1e9;
        let measured: Vec<String> = self
            .measured
            .iter()
            .rev()
            .take(2)
            .rev()
            .map(|(k, g)| format!("{g} at N_max = {k}"))
            .collect();
        let mut s = format!(
            "N_max = {n_max} is too large for task '{task}': about {:.0} graphs, about {:.0} GB in memory (counted: {}; ×{:.1} per internal vertex). One enumeration keeps at most {GRAPHS_MAX} graphs ({:.1} GB).",
            self.graphs,
            gb(self.graphs),
            if measured.is_empty() {
                "none fits".to_string()
            } else {
                measured.join(", ")
            },
            self.ratio,
            gb(GRAPHS_MAX as f64),
        );
        let mut helps = Vec::new();
        if let Some((k, _)) = self.measured.last() {
            helps.push(format!("lower N_max to {k}"));
        }
        if !filters.isomorphism {
            helps.push("switch the isomorphism filter on (drop --no-iso)".to_string());
        }
        if !filters.mirror {
            helps.push("switch the mirror filter on (drop --no-mirror)".to_string());
        }
        if !helps.is_empty() {
            s.push_str(&format!(" To run: {}.", helps.join(", or ")));
        }
        s
    }
}

impl Enumeration {
    /// Enumerate all graphs of `task` up to `n_max` internal vertices.
    pub fn run(task: &Task, n_max: usize, filters: Filters) -> Enumeration {
        match Self::run_limited(task, n_max, filters, usize::MAX) {
            Ok(e) => e,
            Err(e) => unreachable!("no budget, yet {e}"),
        }
    }

    /// As [`Enumeration::run`], but give up once more than `max_graphs` graphs are
    /// generated (every graph is kept in memory, about 10 kB each).
    pub fn run_limited(
        task: &Task,
        n_max: usize,
        filters: Filters,
        max_graphs: usize,
    ) -> Result<Enumeration, TooLarge> {
        let root = CreaseGraph::initial(task);
        let mirror_applied =
            filters.mirror && task.symmetry.mirror_xz && root.initial_graph().mirror.is_some();
        let mut nodes: Vec<Node> = Vec::new();
        // Codes of all graphs seen so far, and of those kept (neither isomorphic nor mirror).
        let mut seen: HashSet<Code> = HashSet::new();
        let mut kept: HashSet<Code> = HashSet::new();
        let mut frontier: Vec<Option<usize>> = vec![None];
        let mut level = 0;
        while !frontier.is_empty() {
            level += 1;
            let mut next = Vec::new();
            for parent in frontier {
                let g = parent.map_or(&root, |i| &nodes[i].graph);
                let mut children = Vec::new();
                for v in g.r1_matches(n_max) {
                    let mut c = g.clone();
                    c.extend(v).expect("r1 matches what r1_matches found");
                    children.push(c);
                }
                for (_, m) in g.r2_matches() {
                    let mut c = g.clone();
                    c.combine(m).expect("r2 matches what r2_matches found");
                    children.push(c);
                }
                if nodes.len() + children.len() > max_graphs {
                    return Err(TooLarge {
                        limit: max_graphs,
                        level,
                        n_max,
                    });
                }
                for graph in children {
                    let code = graph.canonical_code();
                    let status = if filters.isomorphism && !seen.insert(code.clone()) {
                        Status::Isomorphic
                    } else if mirror_applied
                        && graph
                            .mirror_code()
                            .is_some_and(|m| m != code && kept.contains(&m))
                    {
                        Status::Mirror
                    } else {
                        kept.insert(code);
                        if filters.validity && !graph.is_semantically_valid() {
                            Status::Invalid
                        } else {
                            Status::Meaningful
                        }
                    };
                    if matches!(status, Status::Meaningful | Status::Invalid) {
                        next.push(Some(nodes.len()));
                    }
                    nodes.push(Node {
                        graph,
                        parent,
                        level,
                        status,
                    });
                }
            }
            frontier = next;
        }
        Ok(Enumeration {
            root,
            nodes,
            n_max,
            filters,
            mirror_applied,
        })
    }

    /// Enumerate up to `n_max` keeping at most `max_graphs` graphs, or say why not with an
    /// estimate. The smaller N_max are counted first (together about a twentieth of the
    /// last): an N_max whose extrapolated size is far beyond the budget is refused without
    /// being tried, so the refusal costs no more memory than the largest N_max that fits.
    pub fn run_within(
        task: &Task,
        n_max: usize,
        filters: Filters,
        max_graphs: usize,
    ) -> Result<Enumeration, GraphEstimate> {
        let mut measured = Vec::new();
        for k in 1..n_max {
            match Self::run_limited(task, k, filters, max_graphs) {
                Ok(e) => measured.push((k, e.nodes.len())),
                Err(_) => return Err(GraphEstimate::extrapolate(measured, n_max)),
            }
        }
        let estimate = GraphEstimate::extrapolate(measured, n_max);
        if estimate.graphs > 2.0 * max_graphs as f64 {
            return Err(estimate);
        }
        Self::run_limited(task, n_max, filters, max_graphs).map_err(|_| estimate)
    }

    /// The generated graph with this rule sequence, if it was generated.
    pub fn find(&self, sequence: &str) -> Option<&Node> {
        let steps = parse_sequence(sequence).ok()?;
        self.nodes
            .iter()
            .find(|n| n.graph.sequence_steps() == steps)
    }

    /// The meaningful graphs, in generation order.
    pub fn meaningful(&self) -> impl Iterator<Item = &Node> + '_ {
        self.nodes.iter().filter(|n| n.status == Status::Meaningful)
    }

    /// Number of generated graphs with this status.
    pub fn count(&self, status: Status) -> usize {
        self.nodes.iter().filter(|n| n.status == status).count()
    }

    /// Design alternatives: Σ over meaningful graphs of 2^N × 3 gripping candidates.
    pub fn alternatives(&self) -> u64 {
        self.meaningful().map(|n| n.graph.alternatives()).sum()
    }

    /// Counts per level.
    pub fn level_counts(&self) -> Vec<LevelCounts> {
        let depth = self.nodes.iter().map(|n| n.level).max().unwrap_or(0);
        let mut out: Vec<LevelCounts> = (1..=depth)
            .map(|level| LevelCounts {
                level,
                ..LevelCounts::default()
            })
            .collect();
        for n in &self.nodes {
            let c = &mut out[n.level - 1];
            c.generated += 1;
            match n.status {
                Status::Meaningful => c.meaningful += 1,
                Status::Invalid => c.invalid += 1,
                Status::Mirror => c.mirror += 1,
                Status::Isomorphic => c.isomorphic += 1,
            }
        }
        out
    }

    /// The search tree as Graphviz DOT (Fig. 48): one node per generated graph, coloured
    /// by status (meaningful yellow, invalid white, mirror grey, isomorphic blue).
    pub fn to_dot(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "digraph search_tree {{");
        let _ = writeln!(
            s,
            "  // foldsynth enumerate: N_max = {}; meaningful = yellow, invalid = white, mirror = grey, isomorphic = blue",
            self.n_max
        );
        let _ = writeln!(s, "  graph [rankdir=TB, ranksep=0.8, nodesep=0.1];");
        let _ = writeln!(
            s,
            "  node [shape=box, style=\"filled,rounded\", fontname=\"Helvetica\", fontsize=10];"
        );
        let _ = writeln!(s, "  g0 [label=\"G0\", fillcolor=\"#dddddd\"];");
        for (i, n) in self.nodes.iter().enumerate() {
            let color = match n.status {
                Status::Meaningful => "#ffd84d",
                Status::Invalid => "#ffffff",
                Status::Mirror => "#aaaaaa",
                Status::Isomorphic => "#9ecae1",
            };
            let _ = writeln!(
                s,
                "  n{i} [label=\"{}\", fillcolor=\"{color}\", tooltip=\"{}, N = {}\"];",
                n.graph.sequence(),
                n.status.as_str(),
                n.graph.internal_count()
            );
            match n.parent {
                None => {
                    let _ = writeln!(s, "  g0 -> n{i};");
                }
                Some(p) => {
                    let _ = writeln!(s, "  n{p} -> n{i};");
                }
            }
        }
        s.push_str("}\n");
        s
    }
}
