//! The one way rubblepile writes a file into a directory it owns (run directory, `analysis/`, `frames/`, `vtk/`,
//! campaign directory): never through a symbolic link, and whole or not at all. [`write_atomic`] and [`AtomicFile`]
//! write a fresh temporary (`O_CREAT | O_EXCL`) in the same directory and rename it into place (readers see the old
//! or new file, never half). [`create_fresh`] creates growing files (`timeseries.csv`, `tracks.csv`, `spinup.csv`)
//! with `O_EXCL`; [`open_nofollow`] reopens one (or a lock file) and checks it is the regular file at that path.
//! [`ensure_dir`] refuses a linked subdirectory. A link is refused with [`SymlinkRefused`] naming the path; checks use
//! `symlink_metadata` (`O_NOFOLLOW` would need `libc`), and where check and open could race the open cannot follow a
//! link or is re-checked (device and inode on Unix).

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The prefix of the temporary files of [`AtomicFile`] (`.rubblepile-tmp-<pid>-<n>-<name>`): run-directory walks
/// (the manifest, `check`) pass over them.
pub const TMP_PREFIX: &str = ".rubblepile-tmp-";

/// Whether a directory entry named `name` is one of [`AtomicFile`]'s temporary files (left by a process killed
/// mid-write).
pub fn is_tmp_file(name: &std::ffi::OsStr) -> bool {
    name.to_str().is_some_and(|n| n.starts_with(TMP_PREFIX))
}

/// A symbolic link found where rubblepile was to write a regular file or directory. One line, naming the path.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "{} is a symbolic link; rubblepile never writes through a link (remove it, or write somewhere else)",
    .path.display()
)]
pub struct SymlinkRefused {
    /// The link.
    pub path: PathBuf,
}

/// `path` as an I/O error of kind `InvalidInput` carrying [`SymlinkRefused`] (see [`is_symlink_refusal`]).
fn refused(path: &Path) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        SymlinkRefused {
            path: path.to_path_buf(),
        },
    )
}

/// Whether `e` is the refusal of a symbolic link by this module (its message already names the path).
pub fn is_symlink_refusal(e: &std::io::Error) -> bool {
    e.get_ref().is_some_and(|inner| inner.is::<SymlinkRefused>())
}

/// `path: e` for an I/O error on `path`, or `e` alone when it is a [`SymlinkRefused`] (which names the path
/// itself): the one line of an error type's `Io { path, source }` variant.
pub fn describe(path: &Path, e: &std::io::Error) -> String {
    if is_symlink_refusal(e) {
        e.to_string()
    } else {
        format!("{}: {e}", path.display())
    }
}

/// What went wrong with an I/O operation on a path, for a message that names the path before it (`{path}:
/// {reason}`): the OS error, or for a [`SymlinkRefused`] the refusal without its path.
pub fn reason(e: &std::io::Error) -> String {
    if is_symlink_refusal(e) {
        "is a symbolic link; rubblepile never writes through a link (remove it, or write somewhere else)".to_string()
    } else {
        e.to_string()
    }
}

/// Refuses `path` when it is a symbolic link (dangling or not); anything else, or nothing there, is `Ok`.
pub fn refuse_symlink(path: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => Err(refused(path)),
        _ => Ok(()),
    }
}

/// Creates the directory `path` (and its parents) unless it exists; refuses it when it is a symbolic link.
pub fn ensure_dir(path: &Path) -> std::io::Result<()> {
    refuse_symlink(path)?;
    std::fs::create_dir_all(path)
}

/// Creates `path` for writing with `O_CREAT | O_EXCL` (fails when anything, a link included, is there already).
pub fn create_new_nofollow(path: &Path) -> std::io::Result<File> {
    OpenOptions::new().write(true).create_new(true).open(path).map_err(|e| {
        if e.kind() == std::io::ErrorKind::AlreadyExists && refuse_symlink(path).is_err() {
            refused(path)
        } else {
            e
        }
    })
}

/// Creates `path` anew for writing: refuses a link there, removes a regular file of that name, then
/// [`create_new_nofollow`]. For files that grow during a run (appended to, so not written by rename).
pub fn create_fresh(path: &Path) -> std::io::Result<File> {
    refuse_symlink(path)?;
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(e),
        _ => {}
    }
    create_new_nofollow(path)
}

/// Opens the regular file `path` for reading and writing, without truncating it, creating it when `create` and it
/// is missing; refuses a link at `path`, and checks (device and inode, on Unix) that the file opened is the one at
/// `path`, so that a link put there between the check and the open is caught before anything is written.
pub fn open_nofollow(path: &Path, create: bool) -> std::io::Result<File> {
    if create {
        match OpenOptions::new().read(true).write(true).create_new(true).open(path) {
            Ok(f) => return Ok(f),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
            Err(e) => return Err(e),
        }
    }
    let before = std::fs::symlink_metadata(path)?;
    if before.file_type().is_symlink() {
        return Err(refused(path));
    }
    let file = OpenOptions::new().read(true).write(true).open(path)?;
    if !same_file(&before, &file.metadata()?) {
        return Err(refused(path));
    }
    Ok(file)
}

#[cfg(unix)]
fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino()
}

#[cfg(not(unix))]
fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    a.len() == b.len() && a.is_file() == b.is_file()
}

/// A file being written atomically: bytes go to a temporary file beside `path` ([`TMP_PREFIX`]), and
/// [`AtomicFile::finish`] renames it to `path`. Dropped unfinished (an error on the way), the temporary file is
/// removed and `path` is as it was.
pub struct AtomicFile {
    w: Option<BufWriter<File>>,
    tmp: PathBuf,
    path: PathBuf,
}

/// Temporary files this process has made, so that two writers of one name in one process never share one.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Creates a fresh, empty temporary file beside `path` (`O_EXCL`; its name ends with `path`'s file name, so its
/// extension is the same) for a writer that only takes a path (a plotting backend); [`rename_into`] puts it in
/// place. Refuses a link at `path`.
pub fn temp_beside(path: &Path) -> std::io::Result<(PathBuf, File)> {
    refuse_symlink(path)?;
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file name"))?;
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp_name = format!("{TMP_PREFIX}{}-{n}-{}", std::process::id(), name.to_string_lossy());
    let tmp = path.with_file_name(tmp_name);
    let file = create_new_nofollow(&tmp)?;
    Ok((tmp, file))
}

/// Renames the temporary file `tmp` of [`temp_beside`] to `path` (removing `tmp` when that fails); refuses a link
/// at `path`.
pub fn rename_into(tmp: &Path, path: &Path) -> std::io::Result<()> {
    let done = refuse_symlink(path).and_then(|()| std::fs::rename(tmp, path));
    if done.is_err() {
        let _ = std::fs::remove_file(tmp);
    }
    done
}

impl AtomicFile {
    /// Starts writing `path`: refuses a link there, creates the temporary file (`O_EXCL`).
    pub fn create(path: &Path) -> std::io::Result<AtomicFile> {
        let (tmp, file) = temp_beside(path)?;
        Ok(AtomicFile {
            w: Some(BufWriter::with_capacity(1 << 16, file)),
            tmp,
            path: path.to_path_buf(),
        })
    }

    /// The file this will become.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn writer(&mut self) -> std::io::Result<&mut BufWriter<File>> {
        self.w
            .as_mut()
            .ok_or_else(|| std::io::Error::other("the atomic file is finished"))
    }

    /// Puts the written bytes in place at the path (rename; a link put there meanwhile is replaced, not followed).
    pub fn finish(self) -> std::io::Result<()> {
        self.complete(false)
    }

    /// Renames into place; `durable`: the file is synced before the rename and the directory after it.
    fn complete(mut self, durable: bool) -> std::io::Result<()> {
        let w = self.w.take().ok_or_else(|| std::io::Error::other("finished twice"))?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        if durable {
            file.sync_all()?;
        }
        drop(file);
        std::fs::rename(&self.tmp, &self.path)?;
        if durable {
            // Makes the rename durable; not every platform can open a directory, so failures are ignored.
            if let Some(dir) = self.path.parent()
                && let Ok(d) = File::open(if dir.as_os_str().is_empty() {
                    Path::new(".")
                } else {
                    dir
                })
            {
                let _ = d.sync_all();
            }
        }
        Ok(())
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writer()?.write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        self.writer()?.write_all(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.writer()?.flush()
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.w.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Writes `bytes` to `path` atomically ([`AtomicFile`]); refuses a link at `path`.
pub fn write_atomic(path: &Path, bytes: impl AsRef<[u8]>) -> std::io::Result<()> {
    write_whole(path, bytes.as_ref(), false)
}

/// [`write_atomic`], made durable (the file synced before the rename, the directory after it): for the files a
/// resumed run relies on (the checkpoint, the manifest).
pub fn write_atomic_durable(path: &Path, bytes: impl AsRef<[u8]>) -> std::io::Result<()> {
    write_whole(path, bytes.as_ref(), true)
}

fn write_whole(path: &Path, bytes: &[u8], durable: bool) -> std::io::Result<()> {
    let mut f = AtomicFile::create(path)?;
    f.write_all(bytes)?;
    f.complete(durable)
}

/// Copies the file `from` to `to` atomically (read whole, then [`write_atomic`]); refuses a link at `to`.
pub fn copy_atomic(from: &Path, to: &Path) -> std::io::Result<()> {
    write_atomic(to, std::fs::read(from)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("rubblepile-safe-write-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[cfg(unix)]
    #[test]
    fn a_link_is_refused_by_name_and_its_target_is_untouched() {
        let d = temp("link");
        let target = d.join("target.txt");
        std::fs::write(&target, "precious").unwrap();
        let link = d.join("summary.json");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        for e in [
            write_atomic(&link, "x").unwrap_err(),
            create_fresh(&link).unwrap_err(),
            open_nofollow(&link, true).unwrap_err(),
            AtomicFile::create(&link).err().unwrap(),
        ] {
            assert!(is_symlink_refusal(&e), "{e}");
            assert!(e.to_string().contains(&link.display().to_string()), "{e}");
            assert_eq!(e.to_string().lines().count(), 1);
        }
        let dangling = d.join("dangling.lock");
        std::os::unix::fs::symlink(d.join("nowhere"), &dangling).unwrap();
        assert!(is_symlink_refusal(&open_nofollow(&dangling, true).unwrap_err()));
        assert!(!d.join("nowhere").exists(), "a dangling link's target is not created");
        let dir_link = d.join("snapshots");
        std::os::unix::fs::symlink(&d, &dir_link).unwrap();
        assert!(is_symlink_refusal(&ensure_dir(&dir_link).unwrap_err()));
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "precious");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn atomic_writes_replace_whole_files_and_leave_no_temporary_behind() {
        let d = temp("atomic");
        let p = d.join("a.csv");
        write_atomic(&p, "one\n").unwrap();
        write_atomic(&p, "two\n").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "two\n");
        {
            let mut f = AtomicFile::create(&p).unwrap();
            f.write_all(b"half").unwrap();
            // dropped unfinished: the old file stays
        }
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "two\n");
        let mut f = create_fresh(&p).unwrap();
        f.write_all(b"fresh").unwrap();
        drop(f);
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "fresh");
        let names: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names.len(), 1, "{names:?}");
        assert!(!names.iter().any(|n| is_tmp_file(n)));
        std::fs::remove_dir_all(&d).unwrap();
    }
}
