//! Running the built `pinfeed` binary: the one helper every command-line test module uses.

use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output};

/// `pinfeed ARGS`, run from the test's working directory (the package root under `cargo test`).
pub fn pinfeed(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinfeed"))
        .args(args)
        .output()
        .expect("run pinfeed")
}

/// `pinfeed ARGS` run from `dir`.
pub fn pinfeed_in(dir: impl AsRef<Path>, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinfeed"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("run pinfeed")
}

/// `out` of `pinfeed ARGS` must be a success; returns it.
pub fn assert_success(args: &[&str], out: Output) -> Output {
    assert!(
        out.status.success(),
        "pinfeed {args:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// `pinfeed ARGS` must succeed; returns its output.
pub fn pinfeed_ok(args: &[&str]) -> Output {
    assert_success(args, pinfeed(args))
}

/// `pinfeed ARGS` must succeed and print JSON on stdout; returns the parsed value.
pub fn pinfeed_json(args: &[&str]) -> Value {
    let out = pinfeed_ok(args);
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{args:?}: stdout is not JSON ({e}): {}",
            String::from_utf8_lossy(&out.stdout)
        )
    })
}
