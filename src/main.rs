//! The `foldsynth` binary: a thin shell over the library.

use clap::Parser;

fn main() -> std::process::ExitCode {
    // Symbolica (optional feature) prints a licence banner on stdout unless this is set;
    // foldsynth prints its own notice on stderr instead (src/compile/symbolica/).
    #[cfg(feature = "symbolica")]
    if std::env::var_os("SYMBOLICA_HIDE_BANNER").is_none() {
        // SAFETY: the first statement of main: no other thread exists yet that could read
        // the environment concurrently.
        unsafe { std::env::set_var("SYMBOLICA_HIDE_BANNER", "1") };
    }
    let cli = foldsynth::cli::Cli::parse();
    match foldsynth::cli::run(cli) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
