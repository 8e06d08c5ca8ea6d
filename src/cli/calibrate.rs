//! `pinfeed calibrate MEASURED.csv`: fit μc centre and spread, the tripod (or smooth-density)
//! share and the pin radius to measured bands by maximum likelihood over one reweighted ensemble
//! ([`pinfeed::validate::calibrate`]), with 95% profile-likelihood intervals; then score the nominal
//! model and the fitted ensemble on the same rows with `validate`'s scorer (fresh ensembles, the
//! same seed). With `--synthesize` the file is first written: the bundled synthetic data set drawn
//! from hidden parameters ([`pinfeed::validate::synthetic`]), and the report says whether each
//! interval holds the hidden value. Unless `--no-write`, `pinfeed-out/calibrate/<file stem>/` receives
//! `README.md` headed by the regenerating command and `calibration.json`.

use super::validate::{check_members, emit, ensemble_spec, load_measured, pool, ModelArgs};
use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use pinfeed::mechanics::support::{SmoothParams, SupportChoice};
use pinfeed::report::calibrate_report::{calibration_text, write_report, CalibrateReport};
use pinfeed::validate::calibrate::{calibrate_observed, CalibrationSettings};
use pinfeed::validate::input::Setting;
use pinfeed::validate::synthetic::{synthesize, SyntheticDesign};
use std::path::PathBuf;

/// Arguments of `pinfeed calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// The measured-bands file (CSV; docs/commands.md#validating-against-measurements-pinfeed-validate-pinfeed-calibrate).
    pub measured: PathBuf,
    /// First write the bundled synthetic data set (hidden parameters, seed 16) to MEASURED.
    #[arg(long, conflicts_with = "part")]
    pub synthesize: bool,
    /// Members of the proposal ensemble.
    #[arg(long, default_value_t = 2000)]
    pub members: usize,
    /// Random support model whose share is fitted: tripod or smooth.
    #[arg(long, default_value = "tripod")]
    pub support: String,
    /// Pose jitter (sd of θ0 per pass, degrees): known, not fitted.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub jitter: f64,
    /// Range of the μc mean searched (and of the proposal): MIN:MAX.
    #[arg(long, default_value = "0.05:1", allow_hyphen_values = true)]
    pub mu_c_range: String,
    /// Largest pin radius searched (part units, as `validate --pin-radius`).
    #[arg(long, default_value_t = 0.3, allow_hyphen_values = true)]
    pub pin_radius_max: f64,
    /// σρ: spread of the pin radius under every fitted ensemble (part units).
    #[arg(long, default_value_t = 0.03, allow_hyphen_values = true)]
    pub pin_radius_sd: f64,
    /// The nominal model scored beside the fit: its μc (uniform support, point pin).
    #[arg(long, default_value_t = 0.5, allow_hyphen_values = true)]
    pub mu_c: f64,
    /// Members of the ensembles that score the nominal model and the fit.
    #[arg(long, default_value_t = pinfeed::validate::DEFAULT_MEMBERS)]
    pub score_members: usize,
    #[command(flatten)]
    pub common: ModelArgs,
}

/// The calibration settings of the arguments, checked.
pub(crate) fn settings(args: &CalibrateArgs) -> Result<CalibrationSettings> {
    let (lo, hi) = args
        .mu_c_range
        .split_once(':')
        .and_then(|(a, b)| Some((a.trim().parse::<f64>().ok()?, b.trim().parse::<f64>().ok()?)))
        .ok_or_else(|| anyhow!("--mu-c-range must be MIN:MAX, got '{}'", args.mu_c_range))?;
    let (mu_lo, mu_hi) = pinfeed::mechanics::limits::MU_C;
    if !(lo.is_finite() && hi.is_finite() && mu_lo <= lo && lo + 0.05 <= hi && hi <= mu_hi) {
        bail!("--mu-c-range: need {mu_lo} ≤ MIN, MIN + 0.05 ≤ MAX ≤ {mu_hi}, got {lo}:{hi}");
    }
    let positive = [
        ("--pin-radius-max", args.pin_radius_max),
        ("--pin-radius-sd", args.pin_radius_sd),
    ];
    for (flag, v) in positive {
        if !(v.is_finite() && v > 0.0 && v <= 1e3) {
            bail!("{flag} must be a positive number, got {v}");
        }
    }
    if !(args.jitter.is_finite() && (0.0..=90.0).contains(&args.jitter)) {
        bail!("--jitter must lie in [0, 90] degrees, got {}", args.jitter);
    }
    let support = match args.support.as_str() {
        "tripod" => SupportChoice::Tripod,
        "smooth" => SupportChoice::Smooth(SmoothParams::default()),
        s => bail!("--support must be tripod or smooth, got '{s}'"),
    };
    check_members(Setting::Members, args.members)?;
    check_members(Setting::ScoreMembers, args.score_members)?;
    let c = &args.common;
    Ok(CalibrationSettings {
        members: args.members,
        passes: c.passes,
        seed: c.seed,
        mu_c_range: (lo, hi),
        pin_radius_max: args.pin_radius_max,
        pin_radius_sd: args.pin_radius_sd,
        support,
        jitter_deg: args.jitter,
        fidelity: c.model,
        tol: c.tol,
        score: c.score()?,
    })
}

/// Run `pinfeed calibrate`; `recorded` is the command line its report records.
pub fn run(args: &CalibrateArgs, recorded: &str) -> Result<()> {
    let s = settings(args)?;
    let c = &args.common;
    let hidden = if args.synthesize {
        let text = synthesize(&SyntheticDesign::default()).map_err(anyhow::Error::msg)?;
        if let Some(dir) = args.measured.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        }
        pinfeed::output::write_atomic(&args.measured, text)
            .with_context(|| format!("writing {}", args.measured.display()))?;
        eprintln!("synthetic data set written to {}", args.measured.display());
        Some(SyntheticDesign::TRUTH)
    } else {
        None
    };
    let measured = load_measured(&args.measured, &s.proposal(), args.common.part.as_deref())?;
    let pool = pool(c.threads)?;
    let started = std::time::Instant::now();
    let bar = super::progress::bar(0, "steps", c.quiet || c.json);
    let tell = super::progress::counter(&bar);
    bar.set_message("fitting ");
    let cal = pool
        .install(|| calibrate_observed(&measured, &s, &tell))
        .map_err(anyhow::Error::msg)?;
    bar.suspend(|| eprintln!("calibrated in {:.1} s", started.elapsed().as_secs_f64()));
    let nominal = ensemble_spec(args.mu_c, 0.0, None, c)?;
    let fitted = s.spec_at(cal.estimate());
    let score = s.score;
    let run_score = |spec, stage: &str| {
        bar.set_message(format!("scoring {stage} "));
        pool.install(|| {
            let draw = (c.seed, args.score_members, c.passes);
            pinfeed::validate::validate_observed(&measured, spec, draw, &score, &tell)
        })
        .map(|(_, summary, _)| summary)
        .map_err(anyhow::Error::msg)
    };
    let nominal_score = run_score(&nominal, "the nominal model")?;
    let fitted_score = run_score(&fitted, "the fit")?;
    bar.finish_and_clear();
    let text = calibration_text(
        &cal,
        hidden,
        &nominal.describe(),
        &nominal_score,
        &fitted_score,
    );
    let report = CalibrateReport {
        command: recorded.to_string(),
        measured: args.measured.display().to_string(),
        calibration: &cal,
        nominal: nominal.describe(),
        nominal_score: &nominal_score,
        fitted: fitted.describe(),
        fitted_score: &fitted_score,
        hidden,
    };
    emit(&report, &text, c, "calibrate", &args.measured, |dir| {
        Ok(write_report(&report, &text, dir)?)
    })
}
