//! Sensor pins in scenarios and in the line: bad sensor settings are located errors; reading a
//! sensor scene leaves its sensors to train, and building the draft gives the loaded scene; a
//! sensor that cannot be trained is a located error; the bundled sensor scene runs, reports its
//! readings and is reproducible; a passive scene does no sensing work at all (the `work` counters
//! prove it).

use pinfeed::engine::{run, RunOptions, RunResult};
use pinfeed::scenario::{load, parse, InvalidScenario, Obstacle, Scene, SceneDraft};
use std::path::Path;

const SCENE: &str = include_str!("../../scenarios/tripoly1_sensor.toml");

/// Runs `a` and `b` on the first `parts` parts of `a`'s feed, with `a`'s seed.
fn run_both(a: &Scene, b: &Scene, parts: u64) -> (RunResult, RunResult) {
    let opts = RunOptions {
        parts,
        ..RunOptions::from_scene(a)
    };
    let run = |s| run(s, &opts, &mut |_| {}).unwrap();
    (run(a), run(b))
}

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
    let (a, b) = run_both(&scene, &scene, 60);
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

/// Reading a sensor scene trains nothing: its draft lists the probe as a sensor still to train,
/// with the labels its rules may name. Building the draft gives the scene `load` gives: the same
/// obstacles and sensors, and the same run, summary for summary.
#[test]
fn a_sensor_scene_is_read_untrained_and_builds_into_the_loaded_scene() {
    let path = Path::new("scenarios/tripoly1_sensor.toml");
    let draft = SceneDraft::read(path).unwrap();
    assert_eq!(draft.name(), "tripoly1_sensor");
    let [probe] = draft.sensors() else {
        panic!("one sensor to train: {:?}", draft.sensors());
    };
    assert_eq!((probe.obstacle, probe.name.as_str()), (0, "probe"));
    assert_eq!(probe.hypotheses.labels(), ["0°", "135°", "225°"]);
    assert_eq!(
        (probe.classifier.as_str(), probe.templates),
        ("likelihood", 32)
    );
    let built = draft.build().unwrap();
    let loaded = load(path).unwrap();
    assert_eq!(built.obstacles, loaded.obstacles);
    let Obstacle::Pin(pin) = &built.obstacles[0] else {
        panic!("the probe is a pin");
    };
    let sensor = pin.sensor.as_ref().expect("the built probe has its sensor");
    assert_eq!(sensor.labels, probe.hypotheses.labels());
    assert_eq!(sensor.templates_per_hypothesis, 32);
    let (a, b) = run_both(&loaded, &built, 30);
    assert_eq!(a.summary, b.summary);
    assert_eq!(a.summary.sensors[0].readings, 30);
    // A scene without sensor pins has nothing to train.
    let quick = SceneDraft::read(Path::new("scenarios/quickstart.toml")).unwrap();
    assert!(quick.sensors().is_empty());
}

/// A sensor that cannot be trained is refused when the scene is built, not when the file is
/// read, and the error names the file, the line and the sensor's key like any other.
#[test]
fn a_training_error_is_located_at_the_sensor() {
    // The probe 5 cm off the feed line (d = 1.58) never touches a part: no vertex, no edge.
    let src = SCENE.replacen("y = -0.004 ", "y = 0.05 ", 1).replacen(
        "templates = 32 ",
        "templates = 4\nhypotheses = \"vertex-edge\"",
        1,
    );
    let draft = SceneDraft::parse(Path::new("far.toml"), &src).expect("the file itself is fine");
    let e = draft.build().unwrap_err();
    let i = e.invalid().expect("located error");
    let line = src
        .lines()
        .position(|l| l.starts_with("hypotheses"))
        .unwrap()
        + 1;
    assert_eq!(i.file, Path::new("far.toml"));
    assert_eq!((i.line, i.column), (line, 14), "{e}");
    assert_eq!(i.key, "obstacles[0].sensor.hypotheses");
    assert!(
        i.message
            .starts_with("hypothesis 'vertex' never occurs at this pin"),
        "{e}"
    );
    assert!(
        e.to_string().contains("hypotheses = \"vertex-edge\""),
        "{e}"
    );
    // parse reads and builds: the same error.
    let p = parse(Path::new("far.toml"), &src).unwrap_err();
    assert_eq!(p.to_string(), e.to_string());
}
