//! The `foldsynth` binary: a thin shell over the library.
//!
//! Exit status: 0 success, 1 a check the command ran failed (`verify`, `simulate`
//! compared with the PTU, `synthesize` with verification failures), 2 bad input or usage.

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    // Symbolica (optional feature) prints a licence banner on stdout unless this is set;
    // foldsynth prints its own notice on stderr instead (src/compile/symbolica/).
    #[cfg(feature = "symbolica")]
    if std::env::var_os("SYMBOLICA_HIDE_BANNER").is_none() {
        // SAFETY: the first statement of main: no other thread exists yet that could read
        // the environment concurrently.
        unsafe { std::env::set_var("SYMBOLICA_HIDE_BANNER", "1") };
    }
    let cli = match foldsynth::cli::Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if e.use_stderr() => {
            // Usage errors echo what was typed: cut it, then exit 2.
            eprint!(
                "{}",
                foldsynth::text::cut_lines(&e.render().to_string(), 1000)
            );
            eprintln!();
            return ExitCode::from(2);
        }
        Err(e) => {
            // --help, --version.
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
    };
    match foldsynth::cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", foldsynth::cli::error_text(&e));
            ExitCode::from(foldsynth::cli::exit_code(&e))
        }
    }
}
