//! What the search writes: one record per alternative, and the summary.

use crate::check::robustness::RobustnessReport;
use crate::check::verify::VerifyReport;
use crate::check::{Intersection, ObstacleHit};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The outcome of one design alternative (one line of `alternatives.jsonl`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AlternativeRecord {
    /// `sequence|candidate|modes`, unique within a run.
    pub key: String,
    /// Index of the graph among the meaningful graphs (enumeration order).
    pub graph: usize,
    /// The rule sequence.
    pub sequence: String,
    /// Number of rule applications.
    pub level: usize,
    /// Number of internal vertices N.
    pub internal_vertices: usize,
    /// Gripping candidate 1, 2 or 3.
    pub candidate: usize,
    /// Name of the gripping vertex.
    pub gripping_vertex: usize,
    /// Rigid body mode of each internal vertex, in extension order.
    pub modes: Vec<String>,
    /// Ω* as the thesis defines it (Eq. 37/38).
    pub objective: f64,
    /// Whether ψ holds within the tolerance at the optimum.
    pub feasible: bool,
    /// Largest constraint violation at the optimum.
    pub max_violation: f64,
    /// Smallest constraint slack at the optimum.
    pub min_slack: f64,
    /// Feasible and Ω* ≤ ϑ (the thesis's "meets the target").
    pub meets_target: bool,
    /// Free of self-intersection over the checked states (when checked).
    pub self_intersection_free: Option<bool>,
    /// The first self-intersection found.
    pub self_intersection: Option<Intersection>,
    /// Why the flat layout itself is invalid (a facet inverted or overlapping itself).
    #[serde(default)]
    pub layout_defect: Option<String>,
    /// Clear of every obstacle (when checked).
    pub obstacle_free: Option<bool>,
    /// The first obstacle hit found.
    pub obstacle_hit: Option<ObstacleHit>,
    /// The independent verification (when checked).
    pub verification: Option<VerifyReport>,
    /// Whether verification found a bug (isometry, closure, developability or fold angles
    /// off on a rigid state).
    pub verification_failed: Option<bool>,
    /// Whether the optimizer's robustness block accepted the result (absent with
    /// `--post-check-only`).
    #[serde(default)]
    pub robust_accepted: Option<bool>,
    /// Starts on which the optimizer ran its robustness phase.
    #[serde(default)]
    pub robust_attempts: usize,
    /// Margins measured independently on the verification sweep (`check::robustness`),
    /// for alternatives that meet the target.
    #[serde(default)]
    pub robustness: Option<RobustnessReport>,
    /// Why an alternative that passes every check is not a design: the required margins
    /// short of their settings on the sweep ([`AlternativeRecord::margins_short`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub short_of_margins: Vec<String>,
    /// Free variables at the optimum by name.
    pub variables: BTreeMap<String, f64>,
    /// Starting points run.
    pub starts_run: usize,
    /// The optimum came from a warm start (a guided search's start from the parent's
    /// optimum, tried after the quasi-random starts failed).
    #[serde(default)]
    pub warm_start: bool,
    /// Model evaluations spent.
    pub evaluations: usize,
    /// Milliseconds optimizing (CPU time of the worker thread).
    pub optimize_ms: f64,
    /// Milliseconds checking and verifying (CPU time of the worker thread).
    pub check_ms: f64,
    /// For designs of cyclic graphs (r2′) that meet the target: the dense compatibility
    /// sweep and the bar-and-hinge simulation, which decide whether the design folds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cycle: Option<crate::simulate::crossval::CyclicVerdict>,
    /// For acyclic designs with a driven central facet (several drives) that pass every
    /// check: the bar-and-hinge simulation driven the same way, against the PTU's motion.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub simulation: Option<crate::simulate::crossval::SimulationVerdict>,
    /// For designs that meet the target: the task's requirements, obstacles, copies,
    /// targets and area judged again on the dense sweep by `check::requirements` (issue 31).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub requirements: Option<crate::check::requirements::RequirementsReport>,
    /// With `[fabrication]`, for designs that pass every other check: the thick panels built
    /// and tested on the dense sweep (issue 32); `None` when the task has no such table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fabrication: Option<FabricationRecord>,
}

/// A design made thick (issue 32): why the construction refused it, or the independent
/// check of its solids on the dense sweep.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FabricationRecord {
    /// Why the design cannot be built (names the crease or facet), if so.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refused: Option<String>,
    /// The thick-panel check ([`crate::check::thick`]), when built.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub check: Option<crate::check::thick::ThickReport>,
}

impl FabricationRecord {
    /// Built, and its solids kept every clearance on the sweep.
    pub fn passes(&self) -> bool {
        self.refused.is_none() && self.check.as_ref().is_some_and(|c| c.passes())
    }

    /// Why it fails, in words (`None` when it passes).
    pub fn failure(&self) -> Option<String> {
        if let Some(r) = &self.refused {
            return Some(format!("cannot be built: {r}"));
        }
        let hit = self.check.as_ref()?.first_failure.as_ref()?;
        Some(match hit.kind.as_str() {
            "obstacle" => format!(
                "thick panel {} is {} from obstacle {} at t = {} (needs {})",
                hit.facets[0],
                crate::text::num(hit.distance),
                hit.obstacle.as_deref().unwrap_or("?"),
                crate::text::num(hit.t),
                crate::text::num(self.check.as_ref()?.obstacle_clearance),
            ),
            "crossing" => format!(
                "thick panels {} and {} cross at t = {}",
                hit.facets[0],
                hit.facets[1],
                crate::text::num(hit.t)
            ),
            _ => format!(
                "thick panels {} and {} are {} apart at t = {} (needs {})",
                hit.facets[0],
                hit.facets[1],
                crate::text::num(hit.distance),
                crate::text::num(hit.t),
                crate::text::num(self.check.as_ref()?.clearance),
            ),
        })
    }
}

impl AlternativeRecord {
    /// Meets the target, free of self-intersection and clear of obstacles (the thesis's
    /// feasible concepts).
    pub fn thesis_feasible(&self) -> bool {
        self.meets_target
            && self.self_intersection_free == Some(true)
            && self.obstacle_free == Some(true)
    }

    /// Thesis-feasible and, in addition, rigid over the whole motion and verified (the
    /// checks alone, whatever the margins).
    pub fn passes_checks(&self) -> bool {
        self.thesis_feasible()
            && self
                .verification
                .as_ref()
                .is_some_and(|v| v.rigid_over_motion)
            && self.verification_failed == Some(false)
            && self.cycle.as_ref().is_none_or(|c| c.passes)
            && self.requirements.as_ref().is_none_or(requirements_hold)
            && self
                .fabrication
                .as_ref()
                .is_none_or(FabricationRecord::passes)
    }

    /// Whether the margins the run requires hold on the sweep. With the robustness
    /// constraints on (not `--post-check-only`) and some margin set, every margin measured
    /// by `check::robustness` must be at least its setting (a design whose measurement
    /// failed cannot show that); with `--post-check-only` or every setting 0 (the thesis's
    /// setting) the margins are reported, not required.
    pub fn margins_hold(&self) -> bool {
        if self.robust_accepted.is_none() {
            return true;
        }
        self.robustness
            .as_ref()
            .is_some_and(|r| r.margins().all(|m| m.setting == 0.0) || r.meets_settings())
            && self.requirement_margins_short().is_empty()
    }

    /// The clearances to obstacles of the new shapes and to the walls of containment boxes
    /// short of `obstacle_clearance` on the sweep (cylinders are measured by
    /// `check::robustness` with the other margins).
    fn requirement_margins_short(&self) -> Vec<String> {
        let Some(r) = &self.requirements else {
            return Vec::new();
        };
        let obstacles = r
            .obstacles
            .iter()
            .filter(|o| o.kind != "cylinder" && !o.holds)
            .map(|o| (o.name.as_str(), o.least, o.clearance, o.t));
        let boxes = r
            .containment
            .iter()
            .filter(|c| !c.holds)
            .map(|c| (c.name.as_str(), c.least, c.clearance, c.t));
        obstacles
            .chain(boxes)
            .map(|(name, least, setting, t)| {
                let at = t.map(|t| format!(" at t {t:.4}")).unwrap_or_default();
                match least {
                    Some(v) => format!("{name}: clearance {v:.3e} < {setting:.3e}{at}"),
                    None => format!("{name}: clearance not measured"),
                }
            })
            .collect()
    }

    /// The required margins short of their setting on the sweep (see
    /// [`AlternativeRecord::margins_hold`]), e.g. `obstacle_clearance 0.0071 < 0.01 at t
    /// 1.2 (facet f3 ↔ cylinder 1)`; empty when they hold or are not required.
    pub fn margins_short(&self) -> Vec<String> {
        if self.margins_hold() {
            return Vec::new();
        }
        let Some(r) = &self.robustness else {
            return vec!["the robustness measurement failed".into()];
        };
        let mut short = self.requirement_margins_short();
        let named = [
            ("rigid_margin", Some(&r.rigid_margin)),
            ("self_clearance", r.self_clearance.as_ref()),
            ("arm_clearance", r.arm_clearance.as_ref()),
            ("obstacle_clearance", r.obstacle_clearance.as_ref()),
            ("min_feature", r.min_feature.as_ref()),
        ];
        short.extend(
            named
                .into_iter()
                .filter_map(|(name, m)| m.map(|m| (name, m)))
                .filter(|(_, m)| m.value < m.setting)
                .map(|(name, m)| {
                    let at = m.t.map(|t| format!(" at t {t:.4}")).unwrap_or_default();
                    format!(
                        "{name} {:.3e} < {:.3e}{at} ({})",
                        m.value, m.setting, m.location
                    )
                }),
        );
        short
    }

    /// Passes every check and keeps the margins the run requires: what foldsynth reports
    /// as a feasible design.
    pub fn feasible_design(&self) -> bool {
        self.passes_checks() && self.margins_hold()
    }

    /// Whether the design comes from a cyclic graph (an r2′ step in its sequence).
    pub fn is_cyclic(&self) -> bool {
        self.sequence.contains(")'")
    }

    /// The robustness score (−∞ when not measured), for ranking.
    pub fn score(&self) -> f64 {
        self.robustness
            .as_ref()
            .map_or(f64::NEG_INFINITY, |r| r.score)
    }

    /// A file-name-safe identifier.
    pub fn id(&self) -> String {
        format!(
            "g{:02}-c{}-{}",
            self.graph + 1,
            self.candidate,
            self.modes.iter().map(|m| &m[..1]).collect::<String>()
        )
    }
}

/// Seconds spent per stage. Compile, optimize and check add up the CPU time of the worker
/// threads that did them (thread CPU clock: waiting for a core does not count);
/// enumerate, export and total are wall time; `cpu_s` is the whole process's CPU time.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Timings {
    /// Generating and filtering the graphs.
    pub enumerate_s: f64,
    /// Building, simplifying, differentiating and compiling the models.
    pub compile_s: f64,
    /// Optimizing.
    pub optimize_s: f64,
    /// Intersection, obstacle and verification checks.
    pub check_s: f64,
    /// Writing designs, files and the report.
    pub export_s: f64,
    /// The whole run, wall clock.
    pub total_s: f64,
    /// CPU seconds of the whole run, every thread (user + system).
    #[serde(default)]
    pub cpu_s: f64,
}

/// Counts per number of rule applications (thesis Fig. 51).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct LevelCounts {
    /// Number of rule applications.
    pub level: usize,
    /// Alternatives.
    pub alternatives: usize,
    /// Meeting the target.
    pub meets_target: usize,
    /// … and free of self-intersection.
    pub no_self_intersection: usize,
    /// … and clear of obstacles.
    pub no_intersection: usize,
}

/// The distribution of the records over rule applications.
pub fn level_distribution(records: &[AlternativeRecord]) -> Vec<LevelCounts> {
    let mut t = Tally::default();
    for r in records {
        t.add(r);
    }
    t.levels
}

/// The counts of a summary, added up one record at a time (a search reads its records
/// file line by line instead of keeping the records).
#[derive(Clone, Debug, Default)]
pub struct Tally {
    /// Records.
    pub records: usize,
    /// Meeting the target.
    pub meets_target: usize,
    /// … and free of self-intersection.
    pub no_self_intersection: usize,
    /// … and clear of obstacles.
    pub no_intersection: usize,
    /// … and rigid over the whole motion, verified.
    pub feasible: usize,
    /// Meeting the target, rigid at t_max but not over the whole motion.
    pub rigid_at_tmax_only: usize,
    /// Verification failures.
    pub verification_failures: usize,
    /// Per number of rule applications, from 1.
    pub levels: Vec<LevelCounts>,
    /// Milliseconds optimizing, summed.
    pub optimize_ms: f64,
    /// Milliseconds checking, summed.
    pub check_ms: f64,
    /// Feasible designs that meet every robustness margin the task sets.
    pub meets_margins: usize,
    /// Feasible designs within 1e-3 of the rigidity limit.
    pub near_rigid_limit: usize,
    /// Alternatives that pass every check but are short of a required margin (not designs).
    pub short_of_margins: usize,
    /// The records from cyclic graphs (r2′); `graphs` is left 0.
    pub cyclic: CyclicCounts,
    /// Per number of internal vertices N (index N − 1): records and feasible designs.
    pub by_vertices: Vec<(u64, u64)>,
}

impl Tally {
    /// Count one record.
    pub fn add(&mut self, r: &AlternativeRecord) {
        let no_self = r.meets_target && r.self_intersection_free == Some(true);
        self.records += 1;
        self.meets_target += usize::from(r.meets_target);
        self.no_self_intersection += usize::from(no_self);
        self.no_intersection += usize::from(r.thesis_feasible());
        self.feasible += usize::from(r.feasible_design());
        self.short_of_margins += usize::from(r.passes_checks() && !r.margins_hold());
        self.rigid_at_tmax_only += usize::from(
            r.meets_target
                && r.verification
                    .as_ref()
                    .is_some_and(|v| v.rigid_at_tmax && !v.rigid_over_motion),
        );
        self.verification_failures += usize::from(r.verification_failed == Some(true));
        self.optimize_ms += r.optimize_ms;
        self.check_ms += r.check_ms;
        if r.feasible_design() {
            let rob = r.robustness.as_ref();
            self.meets_margins += usize::from(rob.is_some_and(|x| x.meets_settings()));
            self.near_rigid_limit += usize::from(rob.is_some_and(|x| x.rigid_margin.value < 1e-3));
        }
        self.cyclic.add(r);
        if let Some(i) = r.internal_vertices.checked_sub(1) {
            if self.by_vertices.len() <= i {
                self.by_vertices.resize(i + 1, (0, 0));
            }
            self.by_vertices[i].0 += 1;
            self.by_vertices[i].1 += u64::from(r.feasible_design());
        }
        while self.levels.len() < r.level {
            self.levels.push(LevelCounts {
                level: self.levels.len() + 1,
                ..LevelCounts::default()
            });
        }
        if let Some(l) = r.level.checked_sub(1).and_then(|i| self.levels.get_mut(i)) {
            l.alternatives += 1;
            l.meets_target += usize::from(r.meets_target);
            l.no_self_intersection += usize::from(no_self);
            l.no_intersection += usize::from(r.thesis_feasible());
        }
    }
}

/// One design in the ranking of `summary.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RankEntry {
    /// The design's id.
    pub id: String,
    /// Its robustness score.
    pub score: Option<f64>,
}

/// The summary of a search (`OUT/summary.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Summary {
    /// Task name.
    pub task: String,
    /// N_max used.
    pub n_max: usize,
    /// Meaningful graphs.
    pub graphs: usize,
    /// Alternatives evaluated (graphs × 2^N × candidates).
    pub alternatives: usize,
    /// Meeting the target (Ω* ≤ ϑ with ψ satisfied at t_max).
    pub meets_target: usize,
    /// … of those, free of self-intersection.
    pub no_self_intersection: usize,
    /// … of those, clear of every obstacle (the thesis's feasible concepts).
    pub no_intersection: usize,
    /// … of those, rigid over the whole motion and verified: foldsynth's feasible designs.
    pub feasible: usize,
    /// Alternatives meeting the target whose vertices are rigid at t_max (the thesis's
    /// check) but not over the whole motion.
    pub rigid_at_tmax_only: usize,
    /// Verification failures (bugs), which must be 0.
    pub verification_failures: usize,
    /// Feasible designs whose margins, measured on the sweep, meet the task's settings.
    #[serde(default)]
    pub meets_margins: usize,
    /// Feasible designs with a vertex within 1e-3 rad of its rigid limit.
    #[serde(default)]
    pub near_rigid_limit: usize,
    /// Alternatives that pass every check but are short of a margin the run requires (with
    /// the constraints on and a margin set): not counted as designs.
    #[serde(default)]
    pub short_of_margins: usize,
    /// The feasible designs, most robust first.
    #[serde(default)]
    pub ranking: Vec<RankEntry>,
    /// The thesis's figures for this task, when known (alternatives, meets target, no
    /// self-intersection, no intersection).
    pub thesis: Option<[usize; 4]>,
    /// Time per stage.
    pub timings: Timings,
    /// Distribution over rule applications (Fig. 51).
    pub levels: Vec<LevelCounts>,
    /// Settings of the run.
    pub settings: serde_json::Value,
    /// Ids of the feasible designs.
    pub designs: Vec<String>,
    /// With r2′ enabled: what came from cyclic graphs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cyclic: Option<CyclicCounts>,
    /// How much of the design space the run covered, per number of internal vertices.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coverage: Option<super::strategy::Coverage>,
}

/// The share of a search that comes from cyclic graphs (r2′).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct CyclicCounts {
    /// Meaningful cyclic graphs.
    pub graphs: usize,
    /// Their alternatives evaluated.
    pub alternatives: usize,
    /// … meeting the target at the optimizer's states.
    pub meets_target: usize,
    /// … also free of intersections (the thesis's feasibility).
    pub no_intersection: usize,
    /// … whose compatibility sweep passes (residual and positions ≤ 1e-9).
    pub sweep_passes: usize,
    /// … whose bar-and-hinge simulation agrees (Γ ≤ 1e-8, positions).
    pub simulation_agrees: usize,
    /// Feasible designs from cyclic graphs.
    pub feasible: usize,
    /// … of those, whose straight crease through the sink folds (the others close the
    /// cycle trivially: that crease stays flat).
    pub feasible_folding_shared_crease: usize,
}

impl CyclicCounts {
    /// Count the cyclic records among `records`.
    pub fn count(graphs: usize, records: &[AlternativeRecord]) -> CyclicCounts {
        let mut c = CyclicCounts {
            graphs,
            ..CyclicCounts::default()
        };
        for r in records {
            c.add(r);
        }
        c
    }

    /// Count one record (nothing unless it is cyclic): records are counted as they are
    /// read, so a streamed search keeps none.
    pub fn add(&mut self, r: &AlternativeRecord) {
        if !r.is_cyclic() {
            return;
        }
        let verdict = r.cycle.as_ref();
        let feasible = r.feasible_design();
        self.alternatives += 1;
        self.meets_target += usize::from(r.meets_target);
        self.no_intersection += usize::from(r.thesis_feasible());
        self.sweep_passes +=
            usize::from(verdict.is_some_and(|v| v.sweep.passes(crate::check::cycle::CYCLE_TOL)));
        self.simulation_agrees +=
            usize::from(verdict.is_some_and(|v| v.simulation.as_ref().is_some_and(|s| s.agrees)));
        self.feasible += usize::from(feasible);
        self.feasible_folding_shared_crease +=
            usize::from(feasible && verdict.is_some_and(|v| v.sweep.folds_shared_crease()));
    }
}

impl Summary {
    /// The thesis's counts for the two bundled tasks.
    pub fn thesis_counts(task: &str) -> Option<[usize; 4]> {
        match task {
            "gripper" => Some([1170, 836, 148, 36]),
            "robotic_arm" => Some([1170, 56, 29, 29]),
            _ => None,
        }
    }

    /// The summary as text, like the thesis's Sec. 5.6.
    pub fn text(&self) -> String {
        let th = |i: usize| {
            self.thesis
                .map(|t| format!("   (thesis: {})", t[i]))
                .unwrap_or_default()
        };
        let t = &self.timings;
        let mut s = String::new();
        s += &format!(
            "task {}: {} meaningful graphs (N_max = {})\n",
            self.task, self.graphs, self.n_max
        );
        s += &format!(
            "  alternatives evaluated              {:>6}{}\n",
            self.alternatives,
            th(0)
        );
        if let Some(c) = self.coverage.as_ref().filter(|c| c.alternatives < c.total) {
            s += &format!("  ({})\n", c.text());
        }
        s += &format!(
            "  meet the target                     {:>6}{}\n",
            self.meets_target,
            th(1)
        );
        s += &format!(
            "  … free of self-intersection         {:>6}{}\n",
            self.no_self_intersection,
            th(2)
        );
        s += &format!(
            "  … also clear of the obstacles       {:>6}{}\n",
            self.no_intersection,
            th(3)
        );
        s += &format!(
            "  … also rigid over the whole motion  {:>6}   (foldsynth's feasible designs)\n",
            self.feasible
        );
        if self.short_of_margins > 0 {
            s += &format!(
                "  pass every check but short of a required margin (not designs): {}\n",
                self.short_of_margins
            );
        }
        s += &format!(
            "  meet the target, rigid at t_max but not over the whole motion: {}\n",
            self.rigid_at_tmax_only
        );
        s += &format!(
            "  … feasible designs meeting the robustness margins: {} (within 1e-3 rad of a rigid limit: {})\n",
            self.meets_margins, self.near_rigid_limit
        );
        s += &format!(
            "  verification failures (bugs): {}\n",
            self.verification_failures
        );
        if let Some(c) = &self.cyclic {
            s += &format!(
                "  from cyclic graphs (r2′): {} graphs, {} alternatives, {} meet the target, {} also clear, {} pass the compatibility sweep, {} agree with the simulation, {} feasible ({} fold the shared crease)\n",
                c.graphs,
                c.alternatives,
                c.meets_target,
                c.no_intersection,
                c.sweep_passes,
                c.simulation_agrees,
                c.feasible,
                c.feasible_folding_shared_crease
            );
        }
        s += &format!(
            "time: enumerate {:.2} s, compile {:.2} s, optimize {:.2} s, check {:.2} s (CPU seconds over all workers), export {:.2} s; total {:.2} s wall\n",
            t.enumerate_s, t.compile_s, t.optimize_s, t.check_s, t.export_s, t.total_s
        );
        s
    }
}

/// Whether the hard requirements hold on the sweep: every orientation and fold limit, every
/// vertex inside its containment boxes, no obstacle hit, no crossing between copies. The
/// clearances (to obstacles, box walls, between copies) are margins, judged with the others
/// in [`AlternativeRecord::margins_hold`]; the targets and the area are the optimizer's
/// verdict (`meets_target`), recomputed in the report for the reader.
pub fn requirements_hold(r: &crate::check::requirements::RequirementsReport) -> bool {
    r.orientations.iter().all(|o| o.holds)
        && r.max_fold.iter().chain(&r.fold_limits).all(|f| f.holds)
        && r.containment
            .iter()
            .all(|c| c.least.is_some_and(|d| d >= 0.0))
        && r.obstacles.iter().all(|o| o.least.is_some() && !o.hit)
        && r.copies.as_ref().is_none_or(|c| c.crossings == 0)
}
