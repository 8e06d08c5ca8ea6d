//! The feeder line end to end (issue 7 acceptance): determinism, event order, conservation on the
//! bundled scenarios, an empty belt, a pin every part hits, collisions against headway, the cost
//! of unused effects, multi-contacts and off-belt parts, and the `pinfeed run` command's outputs.

use crate::support::pinfeed;
use pinfeed::engine::{self, RunOptions, RunResult};
use pinfeed::scenario::{self, Scene};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// A small line: tripoly2 (scale 2 cm) on a 5 cm/s belt, one 2 mm pin at y = 0, goal "any".
/// `extra` is appended; `replace` swaps whole lines of the base.
fn scenario_text(replace: &[(&str, &str)], extra: &str) -> String {
    let mut s = String::from(
        r#"name = "test"
[belt]
speed = 0.05
width = 0.2
length = 0.5

[part]
shape = "tripoly2"
scale = 0.02

[feed]
parts = 40
arrival = "periodic"
headway = 12.0
orientation = "stable"
weights = [1, 0, 0]

[feed.lateral]
distribution = "uniform"
min = -0.002
max = 0.002

[[obstacles]]
kind = "pin"
x = 0.2
y = 0.0
radius = 0.002

[goal]
any = true
"#,
    );
    for (from, to) in replace {
        assert!(s.contains(from), "base scenario has no line '{from}'");
        s = s.replace(from, to);
    }
    s + extra
}

fn scene(text: &str) -> Scene {
    scenario::parse(Path::new("test.toml"), text).unwrap_or_else(|e| panic!("{e}"))
}

fn run(scene: &Scene) -> RunResult {
    engine::run(scene, &RunOptions::from_scene(scene), &mut |_| {}).unwrap()
}

fn tmpdir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pinfeed-line-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn bundled() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

#[test]
fn same_scenario_and_seed_give_byte_identical_json() {
    let quickstart = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/quickstart.toml");
    let (a, b) = (tmpdir("det-a"), tmpdir("det-b"));
    let args = |d: &Path| {
        vec![
            "run".to_string(),
            quickstart.to_string(),
            "--parts".into(),
            "300".into(),
            "--json".into(),
            "--out".into(),
            d.display().to_string(),
        ]
    };
    let run_a = pinfeed(&args(&a).iter().map(String::as_str).collect::<Vec<_>>());
    let run_b = pinfeed(&args(&b).iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        run_a.status.success(),
        "{}",
        String::from_utf8_lossy(&run_a.stderr)
    );
    assert!(!run_a.stdout.is_empty());
    assert_eq!(
        run_a.stdout, run_b.stdout,
        "stdout JSON differs between identical runs"
    );
    let file = |d: &Path| std::fs::read(d.join("quickstart/summary.json")).unwrap();
    assert_eq!(file(&a), file(&b));
    assert_eq!(file(&a), run_a.stdout, "summary.json is the printed JSON");
    // Another seed gives another run.
    let mut other = args(&a);
    other.extend(["--seed".to_string(), "99".to_string()]);
    let run_c = pinfeed(&other.iter().map(String::as_str).collect::<Vec<_>>());
    assert_ne!(run_a.stdout, run_c.stdout);
}

#[test]
fn events_are_processed_in_time_order_with_ties_in_sequence_order() {
    // A crowded Poisson feed: many events, collisions, ties at collision instants.
    let s = scene(&scenario_text(
        &[
            ("arrival = \"periodic\"", "arrival = \"poisson\""),
            ("headway = 12.0", "headway = 1.0"),
            ("parts = 40", "parts = 150"),
        ],
        "[effects]\nevent_log = true\n",
    ));
    let r = run(&s);
    assert!(r.events.len() > 400, "{} events", r.events.len());
    for w in r.events.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        assert!(
            a.time < b.time || (a.time == b.time && a.seq < b.seq),
            "out of order: {a:?} then {b:?}"
        );
    }
    let ties = r
        .events
        .windows(2)
        .filter(|w| w[0].time == w[1].time)
        .count();
    assert!(ties > 0, "the scenario should produce simultaneous events");
    // Events of one part are causal: arrival first.
    let first_arrival = r
        .events
        .iter()
        .position(|e| matches!(e.kind, engine::event_queue::EventKind::Arrival { part: 7 }))
        .unwrap();
    let first_of_7 = r
        .events
        .iter()
        .position(|e| match e.kind {
            engine::event_queue::EventKind::ContactBegin { part, .. }
            | engine::event_queue::EventKind::ContactEnd { part, .. }
            | engine::event_queue::EventKind::Exit { part }
            | engine::event_queue::EventKind::Decision { part, .. }
            | engine::event_queue::EventKind::Unread { part, .. }
            | engine::event_queue::EventKind::Arrival { part } => part == 7,
            engine::event_queue::EventKind::Collision { first, second } => {
                first == 7 || second == 7
            }
            // A closed loop's events (this scene has none).
            engine::event_queue::EventKind::Return { .. }
            | engine::event_queue::EventKind::MergeFree => false,
        })
        .unwrap();
    assert_eq!(first_arrival, first_of_7);
}

#[test]
fn every_bundled_scenario_conserves_parts() {
    let files = bundled();
    assert!(
        files.len() >= 3,
        "expected the bundled scenarios, found {files:?}"
    );
    for f in files {
        let s = scenario::load(&f).unwrap_or_else(|e| panic!("{e}"));
        let mut opts = RunOptions::from_scene(&s);
        opts.parts = opts.parts.min(400);
        let r = engine::run(&s, &opts, &mut |_| {}).unwrap();
        let o = r.summary.outcomes;
        // A closed loop counts its passes in `parts_in`: its new parts are the loop's, and the
        // passes its gate took off end in no outcome class.
        let loop_ = r.summary.closed_loop.as_ref();
        let new_parts = loop_.map_or(r.summary.parts_in, |l| l.new_parts);
        let diverted = loop_.map_or(0, |l| l.gate_counts.acted);
        assert_eq!(new_parts, opts.parts, "{}", f.display());
        assert_eq!(
            o.success
                + o.wrong_orientation
                + o.collision
                + o.multi_contact
                + o.off_belt
                + o.jam
                + o.solver
                + diverted,
            r.summary.parts_in,
            "{}: {o:?}",
            f.display()
        );
        let exits = o.success + o.wrong_orientation;
        let hist: u64 = r.summary.orientation_histogram.counts.iter().sum();
        assert_eq!(
            hist,
            exits,
            "{}: histogram counts the exiting parts",
            f.display()
        );
    }
}

#[test]
fn empty_belt_every_part_succeeds_at_the_arrival_rate() {
    let mut text = scenario_text(
        &[
            ("orientation = \"stable\"", "orientation = \"uniform\""),
            ("weights = [1, 0, 0]\n", ""),
        ],
        "",
    );
    let start = text.find("[[obstacles]]").unwrap();
    let end = text.find("[goal]").unwrap();
    text.replace_range(start..end, "");
    let s = scene(&text);
    assert!(s.obstacles.is_empty());
    let r = run(&s);
    let sm = &r.summary;
    assert_eq!(sm.outcomes.success, 40);
    assert_eq!(sm.success_rate, 1.0);
    let rate = 60.0 / 12.0;
    assert!((sm.throughput_in_per_min.unwrap() - rate).abs() < 1e-9);
    assert!((sm.throughput_ok_per_min.unwrap() - rate).abs() < 1e-9);
    assert_eq!(sm.contacts_per_part, 0.0);
    // Latency is the ride: length / speed.
    let lat = sm.latency_s.unwrap();
    assert!((lat.max - 0.5 / 0.05).abs() < 1e-9);
    assert!((lat.p50 - 10.0).abs() < 0.01);
    // Uniform entry orientations spread over the histogram.
    assert!(
        sm.orientation_histogram
            .counts
            .iter()
            .filter(|&&c| c > 0)
            .count()
            > 20
    );
}

#[test]
fn a_pin_every_part_hits_gives_one_contact_per_part() {
    let s = scene(&scenario_text(&[], ""));
    let r = run(&s);
    assert_eq!(r.summary.contacts_per_part, 1.0, "{:?}", r.summary);
    assert_eq!(r.summary.obstacles[0].contacts, 40);
    assert_eq!(r.summary.outcomes.success, 40);
    let busy = r.summary.obstacles[0].busy_fraction;
    assert!(busy > 0.0 && busy < 1.0);
}

/// The lag of a held part: how far it falls behind the belt during its push (m).
fn lag_of_one_part(text: &str) -> f64 {
    let mut s = scene(text);
    s.feed.parts = 1;
    let r = run(&s);
    let lat = r.summary.latency_s.unwrap().max;
    lat * s.belt.speed - s.belt.length
}

#[test]
fn collisions_appear_when_headway_is_below_part_length_plus_lag() {
    // Every part identical: stable state 0°, on the centre line, so every push lags the same.
    let base = scenario_text(
        &[(
            "distribution = \"uniform\"\nmin = -0.002\nmax = 0.002",
            "distribution = \"fixed\"\nvalue = 0.001",
        )],
        "",
    );
    let lag = lag_of_one_part(&base);
    assert!(lag > 0.0, "a pushed part lags the belt, got {lag}");
    let s = scene(&base);
    // Part length along the belt at θ = 0: the long leg, 2 units.
    let length = 2.0 * 0.02;
    let critical = (length + lag) / s.belt.speed;
    let collisions_at = |headway: f64| {
        let text = base.replace("headway = 12.0", &format!("headway = {headway}"));
        let r = run(&scene(&text));
        (
            r.summary.outcomes.collision,
            r.summary.work.part_part_checks,
        )
    };
    let (loose, checks_loose) = collisions_at(1.3 * critical);
    let (tight, _) = collisions_at(0.8 * critical);
    assert_eq!(loose, 0, "headway 1.3× (length + lag)/V must not collide");
    assert!(
        checks_loose > 0,
        "parts share the belt, so pairs are checked"
    );
    assert!(
        tight > 0,
        "headway 0.8× (length + lag)/V must collide (lag {lag} m)"
    );
    // Without any lag (no pin) the same tight headway is safe.
    let mut free = base.replace("headway = 12.0", &format!("headway = {}", 0.8 * critical));
    let start = free.find("[[obstacles]]").unwrap();
    let end = free.find("[goal]").unwrap();
    free.replace_range(start..end, "");
    assert_eq!(run(&scene(&free)).summary.outcomes.collision, 0);
}

#[test]
fn unused_effects_cost_nothing() {
    // One part on the belt at a time (headway 12 s > 10 s ride + lag), one isolated pin.
    let r = run(&scene(&scenario_text(&[], "")));
    let w = r.summary.work;
    assert_eq!(w.part_part_checks, 0, "{w:?}");
    assert_eq!(w.part_part_narrow_checks, 0);
    assert_eq!(w.obstacle_sweep_checks, 0);
    assert_eq!(w.traces_recorded, 0);
    assert_eq!(w.pushes_rerun, 0);
    assert_eq!(w.clearance_evaluations, 0);
    assert_eq!(w.tripods_drawn, 0);
    assert!(r.events.is_empty(), "no event log unless asked");
    assert!(r.records.is_empty() && r.paths.is_empty());
    // Crowded, but collision detection switched off: no checks at all.
    let off = run(&scene(&scenario_text(
        &[("headway = 12.0", "headway = 0.5")],
        "[effects]\ncollisions = false\n",
    )));
    assert_eq!(off.summary.work.part_part_checks, 0);
    assert_eq!(off.summary.outcomes.collision, 0);
    // Crowded with detection on: the checks run.
    let on = run(&scene(&scenario_text(
        &[("headway = 12.0", "headway = 0.5")],
        "",
    )));
    assert!(on.summary.work.part_part_checks > 0);
    assert!(on.summary.outcomes.collision > 0);
}

#[test]
fn a_second_pin_within_reach_is_a_multi_contact() {
    // A second pin just upstream of the first and 12 mm to its left: while the first pin holds a
    // part, the part's hypotenuse runs into the second.
    let extra = "[[obstacles]]\nkind = \"pin\"\nname = \"close\"\nx = 0.19\ny = 0.012\nradius = 0.002\n\n[goal]";
    let s = scene(&scenario_text(&[], "").replace("[goal]", extra));
    assert_eq!(s.neighbours[0], vec![1]);
    let r = run(&s);
    let sm = &r.summary;
    assert!(sm.outcomes.multi_contact > 0, "{:?}", sm.outcomes);
    assert!(
        sm.causes.multi_contact.contains_key("second_obstacle"),
        "{:?}",
        sm.causes
    );
    assert!(sm.work.obstacle_sweep_checks > 0 && sm.work.traces_recorded > 0);
    // Switched off, the same layout is simulated as if the pins were independent.
    let off =
        scene(&scenario_text(&[], "[effects]\nobstacle_sweeps = false\n").replace("[goal]", extra));
    let r_off = run(&off);
    assert_eq!(r_off.summary.work.obstacle_sweep_checks, 0);
    assert_eq!(r_off.summary.outcomes.multi_contact, 0);
}

#[test]
fn a_part_pushed_over_the_edge_is_off_belt() {
    // A belt barely wider than the part and a cascade of pins, each 4 mm to the right of where the
    // previous one left the part, shoving it further left until its centroid leaves the belt.
    let pins: String = [(0.1, -0.004), (0.2, 0.0097), (0.3, 0.0181), (0.4, 0.0248)]
        .iter()
        .map(|(x, y)| {
            format!("[[obstacles]]\nkind = \"pin\"\nx = {x}\ny = {y}\nradius = 0.002\n\n")
        })
        .collect();
    let mut text = scenario_text(
        &[
            ("width = 0.2", "width = 0.058"),
            ("length = 0.5", "length = 0.6"),
            ("weights = [1, 0, 0]", "weights = [0, 0, 1]"),
            (
                "distribution = \"uniform\"\nmin = -0.002\nmax = 0.002",
                "distribution = \"fixed\"\nvalue = 0.0",
            ),
            ("parts = 40", "parts = 3"),
        ],
        "",
    );
    let start = text.find("[[obstacles]]").unwrap();
    let end = text.find("[goal]").unwrap();
    text.replace_range(start..end, &pins);
    let r = run(&scene(&text));
    assert_eq!(r.summary.outcomes.off_belt, 3, "{:?}", r.summary.outcomes);
    assert_eq!(r.summary.contacts_per_part, 4.0);
}

#[test]
fn tripod_support_draws_one_tripod_per_part() {
    let s = scene(&scenario_text(
        &[("scale = 0.02", "scale = 0.02\nsupport = \"tripod\"")],
        "",
    ));
    let r = run(&s);
    assert_eq!(r.summary.work.tripods_drawn, 40);
    assert_eq!(r.summary.outcomes.total(), 40);
}

#[test]
fn run_command_writes_results_and_draws_the_line() {
    let out = tmpdir("cli");
    let file = out.join("cli.toml");
    std::fs::write(
        &file,
        scenario_text(
            &[("name = \"test\"", "name = \"cli\"")],
            "[output]\nparts_csv = true\n",
        ),
    )
    .unwrap();
    let svg = out.join("line.svg");
    let o = pinfeed(&[
        "run",
        file.to_str().unwrap(),
        "--parts",
        "12",
        "--seed",
        "5",
        "--json",
        "--out",
        out.to_str().unwrap(),
        "--draw",
        svg.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    for key in [
        "parts_in",
        "outcomes",
        "success_rate",
        "success_ci95",
        "throughput_in_per_min",
        "throughput_ok_per_min",
        "latency_s",
        "contacts_per_part",
    ] {
        assert!(v.get(key).is_some(), "--json lacks {key}: {v}");
    }
    assert_eq!(v["parts_in"], 12);
    assert_eq!(v["seed"], 5);
    for q in ["p50", "p90", "p99", "max"] {
        assert!(v["latency_s"][q].as_f64().unwrap() > 0.0);
    }
    assert!(v["outcomes"]["success"].as_u64().is_some());
    let dir = out.join("cli");
    assert!(dir.join("summary.json").is_file());
    let csv = std::fs::read_to_string(dir.join("parts.csv")).unwrap();
    assert_eq!(csv.lines().count(), 13, "a header and one row per part");
    assert!(csv.starts_with("part,arrival_s,end_s,outcome"));
    let hist = std::fs::read_to_string(dir.join("orientation_histogram.svg")).unwrap();
    assert!(hist.contains("<svg"));
    let drawing = std::fs::read_to_string(&svg).unwrap();
    assert!(drawing.contains("<svg") && drawing.contains("polyline"));
    // The table (no --json) names the outcome classes and the speed.
    let t = pinfeed(&[
        "run",
        file.to_str().unwrap(),
        "--parts",
        "3",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(t.status.success());
    let table = String::from_utf8_lossy(&t.stdout);
    for word in [
        "success",
        "wrong_orientation",
        "collision",
        "throughput",
        "contacts/s",
    ] {
        assert!(table.contains(word), "table lacks {word}:\n{table}");
    }
    // --quiet prints nothing.
    let q = pinfeed(&[
        "run",
        file.to_str().unwrap(),
        "--parts",
        "3",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(q.status.success() && q.stdout.is_empty());
}

#[test]
fn a_part_the_pin_never_releases_is_a_jam() {
    // tripoly2 lying on its short leg (90°), pushed exactly through its centroid: the push never
    // turns it, so it rides on the pin until the travel limit.
    let s = scene(&scenario_text(
        &[
            ("weights = [1, 0, 0]", "weights = [0, 1, 0]"),
            ("headway = 12.0", "headway = 40.0"),
            ("parts = 40", "parts = 3"),
            (
                "distribution = \"uniform\"\nmin = -0.002\nmax = 0.002",
                "distribution = \"fixed\"\nvalue = 0.0",
            ),
        ],
        "[model]\nmax_travel = 20\n",
    ));
    let r = run(&s);
    assert_eq!(r.summary.outcomes.jam, 3, "{:?}", r.summary.outcomes);
    assert!(r.summary.latency_s.is_none(), "no part reached the end");
}

/// A free part casts its path only towards the obstacles that can come first: once a touch is
/// found, an obstacle whose near side lies farther ahead than that touch is skipped. On the
/// quickstart line (three pins in a row; the first two push every part, the third two parts in
/// three) a part casts once on arrival (towards the first pin) and once after each of the first
/// two pins (towards the next): three casts, where casting towards every pin in reach would make
/// six.
#[test]
fn a_free_part_casts_only_towards_the_obstacle_it_can_reach_first() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/quickstart.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let s = scenario::parse(Path::new(path), &text).unwrap();
    let opts = RunOptions {
        parts: 200,
        ..RunOptions::from_scene(&s)
    };
    let r = engine::run(&s, &opts, &mut |_| {}).unwrap();
    assert_eq!(r.summary.outcomes.success, 200);
    assert!(r.summary.contacts_per_part > 2.0);
    assert_eq!(r.summary.work.ray_casts, 3 * 200);
}

/// `pinfeed run` says what the exact model's tables cost to build in the run (slide tables and the
/// evaluations they took); a scene on a closed-form fidelity builds none and the line is absent.
#[test]
fn the_run_table_reports_the_tables_the_exact_model_built() {
    let quickstart = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/quickstart.toml");
    let out = tmpdir("tables-line");
    let text = |file: &str| {
        let o = pinfeed(&["run", file, "--parts", "30", "--out", out.to_str().unwrap()]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap()
    };
    let exact = text(quickstart);
    let line = exact
        .lines()
        .find(|l| l.starts_with("exact model's tables"))
        .unwrap_or_else(|| panic!("no tables line:\n{exact}"));
    let numbers: Vec<u64> = line
        .split(|c: char| !c.is_ascii_digit())
        .filter_map(|w| w.parse().ok())
        .collect();
    // slide tables, nodes, evaluations: a scene's model has no stick tables (they pay only for a
    // map tier's build).
    assert_eq!(numbers.len(), 3, "{line}");
    assert!(numbers.iter().all(|&n| n > 0), "{line}");
    assert!(!line.contains("stick"), "{line}");
    let tip_file = out.join("tip.toml");
    let tip = std::fs::read_to_string(quickstart).unwrap().replace(
        "fidelity = \"exact\"   # or \"ellipsoid\", \"tip\"",
        "fidelity = \"tip\"",
    );
    assert!(tip.contains("fidelity = \"tip\""));
    std::fs::write(&tip_file, tip).unwrap();
    let closed = text(tip_file.to_str().unwrap());
    assert!(closed.contains("simulator speed"), "{closed}");
    assert!(
        !closed.contains("exact model's tables"),
        "a tip scene builds no table:\n{closed}"
    );
}
