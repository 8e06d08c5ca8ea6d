//! `pinfeed validate MEASURED.csv`: measured bands against an ensemble's predictions (
//! [`pinfeed::validate`]). Standard output gets one line per measured row (contained, overlapping,
//! centre offset, predicted probability of the measured band, log score, predicted bands) and the
//! summary; `--json` prints the whole report instead. Unless `--no-write`, the report directory
//! (`pinfeed-out/validate/<file stem>/`) receives `README.md` headed by the regenerating command,
//! `validate.json` and one figure per (part, input): the measured bands over the predicted
//! distributions and bands against d.

use anyhow::{Context, Result};
use clap::Args;
use pinfeed::maps::ensemble::EnsembleSpec;
use pinfeed::mechanics::limits::in_range;
use pinfeed::report::validate_report::{containment_text, rows_text, write_report, ValidateReport};
use pinfeed::validate::input::{self, InputError, Setting};
use pinfeed::validate::measured::Measured;
use pinfeed::validate::score::ScoreSettings;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The model and scoring options `validate` and `calibrate` share.
#[derive(Debug, Args, Clone)]
pub struct ModelArgs {
    /// The part of every row (e.g. vertices:"0,0 36,0 8,22" or tripoly1): the file's part column
    /// may then be left out, and when present this part replaces it.
    #[arg(long, value_name = "PART", allow_hyphen_values = true)]
    pub part: Option<String>,
    /// Fidelity: exact, ellipsoid or tip.
    #[arg(long, default_value = "exact", value_parser = pinfeed::contact_case::parse_model)]
    pub model: pinfeed::mechanics::Fidelity,
    /// Integration tolerance.
    #[arg(long, default_value_t = 1e-6, allow_hyphen_values = true)]
    pub tol: f64,
    /// Passes per member and measured row.
    #[arg(long, default_value_t = 1)]
    pub passes: usize,
    /// Seed of the ensemble.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Log score: kernel sd h in degrees (the measurement error of a band end).
    #[arg(long, default_value_t = 2.0, allow_hyphen_values = true)]
    pub kernel: f64,
    /// Log score: weight of the uniform floor ε.
    #[arg(long, default_value_t = 0.01, allow_hyphen_values = true)]
    pub floor: f64,
    /// Log score: window (degrees each side) for rows with input `all`.
    #[arg(long, default_value_t = 20.0, allow_hyphen_values = true)]
    pub window: f64,
    /// Containment: the least share of the predicted mass inside a measured band (for input
    /// `all`, of the mass within --window of it) for the band to count as contained.
    #[arg(long, default_value_t = pinfeed::validate::score::CONTAINED_SHARE, allow_hyphen_values = true)]
    pub contained_share: f64,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Report directory [default: pinfeed-out/<command>/<file stem>].
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
    /// Print only; write no files.
    #[arg(long, conflicts_with = "out_dir")]
    pub no_write: bool,
    /// Worker threads (0: one per core); the result does not depend on it.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
}

impl ModelArgs {
    /// The score settings and the model's, checked.
    pub fn score(&self) -> Result<ScoreSettings> {
        let (lo, hi) = pinfeed::mechanics::limits::TOL;
        in_range("--tol", self.tol, lo, hi, "per step")?;
        in_range("--passes", self.passes as f64, 1.0, 100.0, "passes")?;
        let max = pinfeed::maps::limits::MAX_THREADS as f64;
        in_range(
            "--threads",
            self.threads as f64,
            0.0,
            max,
            "0: one per core",
        )?;
        let (k, f, w, c) = (self.kernel, self.floor, self.window, self.contained_share);
        ScoreSettings::checked(k, f, w, c).map_err(|mut e| {
            e.name = super::flag(&e.name);
            e.into()
        })
    }

    /// The report directory for `command` and the measured file.
    pub fn out_dir(&self, command: &str, file: &Path) -> PathBuf {
        self.out_dir.clone().unwrap_or_else(|| {
            let stem = file
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("measured");
            pinfeed::default_out(&[command, &super::part_folder(stem)])
        })
    }
}

/// Arguments of `pinfeed validate`.
#[derive(Debug, Args)]
pub struct ValidateArgs {
    /// The measured-bands file (CSV; docs/commands.md#validating-against-measurements-pinfeed-validate-pinfeed-calibrate).
    pub measured: PathBuf,
    /// Uncertain parameters, as for `pinfeed map --uncertain` (none: the nominal model).
    #[arg(long, value_name = "KEY=VALUE,...")]
    pub uncertain: Option<String>,
    /// Nominal pin–part friction μc (replaced by `mu_c=` in --uncertain).
    #[arg(long, default_value_t = 0.5, allow_hyphen_values = true)]
    pub mu_c: f64,
    /// Nominal pin radius in part units, as `contact --pin-radius` (replaced by
    /// `pin_radius=` in --uncertain).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub pin_radius: f64,
    /// Members of the ensemble.
    #[arg(long, default_value_t = pinfeed::validate::DEFAULT_MEMBERS)]
    pub members: usize,
    #[command(flatten)]
    pub common: ModelArgs,
}

/// A worker pool of `threads` threads (0: one per core).
pub fn pool(threads: usize) -> Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("starting the worker threads")
}

/// The ensemble of the nominal values with `uncertain` applied, the fidelity and tolerance from
/// `common` ([`input::ensemble_spec`]).
pub fn ensemble_spec(
    mu_c: f64,
    pin_radius: f64,
    uncertain: Option<&str>,
    common: &ModelArgs,
) -> Result<EnsembleSpec> {
    let model = common.model;
    input::ensemble_spec(mu_c, pin_radius, model, common.tol, uncertain).map_err(flagged)
}

/// A refused input, its message naming the flags (a refused file keeps its own error chain).
pub fn flagged(e: InputError) -> anyhow::Error {
    match e {
        InputError::Measured(m) => match m.missing_setting {
            Some(s) => anyhow::Error::from(m)
                .context(format!("give the {s} of the file with {}", super::flag(s))),
            None => m.into(),
        },
        e => anyhow::anyhow!(e.describe(|s| super::flag(s.field()))),
    }
}

/// The count `members` given by `setting`'s flag, checked.
pub fn check_members(setting: Setting, members: usize) -> Result<()> {
    input::check_members(setting, members).map_err(flagged)
}

/// The measured file for `spec`, checked ([`input::load_measured`]).
pub fn load_measured(
    path: &std::path::Path,
    spec: &EnsembleSpec,
    part: Option<&str>,
) -> Result<pinfeed::validate::measured::Measured> {
    input::load_measured(path, spec, part).map_err(flagged)
}

/// Print a report (`--json`: the document, else `text`) and, unless `--no-write`, have `write`
/// write it into `pinfeed-out/<command>/<file stem>/` (or `--out-dir`).
pub fn emit<T: Serialize>(
    report: &T,
    text: &str,
    c: &ModelArgs,
    command: &str,
    file: &Path,
    write: impl FnOnce(&Path) -> Result<()>,
) -> Result<()> {
    if c.json {
        crate::out!("{}", pinfeed::report::versioned::pretty(report)?);
    } else {
        crate::out!("{text}");
    }
    if !c.no_write {
        let out_dir = c.out_dir(command, file);
        write(&out_dir)?;
        eprintln!("report written to {}", out_dir.display());
    }
    Ok(())
}

impl ValidateArgs {
    /// The checked inputs of a validation: the score settings, the ensemble and the measured file.
    pub fn inputs(&self) -> Result<(ScoreSettings, EnsembleSpec, Measured)> {
        let score = self.common.score()?;
        check_members(Setting::Members, self.members)?;
        let spec = ensemble_spec(
            self.mu_c,
            self.pin_radius,
            self.uncertain.as_deref(),
            &self.common,
        )?;
        let measured = load_measured(&self.measured, &spec, self.common.part.as_deref())?;
        Ok((score, spec, measured))
    }
}

/// Run `pinfeed validate`; `recorded` is the command line its report records.
pub fn run(args: &ValidateArgs, recorded: &str) -> Result<()> {
    let (score, spec, measured) = args.inputs()?;
    let c = &args.common;
    let bar = super::progress::bar(0, "passes", c.quiet || c.json);
    let tell = super::progress::counter(&bar);
    let (rows, summary, _) = pool(c.threads)?
        .install(|| {
            let draw = (c.seed, args.members, c.passes);
            pinfeed::validate::validate_observed(&measured, &spec, draw, &score, &tell)
        })
        .map_err(anyhow::Error::msg)?;
    bar.finish_and_clear();
    let report = ValidateReport {
        command: recorded.to_string(),
        measured: args.measured.display().to_string(),
        uncertain: spec.describe(),
        members: args.members,
        score_settings: score,
        containment: containment_text(score.contained_share),
        summary: &summary,
        rows: &rows,
    };
    let text = rows_text(&rows, &summary);
    emit(&report, &text, c, "validate", &args.measured, |dir| {
        Ok(write_report(&report, &text, dir)?)
    })
}
