//! Running the binary, and reading a search's output folder for comparing two runs (shards
//! merged against one machine's run): records, summary and design files without what
//! depends on the machine and the moment.

use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// Run `foldsynth` with `args`, which must succeed (else its stderr is the panic message);
/// its standard output.
#[allow(dead_code)] // the distribute tests start the binary their own ways
pub fn foldsynth_ok(args: &[&str]) -> Vec<u8> {
    let r = Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(args)
        .output()
        .expect("run foldsynth");
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    r.stdout
}

/// The records of a run by key, without the timing fields (empty when there are none).
pub fn records(dir: &Path) -> BTreeMap<String, Value> {
    let text = std::fs::read_to_string(dir.join("alternatives.jsonl")).unwrap_or_default();
    text.lines()
        .map(|l| {
            let mut v: Value = serde_json::from_str(l).unwrap();
            let m = v.as_object_mut().unwrap();
            m.remove("optimize_ms");
            m.remove("check_ms");
            (m["key"].as_str().unwrap().to_string(), v)
        })
        .collect()
}

/// A summary without timings and the worker count.
pub fn summary(dir: &Path) -> Value {
    let mut s: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let m = s.as_object_mut().unwrap();
    m.remove("timings");
    m["settings"].as_object_mut().unwrap().remove("jobs");
    s
}

/// Every file under `dir/designs`, path relative to `dir` → bytes.
#[allow(dead_code)] // the guided search's tests compare records and summaries only
pub fn design_files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.join("designs")];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().display().to_string();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}
