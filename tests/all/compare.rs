//! `pinfeed compare`: several designs for one part, each on its own feed, one row each, the same
//! row whatever the order of the files, the same JSON byte for byte on every run; scenarios for
//! another part are refused.

use crate::support::pinfeed;
use serde_json::Value;

fn scenario(name: &str) -> String {
    format!("{}/scenarios/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn pins_and_fences_on_one_part_stream() {
    let (pins, fences) = (
        scenario("quickstart.toml"),
        scenario("tripoly2_fences.toml"),
    );
    let args = ["compare", &pins, &fences, "--parts", "40", "--json"];
    let a = pinfeed(&args);
    assert!(a.status.success(), "{}", String::from_utf8_lossy(&a.stderr));
    let b = pinfeed(&args);
    assert_eq!(a.stdout, b.stdout, "compare --json differs between runs");
    let doc: Value = serde_json::from_slice(&a.stdout).unwrap();
    assert_eq!(doc["schema_version"], pinfeed::SCHEMA_VERSION);
    assert_eq!(doc["pinfeed_version"], pinfeed::PINFEED_VERSION);
    let rows = doc["designs"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["scenario"], "quickstart");
    assert_eq!(rows[1]["scenario"], "tripoly2_fences");
    assert_eq!(
        (rows[0]["pins"].clone(), rows[0]["fences"].clone()),
        (3.into(), 0.into())
    );
    assert_eq!(
        (rows[1]["pins"].clone(), rows[1]["fences"].clone()),
        (0.into(), 3.into())
    );
    for r in rows {
        assert_eq!(r["parts_in"], 40);
        assert_eq!(r["seed"], 1);
        let total: u64 = r["outcomes"]
            .as_object()
            .unwrap()
            .values()
            .map(|v| v.as_u64().unwrap())
            .sum();
        assert_eq!(total, 40);
        let [lo, hi] = [
            r["success_ci95"][0].as_f64().unwrap(),
            r["success_ci95"][1].as_f64().unwrap(),
        ];
        let rate = r["success_rate"].as_f64().unwrap();
        assert!(lo <= rate && rate <= hi, "{r}");
        // Footprint: obstacle span along the belt plus the part's length (tripoly2's hypotenuse).
        let span = &r["obstacle_span_m"];
        let length = 0.02 * 5f64.sqrt();
        let expect = span[1].as_f64().unwrap() - span[0].as_f64().unwrap() + length;
        assert!(
            (r["footprint_m"].as_f64().unwrap() - expect).abs() < 1e-12,
            "{r}"
        );
        assert!(
            r["latency_p99_s"].as_f64().unwrap() >= r["latency_mean_s"].as_f64().unwrap() - 0.05
        );
    }
    // The quickstart's pins span x = 0.148 … 0.452 m.
    assert!((rows[0]["footprint_m"].as_f64().unwrap() - (0.304 + 0.02 * 5f64.sqrt())).abs() < 1e-9);

    // The table has one row per scenario and names the part stream.
    let t = pinfeed(&["compare", &pins, &fences, "--parts", "40"]);
    assert!(t.status.success());
    let text = String::from_utf8_lossy(&t.stdout);
    assert!(text.starts_with("every design's part stream: "), "{text}");
    assert!(
        text.contains("seed 1, 40 parts (--parts), one every 4 s,"),
        "{text}"
    );
    assert_eq!(
        text.lines()
            .filter(|l| l.starts_with("quickstart "))
            .count(),
        1,
        "{text}"
    );
    assert_eq!(
        text.lines()
            .filter(|l| l.starts_with("tripoly2_fences "))
            .count(),
        1,
        "{text}"
    );
}

fn compare_json(args: &[&str]) -> Vec<Value> {
    let doc: Value = crate::support::pinfeed_json(args);
    doc["designs"].as_array().unwrap().clone()
}

/// Issue 57 item 1: each design runs at its own headway, so its row is the same in either order
/// (the quickstart at 4 s, the crowded belt at 2 s, where parts collide), and every outcome that
/// happened shows in the table, not only jams.
#[test]
fn compare_reports_the_same_numbers_per_design_in_either_order() {
    let (a, b) = (scenario("quickstart.toml"), scenario("crowded_belt.toml"));
    let ab = compare_json(&["compare", &a, &b, "--parts", "100", "--json"]);
    let ba = compare_json(&["compare", &b, &a, "--parts", "100", "--json"]);
    assert_eq!(ab[0], ba[1], "the quickstart's row depends on the order");
    assert_eq!(ab[1], ba[0], "the crowded belt's row depends on the order");
    assert_eq!(ab[0]["headway_s"], 4.0);
    assert_eq!(ab[1]["headway_s"], 2.0);
    assert!(
        ab[1]["outcomes"]["collision"].as_u64().unwrap() > 0,
        "{}",
        ab[1]
    );
    assert_eq!(ab[0]["outcomes"]["collision"], 0);

    let out = crate::support::pinfeed_ok(&["compare", &b, &a, "--parts", "100"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("other outcomes"), "{text}");
    let row = text
        .lines()
        .find(|l| l.starts_with("crowded_belt "))
        .unwrap();
    let collisions = ab[1]["outcomes"]["collision"].to_string();
    assert!(
        row.contains(&format!("{collisions} collision")),
        "the collisions are not in the table: {text}"
    );
    // The feeds differ (their headways): the header gives each.
    assert!(
        text.contains("one every 2 s,") && text.contains("one every 4 s,"),
        "{text}"
    );
}

/// `--headway` (like `--seed`, `--parts` and `--uniform-orientation`) imposes one value on every
/// design, and the header says so.
#[test]
fn a_named_headway_applies_to_every_design_and_is_said() {
    let (a, b) = (scenario("quickstart.toml"), scenario("crowded_belt.toml"));
    let rows = compare_json(&[
        "compare",
        &a,
        &b,
        "--parts",
        "100",
        "--headway",
        "2",
        "--json",
    ]);
    assert_eq!(rows[0]["headway_s"], 2.0);
    // The same feed and seed: the same parts, the same collisions.
    assert_eq!(rows[0]["outcomes"], rows[1]["outcomes"]);
    assert!(rows[0]["outcomes"]["collision"].as_u64().unwrap() > 0);
    let out = crate::support::pinfeed_ok(&["compare", &a, &b, "--parts", "10", "--headway", "2"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.starts_with("every design's part stream: ")
            && text.contains("one every 2 s (--headway)"),
        "{text}"
    );
    let uniform = compare_json(&[
        "compare",
        &a,
        &b,
        "--parts",
        "30",
        "--uniform-orientation",
        "--seed",
        "5",
        "--json",
    ]);
    for r in &uniform {
        assert_eq!(
            (r["seed"].clone(), r["parts_in"].clone()),
            (5.into(), 30.into())
        );
    }
    let bad = pinfeed(&["compare", &a, "--headway", "0"]);
    assert_eq!(bad.status.code(), Some(1));
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("--headway must lie in [0.000001, 1000000] s, got 0"),
        "{err}"
    );
}

/// Obstacles are named by kind, not all counted as pins.
#[test]
fn compare_names_obstacles_by_kind() {
    let online = scenario("tripoly1_online.toml");
    let rows = compare_json(&["compare", &online, "--parts", "2", "--json"]);
    assert_eq!(
        rows[0]["obstacle_kinds"],
        serde_json::json!({"fixed_pins": 2, "sensor_pins": 1, "moving_pins": 1, "retractable_pins": 0, "fences": 0})
    );
    let out = crate::support::pinfeed_ok(&["compare", &online, "--parts", "2"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains(" 1 sensor pin + 1 moving pin + 2 pins "),
        "{text}"
    );
}

#[test]
fn a_scenario_with_another_part_is_refused() {
    let out = pinfeed(&[
        "compare",
        &scenario("quickstart.toml"),
        &scenario("tripoly1.toml"),
        "--parts",
        "10",
    ]);
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("tripoly1.toml cannot run on the part stream of"),
        "{err}"
    );
    assert!(err.contains("same shape, scale and support"), "{err}");
}

#[test]
fn compare_shows_progress_on_a_terminal_and_nothing_otherwise() {
    let (pins, fences) = (
        scenario("quickstart.toml"),
        scenario("tripoly2_fences.toml"),
    );
    let args = ["compare", &pins, &fences, "--parts", "600"];
    let out = pinfeed(&args);
    assert!(out.status.success());
    assert!(
        !String::from_utf8_lossy(&out.stderr).contains("/1200 parts"),
        "no progress when standard error is not a terminal"
    );
    let log = std::env::temp_dir().join(format!("pinfeed-compare-{}.tty", std::process::id()));
    let Some(text) = crate::support::pinfeed_on_terminal(&args, &log) else {
        return;
    };
    assert!(text.contains("/1200 parts"), "{text}");
    assert!(
        text.contains("success (95% CI)"),
        "the table follows: {text}"
    );
    let quiet = [&args[..], &["--quiet"]].concat();
    let text = crate::support::pinfeed_on_terminal(&quiet, &log).unwrap();
    assert!(
        !text.contains("/1200 parts"),
        "--quiet draws nothing: {text}"
    );
}

/// Each design's goal stands beside its success: designs measured against different windows (or
/// none) say so, in the table, in Markdown and in the JSON.
#[test]
fn each_design_shows_its_goal() {
    let pins = scenario("tripoly1_pins_compact.toml");
    let fences = scenario("tripoly1_fences.toml");
    // The compact pins' scenario with every exiting part counted.
    let text = std::fs::read_to_string(&pins).unwrap();
    let goal = text.find("[goal]").unwrap();
    let end = goal + text[goal..].find("\n\n").unwrap();
    let any = format!("{}[goal]\nany = true{}", &text[..goal], &text[end..])
        .replace("name = \"tripoly1_pins_compact\"", "name = \"every_exit\"");
    let any_file =
        std::env::temp_dir().join(format!("pinfeed-compare-any-{}.toml", std::process::id()));
    std::fs::write(&any_file, any).unwrap();
    let any_path = any_file.to_str().unwrap();

    let doc: Value = crate::support::pinfeed_json(&[
        "compare", &pins, &fences, any_path, "--parts", "20", "--json",
    ]);
    let rows = doc["designs"].as_array().unwrap();
    assert_eq!(
        rows[0]["goal"],
        serde_json::json!([{"name": "apex-forward-left", "orientations_deg": [305.0], "tolerance_deg": 3.0}])
    );
    assert_eq!(
        rows[1]["goal"],
        serde_json::json!([{"name": "hypotenuse-down", "orientations_deg": [6.6], "tolerance_deg": 3.0}])
    );
    assert_eq!(rows[2]["goal"], serde_json::json!([]));

    for format in [None, Some("--markdown")] {
        let mut args = vec!["compare", &pins, &fences, any_path, "--parts", "20"];
        args.extend(format);
        let out = crate::support::pinfeed_ok(&args);
        let text = String::from_utf8_lossy(&out.stdout);
        let header = text
            .lines()
            .nth(if format.is_some() { 2 } else { 1 })
            .unwrap();
        assert!(header.contains("goal"), "{text}");
        let row = |name: &str| {
            text.lines()
                .find(|l| l.trim_start_matches("| ").starts_with(name))
                .unwrap_or_else(|| panic!("no row {name}: {text}"))
                .to_string()
        };
        assert!(
            row("tripoly1_pins_compact").contains("apex-forward-left 305° ± 3°"),
            "{text}"
        );
        assert!(
            row("tripoly1_fences").contains("hypotenuse-down 6.6° ± 3°"),
            "{text}"
        );
        assert!(row("every_exit").contains("any exit"), "{text}");
    }
}
