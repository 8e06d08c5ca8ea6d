//! The csvs fuzz target: measured-band CSV files
//! ([`crate::study::robustness::measured_csv`]: seed rows with mutations) and a random set of the
//! flags of `pinfeed validate` and `pinfeed calibrate` (friction, pin radius, `--uncertain`,
//! `--part`, the score's settings, the members). Three cases in four validate with at most 5
//! members, one in four calibrates with 10 members over the full grid. The file is read from disk
//! as the commands read it; every number of an accepted report must be finite.

use crate::cli::calibrate::CalibrateArgs;
use crate::cli::validate::ValidateArgs;
use crate::random::ChaCha8Rng;
use crate::study::robustness::measured_csv::random_text;
use crate::study::robustness::{refused, shows_non_finite, CaseReport, Class, CommandCases};
use crate::validate::input::load_measured;
use clap::Parser;
use rand::RngExt;
use std::path::Path;

/// A case: the CSV text and the command's arguments (after the file name).
#[derive(Debug, Clone, PartialEq)]
pub struct CsvCase {
    pub calibrate: bool,
    pub text: String,
    pub args: Vec<String>,
}

fn pick<'a>(rng: &mut ChaCha8Rng, values: &[&'a str]) -> &'a str {
    values[rng.random_range(0..values.len())]
}

impl CsvCase {
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
        let words: Vec<String> = self
            .args
            .iter()
            .map(|a| crate::report::shell_word(a))
            .collect();
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

/// The cases of the csvs target, for the fuzzing driver: a case runs with its file written into
/// its folder; its input is the command line with the file's text.
pub const CASES: CommandCases = CommandCases {
    run: |rng, scratch| run(&CsvCase::random(rng), scratch),
    input: |rng| {
        let c = CsvCase::random(rng);
        format!(
            "{}\n# measured.csv:\n{}",
            c.command(Path::new("measured.csv")),
            c.text
        )
    },
};

#[derive(Parser)]
struct ValidateCommand {
    #[command(flatten)]
    args: ValidateArgs,
}

#[derive(Parser)]
struct CalibrateCommand {
    #[command(flatten)]
    args: CalibrateArgs,
}

/// Run a case with its file written into the folder `scratch`.
pub fn run(c: &CsvCase, scratch: &Path) -> CaseReport {
    let _ = std::fs::create_dir_all(scratch);
    let path = scratch.join("measured.csv");
    if let Err(e) = std::fs::write(&path, &c.text) {
        return CaseReport::with(Class::Named, format!("cannot write the file: {e}"));
    }
    let mut r = if c.calibrate {
        run_calibrate(c, &path)
    } else {
        run_validate(c, &path)
    };
    if r.class.is_problem() {
        r.detail = format!("{}: {}", c.command(&path), r.detail);
    }
    r.kind = Some(if c.calibrate { "calibrate" } else { "validate" }.into());
    r
}

fn argv(c: &CsvCase, command: &str, path: &Path) -> Vec<String> {
    let mut v = vec![command.to_string(), path.display().to_string()];
    v.extend(c.args.iter().cloned());
    v
}

fn run_validate(c: &CsvCase, path: &Path) -> CaseReport {
    let a = match ValidateCommand::try_parse_from(argv(c, "validate", path)) {
        Ok(a) => a.args,
        Err(e) => return refused(&e.to_string()),
    };
    let (score, spec, m) = match a.inputs() {
        Ok(x) => x,
        Err(e) => return refused(&format!("{e:#}")),
    };
    match crate::validate::validate(&m, &spec, a.common.seed, a.members, a.common.passes, &score) {
        Err(e) => refused(&e),
        Ok((rows, summary, _)) => {
            if shows_non_finite(&format!("{rows:?} {summary:?}")) {
                CaseReport::with(Class::NonFinite, "a row or the summary holds NaN or inf")
            } else {
                CaseReport::new(Class::Success)
            }
        }
    }
}

fn run_calibrate(c: &CsvCase, path: &Path) -> CaseReport {
    let a = match CalibrateCommand::try_parse_from(argv(c, "calibrate", path)) {
        Ok(a) => a.args,
        Err(e) => return refused(&e.to_string()),
    };
    let checked = (|| {
        let s = crate::cli::calibrate::settings(&a)?;
        let m = load_measured(&a.measured, &s.proposal(), a.common.part.as_deref())?;
        anyhow::Ok((s, m))
    })();
    let (s, m) = match checked {
        Ok(x) => x,
        Err(e) => return refused(&format!("{e:#}")),
    };
    let cal = match crate::validate::calibrate::calibrate(&m, &s) {
        Ok(cal) => cal,
        Err(e) => return refused(&e),
    };
    let fitted = s.spec_at(cal.estimate());
    let scored =
        crate::validate::validate(&m, &fitted, s.seed, a.score_members, s.passes, &s.score);
    match scored {
        Err(e) => refused(&e),
        Ok((rows, summary, _)) => {
            if shows_non_finite(&format!("{cal:?} {rows:?} {summary:?}")) {
                CaseReport::with(
                    Class::NonFinite,
                    "the calibration or the fitted score holds NaN or inf",
                )
            } else {
                CaseReport::new(Class::Success)
            }
        }
    }
}
