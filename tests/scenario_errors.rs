//! Bad scenario files through the CLI (issue 7 acceptance; bad fence fields, issue 5): each is
//! refused with a non-zero exit, no panic, no result on stdout, and a message naming the file,
//! line, column, key and what is allowed. The files are under tests/fixtures/scenarios/.

use std::process::Command;

fn fixture(name: &str) -> String {
    format!(
        "{}/tests/fixtures/scenarios/{name}",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// Run `pinfeed run` on a fixture; it must fail. Returns stderr.
fn refused(name: &str) -> String {
    let out_dir = std::env::temp_dir().join(format!("pinfeed-errors-{}", std::process::id()));
    let out = Command::new(env!("CARGO_BIN_EXE_pinfeed"))
        .args(["run", &fixture(name), "--out", out_dir.to_str().unwrap()])
        .output()
        .expect("run pinfeed");
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!out.status.success(), "{name} was accepted");
    assert_eq!(out.status.code(), Some(1), "{name}: {stderr}");
    assert!(out.stdout.is_empty(), "{name} printed a result");
    assert!(!stderr.contains("panicked"), "{name} panicked: {stderr}");
    stderr
}

/// The first line of the message must be `FILE:LINE:COLUMN: key `KEY`: ...` with every word given.
fn assert_error(name: &str, line: usize, column: usize, key: &str, words: &[&str]) {
    let stderr = refused(name);
    let head = format!("{name}:{line}:{column}: key `{key}`: ");
    assert!(
        stderr.contains(&head),
        "{name}: expected '{head}' in:\n{stderr}"
    );
    for w in words {
        assert!(stderr.contains(w), "{name}: expected '{w}' in:\n{stderr}");
    }
    // The excerpt shows the offending line under the message.
    assert!(
        stderr.contains(&format!("{line} | ")),
        "{name}: no excerpt:\n{stderr}"
    );
}

#[test]
fn unknown_key() {
    assert_error(
        "unknown_key.toml",
        3,
        1,
        "belt.sped",
        &[
            "unknown field `sped`",
            "expected one of `speed`, `width`, `length`",
        ],
    );
}

#[test]
fn wrong_type() {
    assert_error(
        "wrong_type.toml",
        3,
        9,
        "belt.speed",
        &["invalid type: string \"fast\", expected f64"],
    );
}

#[test]
fn negative_speed() {
    assert_error(
        "negative_speed.toml",
        3,
        9,
        "belt.speed",
        &["must be greater than 0 (m/s), got -0.05"],
    );
}

#[test]
fn degenerate_polygon() {
    assert_error(
        "degenerate_polygon.toml",
        8,
        12,
        "part.vertices",
        &["zero area", "simple polygon"],
    );
}

#[test]
fn missing_part() {
    let stderr = refused("missing_part.toml");
    assert!(
        stderr.contains("missing_part.toml:1:1: key `part`: missing section [part]"),
        "{stderr}"
    );
    assert!(stderr.contains("shape = \"tripoly2\"") && stderr.contains("vertices"));
}

#[test]
fn unknown_value_lists_the_allowed_ones() {
    assert_error(
        "bad_arrival.toml",
        13,
        11,
        "feed.arrival",
        &["unknown variant `sometimes`", "`periodic` or `poisson`"],
    );
}

#[test]
fn reserved_obstacle_kind_is_not_yet_supported() {
    assert_error(
        "unsupported_kind.toml",
        18,
        8,
        "obstacles[0].kind",
        &[
            "\"moving_pin\" is not yet supported",
            "kind = \"pin\" and kind = \"fence\"",
        ],
    );
}

#[test]
fn fence_angle_out_of_range() {
    assert_error(
        "fence_bad_angle.toml",
        21,
        9,
        "obstacles[0].angle",
        &["strictly between -90 and 90", "got 90"],
    );
}

#[test]
fn fence_end_off_the_belt() {
    assert_error(
        "fence_off_belt.toml",
        22,
        10,
        "obstacles[0].length",
        &[
            "downstream end (0.500000, 0.256410) m lies off the belt",
            "|y| ≤ width/2 = 0.1",
        ],
    );
}

#[test]
fn fence_length_must_be_positive() {
    assert_error(
        "fence_bad_length.toml",
        22,
        10,
        "obstacles[0].length",
        &["must be greater than 0 (m), got -0.1"],
    );
}

#[test]
fn fence_friction_must_not_be_negative() {
    assert_error(
        "fence_bad_friction.toml",
        23,
        8,
        "obstacles[0].mu_f",
        &["must be at least 0", "got -0.2"],
    );
}

#[test]
fn fence_refuses_pin_keys() {
    assert_error(
        "fence_with_radius.toml",
        23,
        10,
        "obstacles[0].radius",
        &["does not apply to a fence", "x, y, angle, length, mu_f"],
    );
}

#[test]
fn fence_needs_its_angle() {
    assert_error(
        "fence_missing_angle.toml",
        17,
        1,
        "obstacles[0]",
        &["a fence needs x, y", "`angle` is missing"],
    );
}

#[test]
fn value_out_of_range_names_the_range() {
    assert_error(
        "pin_off_belt.toml",
        20,
        5,
        "obstacles[0].y",
        &["must lie in [-0.1, 0.1]", "got 0.3"],
    );
}

#[test]
fn syntax_error() {
    assert_error(
        "syntax.toml",
        11,
        6,
        "(TOML syntax)",
        &["unclosed table", "not valid TOML"],
    );
}

#[test]
fn missing_file() {
    let stderr = refused("no_such_file.toml");
    assert!(
        stderr.contains("no_such_file.toml") && stderr.contains("cannot read"),
        "{stderr}"
    );
}
