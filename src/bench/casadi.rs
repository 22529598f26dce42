//! The CasADi peer of `foldsynth bench vertex --peer casadi`: the same vertex built by
//! `benches/peers/casadi_vertex.py` (CasADi SX, reverse-mode gradient, generated C compiled
//! with `gcc -O3`), its compile timings, and its timing harness run once per round.

use super::fastest;
use crate::kinematics::VertexSpec;
use anyhow::{Context, Result, bail};
use serde_json::json;
use std::path::{Path, PathBuf};

/// What the peer script gave: why it skipped, or its harness.
enum Setup {
    Skipped(serde_json::Value),
    Harness {
        info: serde_json::Value,
        argv: Vec<String>,
        dir: PathBuf,
    },
}

/// The vertex to hand the peer script and how long each of its rounds measures.
pub struct CasadiJob<'a> {
    /// The peer script (default: the crate's `benches/peers/casadi_vertex.py`).
    pub script: Option<&'a Path>,
    /// The vertex.
    pub spec: &'a VertexSpec,
    /// Sector angles as variables (otherwise the gradient is with respect to t).
    pub symbolic_sectors: bool,
    /// The driving parameter.
    pub t: f64,
    /// Milliseconds of measurement per round.
    pub millis: u64,
}

/// The CasADi peer: set up once, its harness run round by round.
pub struct CasadiPeer {
    setup: Setup,
    /// Each round's JSON.
    theirs: Vec<serde_json::Value>,
    /// The first harness failure; later rounds are not run.
    error: Option<anyhow::Error>,
}

impl CasadiPeer {
    /// Build the peer for `job`: its compile timings and the command line of its timing
    /// harness (or why it was skipped: no `python3`, no CasADi).
    pub fn new(job: &CasadiJob<'_>) -> Result<CasadiPeer> {
        Ok(CasadiPeer {
            setup: setup(job)?,
            theirs: Vec::new(),
            error: None,
        })
    }

    /// Run the harness once (unless the peer was skipped or an earlier round failed).
    pub fn round(&mut self) {
        if let Setup::Harness { argv, .. } = &self.setup
            && self.error.is_none()
        {
            match run_harness(argv) {
                Ok(r) => self.theirs.push(r),
                Err(e) => self.error = Some(e),
            }
        }
    }

    /// The peer's figures as JSON after `rounds` rounds (its fastest value+gradient time,
    /// its value and gradient), or why it was skipped; removes the harness's folder. A
    /// harness failure is the error.
    pub fn finish(self, rounds: u32) -> Result<serde_json::Value> {
        match self.setup {
            Setup::Skipped(v) => Ok(v),
            Setup::Harness { mut info, dir, .. } => {
                let _ = std::fs::remove_dir_all(&dir);
                if let Some(e) = self.error {
                    return Err(e);
                }
                let ns: Vec<f64> = self
                    .theirs
                    .iter()
                    .filter_map(|r| r.get("value_grad_ns").and_then(|v| v.as_f64()))
                    .collect();
                if let Some(last) = self.theirs.last() {
                    info["value"] = last["value"].clone();
                    info["grad"] = last["grad"].clone();
                }
                info["value_grad_ns"] = json!(if ns.is_empty() {
                    None
                } else {
                    Some(fastest(&ns))
                });
                info["rounds"] = json!(rounds);
                Ok(info)
            }
        }
    }
}

/// Run the peer script for `job`: it builds and compiles the vertex and writes its
/// harness into a temporary folder.
fn setup(job: &CasadiJob<'_>) -> Result<Setup> {
    let script = super::peer_script(job.script, "casadi_vertex.py")?;
    let units: Vec<_> = job
        .spec
        .units
        .iter()
        .map(|u| {
            json!({
                "sectors_deg": u.sectors_deg,
                "driving": u.driving.iter().map(|d| d.to_string()).collect::<Vec<_>>(),
            })
        })
        .collect();
    let desc = json!({
        "mode": job.spec.mode.sign(),
        "units": units,
        "symbolic_sectors": job.symbolic_sectors,
        "t": job.t,
        "millis": job.millis,
    });
    let dir = super::scratch_dir("casadi");
    let out = std::process::Command::new("python3")
        .arg(&script)
        .arg("--vertex-json")
        .arg(desc.to_string())
        .arg("--emit-harness")
        .arg(&dir)
        .output();
    let out = match out {
        Ok(o) => o,
        Err(e) => {
            return Ok(Setup::Skipped(
                json!({ "skipped": format!("cannot run python3: {e}") }),
            ));
        }
    };
    if !out.status.success() {
        let _ = std::fs::remove_dir_all(&dir);
        bail!(
            "peer script failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    harness(&String::from_utf8_lossy(&out.stdout), dir)
}

/// The harness the peer script's last line names, or why it skipped.
fn harness(text: &str, dir: PathBuf) -> Result<Setup> {
    let info: serde_json::Value = serde_json::from_str(text.lines().last().unwrap_or(""))
        .with_context(|| format!("peer script printed no JSON object: {text}"))?;
    if info.get("skipped").is_some() {
        return Ok(Setup::Skipped(info));
    }
    let argv: Vec<String> = info
        .get("harness")
        .and_then(|h| h.as_array())
        .map(|a| {
            a.iter()
                .filter_map(|x| x.as_str().map(str::to_string))
                .collect()
        })
        .filter(|a: &Vec<String>| !a.is_empty())
        .with_context(|| format!("peer script gave no harness: {text}"))?;
    Ok(Setup::Harness { info, argv, dir })
}

/// Run the peer's timing harness once; its JSON.
fn run_harness(argv: &[String]) -> Result<serde_json::Value> {
    let out = std::process::Command::new(&argv[0])
        .args(&argv[1..])
        .output()
        .with_context(|| format!("cannot run the peer harness {}", argv[0]))?;
    if !out.status.success() {
        bail!(
            "peer harness failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    let text = String::from_utf8_lossy(&out.stdout);
    serde_json::from_str(text.lines().last().unwrap_or(""))
        .with_context(|| format!("peer harness printed no JSON object: {text}"))
}
