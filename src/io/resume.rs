//! The engine-independent first and last steps of `rubblepile resume` for the soft- and hard-sphere engines:
//! refuse a completed run, read and check the engine's `checkpoint.json`, check the run's scene copy against the
//! hash the checkpoint recorded, then clear the interrupted process's stale files and cut `timeseries.csv` back to
//! the checkpoint.

use std::fs::File;
use std::io::{Seek, SeekFrom};
use std::path::Path;

use serde::de::DeserializeOwned;

use crate::io::checkpoint::{CHECKPOINT_FILE, CHECKPOINT_TMP_FILE, fnv1a_hex};
use crate::run::RunError;

/// What every engine's checkpoint records about itself and the scene it was written for.
pub trait EngineCheckpoint: DeserializeOwned {
    /// The checkpoint's `format` field.
    fn format(&self) -> &str;
    /// FNV-1a hash (hex) of the scene text the run started from.
    fn scene_hash(&self) -> &str;
}

/// Reads `dir/checkpoint.json` as an `engine` checkpoint of format `format`, and the run's `scene.toml` text,
/// after refusing a run whose `summary.json` says it completed.
///
/// Errors: [`RunError::AlreadyCompleted`], [`RunError::NoCheckpoint`], or [`RunError::BadCheckpoint`] naming the
/// file and what is wrong (unreadable, another engine's format, scene changed since the checkpoint).
pub fn open_checkpoint<C: EngineCheckpoint>(dir: &Path, format: &str, engine: &str) -> Result<(C, String), RunError> {
    let bad = RunError::BadCheckpoint;
    if let Ok(text) = std::fs::read_to_string(dir.join("summary.json"))
        && let Ok(v) = serde_json::from_str::<serde_json::Value>(&text)
        && v["status"] == "completed"
    {
        let t = v["final_time"].as_f64().or(v["t_reached"].as_f64()).unwrap_or(f64::NAN);
        return Err(RunError::AlreadyCompleted {
            dir: dir.to_path_buf(),
            t,
        });
    }
    let cpath = dir.join(CHECKPOINT_FILE);
    if !cpath.is_file() {
        return Err(RunError::NoCheckpoint { dir: dir.to_path_buf() });
    }
    let ctext = std::fs::read_to_string(&cpath).map_err(|e| bad(format!("{}: {e}", cpath.display())))?;
    let ck: C =
        serde_json::from_str(&ctext).map_err(|e| bad(format!("{}: {}", cpath.display(), e.to_string().trim())))?;
    if ck.format() != format {
        return Err(bad(format!(
            "{}: not a {engine} checkpoint ({:?})",
            cpath.display(),
            ck.format()
        )));
    }
    let spath = dir.join("scene.toml");
    let text = std::fs::read_to_string(&spath).map_err(|e| bad(format!("{}: {e}", spath.display())))?;
    if fnv1a_hex(text.as_bytes()) != ck.scene_hash() {
        return Err(bad(format!(
            "{} changed since the checkpoint was written",
            spath.display()
        )));
    }
    Ok((ck, text))
}

/// Removes the interrupted process's `summary.json`, `last_good_state.csv` and half-written checkpoint, and
/// returns `dir/timeseries.csv` cut back to `bytes` (its length at the checkpoint) and positioned at its end.
pub fn reopen_timeseries(dir: &Path, bytes: u64) -> Result<File, RunError> {
    let io = |p: &Path, e: std::io::Error| RunError::Io {
        path: p.to_path_buf(),
        source: e,
    };
    for name in ["summary.json", "last_good_state.csv", CHECKPOINT_TMP_FILE] {
        let p = dir.join(name);
        if p.is_file() {
            std::fs::remove_file(&p).map_err(|e| io(&p, e))?;
        }
    }
    reopen_truncated(&dir.join("timeseries.csv"), bytes)
}

/// Opens the output file `path` for appending after cutting it back to `bytes`, its length at the checkpoint.
///
/// Errors: [`RunError::BadCheckpoint`] when the file is missing or shorter than `bytes`; [`RunError::Io`].
pub fn reopen_truncated(path: &Path, bytes: u64) -> Result<File, RunError> {
    let io = |e: std::io::Error| RunError::Io {
        path: path.to_path_buf(),
        source: e,
    };
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .open(path)
        .map_err(|e| RunError::BadCheckpoint(format!("{}: {e}", path.display())))?;
    if file.metadata().map_err(io)?.len() < bytes {
        return Err(RunError::BadCheckpoint(format!(
            "{} is shorter than at the checkpoint",
            path.display()
        )));
    }
    file.set_len(bytes).map_err(io)?;
    file.seek(SeekFrom::End(0)).map_err(io)?;
    Ok(file)
}
