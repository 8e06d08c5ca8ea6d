//! Every file pinfeed writes is written whole or not at all: the bytes go to a hidden temporary
//! file in the target's folder (`.NAME.tmp-PID-N`), are flushed to disk, and the file is renamed
//! over the target (a rename within one file system is atomic on POSIX). A process killed at any
//! moment, or a write that fails (a full disk), leaves either the old file or the complete new one
//! — never a partial file under the final name — and a failure removes its temporary file.
//!
//! * [`write_atomic`]: bytes to a file; [`produce_atomic`]: a file produced by a writer that wants
//!   a path; [`Staged`]: the same as a guard (plots drawn by a backend that owns the path).
//! * [`Batch`]: several files that belong together (a run's summary beside its figures): all are
//!   produced as temporary files first and renamed only when every one is complete, so a failure
//!   leaves the previous set whole instead of mixing old and new files.
//!
//! Fault injection (for tests): with the environment variable `PINFEED_FAULT=after-temp-write`
//! (read once per process), the process aborts — like a job killed by its scheduler — right after
//! the first temporary file is complete and before it is renamed, so a test can check
//! deterministically, without timing, what an interrupted job leaves behind. Any other value, or
//! none, changes nothing.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

/// The environment variable that injects a fault, and its one value.
pub const FAULT_VAR: &str = "PINFEED_FAULT";
/// The one value of [`FAULT_VAR`] that injects a fault: abort after the first temporary file is
/// written.
pub const FAULT_AFTER_TEMP_WRITE: &str = "after-temp-write";

/// Whether `PINFEED_FAULT=after-temp-write` is set (read once).
fn abort_after_temp_write() -> bool {
    static FAULT: OnceLock<bool> = OnceLock::new();
    *FAULT
        .get_or_init(|| std::env::var(FAULT_VAR).is_ok_and(|v| v.trim() == FAULT_AFTER_TEMP_WRITE))
}

/// A hidden temporary path beside `path`, unique within the process (threads may write files of
/// the same name at once, e.g. map-cache builders).
pub fn temporary_path(path: &Path) -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let tmp = format!(".{name}.tmp-{}-{n}", std::process::id());
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(d) => d.join(tmp),
        None => PathBuf::from(tmp),
    }
}

/// A file being produced at a temporary path beside its target: [`Staged::commit`] renames it
/// over the target; dropped without a commit (an error on the way), the temporary file is removed.
pub struct Staged {
    path: PathBuf,
    tmp: PathBuf,
    done: bool,
}

impl Staged {
    /// A file to be produced at `path`: its content goes to a temporary path beside it until
    /// committed.
    pub fn new(path: &Path) -> Staged {
        Staged {
            path: path.to_path_buf(),
            tmp: temporary_path(path),
            done: false,
        }
    }

    /// Where to write the file's content.
    pub fn tmp(&self) -> &Path {
        &self.tmp
    }

    /// The target.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flush the temporary file to disk and rename it over the target.
    pub fn commit(mut self) -> std::io::Result<()> {
        std::fs::File::open(&self.tmp)?.sync_all()?;
        if abort_after_temp_write() {
            // Injected fault: die between the complete temporary file and the rename.
            std::process::abort();
        }
        std::fs::rename(&self.tmp, &self.path)?;
        self.done = true;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.done {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Produce a file at `path` atomically: `write` creates it at the temporary path it is given,
/// which is then renamed to `path` (and removed if anything fails).
pub fn produce_atomic<E: From<std::io::Error>>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), E> {
    let staged = Staged::new(path);
    write(staged.tmp())?;
    Ok(staged.commit()?)
}

/// Write `bytes` to `path` atomically.
pub fn write_atomic(path: impl AsRef<Path>, bytes: impl AsRef<[u8]>) -> std::io::Result<()> {
    write_atomic_observed(path.as_ref(), bytes.as_ref(), &mut |_| {})
}

/// [`write_atomic`], with `before_rename` shown the complete temporary file (tests use it to
/// check that nothing is at `path` yet).
pub fn write_atomic_observed(
    path: &Path,
    bytes: &[u8],
    before_rename: &mut dyn FnMut(&Path),
) -> std::io::Result<()> {
    produce_atomic(path, |tmp| {
        let mut f = std::fs::File::create(tmp)?;
        f.write_all(bytes)?;
        drop(f);
        before_rename(tmp);
        Ok::<(), std::io::Error>(())
    })
}

/// Files that appear together or not at all (see the module docs): each is produced at its
/// temporary path, and [`Batch::commit`] renames them all once every one is complete. Dropped
/// without a commit, every temporary file is removed and no target changes.
#[derive(Default)]
pub struct Batch {
    staged: Vec<Staged>,
}

impl Batch {
    /// An empty batch.
    pub fn new() -> Batch {
        Batch::default()
    }

    /// Add `bytes` as the content of `path`.
    pub fn write(&mut self, path: &Path, bytes: impl AsRef<[u8]>) -> std::io::Result<()> {
        let staged = Staged::new(path);
        std::fs::write(staged.tmp(), bytes)?;
        self.staged.push(staged);
        Ok(())
    }

    /// Add the file `write` produces at the temporary path it is given as `path`.
    pub fn produce<E>(
        &mut self,
        path: &Path,
        write: impl FnOnce(&Path) -> Result<(), E>,
    ) -> Result<(), E> {
        let staged = Staged::new(path);
        write(staged.tmp())?;
        self.staged.push(staged);
        Ok(())
    }

    /// Rename every file over its target (renames need no space, so a full disk cannot stop
    /// them half way).
    pub fn commit(self) -> std::io::Result<()> {
        for s in self.staged {
            s.commit()?;
        }
        Ok(())
    }
}

/// Why a report file could not be written: the path and the I/O error, both in the message.
///
/// The I/O error is part of the message rather than a `source`, so a chain printed in full
/// (`{:#}`) names it once.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// The file could not be written.
    #[error("writing {}: {error}", path.display())]
    Writing {
        /// The file.
        path: PathBuf,
        /// Why it could not be written.
        error: std::io::Error,
    },
    /// The folder the file goes into could not be created.
    #[error("creating {}: {error}", dir.display())]
    Creating {
        /// The folder.
        dir: PathBuf,
        /// Why it could not be created.
        error: std::io::Error,
    },
}

/// Write a report file whole (creating its folder), naming the file on failure.
pub fn write_file(path: &Path, bytes: impl AsRef<[u8]>) -> Result<(), WriteError> {
    create_parent(path)?;
    write_atomic(path, bytes).map_err(|error| WriteError::Writing {
        path: path.to_path_buf(),
        error,
    })
}

/// Rewrite a report file from its current text (empty when it does not exist yet), whole: for
/// the benchmarks that replace their own marked section of a shared report.
pub fn rewrite_file(path: &Path, edit: impl FnOnce(&str) -> String) -> Result<(), WriteError> {
    let old = std::fs::read_to_string(path).unwrap_or_default();
    write_file(path, edit(&old))
}

/// A word of a command line, quoted for a POSIX shell if it needs it (for the command lines that
/// regenerate a report, written at its top): plain when it holds only letters, digits and
/// `-_.,:/+=`, else in single quotes.
pub fn shell_word(s: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "-_.,:/+=".contains(c);
    if !s.is_empty() && s.chars().all(plain) {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// Create the folder `path` goes into (if it has one), naming it on failure.
pub fn create_parent(path: &std::path::Path) -> Result<(), WriteError> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|error| WriteError::Creating {
            dir: dir.to_path_buf(),
            error,
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_renames_only_a_complete_file() {
        let dir = std::env::temp_dir().join(format!("pinfeed-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("shard-0000-of-0001.json");
        let _ = std::fs::remove_file(&path);
        let mut seen = None;
        write_atomic_observed(&path, b"complete", &mut |tmp: &Path| {
            // Before the rename only the hidden temporary file exists, already complete.
            assert!(!path.exists());
            assert_eq!(std::fs::read(tmp).unwrap(), b"complete");
            assert!(tmp.file_name().unwrap().to_str().unwrap().starts_with('.'));
            seen = Some(tmp.to_path_buf());
        })
        .unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"complete");
        assert!(!seen.unwrap().exists());
        // A failed write (the target is a directory) leaves no temporary file behind.
        let target = dir.join("occupied");
        std::fs::create_dir_all(target.join("x")).unwrap();
        assert!(write_atomic(&target, b"x").is_err());
        let leftovers: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
            .collect();
        assert!(leftovers.is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A failed write names the file (or the folder it could not create) with the I/O error in
    /// the message, and no source (a chain printed in full names the error once).
    #[test]
    fn write_errors_name_the_path_and_the_error() {
        let e = write_file(Path::new("/proc/pinfeed-no/such.md"), "x").unwrap_err();
        assert!(matches!(e, WriteError::Creating { .. }), "{e:?}");
        assert!(
            e.to_string().starts_with("creating /proc/pinfeed-no: "),
            "{e}"
        );
        assert!(std::error::Error::source(&e).is_none());
    }

    /// A batch whose second file fails changes no target and leaves no temporary file; a
    /// committed batch replaces every target.
    #[test]
    fn a_failed_batch_changes_nothing() {
        let dir = std::env::temp_dir().join(format!("pinfeed-batch-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let (a, b) = (dir.join("a.json"), dir.join("b.svg"));
        std::fs::write(&a, "old a").unwrap();
        std::fs::write(&b, "old b").unwrap();
        let mut batch = Batch::new();
        batch.write(&a, "new a").unwrap();
        let failed: std::io::Result<()> = batch.produce(&b, |tmp| {
            std::fs::write(tmp, "half")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(failed.is_err());
        drop(batch);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "old b");
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
        let mut batch = Batch::new();
        batch.write(&a, "new a").unwrap();
        batch.write(&b, "new b").unwrap();
        batch.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "new b");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
