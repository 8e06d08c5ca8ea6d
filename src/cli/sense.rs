//! `pinfeed sense`: what a sensorised pin can tell about a part (docs/physics.md#sensing, thesis ch. 5).
//!
//! For one push (part in metres via `--scale`, pin offset `--d`, radius, μc, μs) and a set of
//! hypotheses (the part's stable states by default, listed orientations, or `vertex-edge`), every
//! classifier is scored on `--trials` simulated pushes at every factor of the `--noise` sweep
//! ([`pinfeed::sensing::evaluate`]): confusion matrix (rows true, columns decided, "unknown"
//! last), accuracy with a 95% Wilson interval and the mutual information between state and decision
//! in bits. `--placement` adds the search over d × sensor kind ([`pinfeed::sensing::placement`]).
//!
//! Standard output gets a table per classifier (default) or the JSON document (`--json`); unless
//! `--no-write`, the report directory (default `pinfeed-out/sensing/<part>/`) receives `report.md`
//! headed by the command that regenerates it, `sense.json`, and the SVG figures. The time spent goes
//! to standard error.

use anyhow::{Context, Result};
use clap::Args;
use pinfeed::report::sense::{text_summary, write_report};
use pinfeed::sensing::experiment::{self, Request, SenseError, Setting};
use pinfeed::sensing::placement;
use pinfeed::sensing::SensorSettings;
use std::path::PathBuf;

fn dflt() -> SensorSettings {
    SensorSettings::default()
}

/// Arguments of `pinfeed sense`.
#[derive(Debug, Args, Clone)]
pub struct SenseArgs {
    /// Part: tripoly1, tripoly2, square, rect:W:H, ngon:N, lshape, random:SEED[:N], or vertices:"x,y x,y ...".
    #[arg(long)]
    pub part: String,
    /// Metres per part unit (the part's vertices are multiplied by it).
    #[arg(long, default_value_t = 0.02, allow_hyphen_values = true)]
    pub scale: f64,
    /// Part mass (kg): forces scale with μs·m·g.
    #[arg(long, default_value_t = 0.05, allow_hyphen_values = true)]
    pub mass: f64,
    /// Belt speed (m/s): turns travel into time.
    #[arg(long, default_value_t = 0.05, allow_hyphen_values = true)]
    pub belt_speed: f64,
    /// Contact parameter of the sensorised pin: d = (y_pin − y_com)/a: the pin's lateral offset from the part's centroid in units of a (its
    /// largest centroid–vertex distance), a ratio without a length unit.
    #[arg(long, allow_hyphen_values = true)]
    pub d: f64,
    /// Pin radius in part units, like the part's vertices and as in every command (0: point pin;
    /// metres = part units × --scale).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub pin_radius: f64,
    /// Pin–part friction μc (nominal).
    #[arg(long, default_value_t = 0.5, allow_hyphen_values = true)]
    pub mu_c: f64,
    /// Part–belt friction μs (scales forces).
    #[arg(long, default_value_t = 0.3, allow_hyphen_values = true)]
    pub mu_s: f64,
    /// Fidelity: exact, ellipsoid or tip.
    #[arg(long, default_value = "exact", value_parser = pinfeed::contact_case::parse_model)]
    pub model: pinfeed::mechanics::Fidelity,
    /// Integration tolerance per step.
    #[arg(long, default_value_t = 1e-6, allow_hyphen_values = true)]
    pub tol: f64,
    /// Hypotheses: `stable` (the part's stable states), degrees `0,135,225`, or `vertex-edge`
    /// (first contact on a vertex or an edge, pushes drawn over orientations every 5°).
    #[arg(long, default_value = "stable", allow_hyphen_values = true)]
    pub hypotheses: String,
    /// Sensor kind: ft (force/torque) or timing (contact instants).
    #[arg(long, default_value = "ft")]
    pub sensor: String,
    /// F/T sampling rate (Hz).
    #[arg(long, default_value_t = dflt().rate, allow_hyphen_values = true)]
    pub rate: f64,
    /// Height of the sensor origin above the contact (m).
    #[arg(long, default_value_t = dflt().height, allow_hyphen_values = true)]
    pub height: f64,
    /// White noise σ per force channel (N) at noise factor 1.
    #[arg(long, default_value_t = dflt().noise_force, allow_hyphen_values = true)]
    pub noise_force: f64,
    /// White noise σ per torque channel (N·mm) at noise factor 1.
    #[arg(long, default_value_t = dflt().noise_torque, allow_hyphen_values = true)]
    pub noise_torque: f64,
    /// Bias per force channel (N).
    #[arg(long, default_value_t = dflt().bias_force, allow_hyphen_values = true)]
    pub bias_force: f64,
    /// Bias per torque channel (N·mm).
    #[arg(long, default_value_t = dflt().bias_torque, allow_hyphen_values = true)]
    pub bias_torque: f64,
    /// Drift of the force channels (N/s).
    #[arg(long, default_value_t = dflt().drift_force, allow_hyphen_values = true)]
    pub drift_force: f64,
    /// Drift of the torque channels (N·mm/s).
    #[arg(long, default_value_t = dflt().drift_torque, allow_hyphen_values = true)]
    pub drift_torque: f64,
    /// Quantisation step of Fx, Fy (N; 0: none).
    #[arg(long, default_value_t = dflt().resolution_force, allow_hyphen_values = true)]
    pub resolution_force: f64,
    /// First-order low-pass cut-off (Hz; default none).
    #[arg(long, allow_hyphen_values = true)]
    pub lowpass: Option<f64>,
    /// Timing sensor: |F| threshold (N).
    #[arg(long, default_value_t = dflt().threshold, allow_hyphen_values = true)]
    pub threshold: f64,
    /// Timing sensor: σ of each reported instant (s) at noise factor 1.
    #[arg(long, default_value_t = dflt().jitter, allow_hyphen_values = true)]
    pub jitter: f64,
    /// Classifiers, comma-separated (default: all that apply to the sensor and hypotheses).
    #[arg(long, value_delimiter = ',')]
    pub classifiers: Vec<String>,
    /// Reject option: decide "unknown" below this largest posterior (methods with a posterior).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub reject_below: f64,
    /// Noise sweep: factors on the white noise and jitter (1 = the settings above).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "0,0.5,1,2,4,8,16",
        allow_hyphen_values = true
    )]
    pub noise: Vec<f64>,
    /// Uncertain μc: uniform over LO:HI (replaces --mu-c in templates and trials).
    #[arg(long, value_name = "LO:HI")]
    pub mu_c_range: Option<String>,
    /// A random tripod support per push instead of uniform pressure.
    #[arg(long)]
    pub tripod: bool,
    /// Orientation jitter σ (degrees) about each hypothesis.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub theta_jitter: f64,
    /// Lateral jitter σ of d (units of a).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub d_jitter: f64,
    /// Template ensemble size per hypothesis.
    #[arg(long, default_value_t = 32)]
    pub templates: usize,
    /// Trials per sweep point (the same true pushes at every point).
    #[arg(long, default_value_t = 300)]
    pub trials: usize,
    /// How each trial's true hypothesis is chosen: cycle or uniform.
    #[arg(long, default_value = "cycle")]
    pub truth: String,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Also search the placement: d over --placement-d, sensor kinds ft and timing, nominal noise.
    #[arg(long)]
    pub placement: bool,
    /// Grid of d for --placement.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "-0.9,-0.8,-0.7,-0.6,-0.5,-0.4,-0.3,-0.2,-0.1,0,0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9",
        allow_hyphen_values = true
    )]
    pub placement_d: Vec<f64>,
    /// Print one JSON document.
    #[arg(long)]
    pub json: bool,
    /// Report directory [default: pinfeed-out/sensing/<part>].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print only; write no files.
    #[arg(long, conflicts_with = "out")]
    pub no_write: bool,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
}

/// The default report directory: `pinfeed-out/sensing/<part>` (a vertex list is `custom-HASH`).
pub fn default_out_dir(part: &str) -> PathBuf {
    pinfeed::default_out(&["sensing", &super::part_folder(part)])
}

/// The library's request of the arguments.
pub fn request(a: &SenseArgs) -> Request {
    Request {
        part: a.part.clone(),
        scale: a.scale,
        mass: a.mass,
        belt_speed: a.belt_speed,
        d: a.d,
        pin_radius: a.pin_radius,
        mu_c: a.mu_c,
        mu_s: a.mu_s,
        model: a.model,
        tol: a.tol,
        hypotheses: a.hypotheses.clone(),
        sensor: SensorSettings {
            rate: a.rate,
            height: a.height,
            noise_force: a.noise_force,
            noise_torque: a.noise_torque,
            bias_force: a.bias_force,
            bias_torque: a.bias_torque,
            drift_force: a.drift_force,
            drift_torque: a.drift_torque,
            resolution_force: a.resolution_force,
            lowpass: a.lowpass,
            threshold: a.threshold,
            jitter: a.jitter,
            ..SensorSettings::default()
        },
        sensor_kind: a.sensor.clone(),
        classifiers: a.classifiers.clone(),
        reject_below: a.reject_below,
        noise: a.noise.clone(),
        mu_c_range: a.mu_c_range.clone(),
        tripod: a.tripod,
        theta_jitter: a.theta_jitter,
        d_jitter: a.d_jitter,
        templates: a.templates,
        trials: a.trials,
        truth: a.truth.clone(),
        seed: a.seed,
        threads: a.threads,
        placement: a.placement,
        placement_d: a.placement_d.clone(),
    }
}

/// The flag of `pinfeed sense` that sets `setting`.
fn flag_of(setting: Setting) -> String {
    match setting {
        Setting::SensorKind => "--sensor".into(),
        s => super::flag(s.field()),
    }
}

/// A refused request, its message naming the flags.
fn flagged(e: SenseError) -> anyhow::Error {
    anyhow::anyhow!(e.describe(flag_of))
}

/// Run `pinfeed sense`; `recorded` is the command line its report records.
pub fn run(a: &SenseArgs, recorded: &str) -> Result<()> {
    let req = request(a);
    let p = experiment::check(&req).map_err(flagged)?;
    super::warn_thin_pin(a.pin_radius, a.scale);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads)
        .build()
        .context("starting the worker threads")?;
    let started = std::time::Instant::now();
    let bar = super::progress::bar(a.trials as u64, "trials", a.quiet || a.json);
    let tell = super::progress::counter(&bar);
    let sweep = pool.install(|| p.evaluate(&req, &tell)).map_err(flagged)?;
    bar.finish_and_clear();
    let elapsed = started.elapsed().as_secs_f64();
    eprintln!(
        "sense: {} trials × {} noise levels × {} classifiers in {elapsed:.2} s on {} threads ({:.0} trials/s)",
        a.trials,
        a.noise.len(),
        p.classifiers.len(),
        pool.current_num_threads(),
        a.trials as f64 / elapsed
    );
    let evaluated = sweep.policy(&p).map_err(flagged)?;
    for s in &evaluated.skipped {
        eprintln!("warning: classifier {} skipped: {}", s.classifier, s.reason);
    }
    for u in &evaluated.untrained {
        eprintln!(
            "note: {} cannot be trained at noise ×{} (every reading decided unknown): {}",
            u.classifier, u.noise_factor, u.reason
        );
    }
    if evaluated.classifiers.is_empty() {
        return Err(flagged(SenseError::NoClassifier));
    }
    if p.point_pin_misses_vertices(&evaluated.evaluation) {
        eprintln!("note: a point pin (--pin-radius 0) first meets the part on an edge almost always; give the pin a radius for vertex contacts");
    }

    // Placement: every sensor kind at nominal noise with its default classifiers.
    let placement = if a.placement {
        let started = std::time::Instant::now();
        let bar = super::progress::bar(a.placement_d.len() as u64, "offsets", a.quiet || a.json);
        bar.set_message("placement ");
        let mut progress = |d: f64, rows: &[placement::Row]| {
            bar.suspend(|| {
                for r in rows {
                    eprintln!(
                        "placement d = {d:+.2} {:>6}: {:.3} bits ({})",
                        r.sensor,
                        r.mutual_information_bits,
                        r.classifier.as_deref().unwrap_or("-")
                    );
                }
            });
            bar.inc(1);
        };
        let pl = pool
            .install(|| p.place(&req, &mut progress))
            .map_err(flagged)?;
        bar.finish_and_clear();
        eprintln!(
            "placement: {} offsets × 2 sensor kinds in {:.2} s",
            a.placement_d.len(),
            started.elapsed().as_secs_f64()
        );
        Some(pl)
    } else {
        None
    };

    let (report, templates) = p.report(&req, recorded.to_string(), evaluated, placement);
    if a.json {
        crate::out!("{}", pinfeed::report::versioned::pretty(&report)?);
    } else {
        crate::out!("{}", text_summary(&report));
    }
    if !a.no_write {
        let out = a.out.clone().unwrap_or_else(|| default_out_dir(&a.part));
        let config = p.config(&req);
        write_report(&report, &p.problem(), &config, &templates, &out)?;
        eprintln!("report written to {}", out.display());
    }
    Ok(())
}
