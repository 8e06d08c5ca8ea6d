//! Atomic file writes: the bytes go to a hidden temporary file in the target's folder
//! (`.NAME.tmp-PID`), are flushed to disk, and the file is renamed over the target (a rename within
//! one file system is atomic on POSIX). A process killed at any moment leaves either the old file,
//! or the complete new one — never a partial file under the final name. Shard files and reports
//! are written this way.
//!
//! Fault injection (for tests): with the environment variable `PINFEED_FAULT=after-temp-write`
//! (read once per process), the process aborts — like a job killed by its scheduler — right after
//! the first temporary file is complete and before it is renamed, so a test can check
//! deterministically, without timing, what an interrupted job leaves behind. Any other value, or
//! none, changes nothing.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The environment variable that injects a fault, and its one value.
pub const FAULT_VAR: &str = "PINFEED_FAULT";
pub const FAULT_AFTER_TEMP_WRITE: &str = "after-temp-write";

/// Whether `PINFEED_FAULT=after-temp-write` is set (read once).
fn abort_after_temp_write() -> bool {
    static FAULT: OnceLock<bool> = OnceLock::new();
    *FAULT
        .get_or_init(|| std::env::var(FAULT_VAR).is_ok_and(|v| v.trim() == FAULT_AFTER_TEMP_WRITE))
}

/// The hidden temporary path beside `path`.
pub fn temporary_path(path: &Path) -> PathBuf {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("file");
    let tmp = format!(".{name}.tmp-{}", std::process::id());
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(d) => d.join(tmp),
        None => PathBuf::from(tmp),
    }
}

/// Produce a file at `path` atomically: `write` creates it at the temporary path it is given,
/// which is then renamed to `path` (and removed if anything fails).
pub fn produce_atomic(
    path: &Path,
    write: impl FnOnce(&Path) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let tmp = temporary_path(path);
    let result = write(&tmp).and_then(|_| {
        if abort_after_temp_write() {
            // Injected fault: die between the complete temporary file and the rename.
            std::process::abort();
        }
        std::fs::rename(&tmp, path)
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Write `bytes` to `path` atomically: a hidden temporary file beside it, flushed, then renamed.
/// `before_rename` sees the temporary path (tests use it to check that nothing is at `path` yet).
pub fn write_atomic(
    path: &Path,
    bytes: &[u8],
    before_rename: &mut dyn FnMut(&Path),
) -> std::io::Result<()> {
    produce_atomic(path, |tmp| {
        let mut f = std::fs::File::create(tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        before_rename(tmp);
        Ok(())
    })
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
        write_atomic(&path, b"complete", &mut |tmp: &Path| {
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
        assert!(write_atomic(&target, b"x", &mut |_| {}).is_err());
        let leftovers: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains(".tmp-"))
            .collect();
        assert!(leftovers.is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
