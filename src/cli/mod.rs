//! The command-line interface: one file per subcommand; `main.rs` only dispatches.

use clap::{Parser, Subcommand};

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
    /// The PTU for one vertex: unit, internal, start/end and dihedral angles over t.
    Vertex(vertex::VertexArgs),
}

/// Run one parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Vertex(a) => vertex::run(a),
    }
}
