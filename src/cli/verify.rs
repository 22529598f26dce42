//! `foldsynth verify FILE.fold`: check any FOLD file (see [`crate::export::verify`]).

use std::path::PathBuf;

use crate::export::verify::{VerifyOptions, verify_file};

/// Arguments of `foldsynth verify`.
#[derive(Debug, clap::Args)]
pub struct VerifyArgs {
    /// The FOLD file.
    pub file: PathBuf,
    /// Isometry and flatness tolerance, relative to each face's (the sheet's) size; the
    /// file's own precision is added to it.
    #[arg(long, default_value_t = 1e-9, allow_hyphen_values = true)]
    pub tol: f64,
    /// Fold-angle and sector-sum tolerance in degrees; the file's own precision is added.
    #[arg(long, default_value_t = 1e-6, allow_hyphen_values = true)]
    pub angle_tol: f64,
    /// Significant digits of the file's coordinates, 1 to 17 (default: detected; 17 takes
    /// them as exact).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=17))]
    pub digits: Option<u32>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Run `foldsynth verify`; exit status 1 when a check fails, 2 when the file cannot be
/// read as FOLD.
pub fn run(a: VerifyArgs) -> anyhow::Result<()> {
    for (name, v) in [("--tol", a.tol), ("--angle-tol", a.angle_tol)] {
        if !(v.is_finite() && v > 0.0 && v <= 1.0e3) {
            anyhow::bail!(
                "{name} {}: must be a positive number (at most 1000)",
                crate::text::num(v)
            );
        }
    }
    let opts = VerifyOptions {
        tol: a.tol,
        angle_tol_deg: a.angle_tol,
        digits: a.digits,
    };
    let report = verify_file(&a.file, &opts)?;
    let text = if a.json {
        serde_json::to_string_pretty(&report)? + "\n"
    } else {
        report.to_string()
    };
    super::simulate::emit(&text)?;
    if report.ok {
        Ok(())
    } else {
        Err(super::CheckFailed(format!("{}: verification failed", a.file.display())).into())
    }
}
