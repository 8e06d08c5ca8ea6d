//! Issue 57 item 14: a command whose reader closes standard output early (`pinfeed completions
//! bash | head -1`, `pinfeed map ... --json | head -c 200`) ends quietly with its own status,
//! never a panic (exit 101). The pipe's read end is closed as soon as the command is spawned,
//! before it has started up, so its writes find the reader gone.

use std::process::{Command, Stdio};

/// Run `pinfeed ARGS` (in a scratch folder) with a standard output nobody reads; its status and
/// standard error.
fn with_closed_stdout(args: &[&str]) -> (Option<i32>, String) {
    let dir = std::env::temp_dir().join(format!(
        "pinfeed-closed-stdout-{}-{}",
        std::process::id(),
        args[0]
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_pinfeed"))
        .args(args)
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const MAP: &[&str] = &[
    "map",
    "--part",
    "tripoly2",
    "--d",
    "0.3",
    "--theta-step",
    "10",
    "--no-write",
];

#[test]
fn a_closed_stdout_ends_quietly_never_in_a_panic() {
    let quickstart = format!("{}/scenarios/quickstart.toml", env!("CARGO_MANIFEST_DIR"));
    let cases: [&[&str]; 7] = [
        // clap_complete's writer.
        &["completions", "bash"],
        // print! of a command's report, and a CSV written to standard output as it goes.
        &[MAP, &["--json"]].concat(),
        &[MAP, &["--csv"]].concat(),
        &["part", "--part", "tripoly2", "--json"],
        // The shared result printer.
        &["compare", &quickstart, "--parts", "3", "--json"],
        // println! line by line.
        &["examples"],
        &[
            "contact", "--part", "tripoly2", "--d", "0.3", "--theta0", "10",
        ],
    ];
    for args in cases {
        let (status, stderr) = with_closed_stdout(args);
        assert!(!stderr.contains("panicked"), "{args:?} panicked: {stderr}");
        assert_eq!(status, Some(0), "{args:?}: {stderr}");
        assert!(!stderr.contains("error"), "{args:?} complained: {stderr}");
    }
}
