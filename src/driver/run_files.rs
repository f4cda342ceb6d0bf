//! A run's time series and snapshots on their way to disk.
//!
//! Rows of `timeseries.csv` are buffered and handed to the operating system at most once per [`FLUSH_EVERY`] of
//! wall time, and always before a checkpoint, on a failure and at the end of the run: a short run of small samples
//! (the outer Solar System to t = 1000 with a row every 10 time units) otherwise spent as long in `write` calls as in
//! its physics. Files are made durable (fsync) only where something relies on it: just before a checkpoint is
//! written, the rows and snapshots it counts (resume cuts the time series back to the checkpoint's length, so it
//! must be on disk first), and once at the end of the run, after its wall time is taken, before `summary.json`
//! says it completed.
//!
//! Rows written after the last flush of a killed process are lost, as are those after its last checkpoint
//! whatever the flushing: `resume` continues from the checkpoint and writes them again.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Longest wall time a written row waits in memory before it is handed to the OS (so `tail -f` and `analyze` of a
/// running run see it).
pub const FLUSH_EVERY: Duration = Duration::from_secs(1);

/// The open time series of a run and the snapshots not yet made durable.
pub struct RunFiles {
    timeseries: BufWriter<File>,
    path: PathBuf,
    last_flush: Instant,
    unsynced: Vec<PathBuf>,
}

/// An I/O failure and the file it happened on.
pub type FileError = (PathBuf, std::io::Error);

impl RunFiles {
    /// Wraps the open `timeseries.csv` at `path` (positioned where rows are appended).
    pub fn new(timeseries: File, path: &Path) -> RunFiles {
        RunFiles {
            timeseries: BufWriter::with_capacity(1 << 16, timeseries),
            path: path.to_path_buf(),
            last_flush: Instant::now(),
            unsynced: Vec::new(),
        }
    }

    /// Appends one row (with its newline); hands the buffer to the OS when [`FLUSH_EVERY`] has passed.
    pub fn write_row(&mut self, row: &str) -> Result<(), FileError> {
        self.timeseries
            .write_all(row.as_bytes())
            .map_err(|e| (self.path.clone(), e))?;
        if self.last_flush.elapsed() >= FLUSH_EVERY {
            self.flush()?;
        }
        Ok(())
    }

    /// Notes a snapshot file written since the last [`RunFiles::sync`], to make it durable then.
    pub fn snapshot_written(&mut self, path: PathBuf) {
        self.unsynced.push(path);
    }

    /// Hands the buffered rows to the OS.
    pub fn flush(&mut self) -> Result<(), FileError> {
        self.timeseries.flush().map_err(|e| (self.path.clone(), e))?;
        self.last_flush = Instant::now();
        Ok(())
    }

    /// Flushes, then makes the time series and the snapshots written since the last sync durable (fsync).
    pub fn sync(&mut self) -> Result<(), FileError> {
        self.flush()?;
        self.timeseries
            .get_ref()
            .sync_all()
            .map_err(|e| (self.path.clone(), e))?;
        for p in self.unsynced.drain(..) {
            File::open(&p).and_then(|f| f.sync_all()).map_err(|e| (p.clone(), e))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows reach the file at a flush, a sync or when the writer is dropped, and not row by row; a sync makes the
    /// snapshots noted since the last one durable and forgets them.
    #[test]
    fn rows_wait_for_a_flush_and_syncs_cover_the_noted_snapshots() {
        let dir = std::env::temp_dir().join(format!("rubblepile_run_files_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let ts = dir.join("timeseries.csv");
        let snap = dir.join("0.csv");
        std::fs::write(&snap, "t\n0\n").unwrap();
        let mut files = RunFiles::new(File::create(&ts).unwrap(), &ts);
        files.write_row("t\n").unwrap();
        files.write_row("0\n").unwrap();
        assert_eq!(std::fs::read_to_string(&ts).unwrap(), "", "buffered, not yet written");
        files.flush().unwrap();
        assert_eq!(std::fs::read_to_string(&ts).unwrap(), "t\n0\n");
        files.snapshot_written(snap.clone());
        files.write_row("1\n").unwrap();
        files.sync().unwrap();
        assert!(files.unsynced.is_empty());
        assert_eq!(std::fs::read_to_string(&ts).unwrap(), "t\n0\n1\n");
        files.snapshot_written(dir.join("missing.csv"));
        let (path, _) = files.sync().unwrap_err();
        assert!(
            path.ends_with("missing.csv"),
            "the failing file is named: {}",
            path.display()
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
