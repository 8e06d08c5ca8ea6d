//! The csvs fuzz target: measured-band CSV files
//! ([`pinfeed::study::robustness::measured_csv`]: seed rows with mutations) and a random set of the
//! flags of `pinfeed validate` and `pinfeed calibrate` (friction, pin radius, `--uncertain`,
//! `--part`, the score's settings, the members). Three cases in four validate with at most 5
//! members, one in four calibrates with 10 members over the full grid. The file is read from disk
//! as the commands read it; every number of an accepted report must be finite.

use crate::calibrate::CalibrateArgs;
use crate::validate::load_measured;
use crate::validate::ValidateArgs;
use clap::Parser;
use pinfeed::study::robustness::commands::CsvCase;
use pinfeed::study::robustness::{refused, shows_non_finite, CaseReport, Class, CommandCases};
use std::path::Path;

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
    match pinfeed::validate::validate(&m, &spec, a.common.seed, a.members, a.common.passes, &score)
    {
        Err(e) => refused(&e.to_string()),
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
        let s = crate::calibrate::settings(&a)?;
        let m = load_measured(&a.measured, &s.proposal(), a.common.part.as_deref())?;
        anyhow::Ok((s, m))
    })();
    let (s, m) = match checked {
        Ok(x) => x,
        Err(e) => return refused(&format!("{e:#}")),
    };
    let cal = match pinfeed::validate::calibrate::calibrate(&m, &s) {
        Ok(cal) => cal,
        Err(e) => return refused(&e.to_string()),
    };
    let fitted = s.spec_at(cal.estimate());
    let scored =
        pinfeed::validate::validate(&m, &fitted, s.seed, a.score_members, s.passes, &s.score);
    match scored {
        Err(e) => refused(&e.to_string()),
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
