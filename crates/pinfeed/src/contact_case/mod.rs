//! One fully specified pin (or fence) pass over one part, as `pinfeed contact` runs it and as
//! `sense`, `map`, `validate` and `calibrate` describe theirs (docs/commands.md#one-contact-pinfeed-contact).
//!
//! The part starts with its centroid at the origin of the belt frame at orientation θ0; the pin
//! starts just clear of the part's circumscribed circle, at x = a + ρ + 0.01a, y = d·a, and travels
//! in −x relative to the belt (plus w per unit travel for a moving pin). All lengths are in the
//! part's units. [`check`] holds the input ranges, [`report`] the summary of an outcome,
//! [`batch`] the CSV batch of cases and [`maps`] the configuration maps of a case (θ0 over the
//! circle, for each d), exact, from the map tier or over an ensemble.

pub mod batch;
pub mod check;
pub mod maps;
pub mod report;

use crate::mechanics::limits::{num, OutOfRange};
pub use check::{check_geometry, check_inputs, reach};
pub use report::ContactReport;

use crate::geometry::{named, Polygon, Pose, Vec2};
use crate::mechanics::{
    push, push_fence, push_path, ContactOutcome, ContactSettings, FenceSpec, Fidelity, PartModel,
    Pin, PinPath, Support, TraceSample, Turn,
};

/// One fully specified contact case.
#[derive(Debug, Clone)]
pub struct Case {
    /// The part: a name or spec as [`named::part_from_spec`] reads it (`tripoly1`, `rect:W:H`,
    /// `vertices:…`).
    pub part: String,
    /// Initial orientation θ0 of the part (degrees, counter-clockwise).
    pub theta0_deg: f64,
    /// Lateral offset of the pin's start, d = y/a (units of a; beyond the reach the pin cannot
    /// touch the part).
    pub d: f64,
    /// Pin–part friction coefficient μc.
    pub mu_c: f64,
    /// Part–belt (support) friction coefficient μs.
    pub mu_s: f64,
    /// The contact model (exact, ellipsoid or tip).
    pub model: Fidelity,
    /// Pin radius (part units, at most [`crate::mechanics::limits::PIN_RADIUS_A`]·a; 0: a point
    /// pin).
    pub pin_radius: f64,
    /// Lateral speed w of the pin as a fraction of the belt speed (0: a still pin).
    pub pin_speed: f64,
    /// A moving pin stops after this much belt travel (units of a).
    pub pin_stop: Option<f64>,
    /// A moving pin stops after this much belt travel (units of a) past its first touch.
    pub pin_stop_after_touch: Option<f64>,
    /// The support spec: `uniform` or `tripod:SEED`.
    pub support: String,
    /// Integration tolerance per step.
    pub tol: f64,
    /// A fence (angle in degrees, length in part units; None = default length) instead of a pin.
    pub fence: Option<(f64, Option<f64>)>,
    /// The fence's tail radius (part units; None: no tail), with a fence.
    pub fence_tail: Option<f64>,
}

impl Case {
    /// A pin pass over `part` (a name as `named::part_from_spec` reads it) at θ0 (degrees), d and
    /// μc, with the command line's defaults for the rest: exact fidelity, μs 0.3, a point pin
    /// standing still, uniform support, tolerance 1e-6, no fence.
    pub fn new(part: &str, theta0_deg: f64, d: f64, mu_c: f64) -> Case {
        Case {
            part: part.to_string(),
            theta0_deg,
            d,
            mu_c,
            mu_s: 0.3,
            model: Fidelity::Exact,
            pin_radius: 0.0,
            pin_speed: 0.0,
            pin_stop: None,
            pin_stop_after_touch: None,
            support: "uniform".into(),
            tol: 1e-6,
            fence: None,
            fence_tail: None,
        }
    }
}

/// A case that cannot be run; the messages name the flag (or batch column) of each setting.
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    /// A number outside its range.
    #[error(transparent)]
    OutOfRange(#[from] OutOfRange),
    /// A setting that is NaN or infinite.
    #[error("{name} must be a finite number, got {}", num(*value))]
    NotFinite {
        /// The flag or column.
        name: String,
        /// The value given.
        value: f64,
    },
    /// A pin radius that is negative, not finite or above
    /// [`crate::mechanics::limits::PIN_RADIUS_A`]·a.
    #[error("{name} must be a finite number >= 0 (part units, at most {}·a), got {}", crate::mechanics::limits::PIN_RADIUS_A, num(*value))]
    PinRadius {
        /// The flag or column.
        name: String,
        /// The radius given (part units).
        value: f64,
    },
    /// A pin radius above the limit for this part.
    #[error("{name} must lie in [0, {}] (part units: at most {}·a, a = {}), got {}", num(*max), crate::mechanics::limits::PIN_RADIUS_A, num(*a), num(*value))]
    PinRadiusForPart {
        /// The flag or column.
        name: String,
        /// The largest radius allowed (part units).
        max: f64,
        /// The part's circumradius a (part units).
        a: f64,
        /// The radius given (part units).
        value: f64,
    },
    /// A fence length outside its range for this part.
    #[error("{name}: the length must lie in [{}, {}] (part units: {}·a to {}·a, a = {}), got {}", num(*lo), num(*hi), num(crate::mechanics::limits::FENCE_LENGTH_A.0), num(crate::mechanics::limits::FENCE_LENGTH_A.1), num(*a), num(*value))]
    FenceLength {
        /// The setting's name as the caller knows it (the fence's).
        name: String,
        /// The shortest length allowed (part units).
        lo: f64,
        /// The longest length allowed (part units).
        hi: f64,
        /// The part's circumradius a (part units).
        a: f64,
        /// The length given (part units).
        value: f64,
    },
    /// A fence tail radius outside its range for this part.
    #[error("{name} must lie in [{}, {}] (part units: {}·a to {}·a, a = {}: a sharper tail is the fence's corner, a wider one turns the fence over more than a thousand part sizes), got {}", num(*lo), num(*hi), num(crate::mechanics::limits::FENCE_TAIL_RADIUS_A.0), num(crate::mechanics::limits::FENCE_TAIL_RADIUS_A.1), num(*a), num(*value))]
    FenceTail {
        /// The setting's name as the caller knows it (the tail's).
        name: String,
        /// The smallest radius allowed (part units).
        lo: f64,
        /// The largest radius allowed (part units).
        hi: f64,
        /// The part's circumradius a (part units).
        a: f64,
        /// The radius given (part units).
        value: f64,
    },
    /// A fence tail without a fence.
    #[error("{name} is the tail of a fence: give a fence too")]
    TailWithoutFence {
        /// The setting's name as the caller knows it (the tail's).
        name: String,
    },
    /// An offset d at which the pin cannot touch the part.
    #[error("{name} = {} is out of range: it must lie in [-{}, {}] (units of a: beyond it this pin cannot touch the part)", num(*d), num(*limit), num(*limit))]
    Unreachable {
        /// The flag or column.
        name: String,
        /// The offset given (units of a).
        d: f64,
        /// The largest |d| at which the pin can touch the part (units of a).
        limit: f64,
    },
    /// A fence `ANGLE[:LENGTH]` with a part that is not a number.
    #[error("{name} '{spec}': the {what} is not a number")]
    FenceNumber {
        /// The setting's name as the caller knows it.
        name: String,
        /// The value given.
        spec: String,
        /// Which part of it: the angle or the length.
        what: &'static str,
        /// Why it is not a number.
        #[source]
        source: std::num::ParseFloatError,
    },
    /// A fence angle outside (−90°, 90°).
    #[error("{name} '{spec}': the angle must be strictly between -90 and 90 degrees, got {}", num(*angle))]
    FenceAngle {
        /// The setting's name as the caller knows it.
        name: String,
        /// The value given.
        spec: String,
        /// The angle given (degrees).
        angle: f64,
    },
    /// A fence length that is not positive.
    #[error("{name} '{spec}': the length must be a positive number (part units), got {}", num(*length))]
    FenceLengthSign {
        /// The setting's name as the caller knows it.
        name: String,
        /// The value given.
        spec: String,
        /// The length given (part units).
        length: f64,
    },
    /// An unknown contact model name (not exact, ellipsoid or tip).
    #[error("unknown model '{0}'; expected exact, ellipsoid or tip")]
    Model(String),
    /// An unknown `--model` of `contact` or `map` (where the map tier is a choice too).
    #[error("unknown model '{0}'; expected exact, ellipsoid, tip or map")]
    ModelChoice(String),
    /// A part spec that names no part.
    #[error("part '{part}'")]
    Part {
        /// The part spec given.
        part: String,
        /// Why it names no part.
        #[source]
        source: named::PartSpecError,
    },
    /// The support specification is refused.
    #[error(transparent)]
    Support(#[from] crate::mechanics::part_model::SupportSpecError),
    /// The part's contact model could not be built.
    #[error(transparent)]
    Compile(#[from] crate::mechanics::PartModelError),
    /// A lateral stop the moving pin never reaches, or reaches too late.
    #[error("{name} {}: a pin starting at d = {} and moving {} per unit of travel reaches it after {} units of a; that must lie in [1e-9, 1000] (Y on the side the pin moves to, within 1000·|w| of d)", num(*y), num(*d), num(*w), num(*travel))]
    StopAt {
        /// The setting's name as the caller knows it.
        name: String,
        /// The lateral position to stop at (units of a).
        y: f64,
        /// The pin's starting offset (units of a).
        d: f64,
        /// The pin's lateral speed (fraction of the belt speed).
        w: f64,
        /// The belt travel to reach `y` (units of a).
        travel: f64,
    },
}

/// Parse `ANGLE_DEG[:LENGTH]`; an error names the setting `name` (what the caller calls it).
pub fn parse_fence(spec: &str, name: &str) -> Result<(f64, Option<f64>), CaseError> {
    let number = |what: &'static str, t: &str| {
        t.trim()
            .parse::<f64>()
            .map_err(|source| CaseError::FenceNumber {
                name: name.to_string(),
                spec: spec.to_string(),
                what,
                source,
            })
    };
    let mut it = spec.splitn(2, ':');
    let angle = number("angle", it.next().unwrap_or(""))?;
    if !(angle.is_finite() && angle.abs() < 90.0) {
        return Err(CaseError::FenceAngle {
            name: name.to_string(),
            spec: spec.to_string(),
            angle,
        });
    }
    let length = match it.next() {
        None => None,
        Some(l) => {
            let l = number("length", l)?;
            if !(l.is_finite() && l > 0.0) {
                return Err(CaseError::FenceLengthSign {
                    name: name.to_string(),
                    spec: spec.to_string(),
                    length: l,
                });
            }
            Some(l)
        }
    };
    Ok((angle, length))
}

/// Parse a fidelity name: exact, ellipsoid or tip.
pub fn parse_model(s: &str) -> Result<Fidelity, CaseError> {
    Fidelity::parse(s.trim()).ok_or_else(|| CaseError::Model(s.to_string()))
}

/// What a pass is answered by (`--model` of `pinfeed contact` and `pinfeed map`): the contact
/// model at a fidelity, or the certified map tier over the exact model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelChoice {
    /// The contact model at this fidelity (`exact`, `ellipsoid`, `tip`).
    Model(Fidelity),
    /// The map tier (`map`).
    Map,
}

impl ModelChoice {
    /// The model the passes are computed with: the fidelity chosen, or under the map tier the
    /// exact model (which answers wherever the map cannot vouch).
    pub fn computed_with(self) -> Fidelity {
        match self {
            ModelChoice::Model(f) => f,
            ModelChoice::Map => Fidelity::Exact,
        }
    }
}

impl std::str::FromStr for ModelChoice {
    type Err = CaseError;

    /// `exact`, `ellipsoid`, `tip` or `map` (surrounding blanks ignored).
    fn from_str(s: &str) -> Result<ModelChoice, CaseError> {
        match s.trim() {
            "map" => Ok(ModelChoice::Map),
            m => Fidelity::parse(m)
                .map(ModelChoice::Model)
                .ok_or_else(|| CaseError::ModelChoice(m.to_string())),
        }
    }
}

/// The belt travel (units of a) after which a pin starting at lateral offset `d` and moving at
/// `w` (lateral per unit of travel) stands at offset `y`: (y − d)/w, in the range of
/// [`Case::pin_stop`]; an error names the setting `name` (what the caller calls the stop).
pub fn stop_travel(y: f64, d: f64, w: f64, name: &str) -> Result<f64, CaseError> {
    let s = (y - d) / w;
    if !(y.is_finite() && s.is_finite() && (1e-9..=1e3).contains(&s)) {
        let name = name.to_string();
        return Err(CaseError::StopAt {
            name,
            y,
            d,
            w,
            travel: s,
        });
    }
    Ok(s)
}

/// The fence of a case: the convention of [`crate::maps::fence_pass_start`] (its line 1.01a clear of
/// the centroid, crossing y = d·a; its upstream end 1.5a beyond the part's band on the side it
/// comes from), with the case's μc as the fence friction μf.
pub fn case_fence(poly: &Polygon, c: &Case, angle_deg: f64, length: Option<f64>) -> FenceSpec {
    crate::maps::fence_pass_start(poly, c.d, angle_deg, length, c.mu_c).with_tail(c.fence_tail)
}

/// The initial pose and pin start for a case (part centred at the origin, pin just clear of it):
/// the convention of [`crate::maps::pass_start`], shared with configuration maps.
pub fn case_geometry(poly: &Polygon, c: &Case) -> (Pose, Vec2) {
    crate::maps::pass_start(poly, c.theta0_deg, c.d, c.pin_radius)
}

/// Resolve a part spec and a support spec into the polygon and its compiled contact model.
pub fn compile_part(part: &str, support: &str) -> Result<(Polygon, PartModel), CaseError> {
    let poly = named::part_from_spec(part).map_err(|source| CaseError::Part {
        part: part.to_string(),
        source,
    })?;
    let support = Support::parse(support, &poly)?;
    let model = PartModel::new(&poly, &support)?;
    Ok((poly, model))
}

/// The contact-model settings and the pin of a case.
pub fn settings_and_pin(c: &Case) -> (ContactSettings, Pin) {
    let settings = ContactSettings {
        fidelity: c.model,
        mu_c: c.mu_c,
        mu_s: c.mu_s,
        tol: c.tol,
        ..ContactSettings::default()
    };
    let pin = Pin {
        radius: c.pin_radius,
        lateral_speed: c.pin_speed,
    };
    (settings, pin)
}

/// Run one case; returns the polygon, the outcome and (if asked) the trace. An error names a
/// setting by `name(field)` (the caller's name for the case's field).
pub fn run_case(
    c: &Case,
    want_trace: bool,
    name: &dyn Fn(&str) -> String,
) -> Result<(Polygon, ContactOutcome, Vec<TraceSample>), CaseError> {
    check_inputs(c, name)?;
    let (poly, model) = compile_part(&c.part, &c.support)?;
    check_geometry(c, &poly, name)?;
    let (out, trace) = run_compiled(c, &poly, &model, want_trace);
    Ok((poly, out, trace))
}

/// Run a validated case on an already compiled part.
pub fn run_compiled(
    c: &Case,
    poly: &Polygon,
    model: &PartModel,
    want_trace: bool,
) -> (ContactOutcome, Vec<TraceSample>) {
    let (settings, pin) = settings_and_pin(c);
    let (pose, start) = case_geometry(poly, c);
    let mut trace: Vec<TraceSample> = Vec::new();
    let recorder: Option<&mut dyn crate::mechanics::Recorder> =
        if want_trace { Some(&mut trace) } else { None };
    let out = match c.fence {
        Some((angle, length)) => {
            let fence = case_fence(poly, c, angle, length);
            push_fence(model, pose, &fence, &settings, recorder)
        }
        None => match c.pin_stop {
            _ if c.pin_stop_after_touch.is_some() => {
                let t = c.pin_stop_after_touch.unwrap_or(0.0) * poly.radius();
                let path = crate::mechanics::stop_after_touch(
                    model,
                    pose,
                    start,
                    pin.radius,
                    c.pin_speed,
                    t,
                )
                .expect("checked by check_inputs");
                push_path(model, pose, start, pin.radius, &path, &settings, recorder)
            }
            Some(s_stop) => {
                let turn = Turn {
                    s: s_stop * poly.radius(),
                    w: 0.0,
                };
                let path = PinPath::new(c.pin_speed, vec![turn]).expect("checked by check_inputs");
                push_path(model, pose, start, pin.radius, &path, &settings, recorder)
            }
            None => push(model, pose, start, &pin, &settings, recorder),
        },
    };
    (out, trace)
}
