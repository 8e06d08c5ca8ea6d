//! Shared helpers for the `pinfeed plan` command tests (`tests/plan*.rs`).
#![allow(dead_code)]

use serde_json::Value;
use std::path::PathBuf;
use std::process::{Command, Output};

pub fn pinfeed(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinfeed"))
        .args(args)
        .output()
        .expect("run pinfeed")
}

/// A file in a temporary folder of this test binary and process.
pub fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "pinfeed_{}_{}",
        env!("CARGO_CRATE_NAME"),
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Run `pinfeed` expecting success and JSON on stdout.
pub fn json_ok(args: &[&str]) -> Value {
    let out = pinfeed(args);
    assert!(
        out.status.success(),
        "{args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is JSON")
}

/// `pinfeed run FILE` on 300 parts (reports to a temporary folder): its JSON summary.
pub fn run_300(file: &str) -> Value {
    let out = pinfeed(&[
        "run",
        file,
        "--parts",
        "300",
        "--json",
        "--quiet",
        "--out",
        tmp("runs").to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "run {file} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is JSON")
}
