//! `pinfeed plan` designs against an uncertainty by default (docs/commands.md#planning-a-line-pinfeed-plan):
//! the default set, `--robust`, `--uncertain FILE`, `--nominal`. The verdict is a Monte Carlo
//! study under it, written beside the design; that file is the study the verdict ran, and another
//! seed does not refute a confirmed design.

use crate::plan_cli::{mc_successes, pinfeed, quick_fence_design, tmp};
use serde_json::Value;
use std::path::Path;

/// tripoly2's fence line (a quick, confirmed design) under `extra`, written to `file`.
fn fence_design(file: &Path, extra: &[&str]) -> (i32, Value) {
    quick_fence_design("tripoly2", file, extra)
}

/// `pinfeed mc STUDY`: its one point's (success, samples).
fn mc_success(study: &Path, out: &str) -> (u64, u64) {
    mc_successes(study, out)[0]
}

#[test]
fn a_default_design_is_checked_under_the_documented_uncertainty_by_the_study_it_writes() {
    let file = tmp("uncertain_t2.toml");
    let (code, v) = fence_design(&file, &[]);
    assert_eq!(code, 0, "{}", v["message"]);
    // The uncertainty is the documented default, in words in the JSON.
    let said = v["uncertainty"].as_str().unwrap();
    for part in [
        "the default uncertainty",
        "fence_mu_f uniform [0.4, 0.6]",
        "fence_angle uniform [-0.5, 0.5]",
        "fence_x uniform [-0.0005, 0.0005]",
        "fence_y uniform [-0.0005, 0.0005]",
    ] {
        assert!(said.contains(part), "{said} lacks {part}");
    }
    // The verdict is the check under it, of at least the check's parts.
    let u = &v["uncertain_check"];
    let (success, parts) = (u["success"].as_u64().unwrap(), u["parts"].as_u64().unwrap());
    assert!(parts >= 2000, "{u}");
    assert!(success as f64 / parts as f64 >= 0.99, "{u}");
    assert!(u["lower95"].as_f64().unwrap() < u["success_rate"].as_f64().unwrap());
    // The study beside the design holds what reaches a fence line and nothing else …
    let study = file.with_file_name("uncertain_t2.uncertain.toml");
    let text = std::fs::read_to_string(&study).unwrap();
    for table in ["fence_mu_f", "fence_angle", "fence_x", "fence_y"] {
        assert!(text.contains(&format!("[uncertain.{table}]")), "{text}");
    }
    for table in ["mu_c", "pin_x", "pin_y"] {
        assert!(!text.contains(&format!("[uncertain.{table}]")), "{text}");
    }
    // … and is the verdict's study: `pinfeed mc` on it counts the same successes.
    assert_eq!(mc_success(&study, "uncertain_t2_mc"), (success, parts));
    // Another seed does not refute the confirmed design.
    let other = file.with_file_name("uncertain_t2.seed7.toml");
    std::fs::write(&other, text.replace("seed = 1\n", "seed = 7\n")).unwrap();
    let (s7, n7) = mc_success(&other, "uncertain_t2_mc7");
    let hi = pinfeed::statistics::wilson_interval(s7, n7)[1];
    assert!(hi >= 0.99, "seed 7: {s7} of {n7}");
}

#[test]
fn a_zero_width_uncertainty_reproduces_the_nominal_design() {
    let zero = tmp("uncertain_zero.toml");
    std::fs::write(
        &zero,
        "[uncertain.mu_c]\ndistribution = \"fixed\"\nvalue = 0.5\n\n[uncertain.fence_mu_f]\ndistribution = \"fixed\"\nvalue = 0.5\n\n[uncertain.fence_angle]\ndistribution = \"uniform\"\nmin = 0.0\nmax = 0.0\n",
    )
    .unwrap();
    let (_, nominal) = fence_design(&tmp("uncertain_nominal.toml"), &["--nominal"]);
    let (_, z) = fence_design(
        &tmp("uncertain_z.toml"),
        &["--uncertain", zero.to_str().unwrap()],
    );
    assert_eq!(z["obstacles"], nominal["obstacles"]);
    assert_eq!(z["status"], "confirmed");
    assert!(nominal["uncertain_check"].is_null());
    assert!(nominal["uncertainty"]
        .as_str()
        .unwrap()
        .starts_with("nominal physics"));
    // The zero-width study still ran, and holds the nominal line's parts as the line did.
    let (zs, ns) = (
        z["uncertain_check"]["success_rate"].as_f64().unwrap(),
        nominal["line_check"]["success_rate"].as_f64().unwrap(),
    );
    assert!(zs >= 0.99 && ns >= 0.99, "{zs} {ns}");
}

#[test]
fn the_uncertainty_flags_are_exclusive_and_a_bad_file_is_located() {
    let both = pinfeed(&["plan", "--part", "square", "--robust", "--nominal"]);
    assert_eq!(both.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&both.stderr).contains("--nominal"));
    let bad = tmp("uncertain_bad.toml");
    std::fs::write(
        &bad,
        "[uncertain.fence_angle]\ndistribution = \"uniform\"\nmin = 2.0\nmax = 1.0\n",
    )
    .unwrap();
    let out = pinfeed(&[
        "plan",
        "--part",
        "square",
        "--uncertain",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("uncertain_bad.toml:4") && err.contains("uncertain.fence_angle.max"),
        "{err}"
    );
    let missing = pinfeed(&["plan", "--part", "square", "--uncertain", "no/such.toml"]);
    assert_eq!(missing.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("no/such.toml"));
}
