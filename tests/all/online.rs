//! Dynamic pins and the online controller in the line: the bundled sensing line, late
//! actuations, retractable pins, determinism, zero controller work in passive scenes, and located
//! errors for bad actuators, rules and policy files.

use pinfeed::engine::{self, RunOptions, RunResult};
use pinfeed::scenario::{self, Scene};
use std::path::Path;

const SENSING: &str = "scenarios/tripoly1_sensing.toml";

fn source() -> String {
    std::fs::read_to_string(SENSING).unwrap()
}

pub(crate) fn parse(text: &str) -> Scene {
    scenario::parse(Path::new("test.toml"), text).unwrap_or_else(|e| panic!("{e}"))
}

/// The error a scenario text is refused with.
pub(crate) fn refused(text: &str) -> String {
    match scenario::parse(Path::new("bad.toml"), text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

fn run(scene: &Scene, parts: u64, records: bool) -> RunResult {
    let mut opts = RunOptions::from_scene(scene);
    opts.parts = parts;
    opts.keep_records = records;
    engine::run(scene, &opts, &mut |_| {}).unwrap()
}

/// Swap one line of the bundled scenario (must match exactly once).
fn with(text: &str, old: &str, new: &str) -> String {
    assert_eq!(text.matches(old).count(), 1, "`{old}` must occur once");
    text.replacen(old, new, 1)
}

/// The scenario without its `[controller]` and `[[rules]]` (the goal kept).
fn without_controller(text: &str) -> String {
    let head = text.split("[controller]").next().unwrap();
    let tail = &text[text.find("[goal]").unwrap()..];
    format!("{head}{tail}")
}

fn summary_json(r: &RunResult) -> serde_json::Value {
    let mut v = serde_json::to_value(&r.summary).unwrap();
    // Wall-clock figures are not part of the simulation.
    v.as_object_mut().unwrap().remove("speed");
    v
}

#[test]
fn the_bundled_sensing_line_orients_tripoly1_to_one_set() {
    let scene = parse(&source());
    let r = run(&scene, 300, false);
    let s = &r.summary;
    assert!(s.success_rate >= 0.95, "success {}", s.success_rate);
    let c = s.controller.as_ref().expect("a controller summary");
    assert_eq!(c.late_actuations, 0);
    assert_eq!(c.actuators.len(), 1);
    assert!(c.actuators[0].moves > 100, "{:?}", c.actuators[0]);
    assert!(c.actuators[0].travel_m > 0.0 && c.actuators[0].utilisation < 0.5);
    let decided: u64 = c.decisions.values().map(|d| d.parts).sum();
    assert_eq!(decided, 300, "one decision per part");
    assert_eq!(s.work.decisions, 300);
    // Without the controller (the moving pin stays home) the same line orients far fewer parts.
    let idle = parse(&without_controller(&source()));
    let q = run(&idle, 300, false);
    assert!(
        q.summary.success_rate < 0.8,
        "no rules: {}",
        q.summary.success_rate
    );
    assert_eq!(q.summary.work.actuator_commands, 0);
}

#[test]
fn same_scenario_and_seed_give_the_same_summary() {
    let scene = parse(&source());
    let a = run(&scene, 120, true);
    let b = run(&scene, 120, true);
    assert_eq!(summary_json(&a), summary_json(&b));
    assert_eq!(a.records, b.records);
}

#[test]
fn passive_and_sensing_scenes_do_no_controller_work() {
    for file in [
        "scenarios/quickstart.toml",
        "scenarios/tripoly1_sensor.toml",
        "scenarios/tripoly1.toml",
    ] {
        let scene = scenario::load(Path::new(file)).unwrap();
        let r = run(&scene, 60, false);
        let w = r.summary.work;
        assert_eq!(
            (
                w.decisions,
                w.actuator_commands,
                w.late_actuations,
                w.replans,
                w.stale_events
            ),
            (0, 0, 0, 0, 0),
            "{file}"
        );
        assert!(r.summary.controller.is_none(), "{file}");
        assert!(r.control.is_empty());
    }
}

/// An actuator far too slow for the line: every command is late, counted, and (`skip`) the pin
/// stays where it is — the line is then exactly the line with a still pin at the home position.
#[test]
fn a_too_slow_actuator_counts_late_actuations_and_never_pushes_silently_wrong() {
    let slow = with(
        &source(),
        "speed = 0.1          # m/s",
        "speed = 0.0005       # m/s",
    );
    let scene = parse(&slow);
    let r = run(&scene, 90, true);
    let c = r.summary.controller.as_ref().unwrap();
    assert!(c.late_actuations > 0);
    assert_eq!(r.summary.work.late_actuations, c.late_actuations);
    // Commands for the home position need no motion and are never late: every other one is.
    assert_eq!(c.actuators[0].moves, 0, "{:?}", c.actuators[0]);
    // The same line with a still pin at the mover's home.
    let still = with(
        &with(&source(), "kind = \"moving_pin\"", "kind = \"pin\""),
        "travel = [-0.03, 0.03]   # m\nspeed = 0.1          # m/s\naccel = 1.0          # m/s²\nsettle = 0.05        # s\n",
        "",
    );
    let still = without_controller(&still);
    let s = run(&parse(&still), 90, true);
    let thetas = |r: &RunResult| {
        r.records
            .iter()
            .map(|p| (p.part, p.outcome, p.theta_out_deg))
            .collect::<Vec<_>>()
    };
    assert_eq!(thetas(&r), thetas(&s));
}

/// `on_late = "move"`: late moves are carried out, and parts may meet the pin in motion.
#[test]
fn late_moves_can_be_carried_out() {
    let text = with(
        &source(),
        "speed = 0.1          # m/s",
        "speed = 0.01         # m/s",
    );
    let text = with(&text, "on_late = \"skip\"", "on_late = \"move\"");
    let r = run(&parse(&text), 90, false);
    let c = r.summary.controller.as_ref().unwrap();
    assert!(c.late_actuations > 0);
    assert!(c.actuators[0].moves >= c.late_actuations);
    assert_eq!(r.summary.outcomes.total(), 90);
}

/// A retractable pin raised only for the parts read as 0° pushes exactly those parts.
#[test]
fn a_retractable_pin_pushes_only_the_parts_it_is_raised_for() {
    let text = with(
        &source(),
        "kind = \"moving_pin\"\nname = \"mover\"\nx = 0.27\ny = 0.012            # home (m)\nradius = 0.002\ntravel = [-0.03, 0.03]   # m\nspeed = 0.1          # m/s\naccel = 1.0          # m/s²\nsettle = 0.05        # s\n",
        "kind = \"retractable_pin\"\nname = \"mover\"\nx = 0.27\ny = 0.0\nradius = 0.002\nraised = false\nraise_time = 0.2\nlower_time = 0.2\n",
    );
    let text = with(&text, "y = 0.021", "raised = true");
    let text = with(&text, "y = 0.012\n", "raised = false\n");
    let text = with(&text, "y = -0.006", "raised = false");
    let r = run(&parse(&text), 150, true);
    let c = r.summary.controller.as_ref().unwrap();
    assert_eq!(c.late_actuations, 0);
    let zero = c.decisions["probe=0°"].parts;
    assert!(zero > 20);
    let mover = r
        .summary
        .obstacles
        .iter()
        .find(|o| o.name == "mover")
        .unwrap();
    assert_eq!(
        mover.contacts, zero,
        "the gate pushes the parts read as 0° and no others"
    );
}

/// A moving pin can carry a sensor: it reads the parts it pushes.
#[test]
fn a_moving_pin_can_sense() {
    let text = with(
        &source(),
        "settle = 0.05        # s\n",
        "settle = 0.05        # s\n\n[obstacles.sensor]\ntype = \"timing\"\nclassifier = \"timing\"\ntemplates = 8\n",
    );
    let r = run(&parse(&text), 30, false);
    assert_eq!(r.summary.sensors.len(), 2);
    assert!(
        r.summary.sensors[1].readings > 20,
        "{:?}",
        r.summary.sensors[1]
    );
}

#[test]
fn bad_rules_and_actuators_are_located_errors() {
    let src = source();
    let cases: Vec<(String, &str, &str)> = vec![
        (
            with(
                &src,
                "sensor = \"probe\"\ndecides = \"0°\"",
                "sensor = \"prob\"\ndecides = \"0°\"",
            ),
            "rules[0].sensor",
            "not a sensor pin",
        ),
        (
            with(&src, "decides = \"135°\"", "decides = \"136°\""),
            "rules[1].decides",
            "not a hypothesis of sensor \"probe\"",
        ),
        (
            with(
                &src,
                "pin = \"mover\"\ny = 0.021",
                "pin = \"merge1\"\ny = 0.021",
            ),
            "rules[0].pin",
            "not a moving or retractable pin",
        ),
        (
            with(&src, "y = 0.021", "y = 0.05"),
            "rules[0].y",
            "within the pin's travel",
        ),
        (
            with(&src, "y = 0.021", "raised = true"),
            "rules[0].pin",
            "is a moving pin",
        ),
        (
            with(&src, "travel = [-0.03, 0.03]", "travel = [-0.03, 0.07]"),
            "obstacles[1].travel",
            "over the belt",
        ),
        (
            with(&src, "travel = [-0.03, 0.03]", "travel = [0.02, 0.03]"),
            "obstacles[1].travel",
            "min ≤ y ≤ max",
        ),
        (
            with(&src, "speed = 0.1 ", "speed = 0.0 "),
            "obstacles[1].speed",
            "m/s",
        ),
        (
            with(&src, "accel = 1.0 ", "accel = -1.0 "),
            "obstacles[1].accel",
            "m/s²",
        ),
        (
            with(&src, "latency = 0.02 ", "latency = -1 "),
            "controller.latency",
            "s",
        ),
        (
            with(&src, "on_late = \"skip\"", "on_late = \"wait\""),
            "controller.on_late",
            "\"skip\"",
        ),
        (
            with(&src, "settle = 0.05 ", "settle = 0.05\nangle = 3 "),
            "obstacles[1].angle",
            "does not apply to a moving_pin",
        ),
    ];
    for (text, key, words) in cases {
        let e = refused(&text);
        assert!(e.starts_with("bad.toml:"), "{e}");
        assert!(
            e.contains(&format!("key `{key}`")),
            "expected key {key}: {e}"
        );
        assert!(e.contains(words), "expected '{words}': {e}");
    }
}

#[test]
fn a_policy_file_is_read_and_checked_against_the_part() {
    let dir = std::env::temp_dir().join(format!("pinfeed-policy-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let src = source();
    let base = src.split("[[rules]]").next().unwrap().to_string();
    let scenario = base.replace(
        "on_late = \"skip\"",
        "on_late = \"skip\"\npolicy = \"p.toml\"",
    )
        + "[goal]\n[[goal.sets]]\nname = \"one-set\"\norientations = [6.3]\ntolerance = 3.0\n";
    let rules: String = src
        .split("[[rules]]")
        .skip(1)
        .map(|r| format!("[[rules]]{}", r.split("[goal]").next().unwrap()))
        .collect();
    let file = dir.join("s.toml");
    std::fs::write(&file, &scenario).unwrap();
    // A policy planned for this part: the same line as the rules in the scenario.
    std::fs::write(dir.join("p.toml"), format!("part = \"tripoly1\"\n{rules}")).unwrap();
    let scene = scenario::load(&file).unwrap_or_else(|e| panic!("{e}"));
    let c = scene.controller.as_ref().unwrap();
    assert_eq!(c.rules.len(), 3);
    assert!(c.source.ends_with("p.toml"));
    let from_file = run(&scene, 60, false);
    let inline = run(&parse(&src), 60, false);
    assert_eq!(from_file.summary.outcomes, inline.summary.outcomes);
    // A policy for another part is refused, located in the policy file.
    std::fs::write(dir.join("p.toml"), format!("part = \"tripoly2\"\n{rules}")).unwrap();
    let e = scenario::load(&file).unwrap_err().to_string();
    assert!(
        e.contains("p.toml:1:")
            && e.contains("key `part`")
            && e.contains("planned for part \"tripoly2\""),
        "{e}"
    );
    // A rule in the policy naming an unknown pin: located in the policy file.
    std::fs::write(
        dir.join("p.toml"),
        format!(
            "part = \"tripoly1\"\n{}",
            rules.replacen("pin = \"mover\"", "pin = \"nope\"", 1)
        ),
    )
    .unwrap();
    let e = scenario::load(&file).unwrap_err().to_string();
    assert!(e.contains("p.toml:") && e.contains("rules[0].pin"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A pin in use never moves: with decisions so slow that they arrive while parts are being pushed
/// by the moving pin (and late moves carried out), no move starts during a contact with it.
#[test]
fn a_pin_in_contact_never_starts_moving() {
    use pinfeed::engine::event_queue::EventKind;
    let text = with(&source(), "latency = 0.02 ", "latency = 2.1 ");
    let text = with(&text, "on_late = \"skip\"", "on_late = \"move\"");
    let text = text.replace("[model]", "[effects]\nevent_log = true\n\n[model]");
    let r = run(&parse(&text), 80, false);
    let c = r.summary.controller.as_ref().unwrap();
    assert!(c.late_actuations > 0, "{c:?}");
    assert!(c.actuators[0].utilisation <= 1.0);
    // Contacts with the mover (obstacle 1): [begin, end] per part.
    let mut open = std::collections::BTreeMap::new();
    let mut contacts = Vec::new();
    for e in &r.events {
        match e.kind {
            EventKind::ContactBegin { part, obstacle: 1 } => {
                open.insert(part, e.time);
            }
            EventKind::ContactEnd { part, obstacle: 1 } => {
                contacts.push((open.remove(&part).unwrap(), e.time));
            }
            _ => {}
        }
    }
    assert!(contacts.len() > 40);
    let moves: Vec<_> = r.control.iter().filter_map(|rec| rec.motion).collect();
    assert!(!moves.is_empty());
    for m in &moves {
        for &(b, e) in &contacts {
            assert!(
                !(m.t_start > b && m.t_start < e),
                "a move starts at {} during a contact [{b}, {e}]",
                m.t_start
            );
        }
    }
}
