//! Monte Carlo studies perturb every obstacle: the fence parameters (μf,
//! angle, upstream end, length), the actuator parameters (speed, acceleration, settle) and the
//! controller's latency each change what they should and nothing else, each from its own stream;
//! a fence μf drawn into the jam region is reported as jams; a parameter that reaches nothing in
//! the scenario is a located error; shards merge byte for byte and the thread count changes
//! nothing; a study without the new parameters does no extra work and draws what it drew before.

use crate::mc::refused;
use crate::support::{pinfeed, pinfeed_json, pinfeed_ok, report_text};
use pinfeed::scenario::{Actuator, Obstacle, Scene};
use pinfeed::study::mc::{self, sample};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// A line with every kind of obstacle: two fences (tripoly1_fences.toml's), a fixed pin, a
/// moving pin, a retractable pin and a controller.
const LINE: &str = r#"
name = "mixed"
seed = 1
[belt]
speed = 0.05
width = 0.18
length = 0.6
[part]
shape = "tripoly1"
scale = 0.02
[feed]
parts = 10
arrival = "periodic"
headway = 6.0
orientation = "stable"
jitter = 2.0
[[obstacles]]
kind = "fence"
name = "f1"
x = 0.08
y = -0.0343
angle = 36
length = 0.1014
mu_f = 0.5
[[obstacles]]
kind = "fence"
name = "f2"
x = 0.2016
y = 0.0062
angle = 48
length = 0.0829
mu_f = 0.5
[[obstacles]]
kind = "pin"
name = "p1"
x = 0.4
y = 0.07
radius = 0.002
[[obstacles]]
kind = "moving_pin"
name = "m1"
x = 0.45
y = -0.06
radius = 0.002
travel = [-0.08, -0.04]
speed = 0.1
accel = 1.0
settle = 0.05
[[obstacles]]
kind = "retractable_pin"
name = "r1"
x = 0.5
y = -0.07
radius = 0.002
raised = false
raise_time = 0.2
lower_time = 0.3
[controller]
latency = 0.02
[goal]
[[goal.sets]]
name = "g"
orientations = [6.6]
tolerance = 3.0
"#;

/// Each new parameter, a distribution of it, and the fields it must change (obstacle.field).
const NEW: [(&str, &str, &[&str]); 9] = [
    (
        "fence_mu_f",
        "distribution = \"uniform\"\nmin = 0.3\nmax = 0.7",
        &["f1.mu_f", "f2.mu_f"],
    ),
    (
        "fence_angle",
        "distribution = \"normal\"\nsd = 2.0",
        &["f1.angle", "f2.angle"],
    ),
    (
        "fence_x",
        "distribution = \"normal\"\nsd = 0.001",
        &["f1.x", "f2.x"],
    ),
    (
        "fence_y",
        "distribution = \"normal\"\nsd = 0.001",
        &["f1.y", "f2.y"],
    ),
    (
        "fence_length",
        "distribution = \"uniform\"\nmin = -0.005\nmax = 0.005",
        &["f1.length", "f2.length"],
    ),
    (
        "actuator_speed",
        "distribution = \"uniform\"\nmin = 0.5\nmax = 1.5",
        &["m1.speed", "r1.raise_time", "r1.lower_time"],
    ),
    (
        "actuator_accel",
        "distribution = \"uniform\"\nmin = 0.5\nmax = 1.5",
        &["m1.accel"],
    ),
    (
        "actuator_settle",
        "distribution = \"uniform\"\nmin = -0.01\nmax = 0.01",
        &["m1.settle"],
    ),
    (
        "controller_latency",
        "distribution = \"uniform\"\nmin = -0.01\nmax = 0.01",
        &["controller.latency"],
    ),
];

/// A fresh, empty folder for one test.
fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "pinfeed-mc-obstacles-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A study of `scenario` (a path) with `body` after its `scenario` line, written as `file`.
fn study_of(dir: &Path, file: &str, scenario: &str, body: &str) -> PathBuf {
    let p = dir.join(file);
    std::fs::write(&p, format!("scenario = \"{scenario}\"\n{body}")).unwrap();
    p
}

/// A study of [`LINE`] (written beside it) with `body`.
fn mixed_study(dir: &Path, file: &str, body: &str) -> PathBuf {
    std::fs::write(dir.join("line.toml"), LINE).unwrap();
    study_of(dir, file, "line.toml", body)
}

/// `[uncertain.NAME]` tables of the given parameters (from [`NEW`]).
fn tables(names: &[&str]) -> String {
    NEW.iter()
        .filter(|(n, _, _)| names.contains(n))
        .map(|(n, d, _)| format!("[uncertain.{n}]\n{d}\n"))
        .collect()
}

fn bundled(name: &str) -> String {
    format!("{}/scenarios/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// What differs between two drawn scenes, as `obstacle.field` (and `part`, `feed`, `belt`,
/// `mu_c`, `controller.latency`, `controller`).
fn changed(a: &Scene, b: &Scene) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut note = |differs: bool, what: String| {
        if differs {
            out.insert(what);
        }
    };
    note(a.belt != b.belt, "belt".into());
    note(a.feed != b.feed, "feed".into());
    note(
        a.part.polygon.vertices() != b.part.polygon.vertices(),
        "part".into(),
    );
    note(
        a.part.mu_c != b.part.mu_c || a.contact.mu_c != b.contact.mu_c,
        "mu_c".into(),
    );
    match (&a.controller, &b.controller) {
        (Some(x), Some(y)) => {
            note(x.latency != y.latency, "controller.latency".into());
            let same_but_latency = pinfeed::scenario::Controller {
                latency: x.latency,
                ..y.clone()
            };
            note(*x != same_but_latency, "controller".into());
        }
        (x, y) => note(x != y, "controller".into()),
    }
    assert_eq!(a.obstacles.len(), b.obstacles.len());
    for (x, y) in a.obstacles.iter().zip(&b.obstacles) {
        let n = x.name();
        match (x, y) {
            (Obstacle::Fence(f), Obstacle::Fence(g)) => {
                note(f.name != g.name, format!("{n}.name"));
                note(f.mu_f != g.mu_f, format!("{n}.mu_f"));
                note(f.angle_rad != g.angle_rad, format!("{n}.angle"));
                note(f.start.x != g.start.x, format!("{n}.x"));
                note(f.start.y != g.start.y, format!("{n}.y"));
                note(f.length != g.length, format!("{n}.length"));
            }
            (Obstacle::Pin(p), Obstacle::Pin(q)) => {
                note(p.centre != q.centre, format!("{n}.centre"));
                note(p.radius != q.radius, format!("{n}.radius"));
                note(p.mu_c != q.mu_c, format!("{n}.mu_c"));
                match (p.actuator, q.actuator) {
                    (Some(Actuator::Moving(u)), Some(Actuator::Moving(v))) => {
                        note(u.speed != v.speed, format!("{n}.speed"));
                        note(u.accel != v.accel, format!("{n}.accel"));
                        note(u.settle != v.settle, format!("{n}.settle"));
                        let rest = |m: pinfeed::scenario::MovingSpec| (m.home, m.travel, m.pieces);
                        note(rest(u) != rest(v), format!("{n}.actuator"));
                    }
                    (Some(Actuator::Retractable(u)), Some(Actuator::Retractable(v))) => {
                        note(u.raise_time != v.raise_time, format!("{n}.raise_time"));
                        note(u.lower_time != v.lower_time, format!("{n}.lower_time"));
                        note(u.raised != v.raised, format!("{n}.actuator"));
                    }
                    (u, v) => note(u != v, format!("{n}.actuator")),
                }
            }
            _ => note(true, format!("{n}.kind")),
        }
    }
    out
}

/// Samples compared per test.
const SAMPLES: u64 = 30;

/// The drawn scenes of samples 0..SAMPLES of a study.
fn draws(study: &mc::Study) -> Vec<sample::DrawnScene> {
    (0..SAMPLES)
        .map(|i| sample::draw_scene(&study.scene, &study.points[0], study.seed, i).unwrap())
        .collect()
}

/// What differs between the draws of two studies, over every sample ([`changed`]).
fn changes(a: &[sample::DrawnScene], b: &[sample::DrawnScene]) -> BTreeSet<String> {
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| changed(&x.scene, &y.scene))
        .collect()
}

fn set(fields: &[&str]) -> BTreeSet<String> {
    fields.iter().map(|f| f.to_string()).collect()
}

#[test]
fn each_new_parameter_changes_what_it_should_and_nothing_else() {
    let d = tmp("each");
    // The part's shape and pose are uncertain too, so that a shifted stream would show.
    let base_body = "[uncertain.shape]\ndistribution = \"normal\"\nsd = 0.0002\n[uncertain.pose_theta]\ndistribution = \"normal\"\nsd = 2.0\n";
    let nominal = mc::load(&mixed_study(&d, "nominal.toml", base_body), None).unwrap();
    let nominal = draws(&nominal);
    let every: Vec<&str> = NEW.iter().map(|(n, _, _)| *n).collect();
    let all = mc::load(
        &mixed_study(&d, "all.toml", &format!("{base_body}{}", tables(&every))),
        None,
    )
    .unwrap();
    let all = draws(&all);
    for (name, _, fields) in NEW {
        // Alone: exactly its fields change, at some sample (and never anything else).
        let alone = mixed_study(
            &d,
            &format!("{name}.toml"),
            &format!("{base_body}{}", tables(&[name])),
        );
        let alone = draws(&mc::load(&alone, None).unwrap());
        let seen = changes(&nominal, &alone);
        assert_eq!(seen, set(fields), "{name} alone");
        // Left out of a study of every new parameter: only its fields differ (every other
        // parameter draws the same numbers from its own stream).
        let others: Vec<&str> = every.iter().copied().filter(|n| *n != name).collect();
        let without = mixed_study(
            &d,
            &format!("without-{name}.toml"),
            &format!("{base_body}{}", tables(&others)),
        );
        let without = draws(&mc::load(&without, None).unwrap());
        let seen = changes(&all, &without);
        assert_eq!(seen, set(fields), "every parameter but {name}");
    }
    // Fence μf: one draw per sample for every fence, within its range; the geometry errors are
    // drawn per fence; the speed factor keeps a retractable pin's raise/lower ratio.
    for x in &all {
        let fences: Vec<_> = x
            .scene
            .obstacles
            .iter()
            .filter_map(|o| match o {
                Obstacle::Fence(f) => Some(f),
                Obstacle::Pin(_) => None,
            })
            .collect();
        assert_eq!(fences[0].mu_f, fences[1].mu_f);
        assert!((0.3..=0.7).contains(&fences[0].mu_f));
        let r1 = x.scene.obstacles.iter().find(|o| o.name() == "r1").unwrap();
        let Obstacle::Pin(r1) = r1 else { panic!() };
        let Some(Actuator::Retractable(r)) = r1.actuator else {
            panic!()
        };
        assert!((r.raise_time / r.lower_time - 0.2 / 0.3).abs() < 1e-12);
        let latency = x.scene.controller.as_ref().unwrap().latency;
        assert!((0.01..=0.03).contains(&latency), "{latency}");
    }
    let angle_errors: BTreeSet<String> = all
        .iter()
        .zip(&nominal)
        .map(|(a, b)| {
            let e = |s: &Scene, k: usize| match &s.obstacles[k] {
                Obstacle::Fence(f) => f.angle_rad,
                Obstacle::Pin(_) => panic!(),
            };
            format!(
                "{:.12}",
                (e(&a.scene, 0) - e(&b.scene, 0)) - (e(&a.scene, 1) - e(&b.scene, 1))
            )
        })
        .collect();
    assert!(
        angle_errors.len() > 1,
        "the fences' angle errors are not independent"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn selectors_restrict_a_parameter_to_the_obstacles_they_name() {
    let d = tmp("select");
    let nominal = draws(&mc::load(&mixed_study(&d, "nominal.toml", ""), None).unwrap());
    let cases: [(&str, &[&str]); 4] = [
        (
            "[uncertain.fence_mu_f]\ndistribution = \"fixed\"\nvalue = 0.9\nfences = [\"f2\"]\n",
            &["f2.mu_f"],
        ),
        (
            "[uncertain.fence_angle]\ndistribution = \"normal\"\nsd = 2.0\nfences = [\"f1\"]\n",
            &["f1.angle"],
        ),
        (
            "[uncertain.actuator_speed]\ndistribution = \"uniform\"\nmin = 0.5\nmax = 1.5\npins = [\"r1\"]\n",
            &["r1.raise_time", "r1.lower_time"],
        ),
        // Fixed by a sweep, the parameter keeps its selector.
        (
            "[uncertain.fence_length]\ndistribution = \"normal\"\nsd = 0.001\nfences = [\"f2\"]\n[[sweep]]\nparameter = \"fence_length\"\nvalues = [0.004]\n",
            &["f2.length"],
        ),
    ];
    for (k, (body, fields)) in cases.iter().enumerate() {
        let st = mc::load(&mixed_study(&d, &format!("s{k}.toml"), body), None).unwrap();
        let got = draws(&st);
        let seen = changes(&nominal, &got);
        assert_eq!(seen, set(fields), "{body}");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn fence_friction_in_the_jam_region_reports_jams() {
    // tripoly1_fences: fences at 36° and 48°, which jam from μf = tan 54° ≈ 1.38 and tan 42° ≈ 0.90.
    let d = tmp("jam");
    let study = study_of(
        &d,
        "jam.toml",
        &bundled("tripoly1_fences.toml"),
        "samples = 60\n[uncertain.fence_mu_f]\ndistribution = \"fixed\"\nvalue = 0.5\n[[sweep]]\nparameter = \"fence_mu_f\"\nvalues = [0.5, 0.8, 3.0]\n",
    );
    let r = pinfeed_json(&[
        "mc",
        s(&study),
        "--json",
        "--quiet",
        "--out",
        s(&d.join("o")),
    ]);
    let counts = |k: usize, class: &str| r["results"][k]["outcomes"][class].as_u64().unwrap();
    // Below the jam angle of either fence: every part slides, and the nominal line orients all.
    for k in [0, 1] {
        assert_eq!(counts(k, "jam"), 0, "μf below the jam region jammed");
    }
    assert_eq!(counts(0, "success"), 60);
    // μf = 3: both fences are in the jam region; a part that lies flush on one jams.
    assert!(counts(2, "jam") >= 30, "{}", r["results"][2]);
    assert!(counts(2, "success") < 60);
    // The report's table shows the class.
    let md = std::fs::read_to_string(d.join("o").join("report.md")).unwrap();
    assert!(md.contains("jam % [95% CI]"), "{md}");
    // The line's own μc fixed at 3.0 reaches no fence: refused, pointing at fence_mu_f.
    let study = study_of(
        &d,
        "mu_c.toml",
        &bundled("tripoly1_fences.toml"),
        "[uncertain.mu_c]\ndistribution = \"fixed\"\nvalue = 3.0\n",
    );
    let e = refused(&["mc", s(&study), "--out", s(&d.join("o2"))]);
    assert!(e.contains("mu_c.toml:2:1: key `uncertain.mu_c`: "), "{e}");
    assert!(e.contains("[uncertain.fence_mu_f]"), "{e}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_parameter_that_reaches_nothing_is_a_located_error() {
    let d = tmp("reach");
    let quickstart = bundled("quickstart.toml");
    let fences = bundled("tripoly1_fences.toml");
    let cases: [Refusal; 9] = [
        (
            &quickstart,
            "[uncertain.fence_angle]\ndistribution = \"normal\"\nsd = 1.0\n",
            2,
            "uncertain.fence_angle",
            &["fence_angle perturbs fences", "the scenario has none"],
        ),
        (
            &fences,
            "[uncertain.pin_x]\ndistribution = \"normal\"\nsd = 0.001\n",
            2,
            "uncertain.pin_x",
            &["pin_x perturbs pins", "fence_x"],
        ),
        (
            &fences,
            "[uncertain.actuator_accel]\ndistribution = \"fixed\"\nvalue = 2.0\n",
            2,
            "uncertain.actuator_accel",
            &["moving pins", "the scenario has none"],
        ),
        (
            &quickstart,
            "[uncertain.actuator_speed]\ndistribution = \"fixed\"\nvalue = 2.0\n",
            2,
            "uncertain.actuator_speed",
            &["moving or retractable pins"],
        ),
        (
            &quickstart,
            "[uncertain.controller_latency]\ndistribution = \"fixed\"\nvalue = 0.01\n",
            2,
            "uncertain.controller_latency",
            &["[controller]"],
        ),
        (
            &quickstart,
            "[uncertain.mu_c]\ndistribution = \"fixed\"\nvalue = 0.5\n[[sweep]]\nparameter = \"fence_mu_f\"\nvalues = [0.5]\n",
            6,
            "sweep[0].parameter",
            &["fence_mu_f perturbs fences"],
        ),
        (
            &fences,
            "[uncertain.fence_mu_f]\ndistribution = \"fixed\"\nvalue = 0.5\nfences = [\"left1\", \"left3\"]\n",
            5,
            "uncertain.fence_mu_f.fences[1]",
            &["`left3` names no obstacle", "`left1`, `left2`"],
        ),
        (
            &quickstart,
            "[uncertain.pin_y]\ndistribution = \"fixed\"\nvalue = 0.0\nfences = [\"pin1\"]\n",
            5,
            "uncertain.pin_y.fences",
            &["applies only to the fence parameters"],
        ),
        (
            &fences,
            "[uncertain.fence_angle]\ndistribution = \"fixed\"\nvalue = 1.0\npins = [\"left1\"]\n",
            5,
            "uncertain.fence_angle.pins",
            &["applies only to the actuator parameters"],
        ),
    ];
    for (k, case) in cases.iter().enumerate() {
        refused_at(&d, k, case);
    }
    // A selector naming a pin of the wrong kind says what it is.
    let study = mixed_study(
        &d,
        "wrong_kind.toml",
        "[uncertain.actuator_accel]\ndistribution = \"fixed\"\nvalue = 2.0\npins = [\"r1\"]\n",
    );
    let e = refused(&["mc", s(&study), "--out", s(&d.join("o"))]);
    assert!(
        e.contains("key `uncertain.actuator_accel.pins[0]`: `r1` is a retractable pin; actuator_accel reaches moving pins"),
        "{e}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

/// A study case: its scenario (a path), its body, and the line, key and words of its error.
type Refusal<'a> = (&'a str, &'a str, usize, &'a str, &'a [&'a str]);

/// Study `case` number `k`, written in `d`, is refused at its line and key (with the excerpt),
/// with its words; returns the error.
fn refused_at(d: &Path, k: usize, (scenario, body, line, key, words): &Refusal) -> String {
    let file = format!("case{k}.toml");
    let study = study_of(d, &file, scenario, body);
    let e = refused(&["mc", s(&study), "--out", s(&d.join("o"))]);
    let head = format!("{file}:{line}:");
    assert!(e.contains(&head), "case {k}: expected '{head}' in:\n{e}");
    assert!(
        e.contains(&format!("key `{key}`: ")),
        "case {k}: expected key `{key}` in:\n{e}"
    );
    for w in *words {
        assert!(e.contains(w), "case {k}: expected '{w}' in:\n{e}");
    }
    assert!(
        e.contains(&format!("{line} | ")),
        "case {k}: no excerpt:\n{e}"
    );
    e
}

/// Every new parameter on the mixed line, swept over fence μf's upper bound.
fn every_new_parameter(d: &Path) -> PathBuf {
    let every: Vec<&str> = NEW.iter().map(|(n, _, _)| *n).collect();
    mixed_study(
        d,
        "every.toml",
        &format!(
            "seed = 5\nsamples = 20\n{}[[sweep]]\nparameter = \"fence_mu_f.max\"\nvalues = [0.7, 2.0, 3.0]\n",
            tables(&every)
        ),
    )
}

#[test]
fn shards_merge_byte_for_byte_with_the_new_parameters() {
    let d = tmp("shards");
    let study = every_new_parameter(&d);
    let full = d.join("full");
    pinfeed_ok(&["mc", s(&study), "--quiet", "--out", s(&full)]);
    let shards = d.join("shards");
    for k in 0..3 {
        pinfeed_ok(&[
            "mc",
            s(&study),
            "--shard",
            &format!("{k}/3"),
            "--out",
            s(&shards),
            "--quiet",
        ]);
    }
    let merged = d.join("merged");
    let files: Vec<String> = (0..3)
        .map(|k| s(&shards.join(format!("shard-000{k}-of-0003.json"))).to_string())
        .collect();
    let mut args = vec!["merge", "--quiet", "--out", s(&merged)];
    args.extend(files.iter().map(String::as_str));
    pinfeed_ok(&args);
    for f in ["report.json", "report.md", "sensitivity.svg"] {
        assert_eq!(
            report_text(&full, f),
            report_text(&merged, f),
            "{f} differs between the full run and the merged shards"
        );
    }
    // The study hash covers the new parameters: changing one changes it, and merge refuses to
    // mix the two studies' shards.
    let hash = |p: &Path| mc::load(p, None).unwrap().study_hash;
    let before = hash(&study);
    let text = std::fs::read_to_string(&study).unwrap().replace(
        "[uncertain.actuator_settle]\ndistribution = \"uniform\"\nmin = -0.01",
        "[uncertain.actuator_settle]\ndistribution = \"uniform\"\nmin = -0.02",
    );
    std::fs::write(&study, text).unwrap();
    assert_ne!(hash(&study), before);
    let other = d.join("other");
    pinfeed_ok(&[
        "mc",
        s(&study),
        "--shard",
        "0/3",
        "--out",
        s(&other),
        "--quiet",
    ]);
    let out = pinfeed(&[
        "merge",
        "--out",
        s(&d.join("mixed")),
        s(&other.join("shard-0000-of-0003.json")),
        &files[1],
        &files[2],
    ]);
    assert_eq!(out.status.code(), Some(1), "merge mixed two studies");
    // Fence μf in the jam region shows as jams in the merged report.
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(merged.join("report.json")).unwrap())
            .unwrap();
    assert!(
        r["results"][2]["outcomes"]["jam"].as_u64().unwrap() > 0,
        "{r}"
    );
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn the_thread_count_changes_nothing_with_the_new_parameters() {
    let d = tmp("threads");
    let study = every_new_parameter(&d);
    let (a, b) = (d.join("a"), d.join("b"));
    pinfeed_ok(&["mc", s(&study), "--threads", "1", "--quiet", "--out", s(&a)]);
    pinfeed_ok(&["mc", s(&study), "--threads", "2", "--quiet", "--out", s(&b)]);
    for f in ["report.json", "report.md", "sensitivity.svg"] {
        assert_eq!(report_text(&a, f), report_text(&b, f), "{f}");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_study_without_the_new_parameters_does_no_extra_work() {
    let d = tmp("cost");
    // Shape, pose and support uncertain (every stream of a study without the new parameters).
    let body = "samples = 40\n[uncertain.shape]\ndistribution = \"normal\"\nsd = 0.0003\n[uncertain.pose_theta]\ndistribution = \"normal\"\nsd = 3.0\n[uncertain.pose_y]\ndistribution = \"normal\"\nsd = 0.001\n[uncertain.support]\nmodel = \"tripod\"\n";
    let without = mixed_study(&d, "without.toml", body);
    let st = mc::load(&without, None).unwrap();
    assert!(!st.points[0].perturbs_obstacles());
    // It seeds no stream for the new parameters ...
    for x in draws(&st) {
        assert_eq!(x.streams, sample::BASE_STREAMS);
    }
    // ... while one that declares any does.
    let with = mixed_study(
        &d,
        "with.toml",
        &format!("{body}[uncertain.controller_latency]\ndistribution = \"fixed\"\nvalue = 0.0\n[uncertain.fence_angle]\ndistribution = \"fixed\"\nvalue = 0.0\n[uncertain.actuator_speed]\ndistribution = \"fixed\"\nvalue = 1.0\n"),
    );
    let st_with = mc::load(&with, None).unwrap();
    for x in draws(&st_with) {
        assert_eq!(x.streams, sample::BASE_STREAMS + sample::OBSTACLE_STREAMS);
    }
    // New parameters fixed at their nominal values change no outcome: the other parameters'
    // draws are what they were without them.
    let run = |p: &Path, out: &str| {
        pinfeed_json(&["mc", s(p), "--json", "--quiet", "--out", s(&d.join(out))])["results"]
            .clone()
    };
    let (a, b) = (run(&without, "a"), run(&with, "b"));
    assert_eq!(a, b);
    assert!(a[0]["outcomes"]["success"].as_u64().unwrap() < 40, "{a}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_plans_uncertainty_study_perturbs_the_fences_friction_with_the_pins() {
    use pinfeed::plan::check::Uncertainty;
    let range = Uncertainty::custom(Some((0.3, 0.7)), false, false);
    let own_mu_f = Uncertainty::custom(Some((0.3, 0.7)), false, true);
    let study = |u: &Uncertainty, kinds: &[&str]| {
        u.study_text(kinds, "plan.toml", "u.toml", 1, 100).unwrap()
    };
    // Fences whose μf is the nominal μc vary with it; μc itself only where there are pins.
    let fences = study(&range, &["fence", "fence"]);
    assert!(
        fences.contains("[uncertain.fence_mu_f]\ndistribution = \"uniform\"\nmin = 0.3\nmax = 0.7")
    );
    assert!(!fences.contains("[uncertain.mu_c]"), "{fences}");
    let both = study(&range, &["pin", "fence"]);
    assert!(both.contains("[uncertain.mu_c]") && both.contains("[uncertain.fence_mu_f]"));
    // Given their own μf (--mu-f), the fences keep it.
    let own = study(&own_mu_f, &["fence", "moving_pin"]);
    assert!(
        own.contains("[uncertain.mu_c]") && !own.contains("fence_mu_f"),
        "{own}"
    );
    // The default set: friction around each nominal value, placement of pins (a moving pin is
    // a pin) and fences, fence angles.
    let default = study(
        &Uncertainty::default_around(0.5, 0.4),
        &["fence", "moving_pin"],
    );
    for table in [
        "mu_c",
        "pin_x",
        "pin_y",
        "fence_mu_f",
        "fence_angle",
        "fence_x",
        "fence_y",
    ] {
        assert!(
            default.contains(&format!("[uncertain.{table}]")),
            "{table}: {default}"
        );
    }
    // Every study it writes loads: nothing declared reaches nothing.
    let d = tmp("plan");
    std::fs::write(d.join("line.toml"), LINE).unwrap();
    for text in [&fences, &both, &own, &default] {
        std::fs::write(d.join("u.toml"), text.replace("plan.toml", "line.toml")).unwrap();
        mc::load(&d.join("u.toml"), None).unwrap();
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn mu_c_on_a_line_with_fences_warns_that_it_does_not_reach_them() {
    let d = tmp("warn");
    let mu_c = "[uncertain.mu_c]\ndistribution = \"uniform\"\nmin = 0.3\nmax = 0.7\n";
    let st = mc::load(&mixed_study(&d, "mu_c.toml", mu_c), None).unwrap();
    let w = st.warnings().join("\n");
    assert!(
        w.contains("`f1` (μf 0.5), `f2` (μf 0.5) keep their own μf"),
        "{w}"
    );
    // On the command line, on stderr (the report is what it was).
    let out = pinfeed_ok(&[
        "mc",
        s(&d.join("mu_c.toml")),
        "--samples",
        "2",
        "--quiet",
        "--out",
        s(&d.join("o")),
    ]);
    assert!(String::from_utf8_lossy(&out.stderr)
        .contains("warning: mu_c varies the pins' friction only"));
    // fence_mu_f reaching one fence leaves the other in the warning; reaching both, none.
    let one = format!(
        "{mu_c}[uncertain.fence_mu_f]\ndistribution = \"fixed\"\nvalue = 0.6\nfences = [\"f2\"]\n"
    );
    let st = mc::load(&mixed_study(&d, "one.toml", &one), None).unwrap();
    let w = st.warnings().join("\n");
    assert!(w.contains("`f1`") && !w.contains("`f2`"), "{w}");
    let both = format!("{mu_c}{}", tables(&["fence_mu_f"]));
    let st = mc::load(&mixed_study(&d, "both.toml", &both), None).unwrap();
    assert!(st.warnings().is_empty());
    // No μc, no warning.
    let st = mc::load(&mixed_study(&d, "none.toml", ""), None).unwrap();
    assert!(st.warnings().is_empty());
    std::fs::remove_dir_all(&d).unwrap();
}

/// Issue 57 item 6: values inside a parameter's documented range that no sample can be drawn
/// with on the scenario passed the parser and failed at sample 0 ("1001 draws in a row …", no
/// file:line). They are refused when the study is read, at the parameter (or its sweep), with
/// the range the scenario allows.
#[test]
fn values_no_sample_can_be_drawn_with_are_refused_when_the_study_is_read() {
    let d = tmp("undrawable");
    let sensing = bundled("tripoly1_sensing.toml");
    std::fs::write(d.join("line.toml"), LINE).unwrap();
    let cases: [Refusal; 5] = [
        (
            "line.toml",
            "[uncertain.mu_c]\ndistribution = \"normal\"\nmean = 0.5\nsd = 0.1\nmin = 0.5\nmax = 0.5\n",
            7,
            "uncertain.mu_c.max",
            &["keeps 0.00% of normal", "give distribution = \"fixed\", value = 0.5"],
        ),
        (
            "line.toml",
            "[uncertain.mu_c]\ndistribution = \"normal\"\nmean = 0.5\nsd = 0.1\nmin = 0.5\nmax = 0.505\n",
            6,
            "uncertain.mu_c.min",
            &["keeps 1.99% of normal", "at least 5% must land in [min, max]"],
        ),
        (
            "line.toml",
            "[uncertain.actuator_speed]\ndistribution = \"fixed\"\nvalue = 1e-6\n",
            2,
            "uncertain.actuator_speed",
            &[
                "no valid sample can be drawn on this scenario",
                "pin `m1`",
                "actuator_speed must lie in [1e-5, 500] (its speed 0.1 m/s must stay in [1e-6, 50] m/s)",
            ],
        ),
        (
            &sensing,
            "[uncertain.sensor_noise]\ndistribution = \"fixed\"\nvalue = 100000\n",
            2,
            "uncertain.sensor_noise",
            &[
                "no valid sample can be drawn on this scenario",
                "at sensor_noise = 100000 the sensor's jitter: must lie in [0, 10] (s, ≥ 0), got 100",
            ],
        ),
        (
            "line.toml",
            "[[sweep]]\nparameter = \"actuator_speed\"\nvalues = [1.0, 1e-6]\n",
            3,
            "sweep[0].parameter",
            &["no valid sample can be drawn at actuator_speed = 1e-6 on this scenario"],
        ),
    ];
    for (k, case) in cases.iter().enumerate() {
        let e = refused_at(&d, k, case);
        assert!(!e.contains("sample 0 of sweep point"), "case {k}: {e}");
        assert!(!d.join("o").exists(), "case {k}: wrote a report");
    }
    // The range the error states is the real one: just inside it the study loads and draws.
    for (body, what) in [
        (
            "[uncertain.actuator_speed]\ndistribution = \"fixed\"\nvalue = 1.0001e-5\npins = [\"m1\"]\n",
            "slowest speed",
        ),
        (
            "[uncertain.actuator_speed]\ndistribution = \"fixed\"\nvalue = 499.9\n",
            "fastest speed",
        ),
        (
            "[uncertain.mu_c]\ndistribution = \"normal\"\nmean = 0.5\nsd = 0.1\nmin = 0.5\nmax = 0.513\n",
            "truncation",
        ),
    ] {
        let study = study_of(&d, "inside.toml", "line.toml", body);
        let st = mc::load(&study, None).unwrap_or_else(|e| panic!("{what}: {e}"));
        for i in 0..20 {
            sample::draw_scene(&st.scene, &st.points[0], st.seed, i).unwrap();
        }
    }
    let study = study_of(
        &d,
        "inside.toml",
        &sensing,
        "[uncertain.sensor_noise]\ndistribution = \"fixed\"\nvalue = 10000\n",
    );
    mc::load(&study, None).unwrap();
    std::fs::remove_dir_all(&d).unwrap();
}
