//! Issue 28 ("Hardening the new surface"): each reproducer of the report as a named regression
//! test, run through the release binary as the report ran it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn pinfeed(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pinfeed"))
        .args(args)
        .output()
        .expect("run pinfeed")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).to_string()
}

/// A fresh, empty folder for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinfeed-harden-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn bundled(name: &str) -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios")
            .join(name),
    )
    .unwrap()
}

/// Refused cleanly: exit 1, no panic, nothing on stdout. Returns stderr.
fn refused(o: &Output, what: &str) -> String {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(1), "{what}: {e}");
    assert!(!e.contains("panicked"), "{what} panicked: {e}");
    assert!(o.stdout.is_empty(), "{what} printed a result");
    e
}

/// tripoly1_sensing.toml with the moving pin's speed and accel replaced.
fn mover_scenario(dir: &Path, speed: &str, accel: &str) -> PathBuf {
    let src = bundled("tripoly1_sensing.toml")
        .replace(
            "speed = 0.1          # m/s",
            &format!("speed = {speed}          # m/s"),
        )
        .replace(
            "accel = 1.0          # m/s²",
            &format!("accel = {accel}          # m/s²"),
        );
    assert!(
        src.contains(&format!("speed = {speed} ")) && src.contains(&format!("accel = {accel} "))
    );
    let p = dir.join(format!("mover_{speed}_{accel}.toml"));
    std::fs::write(&p, src).unwrap();
    p
}

/// Item 1: speed = 60 m/s, accel = 1e6 m/s² (inside the actuator ranges) at belt 0.05 m/s asked
/// the pin path for 1200 belt speeds and panicked in actuator.rs; it is refused where the file is
/// read, located, with the range the belt allows.
#[test]
fn moving_pin_faster_than_the_belt_allows_is_refused_where_read() {
    let dir = scratch("mover-fast");
    let f = mover_scenario(&dir, "60", "1e6");
    let out = dir.join("out");
    let f = f.to_str().unwrap();
    let runs: [(&str, Vec<&str>); 2] = [
        (
            "run",
            vec!["run", f, "--parts", "3", "--out", out.to_str().unwrap()],
        ),
        ("compare", vec!["compare", f, f, "--parts", "3"]),
    ];
    for (cmd, args) in runs {
        let o = pinfeed(&args);
        let e = refused(&o, cmd);
        let line = bundled("tripoly1_sensing.toml")
            .lines()
            .position(|l| l.starts_with("speed = 0.1"))
            .unwrap()
            + 1;
        assert!(
            e.contains(&format!("mover_60_1e6.toml:{line}:")),
            "{cmd}: not located: {e}"
        );
        assert!(e.contains("key `obstacles[1].speed`"), "{cmd}: {e}");
        assert!(
            e.contains("[0.000001, 50]") || e.contains("[1e-6, 50]"),
            "{cmd}: {e}"
        );
        assert!(e.contains("got 60"), "{cmd}: {e}");
        assert!(e.contains("belt.speed = 0.05"), "{cmd}: {e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Item 1: the fastest pin the rule allows (exactly 1000 belt speeds, a very hard actuator) runs.
#[test]
fn moving_pin_at_the_speed_limit_runs() {
    let dir = scratch("mover-limit");
    let f = mover_scenario(&dir, "50", "1e6");
    let out = dir.join("out");
    let o = pinfeed(&[
        "run",
        f.to_str().unwrap(),
        "--parts",
        "4",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("\"parts\""), "{}", stdout(&o));
    let _ = std::fs::remove_dir_all(&dir);
}
