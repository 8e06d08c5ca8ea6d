//! Monte Carlo studies with sensor pins: the sensor parameters parse, describe
//! themselves and are refused with a location when out of range or when the scenario has no
//! sensor pin; each sample perturbs every sensor pin's settings and keeps its trained classifier;
//! a sensor pin is a pin for the pin errors; the report carries the sensors' accuracy, which falls
//! as the noise factor grows, and merges exactly from shards; a study without sensor parameters
//! writes the same bytes as before sensor parameters existed.

use crate::support::{assert_success, pinfeed_in};
use pinfeed::scenario::scene::{Obstacle, PinObstacle};
use pinfeed::study::mc::{self, sample};
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::Arc;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn sensor_scenario() -> String {
    format!("{ROOT}/tests/fixtures/scenarios/sensor_pin.toml")
}

fn fixture(name: &str) -> String {
    format!("{ROOT}/tests/fixtures/studies/{name}")
}

/// A fresh, empty folder for one test.
fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinfeed-mc-sensing-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A study of the sensor-pin fixture with `body` after its `scenario` line.
fn write_study(dir: &Path, body: &str) -> PathBuf {
    let p = dir.join("study.toml");
    std::fs::write(&p, format!("scenario = \"{}\"\n{body}", sensor_scenario())).unwrap();
    p
}

/// `pinfeed ARGS` run from the crate's root (so relative paths in reports are the committed ones)
/// must succeed; returns its output.
fn ok(args: &[&str]) -> Output {
    assert_success(args, pinfeed_in(ROOT, args))
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The only pin of a scene (the fixture has one: the sensor pin `probe`).
fn the_pin(obstacles: &[Obstacle]) -> &PinObstacle {
    match obstacles {
        [Obstacle::Pin(p)] => p,
        other => panic!("expected one pin, got {other:?}"),
    }
}

#[test]
fn a_study_without_sensor_parameters_writes_the_bytes_it_wrote_before() {
    // Every parameter there was before sensors, on a 3 × 2 grid: the report committed beside the
    // study was written by pinfeed before sensor parameters existed.
    let d = tmp("golden");
    ok(&[
        "mc",
        "tests/fixtures/studies/every_parameter.toml",
        "--quiet",
        "--out",
        s(&d.join("grid")),
    ]);
    for f in ["report.json", "report.md"] {
        let want = std::fs::read_to_string(fixture(&format!("every_parameter.{f}"))).unwrap();
        // The report names the folder it was written to; the fixture has it as `OUT`.
        let got = std::fs::read_to_string(d.join("grid").join(f))
            .unwrap()
            .replace(s(&d.join("grid")), "OUT");
        assert!(want == got, "{f} changed:\n{got}");
    }
    // The bundled quickstart study gives the same bytes on one thread and on two (nothing of the
    // report depends on the schedule), and its report names the folder it was written to.
    let mut runs = Vec::new();
    for threads in ["1", "2"] {
        let _ = std::fs::remove_dir_all(d.join("mu"));
        ok(&[
            "mc",
            "studies/quickstart_mu_tripod.toml",
            "--samples",
            "300",
            "--threads",
            threads,
            "--quiet",
            "--out",
            s(&d.join("mu")),
        ]);
        let files: Vec<Vec<u8>> = ["report.json", "report.md", "sensitivity.svg"]
            .iter()
            .map(|f| std::fs::read(d.join("mu").join(f)).unwrap())
            .collect();
        runs.push(files);
    }
    assert!(runs[0] == runs[1], "the report depends on the thread count");
    let md = String::from_utf8(runs[0][1].clone()).unwrap();
    assert!(
        md.contains(&format!(
            "mc studies/quickstart_mu_tripod.toml --samples 300 --out {}",
            d.join("mu").display()
        )),
        "{md}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn sensor_parameters_parse_and_describe_themselves() {
    let d = tmp("parse");
    let p = write_study(
        &d,
        r#"
samples = 3
[uncertain.sensor_noise]
distribution = "uniform"
min = 0.5
max = 2.0
[uncertain.sensor_bias]
distribution = "normal"
sd = 0.01
[uncertain.sensor_threshold]
distribution = "triangular"
min = 0.03
mode = 0.05
max = 0.1
[uncertain.sensor_jitter]
distribution = "normal"
mean = 0.0
sd = 0.0005
[[sweep]]
parameter = "sensor_noise.max"
values = [1.0, 4.0]
"#,
    );
    let st = mc::load(&p, None).unwrap();
    let text = st.declared.describe().join("\n");
    for w in [
        "sensor_noise: uniform [0.5, 2]",
        "sensor_bias: normal (mean 0, sd 0.01) N added to the force bias",
        "sensor_threshold: triangular [0.03, 0.1] with mode 0.05 N",
        "sensor_jitter: normal (mean 0, sd 0.0005) s added",
    ] {
        assert!(text.contains(w), "no '{w}' in:\n{text}");
    }
    assert_eq!(st.points.len(), 2);
    assert!(st.points.iter().all(|p| p.perturbs_sensors()));
    std::fs::remove_dir_all(&d).unwrap();
}

/// `pinfeed mc FIXTURE` fails with `FILE:LINE:COLUMN: key `KEY`: ...` containing every word.
fn assert_located(name: &str, line: usize, column: usize, key: &str, words: &[&str]) {
    let d = tmp(&format!("bad-{name}"));
    let out = pinfeed_in(ROOT, &["mc", &fixture(name), "--out", s(&d)]);
    let e = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(1), "{name}: {e}");
    assert!(out.stdout.is_empty(), "{name} printed a result");
    assert!(!e.contains("panicked"), "{name} panicked: {e}");
    let head = format!("{name}:{line}:{column}: key `{key}`: ");
    assert!(e.contains(&head), "{name}: expected '{head}' in:\n{e}");
    for w in words {
        assert!(e.contains(w), "{name}: expected '{w}' in:\n{e}");
    }
    assert!(
        e.contains(&format!("{line} | ")),
        "{name}: no excerpt:\n{e}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn out_of_range_sensor_parameters_are_located_errors() {
    assert_located(
        "sensor_noise_negative.toml",
        7,
        7,
        "uncertain.sensor_noise.min",
        &["sensor_noise must be at least 0", "-0.5"],
    );
    assert_located(
        "sensor_threshold_zero.toml",
        7,
        9,
        "uncertain.sensor_threshold.value",
        &["sensor_threshold must be at least 1e-9", "got 0"],
    );
    assert_located(
        "sensor_jitter_sweep_bad.toml",
        9,
        1,
        "sweep[0]",
        &["at sensor_jitter = 20", "at most 10"],
    );
}

#[test]
fn sensor_parameters_need_a_sensor_pin() {
    assert_located(
        "sensor_without_sensor_pin.toml",
        10,
        1,
        "uncertain.sensor_bias",
        &["the scenario has no sensor pin"],
    );
    assert_located(
        "sensor_sweep_without_sensor_pin.toml",
        6,
        13,
        "sweep[0].parameter",
        &["sensor_noise", "the scenario has no sensor pin"],
    );
}

#[test]
fn every_sample_perturbs_the_sensor_settings_and_keeps_the_classifier() {
    let d = tmp("apply");
    let p = write_study(
        &d,
        r#"
samples = 4
[uncertain.sensor_noise]
distribution = "fixed"
value = 3.0
[uncertain.sensor_bias]
distribution = "fixed"
value = 0.02
[uncertain.sensor_threshold]
distribution = "fixed"
value = 0.08
[uncertain.sensor_jitter]
distribution = "fixed"
value = 0.0005
"#,
    );
    let st = mc::load(&p, None).unwrap();
    let base = the_pin(&st.scene.obstacles);
    let b = base
        .sensor
        .as_ref()
        .expect("the fixture's pin has a sensor");
    for i in 0..4 {
        let ds = sample::draw_scene(&st.scene, &st.points[0], st.seed, i).unwrap();
        let pin = the_pin(&ds.scene.obstacles);
        let sensor = pin.sensor.as_ref().expect("the sensor is kept");
        let (got, nominal) = (&sensor.settings, &b.settings);
        // Errors first, then the factor on the noise figures.
        assert_eq!(got.noise_force, nominal.noise_force * 3.0);
        assert_eq!(got.noise_torque, nominal.noise_torque * 3.0);
        assert_eq!(got.jitter, (nominal.jitter + 0.0005) * 3.0);
        assert_eq!(got.bias_force, nominal.bias_force + 0.02);
        assert_eq!(
            got.bias_torque, nominal.bias_torque,
            "torque bias unchanged"
        );
        assert_eq!(got.threshold, 0.08);
        // Everything else is the scenario's: rate, height, resolution, drift.
        assert_eq!(got.rate, nominal.rate);
        assert_eq!(got.height, nominal.height);
        assert_eq!(got.resolution_force, nominal.resolution_force);
        assert_eq!(got.drift_force, nominal.drift_force);
        // The same trained classifier (shared, not retrained).
        assert!(Arc::ptr_eq(&sensor.classifier, &b.classifier));
        assert_eq!(sensor.labels, b.labels);
        assert_eq!(sensor.hypotheses, b.hypotheses);
        // Samples of a sensor line draw their readings from streams of their own.
        assert_ne!(ds.run_seed, 0);
    }
    let seeds: Vec<u64> = (0..4)
        .map(|i| {
            sample::draw_scene(&st.scene, &st.points[0], st.seed, i)
                .unwrap()
                .run_seed
        })
        .collect();
    assert!(seeds.windows(2).all(|w| w[0] != w[1]), "{seeds:?}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_negative_jitter_is_redrawn_and_an_impossible_one_reported() {
    let d = tmp("jitter");
    // The fixture's jitter is 1 ms: errors below −1 ms are redrawn (and counted).
    let p = write_study(
        &d,
        "samples = 40\n[uncertain.sensor_jitter]\ndistribution = \"uniform\"\nmin = -0.003\nmax = 0.003\n",
    );
    let st = mc::load(&p, None).unwrap();
    let mut redraws = 0;
    for i in 0..40 {
        let ds = sample::draw_scene(&st.scene, &st.points[0], st.seed, i).unwrap();
        let j = the_pin(&ds.scene.obstacles)
            .sensor
            .as_ref()
            .unwrap()
            .settings
            .jitter;
        assert!((0.0..=0.004).contains(&j), "jitter {j}");
        redraws += ds.other_redraws;
    }
    assert!(redraws > 0);
    // A fixed error of −0.5 s can never give a jitter ≥ 0: a clear error naming the parameter.
    let p = write_study(
        &d,
        "samples = 4\n[uncertain.sensor_jitter]\ndistribution = \"fixed\"\nvalue = -0.5\n",
    );
    let e = mc::load(&p, None)
        .expect_err("refused when read")
        .to_string();
    assert!(
        e.contains("key `uncertain.sensor_jitter`: no valid sample can be drawn on this scenario: sensor_jitter: "),
        "{e}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn sensor_pins_are_perturbed_like_other_pins_and_keep_their_sensor() {
    let d = tmp("pins");
    let p = write_study(
        &d,
        r#"
samples = 4
[uncertain.pin_x]
distribution = "fixed"
value = 0.002
[uncertain.pin_y]
distribution = "fixed"
value = -0.001
[uncertain.pin_radius]
distribution = "fixed"
value = 0.0005
"#,
    );
    let st = mc::load(&p, None).unwrap();
    let base = the_pin(&st.scene.obstacles);
    let ds = sample::draw_scene(&st.scene, &st.points[0], st.seed, 0).unwrap();
    let pin = the_pin(&ds.scene.obstacles);
    assert!((pin.centre.x - (base.centre.x + 0.002)).abs() < 1e-15);
    assert!((pin.centre.y - (base.centre.y - 0.001)).abs() < 1e-15);
    assert!((pin.radius - (base.radius + 0.0005)).abs() < 1e-15);
    // Without sensor parameters the very same sensor (settings and classifier) rides along.
    let (a, b) = (pin.sensor.as_ref().unwrap(), base.sensor.as_ref().unwrap());
    assert!(Arc::ptr_eq(a, b));
    // Random errors move it too, differently per sample.
    let p = write_study(
        &d,
        "samples = 4\n[uncertain.pin_y]\ndistribution = \"normal\"\nsd = 0.001\n",
    );
    let st = mc::load(&p, None).unwrap();
    let ys: Vec<f64> = (0..4)
        .map(|i| {
            let ds = sample::draw_scene(&st.scene, &st.points[0], st.seed, i).unwrap();
            let pin = the_pin(&ds.scene.obstacles);
            assert!(pin.sensor.is_some());
            pin.centre.y
        })
        .collect();
    assert!(ys.iter().all(|&y| y != base.centre.y), "{ys:?}");
    assert!(ys.windows(2).all(|w| w[0] != w[1]), "{ys:?}");
    std::fs::remove_dir_all(&d).unwrap();
}

/// A noise sweep on the sensor line, 150 samples per point.
const NOISE_SWEEP: &str = r#"
name = "noise"
samples = 150
[uncertain.pin_y]
distribution = "normal"
sd = 0.0003
[[sweep]]
parameter = "sensor_noise"
values = [0.0, 1000.0]
"#;

#[test]
fn the_noise_factor_moves_the_sensor_accuracy_the_right_way() {
    let d = tmp("noise");
    let p = write_study(&d, NOISE_SWEEP);
    let out = ok(&["mc", s(&p), "--json", "--quiet", "--out", s(&d.join("o"))]);
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["sensors"][0], "probe (likelihood, ft)", "{r}");
    let acc = |j: usize| {
        let sn = &r["results"][j]["sensor"];
        assert_eq!(sn["readings"], 150, "every sample is read once: {sn}");
        sn["accuracy"].as_f64().unwrap()
    };
    let (quiet, loud) = (acc(0), acc(1));
    // An ideal sensor tells the three stable states apart; 1000 × the Nano's noise (σ 12.5 N
    // against a push of about 0.15 N) leaves the classifier guessing.
    assert!(quiet >= 0.9, "accuracy without noise {quiet}");
    assert!(loud < quiet - 0.25, "accuracy {quiet} → {loud}");
    let ci = &r["results"][1]["sensor"]["ci95"];
    assert!(ci[0].as_f64().unwrap() <= loud && loud <= ci[1].as_f64().unwrap());
    // The table shows it as well.
    let md = std::fs::read_to_string(d.join("o/report.md")).unwrap();
    assert!(md.contains("sensor accuracy % [95% CI]"), "{md}");
    assert!(md.contains("Sensor pins: probe (likelihood, ft)"), "{md}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn sensor_counts_merge_exactly_from_shards() {
    let d = tmp("shards");
    let p = write_study(&d, &NOISE_SWEEP.replace("samples = 150", "samples = 20"));
    let full = d.join("full");
    let one = ok(&["mc", s(&p), "--json", "--quiet", "--out", s(&full)]);
    let shards = d.join("shards");
    for k in 0..3 {
        ok(&[
            "mc",
            s(&p),
            "--shard",
            &format!("{k}/3"),
            "--out",
            s(&shards),
            "--quiet",
        ]);
    }
    let text = std::fs::read_to_string(shards.join("shard-0001-of-0003.json")).unwrap();
    assert!(text.contains("\"sensor_readings\""), "{text}");
    let merged = d.join("merged");
    let mut args = vec!["merge", "--json", "--quiet", "--out", s(&merged)];
    let files: Vec<String> = (0..3)
        .map(|k| s(&shards.join(format!("shard-000{k}-of-0003.json"))).to_string())
        .collect();
    args.extend(files.iter().map(String::as_str));
    let m = ok(&args);
    let stdout = |o: &Output, dir: &Path| {
        crate::support::without_dir(&String::from_utf8_lossy(&o.stdout), dir)
    };
    assert_eq!(stdout(&one, &full), stdout(&m, &merged));
    for f in ["report.md", "report.json"] {
        assert!(
            crate::support::report_text(&full, f) == crate::support::report_text(&merged, f),
            "{f} differs"
        );
    }
    std::fs::remove_dir_all(&d).unwrap();
}
