//! Sensor pins in scenarios and in the line: bad sensor settings are located errors; the bundled
//! sensor scene runs, reports its readings and is reproducible; a passive scene does no sensing
//! work at all (the `work` counters prove it).

use pinfeed::engine::{run, RunOptions};
use pinfeed::scenario::{parse, InvalidScenario, Scene};
use std::path::Path;

const SCENE: &str = include_str!("../../scenarios/tripoly1_sensor.toml");

fn compile(src: &str) -> Result<Scene, InvalidScenario> {
    parse(Path::new("sensor.toml"), src).map_err(|e| e.invalid().expect("located error").clone())
}

/// The bundled scene with `old` replaced by `new` must be refused at `key` (line of `new`).
fn refused(old: &str, new: &str, key: &str, words: &[&str]) {
    assert!(SCENE.contains(old), "the scene has no '{old}'");
    let src = SCENE.replacen(old, new, 1);
    let e = match compile(&src) {
        Ok(_) => panic!("accepted with {new}"),
        Err(e) => e,
    };
    assert_eq!(e.key, key, "{new}: {e}");
    // The line of the key at fault: the line of `new` that sets it (or the table's header).
    let last = key.rsplit('.').next().unwrap();
    let wanted = new
        .lines()
        .find(|l| l.trim_start().starts_with(&format!("{last} =")))
        .unwrap_or_else(|| new.lines().next().unwrap());
    let wanted = if last == "sensor" {
        "[obstacles.sensor]"
    } else {
        wanted
    };
    let line = src.lines().position(|l| l.contains(wanted)).unwrap() + 1;
    assert_eq!(e.line, line, "{new}: {e}");
    for w in words {
        assert!(
            e.message.contains(w),
            "{new}: expected '{w}' in {}",
            e.message
        );
    }
}

#[test]
fn bad_sensor_settings_are_located_errors() {
    let s = "obstacles[0].sensor";
    refused("rate = 1000 ", "rate = 0 ", &format!("{s}.rate"), &["Hz"]);
    refused("rate = 1000 ", "rate = -5 ", &format!("{s}.rate"), &["Hz"]);
    refused(
        "rate = 1000 ",
        "rate = nan ",
        &format!("{s}.rate"),
        &["got NaN"],
    );
    refused(
        "height = 0.02 ",
        "height = -0.01 ",
        &format!("{s}.height"),
        &["m"],
    );
    refused(
        "rate = 1000 ",
        "noise_force = -0.1\nrate = 1000 ",
        &format!("{s}.noise_force"),
        &["≥ 0"],
    );
    refused(
        "type = \"ft\"",
        "type = \"timing\"\nthreshold = 0",
        &format!("{s}.threshold"),
        &["N"],
    );
    refused(
        "classifier = \"likelihood\"",
        "classifier = \"magic\"",
        &format!("{s}.classifier"),
        &["unknown classifier 'magic'", "likelihood", "sign-matrix"],
    );
    refused(
        "templates = 32 ",
        "templates = 0 ",
        &format!("{s}.templates"),
        &["[1, 1024]"],
    );
    refused(
        "templates = 32 ",
        "templates = 32\nhypotheses = [0, 135, -225]",
        &format!("{s}.hypotheses"),
        &["same angle"],
    );
    refused(
        "templates = 32 ",
        "templates = 32\nhypotheses = [0, 400]",
        &format!("{s}.hypotheses"),
        &["[-360, 360]"],
    );
    refused(
        "templates = 32 ",
        "templates = 32\nhypotheses = \"some\"",
        &format!("{s}.hypotheses"),
        &["stable", "vertex-edge"],
    );
    refused(
        "classifier = \"likelihood\"",
        "classifier = \"zero-crossings\"",
        &format!("{s}.classifier"),
        &["vertex-edge"],
    );
    refused(
        "type = \"ft\"",
        "type = \"sonar\"",
        &format!("{s}.type"),
        &["ft", "timing"],
    );
    refused("mass = 0.05 ", "mass = -1 ", "part.mass", &["kg"]);
    // A sensor table on a plain pin.
    refused(
        "kind = \"sensor_pin\"",
        "kind = \"pin\"",
        s,
        &["sensor_pin"],
    );
}

/// The bundled sensor scene: every part that reaches the probe is read, the confusion matrix holds
/// every reading, and the same seed gives the same summary.
#[test]
fn sensor_scene_reads_every_part_and_is_reproducible() {
    let scene = compile(SCENE).expect("the bundled sensor scene compiles");
    let opts = RunOptions {
        parts: 60,
        ..RunOptions::from_scene(&scene)
    };
    let a = run(&scene, &opts, &mut |_| {}).unwrap();
    let b = run(&scene, &opts, &mut |_| {}).unwrap();
    assert_eq!(a.summary, b.summary);
    let s = &a.summary.sensors;
    assert_eq!(s.len(), 1);
    let probe = &s[0];
    assert_eq!(probe.readings + probe.untouched, 60);
    assert!(probe.readings >= 55, "{probe:?}");
    assert_eq!(probe.confusion.total() + probe.unmatched, probe.readings);
    assert_eq!(
        probe.unmatched, 0,
        "every stable-state reading has a nearest state"
    );
    assert_eq!(a.summary.work.sensor_readings, probe.readings);
    assert_eq!(a.summary.work.classifications, probe.readings);
    assert!(a.summary.work.signal_knots >= 5 * probe.readings);
    // The probe tells 225° from the other two (the thesis's finding at d < 0): that row is right.
    let k = probe
        .confusion
        .labels
        .iter()
        .position(|l| l == "225°")
        .unwrap();
    let row = &probe.confusion.counts[k];
    let n: u64 = row.iter().sum();
    assert!(n > 0 && row[k] * 10 >= n * 9, "225° row {row:?}");
}

/// A scene without sensor pins does no sensing work: the counters stay zero, and its summary JSON
/// carries no `sensors` key (reports of passive scenes are unchanged).
#[test]
fn passive_scene_pays_nothing_for_sensing() {
    let quick = include_str!("../../scenarios/quickstart.toml");
    let scene = parse(Path::new("quickstart.toml"), quick).unwrap();
    let opts = RunOptions {
        parts: 40,
        ..RunOptions::from_scene(&scene)
    };
    let r = run(&scene, &opts, &mut |_| {}).unwrap();
    assert!(r.summary.work.contact_solves > 0);
    assert_eq!(r.summary.work.sensor_readings, 0);
    assert_eq!(r.summary.work.signal_knots, 0);
    assert_eq!(r.summary.work.classifications, 0);
    assert!(r.summary.sensors.is_empty());
    let json = serde_json::to_string(&r.summary).unwrap();
    assert!(!json.contains("\"sensors\""));
}

/// The sensor pin pushes exactly as a plain pin at the same place: sensing observes only.
#[test]
fn a_sensor_pin_pushes_like_a_plain_pin() {
    let sensed = compile(SCENE).unwrap();
    let plain_src = SCENE
        .replace("kind = \"sensor_pin\"", "kind = \"pin\"")
        .split("[obstacles.sensor]")
        .next()
        .unwrap()
        .to_string()
        + "\n[goal]\nany = true\n";
    let plain = compile(&plain_src).expect("plain variant compiles");
    let opts = RunOptions {
        parts: 30,
        keep_records: true,
        ..RunOptions::from_scene(&sensed)
    };
    let a = run(&sensed, &opts, &mut |_| {}).unwrap();
    let b = run(&plain, &opts, &mut |_| {}).unwrap();
    assert_eq!(a.records.len(), b.records.len());
    for (x, y) in a.records.iter().zip(&b.records) {
        assert_eq!(x.theta_out_deg, y.theta_out_deg);
        assert_eq!(x.y_out_m, y.y_out_m);
        assert_eq!(x.outcome, y.outcome);
        assert_eq!(x.sensed.len(), 1, "{:?}", x.sensed);
        assert_eq!(x.sensed[0].sensor, "probe");
        assert!(x.sensed[0].to_string().starts_with("probe="));
        assert!(y.sensed.is_empty());
    }
    assert_eq!(a.summary.outcomes, b.summary.outcomes);
    assert_eq!(a.summary.work.contact_solves, b.summary.work.contact_solves);
}
