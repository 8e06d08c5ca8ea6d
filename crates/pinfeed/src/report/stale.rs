//! A folder written whole: after a command has written its files into a report folder, the files
//! of the same kind that an earlier run left there and this run did not write (a map for a `d`
//! no longer asked for, a `parts.csv` the scenario no longer asks for) are removed, so the folder
//! never mixes old and new outputs. Only names the command itself writes are touched
//! (`ours(name)`); anything else in the folder (a user's notes, a sub-folder) is left as it is.

use std::path::{Path, PathBuf};

/// Remove the files of `dir` whose name `ours` claims but which are not among `written`
/// (file names); returns the removed paths. A missing folder removes nothing.
pub fn remove_stale(
    dir: &Path,
    written: &[String],
    ours: impl Fn(&str) -> bool,
) -> std::io::Result<Vec<PathBuf>> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e),
    };
    let mut removed = Vec::new();
    for entry in entries {
        let entry = entry?;
        if !entry.file_type()?.is_file() {
            continue;
        }
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        if ours(name) && !written.iter().any(|w| w == name) {
            std::fs::remove_file(entry.path())?;
            removed.push(entry.path());
        }
    }
    removed.sort();
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_our_unwritten_files_go() {
        let dir = std::env::temp_dir().join(format!("pinfeed-stale-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("map_d+0.5.svg.d")).unwrap();
        for f in ["map_d+0.1.svg", "map_d+0.2.svg", "notes.txt"] {
            std::fs::write(dir.join(f), "x").unwrap();
        }
        let removed = remove_stale(&dir, &["map_d+0.1.svg".into()], |n| {
            n.starts_with("map_d") && n.ends_with(".svg")
        })
        .unwrap();
        assert_eq!(removed, vec![dir.join("map_d+0.2.svg")]);
        assert!(dir.join("map_d+0.1.svg").exists());
        assert!(dir.join("notes.txt").exists());
        assert!(dir.join("map_d+0.5.svg.d").is_dir());
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(remove_stale(&dir, &[], |_| true).unwrap().is_empty());
    }
}
