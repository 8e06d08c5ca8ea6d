//! One sensing experiment as `pinfeed sense` runs it (docs/commands.md): the request (a part, one
//! push, hypotheses, a sensor, classifiers, a noise sweep and the declared uncertainty), its
//! checks ([`check`], errors naming the [`Setting`] at fault), the evaluation with the policy for
//! classifiers that cannot be trained ([`Checked::evaluate`]), the placement search
//! ([`Checked::place`]) and the typed result ([`SenseReport`]). The text and Markdown reports are
//! in `report::sense`.

mod run;

pub use run::{Evaluated, Placeholder, SenseReport, Skipped, Sweep, UncertaintyReport, Untrained};

use crate::geometry::{named, Polygon};
use crate::mechanics::limits::{self, num, OutOfRange};
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

/// A setting of a [`Request`], as its errors name it: [`SenseError`]'s message names it by its
/// field ([`Setting::field`]); a front end names it by what set it ([`SenseError::describe`];
/// `pinfeed sense` by its flag).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    /// [`Request::part`].
    Part,
    /// [`Request::scale`].
    Scale,
    /// [`Request::mass`].
    Mass,
    /// [`Request::belt_speed`].
    BeltSpeed,
    /// [`Request::d`].
    D,
    /// [`Request::pin_radius`].
    PinRadius,
    /// [`Request::mu_c`].
    MuC,
    /// [`Request::mu_s`].
    MuS,
    /// [`Request::tol`].
    Tol,
    /// [`Request::hypotheses`].
    Hypotheses,
    /// A field of [`Request::sensor`] ([`SensorSettings`]), by name (`rate`, `noise_force`, …).
    Sensor(&'static str),
    /// [`Request::sensor_kind`].
    SensorKind,
    /// [`Request::classifiers`].
    Classifiers,
    /// [`Request::reject_below`].
    RejectBelow,
    /// [`Request::noise`].
    Noise,
    /// [`Request::mu_c_range`].
    MuCRange,
    /// [`Request::theta_jitter`].
    ThetaJitter,
    /// [`Request::d_jitter`].
    DJitter,
    /// [`Request::templates`].
    Templates,
    /// [`Request::trials`].
    Trials,
    /// [`Request::truth`].
    Truth,
    /// [`Request::threads`].
    Threads,
    /// [`Request::placement_d`].
    PlacementD,
}

impl Setting {
    /// The field of [`Request`] (or of its [`SensorSettings`]) that holds the setting.
    pub fn field(self) -> &'static str {
        match self {
            Setting::Part => "part",
            Setting::Scale => "scale",
            Setting::Mass => "mass",
            Setting::BeltSpeed => "belt_speed",
            Setting::D => "d",
            Setting::PinRadius => "pin_radius",
            Setting::MuC => "mu_c",
            Setting::MuS => "mu_s",
            Setting::Tol => "tol",
            Setting::Hypotheses => "hypotheses",
            Setting::Sensor(field) => field,
            Setting::SensorKind => "sensor_kind",
            Setting::Classifiers => "classifiers",
            Setting::RejectBelow => "reject_below",
            Setting::Noise => "noise",
            Setting::MuCRange => "mu_c_range",
            Setting::ThetaJitter => "theta_jitter",
            Setting::DJitter => "d_jitter",
            Setting::Templates => "templates",
            Setting::Trials => "trials",
            Setting::Truth => "truth",
            Setting::Threads => "threads",
            Setting::PlacementD => "placement_d",
        }
    }
}

/// A request that cannot be run. Its message names the setting at fault by its [`Request`] field
/// (`scale must be …`); [`SenseError::describe`] names it otherwise (`pinfeed sense` by its flag).
#[derive(Debug)]
pub enum SenseError {
    /// A number outside its range.
    Range {
        /// The setting.
        setting: Setting,
        /// Which of the setting's numbers, when it has two (` LO`, ` HI`); empty otherwise.
        which: &'static str,
        /// The value, its range and what it is (`name`: the setting's field and `which`).
        range: OutOfRange,
    },
    /// A quantity that must be positive and finite is not, or is too large.
    Positive {
        /// The setting.
        setting: Setting,
        /// The value given.
        value: f64,
        /// The largest value allowed.
        hi: f64,
        /// The quantity's unit, in words.
        what: &'static str,
    },
    /// A count outside [1, max].
    Count {
        /// The setting.
        setting: Setting,
        /// The largest count allowed.
        max: usize,
        /// The count given.
        value: usize,
    },
    /// More threads than [`MAX_THREADS`].
    Threads(usize),
    /// A list with no entries or too many.
    ListLength {
        /// The setting.
        setting: Setting,
        /// The most entries allowed.
        max: usize,
        /// What the entries are, in words.
        unit: &'static str,
        /// The number of entries given.
        value: usize,
    },
    /// A word that is not one of the choices.
    Choice {
        /// The setting.
        setting: Setting,
        /// The choices, in words.
        expected: &'static str,
        /// The word given.
        got: String,
    },
    /// A sensor setting outside its range.
    Sensor {
        /// The setting's field name in [`SensorSettings`].
        field: &'static str,
        /// Why it is refused.
        message: String,
    },
    /// A sensor setting that leaves its range at one of the noise factors.
    NoiseSensor {
        /// The noise factor.
        factor: f64,
        /// The setting's field name.
        field: &'static str,
        /// Why it is refused.
        message: String,
    },
    /// A part spec that names no part.
    Part {
        /// The spec given.
        spec: String,
        /// Why it names no part.
        error: named::PartSpecError,
    },
    /// A part whose model cannot be built (the reason).
    PartModel(crate::mechanics::PartModelError),
    /// A hypothesis that is neither `stable`, `vertex-edge` nor a number of degrees.
    HypothesisDegrees(String),
    /// Hypotheses that cannot be told apart or built for the part.
    Hypotheses {
        /// The hypotheses as given.
        spec: String,
        /// Why they are refused.
        message: crate::sensing::templates::HypothesesError,
    },
    /// A μc range without a colon.
    MuCRangeForm(String),
    /// A bound of the μc range that is not a number.
    MuCRangeNumber(String),
    /// A μc range with LO above HI.
    MuCRangeOrder {
        /// The lower bound given.
        lo: f64,
        /// The upper bound given.
        hi: f64,
    },
    /// A classifier name that is not in [`classify::NAMES`].
    UnknownClassifier {
        /// The name given.
        name: String,
    },
    /// A classifier listed twice.
    ClassifierTwice(String),
    /// A classifier asked for by name could not be trained at any sweep point.
    Untrainable(String),
    /// None of the classifiers could be trained.
    NoClassifier,
    /// The evaluation or the placement search failed.
    Evaluate(crate::sensing::evaluate::EvaluateError),
}

impl SenseError {
    /// The setting at fault, if the error names one.
    pub fn setting(&self) -> Option<Setting> {
        use SenseError as E;
        Some(match self {
            E::Range { setting, .. }
            | E::Positive { setting, .. }
            | E::Count { setting, .. }
            | E::ListLength { setting, .. }
            | E::Choice { setting, .. } => *setting,
            E::Threads(_) => Setting::Threads,
            E::Sensor { field, .. } => Setting::Sensor(field),
            E::NoiseSensor { .. } => Setting::Noise,
            E::Part { .. } | E::PartModel(_) => Setting::Part,
            E::HypothesisDegrees(_) | E::Hypotheses { .. } => Setting::Hypotheses,
            E::MuCRangeForm(_) | E::MuCRangeNumber(_) | E::MuCRangeOrder { .. } => {
                Setting::MuCRange
            }
            E::UnknownClassifier { .. } | E::ClassifierTwice(_) | E::Untrainable(_) => {
                Setting::Classifiers
            }
            E::NoClassifier | E::Evaluate(_) => return None,
        })
    }

    /// The message, with each setting named by `name` (its [`Setting::field`] in the error's
    /// `Display`).
    pub fn describe(&self, name: impl Fn(Setting) -> String) -> String {
        use SenseError as E;
        let n = |s: Setting| name(s);
        match self {
            E::Range {
                setting,
                which,
                range,
            } => OutOfRange {
                name: format!("{}{which}", n(*setting)),
                ..range.clone()
            }
            .to_string(),
            E::Positive {
                setting,
                value,
                hi,
                what,
            } => format!(
                "{} must be a finite number > 0 and at most {} ({what}), got {}",
                n(*setting),
                num(*hi),
                num(*value)
            ),
            E::Count {
                setting,
                max,
                value,
            } => format!("{} must lie in [1, {max}], got {value}", n(*setting)),
            E::Threads(v) => format!(
                "{} must lie in [0, {MAX_THREADS}] (0: one per core), got {v}",
                n(Setting::Threads)
            ),
            E::ListLength {
                setting,
                max,
                unit,
                value,
            } => format!("{} takes 1 to {max} {unit}, got {value}", n(*setting)),
            E::Choice {
                setting,
                expected,
                got,
            } => format!("{} must be {expected}, got '{got}'", n(*setting)),
            E::Sensor { field, message } => format!("{}: {message}", n(Setting::Sensor(field))),
            E::NoiseSensor {
                factor,
                field,
                message,
            } => format!(
                "{} {}: the sensor's {field} leaves its range: {message}",
                n(Setting::Noise),
                num(*factor)
            ),
            E::Part { spec, error } => format!("{} '{spec}': {error}", n(Setting::Part)),
            E::PartModel(e) => format!("{}: {e}", n(Setting::Part)),
            E::HypothesisDegrees(t) => format!(
                "{}: '{t}' is not a number of degrees (or give stable or vertex-edge)",
                n(Setting::Hypotheses)
            ),
            E::Hypotheses { spec, message } => {
                format!("{} {spec}: {message}", n(Setting::Hypotheses))
            }
            E::MuCRangeForm(spec) => format!(
                "{} must be LO:HI (e.g. 0.3:0.7), got '{spec}'",
                n(Setting::MuCRange)
            ),
            E::MuCRangeNumber(t) => format!("{}: '{t}' is not a number", n(Setting::MuCRange)),
            E::MuCRangeOrder { lo, hi } => format!(
                "{}: LO must not exceed HI, got {}:{}",
                n(Setting::MuCRange),
                num(*lo),
                num(*hi)
            ),
            E::UnknownClassifier { name } => format!(
                "{}: unknown classifier '{name}'; known: {}",
                n(Setting::Classifiers),
                classify::NAMES.join(", ")
            ),
            E::ClassifierTwice(c) => format!("{}: '{c}' is listed twice", n(Setting::Classifiers)),
            E::Untrainable(reason) => format!("{}: {reason}", n(Setting::Classifiers)),
            E::NoClassifier => {
                "no classifier could be trained for these hypotheses and this sensor".to_string()
            }
            E::Evaluate(e) => e.to_string(),
        }
    }
}

impl std::fmt::Display for SenseError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.describe(|s| s.field().to_string()))
    }
}

impl std::error::Error for SenseError {}

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

/// `setting must be > 0 …` for strictly positive quantities.
fn positive(setting: Setting, v: f64, hi: f64, what: &'static str) -> Result<(), SenseError> {
    if !(v.is_finite() && v > 0.0 && v <= hi) {
        return Err(SenseError::Positive {
            setting,
            value: v,
            hi,
            what,
        });
    }
    Ok(())
}

/// `setting` (with `which` of its numbers) within [lo, hi] ([`limits::in_range`]).
fn in_range(
    setting: Setting,
    which: &'static str,
    v: f64,
    lo: f64,
    hi: f64,
    what: &str,
) -> Result<(), SenseError> {
    limits::in_range(&format!("{}{which}", setting.field()), v, lo, hi, what).map_err(|range| {
        SenseError::Range {
            setting,
            which,
            range,
        }
    })
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
    in_range(
        Setting::MuCRange,
        " LO",
        lo,
        min,
        max,
        "friction coefficient",
    )?;
    in_range(
        Setting::MuCRange,
        " HI",
        hi,
        min,
        max,
        "friction coefficient",
    )?;
    if lo > hi {
        return Err(SenseError::MuCRangeOrder { lo, hi });
    }
    Ok(if lo == hi {
        Distribution::Fixed(lo)
    } else {
        Distribution::Uniform { min: lo, max: hi }
    })
}

/// The sensor of the request (noise factor 1), validated; errors name the setting.
pub fn sensor_settings(r: &Request) -> Result<SensorSettings, SenseError> {
    let kind = match r.sensor_kind.trim() {
        "ft" => SensorKind::Ft,
        "timing" => SensorKind::Timing,
        other => {
            return Err(SenseError::Choice {
                setting: Setting::SensorKind,
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
    positive(Setting::Scale, a.scale, 100.0, "metres per part unit")?;
    positive(Setting::Mass, a.mass, 1e3, "kg")?;
    positive(Setting::BeltSpeed, a.belt_speed, 100.0, "m/s")?;
    in_range(
        Setting::MuC,
        "",
        a.mu_c,
        limits::MU_C.0,
        limits::MU_C.1,
        "friction coefficient",
    )?;
    in_range(
        Setting::MuS,
        "",
        a.mu_s,
        limits::MU_S.0,
        limits::MU_S.1,
        "support friction",
    )?;
    in_range(
        Setting::Tol,
        "",
        a.tol,
        limits::TOL.0,
        limits::TOL.1,
        "integration tolerance per step",
    )?;
    in_range(
        Setting::ThetaJitter,
        "",
        a.theta_jitter,
        0.0,
        180.0,
        "degrees",
    )?;
    in_range(Setting::DJitter, "", a.d_jitter, 0.0, 1.0, "units of a")?;
    in_range(
        Setting::RejectBelow,
        "",
        a.reject_below,
        0.0,
        1.0,
        "largest posterior",
    )?;
    if !(1..=MAX_TRIALS).contains(&a.trials) {
        return Err(SenseError::Count {
            setting: Setting::Trials,
            max: MAX_TRIALS,
            value: a.trials,
        });
    }
    if !(1..=MAX_TEMPLATES).contains(&a.templates) {
        return Err(SenseError::Count {
            setting: Setting::Templates,
            max: MAX_TEMPLATES,
            value: a.templates,
        });
    }
    if a.threads > MAX_THREADS {
        return Err(SenseError::Threads(a.threads));
    }
    if a.noise.is_empty() || a.noise.len() > MAX_FACTORS {
        return Err(SenseError::ListLength {
            setting: Setting::Noise,
            max: MAX_FACTORS,
            unit: "factors",
            value: a.noise.len(),
        });
    }
    for &f in &a.noise {
        in_range(
            Setting::Noise,
            "",
            f,
            0.0,
            1e6,
            "factor on the nominal noise, ≥ 0",
        )?;
    }
    if a.placement && (a.placement_d.is_empty() || a.placement_d.len() > MAX_PLACEMENT_D) {
        return Err(SenseError::ListLength {
            setting: Setting::PlacementD,
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
                setting: Setting::Truth,
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
        Setting::PinRadius,
        "",
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
    in_range(Setting::D, "", a.d, -reach, reach, beyond)?;
    if a.placement {
        for &d in &a.placement_d {
            in_range(Setting::PlacementD, "", d, -reach, reach, beyond)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The request `pinfeed sense --part tripoly1 --d=-0.2` makes, with its defaults.
    fn request() -> Request {
        Request {
            part: "tripoly1".into(),
            scale: 0.02,
            mass: 0.05,
            belt_speed: 0.05,
            d: -0.2,
            pin_radius: 0.0,
            mu_c: 0.5,
            mu_s: 0.3,
            model: Fidelity::Exact,
            tol: 1e-6,
            hypotheses: "stable".into(),
            sensor: SensorSettings::default(),
            sensor_kind: "ft".into(),
            classifiers: Vec::new(),
            reject_below: 0.0,
            noise: vec![1.0],
            mu_c_range: None,
            tripod: false,
            theta_jitter: 0.0,
            d_jitter: 0.0,
            templates: 8,
            trials: 10,
            truth: "cycle".into(),
            seed: 1,
            threads: 0,
            placement: false,
            placement_d: Vec::new(),
        }
    }

    /// The error `check` gives for the request `change` makes.
    fn refused(change: impl FnOnce(&mut Request)) -> SenseError {
        let mut r = request();
        change(&mut r);
        match check(&r) {
            Ok(_) => panic!("accepted"),
            Err(e) => e,
        }
    }

    #[test]
    fn errors_name_the_setting_by_its_field_or_by_the_callers_name() {
        assert!(check(&request()).is_ok());
        let cases: Vec<(SenseError, Setting, &str)> = vec![
            (
                refused(|r| r.scale = 1e3),
                Setting::Scale,
                "scale must be a finite number > 0",
            ),
            (
                refused(|r| r.mu_c = 99.0),
                Setting::MuC,
                "mu_c must be in [0, 5]",
            ),
            (
                refused(|r| r.mu_c_range = Some("0.3:99".into())),
                Setting::MuCRange,
                "mu_c_range HI must be in [0, 5]",
            ),
            (
                refused(|r| r.sensor_kind = "sonar".into()),
                Setting::SensorKind,
                "sensor_kind must be ft or timing, got 'sonar'",
            ),
            (
                refused(|r| r.sensor.noise_force = -1.0),
                Setting::Sensor("noise_force"),
                "noise_force: must lie in",
            ),
            (
                refused(|r| r.trials = 0),
                Setting::Trials,
                "trials must lie in [1, ",
            ),
            (
                refused(|r| r.threads = 1 << 20),
                Setting::Threads,
                "threads must lie in [0, ",
            ),
            (
                refused(|r| {
                    r.sensor.noise_force = 1e5;
                    r.noise = vec![1.0, 1e3];
                }),
                Setting::Noise,
                "noise 1000: the sensor's",
            ),
            (
                refused(|r| r.classifiers = vec!["oracle".into()]),
                Setting::Classifiers,
                "classifiers: unknown classifier 'oracle'",
            ),
        ];
        for (e, setting, text) in cases {
            assert_eq!(e.setting(), Some(setting), "{e}");
            let message = e.to_string();
            assert!(message.starts_with(text), "{message}");
            assert!(
                !message.contains("--"),
                "a library message names a flag: {message}"
            );
            // A caller names the setting its own way, the rest of the message unchanged.
            let named = e.describe(|s| format!("<{}>", s.field()));
            let field = setting.field();
            assert_eq!(named, format!("<{field}>{}", &message[field.len()..]));
        }
        assert_eq!(SenseError::NoClassifier.setting(), None);
    }
}
