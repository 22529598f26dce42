//! Fuzzing every parser on stable Rust: structure-aware generators and mutations of the
//! valid examples, each input run through its parser and everything a user's file of that
//! kind reaches (validation, enumeration, the model, verification, export writers, the
//! simulator on small patterns), under `catch_unwind`.
//!
//! Inputs are deterministic: input `i` of a run with seed `s` is generated from `(s, i)`
//! alone ([`input`]), so any finding can be regenerated from its index. The targets:
//!
//! | target | parser | also reached |
//! | --- | --- | --- |
//! | `task` | [`crate::task::Task::from_toml_str`] | enumeration (N ≤ 2), [`crate::model::Model`], the f64 design, verification, the intersection check |
//! | `vertex` | [`crate::kinematics::VertexSpec::parse`] | the PTU at several t, rigid intervals, flat foldability, degree 4 |
//! | `expr` | driving angles ([`crate::kinematics::DriveExpr`], [`crate::task::Drive`]), simulator formulas ([`crate::simulate::Formula`]), task numbers | evaluation |
//! | `fold` | [`crate::export::fold::FoldFile::parse`] | `verify`, the pattern, FOLD and SVG writers, the simulator's drive on small patterns |
//! | `design` | [`crate::export::DesignFile::parse`] | FOLD, SVG, OBJ, STL, pictures |
//! | `pattern` | [`crate::simulate::PatternFile::parse`] | one simulation step on small patterns |
//! | `records` | `alternatives.jsonl` ([`crate::search::output::parse_records`]) | the resume invariant: every line reused or reported |
//! | `mesh` | STL (ASCII, binary) and OBJ bytes ([`crate::scene::TriangleMesh::from_stl`], [`crate::scene::TriangleMesh::from_obj`]) | bounds, the triangles, scaling |
//!
//! How each input is made: a third are seeds mutated as trees (TOML/JSON values replaced,
//! deleted, duplicated, nested; for the notations, generated from their grammar), a third
//! byte-level mutations of the seeds (bit flips, interesting tokens such as `1e308`,
//! `nan`, `../..`, deep nesting, splices of two seeds), the rest generated or seeds as is.
//! `foldsynth fuzz` runs batches in child processes so that an abort or a hang is caught
//! too (see `cli/fuzz.rs`).

mod exercise;
mod generate;
mod mutate;
mod seeds;

use std::cell::RefCell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// What is fuzzed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// Task files (TOML).
    Task,
    /// The vertex notation (Eq. 24).
    Vertex,
    /// Driving-angle expressions, simulator formulas, task number expressions.
    Expr,
    /// FOLD files (JSON).
    Fold,
    /// Design files (JSON).
    Design,
    /// Pattern files of the simulator (TOML).
    Pattern,
    /// `alternatives.jsonl` as `--resume` reads it.
    Records,
    /// Mesh files (STL ASCII or binary, OBJ) as a task's obstacles and surfaces read them.
    Mesh,
}

impl Target {
    /// Every target.
    pub const ALL: [Target; 8] = [
        Target::Task,
        Target::Vertex,
        Target::Expr,
        Target::Fold,
        Target::Design,
        Target::Pattern,
        Target::Records,
        Target::Mesh,
    ];

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Target::Task => "task",
            Target::Vertex => "vertex",
            Target::Expr => "expr",
            Target::Fold => "fold",
            Target::Design => "design",
            Target::Pattern => "pattern",
            Target::Records => "records",
            Target::Mesh => "mesh",
        }
    }

    /// The target of a name.
    pub fn from_name(s: &str) -> Option<Target> {
        Target::ALL.into_iter().find(|t| t.name() == s)
    }

    /// The file extension of its inputs (for saved findings).
    pub fn extension(self) -> &'static str {
        match self {
            Target::Task | Target::Pattern => "toml",
            Target::Vertex | Target::Expr => "txt",
            Target::Fold => "fold",
            Target::Design => "json",
            Target::Records => "jsonl",
            Target::Mesh => "mesh",
        }
    }
}

/// What an input did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The parser accepted it (and everything downstream ran).
    Accepted,
    /// The parser rejected it with an error.
    Rejected,
}

/// The target of input `index` when fuzzing `targets` in turn.
pub fn target_of(targets: &[Target], index: u64) -> Target {
    targets[(index % targets.len().max(1) as u64) as usize]
}

/// Input `index` of the run with `seed` for `target` (deterministic).
pub fn input(target: Target, seed: u64, index: u64) -> Vec<u8> {
    let mut rng = ChaCha8Rng::seed_from_u64(mix(seed, index, target as u64));
    mutate::make(target, &mut rng)
}

/// A 64-bit mix (splitmix64) of the run's seed, the index and the target.
fn mix(seed: u64, index: u64, target: u64) -> u64 {
    let mut z = seed
        ^ index.wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ target.wrapping_mul(0xd1b5_4a32_d192_ed03);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Run one input of `target` (see the module docs for what it reaches).
pub fn exercise(target: Target, input: &[u8]) -> Outcome {
    let accepted = match target {
        // Mesh files may be binary (STL).
        Target::Mesh => exercise::mesh(input),
        // Files are read as UTF-8 text: anything else is refused before parsing.
        _ => std::str::from_utf8(input).is_ok_and(|text| text_target(target, text)),
    };
    if accepted {
        Outcome::Accepted
    } else {
        Outcome::Rejected
    }
}

/// Run one text input of `target`; whether the parser accepted it.
fn text_target(target: Target, text: &str) -> bool {
    match target {
        Target::Task => exercise::task(text),
        Target::Vertex => exercise::vertex(text),
        Target::Expr => exercise::expr(text),
        Target::Fold => exercise::fold(text),
        Target::Design => exercise::design(text),
        Target::Pattern => exercise::pattern(text),
        Target::Records => exercise::records(text),
        Target::Mesh => exercise::mesh(text.as_bytes()),
    }
}

/// A panic (or, from the command, an abort or a hang) and the input that caused it.
#[derive(Clone, Debug, Serialize)]
pub struct Finding {
    /// The target.
    pub target: Target,
    /// The input's index in the run.
    pub index: u64,
    /// `panic`, `abort`, `hang` or `slow`.
    pub kind: String,
    /// The panic message (or what happened).
    pub message: String,
    /// Milliseconds the input took.
    pub ms: f64,
}

/// Per-target counts of a batch.
#[derive(Clone, Debug, Default, Serialize, serde::Deserialize)]
pub struct Counts {
    /// Inputs run.
    pub inputs: u64,
    /// Inputs the parser accepted.
    pub accepted: u64,
    /// Milliseconds of the slowest input.
    pub max_ms: f64,
    /// Milliseconds of all inputs.
    #[serde(default)]
    pub total_ms: f64,
}

/// The result of [`run_batch`].
#[derive(Clone, Debug, Default, Serialize)]
pub struct BatchReport {
    /// Counts per target name.
    pub targets: std::collections::BTreeMap<String, Counts>,
    /// Panics, and inputs slower than the slow limit.
    pub findings: Vec<Finding>,
    /// Wall seconds.
    pub seconds: f64,
}

thread_local! {
    static PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Catch panic messages of this thread instead of printing them (for the fuzz loop).
pub fn quiet_panics() {
    std::panic::set_hook(Box::new(|info| {
        let msg = info.to_string();
        PANIC.with(|p| *p.borrow_mut() = Some(msg));
    }));
}

/// Inputs slower than this are reported as `slow`.
pub const SLOW_MS: f64 = 2_000.0;

/// Run inputs `start..start + count` of the run with `seed` over `targets` in this process,
/// each under `catch_unwind`. With `trace`, the index of every input is written to it
/// before the input runs (to find the input of an abort or a hang).
pub fn run_batch(
    targets: &[Target],
    seed: u64,
    start: u64,
    count: u64,
    mut trace: Option<&mut dyn std::io::Write>,
) -> BatchReport {
    let t0 = Instant::now();
    let mut report = BatchReport::default();
    for index in start..start + count {
        let target = target_of(targets, index);
        let bytes = input(target, seed, index);
        if let Some(w) = trace.as_mut() {
            let _ = writeln!(w, "{index}");
            let _ = w.flush();
        }
        PANIC.with(|p| p.borrow_mut().take());
        let t = Instant::now();
        let result = catch_unwind(AssertUnwindSafe(|| exercise(target, &bytes)));
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let c = report.targets.entry(target.name().to_string()).or_default();
        c.inputs += 1;
        c.max_ms = c.max_ms.max(ms);
        c.total_ms += ms;
        match result {
            Ok(Outcome::Accepted) => c.accepted += 1,
            Ok(Outcome::Rejected) => {}
            Err(payload) => {
                let message = PANIC
                    .with(|p| p.borrow_mut().take())
                    .or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string()))
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "panic".into());
                report.findings.push(Finding {
                    target,
                    index,
                    kind: "panic".into(),
                    message,
                    ms,
                });
                continue;
            }
        }
        if ms > SLOW_MS {
            report.findings.push(Finding {
                target,
                index,
                kind: "slow".into(),
                message: format!("took {ms:.0} ms"),
                ms,
            });
        }
    }
    report.seconds = t0.elapsed().as_secs_f64();
    report
}
