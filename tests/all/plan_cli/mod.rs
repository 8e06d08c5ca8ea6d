//! Shared helpers for the `pinfeed plan` command tests (the `plan`, `plan_fences` and `plan_sensing` modules).
#![allow(dead_code)]

pub use crate::support::{pinfeed, pinfeed_json as json_ok};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// A file in a temporary folder of this test binary and process (the `plan*` modules' files have
/// distinct names).
pub fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "pinfeed_{}_{}",
        env!("CARGO_CRATE_NAME"),
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// `pinfeed run FILE` on 300 parts (reports to a temporary folder of its own, named after FILE):
/// its JSON summary.
pub fn run_300(file: &str) -> Value {
    let runs = tmp(&format!(
        "runs_{}",
        Path::new(file).file_stem().unwrap().to_string_lossy()
    ));
    json_ok(&[
        "run",
        file,
        "--parts",
        "300",
        "--json",
        "--quiet",
        "--out",
        runs.to_str().unwrap(),
    ])
}
