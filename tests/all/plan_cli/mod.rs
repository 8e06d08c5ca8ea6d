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

/// `pinfeed plan ARGS` (ARGS include `--json`): its exit code and JSON document. Exit 0 is a
/// confirmed design, 3 a written design the line does not confirm (or an unchecked one), 4 none.
pub fn plan_json(args: &[&str]) -> (i32, Value) {
    let out = pinfeed(args);
    let code = out.status.code().unwrap_or(-1);
    assert!(
        [0, 3, 4].contains(&code),
        "{args:?}: exit {code}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{args:?}: stdout is not JSON ({e}): {}",
            String::from_utf8_lossy(&out.stdout)
        )
    });
    (code, v)
}

/// `pinfeed` with any arguments that are not `plan` (other commands' JSON), or `plan` with a
/// confirmed design (exit 0): its JSON document.
pub fn plan_ok(args: &[&str]) -> Value {
    if args.first() == Some(&"plan") {
        let (code, v) = plan_json(args);
        assert_eq!(code, 0, "{args:?}: {}", v["message"]);
        return v;
    }
    json_ok(args)
}

/// `pinfeed mc STUDY --json` with its reports in a temporary folder named `out`: the
/// (success, samples) of each point, in order.
pub fn mc_successes(study: &Path, out: &str) -> Vec<(u64, u64)> {
    let v = json_ok(&[
        "mc",
        study.to_str().unwrap(),
        "--json",
        "--quiet",
        "--out",
        tmp(out).to_str().unwrap(),
    ]);
    v["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            (
                r["outcomes"]["success"].as_u64().unwrap(),
                r["samples"].as_u64().unwrap(),
            )
        })
        .collect()
}

/// `part`'s fence design with a short check (2000 parts, 500 screened, no margins) under
/// `extra`, written to `file`: (exit status, JSON).
pub fn quick_fence_design(part: &str, file: &Path, extra: &[&str]) -> (i32, Value) {
    let mut args = vec![
        "plan",
        "--part",
        part,
        "--fences",
        "--check-parts",
        "2000",
        "--screen-parts",
        "500",
        "--no-margins",
        "--out",
        file.to_str().unwrap(),
        "--json",
    ];
    args.extend(extra);
    plan_json(&args)
}
