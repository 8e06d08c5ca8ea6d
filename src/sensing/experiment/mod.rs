//! One sensing experiment as `pinfeed sense` runs it (docs/commands.md): the request (a part, one
//! push, hypotheses, a sensor, classifiers, a noise sweep and the declared uncertainty), its
//! checks ([`check`], errors naming the command's flags), the evaluation with the policy for
//! classifiers that cannot be trained ([`Checked::evaluate`]), the placement search
//! ([`Checked::place`]) and the typed result ([`SenseReport`]). The text and Markdown reports are
//! in `report::sense`.

mod run;

pub use run::{Evaluated, Placeholder, SenseReport, Skipped, Sweep, UncertaintyReport, Untrained};

use crate::geometry::{named, Polygon};
use crate::mechanics::limits::{self, in_range, num, OutOfRange};
use crate::mechanics::{Fidelity, PartModel, Support};
use crate::random::distribution::Distribution;
use crate::sensing::classify;
use crate::sensing::evaluate::{applicable, TruthDraw, MAX_TEMPLATES, MAX_TRIALS};
use crate::sensing::templates::{Hypotheses, PushSetup, Uncertainty};
use crate::sensing::{SensorKind, SensorSettings};

/// Most noise factors (`--noise`; for the most hypotheses see [`Hypotheses::orientations`]).
pub const MAX_FACTORS: usize = 64;
/// Most placement offsets (`--placement-d`).
pub const MAX_PLACEMENT_D: usize = 201;
/// Most threads (`--threads`; 0 means one per core).
pub const MAX_THREADS: usize = 1024;

/// Everything a sensing experiment is asked for, unchecked (the pin radius in part units, the
/// unit of the part's vertices, as `scale` makes them metres; other lengths in metres; `d` in
/// units of a).
#[derive(Debug, Clone)]
pub struct Request {
    /// A part spec (`tripoly1`, `rect:W:H`, `vertices:…`).
    pub part: String,
    /// Metres per part unit (in (0, 100]).
    pub scale: f64,
    /// Part mass (kg, in (0, 1000]).
    pub mass: f64,
    /// Belt speed (m/s, in (0, 100]).
    pub belt_speed: f64,
    /// Lateral offset of the pin, d = (y_pin − y_com)/a (units of a; the pin must be able to touch
    /// the part).
    pub d: f64,
    /// Pin radius (part units, at most [`crate::mechanics::limits::PIN_RADIUS_A`]·a; 0: a point
    /// pin).
    pub pin_radius: f64,
    /// Pin–part friction coefficient μc (nominal; see `mu_c_range`).
    pub mu_c: f64,
    /// Part–belt (support) friction coefficient μs.
    pub mu_s: f64,
    /// The contact model's fidelity.
    pub model: Fidelity,
    /// Integration tolerance per step of the contact model.
    pub tol: f64,
    /// `stable`, `vertex-edge` or degrees.
    pub hypotheses: String,
    /// The sensor at noise factor 1; its kind is given by `sensor_kind`.
    pub sensor: SensorSettings,
    /// `ft` or `timing`.
    pub sensor_kind: String,
    /// Classifier names (empty: the defaults for the sensor and hypotheses).
    pub classifiers: Vec<String>,
    /// Classifiers decide "unknown" when their largest posterior is below this (in [0, 1]).
    pub reject_below: f64,
    /// Noise factors of the sweep, each ≥ 0, applied to the sensor's nominal noise (1 to
    /// [`MAX_FACTORS`] of them).
    pub noise: Vec<f64>,
    /// `LO:HI`.
    pub mu_c_range: Option<String>,
    /// Draw a random tripod support per push instead of uniform pressure.
    pub tripod: bool,
    /// Standard deviation of the orientation about each hypothesis (degrees, in [0, 180]).
    pub theta_jitter: f64,
    /// Standard deviation of d (units of a, in [0, 1]).
    pub d_jitter: f64,
    /// Templates per hypothesis (1 to [`MAX_TEMPLATES`]).
    pub templates: usize,
    /// Trials: simulated pushes, each read at every sensor point and classified by every
    /// classifier there (1 to [`MAX_TRIALS`]).
    pub trials: usize,
    /// `cycle` or `uniform`.
    pub truth: String,
    /// Seed of the templates' and trials' random streams; the same seed gives the same report.
    pub seed: u64,
    /// Worker threads (0: one per core; at most [`MAX_THREADS`]).
    pub threads: usize,
    /// Also search the placement of the pin over `placement_d`.
    pub placement: bool,
    /// Offsets d (units of a) the placement search tries (1 to [`MAX_PLACEMENT_D`]).
    pub placement_d: Vec<f64>,
}

/// A request that cannot be run (messages name the flags of `pinfeed sense`).
#[derive(Debug, thiserror::Error)]
pub enum SenseError {
    /// A number outside its range.
    #[error(transparent)]
    Range(#[from] OutOfRange),
    /// A quantity that must be positive and finite is not, or is too large.
    #[error("{flag} must be a finite number > 0 and at most {} ({what}), got {}", num(*hi), num(*value))]
    Positive {
        /// The flag.
        flag: &'static str,
        /// The value given.
        value: f64,
        /// The largest value allowed.
        hi: f64,
        /// The quantity's unit, in words.
        what: &'static str,
    },
    /// A count outside [1, max].
    #[error("{flag} must lie in [1, {max}], got {value}")]
    Count {
        /// The flag.
        flag: &'static str,
        /// The largest count allowed.
        max: usize,
        /// The count given.
        value: usize,
    },
    /// More threads than [`MAX_THREADS`].
    #[error("--threads must lie in [0, {MAX_THREADS}] (0: one per core), got {0}")]
    Threads(usize),
    /// A list with no entries or too many.
    #[error("{flag} takes 1 to {max} {unit}, got {value}")]
    ListLength {
        /// The flag.
        flag: &'static str,
        /// The most entries allowed.
        max: usize,
        /// What the entries are, in words.
        unit: &'static str,
        /// The number of entries given.
        value: usize,
    },
    /// A word that is not one of the choices.
    #[error("{flag} must be {expected}, got '{got}'")]
    Choice {
        /// The flag.
        flag: &'static str,
        /// The choices, in words.
        expected: &'static str,
        /// The word given.
        got: String,
    },
    /// A sensor setting outside its range.
    #[error("--{}: {message}", field.replace('_', "-"))]
    Sensor {
        /// The setting's field name (the flag is `--` and the name with dashes).
        field: &'static str,
        /// Why it is refused.
        message: String,
    },
    /// A sensor setting that leaves its range at one of the noise factors.
    #[error("--noise {}: the sensor's {field} leaves its range: {message}", num(*factor))]
    NoiseSensor {
        /// The noise factor.
        factor: f64,
        /// The setting's field name.
        field: &'static str,
        /// Why it is refused.
        message: String,
    },
    /// A part spec that names no part.
    #[error("--part '{spec}': {error}")]
    Part {
        /// The spec given.
        spec: String,
        /// Why it names no part.
        error: named::PartSpecError,
    },
    /// A part whose model cannot be built (the reason).
    #[error("--part: {0}")]
    PartModel(crate::mechanics::PartModelError),
    /// A hypothesis that is neither `stable`, `vertex-edge` nor a number of degrees.
    #[error("--hypotheses: '{0}' is not a number of degrees (or give stable or vertex-edge)")]
    HypothesisDegrees(String),
    /// Hypotheses that cannot be told apart or built for the part.
    #[error("--hypotheses {spec}: {message}")]
    Hypotheses {
        /// The `--hypotheses` value given.
        spec: String,
        /// Why it is refused.
        message: crate::sensing::templates::HypothesesError,
    },
    /// `--mu-c-range` without a colon.
    #[error("--mu-c-range must be LO:HI (e.g. 0.3:0.7), got '{0}'")]
    MuCRangeForm(String),
    /// A bound of `--mu-c-range` that is not a number.
    #[error("--mu-c-range: '{0}' is not a number")]
    MuCRangeNumber(String),
    /// `--mu-c-range` with LO above HI.
    #[error("--mu-c-range: LO must not exceed HI, got {}:{}", num(*lo), num(*hi))]
    MuCRangeOrder {
        /// The lower bound given.
        lo: f64,
        /// The upper bound given.
        hi: f64,
    },
    /// A classifier name that is not in [`classify::NAMES`].
    #[error("--classifiers: unknown classifier '{name}'; known: {}", classify::NAMES.join(", "))]
    UnknownClassifier {
        /// The name given.
        name: String,
    },
    /// A classifier listed twice.
    #[error("--classifiers: '{0}' is listed twice")]
    ClassifierTwice(String),
    /// A classifier asked for by name could not be trained at any sweep point.
    #[error("--classifiers: {0}")]
    Untrainable(String),
    /// None of the classifiers could be trained.
    #[error("no classifier could be trained for these hypotheses and this sensor")]
    NoClassifier,
    /// The evaluation or the placement search failed.
    #[error("{0}")]
    Evaluate(crate::sensing::evaluate::EvaluateError),
}

/// A request checked: the push, its part model, hypotheses, uncertainty, sensor and classifiers.
pub struct Checked {
    /// The part spec, as given.
    pub part_name: String,
    /// The push: the part in metres, d, pin radius (m), frictions, model and tolerance.
    pub setup: PushSetup,
    /// The part's model under uniform support.
    pub model: PartModel,
    /// The hypotheses to tell apart.
    pub hyps: Hypotheses,
    /// The declared uncertainty of μc, the support and the pose.
    pub unc: Uncertainty,
    /// The sensor at noise factor 1.
    pub sensor: SensorSettings,
    /// The classifiers to score: those named, or the defaults for the sensor and hypotheses.
    pub classifiers: Vec<String>,
    /// Classifiers named by the request (not the defaults).
    pub explicit: bool,
    /// How each trial's hypothesis is chosen.
    pub truth: TruthDraw,
}

/// `flag must be > 0 …` for strictly positive quantities.
fn positive(flag: &'static str, v: f64, hi: f64, what: &'static str) -> Result<(), SenseError> {
    if !(v.is_finite() && v > 0.0 && v <= hi) {
        return Err(SenseError::Positive {
            flag,
            value: v,
            hi,
            what,
        });
    }
    Ok(())
}

/// Parse hypotheses for a part: `stable`, `vertex-edge` or a list of degrees.
pub fn parse_hypotheses(spec: &str, poly: &Polygon) -> Result<Hypotheses, SenseError> {
    let s = spec.trim();
    let hyps = match s.to_lowercase().as_str() {
        "stable" => Hypotheses::stable_states(poly),
        "vertex-edge" => Ok(Hypotheses::vertex_edge_sweep()),
        _ => {
            let degrees = s
                .split(',')
                .map(|tok| {
                    let t = tok.trim();
                    t.parse::<f64>()
                        .map_err(|_| SenseError::HypothesisDegrees(t.to_string()))
                })
                .collect::<Result<Vec<f64>, SenseError>>()?;
            Hypotheses::orientations(degrees)
        }
    };
    hyps.map_err(|message| SenseError::Hypotheses {
        spec: s.to_string(),
        message,
    })
}

/// Parse an uncertain μc `LO:HI` (uniform; fixed when LO = HI).
fn parse_range(spec: &str) -> Result<Distribution, SenseError> {
    let (lo, hi) = spec
        .split_once(':')
        .ok_or_else(|| SenseError::MuCRangeForm(spec.to_string()))?;
    let p = |t: &str| -> Result<f64, SenseError> {
        t.trim()
            .parse::<f64>()
            .map_err(|_| SenseError::MuCRangeNumber(t.to_string()))
    };
    let (lo, hi) = (p(lo)?, p(hi)?);
    let (min, max) = limits::MU_C;
    in_range("--mu-c-range LO", lo, min, max, "friction coefficient")?;
    in_range("--mu-c-range HI", hi, min, max, "friction coefficient")?;
    if lo > hi {
        return Err(SenseError::MuCRangeOrder { lo, hi });
    }
    Ok(if lo == hi {
        Distribution::Fixed(lo)
    } else {
        Distribution::Uniform { min: lo, max: hi }
    })
}

/// The sensor of the request (noise factor 1), validated; errors name the flag.
pub fn sensor_settings(r: &Request) -> Result<SensorSettings, SenseError> {
    let kind = match r.sensor_kind.trim() {
        "ft" => SensorKind::Ft,
        "timing" => SensorKind::Timing,
        other => {
            return Err(SenseError::Choice {
                flag: "--sensor",
                expected: "ft or timing",
                got: other.to_string(),
            })
        }
    };
    let s = SensorSettings { kind, ..r.sensor };
    s.validate().map_err(|e| SenseError::Sensor {
        field: e.field,
        message: e.message,
    })?;
    Ok(s)
}

/// Check every setting of a request and build what it fixes.
pub fn check(a: &Request) -> Result<Checked, SenseError> {
    check_settings(a)?;
    let truth = truth_draw(&a.truth)?;
    let fidelity = a.model;
    let sensor = sensor_settings(a)?;
    check_noise_factors(&sensor, &a.noise)?;
    let part = named::part_from_spec(&a.part).map_err(|error| SenseError::Part {
        spec: a.part.clone(),
        error,
    })?;
    let poly = part.scaled(a.scale);
    check_offsets(a, part.radius())?;
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
    let (classifiers, explicit) = classifier_list(a, sensor.kind, &hyps)?;
    let model = PartModel::new(&poly, &Support::Uniform).map_err(SenseError::PartModel)?;
    let setup = PushSetup {
        polygon: poly,
        d: a.d,
        pin_radius: a.pin_radius * a.scale,
        mu_c: a.mu_c,
        mu_s: a.mu_s,
        fidelity,
        tol: a.tol,
        mass: a.mass,
        belt_speed: a.belt_speed,
        height: sensor.height,
    };
    Ok(Checked {
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

/// Check the request's numbers, counts and list lengths, each against its range (the first
/// step of [`check`], in the order of its error messages).
fn check_settings(a: &Request) -> Result<(), SenseError> {
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
        return Err(SenseError::Count {
            flag: "--trials",
            max: MAX_TRIALS,
            value: a.trials,
        });
    }
    if !(1..=MAX_TEMPLATES).contains(&a.templates) {
        return Err(SenseError::Count {
            flag: "--templates",
            max: MAX_TEMPLATES,
            value: a.templates,
        });
    }
    if a.threads > MAX_THREADS {
        return Err(SenseError::Threads(a.threads));
    }
    if a.noise.is_empty() || a.noise.len() > MAX_FACTORS {
        return Err(SenseError::ListLength {
            flag: "--noise",
            max: MAX_FACTORS,
            unit: "factors",
            value: a.noise.len(),
        });
    }
    for &f in &a.noise {
        in_range("--noise", f, 0.0, 1e6, "factor on the nominal noise, ≥ 0")?;
    }
    if a.placement && (a.placement_d.is_empty() || a.placement_d.len() > MAX_PLACEMENT_D) {
        return Err(SenseError::ListLength {
            flag: "--placement-d",
            max: MAX_PLACEMENT_D,
            unit: "offsets",
            value: a.placement_d.len(),
        });
    }
    Ok(())
}

/// How the true hypothesis of each trial is drawn (`--truth`).
fn truth_draw(spec: &str) -> Result<TruthDraw, SenseError> {
    Ok(match spec.trim() {
        "cycle" => TruthDraw::Cycle,
        "uniform" => TruthDraw::Uniform,
        other => {
            return Err(SenseError::Choice {
                flag: "--truth",
                expected: "cycle or uniform",
                got: other.to_string(),
            })
        }
    })
}

/// Check that the sensor is valid at every noise factor of the sweep.
fn check_noise_factors(sensor: &SensorSettings, noise: &[f64]) -> Result<(), SenseError> {
    for &f in noise {
        sensor
            .with_noise_factor(f)
            .validate()
            .map_err(|e| SenseError::NoiseSensor {
                factor: f,
                field: e.field,
                message: e.message,
            })?;
    }
    Ok(())
}

/// Check the pin radius, the offset d and the placement offsets against the part's radius
/// (`radius_units`, in part units).
fn check_offsets(a: &Request, radius_units: f64) -> Result<(), SenseError> {
    in_range(
        "--pin-radius",
        a.pin_radius,
        0.0,
        limits::PIN_RADIUS_A * radius_units,
        &format!(
            "part units; at most {}·a, a = {} part units",
            limits::PIN_RADIUS_A,
            num(radius_units)
        ),
    )?;
    let reach = 1.0 + a.pin_radius / radius_units;
    let beyond = "units of a; beyond it the pin cannot touch the part";
    in_range("--d", a.d, -reach, reach, beyond)?;
    if a.placement {
        for &d in &a.placement_d {
            in_range("--placement-d", d, -reach, reach, beyond)?;
        }
    }
    Ok(())
}

/// The classifiers to evaluate, and whether they were given explicitly (each known and named
/// once) rather than the defaults for the sensor and hypotheses.
fn classifier_list(
    a: &Request,
    kind: SensorKind,
    hyps: &Hypotheses,
) -> Result<(Vec<String>, bool), SenseError> {
    let explicit = !a.classifiers.is_empty();
    let classifiers: Vec<String> = if explicit {
        let mut v: Vec<String> = Vec::new();
        for c in &a.classifiers {
            let c = c.trim().to_string();
            if !classify::NAMES.contains(&c.as_str()) {
                return Err(SenseError::UnknownClassifier { name: c });
            }
            if v.contains(&c) {
                return Err(SenseError::ClassifierTwice(c));
            }
            v.push(c);
        }
        v
    } else {
        applicable(kind, hyps)
    };
    Ok((classifiers, explicit))
}
