//! `foldsynth verify FILE.fold`: check any FOLD file (see [`crate::export::verify`]).

use std::path::PathBuf;

use crate::export::verify::{VerifyOptions, verify_file};

/// Arguments of `foldsynth verify`.
#[derive(Debug, clap::Args)]
pub struct VerifyArgs {
    /// The FOLD file.
    pub file: PathBuf,
    /// Isometry tolerance, relative to each face's size.
    #[arg(long, default_value_t = 1e-9, allow_hyphen_values = true)]
    pub tol: f64,
    /// Fold-angle and sector-sum tolerance in degrees.
    #[arg(long, default_value_t = 1e-6, allow_hyphen_values = true)]
    pub angle_tol: f64,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Run `foldsynth verify`; fails (non-zero exit) when any check fails.
pub fn run(a: VerifyArgs) -> anyhow::Result<()> {
    for (name, v) in [("--tol", a.tol), ("--angle-tol", a.angle_tol)] {
        if !(v.is_finite() && v > 0.0) {
            anyhow::bail!("{name} {v}: must be a positive number");
        }
    }
    let opts = VerifyOptions {
        tol: a.tol,
        angle_tol_deg: a.angle_tol,
    };
    let report = verify_file(&a.file, &opts)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{report}");
    }
    if report.ok {
        Ok(())
    } else {
        anyhow::bail!("{}: verification failed", a.file.display())
    }
}
