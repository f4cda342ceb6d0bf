//! One writer per directory: an exclusive advisory lock ([`std::fs::File::try_lock`]: `flock`, `LockFileEx`) that
//! every process writing a directory holds while it writes, on `DIR/.rubblepile.lock`, or `DIR/.rubblepile-<part>.lock`
//! for a part written separately (`frames`, `analysis`, a campaign shard's index). The holder writes its pid into it.
//!
//! - A second writer is refused within a quarter of a second (a child between fork and exec may briefly hold a
//!   released lock): [`LockError::Held`] names the directory and pid (one line, exit code 2).
//! - The lock lives with the [`DirLock`] guard; the OS releases it however the process ends.
//! - Lock files are never deleted (two processes could lock two files of one name); emptiness checks and `--force`
//!   ignore them ([`is_lock_file`]). Readers take no lock and are never blocked.
//! - Re-entrant on the holding thread (a command locks, the driver locks again); other threads are refused.
//!   [`DirLock::acquire_shared`]: shared holders exclude an exclusive one, not each other (campaign shards).
//! - Without advisory locks on the file system, the directory is written unlocked after a warning.

use std::fs::{File, TryLockError};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::thread::ThreadId;

/// The lock file of a directory as a whole (`DIR/.rubblepile.lock`).
pub const LOCK_FILE: &str = ".rubblepile.lock";

/// Whether a directory entry named `name` is one of rubblepile's lock files ([`LOCK_FILE`] or a part's), which are
/// no output and never make a directory "not empty".
pub fn is_lock_file(name: &std::ffi::OsStr) -> bool {
    name.to_str()
        .is_some_and(|n| n == LOCK_FILE || (n.starts_with(".rubblepile-") && n.ends_with(".lock")))
}

/// Why a directory could not be locked. Messages are one line.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another process (or another thread of this one) writes the directory.
    #[error(
        "{} is being written by another rubblepile process ({}); wait for it to end{}",
        .dir.display(),
        .pid.map_or("pid unknown".to_string(), |p| format!("pid {p}")),
        .advice.map_or(String::new(), |a| format!(" or {a}"))
    )]
    Held {
        /// The directory (or part of one) being written.
        dir: PathBuf,
        /// The holder's process id, as it wrote it into the lock file (`None`: not written, e.g. shared holders).
        pid: Option<u32>,
        /// What else the refused writer can do, e.g. `use another --out`.
        advice: Option<&'static str>,
    },
    /// The lock file could not be opened or locked.
    #[error("{}", if crate::io::safe_write::is_symlink_refusal(.source) {
        .source.to_string()
    } else {
        format!("{}: cannot lock: {}", .path.display(), .source)
    })]
    Io {
        /// The lock file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

impl LockError {
    /// The same error, telling a refused writer it may also do `advice` (e.g. `use another --out`).
    pub fn or(self, advice: &'static str) -> Self {
        match self {
            LockError::Held { dir, pid, .. } => LockError::Held {
                dir,
                pid,
                advice: Some(advice),
            },
            other => other,
        }
    }
}

/// A lock this process holds: the open lock file (closing it releases the OS lock) and who holds it here.
struct Held {
    path: PathBuf,
    /// The thread holding it exclusively; `None` for a shared lock.
    owner: Option<ThreadId>,
    depth: usize,
    /// `None` where the file system has no advisory locks.
    _file: Option<File>,
}

/// The locks held by this process. The OS lock alone cannot make the lock re-entrant (two opens of one file in one
/// process exclude each other), so this registry does.
static HELD: Mutex<Vec<Held>> = Mutex::new(Vec::new());

fn held() -> std::sync::MutexGuard<'static, Vec<Held>> {
    HELD.lock().unwrap_or_else(|e| e.into_inner())
}

/// An advisory lock on a directory (or a part of one), held until the guard is dropped (see the module docs).
#[derive(Debug)]
#[must_use = "the lock is released when the guard is dropped"]
pub struct DirLock {
    path: PathBuf,
}

impl DirLock {
    /// Locks the existing directory `dir` exclusively (`dir/.rubblepile.lock`).
    ///
    /// Errors: [`LockError::Held`] within a quarter of a second when another process, or another thread of this one, holds the lock;
    /// [`LockError::Io`] when the lock file cannot be created or locked (e.g. `dir` does not exist).
    pub fn acquire(dir: &Path) -> Result<DirLock, LockError> {
        lock(dir, LOCK_FILE, dir.to_path_buf(), false)
    }

    /// Locks `dir/<part>` (a subdirectory or file written apart from the rest, e.g. `frames` or a shard's index)
    /// exclusively, through `dir/.rubblepile-<part>.lock`; `dir` must exist, `dir/<part>` need not. Errors as
    /// [`DirLock::acquire`], naming `dir/<part>`.
    pub fn acquire_part(dir: &Path, part: &str) -> Result<DirLock, LockError> {
        lock(dir, &format!(".rubblepile-{part}.lock"), dir.join(part), false)
    }

    /// Locks the existing directory `dir` shared: other shared holders are let in, exclusive ones are refused (and
    /// refuse it). Shared holders write no pid (an exclusive writer refused by them is told `pid unknown`). Errors as
    /// [`DirLock::acquire`].
    pub fn acquire_shared(dir: &Path) -> Result<DirLock, LockError> {
        lock(dir, LOCK_FILE, dir.to_path_buf(), true)
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        let mut held = held();
        if let Some(i) = held.iter().position(|h| h.path == self.path) {
            held[i].depth -= 1;
            if held[i].depth == 0 {
                // Dropping the file closes it, which releases the OS lock.
                held.swap_remove(i);
            }
        }
    }
}

/// How long a lock held by another process is retried before it is refused: longer than a fork-to-exec window.
const LOCK_RETRY: std::time::Duration = std::time::Duration::from_millis(250);

/// The pid written in the lock file `path` (its first line), if any.
fn holder_pid(path: &Path) -> Option<u32> {
    let mut text = String::new();
    File::open(path).ok()?.read_to_string(&mut text).ok()?;
    text.lines().next()?.trim().parse().ok()
}

fn lock(dir: &Path, name: &str, what: PathBuf, shared: bool) -> Result<DirLock, LockError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| LockError::Io { path, source }
    };
    let named = dir.join(name);
    // One key per lock file, however the directory was spelled.
    let path = std::fs::canonicalize(dir).map_err(io(&named))?.join(name);
    let refused = |pid| LockError::Held {
        dir: what.clone(),
        pid,
        advice: None,
    };
    let me = std::thread::current().id();
    let mut held = held();
    if let Some(h) = held.iter_mut().find(|h| h.path == path) {
        let reentrant = h.owner == Some(me) || (shared && h.owner.is_none());
        if !reentrant {
            return Err(refused(h.owner.map(|_| std::process::id())));
        }
        h.depth += 1;
        return Ok(DirLock { path });
    }
    // Never through a link: a lock file that is one would have the pid written into whatever it points at.
    let mut file = crate::io::safe_write::open_nofollow(&path, true).map_err(io(&named))?;
    // A lock just released can still be held for a moment by a child process of this one (or of the last holder)
    // started by another thread between its fork and its exec: the child's copy of the descriptor shares the lock
    // until exec closes it. So a refusal is retried for up to LOCK_RETRY before it is believed.
    let started = std::time::Instant::now();
    let attempt = loop {
        let attempt = if shared {
            file.try_lock_shared()
        } else {
            file.try_lock()
        };
        match attempt {
            Err(TryLockError::WouldBlock) if started.elapsed() < LOCK_RETRY => {
                std::thread::sleep(std::time::Duration::from_millis(10))
            }
            _ => break attempt,
        }
    };
    let file = match attempt {
        Ok(()) => {
            // The pid first, the old tail cut after: a reader never sees an empty file between the two. Shared
            // holders are several: they leave the file empty, so that no stale pid is named.
            let pid = if shared {
                String::new()
            } else {
                format!("{}\n", std::process::id())
            };
            file.seek(SeekFrom::Start(0))
                .and_then(|_| file.write_all(pid.as_bytes()))
                .and_then(|_| file.set_len(pid.len() as u64))
                .and_then(|_| file.flush())
                .map_err(io(&named))?;
            Some(file)
        }
        // An exclusive holder has written its pid; shared holders have left the file empty.
        Err(TryLockError::WouldBlock) => return Err(refused(holder_pid(&path))),
        Err(TryLockError::Error(e)) if e.kind() == std::io::ErrorKind::Unsupported => {
            super::messages::emit(
                super::messages::Channel::Warning,
                &format!(
                    "warning: {}: this file system has no advisory file locks; nothing keeps a second rubblepile \
                     process from writing {} at the same time",
                    named.display(),
                    what.display()
                ),
            );
            None
        }
        Err(TryLockError::Error(e)) => return Err(io(&named)(e)),
    };
    held.push(Held {
        path: path.clone(),
        owner: (!shared).then_some(me),
        depth: 1,
        _file: file,
    });
    Ok(DirLock { path })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("rubblepile-lock-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn reentrant_on_its_thread_refused_on_another() {
        let d = temp("reentrant");
        let a = DirLock::acquire(&d).unwrap();
        let b = DirLock::acquire(&d).unwrap();
        assert_eq!(holder_pid(a.path()), Some(std::process::id()));
        let other = std::thread::scope(|s| s.spawn(|| DirLock::acquire(&d).map(|_| ())).join().unwrap());
        let e = other.unwrap_err().to_string();
        assert!(e.contains("is being written by another rubblepile process"), "{e}");
        assert!(e.contains(&format!("pid {}", std::process::id())), "{e}");
        drop(a);
        // still held through `b`
        assert!(std::thread::scope(|s| s
            .spawn(|| DirLock::acquire(&d).is_err())
            .join()
            .unwrap()));
        drop(b);
        assert!(std::thread::scope(|s| s
            .spawn(|| DirLock::acquire(&d).is_ok())
            .join()
            .unwrap()));
        let _ = std::fs::remove_dir_all(&d);
    }

    /// A lock held for a moment by a descriptor outside the registry (as a child between fork and exec holds it) is
    /// granted once released within [`LOCK_RETRY`]; one held longer is refused.
    #[test]
    fn a_lock_released_within_the_retry_is_granted_one_held_longer_is_refused() {
        let d = temp("retry");
        let hold_for = |ms: u64| {
            let f = File::create(d.join(LOCK_FILE)).unwrap();
            f.try_lock().unwrap();
            std::thread::spawn(move || {
                std::thread::sleep(std::time::Duration::from_millis(ms));
                drop(f);
            })
        };
        let brief = hold_for(50);
        assert!(DirLock::acquire(&d).is_ok(), "released after 50 ms");
        brief.join().unwrap();
        let long = hold_for(2000);
        let t0 = std::time::Instant::now();
        assert!(DirLock::acquire(&d).is_err(), "held for 2 s");
        assert!(t0.elapsed() < std::time::Duration::from_millis(1500));
        long.join().unwrap();
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn parts_are_locked_apart_and_shared_holders_share() {
        let d = temp("parts");
        let whole = DirLock::acquire(&d).unwrap();
        let frames = std::thread::scope(|s| s.spawn(|| DirLock::acquire_part(&d, "frames").is_ok()).join().unwrap());
        assert!(frames, "a part is locked apart from the whole");
        drop(whole);
        let s1 = DirLock::acquire_shared(&d).unwrap();
        let (s2, ex) = std::thread::scope(|s| {
            s.spawn(|| (DirLock::acquire_shared(&d).is_ok(), DirLock::acquire(&d).map(|_| ())))
                .join()
                .unwrap()
        });
        assert!(s2);
        assert!(ex.unwrap_err().to_string().contains("pid unknown"));
        drop(s1);
        assert!(is_lock_file(LOCK_FILE.as_ref()));
        assert!(is_lock_file(".rubblepile-frames.lock".as_ref()));
        assert!(!is_lock_file("summary.json".as_ref()));
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn the_advice_is_added_to_the_one_line() {
        let e = LockError::Held {
            dir: "runs/x".into(),
            pid: Some(1234),
            advice: None,
        }
        .or("use another --out");
        assert_eq!(
            e.to_string(),
            "runs/x is being written by another rubblepile process (pid 1234); wait for it to end or use another --out"
        );
    }
}
