//! `pinfeed plan --fences` (the fence planner): the tripoly1 fence plan orients
//! ≥ 99% on the line and runs unchanged through `pinfeed run`; the emitted fences respect the jam
//! limit (|α| + atan μf < 90°) and lie over the belt; a belt too narrow for any fence (the pin
//! planner's 10 cm) is a reported answer; plans are deterministic; `--fences` with `--sensor` allows
//! exactly those two kinds of line.

use crate::plan_cli::*;

#[test]
fn tripoly1_fence_plan_orients_the_line_and_runs() {
    let out = tmp("F.toml");
    let o = out.to_str().unwrap();
    let v = plan_ok(&[
        "plan",
        "--nominal",
        "--part",
        "tripoly1",
        "--fences",
        "--belt-width",
        "0.18",
        "--out",
        o,
        "--check-parts",
        "500",
        "--json",
    ]);
    assert_eq!(v["chosen"]["search"]["result"], "found", "{}", v["message"]);
    let steps = v["chosen"]["layout"]["sequence"]["steps"]
        .as_array()
        .unwrap();
    assert!((1..=8).contains(&steps.len()), "{} fences", steps.len());
    for s in steps {
        assert_eq!(s["action"]["kind"], "fence", "{s}");
    }
    assert!(v["predicted_success"].as_f64().unwrap() >= 0.99);
    let rate = v["line_check"]["success_rate"].as_f64().unwrap();
    assert!(rate >= 0.99, "line success {rate}");

    // The scenario: fences only, each below the jam limit and with both ends over the belt.
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.contains("pinfeed plan --part tripoly1 ")
            && text.contains(" --belt-width 0.18")
            && text.contains(" --fences"),
        "{text}"
    );
    assert_eq!(text.matches("kind = \"fence\"").count(), steps.len());
    assert_eq!(text.matches("kind = \"pin\"").count(), 0);
    let doc: toml::Value = toml::from_str(&text).expect("scenario is TOML");
    let half = doc["belt"]["width"].as_float().unwrap() / 2.0;
    let belt_len = doc["belt"]["length"].as_float().unwrap();
    let fences = doc["obstacles"].as_array().unwrap();
    let mut last_x_end = f64::NEG_INFINITY;
    for f in fences {
        let num = |k: &str| f[k].as_float().unwrap();
        let (x, y, angle, length, mu_f) =
            (num("x"), num("y"), num("angle"), num("length"), num("mu_f"));
        assert!(
            angle.abs() + mu_f.atan().to_degrees() < 90.0,
            "fence at {angle}° jams with μf {mu_f}"
        );
        assert!((15.0..=60.0).contains(&angle.abs()), "{angle}");
        let (x1, y1) = (
            x + length * angle.to_radians().cos(),
            y + length * angle.to_radians().sin(),
        );
        for yy in [y, y1] {
            assert!(
                yy.abs() <= half + 1e-9,
                "fence end y {yy} off a ±{half} belt"
            );
        }
        assert!(x > 0.0 && x1 < belt_len, "fence x {x}..{x1} off the belt");
        // One after another along the belt, with room for a part between them.
        assert!(
            x > last_x_end + 0.05,
            "fences overlap along the belt: {x} after {last_x_end}"
        );
        last_x_end = x1;
    }

    // `pinfeed run` runs it unchanged.
    let s = run_300(o);
    assert!(s["success_rate"].as_f64().unwrap() >= 0.99, "{s}");
    assert!(out.with_extension("svg").exists());
}

#[test]
fn fence_plans_are_deterministic() {
    let args = [
        "plan",
        "--part",
        "tripoly1",
        "--fences",
        "--belt-width",
        "0.18",
        "--check-parts",
        "0",
        "--no-write",
        "--json",
    ];
    let (_, a) = plan_json(&args);
    let (_, b) = plan_json(&args);
    assert_eq!(a["status"], "unchecked");
    assert_eq!(
        a["chosen"]["layout"]["sequence"]["steps"],
        b["chosen"]["layout"]["sequence"]["steps"]
    );
    assert_eq!(a["scenario"], b["scenario"]);
}

#[test]
fn a_belt_too_narrow_for_any_fence_is_an_answer() {
    let (code, v) = plan_json(&[
        "plan",
        "--part",
        "tripoly1",
        "--fences",
        "--belt-width",
        "0.1",
        "--check-parts",
        "0",
        "--no-write",
        "--json",
    ]);
    // No fence sequence reaches the goal on it: the best effort is the answer, reported as such.
    assert_eq!(code, 3, "{v}");
    assert_eq!(v["status"], "unchecked", "{v}");
    assert_eq!(v["chosen"]["search"]["result"], "exhausted", "{v}");
}

#[test]
fn fences_and_sensor_allow_exactly_those_kinds_of_line() {
    let (_, v) = plan_json(&[
        "plan",
        "--part",
        "tripoly1",
        "--fences",
        "--sensor",
        "--check-parts",
        "0",
        "--no-write",
        "--json",
    ]);
    for c in v["candidates"].as_array().unwrap() {
        let m = c["mode"].as_str().unwrap();
        assert!(m == "fences" || m == "sensor", "{m}");
    }
}
