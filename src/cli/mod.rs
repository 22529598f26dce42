//! The command-line interface: one file per subcommand; `main.rs` only dispatches.

use clap::{Parser, Subcommand};

pub mod optimize_flasher;
pub mod simulate;

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
    /// Simulate a pattern file with the bar-and-hinge model (thesis Sec. 3).
    Simulate(simulate::SimulateArgs),
    /// Optimize the adapted flasher by simulated annealing (thesis Sec. 3.6-3.7).
    OptimizeFlasher(optimize_flasher::OptimizeFlasherArgs),
}

/// Run one parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Simulate(a) => simulate::run(a),
        Command::OptimizeFlasher(a) => optimize_flasher::run(a),
    }
}
