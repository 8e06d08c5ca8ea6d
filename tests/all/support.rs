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

/// `text` with the folder `dir` written as `OUT`: a report names the folder it was written to in
/// its regenerating command (`--out DIR`), so two reports of the same study written to two
/// folders compare equal after this.
pub fn without_dir(text: &str, dir: &std::path::Path) -> String {
    text.replace(dir.to_str().expect("a UTF-8 path"), "OUT")
}

/// The file `name` of the report folder `dir`, with `dir` written as `OUT` ([`without_dir`]).
pub fn report_text(dir: &std::path::Path, name: &str) -> String {
    let text = std::fs::read_to_string(dir.join(name))
        .unwrap_or_else(|e| panic!("reading {}: {e}", dir.join(name).display()));
    without_dir(&text, dir)
}

/// What `pinfeed ARGS` shows on a terminal: run through a pseudo-terminal (util-linux `script`,
/// on every Debian machine), the bytes the terminal received, standard output and error together
/// (a copy is left in `log`). None, with a note, when `script` is not installed.
pub fn pinfeed_on_terminal(args: &[&str], log: &Path) -> Option<String> {
    let has_script = Command::new("script")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !has_script {
        eprintln!("`script` is not installed: the pseudo-terminal half of this test did not run");
        return None;
    }
    let quoted: Vec<String> = std::iter::once(env!("CARGO_BIN_EXE_pinfeed"))
        .chain(args.iter().copied())
        .map(|a| format!("'{}'", a.replace('\'', r"'\''")))
        .collect();
    let o = Command::new("script")
        .args([
            "-qec",
            &quoted.join(" "),
            log.to_str().expect("a UTF-8 path"),
        ])
        .stdin(std::process::Stdio::null())
        .output()
        .expect("run script");
    assert!([0, 3].contains(&o.status.code().unwrap_or(-1)), "{o:?}");
    Some(String::from_utf8_lossy(&std::fs::read(log).expect("the terminal's log")).to_string())
}

/// A fresh, empty folder `pinfeed-<tag>-<process id>` in the system's temporary folder (a test
/// names it after its module and itself, so no other test uses it).
pub fn fresh_dir(tag: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("pinfeed-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("creating a temporary folder");
    d
}

/// The number of cases of a long randomized test: `bounded` in a plain `cargo test`, `deep` when
/// the environment variable `PINFEED_DEEP_TESTS` is set to anything but `0` (the deep form; see
/// docs/commands.md, "Tests"). Both forms make the same assertions over the same seeds; the deep
/// one draws more cases from each seed's stream.
pub fn cases(bounded: u32, deep: u32) -> u32 {
    match std::env::var("PINFEED_DEEP_TESTS") {
        Ok(v) if v != "0" => deep,
        _ => bounded,
    }
}
