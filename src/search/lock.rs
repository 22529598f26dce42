//! One run per output directory: an exclusive OS lock (`flock` on Unix) on `OUT/.foldsynth.lock`,
//! taken before anything else in the directory is read or written and held until the
//! run's [`OutputDir`](super::output::OutputDir) is dropped. The kernel releases it when
//! the process ends however it ends (SIGKILL included), so a killed run never leaves the
//! directory locked; the file itself stays (with the dead process's id) and is harmless.
//! The holder writes its process id into the file, for the message the next run prints.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;

/// The lock file's name inside the output directory (never listed in the manifest, so no
/// later run deletes it while another might hold it).
pub const LOCK: &str = ".foldsynth.lock";

/// The lock on an output directory, held while this value lives.
#[derive(Debug)]
pub struct DirLock {
    /// The open lock file: closing it releases the lock.
    _file: Option<File>,
    /// Whether this run created the lock file (it did not exist before).
    pub created: bool,
}

/// Why a directory could not be locked.
#[derive(Debug)]
pub enum LockError {
    /// Another process holds the lock: its id as it wrote it (`None` when it has not yet).
    Busy(Option<u32>),
    /// The lock file could not be opened.
    Io(std::io::Error),
}

/// Take the lock on `root` (an existing directory) without waiting. The filesystem may
/// not support locks (some network filesystems): then the run goes on unlocked and the
/// returned note says so.
pub fn lock_dir(root: &Path) -> Result<(DirLock, Option<String>), LockError> {
    let path = root.join(LOCK);
    let created = !path.exists();
    let mut file = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .map_err(LockError::Io)?;
    match try_lock(&file) {
        Ok(()) => {}
        Err(None) => return Err(LockError::Busy(holder(&mut file))),
        Err(Some(e)) => {
            let note = format!(
                "{}: cannot lock ({e}); nothing stops a second run from writing into this directory at the same time",
                path.display()
            );
            return Ok((
                DirLock {
                    _file: None,
                    created,
                },
                Some(note),
            ));
        }
    }
    // Ours now: the id for the message another run prints (a failure to write it only
    // makes that message vaguer).
    let _ = file
        .set_len(0)
        .and_then(|_| file.seek(SeekFrom::Start(0)))
        .and_then(|_| writeln!(file, "{}", std::process::id()));
    Ok((
        DirLock {
            _file: Some(file),
            created,
        },
        None,
    ))
}

/// The id the lock's holder wrote. A holder writes it just after it takes the lock, so a
/// run refused in that instant would read an empty file (or a dead earlier holder's id
/// before the new one truncates it): read again for a moment until the id is of a live
/// process, then report what is there.
fn holder(file: &mut File) -> Option<u32> {
    let read = |file: &mut File| -> Option<u32> {
        let mut text = String::new();
        file.seek(SeekFrom::Start(0)).ok()?;
        file.read_to_string(&mut text).ok()?;
        text.trim().parse().ok()
    };
    let alive =
        |pid: u32| !Path::new("/proc").exists() || Path::new(&format!("/proc/{pid}")).exists();
    let start = std::time::Instant::now();
    loop {
        let pid = read(file);
        if pid.is_some_and(alive) || start.elapsed() > std::time::Duration::from_secs(1) {
            return pid;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

/// The standard library's exclusive, non-blocking file lock (`flock(LOCK_EX | LOCK_NB)` on
/// Unix), released when the file is closed; `Busy` when another open file holds it.
fn try_lock(file: &File) -> Result<(), Option<std::io::Error>> {
    file.try_lock().map_err(|e| match e {
        std::fs::TryLockError::WouldBlock => None,
        std::fs::TryLockError::Error(e) => Some(e),
    })
}
