//! The command-line inputs of the plans and csvs fuzz targets: random `pinfeed plan` argument
//! sets ([`plan_arguments`]) and random measured-band files with `validate` or `calibrate`
//! arguments ([`CsvCase`]). They are plain words and text; `pinfeed fuzz` runs them through the
//! commands' own argument parsers (which is why running them lives with the command line).

use crate::output::shell_word;
use crate::random::ChaCha8Rng;
use crate::study::robustness::measured_csv::random_text;
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

/// The argument list of a plans case (after `pinfeed plan`).
pub fn plan_arguments(rng: &mut ChaCha8Rng) -> Vec<String> {
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

/// The command line of a plans case.
pub fn plan_command(args: &[String]) -> String {
    let words: Vec<String> = args.iter().map(|a| shell_word(a)).collect();
    format!("pinfeed plan {}", words.join(" "))
}

/// A case: the CSV text and the command's arguments (after the file name).
#[derive(Debug, Clone, PartialEq)]
pub struct CsvCase {
    /// `pinfeed calibrate` (one case in four) rather than `pinfeed validate`.
    pub calibrate: bool,
    /// The measured-bands file's text.
    pub text: String,
    /// The command's arguments after the file name, each `--flag=value` or a switch.
    pub args: Vec<String>,
}

fn pick<'a>(rng: &mut ChaCha8Rng, values: &[&'a str]) -> &'a str {
    values[rng.random_range(0..values.len())]
}

impl CsvCase {
    /// A case drawn from `rng`: a mutated seed file and a random set of the command's flags.
    pub fn random(rng: &mut ChaCha8Rng) -> CsvCase {
        let text = random_text(rng);
        let calibrate = rng.random_range(0..4u32) == 0;
        let mut args: Vec<String> = Vec::new();
        let mut flag = |rng: &mut ChaCha8Rng, name: &str, values: &[&str], p: f64| {
            if rng.random::<f64>() < p {
                args.push(format!("{name}={}", pick(rng, values)));
            }
        };
        if calibrate {
            flag(rng, "--members", &["10"], 1.0);
            flag(rng, "--score-members", &["3", "5", "0"], 1.0);
            flag(rng, "--jitter", &["0", "3", "90", "91", "nan"], 0.5);
            flag(rng, "--support", &["tripod", "smooth", "uniform"], 0.3);
            flag(
                rng,
                "--mu-c-range",
                &["0.05:1", "0:10", "1:0.05", "0:0.01", "a"],
                0.3,
            );
            flag(
                rng,
                "--pin-radius-max",
                &["0.3", "1e-9", "1e3", "1e308", "0", "-1"],
                0.3,
            );
            flag(rng, "--pin-radius-sd", &["0.03", "1e-9", "0", "nan"], 0.3);
            flag(rng, "--mu-c", &["0.5", "0", "10", "11"], 0.2);
        } else {
            flag(rng, "--members", &["1", "2", "3", "5", "0", "1000001"], 1.0);
            flag(rng, "--mu-c", &["0.5", "0", "10", "11", "-1", "nan"], 0.3);
            flag(
                rng,
                "--pin-radius",
                &["0", "0.1", "10", "1e308", "-1", "inf"],
                0.3,
            );
            flag(
                rng,
                "--uncertain",
                &[
                    "mu_c=normal:0.5:0.1",
                    "pin_radius=uniform:0:0.1,jitter=2",
                    "support=tripod:0.5",
                    "support=smooth:1",
                    "mu_c=normal:0.5:-1",
                    "jitter=1e9",
                    "bogus=1",
                    "pin_radius=normal:0.12:0.03",
                    "pin_radius=normal:1e308:1",
                    "mu_c=triangular:0:0.5:1,jitter=90",
                ],
                0.5,
            );
        }
        flag(
            rng,
            "--part",
            &["tripoly1", "vertices:0,0 36,0 8,22", "bogus", "ngon:3"],
            0.2,
        );
        flag(rng, "--model", &["exact", "ellipsoid", "tip", "map"], 0.2);
        flag(rng, "--tol", &["1e-6", "1e-12", "1e-2", "0", "1"], 0.2);
        flag(rng, "--passes", &["1", "2", "0", "101"], 0.2);
        flag(rng, "--kernel", &["2", "0.01", "90", "0", "91"], 0.2);
        flag(rng, "--floor", &["0.01", "1e-9", "1", "0", "2"], 0.2);
        flag(rng, "--window", &["20", "0", "180", "181"], 0.2);
        flag(
            rng,
            "--contained-share",
            &["0.8", "0.01", "1", "0", "1.5", "nan"],
            0.2,
        );
        args.extend(["--threads=1", "--no-write"].map(String::from));
        CsvCase {
            calibrate,
            text,
            args,
        }
    }

    /// The command of a case with its file at `path`.
    pub fn command(&self, path: &Path) -> String {
        let words: Vec<String> = self.args.iter().map(|a| shell_word(a)).collect();
        format!(
            "pinfeed {} {} {}",
            if self.calibrate {
                "calibrate"
            } else {
                "validate"
            },
            path.display(),
            words.join(" ")
        )
    }
}
