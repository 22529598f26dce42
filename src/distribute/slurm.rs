//! `foldsynth slurm`: batch scripts that run a search as a Slurm job array and merge it.
//!
//! `DIR/shards.sbatch` is a job array with one task per shard; task K runs
//! `synthesize TASK --shard K/N --jobs $SLURM_CPUS_PER_TASK --resume --out DIR/shards/K`
//! (so a requeued or resubmitted task continues where it stopped). `DIR/merge.sbatch`
//! merges `DIR/shards/1 … N` into `DIR/result`; it is submitted with
//! `--dependency=afterok:<array job>` so it starts once every shard succeeded. The task
//! file is copied to `DIR/task/` first: the jobs read that copy, not a file that may be
//! edited while they wait. Slurm schedules; foldsynth only writes the scripts (and, with
//! `--submit`, calls `sbatch`).

use std::path::{Path, PathBuf};
use std::process::Command;

use super::DistributeError;
use crate::limits;

/// What the batch scripts run and ask for.
#[derive(Clone, Debug)]
pub struct SlurmOptions {
    /// Number of shards (array tasks).
    pub shards: usize,
    /// `#SBATCH --partition`.
    pub partition: Option<String>,
    /// `#SBATCH --time` (Slurm's formats: minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM:SS).
    pub time: Option<String>,
    /// `#SBATCH --cpus-per-task`: worker threads per shard.
    pub cpus_per_task: usize,
    /// Where the scripts, shards, logs and the merged result go.
    pub out: PathBuf,
    /// N_max (default: the task's).
    pub n_max: Option<usize>,
    /// Starting points per alternative.
    pub starts: usize,
    /// Seed.
    pub seed: u64,
    /// States of the verification sweep.
    pub sweep: usize,
    /// Exports and report in the merged run.
    pub export: bool,
    /// The grammar's rules (every shard's search uses them; merge reads them from the
    /// shards' settings).
    pub rules: crate::grammar::Rules,
    /// Optimize without the robustness block (`--post-check-only`).
    pub post_check_only: bool,
    /// A guided search (`--strategy guided`) of this many alternatives (`Some(None)`:
    /// every model, in the guided order); `None`: the exhaustive search. Each shard
    /// evaluates its deal of the budget's models.
    pub guided: Option<Option<u64>>,
    /// The foldsynth binary the jobs run.
    pub foldsynth: PathBuf,
}

/// The files `write_scripts` wrote.
#[derive(Clone, Debug)]
pub struct SlurmFiles {
    /// The directory (absolute).
    pub dir: PathBuf,
    /// The job array.
    pub shards_script: PathBuf,
    /// The merge job.
    pub merge_script: PathBuf,
    /// The merged run's directory.
    pub result: PathBuf,
}

impl SlurmFiles {
    /// The shell commands that submit both jobs, the merge after the array.
    pub fn submit_commands(&self) -> String {
        format!(
            "jid=$(sbatch --parsable {}) && sbatch --dependency=afterok:\"${{jid%%;*}}\" {}",
            quote(&self.shards_script.display().to_string()),
            quote(&self.merge_script.display().to_string())
        )
    }
}

/// The job ids `submit` got from `sbatch`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Submitted {
    /// The job array.
    pub shards: String,
    /// The merge job.
    pub merge: String,
}

/// `s` quoted for a POSIX shell.
fn quote(s: &str) -> String {
    format!("'{}'", s.replace('\'', "'\\''"))
}

/// A value for an `#SBATCH` line: letters, digits and `_ . , : -` only (the line is not
/// parsed by a shell, and whitespace would end the value).
fn sbatch_value(what: &str, v: &str) -> Result<String, DistributeError> {
    let ok = !v.is_empty()
        && v.len() <= 200
        && v.chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | ',' | ':' | '-'));
    if ok {
        Ok(v.to_string())
    } else {
        Err(DistributeError::input(
            format!("--{what}"),
            format!(
                "'{}' is not a Slurm {what}: use letters, digits and _ . , : - only",
                crate::text::excerpt(v, 60)
            ),
        ))
    }
}

/// Write the task copy and both batch scripts into `opts.out` (created if missing).
/// `task_file` is the task's path (its name is kept, so a task without a `name` keeps its
/// name), `task_text` its text.
pub fn write_scripts(
    task_file: &Path,
    task_text: &str,
    task_name: &str,
    opts: &SlurmOptions,
) -> Result<SlurmFiles, DistributeError> {
    let shown = |e: std::io::Error, p: &Path| DistributeError::input(p, e.to_string());
    let resources = sbatch_resources(opts)?;
    std::fs::create_dir_all(&opts.out).map_err(|e| shown(e, &opts.out))?;
    let dir = std::fs::canonicalize(&opts.out).map_err(|e| shown(e, &opts.out))?;
    let dir_text = dir.display().to_string();
    // The log paths go on #SBATCH lines, where Slurm splits at whitespace and expands %.
    if dir_text
        .chars()
        .any(|c| c.is_whitespace() || c.is_control() || c == '%')
    {
        return Err(DistributeError::input(
            &dir,
            "the directory's path contains whitespace or '%', which #SBATCH --output cannot take; choose another --out",
        ));
    }
    let task_copy = copy_task(&dir, task_file, task_text)?;
    let bin = quote(&opts.foldsynth.display().to_string());
    let n = opts.shards;
    let safe_name: String = task_name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .take(40)
        .collect();
    let settings = search_settings(opts);
    let header = |job: &str, log: &str| {
        format!(
            "#!/bin/bash\n#SBATCH --job-name={job}\n{resources}#SBATCH --output={dir_text}/logs/{log}\n"
        )
    };
    let shards_script = dir.join("shards.sbatch");
    let text = format!(
        "{}#SBATCH --array=1-{n}\n\
         # foldsynth slurm: shard $SLURM_ARRAY_TASK_ID of {n} of the search of task '{task_name}'.\n\
         # A rerun continues the shard (--resume); merge.sbatch runs after all shards succeed.\n\
         set -euo pipefail\n\
         exec {bin} synthesize {} --shard \"$SLURM_ARRAY_TASK_ID/{n}\" --jobs \"$SLURM_CPUS_PER_TASK\"{settings} --resume --out {}\"$SLURM_ARRAY_TASK_ID\"\n",
        header(&format!("foldsynth-{safe_name}"), "shard-%a.out"),
        quote(&task_copy.display().to_string()),
        quote(&format!("{dir_text}/shards/")),
    );
    std::fs::write(&shards_script, text).map_err(|e| shown(e, &shards_script))?;
    let merge_script = dir.join("merge.sbatch");
    let result = dir.join("result");
    let text = format!(
        "{}# foldsynth slurm: merge the {n} shards of task '{task_name}' into {}.\n\
         # Submit with --dependency=afterok:<the array job's id>.\n\
         set -euo pipefail\n\
         shards=()\n\
         for k in $(seq 1 {n}); do shards+=({}\"$k\"); done\n\
         exec {bin} merge \"${{shards[@]}}\" --jobs \"$SLURM_CPUS_PER_TASK\"{} --out {}\n",
        header(&format!("foldsynth-{safe_name}-merge"), "merge.out"),
        result.display(),
        quote(&format!("{dir_text}/shards/")),
        if opts.export { "" } else { " --no-export" },
        quote(&result.display().to_string()),
    );
    std::fs::write(&merge_script, text).map_err(|e| shown(e, &merge_script))?;
    Ok(SlurmFiles {
        dir,
        shards_script,
        merge_script,
        result,
    })
}

/// The `#SBATCH` lines both jobs share (CPUs per task, partition, time), each value
/// checked.
fn sbatch_resources(opts: &SlurmOptions) -> Result<String, DistributeError> {
    limits::check_count("shards", opts.shards as u64, 1, limits::SHARDS_MAX as u64)
        .map_err(|m| DistributeError::input("--shards", m))?;
    limits::check_count(
        "cpus-per-task",
        opts.cpus_per_task as u64,
        1,
        limits::JOBS_MAX as u64,
    )
    .map_err(|m| DistributeError::input("--cpus-per-task", m))?;
    let partition = opts
        .partition
        .as_deref()
        .map(|p| sbatch_value("partition", p))
        .transpose()?;
    let time = opts
        .time
        .as_deref()
        .map(|t| sbatch_value("time", t))
        .transpose()?;
    let mut h = format!("#SBATCH --cpus-per-task={}\n", opts.cpus_per_task);
    if let Some(p) = &partition {
        h += &format!("#SBATCH --partition={p}\n");
    }
    if let Some(t) = &time {
        h += &format!("#SBATCH --time={t}\n");
    }
    Ok(h)
}

/// Create `dir`'s `task`, `logs` and `shards` directories and copy the task there (under
/// `task_file`'s name): the jobs read that copy. Its path.
fn copy_task(dir: &Path, task_file: &Path, task_text: &str) -> Result<PathBuf, DistributeError> {
    let shown = |e: std::io::Error, p: &Path| DistributeError::input(p, e.to_string());
    let file_name = task_file
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .filter(|f| !f.is_empty())
        .unwrap_or_else(|| "task.toml".into());
    for sub in ["task", "logs", "shards"] {
        let p = dir.join(sub);
        std::fs::create_dir_all(&p).map_err(|e| shown(e, &p))?;
    }
    let task_copy = dir.join("task").join(&file_name);
    std::fs::write(&task_copy, task_text).map_err(|e| shown(e, &task_copy))?;
    Ok(task_copy)
}

/// The search's settings as `synthesize` flags (each with a leading space).
fn search_settings(opts: &SlurmOptions) -> String {
    let mut settings = String::new();
    if let Some(k) = opts.n_max {
        settings += &format!(" --n-max {k}");
    }
    settings += &format!(
        " --starts {} --seed {} --sweep {}",
        opts.starts, opts.seed, opts.sweep
    );
    if opts.rules != crate::grammar::Rules::default() {
        settings += &format!(" --rules {}", opts.rules.names());
    }
    if opts.post_check_only {
        settings += " --post-check-only";
    }
    if let Some(budget) = opts.guided {
        settings += " --strategy guided";
        if let Some(n) = budget {
            settings += &format!(" --budget-alternatives {n}");
        }
    }
    settings
}

/// Run `sbatch ARGS`; the job id it prints with `--parsable` (`id` or `id;cluster`).
fn sbatch(args: &[&str]) -> Result<String, DistributeError> {
    let out = Command::new("sbatch")
        .arg("--parsable")
        .args(args)
        .output()
        .map_err(|e| {
            DistributeError::input(
                "sbatch",
                format!("cannot run sbatch ({e}): run foldsynth slurm --submit where Slurm's commands are on PATH, or submit the scripts yourself"),
            )
        })?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        return Err(DistributeError::input(
            format!("sbatch {}", args.join(" ")),
            format!(
                "failed ({}): {}",
                out.status,
                crate::text::excerpt(String::from_utf8_lossy(&out.stderr).trim(), 1000)
            ),
        ));
    }
    let id = stdout.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        return Err(DistributeError::input(
            "sbatch",
            format!(
                "printed '{}' where a job id was expected",
                crate::text::excerpt(stdout.trim(), 200)
            ),
        ));
    }
    Ok(id)
}

/// Submit the job array, then the merge job depending on it (`afterok`).
pub fn submit(files: &SlurmFiles) -> Result<Submitted, DistributeError> {
    let shards = sbatch(&[&files.shards_script.display().to_string()])?;
    let merge = sbatch(&[
        &format!("--dependency=afterok:{shards}"),
        &files.merge_script.display().to_string(),
    ])?;
    Ok(Submitted { shards, merge })
}
