//! The output directory of a search: where a run may write, what it may delete, and when
//! it may reuse earlier records.
//!
//! - One run at a time: a run locks its directory ([`super::lock`]) before it reads or
//!   writes anything there; a second run is refused ([`OutputError::Busy`]) at once.
//! - A run writes only under its output directory (`--out`, or `out/<name>` with the task
//!   name made a safe file name by [`default_dir`]).
//! - Every file and directory a run creates is listed in `OUT/manifest.json` *before* it
//!   is written, so even a killed run leaves a complete list. A later run deletes only
//!   what an earlier run listed there: nothing else in the directory is ever removed.
//! - A non-empty directory is used only when it holds a foldsynth run (a readable
//!   manifest) of the same [`RunSettings`]; anything else is refused unless `--force`.
//!   With `--force` a foldsynth run of other settings is replaced (its listed files
//!   deleted) and a foreign directory is written into without deleting anything.
//! - `--resume` reuses `alternatives.jsonl` only when `settings.json` is readable and equal
//!   to this run's settings; [`keep_records`] says how many records it reused and why it
//!   dropped any.

use std::collections::{BTreeSet, HashSet};
use std::fs::{self, File};
use std::io::{BufRead, BufReader, Write};
use std::path::{Component, Path, PathBuf};
use std::sync::Mutex;

use serde::{Deserialize, Serialize};

use super::lock::{DirLock, LOCK, LockError, lock_dir};
use super::record::AlternativeRecord;

/// The list of files a run wrote.
pub const MANIFEST: &str = "manifest.json";
/// The settings that decide the results.
pub const SETTINGS: &str = "settings.json";
/// One record per alternative, streamed.
pub const RECORDS: &str = "alternatives.jsonl";
/// Longest file name [`default_dir`] derives from a task name.
pub const DIR_NAME_MAX: usize = 64;

/// The settings that decide a search's results: a resumed run must use the same ones, or
/// its records would mix two searches.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct RunSettings {
    /// Task name.
    pub task: String,
    /// Digest of the task file's text (FNV-1a, 64 bits): an edited task is another task.
    pub task_digest: String,
    /// N_max used.
    pub n_max: usize,
    /// Starting points per alternative.
    pub starts: usize,
    /// Seed of the starting points.
    pub seed: u64,
    /// States of the verification sweep.
    pub sweep: usize,
    /// foldsynth's version.
    pub foldsynth: String,
    /// Grammar rules when not the default `r1,r2` (e.g. `r1,r2,r2p`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rules: Option<String>,
    /// Optimized without the clearance and margin constraints (`--post-check-only`).
    pub post_check_only: bool,
    /// The share of the search this directory holds (`synthesize --shard K/N`); absent
    /// for a whole run (and for `merge`'s result, which is one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<ShardSpec>,
    /// A shard of a guided search: the budget its share was dealt from (the models a
    /// guided run of this budget evaluates; absent for an exhaustive shard and any whole
    /// run, so a whole run's records serve either strategy).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub guided: Option<super::strategy::Selection>,
    /// The graphs a run restricted to some (`synthesize --graph`), as given; absent: every
    /// meaningful graph.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub graphs: Vec<String>,
}

/// Shard K of N (1 ≤ K ≤ N), written `K/N`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct ShardSpec {
    /// K, from 1.
    pub index: usize,
    /// N.
    pub count: usize,
}

impl std::fmt::Display for ShardSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl std::str::FromStr for ShardSpec {
    type Err = String;
    fn from_str(s: &str) -> Result<ShardSpec, String> {
        let shown = excerpt(s);
        let usage = "write K/N with whole numbers 1 ≤ K ≤ N, e.g. 3/16 (shard 3 of 16)";
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| format!("'{shown}' is not a shard: {usage}"))?;
        let num = |t: &str, what: &str| {
            t.trim().parse::<usize>().map_err(|_| {
                format!(
                    "'{shown}': {what} '{}' is not a whole number; {usage}",
                    excerpt(t)
                )
            })
        };
        let (index, count) = (num(k, "K")?, num(n, "N")?);
        if count == 0 || count > crate::limits::SHARDS_MAX {
            return Err(format!(
                "'{shown}': N = {count} shards; allowed 1 to {}",
                crate::limits::SHARDS_MAX
            ));
        }
        if index == 0 || index > count {
            return Err(format!(
                "'{shown}': shard {index} of {count} does not exist; shards are numbered 1 to {count}"
            ));
        }
        Ok(ShardSpec { index, count })
    }
}

impl TryFrom<String> for ShardSpec {
    type Error = String;
    fn try_from(s: String) -> Result<ShardSpec, String> {
        s.parse()
    }
}

impl From<ShardSpec> for String {
    fn from(s: ShardSpec) -> String {
        s.to_string()
    }
}

impl RunSettings {
    /// The settings that differ between `self` (this run) and `old`, as "key: old → new".
    fn differences(&self, old: &serde_json::Value) -> Vec<String> {
        let new = serde_json::to_value(self).unwrap_or_default();
        let (Some(new), Some(old_map)) = (new.as_object(), old.as_object()) else {
            return vec![format!(
                "not a settings object: {}",
                excerpt(&old.to_string())
            )];
        };
        let keys: BTreeSet<&String> = new.keys().chain(old_map.keys()).collect();
        keys.into_iter()
            .filter(|k| new.get(*k) != old_map.get(*k))
            .map(|k| {
                let show = |v: Option<&serde_json::Value>| {
                    v.map_or("(absent)".to_string(), |v| excerpt(&v.to_string()))
                };
                format!(
                    "{k}: {} there, {} now",
                    show(old_map.get(k)),
                    show(new.get(k))
                )
            })
            .collect()
    }

    /// Whether `old` (an earlier run's settings file) holds these settings: `Err(why)`
    /// when not, or when it is missing or unreadable.
    fn same_as(&self, old: &Found<serde_json::Value>) -> Result<(), String> {
        match old {
            Found::Read(v) => {
                let diff = self.differences(v);
                if diff.is_empty() {
                    Ok(())
                } else {
                    Err(format!(
                        "it holds a run of other settings ({})",
                        diff.join("; ")
                    ))
                }
            }
            Found::Missing => Err(format!(
                "its {SETTINGS} is missing, so nothing shows which settings wrote its records"
            )),
            Found::Unreadable(e) => Err(format!(
                "its {SETTINGS} is unreadable ({e}), so nothing shows which settings wrote its records"
            )),
        }
    }
}

/// An error opening or writing the output directory.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file or directory.
        path: String,
        /// The error.
        #[source]
        source: std::io::Error,
    },
    /// Another run (process `pid`, when it has written its id) holds the directory's lock.
    #[error(
        "{path}: another foldsynth run ({}) is writing into this directory; wait for it to end, or give another --out (--resume and --force do not wait either)",
        pid.map_or("a process that has not yet written its id to .foldsynth.lock".to_string(), |p| format!("process {p}"))
    )]
    Busy {
        /// The directory.
        path: String,
        /// The process that holds the lock.
        pid: Option<u32>,
    },
    /// The directory is not one this run may use (without `--force`).
    #[error("{path}: {message}")]
    Refused {
        /// The directory.
        path: String,
        /// Why, and what to do.
        message: String,
    },
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
    move |source| OutputError::Io {
        path: path.display().to_string(),
        source,
    }
}

/// The directory `shown` may not be used (without `--force`): why, and what to do.
fn refused(shown: &str, message: String) -> OutputError {
    OutputError::Refused {
        path: shown.to_string(),
        message,
    }
}

/// Cut a text echoed in a message to a readable length.
fn excerpt(s: &str) -> String {
    crate::text::excerpt(s, 200)
}

/// `out/<name>` with `name` made one safe path component: characters other than ASCII
/// letters, digits, `-`, `_` and `.` become `_`, a leading `.` too, at most
/// [`DIR_NAME_MAX`] characters; an empty name becomes `task`.
pub fn default_dir(name: &str) -> PathBuf {
    let mut s: String = name
        .chars()
        .take(DIR_NAME_MAX)
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.starts_with('.') {
        s.replace_range(0..1, "_");
    }
    if s.is_empty() {
        s = "task".into();
    }
    PathBuf::from("out").join(s)
}

/// A relative path inside the output directory made only of plain names (what a manifest
/// may list); `None` for anything that could point elsewhere.
fn inside(rel: &str) -> Option<PathBuf> {
    let p = Path::new(rel);
    let plain = !rel.is_empty() && p.components().all(|c| matches!(c, Component::Normal(_)));
    plain.then(|| p.to_path_buf())
}

/// The manifest: every file and directory the run created, relative to the directory.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
struct Manifest {
    /// Who wrote it (always "foldsynth").
    creator: String,
    /// foldsynth's version.
    foldsynth: String,
    /// The command (`synthesize`).
    command: String,
    /// Files, relative paths with `/`.
    #[serde(default)]
    files: BTreeSet<String>,
    /// Directories the run created.
    #[serde(default)]
    dirs: BTreeSet<String>,
}

impl Manifest {
    fn new() -> Manifest {
        Manifest {
            creator: "foldsynth".into(),
            foldsynth: env!("CARGO_PKG_VERSION").into(),
            command: "synthesize".into(),
            ..Manifest::default()
        }
    }
}

/// What was found in a file the decision depends on.
enum Found<T> {
    Missing,
    Unreadable(String),
    Read(T),
}

fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Found<T> {
    match fs::read_to_string(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Found::Missing,
        Err(e) => Found::Unreadable(e.to_string()),
        Ok(text) => match serde_json::from_str(&text) {
            Ok(v) => Found::Read(v),
            Err(e) => Found::Unreadable(format!("not valid: {e}")),
        },
    }
}

/// An output directory opened for one run.
pub struct OutputDir {
    root: PathBuf,
    manifest: Mutex<Manifest>,
    /// This run's lock on the directory ([`super::lock`]), released when dropped.
    _lock: DirLock,
}

/// The outcome of [`OutputDir::open`].
pub struct Opened {
    /// The directory, ready to write.
    pub dir: OutputDir,
    /// Whether the earlier records may be reused (`--resume` on a run of the same settings).
    pub resume: bool,
    /// What was decided and why (for the user).
    pub notes: Vec<String>,
}

impl OutputDir {
    /// Open `root` for a run with `settings`: see the module docs for what is refused.
    pub fn open(
        root: &Path,
        settings: &RunSettings,
        resume: bool,
        force: bool,
    ) -> Result<Opened, OutputError> {
        let shown = root.display().to_string();
        let mut notes = Vec::new();
        match fs::metadata(root) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                fs::create_dir_all(root).map_err(io_err(root))?;
                let lock = OutputDir::lock(root, &mut notes)?;
                if resume {
                    notes.push(format!("--resume: {shown} did not exist; starting afresh"));
                }
                let dir = OutputDir::fresh(root, lock)?;
                return Ok(Opened {
                    dir,
                    resume: false,
                    notes,
                });
            }
            Err(e) => return Err(io_err(root)(e)),
            Ok(m) if !m.is_dir() => {
                return Err(refused(
                    &shown,
                    "is not a directory; --out takes a directory (it is created if missing)".into(),
                ));
            }
            Ok(_) => {}
        }
        // Nothing in the directory is read before the lock is ours.
        let lock = OutputDir::lock(root, &mut notes)?;
        let created = lock.created;
        let opened = OutputDir::open_existing(root, lock, settings, resume, force, notes);
        if created && matches!(opened, Err(OutputError::Refused { .. })) {
            // A refused directory is left as it was (the lock is released by now).
            let _ = fs::remove_file(root.join(LOCK));
        }
        opened
    }

    /// Open `root`, an existing directory this run holds the `lock` of: see the module
    /// docs for what is refused.
    fn open_existing(
        root: &Path,
        lock: DirLock,
        settings: &RunSettings,
        resume: bool,
        force: bool,
        mut notes: Vec<String>,
    ) -> Result<Opened, OutputError> {
        let shown = root.display().to_string();
        let empty = fs::read_dir(root)
            .map_err(io_err(root))?
            .all(|e| e.is_ok_and(|e| e.file_name() == LOCK));
        if empty {
            if resume {
                notes.push(format!(
                    "--resume: {shown} is empty, nothing to resume; starting afresh"
                ));
            }
            return Ok(Opened {
                dir: OutputDir::fresh(root, lock)?,
                resume: false,
                notes,
            });
        }
        let manifest: Found<Manifest> = read_json(&root.join(MANIFEST));
        let old_settings: Found<serde_json::Value> = read_json(&root.join(SETTINGS));
        let manifest = match manifest {
            Found::Read(m) if m.creator == "foldsynth" => m,
            other => return OutputDir::open_foreign(root, lock, &other, resume, force, notes),
        };
        let mut same = settings.same_as(&old_settings);
        // A run killed before it wrote its settings wrote no records either: nothing of
        // it can mix with this run, so it is resumed (or replaced) like one of the same
        // settings.
        let no_records = fs::metadata(root.join(RECORDS)).map_or(true, |m| m.len() == 0);
        if matches!(old_settings, Found::Missing) && no_records {
            same = Ok(());
        }
        OutputDir::open_earlier(root, lock, &manifest, same, resume, force, notes)
    }

    /// Take the lock on `root` ([`super::lock`]): refused while another run holds it.
    fn lock(root: &Path, notes: &mut Vec<String>) -> Result<DirLock, OutputError> {
        match lock_dir(root) {
            Ok((lock, note)) => {
                notes.extend(note);
                Ok(lock)
            }
            Err(LockError::Busy(pid)) => Err(OutputError::Busy {
                path: root.display().to_string(),
                pid,
            }),
            Err(LockError::Io(e)) => Err(io_err(&root.join(LOCK))(e)),
        }
    }

    /// Open `root`, which is not empty and holds no foldsynth run (`manifest`: what was
    /// found instead of its manifest): only with `force`, deleting nothing.
    fn open_foreign(
        root: &Path,
        lock: DirLock,
        manifest: &Found<Manifest>,
        resume: bool,
        force: bool,
        mut notes: Vec<String>,
    ) -> Result<Opened, OutputError> {
        let shown = root.display().to_string();
        let why = match manifest {
            Found::Unreadable(e) => format!("its {MANIFEST} is unreadable ({e})"),
            _ => format!("it has no {MANIFEST}"),
        };
        if !force {
            return Err(refused(
                &shown,
                format!(
                    "not empty, and not a foldsynth run ({why}); foldsynth writes into an empty or new directory, or its own earlier run of the same settings. Give another --out, or --force to write into it anyway (nothing foldsynth did not write is deleted)"
                ),
            ));
        }
        notes.push(format!(
            "--force: writing into {shown}, which is not a foldsynth run ({why}); files foldsynth does not write are left as they are"
        ));
        if resume {
            notes.push(
                "--resume: no earlier run of these settings to resume; starting afresh".into(),
            );
        }
        Ok(Opened {
            dir: OutputDir::fresh(root, lock)?,
            resume: false,
            notes,
        })
    }

    /// Open `root`, which holds an earlier foldsynth run (its `manifest`) of the same
    /// settings (`same`: `Err(why)` when not, or when nothing shows which): resumed or
    /// replaced, deleting only the files the manifest lists; a run of other settings only
    /// with `force`.
    fn open_earlier(
        root: &Path,
        lock: DirLock,
        manifest: &Manifest,
        same: Result<(), String>,
        resume: bool,
        force: bool,
        mut notes: Vec<String>,
    ) -> Result<Opened, OutputError> {
        let shown = root.display().to_string();
        let dir = OutputDir {
            root: root.to_path_buf(),
            manifest: Mutex::new(Manifest::new()),
            _lock: lock,
        };
        match same {
            Ok(()) => {
                // The same settings: an earlier run (or a killed one) of this very search.
                let keep: &[&str] = if resume { &[RECORDS, SETTINGS] } else { &[] };
                notes.extend(dir.remove_listed(manifest, keep));
                dir.adopt(manifest, keep)?;
                Ok(Opened { dir, resume, notes })
            }
            Err(why) if !force => {
                let what = if resume {
                    "--resume would mix two searches"
                } else {
                    "a new run would replace it"
                };
                Err(refused(
                    &shown,
                    format!(
                        "{why}; {what}. Rerun with the settings it was written with, give another --out, or add --force to start afresh there (deleting only the files its {MANIFEST} lists)"
                    ),
                ))
            }
            Err(why) => {
                notes.push(format!(
                    "--force: {shown}: {why}; deleting the files of that run and starting afresh"
                ));
                notes.extend(dir.remove_listed(manifest, &[]));
                dir.save()?;
                Ok(Opened {
                    dir,
                    resume: false,
                    notes,
                })
            }
        }
    }

    fn fresh(root: &Path, lock: DirLock) -> Result<OutputDir, OutputError> {
        let dir = OutputDir {
            root: root.to_path_buf(),
            manifest: Mutex::new(Manifest::new()),
            _lock: lock,
        };
        dir.save()?;
        Ok(dir)
    }

    /// Keep the entries of an earlier manifest that stay (`keep`) in this run's manifest.
    fn adopt(&self, old: &Manifest, keep: &[&str]) -> Result<(), OutputError> {
        let mut m = self.manifest.lock().unwrap_or_else(|e| e.into_inner());
        for f in keep {
            if old.files.contains(*f) {
                m.files.insert((*f).to_string());
            }
        }
        Self::write_manifest(&self.root, &m)
    }

    /// Delete the files an earlier manifest lists (except `keep`), then its directories
    /// that are left empty. Entries that could point outside the directory, and anything
    /// that is not a plain file, are left alone (and reported).
    fn remove_listed(&self, old: &Manifest, keep: &[&str]) -> Vec<String> {
        let mut notes = Vec::new();
        let keep: HashSet<&str> = keep.iter().copied().collect();
        for f in &old.files {
            if keep.contains(f.as_str()) {
                continue;
            }
            let Some(rel) = inside(f) else {
                notes.push(format!(
                    "{MANIFEST} lists {:?}, which is not a plain path inside the directory: left alone",
                    excerpt(f)
                ));
                continue;
            };
            let path = self.root.join(rel);
            match fs::symlink_metadata(&path) {
                Ok(m) if m.is_file() => {
                    if let Err(e) = fs::remove_file(&path) {
                        notes.push(format!("cannot delete {}: {e}", path.display()));
                    }
                }
                Ok(_) => notes.push(format!(
                    "{} is listed as a file of the earlier run but is not a plain file: left alone",
                    path.display()
                )),
                Err(_) => {}
            }
        }
        // Deepest first, so nested directories empty before their parents.
        let mut dirs: Vec<&String> = old.dirs.iter().collect();
        dirs.sort_by_key(|d| std::cmp::Reverse(Path::new(d.as_str()).components().count()));
        for d in dirs {
            if let Some(rel) = inside(d) {
                let path = self.root.join(rel);
                if fs::symlink_metadata(&path).is_ok_and(|m| m.is_dir()) {
                    // Fails, deliberately, when something else is still in there.
                    let _ = fs::remove_dir(&path);
                }
            }
        }
        notes
    }

    /// Write the manifest (atomically: a temporary file renamed over it). The lock is held
    /// throughout, so workers listing files at once do not race on the temporary file.
    fn save(&self) -> Result<(), OutputError> {
        let m = self.manifest.lock().unwrap_or_else(|e| e.into_inner());
        Self::write_manifest(&self.root, &m)
    }

    fn write_manifest(root: &Path, m: &Manifest) -> Result<(), OutputError> {
        let tmp = root.join(format!("{MANIFEST}.tmp"));
        let text = serde_json::to_string_pretty(m).unwrap_or_default();
        fs::write(&tmp, text + "\n").map_err(io_err(&tmp))?;
        let path = root.join(MANIFEST);
        fs::rename(&tmp, &path).map_err(io_err(&path))
    }

    /// The directory.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// `rel` inside the directory.
    pub fn path(&self, rel: &str) -> PathBuf {
        self.root.join(rel)
    }

    /// List files (paths inside the directory, or relative to it) in the manifest before
    /// they are written.
    pub fn register<P: AsRef<Path>>(
        &self,
        paths: impl IntoIterator<Item = P>,
    ) -> Result<(), OutputError> {
        let mut m = self.manifest.lock().unwrap_or_else(|e| e.into_inner());
        for p in paths {
            let p = p.as_ref();
            let rel = p.strip_prefix(&self.root).unwrap_or(p);
            let rel = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy())
                .collect::<Vec<_>>()
                .join("/");
            m.files.insert(rel);
        }
        Self::write_manifest(&self.root, &m)
    }

    /// Create the directory `rel` (listed in the manifest when this run creates it).
    /// A symbolic link there is refused: it could lead writes out of the directory.
    pub fn create_dir(&self, rel: &str) -> Result<PathBuf, OutputError> {
        Ok(self.create_dirs(&[rel.to_string()])?.remove(0))
    }

    /// [`OutputDir::create_dir`] for several directories, listed in one step.
    pub fn create_dirs(&self, rels: &[String]) -> Result<Vec<PathBuf>, OutputError> {
        let mut new = Vec::new();
        for rel in rels {
            let path = self.root.join(rel);
            match fs::symlink_metadata(&path) {
                Ok(m) if m.is_dir() => {}
                Ok(_) => {
                    return Err(OutputError::Refused {
                        path: path.display().to_string(),
                        message: "exists and is not a directory (a file or a link); foldsynth writes its designs into a directory of its own there".into(),
                    });
                }
                Err(_) => new.push(rel),
            }
        }
        if !new.is_empty() {
            let mut m = self.manifest.lock().unwrap_or_else(|e| e.into_inner());
            m.dirs.extend(new.iter().map(|r| r.to_string()));
            Self::write_manifest(&self.root, &m)?;
        }
        let mut out = Vec::with_capacity(rels.len());
        for rel in rels {
            let path = self.root.join(rel);
            fs::create_dir_all(&path).map_err(io_err(&path))?;
            out.push(path);
        }
        Ok(out)
    }

    /// Write a whole file (listed first).
    pub fn write(&self, rel: &str, bytes: impl AsRef<[u8]>) -> Result<PathBuf, OutputError> {
        let path = self.root.join(rel);
        self.register([&path])?;
        fs::write(&path, bytes).map_err(io_err(&path))?;
        Ok(path)
    }

    /// Create (truncate) a file for writing (listed first).
    pub fn create(&self, rel: &str) -> Result<(PathBuf, File), OutputError> {
        let path = self.root.join(rel);
        self.register([&path])?;
        let f = File::create(&path).map_err(io_err(&path))?;
        Ok((path, f))
    }
}

/// Why a line of `alternatives.jsonl` was not reused.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Dropped {
    /// 1-based line number.
    pub line: usize,
    /// Why.
    pub why: String,
}

/// What a resumed run took from `alternatives.jsonl`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ResumeReport {
    /// Records reused.
    pub reused: usize,
    /// Lines not reused, and why (the first [`DROPPED_SHOWN`]).
    pub dropped: Vec<Dropped>,
    /// Lines not reused in all.
    pub dropped_total: usize,
}

/// How many dropped lines a [`ResumeReport`] keeps to show.
pub const DROPPED_SHOWN: usize = 100;

impl ResumeReport {
    fn drop_line(&mut self, d: Dropped) {
        self.dropped_total += 1;
        if self.dropped.len() < DROPPED_SHOWN {
            self.dropped.push(d);
        }
    }
}

impl ResumeReport {
    /// One line for the user.
    pub fn text(&self, file: &Path) -> String {
        let mut s = format!(
            "resume: reused {} record(s) from {}",
            self.reused,
            file.display()
        );
        if self.dropped_total == 0 {
            s.push_str("; dropped none");
        } else {
            let shown: Vec<String> = self
                .dropped
                .iter()
                .take(5)
                .map(|d| format!("line {}: {}", d.line, d.why))
                .collect();
            s.push_str(&format!(
                "; dropped {} (evaluated again): {}{}",
                self.dropped_total,
                shown.join("; "),
                if self.dropped_total > 5 {
                    format!("; and {} more", self.dropped_total - 5)
                } else {
                    String::new()
                }
            ));
        }
        s
    }
}

/// Keep the records of an earlier run of the same settings and open the file to append
/// new ones. `keep` says whether a record belongs to this search (and is not a repeat:
/// `Err(why)` otherwise). Every line that is not kept is reported: a torn last line (the
/// run was killed while writing it), a line that is not a record, a key this search does
/// not have, a repeated key. The kept lines are copied, as they were, into a new file
/// that replaces the old one, one line at a time: memory does not grow with the records.
/// Without `resume` the file starts empty.
pub fn keep_records(
    dir: &OutputDir,
    resume: bool,
    keep: &mut dyn FnMut(&AlternativeRecord) -> Result<(), String>,
) -> Result<(File, Option<ResumeReport>), OutputError> {
    let path = dir.path(RECORDS);
    let open_append = |path: &Path| {
        fs::OpenOptions::new()
            .append(true)
            .open(path)
            .map_err(io_err(path))
    };
    if !resume {
        dir.create(RECORDS)?;
        return Ok((open_append(&path)?, None));
    }
    let mut report = ResumeReport::default();
    let file = match File::open(&path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            dir.create(RECORDS)?;
            return Ok((open_append(&path)?, Some(report)));
        }
        r => r.map_err(io_err(&path))?,
    };
    let tmp_rel = format!("{RECORDS}.resume");
    let (tmp, out) = dir.create(&tmp_rel)?;
    let mut out = std::io::BufWriter::new(out);
    let mut reader = BufReader::new(file);
    let mut buf = Vec::new();
    let mut line = 0;
    loop {
        buf.clear();
        if reader.read_until(b'\n', &mut buf).map_err(io_err(&path))? == 0 {
            break;
        }
        line += 1;
        let why = if !buf.ends_with(b"\n") {
            // Only the last line can lack its newline: a kill tore it, whatever it holds.
            Some("torn (no newline at the end: the run was killed while writing it)".into())
        } else {
            match std::str::from_utf8(&buf) {
                Err(_) => Some("not UTF-8 text".to_string()),
                Ok(t) if t.trim().is_empty() => continue,
                Ok(t) => match serde_json::from_str::<AlternativeRecord>(t) {
                    Err(e) => Some(format!("not a record ({})", excerpt(&e.to_string()))),
                    Ok(r) => match keep(&r) {
                        Err(why) => Some(why),
                        Ok(()) => {
                            out.write_all(&buf).map_err(io_err(&tmp))?;
                            report.reused += 1;
                            None
                        }
                    },
                },
            }
        };
        if let Some(why) = why {
            report.drop_line(Dropped { line, why });
        }
    }
    out.flush().map_err(io_err(&tmp))?;
    drop(out);
    // The old file stays whole until the new one replaces it in one step.
    fs::rename(&tmp, &path).map_err(io_err(&path))?;
    Ok((open_append(&path)?, Some(report)))
}

/// Read the records of an earlier run of the same settings. `wanted` says which keys
/// this search has. Every line that is not reused is reported: a torn last line (the run
/// was killed while writing it), a line that is not a record, a key this search does not
/// have, a repeated key.
pub fn read_records(
    path: &Path,
    wanted: &dyn Fn(&str) -> bool,
) -> Result<(Vec<AlternativeRecord>, ResumeReport), OutputError> {
    match File::open(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            Ok((Vec::new(), ResumeReport::default()))
        }
        Err(e) => Err(io_err(path)(e)),
        Ok(file) => parse_records(BufReader::new(file), wanted).map_err(io_err(path)),
    }
}

/// [`read_records`] on any reader.
pub fn parse_records(
    mut reader: impl BufRead,
    wanted: &dyn Fn(&str) -> bool,
) -> std::io::Result<(Vec<AlternativeRecord>, ResumeReport)> {
    let mut report = ResumeReport::default();
    let mut buf = Vec::new();
    let mut seen: HashSet<String> = HashSet::new();
    let mut out = Vec::new();
    let mut line = 0;
    loop {
        buf.clear();
        if reader.read_until(b'\n', &mut buf)? == 0 {
            break;
        }
        line += 1;
        let why = if !buf.ends_with(b"\n") {
            // Only the last line can lack its newline: a kill tore it, whatever it holds.
            Some("torn (no newline at the end: the run was killed while writing it)".into())
        } else {
            match std::str::from_utf8(&buf) {
                Err(_) => Some("not UTF-8 text".to_string()),
                Ok(t) if t.trim().is_empty() => continue,
                Ok(t) => match serde_json::from_str::<AlternativeRecord>(t) {
                    Err(e) => Some(format!("not a record ({})", excerpt(&e.to_string()))),
                    Ok(r) if !wanted(&r.key) => Some(format!(
                        "alternative {} is not part of this search",
                        excerpt(&r.key)
                    )),
                    Ok(r) if !seen.insert(r.key.clone()) => {
                        Some(format!("alternative {} appears again", excerpt(&r.key)))
                    }
                    Ok(r) => {
                        out.push(r);
                        None
                    }
                },
            }
        };
        if let Some(why) = why {
            report.drop_line(Dropped { line, why });
        }
    }
    report.reused = out.len();
    Ok((out, report))
}
