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
use super::notation::{Step, parse_sequence};
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

impl LevelCounts {
    /// Count one graph of `level` with `status` into `levels` (one entry per level from 1,
    /// grown as needed).
    pub fn count(levels: &mut Vec<LevelCounts>, level: usize, status: Status) {
        while levels.len() < level {
            levels.push(LevelCounts {
                level: levels.len() + 1,
                ..LevelCounts::default()
            });
        }
        let c = &mut levels[level - 1];
        c.generated += 1;
        match status {
            Status::Meaningful => c.meaningful += 1,
            Status::Invalid => c.invalid += 1,
            Status::Mirror => c.mirror += 1,
            Status::Isomorphic => c.isomorphic += 1,
        }
    }
}

/// The start of the search tree in Graphviz DOT, up to the first graph.
pub fn dot_header(n_max: usize) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "digraph search_tree {{");
    let _ = writeln!(
        s,
        "  // foldsynth enumerate: N_max = {n_max}; meaningful = yellow, invalid = white, mirror = grey, isomorphic = blue"
    );
    let _ = writeln!(s, "  graph [rankdir=TB, ranksep=0.8, nodesep=0.1];");
    let _ = writeln!(
        s,
        "  node [shape=box, style=\"filled,rounded\", fontname=\"Helvetica\", fontsize=10];"
    );
    let _ = writeln!(s, "  g0 [label=\"G0\", fillcolor=\"#dddddd\"];");
    s
}

/// One generated graph and its edge from the parent, in Graphviz DOT.
pub fn dot_node(g: &Generated<'_>) -> String {
    let color = match g.status {
        Status::Meaningful => "#ffd84d",
        Status::Invalid => "#ffffff",
        Status::Mirror => "#aaaaaa",
        Status::Isomorphic => "#9ecae1",
    };
    let i = g.index;
    let mut s = format!(
        "  n{i} [label=\"{}\", fillcolor=\"{color}\", tooltip=\"{}, N = {}\"];\n",
        g.graph.sequence(),
        g.status.as_str(),
        g.graph.internal_count()
    );
    match g.parent {
        None => s += &format!("  g0 -> n{i};\n"),
        Some(p) => s += &format!("  n{p} -> n{i};\n"),
    }
    s
}

/// The end of the search tree in Graphviz DOT.
pub const DOT_FOOTER: &str = "}\n";

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

/// One generated graph as [`Enumeration::stream`] hands it over.
#[derive(Clone, Copy, Debug)]
pub struct Generated<'a> {
    /// Position in generation order (breadth-first), counting from 0.
    pub index: usize,
    /// Index of the parent; `None` for children of G0.
    pub parent: Option<usize>,
    /// Number of rule applications.
    pub level: usize,
    /// The filters' verdict.
    pub status: Status,
    /// The graph (borrowed for the call only).
    pub graph: &'a CreaseGraph,
}

/// What a streamed enumeration leaves behind: counts only.
#[derive(Clone, Debug)]
pub struct Streamed {
    /// Graphs generated.
    pub generated: usize,
    /// Whether the mirror filter actually ran (requested and the task is mirror-symmetric).
    pub mirror_applied: bool,
}

/// A graph to expand at the next level: kept as its rule sequence, not as a graph, so the
/// frontier costs a few hundred bytes per graph instead of the graph's ~15 kB.
struct Open {
    index: usize,
    steps: Vec<Step>,
}

/// 128 bits of a canonical code: the filters compare codes of every graph seen so far,
/// and a digest keeps that set small (two SipHash-1-3 of the code under different
/// prefixes; a collision among 10^7 graphs has probability about 10^-25).
fn code_digest(code: &Code) -> u128 {
    use std::hash::{Hash, Hasher};
    let half = |salt: u8| {
        let mut h = std::hash::DefaultHasher::new();
        salt.hash(&mut h);
        code.hash(&mut h);
        h.finish()
    };
    (u128::from(half(0)) << 64) | u128::from(half(1))
}

impl Enumeration {
    /// Enumerate all graphs of `task` up to `n_max` internal vertices, keeping every
    /// graph (use [`Enumeration::stream`] for large N_max).
    pub fn run(task: &Task, n_max: usize, filters: Filters) -> Enumeration {
        let mut nodes = Vec::new();
        let done = Self::stream(task, n_max, filters, |g| {
            nodes.push(Node {
                graph: g.graph.clone(),
                parent: g.parent,
                level: g.level,
                status: g.status,
            });
        });
        Enumeration {
            root: CreaseGraph::initial(task),
            nodes,
            n_max,
            filters,
            mirror_applied: done.mirror_applied,
        }
    }

    /// Generate the graphs of `task` up to `n_max` internal vertices in the order of
    /// [`Enumeration::run`] and hand each to `visit`, without keeping them: memory holds
    /// the codes' digests of the graphs seen and the rule sequences of the graphs still
    /// to expand, so N_max = 5 and 6 fit where keeping every graph would not.
    pub fn stream(
        task: &Task,
        n_max: usize,
        filters: Filters,
        mut visit: impl FnMut(Generated<'_>),
    ) -> Streamed {
        let root = CreaseGraph::initial(task);
        let mirror_applied =
            filters.mirror && task.symmetry.mirror_xz && root.initial_graph().mirror.is_some();
        // Digests of all codes seen so far, and of those kept (neither isomorphic nor
        // mirror).
        let mut seen: HashSet<u128> = HashSet::new();
        let mut kept: HashSet<u128> = HashSet::new();
        let mut frontier: Vec<Option<Open>> = vec![None];
        let mut generated = 0;
        let mut level = 0;
        while !frontier.is_empty() {
            level += 1;
            let mut next = Vec::new();
            for parent in frontier {
                // The parent rebuilt from its sequence: the same rule applications that
                // made it, so the same graph.
                let g = match &parent {
                    None => root.clone(),
                    Some(open) => {
                        let mut g = root.clone();
                        for &step in &open.steps {
                            g.apply_step(step)
                                .expect("a generated graph's own sequence applies");
                        }
                        g
                    }
                };
                let parent_index = parent.as_ref().map(|o| o.index);
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
                for graph in children {
                    let code = code_digest(&graph.canonical_code());
                    let status = if filters.isomorphism && !seen.insert(code) {
                        Status::Isomorphic
                    } else if mirror_applied
                        && graph
                            .mirror_code()
                            .map(|m| code_digest(&m))
                            .is_some_and(|m| m != code && kept.contains(&m))
                    {
                        Status::Mirror
                    } else {
                        if mirror_applied {
                            kept.insert(code);
                        }
                        if filters.validity && !graph.is_semantically_valid() {
                            Status::Invalid
                        } else {
                            Status::Meaningful
                        }
                    };
                    if matches!(status, Status::Meaningful | Status::Invalid) {
                        next.push(Some(Open {
                            index: generated,
                            steps: graph.sequence_steps(),
                        }));
                    }
                    visit(Generated {
                        index: generated,
                        parent: parent_index,
                        level,
                        status,
                        graph: &graph,
                    });
                    generated += 1;
                }
            }
            frontier = next;
        }
        Streamed {
            generated,
            mirror_applied,
        }
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
        let mut out = Vec::new();
        for n in &self.nodes {
            LevelCounts::count(&mut out, n.level, n.status);
        }
        out
    }

    /// The search tree as Graphviz DOT (Fig. 48): one node per generated graph, coloured
    /// by status (meaningful yellow, invalid white, mirror grey, isomorphic blue).
    pub fn to_dot(&self) -> String {
        let mut s = dot_header(self.n_max);
        for (i, n) in self.nodes.iter().enumerate() {
            s += &dot_node(&Generated {
                index: i,
                parent: n.parent,
                level: n.level,
                status: n.status,
                graph: &n.graph,
            });
        }
        s.push_str(DOT_FOOTER);
        s
    }
}
