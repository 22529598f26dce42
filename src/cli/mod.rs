//! The command-line interface: one file per subcommand; `main.rs` only dispatches.

use clap::{Parser, Subcommand};

pub mod export;
pub mod verify;

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
    /// Write one design (from a design JSON) as FOLD, SVG, OBJ, STL, GIF or PNG.
    Export(export::ExportArgs),
    /// Check a FOLD file: isometry of every folded frame, fold angles, face consistency.
    Verify(verify::VerifyArgs),
}

/// Run one parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Export(a) => export::run(a),
        Command::Verify(a) => verify::run(a),
    }
}
