//! The automated generation of Table 3 with the filters of SPEC §2 / thesis Sec. 5.5.2.
//!
//! Breadth-first by number of rule applications. From every graph that is expanded, the
//! r1 matches (while N < N_max) in increasing vertex name, then the r2 matches in
//! increasing sorted name pairs, then (only when [`Rules::r2p`] is on) the r2′ matches in
//! the same order, each give one child. Every child gets one status:
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
use super::step::Step;
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

/// Which rules the enumeration applies. The thesis's grammar is r1 and r2 (the default);
/// r2′ (Sec. 5.7) is opt-in, so the thesis's counts stay what they are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Rules {
    /// r1: extend a vertex.
    pub r1: bool,
    /// r2: combine two vertices.
    pub r2: bool,
    /// r2′: combine two vertices into a sink on the straight segment between their
    /// predecessors (cyclic, overconstrained patterns such as the Miura-ori).
    pub r2p: bool,
}

impl Default for Rules {
    fn default() -> Self {
        Rules {
            r1: true,
            r2: true,
            r2p: false,
        }
    }
}

impl Rules {
    /// Every rule, r2′ included.
    pub fn all() -> Rules {
        Rules {
            r1: true,
            r2: true,
            r2p: true,
        }
    }

    /// Read a comma-separated list such as `r1,r2,r2p` (`r2'` and `r2′` name r2′ too).
    pub fn parse(text: &str) -> Result<Rules, String> {
        let mut r = Rules {
            r1: false,
            r2: false,
            r2p: false,
        };
        for name in text.split(',').map(str::trim) {
            match name {
                "r1" => r.r1 = true,
                "r2" => r.r2 = true,
                "r2p" | "r2'" | "r2′" => r.r2p = true,
                "" => {
                    return Err(format!(
                        "\"{text}\": an empty rule name; list rules as r1,r2,r2p"
                    ));
                }
                other => {
                    return Err(format!(
                        "\"{other}\" is not a rule; the rules are r1, r2 and r2p (r2′)"
                    ));
                }
            }
        }
        if !r.r1 {
            return Err(format!(
                "\"{text}\": r1 must be among the rules (without it no vertex is ever extended)"
            ));
        }
        Ok(r)
    }

    /// The list as [`Rules::parse`] reads it, e.g. `r1,r2,r2p`.
    pub fn names(&self) -> String {
        [(self.r1, "r1"), (self.r2, "r2"), (self.r2p, "r2p")]
            .iter()
            .filter(|(on, _)| *on)
            .map(|(_, n)| *n)
            .collect::<Vec<_>>()
            .join(",")
    }
}

impl std::str::FromStr for Rules {
    type Err = String;
    fn from_str(s: &str) -> Result<Rules, String> {
        Rules::parse(s)
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
    /// The rules applied.
    pub rules: Rules,
}

/// The search tree grew past the graph budget given to [`Enumeration::run_limited`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the search tree exceeded {limit} graphs at level {level} (N_max = {n_max})")]
pub struct TooLarge {
    /// The budget.
    pub limit: usize,
    /// The level at which it was exceeded.
    pub level: usize,
    /// The N_max requested.
    pub n_max: usize,
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

/// The parent rebuilt from its sequence: the same rule applications that made it, so the
/// same graph (`None`: G0).
fn rebuilt(root: &CreaseGraph, parent: Option<&Open>) -> CreaseGraph {
    match parent {
        None => root.clone(),
        Some(open) => {
            let mut g = root.clone();
            for &step in &open.steps {
                g.apply_step(step)
                    .expect("a generated graph's own sequence applies");
            }
            g
        }
    }
}

/// Every child of `g` under `rules`: r1's matches, then r2's, then r2′'s.
fn children(g: &CreaseGraph, rules: Rules, n_max: usize) -> Vec<CreaseGraph> {
    let mut children = Vec::new();
    if rules.r1 {
        for v in g.r1_matches(n_max) {
            let mut c = g.clone();
            c.extend(v).expect("r1 matches what r1_matches found");
            children.push(c);
        }
    }
    if rules.r2 {
        for (_, m) in g.r2_matches() {
            let mut c = g.clone();
            c.combine(m).expect("r2 matches what r2_matches found");
            children.push(c);
        }
    }
    if rules.r2p {
        for (_, m) in g.r2p_matches() {
            let mut c = g.clone();
            c.combine_straight(m)
                .expect("r2′ matches what r2p_matches found");
            children.push(c);
        }
    }
    children
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
        Self::run_with(task, n_max, filters, Rules::default())
    }

    /// Generate the graphs of `task` up to `n_max` internal vertices in the order of
    /// [`Enumeration::run`] and hand each to `visit`, without keeping them: memory holds
    /// the codes' digests of the graphs seen and the rule sequences of the graphs still
    /// to expand, so N_max = 5 and 6 fit where keeping every graph would not.
    pub fn stream(
        task: &Task,
        n_max: usize,
        filters: Filters,
        visit: impl FnMut(Generated<'_>),
    ) -> Streamed {
        Self::stream_with(task, n_max, filters, Rules::default(), visit)
    }

    /// As [`Enumeration::run`] with a choice of rules (r2′ adds its matches after r2's).
    pub fn run_with(task: &Task, n_max: usize, filters: Filters, rules: Rules) -> Enumeration {
        match Self::run_limited_with(task, n_max, filters, rules, usize::MAX) {
            Ok(e) => e,
            Err(e) => unreachable!("no budget, yet {e}"),
        }
    }

    /// Enumerate keeping at most `max_graphs` graphs (for callers that must stay small,
    /// such as the fuzzer and the Python binding).
    pub fn run_limited(
        task: &Task,
        n_max: usize,
        filters: Filters,
        max_graphs: usize,
    ) -> Result<Enumeration, TooLarge> {
        Self::run_limited_with(task, n_max, filters, Rules::default(), max_graphs)
    }

    /// As [`Enumeration::run_limited`] with a choice of rules.
    pub fn run_limited_with(
        task: &Task,
        n_max: usize,
        filters: Filters,
        rules: Rules,
        max_graphs: usize,
    ) -> Result<Enumeration, TooLarge> {
        let mut nodes = Vec::new();
        let done = Self::stream_limited(task, n_max, filters, rules, max_graphs, |g| {
            nodes.push(Node {
                graph: g.graph.clone(),
                parent: g.parent,
                level: g.level,
                status: g.status,
            });
        })?;
        Ok(Enumeration {
            root: CreaseGraph::initial(task),
            nodes,
            n_max,
            filters,
            mirror_applied: done.mirror_applied,
            rules,
        })
    }

    /// As [`Enumeration::stream`] with a choice of rules.
    pub fn stream_with(
        task: &Task,
        n_max: usize,
        filters: Filters,
        rules: Rules,
        visit: impl FnMut(Generated<'_>),
    ) -> Streamed {
        match Self::stream_limited(task, n_max, filters, rules, usize::MAX, visit) {
            Ok(s) => s,
            Err(e) => unreachable!("no budget, yet {e}"),
        }
    }

    /// The one generator: streams at most `max_graphs` graphs, then stops with
    /// [`TooLarge`] before generating a level's children past the budget.
    fn stream_limited(
        task: &Task,
        n_max: usize,
        filters: Filters,
        rules: Rules,
        max_graphs: usize,
        mut visit: impl FnMut(Generated<'_>),
    ) -> Result<Streamed, TooLarge> {
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
                let g = rebuilt(&root, parent.as_ref());
                let parent_index = parent.as_ref().map(|o| o.index);
                let children = children(&g, rules, n_max);
                if generated + children.len() > max_graphs {
                    return Err(TooLarge {
                        limit: max_graphs,
                        level,
                        n_max,
                    });
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
        Ok(Streamed {
            generated,
            mirror_applied,
        })
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
