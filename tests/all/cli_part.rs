//! End-to-end tests of `pinfeed part` through the built binary: JSON output for the named parts,
//! user vertex lists, refusal of bad input (non-zero exit, reason on stderr) and the SVG plot.

use crate::support::{pinfeed, pinfeed_json};
use serde_json::Value;
use std::path::PathBuf;

/// Run a command that must fail; return its stderr.
fn refused(args: &[&str]) -> String {
    let out = pinfeed(args);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(
        !out.status.success(),
        "{args:?} was accepted: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert_ne!(out.status.code(), Some(0));
    assert!(
        out.stdout.is_empty(),
        "{args:?} printed a result despite failing"
    );
    stderr
}

fn assert_refused_with(args: &[&str], words: &[&str]) {
    let err = refused(args).to_lowercase();
    assert!(
        words.iter().any(|w| err.contains(w)),
        "{args:?}: stderr should mention one of {words:?}, got: {err}"
    );
}

fn f(v: &Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("key {key} missing or not a number in {v}"))
}

fn states(v: &Value) -> Vec<f64> {
    v["stable_states_deg"]
        .as_array()
        .expect("stable_states_deg array")
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

fn assert_states(v: &Value, want: &[f64]) {
    let got = states(v);
    assert_eq!(got.len(), want.len(), "{got:?} vs {want:?}");
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() < 1e-6, "{got:?} vs {want:?}");
    }
}

fn centroid(v: &Value) -> (f64, f64) {
    let c = v["centroid"].as_array().expect("centroid array");
    assert_eq!(c.len(), 2);
    (c[0].as_f64().unwrap(), c[1].as_f64().unwrap())
}

#[test]
fn tripoly1_json() {
    let v = pinfeed_json(&["part", "tripoly1", "--json"]);
    assert!((f(&v, "area") - 2.25).abs() < 1e-12);
    assert!((f(&v, "a") - 2.5f64.sqrt()).abs() < 1e-12);
    assert_eq!(v["convex"], Value::Bool(true));
    let (cx, cy) = centroid(&v);
    assert!(cx.abs() < 1e-12 && cy.abs() < 1e-12);
    assert_states(&v, &[0.0, 135.0, 225.0]);
}

#[test]
fn tripoly2_json() {
    let v = pinfeed_json(&["part", "tripoly2", "--json"]);
    assert!((f(&v, "area") - 1.0).abs() < 1e-12);
    assert!((f(&v, "a") - 17f64.sqrt() / 3.0).abs() < 1e-12);
    assert_eq!(v["convex"], Value::Bool(true));
    let (cx, cy) = centroid(&v);
    assert!(cx.abs() < 1e-12 && cy.abs() < 1e-12);
    assert_states(&v, &[0.0, 90.0, 206.565051177078]);
    assert!((states(&v)[2] - 206.565).abs() < 1e-3);
}

#[test]
fn lshape_json_is_concave() {
    let v = pinfeed_json(&["part", "lshape", "--json"]);
    assert_eq!(v["convex"], Value::Bool(false));
    assert!((f(&v, "area") - 3.0).abs() < 1e-12);
    let (cx, cy) = centroid(&v);
    assert!((cx - 5.0 / 6.0).abs() < 1e-12 && (cy - 5.0 / 6.0).abs() < 1e-12);
    assert_states(&v, &[0.0, 90.0, 180.0, 225.0, 270.0]);
}

#[test]
fn parametrised_parts_json() {
    let v = pinfeed_json(&["part", "rect:4:2", "--json"]);
    assert!((f(&v, "area") - 8.0).abs() < 1e-12);
    assert!((f(&v, "a") - 5f64.sqrt()).abs() < 1e-12);
    assert_states(&v, &[0.0, 90.0, 180.0, 270.0]);
    let v = pinfeed_json(&["part", "ngon:5", "--json"]);
    assert!((f(&v, "a") - 1.0).abs() < 1e-12);
    assert_states(&v, &[0.0, 72.0, 144.0, 216.0, 288.0]);
}

#[test]
fn vertex_list_json() {
    // tripoly1 typed shifted by (10, 20) and clockwise: same answers, centroid (10, 20).
    let v = pinfeed_json(&[
        "part",
        "--part",
        "vertices:10,21 11.5,19.5 8.5,19.5",
        "--json",
    ]);
    let (cx, cy) = centroid(&v);
    assert!((cx - 10.0).abs() < 1e-12 && (cy - 20.0).abs() < 1e-12);
    assert_states(&v, &[0.0, 135.0, 225.0]);
    // A list starting with a negative number must not be taken for a command-line flag.
    let v = pinfeed_json(&[
        "part",
        "--part",
        "vertices:-1.5,-0.5 1.5,-0.5 0,1",
        "--json",
    ]);
    assert!((f(&v, "area") - 2.25).abs() < 1e-12);
    assert_states(&v, &[0.0, 135.0, 225.0]);
    // Semicolons separate vertices too, and the `vertices:` spec works as a NAME.
    let v = pinfeed_json(&["part", "vertices:0,0; 3,0; 0,3", "--json"]);
    let (cx, cy) = centroid(&v);
    assert!((cx - 1.0).abs() < 1e-12 && (cy - 1.0).abs() < 1e-12);
    assert!((f(&v, "area") - 4.5).abs() < 1e-12);
}

#[test]
fn vertex_list_scale_free_through_cli() {
    // Scaling the typed vertices by 1000 multiplies a by 1000, area by 10⁶, keeps stable states.
    let small = pinfeed_json(&["part", "--part", "vertices:0,0 2,0 0,1", "--json"]);
    let big = pinfeed_json(&["part", "--part", "vertices:0,0 2000,0 0,1000", "--json"]);
    assert!((f(&big, "a") - 1000.0 * f(&small, "a")).abs() < 1e-9);
    assert!((f(&big, "area") - 1e6 * f(&small, "area")).abs() < 1e-6);
    let (s, b) = (states(&small), states(&big));
    assert_eq!(s.len(), b.len());
    for (x, y) in s.iter().zip(&b) {
        assert!((x - y).abs() < 1e-9);
    }
}

#[test]
fn text_output_lists_stable_states() {
    let out = pinfeed(&["part", "tripoly2"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("206.565"), "{text}");
    assert!(text.contains("stable states"), "{text}");
}

// ------------------------------------------------------------------------------------------------
// Refusals: non-zero exit and the reason on stderr

#[test]
fn refuses_too_few_vertices() {
    assert_refused_with(&["part", "--part", "vertices:0,0 1,0"], &["at least 3"]);
    assert_refused_with(&["part", "--part", "vertices:0,0"], &["at least 3"]);
    assert_refused_with(&["part", "--part", "vertices:"], &["at least 3"]);
}

#[test]
fn refuses_collinear_vertices() {
    assert_refused_with(&["part", "--part", "vertices:0,0 1,1 2,2"], &["collinear"]);
    assert_refused_with(
        &["part", "--part", "vertices:0,0 1,0 3,0 2,0"],
        &["collinear"],
    );
}

#[test]
fn refuses_degenerate_sliver() {
    // Not all collinear, but with an area below the relative tolerance: zero area.
    assert_refused_with(
        &["part", "--part", "vertices:0,0 1,0 2,1e-14"],
        &["zero area"],
    );
}

#[test]
fn refuses_self_intersecting() {
    assert_refused_with(
        &["part", "--part", "vertices:0,0 1,1 1,0 0,1"],
        &["not simple", "intersect"],
    );
    // A vertex touching a non-adjacent edge, and a spike folding back on itself.
    assert_refused_with(
        &["part", "--part", "vertices:0,0 4,0 4,2 2,0 0,2"],
        &["not simple", "intersect"],
    );
    assert_refused_with(
        &["part", "--part", "vertices:0,0 2,0 1,0 1,1"],
        &["not simple", "intersect"],
    );
}

#[test]
fn refuses_non_finite() {
    // Rust's f64 parser accepts "NaN", "nan", "inf", "-infinity"; 1e999 overflows to infinity.
    for list in [
        "NaN,0 1,0 0,1",
        "0,0 1,nan 0,1",
        "0,0 inf,0 0,1",
        "0,0 1,0 0,-infinity",
        "0,0 1e999,0 0,1",
    ] {
        assert_refused_with(&["part", "--vertices", list], &["non-finite"]);
    }
}

#[test]
fn refuses_repeated_vertex() {
    assert_refused_with(&["part", "--part", "vertices:0,0 1,0 1,0 0,1"], &["repeat"]);
    // Closing the ring by hand is refused too, with the hint.
    let err = refused(&["part", "--part", "vertices:0,0 1,0 0,1 0,0"]);
    assert!(err.contains("repeat"), "{err}");
    assert!(err.contains("do not repeat the first vertex"), "{err}");
}

#[test]
fn refuses_malformed_vertex_lists() {
    assert_refused_with(
        &["part", "--part", "vertices:0,0 1,x 0,1"],
        &["not a number"],
    );
    assert_refused_with(&["part", "--part", "vertices:0,0 1 0,1"], &["x,y"]);
    assert_refused_with(&["part", "--part", "vertices:0,0 1,0,2 0,1"], &["x,y"]);
}

#[test]
fn refuses_unknown_part_name() {
    let err = refused(&["part", "blob"]);
    assert!(err.contains("unknown part"), "{err}");
    assert!(err.contains("blob"), "{err}");
    assert!(
        err.contains("tripoly2"),
        "the message should list the known names: {err}"
    );
}

#[test]
fn refuses_bad_rect_and_ngon_parameters() {
    for (spec, word) in [
        ("rect:2", "rect:w:h"),
        ("rect:1:2:3", "rect:w:h"),
        ("rect:0:1", "positive"),
        ("rect:1:-2", "positive"),
        ("rect:nan:1", "positive"),
        ("rect:inf:1", "positive"),
        ("rect:a:1", "not a number"),
        ("ngon:2", "between 3 and 1000"),
        ("ngon:1001", "between 3 and 1000"),
        ("ngon:x", "whole number"),
        ("ngon:4.5", "whole number"),
    ] {
        assert_refused_with(&["part", spec], &[word]);
    }
}

#[test]
fn refuses_missing_or_conflicting_part() {
    assert_refused_with(&["part"], &["give a part: --part"]);
    // NAME and --vertices together: clap refuses (usage error).
    let err = refused(&["part", "square", "--vertices", "0,0 1,0 0,1"]);
    assert!(err.contains("cannot be used with"), "{err}");
}

// ------------------------------------------------------------------------------------------------
// Plot

fn tmp_file(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    let _ = std::fs::remove_file(&p);
    p
}

#[test]
fn plot_writes_svg() {
    for name in ["tripoly2", "lshape"] {
        let path = tmp_file(&format!("cli_part_{name}.svg"));
        let out = pinfeed(&["part", name, "--plot", path.to_str().unwrap()]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let meta = std::fs::metadata(&path).expect("plot file written");
        assert!(meta.len() > 1024, "{name}: SVG only {} bytes", meta.len());
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.contains("<svg"), "{name}: not an SVG");
        assert!(svg.trim_end().ends_with("</svg>"), "{name}: SVG not closed");
    }
}

#[test]
fn plot_with_json_still_prints_json() {
    let path = tmp_file("cli_part_json_plot.svg");
    let v = pinfeed_json(&[
        "part",
        "tripoly1",
        "--json",
        "--plot",
        path.to_str().unwrap(),
    ]);
    assert_states(&v, &[0.0, 135.0, 225.0]);
    assert!(std::fs::metadata(&path).unwrap().len() > 1024);
}

#[test]
fn plot_to_unwritable_path_fails_cleanly() {
    let path = tmp_file("no_such_dir/sub/plot.svg");
    assert_refused_with(
        &["part", "square", "--plot", path.to_str().unwrap()],
        &["writing"],
    );
}

/// `--part` is the flag every command takes; `--vertices` still works, hidden, with a warning
/// naming its replacement, and the two cannot be mixed.
#[test]
fn part_takes_the_part_flag_and_warns_on_vertices() {
    let by_flag = pinfeed_json(&["part", "--part", "tripoly2", "--json"]);
    let by_name = pinfeed_json(&["part", "tripoly2", "--json"]);
    assert_eq!(by_flag, by_name);
    assert_eq!(by_flag["name"], "tripoly2");
    assert_eq!(by_flag["schema_version"], pinfeed::SCHEMA_VERSION);
    assert_eq!(by_flag["pinfeed_version"], pinfeed::PINFEED_VERSION);
    let custom = pinfeed_json(&["part", "--part", "vertices:0,0 3,0 0,3", "--json"]);
    assert_eq!(custom["name"], "vertices");
    let old = pinfeed(&["part", "--vertices", "0,0 3,0 0,3", "--json"]);
    assert!(old.status.success());
    let stderr = String::from_utf8_lossy(&old.stderr);
    assert!(
        stderr.contains("--vertices is deprecated") && stderr.contains("--part vertices:"),
        "{stderr}"
    );
    let old: Value = serde_json::from_slice(&old.stdout).unwrap();
    assert_eq!(old["area"], custom["area"]);
    let help = pinfeed(&["part", "--help"]);
    assert!(!String::from_utf8_lossy(&help.stdout).contains("--vertices"));
    assert_refused_with(
        &["part", "--part", "tripoly1", "--vertices", "0,0 1,0 0,1"],
        &["cannot be used with"],
    );
}
