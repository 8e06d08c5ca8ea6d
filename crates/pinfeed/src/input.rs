//! Bounded reads of the files a user names (scenario, study, policy, measured-bands and contact
//! CSVs, shard files, map-cache files): one helper that reads only regular files (a device such
//! as /dev/zero or /dev/urandom, a FIFO or a folder is refused before it is opened, so a read can
//! neither block nor run without end) of at most a cap, named in the error with the file.

use std::io::Read;
use std::path::Path;

/// The largest text input (scenario, study, policy, CSV, shard): 64 MiB.
pub const TEXT_CAP: u64 = 64 << 20;
/// The largest map-cache file: 1 GiB.
pub const MAP_CAP: u64 = 1 << 30;

/// A cap as the messages show it.
fn show_cap(cap: u64) -> String {
    if cap >= 1 << 30 && cap % (1 << 30) == 0 {
        format!("{} GiB", cap >> 30)
    } else {
        format!("{} MiB", cap as f64 / (1u64 << 20) as f64)
    }
}

/// The bytes of the regular file `path`, if it holds at most `cap` bytes. The error's message says
/// what is wrong and the cap; callers name the file.
pub fn read_bounded(path: &Path, cap: u64) -> std::io::Result<Vec<u8>> {
    use std::io::{Error, ErrorKind};
    // Follows symbolic links: a link to /dev/zero is a device.
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a folder"
        } else {
            "not a regular file (a device, FIFO or socket)"
        };
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("{what}; pinfeed reads only regular files"),
        ));
    }
    let too_big = |size: String| {
        Error::new(
            ErrorKind::InvalidData,
            format!(
                "{size}, more than the {} pinfeed reads from one file",
                show_cap(cap)
            ),
        )
    };
    if meta.len() > cap {
        return Err(too_big(format!("{} bytes", meta.len())));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    std::fs::File::open(path)?
        .take(cap + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > cap {
        return Err(too_big("it grew while read".into()));
    }
    Ok(bytes)
}

/// [`read_bounded`] as UTF-8 text with [`TEXT_CAP`] (a leading byte-order mark is dropped).
pub fn read_text(path: &Path) -> std::io::Result<String> {
    let bytes = read_bounded(path, TEXT_CAP)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        )
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn devices_folders_and_large_files_are_refused() {
        for dev in ["/dev/zero", "/dev/urandom", "/dev/null"] {
            if Path::new(dev).exists() {
                let e = read_bounded(Path::new(dev), TEXT_CAP).unwrap_err();
                assert!(e.to_string().contains("not a regular file"), "{dev}: {e}");
            }
        }
        let dir = std::env::temp_dir().join(format!("pinfeed-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        assert!(read_text(&dir)
            .unwrap_err()
            .to_string()
            .contains("a folder"));
        let f = dir.join("big.toml");
        std::fs::write(&f, vec![b'#'; 2000]).unwrap();
        let e = read_bounded(&f, 1000).unwrap_err().to_string();
        assert!(
            e.contains("2000 bytes") && e.contains("MiB pinfeed reads"),
            "{e}"
        );
        assert_eq!(read_bounded(&f, 2000).unwrap().len(), 2000);
        std::fs::write(&f, "\u{feff}name = \"x\"").unwrap();
        assert_eq!(read_text(&f).unwrap(), "name = \"x\"");
        assert!(show_cap(TEXT_CAP) == "64 MiB" && show_cap(MAP_CAP) == "1 GiB");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
