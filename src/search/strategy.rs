//! What a search is asked to cover: the strategy (exhaustive or guided), a guided
//! search's budget, and how much of the design space a run covered. Plain data, read by
//! the options, the settings and the summary; the guided order is in `guide`.

use serde::{Deserialize, Serialize};

/// How a search chooses what to optimize.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Strategy {
    /// Every alternative, in enumeration order (the thesis's method and the reference).
    #[default]
    Exhaustive,
    /// The models in the order of [`score`](super::guide::score), up to a [`Budget`].
    Guided,
}

impl std::fmt::Display for Strategy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Strategy::Exhaustive => "exhaustive",
            Strategy::Guided => "guided",
        })
    }
}

impl std::str::FromStr for Strategy {
    type Err = String;
    fn from_str(s: &str) -> Result<Strategy, String> {
        match s.trim() {
            "exhaustive" => Ok(Strategy::Exhaustive),
            "guided" => Ok(Strategy::Guided),
            other => Err(format!(
                "'{}' is not a strategy; the strategies are exhaustive and guided",
                crate::text::excerpt(other, 40)
            )),
        }
    }
}

/// How much a guided search may spend; both `None`: the whole plan.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Budget {
    /// Alternatives to optimize, rounded up to whole models (a model's 2^N alternatives
    /// share one compiled function). Decides the records: the same seed and budget give
    /// the same records on any machine, in any number of shards.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alternatives: Option<u64>,
    /// CPU seconds (all threads): no model is started after they are spent. What is
    /// evaluated depends on the machine; a resumed run counts the CPU time of the records
    /// it keeps.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpu_s: Option<f64>,
}

/// The models a guided search in shards evaluates, as its shards' settings record it:
/// those of a budget of `alternatives` (`None`: every model, in the guided order).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Selection {
    /// The budget of alternatives.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alternatives: Option<u64>,
}

/// How much of the design space a run covered (`summary.json`'s `coverage`, the report's
/// header and the end of a run's output).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Coverage {
    /// The strategy.
    pub strategy: Strategy,
    /// Its budget (guided runs).
    #[serde(default)]
    pub budget: Budget,
    /// Alternatives with a record.
    pub alternatives: u64,
    /// Alternatives in the plan.
    pub total: u64,
    /// Per number of internal vertices N (1, 2, …): alternatives with a record, in the
    /// plan, and feasible designs found.
    pub by_vertices: Vec<VertexCoverage>,
}

/// The coverage of the graphs with N internal vertices.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct VertexCoverage {
    /// N.
    pub n: usize,
    /// Alternatives with a record.
    pub alternatives: u64,
    /// Alternatives in the plan.
    pub total: u64,
    /// Feasible designs.
    pub designs: u64,
}

impl Coverage {
    /// One line: how much was searched, per N.
    pub fn text(&self) -> String {
        let pct = |a: u64, t: u64| 100.0 * a as f64 / t.max(1) as f64;
        let per: Vec<String> = self
            .by_vertices
            .iter()
            .map(|v| {
                format!(
                    "N = {}: {:.3}% ({} designs)",
                    v.n,
                    pct(v.alternatives, v.total),
                    v.designs
                )
            })
            .collect();
        format!(
            "{} search covered {} of {} alternatives ({:.3}%); {}",
            self.strategy,
            self.alternatives,
            self.total,
            pct(self.alternatives, self.total),
            per.join(", ")
        )
    }
}
