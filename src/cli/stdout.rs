//! Writing to standard output, where a closed pipe (`| head`) is the reader's choice, not an
//! error: once the reader has gone, what the command still prints is dropped, the command
//! finishes its work (the files it writes) and ends with its own status, as Unix tools do. Every
//! print of the command line goes through here ([`print_result`], [`writer`], and the `out!` and
//! `outln!` macros); `clippy::print_stdout` is denied everywhere else.

use anyhow::{Context, Result};
use std::io::{ErrorKind, Write};
use std::sync::atomic::{AtomicBool, Ordering};

/// Set when a write found standard output closed: later writes are dropped.
static CLOSED: AtomicBool = AtomicBool::new(false);

/// Standard output as a writer that drops what it is given once the reader has closed the pipe
/// (other write errors are returned).
#[derive(Debug, Default)]
pub struct QuietStdout;

/// Standard output as a [`QuietStdout`].
pub fn writer() -> QuietStdout {
    QuietStdout
}

impl QuietStdout {
    fn guard<T>(r: std::io::Result<T>, closed: T) -> std::io::Result<T> {
        match r {
            Err(e) if e.kind() == ErrorKind::BrokenPipe => {
                CLOSED.store(true, Ordering::Relaxed);
                Ok(closed)
            }
            r => r,
        }
    }
}

impl Write for QuietStdout {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if CLOSED.load(Ordering::Relaxed) {
            return Ok(buf.len());
        }
        Self::guard(std::io::stdout().lock().write(buf), buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        if CLOSED.load(Ordering::Relaxed) {
            return Ok(());
        }
        Self::guard(std::io::stdout().lock().flush(), ())
    }
}

/// Write `text` to standard output and flush it; a closed pipe is not an error.
pub fn print_result(text: &str) -> Result<()> {
    let mut out = writer();
    out.write_all(text.as_bytes())
        .and_then(|_| out.flush())
        .context("writing to stdout")
}

/// `print!` through [`print_result`]: returns from the enclosing function on a write error.
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::stdout::print_result(&format!($($arg)*))?
    };
}

/// `println!` through [`print_result`]: returns from the enclosing function on a write error.
#[macro_export]
macro_rules! outln {
    () => {
        $crate::stdout::print_result("\n")?
    };
    ($($arg:tt)*) => {
        $crate::stdout::print_result(&format!("{}\n", format_args!($($arg)*)))?
    };
}
