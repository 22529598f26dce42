//! One run per output directory (issue 35): a run holds an OS lock on its directory; a
//! second run into it exits 2 naming the directory and the holder's process, `--resume`
//! and `--force` do not wait either, and the lock goes with the process that held it,
//! even one killed by SIGKILL.

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

const GRIPPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml");
const LOCK: &str = ".foldsynth.lock";

fn synthesize(out: &Path, extra: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_foldsynth"));
    c.current_dir(out.parent().unwrap())
        .args(["synthesize", GRIPPER, "--no-export", "--json", "--out"])
        .arg(out)
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    c
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Take the lock the way a run does, as this test process (the lock file holds our id).
fn hold(dir: &Path) -> File {
    std::fs::create_dir_all(dir).unwrap();
    let mut f = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(true)
        .open(dir.join(LOCK))
        .unwrap();
    f.try_lock().expect("the directory is not locked yet");
    writeln!(f, "{}", std::process::id()).unwrap();
    f
}

/// Whether a fresh process could take the lock on `dir` now (tried from this process: a
/// lock of another open file conflicts with ours as with another process's).
fn free(dir: &Path) -> bool {
    let f = OpenOptions::new()
        .read(true)
        .write(true)
        .open(dir.join(LOCK))
        .unwrap();
    f.try_lock().is_ok()
}

#[test]
fn a_locked_directory_is_refused_with_the_holder_named_until_it_lets_go() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let lock = hold(&out);
    let me = std::process::id();
    for extra in [&[][..], &["--resume"], &["--force"]] {
        let mut args = vec!["--n-max", "1"];
        args.extend_from_slice(extra);
        let o = synthesize(&out, &args).output().unwrap();
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(err.contains(&out.display().to_string()), "{err}");
        assert!(err.contains(&format!("process {me}")), "{err}");
    }
    // Refused before anything was touched: the directory holds only the lock file.
    let names: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from(LOCK)]);
    drop(lock);
    let o = synthesize(&out, &["--n-max", "1"]).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    // The stale lock file is no obstacle, and the run let go of the lock when it ended.
    assert!(free(&out));
    let o = synthesize(&out, &["--n-max", "1", "--resume"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Wait for the first of `runs` to end: its index and output.
fn first_to_end(runs: &mut [Child; 2], limit: Duration) -> (usize, Output) {
    use std::io::Read;
    let start = Instant::now();
    loop {
        for (k, run) in runs.iter_mut().enumerate() {
            if let Some(status) = run.try_wait().unwrap() {
                // It has ended: its pipes hold all it wrote.
                let mut out = Output {
                    status,
                    stdout: Vec::new(),
                    stderr: Vec::new(),
                };
                run.stdout
                    .take()
                    .unwrap()
                    .read_to_end(&mut out.stdout)
                    .unwrap();
                run.stderr
                    .take()
                    .unwrap()
                    .read_to_end(&mut out.stderr)
                    .unwrap();
                return (k, out);
            }
        }
        assert!(start.elapsed() < limit, "neither run ended");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn two_runs_started_together_one_proceeds_the_other_says_why() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    // A search long enough (one worker, N_max = 2) to still be running when the other
    // run has been refused.
    let args = ["--n-max", "2", "--jobs", "1"];
    let mut runs = [
        synthesize(&out, &args).spawn().unwrap(),
        synthesize(&out, &args).spawn().unwrap(),
    ];
    let (k, refused) = first_to_end(&mut runs, Duration::from_secs(600));
    let survivor = &mut runs[1 - k];
    assert!(
        survivor.try_wait().unwrap().is_none(),
        "the run that proceeds is still running"
    );
    assert_eq!(refused.status.code(), Some(2), "{}", stderr(&refused));
    let err = stderr(&refused);
    assert!(err.contains(&out.display().to_string()), "{err}");
    assert!(err.contains(&format!("process {}", survivor.id())), "{err}");
    assert!(!free(&out), "the survivor holds the lock");
    // SIGKILL: the kernel releases the lock with the process.
    survivor.kill().unwrap();
    survivor.wait().unwrap();
    assert!(free(&out), "a killed run's lock is released");
    let o = synthesize(&out, &[&args[..], &["--resume"]].concat())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let records = std::fs::read_to_string(out.join("alternatives.jsonl")).unwrap();
    assert_eq!(
        records.lines().count() as u64,
        summary["alternatives"].as_u64().unwrap()
    );
}
