//! `pinfeed plan --goal ANGLE`: the design brings the parts to the exit orientation the user
//! asked for, not one the planner chose; a goal no line can reach is not confirmed; bad goals are
//! refused with the option named.

use crate::plan_cli::{pinfeed, plan_json, tmp};
use serde_json::Value;

/// The `[goal]` orientations of a written design.
fn goal_orientations(design: &std::path::Path) -> Vec<f64> {
    let text = std::fs::read_to_string(design).unwrap();
    let v: toml::Value = toml::from_str(&text).unwrap();
    v["goal"]["sets"][0]["orientations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_float().unwrap())
        .collect()
}

fn plan_to(design: &std::path::Path, extra: &[&str]) -> (i32, Value) {
    let mut args = vec![
        "plan",
        "--nominal",
        "--part",
        "tripoly2",
        "--pins",
        "--check-parts",
        "2000",
        "--no-margins",
        "--out",
        design.to_str().unwrap(),
        "--json",
    ];
    args.extend(extra);
    plan_json(&args)
}

#[test]
fn a_goal_orientation_designs_a_line_whose_parts_exit_inside_its_window() {
    // Without a goal the planner chooses tripoly2's window; 0° is another one a pin line reaches.
    let free = tmp("goal_free.toml");
    let (_, _) = plan_to(&free, &[]);
    let chosen = goal_orientations(&free);
    assert!(
        chosen.iter().all(|c| c.abs() > 6.0),
        "{chosen:?}: pick another goal"
    );
    for (goal, centre) in [("0", 0.0), ("-360", 0.0), ("720.0", 0.0)] {
        let design = tmp(&format!("goal_{goal}.toml"));
        let (code, v) = plan_to(&design, &["--goal", goal]);
        assert_eq!(code, 0, "--goal {goal}: {}", v["message"]);
        assert_eq!(goal_orientations(&design), [centre], "--goal {goal}");
        // Run independently, with another seed: the parts exit inside the goal's window.
        let runs = tmp(&format!("goal_runs_{goal}"));
        let out = pinfeed(&[
            "run",
            design.to_str().unwrap(),
            "--parts",
            "500",
            "--seed",
            "7",
            "--json",
            "--quiet",
            "--out",
            runs.to_str().unwrap(),
        ]);
        let r: Value = serde_json::from_slice(&out.stdout).unwrap();
        let rate = r["success_rate"].as_f64().unwrap();
        assert!(
            rate >= 0.98,
            "--goal {goal}: {rate} of the parts in the window: {r}"
        );
    }
}

#[test]
fn a_goal_no_line_reaches_is_not_confirmed_and_bad_goals_are_refused() {
    let design = tmp("goal_30.toml");
    let (code, v) = plan_to(&design, &["--goal", "30", "--depth", "4"]);
    assert_eq!(v["status"], "not_confirmed", "{}", v["message"]);
    assert_eq!(code, 3);
    assert_eq!(goal_orientations(&design), [30.0]);
    for (bad, says) in [("nan", "finite angle"), ("inf", "finite angle")] {
        let out = pinfeed(&["plan", "--part", "tripoly2", "--goal", bad, "--no-write"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "--goal {bad}: {err}");
        assert!(err.contains("--goal") && err.contains(says), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let out = pinfeed(&[
        "plan",
        "--part",
        "tripoly2",
        "--goal",
        "10",
        "--fewest-sets",
        "--no-write",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--goal") && err.contains("fewest"), "{err}");
}
