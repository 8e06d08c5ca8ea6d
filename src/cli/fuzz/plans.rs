//! `pinfeed plan` argument sets: a part and a short time limit (≤ 1 s), small line checks, one
//! thread and no files, plus 0–4 more flags from [`PLAN_FLAGS`] with values inside, at the ends of
//! and beyond their ranges. The arguments go through the command's own parser and checks
//! ([`crate::cli::plan::options_of`]) and the design workflow ([`crate::plan::design::design`]);
//! an accepted design's numbers must be finite and the scenario it would write (with its policy
//! file) must be accepted by the scenario parser and run ([`files::check_scenario`]) — a
//! written plan the parser refuses counts as a self-check disagreement.

use crate::cli::plan::PlanArgs;
use crate::random::ChaCha8Rng;
use crate::study::robustness::{files, refused, shows_non_finite, CaseReport, Class, CommandCases};
use clap::Parser;
use rand::RngExt;
use std::path::Path;

/// The parts a case plans for.
const PARTS: [&str; 12] = [
    "tripoly1",
    "tripoly2",
    "square",
    "rect:2:1",
    "lshape",
    "ngon:5",
    "ngon:40",
    "ngon:500",
    "random:3:7",
    "vertices:0,0 1,0 0,1",
    "vertices:0,0 1e-9,0 0,1e-9",
    "bogus",
];

/// Flags a case may add, with their values (an empty list: a switch).
pub const PLAN_FLAGS: [(&str, &[&str]); 36] = [
    (
        "--scale",
        &["0.02", "0.001", "1e-9", "1e9", "0", "-1", "nan"],
    ),
    ("--pins", &[]),
    ("--fences", &[]),
    ("--sensor", &[]),
    (
        "--objective",
        &[
            "belt-length",
            "obstacles",
            "actuators",
            "throughput",
            "bogus",
        ],
    ),
    ("--feed", &["stable", "uniform", "bogus"]),
    ("--jitter", &["0", "2", "45", "46", "1e9", "-1", "nan"]),
    ("--lateral", &["0", "0.002", "0.05", "1", "-1"]),
    ("--jitter-samples", &["0", "1", "5", "2000", "2001"]),
    ("--offset-samples", &["0", "1", "5", "2000", "2001"]),
    ("--orientation-samples", &["0", "1", "72", "2000", "2001"]),
    ("--mu-c", &["0", "0.5", "10", "11", "-1", "nan"]),
    (
        "--mu-c-range",
        &["0.3:0.7", "0.7:0.3", "a:b", "0:10", "0:11", "0.5"],
    ),
    ("--tripod", &[]),
    ("--pin-radius", &["0", "0.002", "0.05", "1", "-1"]),
    (
        "--belt-width",
        &["0.1", "0.12", "0.001", "10", "1e308", "0", "-1"],
    ),
    ("--spacing", &["0.15", "1e-6", "10", "1e6", "0", "-1"]),
    ("--max-pins", &["0", "1", "2", "8", "100", "1000000"]),
    ("--tolerance", &["0", "3", "179", "180", "1e9"]),
    ("--target", &["0", "0.5", "0.99", "1", "1.5"]),
    ("--fewest-sets", &[]),
    ("--min-margin", &["0", "0.5", "1e9", "-1"]),
    ("--y-quantum", &["0.25", "0", "1e-3", "1e-9", "1e9"]),
    (
        "--theta-quantum",
        &["0.25", "0.7", "0", "10", "360", "1e-9"],
    ),
    ("--coarse", &["0", "1", "4", "64", "65"]),
    ("--max-states", &["0", "1", "100", "1000000"]),
    ("--no-bound", &[]),
    ("--contact-tol", &["1e-5", "0", "1e-12", "1", "nan"]),
    ("--seed", &["0", "1", "18446744073709551615"]),
    ("--max-moving", &["0", "1", "3", "100"]),
    ("--sensor-candidates", &["0", "1", "6", "1000"]),
    ("--mu-f", &["0", "0.5", "5", "-1"]),
    ("--fence-overhang", &["0", "1", "1e9", "-1"]),
    ("--max-fence-angle", &["55", "0", "89.9", "90", "1e9"]),
    ("--fence-angle-step", &["5", "0", "1e-9", "90"]),
    ("--refine", &["0", "2", "100"]),
];

/// The arguments every case has: the part, the time limit, the line checks' parts, one thread,
/// no files, no progress display.
pub fn base_arguments(part: &str, time: &str, check: &str, screen: &str) -> Vec<String> {
    [
        "--part",
        part,
        "--time-limit",
        time,
        "--check-parts",
        check,
        "--screen-parts",
        screen,
        "--threads",
        "1",
        "--no-write",
        "--quiet",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

/// The argument list of a case (after `pinfeed plan`).
pub fn arguments(rng: &mut ChaCha8Rng) -> Vec<String> {
    let part = PARTS[rng.random_range(0..PARTS.len())];
    let time = ["0.05", "0.2", "1"][rng.random_range(0..3usize)];
    let check = ["0", "1", "50", "200"][rng.random_range(0..4usize)];
    let screen = ["1", "50", "200"][rng.random_range(0..3usize)];
    let mut a = base_arguments(part, time, check, screen);
    for _ in 0..rng.random_range(0..=4usize) {
        let (flag, values) = PLAN_FLAGS[rng.random_range(0..PLAN_FLAGS.len())];
        if values.is_empty() {
            a.push(flag.to_string());
        } else {
            a.push(format!(
                "{flag}={}",
                values[rng.random_range(0..values.len())]
            ));
        }
    }
    a
}

/// The cases of the plans target, for the fuzzing driver.
pub const CASES: CommandCases = CommandCases {
    run: |rng, scratch| run(&arguments(rng), scratch),
    input: |rng| command(&arguments(rng)),
};

/// The command line of a case.
pub fn command(args: &[String]) -> String {
    let words: Vec<String> = args.iter().map(|a| crate::report::shell_word(a)).collect();
    format!("pinfeed plan {}", words.join(" "))
}

#[derive(Parser)]
#[command(name = "plan")]
struct PlanCommand {
    #[command(flatten)]
    args: PlanArgs,
}

/// Run a case's arguments; `scratch` is a fresh folder for the written scenario.
pub fn run(args: &[String], scratch: &Path) -> CaseReport {
    let mut r = run_unlabelled(args, scratch);
    if r.class.is_problem() {
        r.detail = format!("{}: {}", command(args), r.detail);
    }
    r
}

fn run_unlabelled(args: &[String], scratch: &Path) -> CaseReport {
    let argv = std::iter::once("plan".to_string()).chain(args.iter().cloned());
    let parsed = match PlanCommand::try_parse_from(argv) {
        Ok(p) => p.args,
        Err(e) => return refused(&e.to_string()),
    };
    let o = match crate::cli::plan::options_of(&parsed) {
        Ok(o) => o,
        Err(e) => return refused(&format!("{e:#}")),
    };
    let d = match crate::plan::design::design(&o, &|_| {}) {
        Ok(d) => d,
        Err(e) => return refused(&e.to_string()),
    };
    if shows_non_finite(&format!("{d:?}")) {
        return CaseReport::with(Class::NonFinite, "the design holds NaN or inf");
    }
    let Some(toml) = &d.scenario_toml else {
        return CaseReport::new(Class::Success);
    };
    let _ = std::fs::create_dir_all(scratch);
    if let Some((name, text)) = &d.policy_toml {
        let file = Path::new(name).file_name().unwrap_or_default();
        if let Err(e) = std::fs::write(scratch.join(file), text) {
            return CaseReport::with(Class::Named, format!("cannot write the policy: {e}"));
        }
    }
    let written = files::check_scenario(&scratch.join("plan.toml"), toml);
    match written.class {
        Class::Success => CaseReport::new(Class::Success),
        Class::Located | Class::Named | Class::Unlocated => CaseReport::with(
            Class::Disagreement,
            format!(
                "the scenario the design writes is refused ({:?}{})",
                written.class,
                if written.detail.is_empty() {
                    String::new()
                } else {
                    format!(": {}", written.detail)
                }
            ),
        ),
        _ => written,
    }
}
