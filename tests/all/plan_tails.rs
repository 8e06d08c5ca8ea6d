//! Fence designs with curved tails (docs/commands.md, "Curved tails"): `--tail-max`, its
//! located errors, and a symmetric part on random tripods oriented modulo its outline's symmetry.

use crate::plan_cli::{pinfeed, quick_fence_design, tmp};

/// A square on random tripods with friction anywhere in [0.3, 0.7] (`--robust`) is still a
/// square to the next station: one fence brings every sample into one ±3° window modulo 90°,
/// and the scenario's goal lists the four orientations a quarter turn apart. (Were the tripod
/// taken to break the symmetry, no fence line could tell a square's four quarter turns apart and
/// at most a quarter of the parts would count: the planted bug fails here.)
#[test]
fn a_square_on_random_tripods_is_oriented_modulo_its_outline_s_symmetry() {
    let file = tmp("tails_square.toml");
    let (code, v) = quick_fence_design("square", &file, &["--robust"]);
    assert_eq!(code, 0, "{}", v["message"]);
    let u = &v["uncertain_check"];
    assert!(u["success_rate"].as_f64().unwrap() >= 0.99, "{u}");
    assert!(v["uncertainty"].as_str().unwrap().contains("tripod"));
    let text = std::fs::read_to_string(&file).unwrap();
    let goal = text
        .lines()
        .find(|l| l.starts_with("orientations"))
        .unwrap_or_else(|| panic!("no goal orientations in {text}"));
    let angles: Vec<f64> = goal
        .split(['[', ']'])
        .nth(1)
        .unwrap()
        .split(',')
        .map(|t| t.trim().parse().unwrap())
        .collect();
    assert_eq!(angles.len(), 4, "{goal}");
    for w in angles.windows(2) {
        assert!((w[1] - w[0] - 90.0).abs() < 1e-3, "{goal}");
    }
}

/// A tail radius outside [4a, 1000a] (0 turns tails off) is refused before any search, naming
/// the flag's field and its range.
#[test]
fn a_bad_tail_radius_is_a_located_error() {
    for bad in ["2", "-5", "1e9", "NaN"] {
        let out = pinfeed(&[
            "plan",
            "--part",
            "square",
            "--fences",
            "--tail-max",
            bad,
            "--no-write",
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "--tail-max {bad}: {err}");
        assert!(
            err.contains("--tail-max") && err.contains("[4, 1000]"),
            "--tail-max {bad}: {err}"
        );
    }
}
