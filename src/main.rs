//! The `foldsynth` binary: a thin shell over the library.

use clap::Parser;

fn main() -> std::process::ExitCode {
    let cli = foldsynth::cli::Cli::parse();
    match foldsynth::cli::run(cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
