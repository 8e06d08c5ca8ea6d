//! `pinfeed sense`: what a sensorised pin can tell about a part (docs/physics.md#sensing, thesis ch. 5).
//!
//! For one push (part in metres via `--scale`, pin offset `--d`, radius, μc, μs) and a set of
//! hypotheses (the part's stable states by default, listed orientations, or `vertex-edge`), every
//! classifier is scored on `--trials` simulated pushes at every factor of the `--noise` sweep
//! ([`crate::sensing::evaluate`]): confusion matrix (rows true, columns decided, "unknown"
//! last), accuracy with a 95% Wilson interval and the mutual information between state and decision
//! in bits. `--placement` adds the search over d × sensor kind ([`crate::sensing::placement`]).
//!
//! Standard output gets a table per classifier (default) or the JSON document (`--json`); unless
//! `--no-write`, the report directory (default `pinfeed-out/sensing/<part>/`) receives `report.md`
//! headed by the command that regenerates it, `sense.json`, and the SVG figures. The time spent goes
//! to standard error.

use super::contact::{in_range, num, parse_model};
use crate::geometry::named;
use crate::mechanics::{PartModel, Support};
use crate::random::distribution::Distribution;
use crate::report::plot_sensing;
use crate::report::shell_word;
use crate::sensing::classify::{self, Classifier, ClassifierOptions};
use crate::sensing::evaluate::{
    applicable, evaluate_observed, noise_sweep, trial_pass, Cell, Config, Evaluation, Factory,
    Problem, SensorPoint, TruthDraw, MAX_TEMPLATES, MAX_TRIALS, READING_STREAMS,
};
use crate::sensing::placement::{self, Placement};
use crate::sensing::templates::{Hypotheses, PushSetup, TemplateSet, Uncertainty};
use crate::sensing::{read, SensorKind, SensorSettings};
use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

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
    /// Pin radius in metres (0: point pin); `contact`, `map` and `validate` take part units.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub pin_radius: f64,
    /// Pin–part friction μc (nominal).
    #[arg(long, default_value_t = 0.5, allow_hyphen_values = true)]
    pub mu_c: f64,
    /// Part–belt friction μs (scales forces).
    #[arg(long, default_value_t = 0.3, allow_hyphen_values = true)]
    pub mu_s: f64,
    /// Fidelity: exact, ellipsoid or tip.
    #[arg(long, default_value = "exact")]
    pub model: String,
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

/// Most noise factors, placement offsets, threads (hypotheses: [`Hypotheses::orientations`]).
pub const MAX_FACTORS: usize = 64;
pub const MAX_PLACEMENT_D: usize = 201;
pub const MAX_THREADS: usize = 1024;

/// The declared uncertainty, as reported.
#[derive(Debug, Serialize)]
pub struct UncertaintyReport {
    pub mu_c: String,
    pub tripod: bool,
    pub theta_jitter_deg: f64,
    pub d_jitter: f64,
}

/// A default classifier that could not be trained here, and why.
#[derive(Debug, Serialize, Clone)]
pub struct Skipped {
    pub classifier: String,
    pub reason: String,
}

/// A classifier that could not be trained at one sweep point, and why.
#[derive(Debug, Serialize, Clone)]
pub struct Untrained {
    pub classifier: String,
    pub noise_factor: f64,
    pub reason: String,
}

/// The JSON document of `pinfeed sense --json` (and `sense.json`).
#[derive(Debug, Serialize)]
pub struct SenseReport {
    /// The command that regenerates this report.
    pub command: String,
    pub part: String,
    pub scale_m_per_unit: f64,
    /// The part's circumradius a (m).
    pub a_m: f64,
    pub mass_kg: f64,
    pub belt_speed_m_s: f64,
    pub d: f64,
    pub pin_radius_m: f64,
    pub mu_c: f64,
    pub mu_s: f64,
    pub model: String,
    pub hypotheses: Hypotheses,
    pub sensor: SensorSettings,
    pub uncertainty: UncertaintyReport,
    pub templates_per_hypothesis: usize,
    pub trials: usize,
    pub truth: TruthDraw,
    pub seed: u64,
    pub noise_factors: Vec<f64>,
    pub classifiers: Vec<String>,
    pub skipped: Vec<Skipped>,
    /// Sweep points where a classifier could not be trained (it decided "unknown" there).
    pub untrained: Vec<Untrained>,
    pub evaluation: Evaluation,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub placement: Option<Placement>,
}

fn list(v: &[f64]) -> String {
    v.iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(",")
}

/// The command line that regenerates a report, every setting explicit.
pub fn command_line(a: &SenseArgs) -> String {
    let mut w: Vec<String> = vec!["pinfeed".into(), "sense".into()];
    let mut kv = |k: &str, v: String| w.push(format!("--{k}={v}"));
    kv("part", shell_word(&a.part));
    kv("scale", a.scale.to_string());
    kv("mass", a.mass.to_string());
    kv("belt-speed", a.belt_speed.to_string());
    kv("d", a.d.to_string());
    kv("pin-radius", a.pin_radius.to_string());
    kv("mu-c", a.mu_c.to_string());
    kv("mu-s", a.mu_s.to_string());
    kv("model", shell_word(&a.model));
    kv("tol", a.tol.to_string());
    kv("hypotheses", shell_word(&a.hypotheses));
    kv("sensor", shell_word(&a.sensor));
    kv("rate", a.rate.to_string());
    kv("height", a.height.to_string());
    kv("noise-force", a.noise_force.to_string());
    kv("noise-torque", a.noise_torque.to_string());
    kv("bias-force", a.bias_force.to_string());
    kv("bias-torque", a.bias_torque.to_string());
    kv("drift-force", a.drift_force.to_string());
    kv("drift-torque", a.drift_torque.to_string());
    kv("resolution-force", a.resolution_force.to_string());
    if let Some(l) = a.lowpass {
        kv("lowpass", l.to_string());
    }
    kv("threshold", a.threshold.to_string());
    kv("jitter", a.jitter.to_string());
    if !a.classifiers.is_empty() {
        kv("classifiers", shell_word(&a.classifiers.join(",")));
    }
    kv("reject-below", a.reject_below.to_string());
    kv("noise", list(&a.noise));
    if let Some(r) = &a.mu_c_range {
        kv("mu-c-range", shell_word(r));
    }
    kv("theta-jitter", a.theta_jitter.to_string());
    kv("d-jitter", a.d_jitter.to_string());
    kv("templates", a.templates.to_string());
    kv("trials", a.trials.to_string());
    kv("truth", shell_word(&a.truth));
    kv("seed", a.seed.to_string());
    if a.placement {
        kv("placement-d", list(&a.placement_d));
    }
    if let Some(o) = &a.out {
        kv("out", shell_word(&o.display().to_string()));
    }
    if a.tripod {
        w.push("--tripod".into());
    }
    if a.placement {
        w.push("--placement".into());
    }
    w.join(" ")
}

/// The default report directory: `pinfeed-out/sensing/<part>` (a vertex list is `custom`).
pub fn default_out_dir(part: &str) -> PathBuf {
    crate::default_out(&["sensing", &super::part_folder(part)])
}

/// `flag must be > lo …` for strictly positive quantities.
fn positive(flag: &str, v: f64, hi: f64, what: &str) -> Result<()> {
    if !(v.is_finite() && v > 0.0 && v <= hi) {
        bail!(
            "{flag} must be a finite number > 0 and at most {} ({what}), got {}",
            num(hi),
            num(v)
        );
    }
    Ok(())
}

/// Parse `--hypotheses` for a part: `stable`, `vertex-edge` or a list of degrees.
pub fn parse_hypotheses(spec: &str, poly: &crate::geometry::Polygon) -> Result<Hypotheses> {
    let s = spec.trim();
    let hyps = match s.to_lowercase().as_str() {
        "stable" => Hypotheses::stable_states(poly),
        "vertex-edge" => Ok(Hypotheses::vertex_edge_sweep()),
        _ => {
            let degrees = s
                .split(',')
                .map(|tok| {
                    let t = tok.trim();
                    t.parse::<f64>().map_err(|_| {
                        anyhow!("--hypotheses: '{t}' is not a number of degrees (or give stable or vertex-edge)")
                    })
                })
                .collect::<Result<Vec<f64>>>()?;
            Hypotheses::orientations(degrees)
        }
    };
    hyps.map_err(|e| anyhow!("--hypotheses {s}: {e}"))
}

fn parse_range(spec: &str) -> Result<Distribution> {
    let (lo, hi) = spec
        .split_once(':')
        .ok_or_else(|| anyhow!("--mu-c-range must be LO:HI (e.g. 0.3:0.7), got '{spec}'"))?;
    let p = |t: &str| -> Result<f64> {
        t.trim()
            .parse::<f64>()
            .map_err(|_| anyhow!("--mu-c-range: '{t}' is not a number"))
    };
    let (lo, hi) = (p(lo)?, p(hi)?);
    in_range("--mu-c-range LO", lo, 0.0, 10.0, "friction coefficient")?;
    in_range("--mu-c-range HI", hi, 0.0, 10.0, "friction coefficient")?;
    if lo > hi {
        bail!(
            "--mu-c-range: LO must not exceed HI, got {}:{}",
            num(lo),
            num(hi)
        );
    }
    Ok(if lo == hi {
        Distribution::Fixed(lo)
    } else {
        Distribution::Uniform { min: lo, max: hi }
    })
}

/// The sensor of the arguments (noise factor 1), validated; errors name the flag.
pub fn sensor_settings(a: &SenseArgs) -> Result<SensorSettings> {
    let kind = match a.sensor.trim() {
        "ft" => SensorKind::Ft,
        "timing" => SensorKind::Timing,
        other => bail!("--sensor must be ft or timing, got '{other}'"),
    };
    let s = SensorSettings {
        kind,
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
    };
    s.validate()
        .map_err(|e| anyhow!("--{}: {}", e.field.replace('_', "-"), e.message))?;
    Ok(s)
}

/// Everything the arguments fix, checked.
struct Plan {
    part_name: String,
    setup: PushSetup,
    model: PartModel,
    hyps: Hypotheses,
    unc: Uncertainty,
    sensor: SensorSettings,
    classifiers: Vec<String>,
    /// Classifiers named by --classifiers (not the defaults).
    explicit: bool,
    truth: TruthDraw,
}

fn plan(a: &SenseArgs) -> Result<Plan> {
    use crate::mechanics::limits;
    positive("--scale", a.scale, 100.0, "metres per part unit")?;
    positive("--mass", a.mass, 1e3, "kg")?;
    positive("--belt-speed", a.belt_speed, 100.0, "m/s")?;
    in_range(
        "--mu-c",
        a.mu_c,
        limits::MU_C.0,
        limits::MU_C.1,
        "friction coefficient",
    )?;
    in_range(
        "--mu-s",
        a.mu_s,
        limits::MU_S.0,
        limits::MU_S.1,
        "support friction",
    )?;
    in_range(
        "--tol",
        a.tol,
        limits::TOL.0,
        limits::TOL.1,
        "integration tolerance per step",
    )?;
    in_range("--theta-jitter", a.theta_jitter, 0.0, 180.0, "degrees")?;
    in_range("--d-jitter", a.d_jitter, 0.0, 1.0, "units of a")?;
    in_range(
        "--reject-below",
        a.reject_below,
        0.0,
        1.0,
        "largest posterior",
    )?;
    if !(1..=MAX_TRIALS).contains(&a.trials) {
        bail!("--trials must lie in [1, {MAX_TRIALS}], got {}", a.trials);
    }
    if !(1..=MAX_TEMPLATES).contains(&a.templates) {
        bail!(
            "--templates must lie in [1, {MAX_TEMPLATES}], got {}",
            a.templates
        );
    }
    if a.threads > MAX_THREADS {
        bail!(
            "--threads must lie in [0, {MAX_THREADS}] (0: one per core), got {}",
            a.threads
        );
    }
    if a.noise.is_empty() || a.noise.len() > MAX_FACTORS {
        bail!(
            "--noise takes 1 to {MAX_FACTORS} factors, got {}",
            a.noise.len()
        );
    }
    for &f in &a.noise {
        in_range("--noise", f, 0.0, 1e6, "factor on the nominal noise, ≥ 0")?;
    }
    if a.placement && (a.placement_d.is_empty() || a.placement_d.len() > MAX_PLACEMENT_D) {
        bail!(
            "--placement-d takes 1 to {MAX_PLACEMENT_D} offsets, got {}",
            a.placement_d.len()
        );
    }
    let truth = match a.truth.trim() {
        "cycle" => TruthDraw::Cycle,
        "uniform" => TruthDraw::Uniform,
        other => bail!("--truth must be cycle or uniform, got '{other}'"),
    };
    let fidelity = parse_model(&a.model).map_err(|e| anyhow!("--model: {e}"))?;
    let sensor = sensor_settings(a)?;
    for &f in &a.noise {
        sensor.with_noise_factor(f).validate().map_err(|e| {
            anyhow!(
                "--noise {}: the sensor's {} leaves its range: {}",
                num(f),
                e.field,
                e.message
            )
        })?;
    }
    let part = named::part_from_spec(&a.part).map_err(|e| anyhow!("--part '{}': {e}", a.part))?;
    let poly = part.scaled(a.scale);
    let radius_a = poly.radius();
    in_range(
        "--pin-radius",
        a.pin_radius,
        0.0,
        limits::PIN_RADIUS_A * radius_a,
        &format!(
            "m; at most {}·a, a = {} m",
            limits::PIN_RADIUS_A,
            num(radius_a)
        ),
    )?;
    let reach = 1.0 + a.pin_radius / radius_a;
    in_range(
        "--d",
        a.d,
        -reach,
        reach,
        "units of a; beyond it the pin cannot touch the part",
    )?;
    if a.placement {
        for &d in &a.placement_d {
            in_range(
                "--placement-d",
                d,
                -reach,
                reach,
                "units of a; beyond it the pin cannot touch the part",
            )?;
        }
    }
    let hyps = parse_hypotheses(&a.hypotheses, &part)?;
    let mu_c = match &a.mu_c_range {
        Some(r) => parse_range(r)?,
        None => Distribution::Fixed(a.mu_c),
    };
    let unc = Uncertainty {
        mu_c,
        tripod: a.tripod,
        theta_sd_deg: a.theta_jitter,
        d_sd: a.d_jitter,
    };
    let explicit = !a.classifiers.is_empty();
    let classifiers: Vec<String> = if explicit {
        let mut v: Vec<String> = Vec::new();
        for c in &a.classifiers {
            let c = c.trim().to_string();
            if !classify::NAMES.contains(&c.as_str()) {
                bail!(
                    "--classifiers: unknown classifier '{c}'; known: {}",
                    classify::NAMES.join(", ")
                );
            }
            if v.contains(&c) {
                bail!("--classifiers: '{c}' is listed twice");
            }
            v.push(c);
        }
        v
    } else {
        applicable(sensor.kind, &hyps)
    };
    let model = PartModel::new(&poly, &Support::Uniform).map_err(|e| anyhow!("--part: {e}"))?;
    let setup = PushSetup {
        polygon: poly,
        d: a.d,
        pin_radius: a.pin_radius,
        mu_c: a.mu_c,
        mu_s: a.mu_s,
        fidelity,
        tol: a.tol,
        mass: a.mass,
        belt_speed: a.belt_speed,
        height: sensor.height,
    };
    Ok(Plan {
        part_name: a.part.clone(),
        setup,
        model,
        hyps,
        unc,
        sensor,
        classifiers,
        explicit,
        truth,
    })
}

/// A classifier that decides nothing: stands in for a default classifier that could not be trained
/// (its cells are dropped from the report and the reason listed).
struct Placeholder;
impl Classifier for Placeholder {
    fn name(&self) -> &'static str {
        "skipped"
    }
    fn classify(&self, _: &crate::sensing::Reading) -> classify::Classification {
        classify::Classification::unknown()
    }
}

pub fn run(a: &SenseArgs) -> Result<()> {
    let p = plan(a)?;
    let options = ClassifierOptions {
        reject_below: a.reject_below,
    };
    // A classifier that cannot be trained at a sweep point (e.g. its contact detector's threshold,
    // raised with the noise, exceeds every template's force) decides "unknown" there; one that can
    // be trained nowhere is an error when asked for by name and skipped otherwise.
    let failures: Mutex<Vec<(String, SensorSettings, String)>> = Mutex::new(Vec::new());
    let factory = |name: &str, t: &TemplateSet, s: &SensorSettings| match classify::build(
        name, t, s, &options,
    ) {
        Ok(c) => Ok(c),
        Err(e) => {
            failures
                .lock()
                .expect("lock")
                .push((name.to_string(), *s, e));
            Ok(Box::new(Placeholder) as Box<dyn Classifier>)
        }
    };
    let config = Config {
        templates_per_hypothesis: a.templates,
        trials: a.trials,
        truth: p.truth,
        seed: a.seed,
        options,
    };
    let problem = Problem {
        setup: &p.setup,
        model: &p.model,
        hypotheses: &p.hyps,
        uncertainty: &p.unc,
    };
    let points = noise_sweep(&p.sensor, &a.noise, &p.classifiers);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads)
        .build()
        .context("starting the worker threads")?;
    let started = std::time::Instant::now();
    let bar = super::progress::bar(a.trials as u64, "trials", a.quiet || a.json);
    let tell = super::progress::counter(&bar);
    let (templates, mut evaluation) = pool
        .install(|| evaluate_observed(&problem, &points, &config, &factory, &tell))
        .map_err(|e| anyhow!(e))?;
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
    let failures = failures.into_inner().expect("lock");
    let mut skipped: Vec<Skipped> = Vec::new();
    let mut untrained: Vec<Untrained> = Vec::new();
    for name in &p.classifiers {
        let fails: Vec<_> = failures.iter().filter(|f| &f.0 == name).collect();
        if fails.len() == points.len() {
            let reason = fails.first().map_or(String::new(), |f| f.2.clone());
            if p.explicit {
                bail!("--classifiers: {reason}");
            }
            skipped.push(Skipped {
                classifier: name.clone(),
                reason,
            });
        } else {
            for f in fails {
                let factor = points
                    .iter()
                    .find(|pt| pt.sensor == f.1)
                    .map_or(f64::NAN, |pt| pt.noise_factor);
                untrained.push(Untrained {
                    classifier: name.clone(),
                    noise_factor: factor,
                    reason: f.2.clone(),
                });
            }
        }
    }
    evaluation
        .cells
        .retain(|c| !skipped.iter().any(|s| s.classifier == c.classifier));
    for s in &skipped {
        eprintln!("warning: classifier {} skipped: {}", s.classifier, s.reason);
    }
    for u in &untrained {
        eprintln!(
            "note: {} cannot be trained at noise ×{} (every reading decided unknown): {}",
            u.classifier, u.noise_factor, u.reason
        );
    }
    let classifiers: Vec<String> = p
        .classifiers
        .iter()
        .filter(|c| !skipped.iter().any(|s| &s.classifier == *c))
        .cloned()
        .collect();
    if classifiers.is_empty() {
        bail!("no classifier could be trained for these hypotheses and this sensor");
    }
    if matches!(p.hyps, Hypotheses::VertexEdge { .. })
        && evaluation.truth_counts.contains(&0)
        && a.pin_radius == 0.0
    {
        eprintln!("note: a point pin (--pin-radius 0) first meets the part on an edge almost always; give the pin a radius for vertex contacts");
    }

    // Placement: every sensor kind at nominal noise with its default classifiers.
    let placement = if a.placement {
        let kinds = [SensorKind::Ft, SensorKind::Timing];
        let pts: Vec<SensorPoint> = kinds
            .iter()
            .map(|&k| SensorPoint {
                noise_factor: 1.0,
                sensor: SensorSettings {
                    kind: k,
                    ..p.sensor
                },
                classifiers: applicable(k, &p.hyps),
            })
            .collect();
        let started = std::time::Instant::now();
        let lenient = |name: &str, t: &TemplateSet, s: &SensorSettings| {
            classify::build(name, t, s, &options)
                .or_else(|_| Ok(Box::new(Placeholder) as Box<dyn Classifier>))
        };
        let lenient: &Factory = &lenient;
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
            .install(|| {
                placement::search_with(
                    &problem,
                    &a.placement_d,
                    &pts,
                    &config,
                    lenient,
                    &mut progress,
                )
            })
            .map_err(|e| anyhow!(e))?;
        bar.finish_and_clear();
        eprintln!(
            "placement: {} offsets × {} sensor kinds in {:.2} s",
            a.placement_d.len(),
            kinds.len(),
            started.elapsed().as_secs_f64()
        );
        Some(pl)
    } else {
        None
    };

    let report = SenseReport {
        command: command_line(a),
        part: p.part_name.clone(),
        scale_m_per_unit: a.scale,
        a_m: p.setup.polygon.radius(),
        mass_kg: a.mass,
        belt_speed_m_s: a.belt_speed,
        d: a.d,
        pin_radius_m: a.pin_radius,
        mu_c: a.mu_c,
        mu_s: a.mu_s,
        model: p.setup.fidelity.name().to_string(),
        hypotheses: p.hyps.clone(),
        sensor: p.sensor,
        uncertainty: UncertaintyReport {
            mu_c: p.unc.mu_c.describe(),
            tripod: p.unc.tripod,
            theta_jitter_deg: p.unc.theta_sd_deg,
            d_jitter: p.unc.d_sd,
        },
        templates_per_hypothesis: a.templates,
        trials: a.trials,
        truth: p.truth,
        seed: a.seed,
        noise_factors: a.noise.clone(),
        classifiers,
        skipped,
        untrained,
        evaluation,
        placement,
    };
    if a.json {
        print!("{}", crate::report::versioned::pretty(&report)?);
    } else {
        print!("{}", text_summary(&report));
    }
    if !a.no_write {
        let out = a.out.clone().unwrap_or_else(|| default_out_dir(&a.part));
        write_report(&report, &p, &problem, &config, &templates, &out)?;
        eprintln!("report written to {}", out.display());
    }
    Ok(())
}

fn matrix_line(c: &Cell) -> String {
    let rows: Vec<String> = c
        .confusion
        .counts
        .iter()
        .zip(&c.confusion.labels)
        .map(|(r, l)| {
            let k = r.len() - 1;
            let v: Vec<String> = r[..k].iter().map(|x| x.to_string()).collect();
            format!("{l}→[{} | {}]", v.join(" "), r[k])
        })
        .collect();
    rows.join("  ")
}

/// The terminal summary: per classifier, accuracy and information against noise, and matrices.
pub fn text_summary(r: &SenseReport) -> String {
    let ev = &r.evaluation;
    let mut s = format!(
        "{} d {} sensor {}  hypotheses {}  {} trials ({} unscored), {} templates each  H(state) {:.3} bits, chance {:.1}%\n",
        r.part,
        r.d,
        r.sensor.kind.name(),
        ev.labels.join(", "),
        r.trials,
        ev.unscored,
        r.templates_per_hypothesis,
        ev.state_entropy_bits,
        100.0 * ev.chance_accuracy
    );
    for name in &r.classifiers {
        s += &format!("\n{name}\n  noise   accuracy  95% interval     unknown  I (bits)   confusion (rows true: decided… | unknown)\n");
        for c in ev.of(name) {
            s += &format!(
                "  ×{:<5} {:>7.1}%  [{:>5.1}, {:>5.1}]%  {:>7}  {:>8.3}   {}\n",
                c.noise_factor,
                100.0 * c.accuracy,
                100.0 * c.accuracy_ci95[0],
                100.0 * c.accuracy_ci95[1],
                c.unknown,
                c.mutual_information_bits,
                matrix_line(c)
            );
        }
    }
    for sk in &r.skipped {
        s += &format!("\nskipped {}: {}\n", sk.classifier, sk.reason);
    }
    for u in &r.untrained {
        s += &format!(
            "\n{} not trainable at ×{} (decided unknown): {}\n",
            u.classifier, u.noise_factor, u.reason
        );
    }
    if let Some(pl) = &r.placement {
        s += "\nplacement (nominal noise): d, sensor, best classifier, I (bits), accuracy\n";
        for row in &pl.rows {
            s += &format!(
                "  {:+.2}  {:>6}  {:<15} {:>6.3}  {:>5.1}%\n",
                row.d,
                row.sensor,
                row.classifier.as_deref().unwrap_or("-"),
                row.mutual_information_bits,
                100.0 * row.accuracy
            );
        }
        if let Some(b) = pl.best.and_then(|b| pl.rows.get(b)) {
            s += &format!(
                "  best: {} at d = {} ({}, {:.3} bits)\n",
                b.sensor,
                b.d,
                b.classifier.as_deref().unwrap_or("-"),
                b.mutual_information_bits
            );
        }
    }
    s
}

fn write_report(
    r: &SenseReport,
    p: &Plan,
    problem: &Problem,
    config: &Config,
    templates: &TemplateSet,
    out: &Path,
) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let json_path = out.join("sense.json");
    crate::report::atomic::write_atomic(&json_path, crate::report::versioned::pretty(r)?)
        .with_context(|| format!("writing {}", json_path.display()))?;
    let what = format!(
        "{} at d = {}, μc {}, {} sensor",
        r.part,
        r.d,
        r.uncertainty.mu_c,
        r.sensor.kind.name()
    );
    // (a) templates with trial 0's reading at noise factor 1.
    let (truth, pass) = trial_pass(problem, config, 0).map_err(|e| anyhow!(e))?;
    let mut rng = crate::random::stream(config.seed, READING_STREAMS);
    let reading = read(&pass.signal, &p.sensor, &mut rng);
    let overlay = match (&reading, pass.signal.span()) {
        (Some(rd), Some((b, _))) => Some(plot_sensing::Overlay {
            reading: rd,
            contact_begin: b,
            label: format!(
                "one reading at nominal noise (true: {})",
                truth.map_or("none".to_string(), |t| r.evaluation.labels[t].clone())
            ),
        }),
        _ => None,
    };
    let f_templates = out.join("templates.svg");
    plot_sensing::plot_templates(
        templates,
        overlay.as_ref(),
        &format!("Templates per hypothesis: {what}"),
        &f_templates,
    )
    .with_context(|| format!("writing {}", f_templates.display()))?;
    let f_acc = out.join("accuracy_noise.svg");
    plot_sensing::plot_accuracy_noise(
        &r.evaluation,
        &format!("Accuracy against noise: {what}, {} trials", r.trials),
        &f_acc,
    )
    .with_context(|| format!("writing {}", f_acc.display()))?;
    if let Some(pl) = &r.placement {
        let f = out.join("placement.svg");
        plot_sensing::plot_placement(
            pl,
            &format!(
                "Where to sense {} (nominal noise, {} trials per d)",
                r.part, r.trials
            ),
            &f,
        )
        .with_context(|| format!("writing {}", f.display()))?;
    }
    crate::report::atomic::write_atomic(out.join("report.md"), report_markdown(r))
        .with_context(|| format!("writing {}", out.join("report.md").display()))?;
    // A placement figure of an earlier run with --placement does not outlive this one.
    let written: Vec<String> = ["templates.svg", "accuracy_noise.svg"]
        .into_iter()
        .chain(r.placement.as_ref().map(|_| "placement.svg"))
        .map(String::from)
        .collect();
    crate::report::stale::remove_stale(out, &written, |n| n.ends_with(".svg"))
        .with_context(|| format!("removing earlier figures from {}", out.display()))?;
    Ok(())
}

/// `report.md`: the command, the settings, a table per classifier, the figures.
pub fn report_markdown(r: &SenseReport) -> String {
    let ev = &r.evaluation;
    let mut md = format!(
        "# What a sensor tells: {}\n\nRegenerate from the repository root with\n\n    cargo run --release -- {}\n\n",
        r.part,
        r.command.trim_start_matches("pinfeed ")
    );
    md += &format!(
        "Part `{}` scaled to a = {:.4} m, mass {} kg, belt {} m/s; pin at d = {}, radius {} m, μs = {}, \
         model `{}`. Sensor `{}`: rate {} Hz, height {} m, noise σ {} N / {} N·mm, resolution {} N, \
         threshold {} N, jitter {} s at noise factor 1. Uncertainty: μc {}, tripod supports: {}, \
         θ jitter σ {}°, d jitter σ {}. Hypotheses: {}; {} templates each (built: {:?}); {} trials \
         (truth {:?}, {} unscored), seed {}. Module docs of `src/sensing/evaluate.rs` give the streams \
         and the estimates; mutual information is the plug-in estimate (biased up by about \
         (k−1)(m−1)/(2n ln 2) bits on n trials).\n\n",
        r.part,
        r.a_m,
        r.mass_kg,
        r.belt_speed_m_s,
        r.d,
        r.pin_radius_m,
        r.mu_s,
        r.model,
        r.sensor.kind.name(),
        r.sensor.rate,
        r.sensor.height,
        r.sensor.noise_force,
        r.sensor.noise_torque,
        r.sensor.resolution_force,
        r.sensor.threshold,
        r.sensor.jitter,
        r.uncertainty.mu_c,
        r.uncertainty.tripod,
        r.uncertainty.theta_jitter_deg,
        r.uncertainty.d_jitter,
        ev.labels.join(", "),
        r.templates_per_hypothesis,
        ev.template_counts,
        r.trials,
        r.truth,
        ev.unscored,
        r.seed
    );
    md += &format!(
        "H(state) = {:.3} bits; chance accuracy {:.1}%.\n\n",
        ev.state_entropy_bits,
        100.0 * ev.chance_accuracy
    );
    for name in &r.classifiers {
        md += &format!("## {name}\n\n| noise | accuracy | 95% interval | unknown | I (bits) | confusion (rows true: decided … \\| unknown) |\n|---|---|---|---|---|---|\n");
        for c in ev.of(name) {
            md += &format!(
                "| ×{} | {:.1}% | [{:.1}, {:.1}]% | {} | {:.3} | {} |\n",
                c.noise_factor,
                100.0 * c.accuracy,
                100.0 * c.accuracy_ci95[0],
                100.0 * c.accuracy_ci95[1],
                c.unknown,
                c.mutual_information_bits,
                matrix_line(c).replace('|', "\\|")
            );
        }
        md += "\n";
    }
    for sk in &r.skipped {
        md += &format!("Skipped `{}`: {}\n\n", sk.classifier, sk.reason);
    }
    for u in &r.untrained {
        md += &format!(
            "`{}` could not be trained at noise ×{} (every reading counted unknown): {}\n\n",
            u.classifier, u.noise_factor, u.reason
        );
    }
    if let Some(pl) = &r.placement {
        md += "## Placement (nominal noise)\n\n| d | sensor | best classifier | I (bits) | accuracy | 95% interval |\n|---|---|---|---|---|---|\n";
        for row in &pl.rows {
            md += &format!(
                "| {:+.2} | {} | {} | {:.3} | {:.1}% | [{:.1}, {:.1}]% |\n",
                row.d,
                row.sensor,
                row.classifier.as_deref().unwrap_or("-"),
                row.mutual_information_bits,
                100.0 * row.accuracy,
                100.0 * row.accuracy_ci95[0],
                100.0 * row.accuracy_ci95[1]
            );
        }
        for &b in &pl.best_per_sensor {
            let row = &pl.rows[b];
            md += &format!(
                "\nBest {} placement: d = {} ({}, {:.3} bits, {:.1}%).",
                row.sensor,
                row.d,
                row.classifier.as_deref().unwrap_or("-"),
                row.mutual_information_bits,
                100.0 * row.accuracy
            );
        }
        md += "\n\n![placement](placement.svg)\n\n";
    }
    md += "## Figures\n\n![templates](templates.svg)\n\n![accuracy against noise](accuracy_noise.svg)\n";
    md
}
