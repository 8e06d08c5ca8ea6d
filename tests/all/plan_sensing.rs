//! `pinfeed plan --sensor` (the contingent planner): tripoly1 gets a sensor pin
//! and per-decision moving pins whose scenario and policy file `pinfeed run` executes unchanged
//! and that orient ≥ 95% on the line; the policy names the part; plans are deterministic for a
//! seed.

use crate::plan_cli::*;
use serde_json::Value;

fn plan(out: &str) -> Value {
    let o = pinfeed(&[
        "plan",
        "--part",
        "tripoly1",
        "--sensor",
        "--out",
        out,
        "--check-parts",
        "500",
        "--json",
    ]);
    assert!(
        [0, 3].contains(&o.status.code().unwrap()),
        "plan failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).expect("stdout is JSON")
}

#[test]
fn tripoly1_sensing_plan_runs_and_orients() {
    let out = tmp("t1.toml");
    let v = plan(out.to_str().unwrap());
    assert_eq!(v["chosen"]["search"]["result"], "found");
    let k = v["chosen"]["layout"]["contingent"]["k"].as_u64().unwrap();
    assert!((1..=3).contains(&k), "{k} moving pins");
    assert_eq!(
        v["chosen"]["layout"]["contingent"]["branches"]
            .as_array()
            .unwrap()
            .len(),
        3
    );
    assert!(v["predicted_success"].as_f64().unwrap() >= 0.99);
    let rate = v["line_check"]["success_rate"].as_f64().unwrap();
    assert!(rate >= 0.95, "line success {rate}");
    assert!(v["chosen"]["predicted_with_confusion"].as_f64().is_some());
    // The scenario and its policy file.
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("kind = \"sensor_pin\""), "{text}");
    assert!(text.contains("policy = \"t1.policy.toml\""), "{text}");
    let pol_path = out.with_file_name("t1.policy.toml");
    let pol: toml::Value = toml::from_str(&std::fs::read_to_string(&pol_path).unwrap()).unwrap();
    assert_eq!(pol["part"].as_str(), Some("tripoly1"));
    let rules = pol["rules"].as_array().unwrap();
    assert!(!rules.is_empty());
    for r in rules {
        let d = r["decides"].as_str().unwrap();
        assert!(["0°", "135°", "225°"].contains(&d), "{d}");
    }
    // The drawing beside it: one label per decision branch, a dot per moving pin target.
    let svg = std::fs::read_to_string(out.with_extension("svg")).unwrap();
    for label in ["decides 0°", "decides 135°", "decides 225°"] {
        assert!(svg.contains(label), "{label} missing from the drawing");
    }
    assert!(svg.contains("mover1") && svg.contains("sensor y="));
    // `pinfeed run` executes it unchanged.
    let s = run_300(out.to_str().unwrap());
    let rate = s["success_rate"].as_f64().unwrap();
    assert!(rate >= 0.95, "run success {rate}");
}

#[test]
fn sensing_plans_are_deterministic() {
    let a = plan(tmp("a.toml").to_str().unwrap());
    let b = plan(tmp("b.toml").to_str().unwrap());
    assert_eq!(a["chosen"]["layout"], b["chosen"]["layout"]);
    for k in ["success", "parts", "outcomes", "headway_s"] {
        assert_eq!(a["line_check"][k], b["line_check"][k], "{k}");
    }
    let pol = |f: &str| {
        std::fs::read_to_string(tmp(f))
            .unwrap()
            .lines()
            .skip(2)
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(pol("a.policy.toml"), pol("b.policy.toml"));
}

#[test]
fn sensing_plans_for_a_custom_part_run() {
    // An L-bracket in millimetres: the sensing design's scenario and policy compile and run
    // unchanged, and its policy names the part as the scenario does.
    let out = tmp("lbracket.toml");
    let o = pinfeed(&[
        "plan",
        "--part",
        "vertices:0,0 50,0 50,10 12,10 12,30 0,30",
        "--scale",
        "0.001",
        "--sensor",
        "--check-parts",
        "300",
        "--screen-parts",
        "300",
        "--refine",
        "0",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        [0, 3].contains(&o.status.code().unwrap()),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["mode"], "sensor");
    let pol = std::fs::read_to_string(out.with_file_name("lbracket.policy.toml")).unwrap();
    assert!(pol.contains("part = \"vertices\""), "{pol}");
    let s = run_300(out.to_str().unwrap());
    let line = v["line_check"]["success_rate"].as_f64().unwrap();
    assert!(s["success_rate"].as_f64().unwrap() > 0.0 && line > 0.0);
}

#[test]
fn sensing_needs_a_stable_feed() {
    let o = pinfeed(&[
        "plan", "--part", "tripoly1", "--sensor", "--feed", "uniform",
    ]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("--feed"), "{e}");
}
