//! The manifest of a run directory (`DIR/manifest.txt`): every finished file with its size and BLAKE3 checksum, so
//! that `check`, `resume`, `analyze`, `export` and `render` name a damaged file instead of reading it.
//!
//! The driver rewrites it atomically ([`crate::io::safe_write`]) after each checkpoint, at completion and on failure
//! ([`Recorder::write`]), listing every regular file except locks, temporaries, itself and the trees other commands
//! write later (`analysis/`, `frames/`). Line format: `<64 hex> <bytes> <=|+|~> <path>` — `=` exactly these bytes,
//! `+` a prefix ([`GROWING`] files, recorded at a checkpoint), `~` the checkpoint about to replace the current one
//! (written before the rename, so a run killed between rename and manifest still verifies and resumes); header lines
//! `# rubblepile manifest 1: …`, `# state: …`, and a last line `# end <checksum of every byte above>`. Run
//! directories without a manifest are checked row by row ([`check_rows`]: cell counts, finite numbers, final newline).

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};

/// The manifest's file name in a run directory.
pub const MANIFEST_FILE: &str = "manifest.txt";

/// The first line of a manifest (its format and version).
const HEADER: &str =
    "# rubblepile manifest 1: the finished files of this run directory (BLAKE3 of the bytes, bytes, path)";

/// Files at the top of a run directory that grow while the run goes on: recorded at a checkpoint by the bytes they
/// held then (`+`).
pub const GROWING: [&str; 4] = ["timeseries.csv", "tracks.csv", "spinup.csv", "barrier_overruns.csv"];

/// Subdirectories written by other commands on their own (`analyze`, `render`), never part of the run's record.
pub const NOT_RECORDED: [&str; 2] = ["analysis", "frames"];

/// One file of a manifest.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Entry {
    /// Path relative to the run directory, `/` between folders.
    pub path: String,
    /// Size (bytes) recorded.
    pub bytes: u64,
    /// BLAKE3 of those bytes, 64 lowercase hex digits.
    pub hash: String,
    /// Whether the file may have grown since (`+`): only its first `bytes` bytes are checked.
    pub growing: bool,
    /// The file being put in place when the manifest was written (`~`: size and BLAKE3), which the file may be
    /// instead of the recorded one.
    pub pending: Option<(u64, String)>,
}

/// A run directory's manifest, as read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Manifest {
    /// What the run was when it was written (`completed`, `failed`, `checkpoint at t = … s`).
    pub state: String,
    /// The files, sorted by path.
    pub entries: Vec<Entry>,
}

impl Manifest {
    /// The entry of `rel` (a path relative to the run directory, `/` between folders), if recorded.
    pub fn entry(&self, rel: &str) -> Option<&Entry> {
        self.entries
            .binary_search_by(|e| e.path.as_str().cmp(rel))
            .ok()
            .map(|i| &self.entries[i])
    }
}

/// Reads `dir`'s manifest: `Ok(None)` when there is none (a run directory written before it), `Err` (one line
/// naming the manifest) when it is damaged or unreadable.
pub fn read(dir: &Path) -> Result<Option<Manifest>, String> {
    let path = dir.join(MANIFEST_FILE);
    let damaged = |why: &str| format!("{}: damaged manifest: {why}", path.display());
    let bytes = match crate::io::scene_file::read_text_bounded(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(damaged(&e.to_string())),
    };
    let body_len = bytes
        .trim_end_matches('\n')
        .rfind('\n')
        .map(|i| i + 1)
        .ok_or_else(|| damaged("no end line"))?;
    let (body, end) = bytes.split_at(body_len);
    let sum = end
        .strip_prefix("# end ")
        .map(str::trim_end)
        .ok_or_else(|| damaged("no `# end` line (cut short?)"))?;
    if sum != blake3::hash(body.as_bytes()).to_hex().as_str() {
        return Err(damaged("its own checksum does not match its lines"));
    }
    let mut lines = body.lines();
    if lines.next() != Some(HEADER) {
        return Err(damaged("unknown first line"));
    }
    let state = lines
        .next()
        .and_then(|l| l.strip_prefix("# state: "))
        .ok_or_else(|| damaged("no `# state:` line"))?
        .to_string();
    let mut entries = Vec::new();
    let mut pending = Vec::new();
    for line in lines {
        let mut parts = line.splitn(4, ' ');
        let (Some(hash), Some(size), Some(kind), Some(rel)) = (parts.next(), parts.next(), parts.next(), parts.next())
        else {
            return Err(damaged(&format!("malformed line {line:?}")));
        };
        let bytes = size
            .parse()
            .map_err(|_| damaged(&format!("malformed size in {line:?}")))?;
        if hash.len() != 64 || !hash.bytes().all(|b| b.is_ascii_hexdigit()) || !matches!(kind, "=" | "+" | "~") {
            return Err(damaged(&format!("malformed line {line:?}")));
        }
        if kind == "~" {
            pending.push((rel.to_string(), bytes, hash.to_string()));
            continue;
        }
        entries.push(Entry {
            path: rel.to_string(),
            bytes,
            hash: hash.to_string(),
            growing: kind == "+",
            pending: None,
        });
    }
    entries.sort_by(|a, b| a.path.cmp(&b.path));
    // A pending file without a recorded one (the first checkpoint) is, like any file written after the manifest,
    // not recorded.
    for (rel, bytes, hash) in pending {
        if let Ok(i) = entries.binary_search_by(|e| e.path.as_str().cmp(&rel)) {
            entries[i].pending = Some((bytes, hash));
        }
    }
    Ok(Some(Manifest { state, entries }))
}

/// BLAKE3 of the first `bytes` bytes of `path` (hex), or the I/O error.
fn hash_prefix(path: &Path, bytes: u64) -> std::io::Result<String> {
    let mut h = blake3::Hasher::new();
    feed(&mut h, std::fs::File::open(path)?.take(bytes))?;
    Ok(h.finalize().to_hex().to_string())
}

/// Feeds everything `r` reads to `h` (64 KiB at a time).
fn feed(h: &mut blake3::Hasher, mut r: impl Read) -> std::io::Result<()> {
    let mut buf = vec![0u8; 1 << 16];
    loop {
        match r.read(&mut buf) {
            Ok(0) => return Ok(()),
            Ok(n) => {
                h.update(&buf[..n]);
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
}

/// Checks the file of `entry` in `dir` against it, or against the file that was being put in place
/// ([`Entry::pending`]); the error (one line) names the file and what differs from the recorded one.
pub fn verify_entry(dir: &Path, entry: &Entry) -> Result<(), String> {
    let recorded = verify_recorded(dir, entry);
    match (&recorded, &entry.pending) {
        (Err(_), Some((bytes, hash))) => {
            let pending = Entry {
                path: entry.path.clone(),
                bytes: *bytes,
                hash: hash.clone(),
                growing: false,
                pending: None,
            };
            verify_recorded(dir, &pending).or(recorded)
        }
        _ => recorded,
    }
}

/// Checks the file of `entry` in `dir` against its recorded size and checksum.
fn verify_recorded(dir: &Path, entry: &Entry) -> Result<(), String> {
    let path = dir.join(&entry.path);
    let meta = std::fs::symlink_metadata(&path).map_err(|e| {
        format!(
            "{}: {} (the manifest records {} bytes)",
            path.display(),
            if e.kind() == std::io::ErrorKind::NotFound {
                "missing".to_string()
            } else {
                e.to_string()
            },
            entry.bytes
        )
    })?;
    if !meta.is_file() {
        return Err(format!(
            "{}: not a regular file (the manifest records one)",
            path.display()
        ));
    }
    let len = meta.len();
    if len < entry.bytes || (!entry.growing && len != entry.bytes) {
        return Err(format!(
            "{}: damaged: {len} bytes, the manifest records {}{}",
            path.display(),
            entry.bytes,
            if len < entry.bytes { " (cut short)" } else { "" }
        ));
    }
    let got = hash_prefix(&path, entry.bytes).map_err(|e| format!("{}: {e}", path.display()))?;
    if got != entry.hash {
        return Err(format!(
            "{}: damaged: the BLAKE3 checksum of its {}{} bytes differs from the manifest's",
            path.display(),
            if entry.growing { "first " } else { "" },
            entry.bytes
        ));
    }
    Ok(())
}

/// Checks every file of `dir`'s manifest, in path order; `Ok(None)` without a manifest, `Ok(Some(n))` with `n` files
/// verified, `Err` naming the first damaged file (or the damaged manifest).
pub fn verify_all(dir: &Path) -> Result<Option<usize>, String> {
    let Some(m) = read(dir)? else {
        return Ok(None);
    };
    for e in &m.entries {
        verify_entry(dir, e)?;
    }
    Ok(Some(m.entries.len()))
}

/// `path` (a file below `dir`) relative to `dir` with `/` between folders, if it is below it.
fn relative(dir: &Path, path: &Path) -> Option<String> {
    let rel = path.strip_prefix(dir).ok()?;
    let parts: Option<Vec<&str>> = rel.components().map(|c| c.as_os_str().to_str()).collect();
    Some(parts?.join("/"))
}

/// Checks one file a reader is about to use (`resume`, `analyze`, `export`, `render`): against `dir`'s manifest when
/// the manifest records it, and row by row ([`check_rows`]) when it is a CSV file (`finite`: every cell a finite
/// number, as in a snapshot). The error is one line naming the file.
pub fn verify_file(dir: &Path, path: &Path, finite: bool) -> Result<(), String> {
    if let Some(m) = read(dir)?
        && let Some(e) = relative(dir, path).and_then(|rel| m.entry(&rel).cloned())
    {
        verify_entry(dir, &e)?;
    }
    if path.extension().is_some_and(|e| e == "csv") {
        check_rows(path, finite)?;
    }
    Ok(())
}

/// Checks a CSV file row by row: a header, every row as many cells as the header, (`finite`) every cell a finite
/// number, and a newline at the end (every row rubblepile writes ends with one, so a file without it was cut
/// short mid-row). Returns the number of rows; the error is one line naming the file and the line.
pub fn check_rows(path: &Path, finite: bool) -> Result<usize, String> {
    let text = crate::io::scene_file::read_text_bounded(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if text.is_empty() {
        return Err(format!("{}: empty (no header)", path.display()));
    }
    if !text.ends_with('\n') {
        return Err(format!(
            "{}: damaged: its last line ends without a newline (cut short mid-row)",
            path.display()
        ));
    }
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default();
    let columns: Vec<&str> = header.split(',').map(str::trim).collect();
    let mut rows = 0;
    for (i, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != columns.len() {
            return Err(format!(
                "{} line {}: damaged: {} cells, the header has {}",
                path.display(),
                i + 2,
                cells.len(),
                columns.len()
            ));
        }
        if finite
            && let Some((k, cell)) = cells
                .iter()
                .enumerate()
                .find(|(_, c)| c.parse::<f64>().map_or(true, |x| !x.is_finite()))
        {
            return Err(format!(
                "{} line {}: column {}: {cell:?} is not a finite number",
                path.display(),
                i + 2,
                columns[k]
            ));
        }
        rows += 1;
    }
    Ok(rows)
}

/// Every file the manifest of `dir` records now: regular files below it, except lock files, temporary files, the
/// manifest and the trees of [`NOT_RECORDED`]; `(relative path, full path)` sorted.
fn recordable_files(dir: &Path) -> std::io::Result<Vec<(String, PathBuf)>> {
    fn walk(dir: &Path, prefix: &str, top: bool, out: &mut Vec<(String, PathBuf)>) -> std::io::Result<()> {
        for entry in std::fs::read_dir(dir)? {
            let entry = entry?;
            let name = entry.file_name();
            let Some(name_s) = name.to_str().filter(|n| !n.contains('\n')) else {
                continue;
            };
            if crate::io::run_lock::is_lock_file(&name)
                || crate::io::safe_write::is_tmp_file(&name)
                || (top && (name_s == MANIFEST_FILE || name_s == crate::io::checkpoint::CHECKPOINT_TMP_FILE))
                || (top && NOT_RECORDED.contains(&name_s))
            {
                continue;
            }
            // Never followed: a link is no file of the run.
            let kind = entry.file_type()?;
            let rel = format!("{prefix}{name_s}");
            if kind.is_dir() {
                walk(&entry.path(), &format!("{rel}/"), false, out)?;
            } else if kind.is_file() {
                out.push((rel, entry.path()));
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    walk(dir, "", true, &mut out)?;
    out.sort();
    Ok(out)
}

/// What [`Recorder`] knows of a file it hashed: its size and modification time then, and the hasher state after
/// its bytes (a growing file is hashed on from there).
struct Known {
    bytes: u64,
    modified: Option<std::time::SystemTime>,
    hasher: blake3::Hasher,
}

/// Writes the manifest of a run directory, hashing each file once: a file unchanged since the last manifest (same
/// size and modification time) is not read again, and a file that only grew is hashed from where it stopped.
#[derive(Default)]
pub struct Recorder {
    known: HashMap<String, Known>,
}

impl Recorder {
    /// A recorder that knows no file yet.
    pub fn new() -> Recorder {
        Recorder::default()
    }

    /// The checksum and size of `path` now (`rel` its manifest path), hashing only what is new since last time.
    fn hash(&mut self, rel: &str, path: &Path) -> std::io::Result<(String, u64)> {
        let meta = std::fs::symlink_metadata(path)?;
        let (len, modified) = (meta.len(), meta.modified().ok());
        let known = self.known.remove(rel);
        let (mut hasher, from) = match known {
            Some(k) if k.bytes == len && k.modified == modified && modified.is_some() => {
                let hex = k.hasher.finalize().to_hex().to_string();
                self.known.insert(rel.to_string(), k);
                return Ok((hex, len));
            }
            // Grown by appending (the time series): hash on from where it stopped.
            Some(k) if k.bytes <= len && GROWING.contains(&rel) => (k.hasher, k.bytes),
            _ => (blake3::Hasher::new(), 0),
        };
        let mut f = std::fs::File::open(path)?;
        std::io::Seek::seek(&mut f, std::io::SeekFrom::Start(from))?;
        feed(&mut hasher, f.take(len - from))?;
        let hex = hasher.finalize().to_hex().to_string();
        self.known.insert(
            rel.to_string(),
            Known {
                bytes: len,
                modified,
                hasher,
            },
        );
        Ok((hex, len))
    }

    /// Writes `dir/manifest.txt` for the files below `dir` now, the run being `state` (`completed`, `failed`,
    /// `checkpoint at t = … s`): atomically and durably. `finished`: the run wrote its last byte, so every file is
    /// recorded exactly (`=`); otherwise the files of [`GROWING`] are recorded as prefixes (`+`).
    pub fn write(&mut self, dir: &Path, state: &str, finished: bool) -> std::io::Result<()> {
        self.write_with_pending(dir, state, finished, None)
    }

    /// [`Recorder::write`], with a `~` line for the file `pending.0` (a relative path) that is about to be replaced
    /// by the bytes `pending.1`: written before the replacement, so that the directory verifies whichever of the
    /// two the file is when the run is killed.
    pub fn write_with_pending(
        &mut self,
        dir: &Path,
        state: &str,
        finished: bool,
        pending: Option<(&str, &[u8])>,
    ) -> std::io::Result<()> {
        let mut text = format!("{HEADER}\n# state: {state}\n");
        for (rel, path) in recordable_files(dir)? {
            let (hash, bytes) = self.hash(&rel, &path)?;
            let kind = if !finished && GROWING.contains(&rel.as_str()) {
                '+'
            } else {
                '='
            };
            text.push_str(&format!("{hash} {bytes} {kind} {rel}\n"));
        }
        if let Some((rel, bytes)) = pending {
            text.push_str(&format!("{} {} ~ {rel}\n", blake3::hash(bytes).to_hex(), bytes.len()));
        }
        let sum = blake3::hash(text.as_bytes()).to_hex();
        text.push_str(&format!("# end {sum}\n"));
        crate::io::safe_write::write_atomic_durable(&dir.join(MANIFEST_FILE), text)
    }
}

/// Adds the files `names` (relative paths) written into the finished run `dir` after its manifest (the built-in
/// scene's `impact.json`) to that manifest, keeping its state; nothing without a manifest.
pub fn add_files(dir: &Path, names: &[&str]) -> std::io::Result<()> {
    let Some(m) = read(dir).map_err(std::io::Error::other)? else {
        return Ok(());
    };
    let mut text = format!("{HEADER}\n# state: {}\n", m.state);
    let mut entries = m.entries;
    for name in names {
        let path = dir.join(name);
        let bytes = std::fs::metadata(&path)?.len();
        entries.retain(|e| e.path != *name);
        entries.push(Entry {
            path: name.to_string(),
            bytes,
            hash: hash_prefix(&path, bytes)?,
            growing: false,
            pending: None,
        });
    }
    entries.sort_by(|a, b| a.path.cmp(&b.path));
    for e in &entries {
        let kind = if e.growing { '+' } else { '=' };
        text.push_str(&format!("{} {} {kind} {}\n", e.hash, e.bytes, e.path));
    }
    let sum = blake3::hash(text.as_bytes()).to_hex();
    text.push_str(&format!("# end {sum}\n"));
    crate::io::safe_write::write_atomic_durable(&dir.join(MANIFEST_FILE), text)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("rubblepile-manifest-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(d.join("snapshots")).unwrap();
        d
    }

    #[test]
    fn a_flipped_byte_or_a_cut_is_named_and_growth_of_a_growing_file_is_not() {
        let d = temp("flip");
        std::fs::write(d.join("scene.toml"), "[scene]\n").unwrap();
        std::fs::write(d.join("snapshots/0.csv"), "t,x\n0,1\n").unwrap();
        std::fs::write(d.join("timeseries.csv"), "t\n0\n").unwrap();
        std::fs::create_dir_all(d.join("analysis")).unwrap();
        std::fs::write(d.join("analysis/a.json"), "{}").unwrap();
        let mut r = Recorder::new();
        r.write(&d, "checkpoint at t = 0 s", false).unwrap();
        assert_eq!(verify_all(&d), Ok(Some(3)), "analysis/ is not recorded");
        std::fs::write(d.join("timeseries.csv"), "t\n0\n1\n").unwrap();
        assert_eq!(
            verify_all(&d),
            Ok(Some(3)),
            "the time series may grow after a checkpoint"
        );
        r.write(&d, "completed", true).unwrap();
        let m = read(&d).unwrap().unwrap();
        assert_eq!(m.state, "completed");
        assert_eq!(m.entry("timeseries.csv").unwrap().bytes, 6);
        assert!(!m.entry("timeseries.csv").unwrap().growing);

        let snap = d.join("snapshots/0.csv");
        std::fs::write(&snap, "t,x\n0,2\n").unwrap();
        let e = verify_all(&d).unwrap_err();
        assert!(e.contains("snapshots/0.csv: damaged: the BLAKE3 checksum"), "{e}");
        std::fs::write(&snap, "t,x\n0,").unwrap();
        let e = verify_all(&d).unwrap_err();
        assert!(
            e.contains("snapshots/0.csv: damaged: 6 bytes, the manifest records 8 (cut short)"),
            "{e}"
        );
        std::fs::write(&snap, "t,x\n0,1\n").unwrap();
        assert_eq!(verify_all(&d), Ok(Some(3)));

        // The manifest itself: any byte changed is found by its end line.
        let mp = d.join(MANIFEST_FILE);
        let mut bytes = std::fs::read(&mp).unwrap();
        bytes[70] ^= 1;
        std::fs::write(&mp, &bytes).unwrap();
        assert!(verify_all(&d).unwrap_err().contains("damaged manifest"));
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A run killed between the checkpoint's rename and the manifest after it: the manifest written before the
    /// rename records the new checkpoint as pending, so both the old and the new checkpoint verify, and a flipped
    /// byte in either is still found.
    #[test]
    fn a_checkpoint_replaced_after_the_manifest_verifies_as_pending() {
        let d = temp("pending");
        let cp = d.join("checkpoint.json");
        std::fs::write(&cp, "{\"t\": 1}\n").unwrap();
        let mut r = Recorder::new();
        r.write(&d, "checkpoint at t = 1 s", false).unwrap();
        let new = b"{\"t\": 2}\n";
        r.write_with_pending(
            &d,
            "checkpoint at t = 2 s being written",
            false,
            Some(("checkpoint.json", new)),
        )
        .unwrap();
        assert_eq!(verify_all(&d), Ok(Some(1)), "the old checkpoint, before the rename");
        std::fs::write(&cp, new).unwrap();
        assert_eq!(
            verify_all(&d),
            Ok(Some(1)),
            "the new checkpoint, killed before the next manifest"
        );
        std::fs::write(&cp, "{\"t\": 3}\n").unwrap();
        let e = verify_all(&d).unwrap_err();
        assert!(e.contains("checkpoint.json: damaged: the BLAKE3 checksum"), "{e}");
        // the manifest after the rename knows only the new one
        std::fs::write(&cp, new).unwrap();
        r.write(&d, "checkpoint at t = 2 s", false).unwrap();
        assert_eq!(
            read(&d).unwrap().unwrap().entry("checkpoint.json").unwrap().pending,
            None
        );
        std::fs::write(&cp, "{\"t\": 1}\n").unwrap();
        assert!(verify_all(&d).is_err(), "the old checkpoint is no longer accepted");
        // a first checkpoint (nothing recorded yet) is not recorded while pending
        std::fs::remove_file(&cp).unwrap();
        r.write_with_pending(&d, "first", false, Some(("checkpoint.json", new)))
            .unwrap();
        assert_eq!(verify_all(&d), Ok(Some(0)));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn rows_are_checked_without_a_manifest() {
        let d = temp("rows");
        let p = d.join("snapshots/1.csv");
        std::fs::write(&p, "t,x\n0,1\n1,2\n").unwrap();
        assert_eq!(check_rows(&p, true), Ok(2));
        std::fs::write(&p, "t,x\n0,1\n1,2").unwrap();
        assert!(check_rows(&p, true).unwrap_err().contains("without a newline"));
        std::fs::write(&p, "t,x\n0,NaN\n").unwrap();
        let e = check_rows(&p, true).unwrap_err();
        assert!(e.contains("line 2: column x: \"NaN\" is not a finite number"), "{e}");
        assert_eq!(check_rows(&p, false), Ok(1));
        std::fs::write(&p, "t,x\n0\n").unwrap();
        assert!(check_rows(&p, false).unwrap_err().contains("1 cells, the header has 2"));
        assert_eq!(verify_all(&d), Ok(None));
        std::fs::remove_dir_all(&d).unwrap();
    }
}
