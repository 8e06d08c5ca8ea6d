//! Sensing, actuator, controller and policy scenarios with *pairs* of keys moved together: the
//! bundled scenarios that have a sensor pin, a moving or retractable pin or a controller (their
//! classifier templates cut to 4 per hypothesis, so a case stays cheap), each either as bundled or
//! with its rules moved into a policy file (`[controller] policy`). A case picks two keys from
//! [`PAIR_KEYS`] (a moving pin's speed and acceleration, a sensor's rate and noise, a rule's
//! target and the controller's latency, …) and gives each a value from its list — values inside
//! the documented ranges, at their ends and beyond them — then parses, compiles and runs the
//! scenario for a few parts ([`super::files::check_scenario`]). The policy file, when there is
//! one, is written beside the scenario in a fresh temporary folder for the case.

use super::files::{check_scenario, Seeds};
use super::CaseReport;
use crate::random::ChaCha8Rng;
use rand::RngExt;
use std::path::{Path, PathBuf};

/// What a case of the pairs target is (in the fuzz report).
pub const DESCRIPTION: &str = "the bundled scenarios with a sensor pin, a moving or retractable pin or a controller, except those with the online controller (classifier templates cut to 4), as bundled or with their rules moved into a policy file, with two keys of the sensor, the actuators, the controller (its mode included: rules or the online belief), the rules or the policy set together to values inside, at the ends of and beyond their ranges; parsed, compiled and run for at most 3 parts";

/// Where a key lives: a section, an obstacle of a kind, its sensor table, a rule, the policy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Place {
    /// A plain section (`[controller]`, `[belt]`, …).
    Section(&'static str),
    /// The `[[obstacles]]` entry of this kind.
    Obstacle(&'static str),
    /// The `[obstacles.sensor]` table.
    Sensor,
    /// One of the `[[rules]]` (in the scenario or in the policy file).
    Rule,
    /// The top of the policy file (`part = …`).
    PolicyTop,
}

/// The keys moved in pairs and the values each takes.
pub const PAIR_KEYS: [(Place, &str, &[&str]); 31] = [
    (
        Place::Obstacle("moving_pin"),
        "speed",
        &["0.1", "60", "1e-6", "1000", "50", "0", "-1", "nan"],
    ),
    (
        Place::Obstacle("moving_pin"),
        "accel",
        &["1", "1e6", "1e-6", "0", "1e308", "inf"],
    ),
    (
        Place::Obstacle("moving_pin"),
        "settle",
        &["0", "0.05", "1e4", "-1", "1e308"],
    ),
    (
        Place::Obstacle("moving_pin"),
        "pieces",
        &["1", "4", "64", "0", "100000"],
    ),
    (
        Place::Obstacle("moving_pin"),
        "travel",
        &[
            "[-0.03, 0.03]",
            "[0.03, -0.03]",
            "[-0.06, 0.06]",
            "[0, 0]",
            "[-1, 1]",
            "[]",
        ],
    ),
    (
        Place::Obstacle("moving_pin"),
        "y",
        &["0.012", "0.03", "-0.03", "0.0599", "1", "nan"],
    ),
    (
        Place::Obstacle("moving_pin"),
        "x",
        &["0.27", "0.0341", "0.8999", "0", "-0.1"],
    ),
    (
        Place::Obstacle("moving_pin"),
        "radius",
        &["0.002", "0", "0.12", "1e-300", "-0.002"],
    ),
    (
        Place::Obstacle("retractable_pin"),
        "raise_time",
        &["0.1", "0", "1e4", "-1", "nan"],
    ),
    (
        Place::Obstacle("retractable_pin"),
        "lower_time",
        &["0.1", "0", "1e4", "1e5"],
    ),
    (
        Place::Obstacle("sensor_pin"),
        "y",
        &["-0.007", "0.06", "-0.06", "0", "0.5"],
    ),
    (
        Place::Obstacle("sensor_pin"),
        "radius",
        &["0.002", "0", "0.12", "-1"],
    ),
    (
        Place::Sensor,
        "type",
        &["\"ft\"", "\"timing\"", "\"bogus\""],
    ),
    (
        Place::Sensor,
        "rate",
        &["1000", "1", "1e5", "0.5", "1e6", "nan"],
    ),
    (Place::Sensor, "height", &["0.02", "0", "10", "11", "-0.01"]),
    (
        Place::Sensor,
        "noise_force",
        &["0.0125", "0", "1e6", "1e7", "-1"],
    ),
    (Place::Sensor, "bias_force", &["0", "1e6", "-1e6", "1e7"]),
    (Place::Sensor, "drift_torque", &["0", "1e9", "-1e9", "1e10"]),
    (
        Place::Sensor,
        "lowpass",
        &["200", "1e-3", "1e6", "0", "1e7"],
    ),
    (
        Place::Sensor,
        "threshold",
        &["0.05", "1e-9", "1e6", "0", "-1"],
    ),
    (Place::Sensor, "jitter", &["0.001", "0", "10", "11", "nan"]),
    (
        Place::Sensor,
        "classifier",
        &[
            "\"likelihood\"",
            "\"timing\"",
            "\"sign-matrix\"",
            "\"zero-crossings\"",
            "\"bogus\"",
        ],
    ),
    (
        Place::Sensor,
        "hypotheses",
        &[
            "\"stable\"",
            "\"vertex-edge\"",
            "[0, 135, 225]",
            "[]",
            "[0, 0]",
        ],
    ),
    (Place::Sensor, "templates", &["1", "4", "0", "1025"]),
    (
        Place::Sensor,
        "reject_below",
        &["0", "0.5", "1", "1.5", "-0.1"],
    ),
    (
        Place::Section("controller"),
        "latency",
        &["0.02", "0", "1e4", "1e5", "-1", "nan"],
    ),
    (
        Place::Section("controller"),
        "on_late",
        &["\"skip\"", "\"move\"", "\"wait\""],
    ),
    (
        Place::Section("controller"),
        "mode",
        &["\"policy\"", "\"online\"", "\"bogus\""],
    ),
    (
        Place::Rule,
        "y",
        &["0.021", "-0.006", "0.03", "-0.03", "0.031", "1e308"],
    ),
    (
        Place::Rule,
        "decides",
        &[
            "\"0°\"",
            "\"135°\"",
            "\"225°\"",
            "\"unknown\"",
            "\"90°\"",
            "\"\"",
        ],
    ),
    (
        Place::PolicyTop,
        "part",
        &["\"tripoly1\"", "\"tripoly2\"", "\"square\"", "\"\""],
    ),
];

/// The seed scenarios of this target: bundled ones with a sensor, an actuator or a controller.
pub fn seeds(files: &Seeds) -> Vec<(PathBuf, String)> {
    files
        .scenarios
        .iter()
        .filter(|(p, t)| {
            // The online controller builds its model per case (a third of a second): it is
            // reached through the `mode` key instead of as a seed.
            !p.components().any(|c| c.as_os_str() == "fixtures")
                && !t.contains("mode = \"online\"")
                && [
                    "sensor_pin",
                    "moving_pin",
                    "retractable_pin",
                    "[controller]",
                ]
                .iter()
                .any(|k| t.contains(k))
        })
        .flat_map(|(p, t)| {
            let t = t.replace("templates = 32", "templates = 4");
            let retractable =
                retractable_variant(&t).map(|r| (p.with_extension("retractable.toml"), r));
            std::iter::once((p.clone(), t)).chain(retractable)
        })
        .collect()
}

/// A seed's moving pin made a retractable one (its rules raise it for the first decision and
/// lower it for the others), or `None` without a moving pin.
fn retractable_variant(text: &str) -> Option<String> {
    if !text.contains("\"moving_pin\"") {
        return None;
    }
    let mut out = Vec::new();
    let (mut in_mover, mut in_rules, mut first_rule) = (false, false, true);
    for l in text.lines() {
        if let Some(h) = header(l) {
            in_rules = h == "rules";
            in_mover = false;
            if in_rules && !first_rule {
                out.push(l.to_string());
                continue;
            }
        }
        if l.contains("\"moving_pin\"") {
            in_mover = true;
            out.push(l.replace("\"moving_pin\"", "\"retractable_pin\""));
            continue;
        }
        let key = l.split('=').next().unwrap_or("").trim();
        if in_mover && ["travel", "speed", "accel", "settle", "pieces"].contains(&key) {
            continue;
        }
        if in_rules && key == "y" {
            out.push(format!("raised = {first_rule}"));
            first_rule = false;
            continue;
        }
        out.push(l.to_string());
    }
    Some(out.join("\n") + "\n")
}

/// A case: the seed, whether its rules move into a policy file, and the two (key, value) picks.
#[derive(Debug, Clone, PartialEq)]
pub struct PairCase {
    /// Index of the seed scenario.
    pub seed: usize,
    /// The scenario's rules move into a policy file.
    pub policy: bool,
    /// The two (key, value) picks: an index of the key, and of its candidate value.
    pub picks: [(usize, usize); 2],
}

impl PairCase {
    /// Draw a case for the seeds `seeds` (rules move into a policy file only where there are some).
    pub fn random(seeds: &[(PathBuf, String)], rng: &mut ChaCha8Rng) -> PairCase {
        let seed = rng.random_range(0..seeds.len().max(1));
        let has_rules = seeds
            .get(seed)
            .is_some_and(|(_, t)| t.contains("[[rules]]"));
        let policy = rng.random::<bool>() && has_rules;
        let k1 = rng.random_range(0..PAIR_KEYS.len());
        // Two different keys.
        let k2 = (k1 + rng.random_range(1..PAIR_KEYS.len())) % PAIR_KEYS.len();
        let v = |rng: &mut ChaCha8Rng, k: usize| rng.random_range(0..PAIR_KEYS[k].2.len());
        let picks = [(k1, v(rng, k1)), (k2, v(rng, k2))];
        PairCase {
            seed,
            policy,
            picks,
        }
    }

    /// What the case changes, for the report.
    pub fn describe(&self, seed_path: &Path) -> String {
        let picks: Vec<String> = self
            .picks
            .iter()
            .map(|&(k, v)| {
                let (place, key, values) = PAIR_KEYS[k];
                format!("{place:?} {key} = {}", values[v])
            })
            .collect();
        format!(
            "{}{} with {}",
            seed_path
                .file_name()
                .and_then(|s| s.to_str())
                .unwrap_or("?"),
            if self.policy {
                " (rules in a policy file)"
            } else {
                ""
            },
            picks.join(" and ")
        )
    }
}

/// A header's table name (`[a.b]` or `[[a]]` → `a.b` / `a`).
fn header(line: &str) -> Option<&str> {
    super::files::header_name(line)
}

/// The blocks of `lines`: (header line index or None for the top, end index).
fn blocks(lines: &[String]) -> Vec<(Option<usize>, usize)> {
    let heads: Vec<usize> = (0..lines.len())
        .filter(|&i| header(&lines[i]).is_some())
        .collect();
    let mut out = vec![(None, heads.first().copied().unwrap_or(lines.len()))];
    for (j, &h) in heads.iter().enumerate() {
        out.push((Some(h), heads.get(j + 1).copied().unwrap_or(lines.len())));
    }
    out
}

/// Set `key = value` in the block starting at header `h` (None: the top), or insert it.
fn set_in_block(lines: &mut Vec<String>, block: (Option<usize>, usize), key: &str, value: &str) {
    let start = block.0.map_or(0, |h| h + 1);
    for l in &mut lines[start..block.1] {
        let k = l.split('=').next().unwrap_or("").trim();
        if k == key && !l.trim_start().starts_with('#') {
            *l = format!("{key} = {value}");
            return;
        }
    }
    lines.insert(start, format!("{key} = {value}"));
}

/// Set a key at `place` in `lines` (nothing when the place is absent).
fn set(lines: &mut Vec<String>, place: Place, key: &str, value: &str, which: usize) {
    let bl = blocks(lines);
    let of = |name: &str| -> Vec<(Option<usize>, usize)> {
        bl.iter()
            .filter(|b| b.0.is_some_and(|h| header(&lines[h]) == Some(name)))
            .copied()
            .collect()
    };
    let target = match place {
        Place::Section(s) => of(s).first().copied(),
        Place::Obstacle(kind) => of("obstacles").into_iter().find(|b| {
            lines[b.0.unwrap_or(0)..b.1]
                .iter()
                .any(|l| l.contains(&format!("\"{kind}\"")))
        }),
        Place::Sensor => of("obstacles.sensor").first().copied(),
        Place::Rule => {
            let rules = of("rules");
            (!rules.is_empty()).then(|| rules[which % rules.len()])
        }
        Place::PolicyTop => None,
    };
    if let Some(b) = target {
        set_in_block(lines, b, key, value);
    }
}

/// Split a scenario's `[[rules]]` off into a policy file: (scenario text, policy text).
fn split_policy(text: &str, policy_name: &str) -> (String, String) {
    let lines: Vec<String> = text.lines().map(str::to_string).collect();
    let part = lines
        .iter()
        .find_map(|l| {
            let (k, v) = l.split_once('=')?;
            (k.trim() == "shape").then(|| v.split('#').next().unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "\"tripoly1\"".into());
    let mut scenario = Vec::new();
    let mut policy = vec![format!("part = {part}"), String::new()];
    let mut in_rules = false;
    for l in &lines {
        if let Some(h) = header(l) {
            in_rules = h == "rules";
        }
        if in_rules {
            policy.push(l.clone());
        } else {
            scenario.push(l.clone());
        }
    }
    let bl = blocks(&scenario);
    let controller = bl
        .iter()
        .find(|b| {
            b.0.is_some_and(|h| header(&scenario[h]) == Some("controller"))
        })
        .copied();
    match controller {
        Some(b) => set_in_block(&mut scenario, b, "policy", &format!("\"{policy_name}\"")),
        None => {
            scenario.push("[controller]".into());
            scenario.push(format!("policy = \"{policy_name}\""));
        }
    }
    (scenario.join("\n") + "\n", policy.join("\n") + "\n")
}

/// The texts of a case: (scenario, policy file if any).
pub fn texts(c: &PairCase, seed_text: &str) -> (String, Option<String>) {
    let (scenario, policy) = if c.policy {
        let (s, p) = split_policy(seed_text, POLICY_NAME);
        (s, Some(p))
    } else {
        (seed_text.to_string(), None)
    };
    let mut s: Vec<String> = scenario.lines().map(str::to_string).collect();
    let mut p: Option<Vec<String>> = policy.map(|p| p.lines().map(str::to_string).collect());
    for (n, &(k, v)) in c.picks.iter().enumerate() {
        let (place, key, values) = PAIR_KEYS[k];
        match (place, p.as_mut()) {
            (Place::Rule, Some(pl)) => set(pl, place, key, values[v], n),
            (Place::PolicyTop, Some(pl)) => {
                set_in_block(pl, (None, blocks(pl)[0].1), key, values[v])
            }
            (Place::PolicyTop, None) => {}
            _ => set(&mut s, place, key, values[v], n),
        }
    }
    (s.join("\n") + "\n", p.map(|p| p.join("\n") + "\n"))
}

/// The policy file's name beside the scenario.
pub const POLICY_NAME: &str = "fuzz.policy.toml";

/// Run a case: write its files into a fresh folder, then parse, compile and run.
pub fn run(c: &PairCase, seeds: &[(PathBuf, String)], scratch: &Path) -> CaseReport {
    let Some((seed_path, seed_text)) = seeds.get(c.seed) else {
        return CaseReport::with(super::Class::Unlocated, "no seed scenario");
    };
    let (scenario, policy) = texts(c, seed_text);
    let dir = scratch;
    let _ = std::fs::create_dir_all(dir);
    let path = dir.join(seed_path.file_name().unwrap_or_default());
    if let Some(p) = &policy {
        if let Err(e) = std::fs::write(dir.join(POLICY_NAME), p) {
            return CaseReport::with(super::Class::Named, format!("cannot write the policy: {e}"));
        }
    }
    let mut r = check_scenario(&path, &scenario);
    if r.class.is_problem() {
        r.detail = format!("{}: {}", c.describe(seed_path), r.detail);
    }
    r.kind = Some(
        if c.policy {
            "rules in a policy file"
        } else {
            "rules in the scenario"
        }
        .into(),
    );
    r
}
