//! `foldsynth slurm` against a real Slurm (issue 15): a one-node cluster on localhost —
//! munged, slurmctld and slurmd of this test's own, configured from
//! `tests/slurm/slurm.conf.in` with fresh ports and state — runs the gripper at
//! N_max = 3 as a 4-shard job array and the merge job after it (`afterok`); the merged
//! run equals the single-machine run: the same records (timings aside), summary and
//! design files.
//!
//! Starting the daemons needs root and Debian's `slurm-wlm` and `munge`. Where they cannot
//! start, the test prints why and passes; with `FOLDSYNTH_REQUIRE_SLURM=1` (set by
//! `.ci/run`) that is a failure instead. The daemons are stopped when the test ends, also
//! when it fails (a guard's `Drop`).

use std::collections::BTreeMap;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

#[path = "common/runs.rs"]
mod runs;
use runs::{design_files, records, summary};

const GRIPPER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/grammar/gripper.toml");
const CONF_IN: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/slurm/slurm.conf.in");

/// The daemons of one test run; stopped on drop.
struct Cluster {
    dir: tempfile::TempDir,
    conf: PathBuf,
    /// (name, pid) of every daemon started, in start order.
    daemons: Vec<(&'static str, u32)>,
}

fn run(cmd: &mut Command) -> Result<Output, String> {
    let shown = format!("{cmd:?}");
    let o = cmd
        .output()
        .map_err(|e| format!("cannot run {shown}: {e}"))?;
    if o.status.success() {
        Ok(o)
    } else {
        Err(format!(
            "{shown} failed ({}): {}{}",
            o.status,
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        ))
    }
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).trim().to_string()
}

fn free_port() -> Result<u16, String> {
    let l = std::net::TcpListener::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    Ok(l.local_addr().map_err(|e| e.to_string())?.port())
}

/// Whether process `pid` still runs (a zombie has exited).
fn alive(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat"))
        .map(|s| {
            let state = s.rsplit(')').next().unwrap_or("").trim_start();
            !state.starts_with('Z') && !state.starts_with('X')
        })
        .unwrap_or(false)
}

/// The pid a daemon wrote to `file`, waiting for it up to 10 s.
fn pid_from(file: &Path) -> Result<u32, String> {
    let t0 = Instant::now();
    loop {
        if let Ok(text) = std::fs::read_to_string(file)
            && let Ok(pid) = text.trim().parse()
        {
            return Ok(pid);
        }
        if t0.elapsed() > Duration::from_secs(10) {
            return Err(format!("{} did not appear", file.display()));
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

impl Cluster {
    fn start() -> Result<Cluster, String> {
        let uid = run(Command::new("id").arg("-u")).map(|o| stdout(&o))?;
        if uid != "0" {
            return Err(format!(
                "starting munged and slurmd needs root (uid {uid} here)"
            ));
        }
        for tool in [
            "munged",
            "slurmctld",
            "slurmd",
            "sbatch",
            "scontrol",
            "sinfo",
        ] {
            run(Command::new("sh").args(["-c", &format!("command -v {tool}")]))
                .map_err(|_| format!("{tool} is not installed (Debian: slurm-wlm, munge)"))?;
        }
        // Short: the munge socket's path must fit a Unix socket address.
        let dir = tempfile::Builder::new()
            .prefix("fs-slurm")
            .tempdir_in("/tmp")
            .map_err(|e| e.to_string())?;
        let d = dir.path().to_path_buf();
        let conf = d.join("slurm.conf");
        let mut cluster = Cluster {
            dir,
            conf: conf.clone(),
            daemons: Vec::new(),
        };
        let perm = |p: &Path, mode| {
            std::fs::set_permissions(p, std::fs::Permissions::from_mode(mode))
                .map_err(|e| format!("{}: {e}", p.display()))
        };
        perm(&d, 0o755)?;
        for sub in ["munge", "state", "spool", "log"] {
            std::fs::create_dir_all(d.join(sub)).map_err(|e| e.to_string())?;
        }
        // A key of this test's own: no other munged can vouch for its jobs.
        let mut key = vec![0u8; 1024];
        {
            use std::io::Read;
            std::fs::File::open("/dev/urandom")
                .and_then(|mut f| f.read_exact(&mut key))
                .map_err(|e| format!("/dev/urandom: {e}"))?;
        }
        let munge = d.join("munge");
        std::fs::write(munge.join("munge.key"), &key).map_err(|e| e.to_string())?;
        run(Command::new("chown")
            .args(["-R", "munge:munge"])
            .arg(&munge))?;
        perm(&munge.join("munge.key"), 0o400)?;
        // munged requires its socket's directory to be searchable by everyone.
        perm(&munge, 0o755)?;
        let socket = munge.join("munge.socket");
        run(Command::new("runuser")
            .args(["-u", "munge", "--", "munged"])
            .arg(format!("--socket={}", socket.display()))
            .arg(format!("--key-file={}", munge.join("munge.key").display()))
            .arg(format!("--pid-file={}", munge.join("munged.pid").display()))
            .arg(format!("--log-file={}", munge.join("munged.log").display()))
            .arg(format!(
                "--seed-file={}",
                munge.join("munged.seed").display()
            )))?;
        cluster
            .daemons
            .push(("munged", pid_from(&munge.join("munged.pid"))?));

        let host = run(Command::new("hostname").arg("-s")).map(|o| stdout(&o))?;
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let text = std::fs::read_to_string(CONF_IN)
            .map_err(|e| format!("{CONF_IN}: {e}"))?
            .replace("@DIR@", &d.display().to_string())
            .replace("@HOST@", &host)
            .replace("@CPUS@", &cpus.to_string())
            .replace("@CTLD_PORT@", &free_port()?.to_string())
            .replace("@SLURMD_PORT@", &free_port()?.to_string())
            .replace("@MUNGE_SOCKET@", &socket.display().to_string());
        std::fs::write(&conf, text).map_err(|e| e.to_string())?;
        for (daemon, pid_file) in [("slurmctld", "slurmctld.pid"), ("slurmd", "slurmd.pid")] {
            run(Command::new(daemon)
                .arg("-f")
                .arg(&conf)
                .env("SLURM_CONF", &conf))?;
            cluster.daemons.push((daemon, pid_from(&d.join(pid_file))?));
        }
        // Ready when the node is idle.
        let t0 = Instant::now();
        loop {
            let state = cluster
                .cmd("sinfo")
                .args(["-h", "-o", "%T"])
                .output()
                .map(|o| stdout(&o))
                .unwrap_or_default();
            if state == "idle" {
                return Ok(cluster);
            }
            if t0.elapsed() > Duration::from_secs(60) {
                return Err(format!(
                    "the node did not become idle in 60 s (sinfo: '{state}'); logs in {}",
                    d.join("log").display()
                ));
            }
            std::thread::sleep(Duration::from_millis(300));
        }
    }

    /// A command that talks to this cluster.
    fn cmd(&self, program: &str) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", &self.conf);
        c
    }

    /// `scontrol show job ID` as key=value pairs, one map per job (array tasks).
    /// Wait for job `id` (a merge job: it runs only after every shard succeeded); its
    /// final state and reason.
    fn wait(&self, id: &str) -> String {
        let t0 = Instant::now();
        loop {
            let job = self.jobs(id).pop().unwrap_or_default();
            let state = job.get("JobState").cloned().unwrap_or_default();
            let reason = job.get("Reason").cloned().unwrap_or_default();
            if DONE.contains(&state.as_str()) || reason == "DependencyNeverSatisfied" {
                return format!("{state} ({reason})");
            }
            if t0.elapsed() > Duration::from_secs(1800) {
                return format!("still {state} ({reason}) after 30 min");
            }
            std::thread::sleep(Duration::from_secs(1));
        }
    }

    fn jobs(&self, id: &str) -> Vec<BTreeMap<String, String>> {
        let o = self
            .cmd("scontrol")
            .args(["show", "job", "-o", id])
            .output()
            .map(|o| stdout(&o))
            .unwrap_or_default();
        o.lines()
            .map(|l| {
                l.split_whitespace()
                    .filter_map(|kv| kv.split_once('='))
                    .map(|(k, v)| (k.to_string(), v.to_string()))
                    .collect()
            })
            .collect()
    }

    /// The daemons' logs, for a failure message.
    fn logs(&self) -> String {
        let mut s = String::new();
        for f in ["log/slurmctld.log", "log/slurmd.log", "munge/munged.log"] {
            let text = std::fs::read_to_string(self.dir.path().join(f)).unwrap_or_default();
            let tail: Vec<&str> = text.lines().rev().take(15).collect();
            s += &format!(
                "--- {f} (last lines)\n{}\n",
                tail.into_iter().rev().collect::<Vec<_>>().join("\n")
            );
        }
        s
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        // `scontrol shutdown` stops slurmctld and the slurmd; whatever still runs after
        // 10 s, and munged, get SIGTERM.
        let _ = self.cmd("scontrol").arg("shutdown").output();
        let t0 = Instant::now();
        while self
            .daemons
            .iter()
            .any(|(n, pid)| *n != "munged" && alive(*pid))
            && t0.elapsed() < Duration::from_secs(10)
        {
            std::thread::sleep(Duration::from_millis(200));
        }
        for (_, pid) in self.daemons.iter().rev() {
            if alive(*pid) {
                let _ = Command::new("kill").arg(pid.to_string()).output();
            }
        }
    }
}

/// The cluster, or `None` (after saying why) where Slurm cannot start here.
fn cluster_or_skip() -> Option<Cluster> {
    match Cluster::start() {
        Ok(c) => Some(c),
        Err(why) if std::env::var("FOLDSYNTH_REQUIRE_SLURM").as_deref() == Ok("1") => {
            panic!("FOLDSYNTH_REQUIRE_SLURM=1, but Slurm cannot start: {why}")
        }
        Err(why) => {
            eprintln!("skipping the Slurm test: {why}");
            None
        }
    }
}

const DONE: [&str; 7] = [
    "COMPLETED",
    "FAILED",
    "CANCELLED",
    "TIMEOUT",
    "NODE_FAIL",
    "OUT_OF_MEMORY",
    "PREEMPTED",
];

#[test]
fn four_slurm_shards_merged_equal_the_single_machine_run() {
    let Some(cluster) = cluster_or_skip() else {
        return;
    };
    let work = cluster.dir.path().join("work");
    let settings = ["--n-max", "3", "--starts", "8", "--seed", "5"];
    let o = cluster
        .cmd(env!("CARGO_BIN_EXE_foldsynth"))
        .args(["slurm", GRIPPER, "--shards", "4", "--cpus-per-task", "1"])
        .args(settings)
        .args(["--no-export", "--submit", "--out"])
        .arg(&work)
        .output()
        .unwrap();
    let said = stdout(&o);
    assert!(
        o.status.success(),
        "{said}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // "submitted: shards job A (array 1-4), merge job B (after all shards succeed)"
    let ids: Vec<&str> = said
        .lines()
        .find(|l| l.starts_with("submitted:"))
        .expect("job ids printed")
        .split_whitespace()
        .filter(|w| w.chars().all(|c| c.is_ascii_digit()) && !w.is_empty())
        .collect();
    let (array, merge) = (ids[0].to_string(), ids[1].to_string());
    let script = std::fs::read_to_string(work.join("shards.sbatch")).unwrap();
    assert!(script.contains("#SBATCH --array=1-4"), "{script}");
    assert!(
        script.contains("--shard \"$SLURM_ARRAY_TASK_ID/4\" --jobs \"$SLURM_CPUS_PER_TASK\""),
        "{script}"
    );

    let merge_state = cluster.wait(&merge);
    let shard_states: Vec<String> = cluster
        .jobs(&array)
        .iter()
        .map(|j| {
            format!(
                "{}:{}",
                j.get("ArrayTaskId").cloned().unwrap_or_default(),
                j.get("JobState").cloned().unwrap_or_default()
            )
        })
        .collect();
    let logs = || {
        let mut s = cluster.logs();
        if let Ok(dir) = std::fs::read_dir(work.join("logs")) {
            for e in dir.flatten() {
                s += &format!(
                    "--- {}\n{}\n",
                    e.path().display(),
                    std::fs::read_to_string(e.path()).unwrap_or_default()
                );
            }
        }
        s
    };
    assert!(
        merge_state.starts_with("COMPLETED"),
        "merge job {merge}: {merge_state}; shards {shard_states:?}\n{}",
        logs()
    );
    assert_eq!(shard_states.len(), 4, "{shard_states:?}");
    assert!(
        shard_states.iter().all(|s| s.ends_with(":COMPLETED")),
        "{shard_states:?}"
    );

    // The same search on one machine.
    let single = cluster.dir.path().join("single");
    let o = Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args(["synthesize", GRIPPER, "--jobs", "2", "--no-export"])
        .args(settings)
        .arg("--out")
        .arg(&single)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let merged = work.join("result");
    let whole = records(&single);
    assert_eq!(whole.len(), 1194, "the gripper's alternatives at N_max = 3");
    assert_eq!(records(&merged), whole, "merged records differ");
    assert_eq!(summary(&merged), summary(&single));
    assert_eq!(design_files(&merged), design_files(&single));
    // Every shard ran its own share: four directories whose records add up to the whole.
    let per_shard: Vec<usize> = (1..=4)
        .map(|k| records(&work.join("shards").join(k.to_string())).len())
        .collect();
    assert_eq!(per_shard.iter().sum::<usize>(), 1194, "{per_shard:?}");
    assert!(per_shard.iter().all(|&n| n > 0), "{per_shard:?}");
}

#[test]
fn a_guided_search_in_slurm_shards_is_the_single_machine_guided_run() {
    let Some(cluster) = cluster_or_skip() else {
        return;
    };
    let work = cluster.dir.path().join("guided");
    let settings = ["--n-max", "3", "--starts", "4", "--seed", "2"];
    let guided = ["--strategy", "guided", "--budget-alternatives", "300"];
    let o = cluster
        .cmd(env!("CARGO_BIN_EXE_foldsynth"))
        .args(["slurm", GRIPPER, "--shards", "3", "--cpus-per-task", "1"])
        .args(settings)
        .args(guided)
        .args(["--no-export", "--submit", "--out"])
        .arg(&work)
        .output()
        .unwrap();
    let said = stdout(&o);
    assert!(
        o.status.success(),
        "{said}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let script = std::fs::read_to_string(work.join("shards.sbatch")).unwrap();
    assert!(
        script.contains("--strategy guided --budget-alternatives 300"),
        "{script}"
    );
    let merge = said
        .split_whitespace()
        .skip_while(|w| *w != "merge")
        .nth(2)
        .expect("the merge job's id printed")
        .to_string();
    let state = cluster.wait(&merge);
    assert!(
        state.starts_with("COMPLETED"),
        "merge job {merge}: {state}\n{}",
        cluster.logs()
    );
    // Shards start from no parent's optimum: the single run without warm starts.
    let single = cluster.dir.path().join("single-guided");
    let o = Command::new(env!("CARGO_BIN_EXE_foldsynth"))
        .args([
            "synthesize",
            GRIPPER,
            "--jobs",
            "2",
            "--no-export",
            "--no-warm-starts",
        ])
        .args(settings)
        .args(guided)
        .arg("--out")
        .arg(&single)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let merged = work.join("result");
    let whole = records(&single);
    assert!(whole.len() >= 300 && whole.len() < 1194, "{}", whole.len());
    assert_eq!(records(&merged), whole, "merged records differ");
    assert_eq!(summary(&merged), summary(&single));
}
