//! Writing a command's result to standard output, where a closed pipe (`| head`) is the reader's
//! choice, not an error.

use anyhow::{Context, Result};
use std::io::Write;

/// Write `text` to standard output and flush it; a broken pipe is not an error.
pub fn print_result(text: &str) -> Result<()> {
    let mut stdout = std::io::stdout().lock();
    match stdout
        .write_all(text.as_bytes())
        .and_then(|_| stdout.flush())
    {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e).context("writing to stdout"),
        _ => Ok(()),
    }
}
