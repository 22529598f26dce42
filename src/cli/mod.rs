//! The command-line interface: one file per subcommand; `main.rs` only dispatches.

use clap::{Parser, Subcommand};

pub mod bench;
pub mod bench_export;
pub mod bench_model;
pub mod bench_numeric;
pub mod bench_optimize;
pub mod compile;
pub mod enumerate;
pub mod export;
pub mod fabricate;
pub mod formulas;
pub mod fuzz;
pub mod merge;
pub mod model;
pub mod optimize_flasher;
pub mod simulate;
pub mod slurm;
pub mod synthesize;
pub mod verify;
pub mod vertex;

/// foldsynth: synthesize rigidly foldable origami crease patterns.
#[derive(Debug, Parser)]
#[command(name = "foldsynth", version, about)]
pub struct Cli {
    /// The subcommand to run.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run the whole method on a design task: enumerate, optimize, check, verify, export.
    Synthesize(synthesize::SynthesizeArgs),
    /// Merge the shard directories of one search into the run one machine would write.
    Merge(merge::MergeArgs),
    /// Write (and with --submit, submit) Slurm batch scripts: a job array of shards and a
    /// merge job after it.
    Slurm(slurm::SlurmArgs),
    /// The PTU for one vertex: unit, internal, start/end and dihedral angles over t.
    Vertex(vertex::VertexArgs),
    /// Generate every crease pattern graph of a task (rules r1, r2; thesis Table 3).
    Enumerate(enumerate::EnumerateArgs),
    /// Benchmarks measured in one run (`foldsynth bench vertex …`).
    Bench(bench::BenchArgs),
    /// Symbolic formulas of U, θ, φ of a vertex (plain, LaTeX, Mathematica, Python, DOT).
    Formulas(formulas::FormulasArgs),
    /// The optimization model of one graph: variables, constraints, compiled, verified.
    Model(model::ModelArgs),
    /// Compile one design model ahead of time: object, shared library, C header, manifest.
    Compile(compile::CompileArgs),
    /// Write one design (from a design JSON) as FOLD, SVG, OBJ, STL, GIF or PNG.
    Export(export::ExportArgs),
    /// Check a FOLD file: isometry of every folded frame, fold angles, face consistency.
    Verify(verify::VerifyArgs),
    /// Thick panels for a design: ply drawings (DXF, SVG), panel solids (STL, 3MF), bill.
    Fabricate(fabricate::FabricateArgs),
    /// Simulate a pattern file with the bar-and-hinge model (thesis Sec. 3).
    Simulate(simulate::SimulateArgs),
    /// Optimize the adapted flasher by simulated annealing (thesis Sec. 3.6-3.7).
    OptimizeFlasher(optimize_flasher::OptimizeFlasherArgs),
    /// Fuzz every parser: generated and mutated inputs, panics, aborts and hangs reported.
    Fuzz(fuzz::FuzzArgs),
}

/// A check the command ran failed (`verify`, `simulate` compared with the PTU, a
/// synthesis whose designs fail verification): exit status 1. Every other error is bad
/// input or usage: exit status 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct CheckFailed(pub String);

/// The exit status of a failed command: 1 when a check it ran failed, 2 otherwise (bad
/// input, usage, a file that cannot be read or written).
pub fn exit_code(e: &anyhow::Error) -> u8 {
    if e.downcast_ref::<CheckFailed>().is_some() {
        1
    } else {
        2
    }
}

/// The message of an error and its causes, each said once (an I/O error wrapped with its
/// path is not repeated), every line cut to a readable length.
pub fn error_text(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let c = cause.to_string();
        if c.is_empty() || text.contains(&c) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&c);
    }
    crate::text::cut_lines(&text, 1000)
}

/// Run one parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Synthesize(a) => synthesize::run(a),
        Command::Merge(a) => merge::run(a),
        Command::Slurm(a) => slurm::run(a),
        Command::Vertex(a) => vertex::run(a),
        Command::Enumerate(args) => enumerate::run(args),
        Command::Bench(a) => bench::run(a),
        Command::Formulas(a) => formulas::run(a),
        Command::Model(a) => model::run(a),
        Command::Compile(a) => compile::run(a),
        Command::Export(a) => export::run(a),
        Command::Verify(a) => verify::run(a),
        Command::Fabricate(a) => fabricate::run(a),
        Command::Simulate(a) => simulate::run(a),
        Command::OptimizeFlasher(a) => optimize_flasher::run(a),
        Command::Fuzz(a) => fuzz::run(a),
    }
}
