//! Validation of a study file: [`RawStudy`] → distributions per sweep point, with errors located by
//! the scenario parser's machinery (file:line:column, key, what is allowed).
//!
//! Sweeps: each `[[sweep]]` names a parameter and its values (`values = [...]`, or `from`, `to`,
//! `steps` evenly spaced, ends included). `NAME` fixes the parameter at each value; `NAME.FIELD`
//! overrides one field of its declared distribution (`shape.sd`, `mu_c.max`, `support.width`).
//! One or two sweeps make a grid; the first sweep varies slowest (point = i₀·n₁ + i₁).

use super::distribution::Distribution;
use super::perturbations::Perturbations;
use super::raw::*;
use crate::mechanics::support::{SmoothParams, SupportChoice};
use crate::scenario::error::Locator;
use crate::scenario::limits::num;
use crate::scenario::location::KeyPath;
use crate::scenario::{ScenarioError, SupportKind};

type R<T> = Result<T, ScenarioError>;

/// Largest number of sweep points.
pub const MAX_POINTS: usize = 10_000;

/// Names of the distribution parameters, in the order they are drawn (the sensor parameters
/// after the others, then the fence and actuator parameters: each group's streams come after
/// every earlier one, so studies without them draw as before).
pub const DISTRIBUTION_PARAMETERS: [&str; 21] = [
    "mu_c",
    "belt_speed",
    "shape",
    "pin_x",
    "pin_y",
    "pin_radius",
    "pose_theta",
    "pose_y",
    "sensor_noise",
    "sensor_bias",
    "sensor_threshold",
    "sensor_jitter",
    "fence_mu_f",
    "fence_angle",
    "fence_x",
    "fence_y",
    "fence_length",
    "actuator_speed",
    "actuator_accel",
    "actuator_settle",
    "controller_latency",
];

/// The parameters that act on pins (every kind: fixed, sensor, moving, retractable).
pub const PIN_PARAMETERS: [&str; 4] = ["mu_c", "pin_x", "pin_y", "pin_radius"];

/// The parameters that act on fences; each takes an optional `fences = [NAME, ...]`.
pub const FENCE_PARAMETERS: [&str; 5] = [
    "fence_mu_f",
    "fence_angle",
    "fence_x",
    "fence_y",
    "fence_length",
];

/// The parameters that act on dynamic pins' actuators; each takes an optional
/// `pins = [NAME, ...]`.
pub const ACTUATOR_PARAMETERS: [&str; 3] = ["actuator_speed", "actuator_accel", "actuator_settle"];

/// The parameters that act on sensor pins' settings: a study may give them only for a scenario
/// with at least one sensor pin.
pub const SENSOR_PARAMETERS: [&str; 4] = [
    "sensor_noise",
    "sensor_bias",
    "sensor_threshold",
    "sensor_jitter",
];

/// A swept parameter and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepAxis {
    /// `NAME` (the parameter fixed at each value) or `NAME.FIELD` (one field of its distribution,
    /// e.g. `shape.sd`).
    pub parameter: String,
    /// The values the parameter takes, in order (1 to 1000 of them, each finite), in the
    /// parameter's own unit.
    pub values: Vec<f64>,
}

fn err(loc: &Locator, path: &str, msg: impl Into<String>) -> ScenarioError {
    loc.at_key(&KeyPath::parse(path), msg)
}

fn finite(loc: &Locator, path: &str, v: f64) -> R<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(err(loc, path, format!("must be a finite number, got {v}")))
    }
}

fn slot<'a>(u: &'a RawUncertain, name: &str) -> &'a Option<RawDistribution> {
    match name {
        "mu_c" => &u.mu_c,
        "belt_speed" => &u.belt_speed,
        "shape" => &u.shape,
        "pin_x" => &u.pin_x,
        "pin_y" => &u.pin_y,
        "pin_radius" => &u.pin_radius,
        "pose_theta" => &u.pose_theta,
        "sensor_noise" => &u.sensor_noise,
        "sensor_bias" => &u.sensor_bias,
        "sensor_threshold" => &u.sensor_threshold,
        "sensor_jitter" => &u.sensor_jitter,
        "fence_mu_f" => &u.fence_mu_f,
        "fence_angle" => &u.fence_angle,
        "fence_x" => &u.fence_x,
        "fence_y" => &u.fence_y,
        "fence_length" => &u.fence_length,
        "actuator_speed" => &u.actuator_speed,
        "actuator_accel" => &u.actuator_accel,
        "actuator_settle" => &u.actuator_settle,
        "controller_latency" => &u.controller_latency,
        _ => &u.pose_y,
    }
}

fn slot_mut<'a>(u: &'a mut RawUncertain, name: &str) -> &'a mut Option<RawDistribution> {
    match name {
        "mu_c" => &mut u.mu_c,
        "belt_speed" => &mut u.belt_speed,
        "shape" => &mut u.shape,
        "pin_x" => &mut u.pin_x,
        "pin_y" => &mut u.pin_y,
        "pin_radius" => &mut u.pin_radius,
        "pose_theta" => &mut u.pose_theta,
        "sensor_noise" => &mut u.sensor_noise,
        "sensor_bias" => &mut u.sensor_bias,
        "sensor_threshold" => &mut u.sensor_threshold,
        "sensor_jitter" => &mut u.sensor_jitter,
        "fence_mu_f" => &mut u.fence_mu_f,
        "fence_angle" => &mut u.fence_angle,
        "fence_x" => &mut u.fence_x,
        "fence_y" => &mut u.fence_y,
        "fence_length" => &mut u.fence_length,
        "actuator_speed" => &mut u.actuator_speed,
        "actuator_accel" => &mut u.actuator_accel,
        "actuator_settle" => &mut u.actuator_settle,
        "controller_latency" => &mut u.controller_latency,
        _ => &mut u.pose_y,
    }
}

/// Smallest share of a normal's draws its truncation `[min, max]` may keep: a draw outside is
/// redrawn, at most [`super::distribution::MAX_REDRAWS`] times, so with 5% a sample fails to draw
/// with probability 0.95¹⁰⁰¹ ≈ 5·10⁻²³ (docs/study-format.md).
pub const MIN_TRUNCATION_MASS: f64 = 0.05;

/// Largest error (m) a study may add to a length (shape, pin position and radius, lateral pose):
/// the longest belt (docs/study-format.md).
pub const LENGTH_ERROR: (f64, f64) = (-1e3, 1e3);
/// Largest error (degrees) a study may add to the entry orientation.
pub const ANGLE_ERROR: (f64, f64) = (-360.0, 360.0);
/// Range of the sensor noise factor (0: an ideal sensor's white noise and jitter).
pub const SENSOR_NOISE_FACTOR: (f64, f64) = (0.0, 1e6);
/// Range of the error added to a sensor's force bias (N): the range of the bias itself
/// ([`crate::sensing::SensorSettings::validate`]).
pub const SENSOR_BIAS: (f64, f64) = (-1e6, 1e6);
/// Range of a timing threshold (N, > 0): the sensor's own range
/// ([`crate::sensing::SensorSettings::validate`]).
pub const SENSOR_THRESHOLD: (f64, f64) = (1e-9, 1e6);
/// Range of the error added to a sensor's timing jitter (s): ± the largest jitter a sensor takes.
pub const SENSOR_JITTER: (f64, f64) = (-10.0, 10.0);
/// Largest error (degrees) a study may add to a fence's angle (a drawn angle must still lie
/// strictly between −90° and 90°).
pub const FENCE_ANGLE_ERROR: (f64, f64) = (-180.0, 180.0);
/// Range of the factors on an actuator's speed and acceleration.
pub const ACTUATOR_FACTOR: (f64, f64) = (1e-6, 1e6);
/// Largest error (s) a study may add to a settle time or the controller's latency: ± the longest
/// actuator time ([`crate::scenario::limits::ACTUATOR_TIME`]).
pub const TIME_ERROR: (f64, f64) = (-1e4, 1e4);

/// The physical range of parameter `name` and its unit (crate::scenario::limits): every value a
/// study gives (value, min, max, mean, mode) must lie in it, a standard deviation must not exceed
/// its width, and a drawn friction or belt speed outside it is redrawn.
pub fn domain(name: &str) -> ((f64, f64), &'static str) {
    use crate::scenario::limits;
    match name {
        "mu_c" => (limits::FRICTION, "a friction coefficient"),
        "belt_speed" => (limits::BELT_SPEED, "m/s"),
        "pose_theta" => (
            ANGLE_ERROR,
            "degrees, an error added to the entry orientation",
        ),
        "sensor_noise" => (
            SENSOR_NOISE_FACTOR,
            "a factor multiplying every sensor's white noise and timing jitter",
        ),
        "sensor_bias" => (SENSOR_BIAS, "N, added to every sensor's force bias"),
        "sensor_threshold" => (SENSOR_THRESHOLD, "N, every sensor's timing threshold, > 0"),
        "sensor_jitter" => (SENSOR_JITTER, "s, added to every sensor's timing jitter"),
        "fence_mu_f" => (limits::FRICTION, "a fence-part friction coefficient"),
        "fence_angle" => (
            FENCE_ANGLE_ERROR,
            "degrees, an error added to a fence's angle",
        ),
        "actuator_speed" => (
            ACTUATOR_FACTOR,
            "a factor multiplying a dynamic pin's speed",
        ),
        "actuator_accel" => (
            ACTUATOR_FACTOR,
            "a factor multiplying a moving pin's acceleration",
        ),
        "actuator_settle" => (
            TIME_ERROR,
            "s, an error added to a moving pin's settle time",
        ),
        "controller_latency" => (TIME_ERROR, "s, an error added to the controller's latency"),
        _ => (LENGTH_ERROR, "m, an error added to a length or position"),
    }
}

/// Does `v` lie in the domain of parameter `name`?
pub fn in_domain(name: &str, v: f64) -> bool {
    crate::scenario::limits::contains(domain(name).0, v)
}

fn compile_distribution(loc: &Locator, name: &str, d: &RawDistribution) -> R<Distribution> {
    let base = format!("uncertain.{name}");
    let Some(kind) = d.distribution else {
        return Err(err(
            loc,
            &base,
            "give distribution = \"fixed\" (value), \"uniform\" (min, max), \"normal\" (mean, sd) or \"triangular\" (min, mode, max)",
        ));
    };
    let vals = distribution_fields(loc, name, kind, d)?;
    check_fields_in_domain(loc, name, &vals)?;
    build_distribution(loc, name, kind, d, &vals)
}

/// The values a distribution table gives, each finite, by field name: an error for a field the
/// kind does not take (the first in the order value, min, max, mean, sd, mode) or one it needs.
fn distribution_fields(
    loc: &Locator,
    name: &str,
    kind: DistributionKind,
    d: &RawDistribution,
) -> R<std::collections::BTreeMap<&'static str, f64>> {
    let base = format!("uncertain.{name}");
    let key = |k: &str| format!("{base}.{k}");
    let given = [
        ("value", d.value),
        ("min", d.min),
        ("max", d.max),
        ("mean", d.mean),
        ("sd", d.sd),
        ("mode", d.mode),
    ];
    let (needed, optional): (&[&str], &[&str]) = match kind {
        DistributionKind::Fixed => (&["value"], &[]),
        DistributionKind::Uniform => (&["min", "max"], &[]),
        DistributionKind::Normal => (&["sd"], &["mean", "min", "max"]),
        DistributionKind::Triangular => (&["min", "mode", "max"], &[]),
    };
    for (k, v) in given {
        if v.is_some() && !needed.contains(&k) && !optional.contains(&k) {
            let mut takes = needed.join(", ");
            if !optional.is_empty() {
                takes.push_str(&format!(" (optional: {})", optional.join(", ")));
            }
            return Err(err(
                loc,
                &key(k),
                format!("does not apply to this distribution, which takes {takes}"),
            ));
        }
    }
    let mut vals = std::collections::BTreeMap::new();
    for (k, v) in given {
        if let Some(v) = v {
            vals.insert(k, finite(loc, &key(k), v)?);
        }
    }
    for k in needed {
        if !vals.contains_key(k) {
            return Err(err(
                loc,
                &base,
                format!(
                    "this distribution needs {}; `{k}` is missing",
                    needed.join(", ")
                ),
            ));
        }
    }
    Ok(vals)
}

/// Check a field's value `v` against the parameter's domain (see [`domain`]).
fn check_in_domain(loc: &Locator, name: &str, k: &str, v: f64) -> R<()> {
    let ((lo_dom, hi_dom), dom_text) = domain(name);
    if !in_domain(name, v) {
        return Err(err(
            loc,
            &format!("uncertain.{name}.{k}"),
            format!(
                "{name} must be at least {} and at most {} ({dom_text}), got {}",
                num(lo_dom),
                num(hi_dom),
                num(v)
            ),
        ));
    }
    Ok(())
}

/// Check every field in key order: sd within the domain's width, the others within the domain.
fn check_fields_in_domain(
    loc: &Locator,
    name: &str,
    vals: &std::collections::BTreeMap<&'static str, f64>,
) -> R<()> {
    let key = |k: &str| format!("uncertain.{name}.{k}");
    let ((lo_dom, hi_dom), dom_text) = domain(name);
    for (k, v) in vals {
        if *k == "sd" {
            let widest = hi_dom - lo_dom;
            if !(0.0..=widest).contains(v) {
                return Err(err(
                    loc,
                    &key(k),
                    format!(
                        "must lie in [0, {}] (the width of {name}'s range [{}, {}], {dom_text}), got {}",
                        num(widest),
                        num(lo_dom),
                        num(hi_dom),
                        num(*v)
                    ),
                ));
            }
        } else {
            check_in_domain(loc, name, k, *v)?;
        }
    }
    Ok(())
}

/// The distribution of a checked table: its own constraints (min ≤ max, min ≤ mode ≤ max,
/// sd ≥ 0, the mean within the truncation) and its location within the domain.
fn build_distribution(
    loc: &Locator,
    name: &str,
    kind: DistributionKind,
    d: &RawDistribution,
    vals: &std::collections::BTreeMap<&'static str, f64>,
) -> R<Distribution> {
    let key = |k: &str| format!("uncertain.{name}.{k}");
    let g = |k: &str| vals.get(k).copied();
    let dist = match kind {
        DistributionKind::Fixed => {
            let v = g("value").expect("checked");
            check_in_domain(loc, name, "value", v)?;
            Distribution::Fixed(v)
        }
        DistributionKind::Uniform => {
            let (min, max) = (g("min").expect("checked"), g("max").expect("checked"));
            if min > max {
                return Err(err(
                    loc,
                    &key("max"),
                    format!("must be at least min ({min}), got {max}"),
                ));
            }
            check_in_domain(loc, name, "min", min)?;
            Distribution::Uniform { min, max }
        }
        DistributionKind::Triangular => {
            let (min, mode, max) = (
                g("min").expect("checked"),
                g("mode").expect("checked"),
                g("max").expect("checked"),
            );
            if !(min <= mode && mode <= max) {
                return Err(err(
                    loc,
                    &key("mode"),
                    format!("needs min ≤ mode ≤ max, got {min}, {mode}, {max}"),
                ));
            }
            check_in_domain(loc, name, "min", min)?;
            Distribution::Triangular { min, mode, max }
        }
        DistributionKind::Normal => {
            let sd = g("sd").expect("checked");
            if sd < 0.0 {
                return Err(err(
                    loc,
                    &key("sd"),
                    format!("must be at least 0, got {sd}"),
                ));
            }
            let mean = g("mean").unwrap_or(0.0);
            let lo = g("min").unwrap_or(f64::NEG_INFINITY);
            let hi = g("max").unwrap_or(f64::INFINITY);
            if lo > hi {
                return Err(err(
                    loc,
                    &key("max"),
                    format!("must be at least min ({lo}), got {hi}"),
                ));
            }
            if !(lo..=hi).contains(&mean) {
                return Err(err(
                    loc,
                    &key("mean"),
                    format!("must lie within the truncation [{lo}, {hi}], got {mean}"),
                ));
            }
            let where_ = if d.mean.is_some() { "mean" } else { "sd" };
            check_in_domain(loc, name, where_, mean)?;
            let dist = Distribution::Normal { mean, sd, lo, hi };
            let kept = dist.truncation_mass();
            if kept < MIN_TRUNCATION_MASS {
                let hint = if lo == hi {
                    format!(
                        "a normal truncated to the single value {} never draws it: give distribution = \"fixed\", value = {}",
                        num(lo),
                        num(lo)
                    )
                } else {
                    "widen [min, max] or lower sd, or use a uniform distribution on [min, max]"
                        .to_string()
                };
                return Err(err(
                    loc,
                    &key(if lo == hi { "max" } else { "min" }),
                    format!(
                        "the truncation [{}, {}] keeps {:.2}% of normal (mean {}, sd {}) draws; a value is redrawn at most {} times, so at least {}% must land in [min, max]: {hint}",
                        num(lo),
                        num(hi),
                        100.0 * kept,
                        num(mean),
                        num(sd),
                        super::distribution::MAX_REDRAWS,
                        100.0 * MIN_TRUNCATION_MASS
                    ),
                ));
            }
            dist
        }
    };
    Ok(dist)
}

fn compile_support(loc: &Locator, s: &RawSupport) -> R<SupportChoice> {
    let Some(model) = s.model else {
        return Err(err(
            loc,
            "uncertain.support",
            "give model = \"uniform\", \"tripod\" or \"smooth\"",
        ));
    };
    let smooth_keys = [
        ("bumps", s.bumps),
        ("width", s.width),
        ("contrast", s.contrast),
        ("points", s.points),
    ];
    if model != SupportModel::Smooth {
        if let Some((k, _)) = smooth_keys.iter().find(|(_, v)| v.is_some()) {
            return Err(err(
                loc,
                &format!("uncertain.support.{k}"),
                "applies only to model = \"smooth\"",
            ));
        }
    }
    Ok(match model {
        SupportModel::Uniform => SupportChoice::Uniform,
        SupportModel::Tripod => SupportChoice::Tripod,
        SupportModel::Smooth => {
            let d = SmoothParams::default();
            let whole = |k: &str, v: Option<f64>, lo: f64, hi: f64, dflt: usize| -> R<usize> {
                let Some(v) = v else { return Ok(dflt) };
                let path = format!("uncertain.support.{k}");
                if !(v.is_finite() && v.fract() == 0.0 && (lo..=hi).contains(&v)) {
                    return Err(err(
                        loc,
                        &path,
                        format!("must be a whole number in [{lo}, {hi}], got {v}"),
                    ));
                }
                Ok(v as usize)
            };
            let real = |k: &str, v: Option<f64>, lo: f64, hi: f64, dflt: f64| -> R<f64> {
                let Some(v) = v else { return Ok(dflt) };
                let path = format!("uncertain.support.{k}");
                let v = finite(loc, &path, v)?;
                if !(lo..=hi).contains(&v) || (k == "width" && v == 0.0) {
                    return Err(err(
                        loc,
                        &path,
                        format!(
                            "must lie in {}{lo}, {hi}], got {v}",
                            if k == "width" { "(" } else { "[" }
                        ),
                    ));
                }
                Ok(v)
            };
            SupportChoice::Smooth(SmoothParams {
                bumps: whole("bumps", s.bumps, 0.0, 50.0, d.bumps)?,
                width: real("width", s.width, 0.0, 10.0, d.width)?,
                contrast: real("contrast", s.contrast, 0.0, 100.0, d.contrast)?,
                points: whole("points", s.points, 8.0, 2000.0, d.points)?,
            })
        }
    })
}

/// Compile the `[uncertain]` table. `scenario_support` is the scenario's own support, used when
/// the study does not declare one.
pub fn compile_uncertain(
    loc: &Locator,
    u: &RawUncertain,
    scenario_support: SupportKind,
) -> R<Perturbations> {
    let mut d: Vec<Option<Distribution>> = Vec::new();
    let mut only = std::collections::BTreeMap::new();
    for name in DISTRIBUTION_PARAMETERS {
        d.push(match slot(u, name) {
            Some(raw) => {
                if let Some(names) = selection(loc, name, raw)? {
                    only.insert(name.to_string(), names);
                }
                Some(compile_distribution(loc, name, raw)?)
            }
            None => None,
        });
    }
    let support = match &u.support {
        Some(s) => compile_support(loc, s)?,
        None => match scenario_support {
            SupportKind::Uniform => SupportChoice::Uniform,
            SupportKind::Tripod => SupportChoice::Tripod,
        },
    };
    Ok(Perturbations {
        mu_c: d[0],
        belt_speed: d[1],
        shape: d[2],
        pin_x: d[3],
        pin_y: d[4],
        pin_radius: d[5],
        pose_theta: d[6],
        pose_y: d[7],
        sensor_noise: d[8],
        sensor_bias: d[9],
        sensor_threshold: d[10],
        sensor_jitter: d[11],
        fence_mu_f: d[12],
        fence_angle: d[13],
        fence_x: d[14],
        fence_y: d[15],
        fence_length: d[16],
        actuator_speed: d[17],
        actuator_accel: d[18],
        actuator_settle: d[19],
        controller_latency: d[20],
        only,
        support,
    })
}

/// The `fences = [...]` or `pins = [...]` of parameter `name`'s table, if given: only on the
/// parameters it applies to, non-empty, without repeats. (Whether the names exist in the scenario
/// is checked by [`check_reach`].)
fn selection(loc: &Locator, name: &str, d: &RawDistribution) -> R<Option<Vec<String>>> {
    let base = format!("uncertain.{name}");
    let (key, given, applies, what) = match (&d.fences, &d.pins) {
        (Some(f), _) => ("fences", f, FENCE_PARAMETERS.contains(&name), "fence"),
        (None, Some(p)) => ("pins", p, ACTUATOR_PARAMETERS.contains(&name), "actuator"),
        (None, None) => return Ok(None),
    };
    if !applies {
        return Err(err(
            loc,
            &format!("{base}.{key}"),
            format!(
                "applies only to the {what} parameters ({}); {name} reaches {}",
                if what == "fence" {
                    FENCE_PARAMETERS.join(", ")
                } else {
                    ACTUATOR_PARAMETERS.join(", ")
                },
                reach_text(name)
            ),
        ));
    }
    if given.is_empty() {
        return Err(err(
            loc,
            &format!("{base}.{key}"),
            format!("names no {what}; name at least one, or leave `{key}` out to reach every one"),
        ));
    }
    for (i, n) in given.iter().enumerate() {
        if given[..i].contains(n) {
            return Err(err(
                loc,
                &format!("{base}.{key}[{i}]"),
                format!("`{n}` is named twice"),
            ));
        }
    }
    Ok(Some(given.clone()))
}

/// What parameter `name` reaches, in words (docs/study-format.md, the table of what reaches what).
pub fn reach_text(name: &str) -> &'static str {
    match name {
        "mu_c" => "every pin's friction (not the fences': their μf is fence_mu_f)",
        "pin_x" | "pin_y" | "pin_radius" => "every pin (of any kind)",
        "fence_mu_f" | "fence_angle" | "fence_x" | "fence_y" | "fence_length" => "fences",
        "actuator_speed" => "moving and retractable pins",
        "actuator_accel" | "actuator_settle" => "moving pins",
        "controller_latency" => "the controller",
        n if n.starts_with("sensor_") => "sensor pins",
        _ => "the part, the belt or the feed",
    }
}

/// A sweep that names no field of the declared uncertainty ([`apply_sweep`]); the study's
/// error locates it at the sweep's `parameter`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
enum SweepError {
    /// A field of the support swept without an `[uncertain.support]` table.
    #[error("[uncertain.support] is not declared; declare model = \"smooth\" to sweep its fields")]
    NoSupport,
    /// A field the support does not have (holds the parameter as given).
    #[error("`{0}`: the support can be swept only through support.bumps, support.width, support.contrast or support.points")]
    SupportField(String),
    /// A parameter that is no distribution parameter (holds its name before any `.`).
    #[error("unknown parameter `{0}`; expected one of {known}, support", known = DISTRIBUTION_PARAMETERS.join(", "))]
    UnknownParameter(String),
    /// A field of a distribution the study does not declare (holds the parameter's name).
    #[error("[uncertain.{0}] is not declared; declare its distribution, or sweep `{0}` itself to fix it at each value")]
    Undeclared(String),
    /// A field no distribution has (holds the field).
    #[error("`{0}` is not a distribution field; expected value, min, max, mean, sd or mode")]
    Field(String),
}

/// Set the field a sweep names to `value` (see the module docs).
fn apply_sweep(u: &mut RawUncertain, parameter: &str, value: f64) -> Result<(), SweepError> {
    let (name, field) = match parameter.split_once('.') {
        Some((n, f)) => (n, Some(f)),
        None => (parameter, None),
    };
    if name == "support" {
        let Some(s) = u.support.as_mut() else {
            return Err(SweepError::NoSupport);
        };
        let target = match field {
            Some("bumps") => &mut s.bumps,
            Some("width") => &mut s.width,
            Some("contrast") => &mut s.contrast,
            Some("points") => &mut s.points,
            _ => return Err(SweepError::SupportField(parameter.to_string())),
        };
        *target = Some(value);
        return Ok(());
    }
    if !DISTRIBUTION_PARAMETERS.contains(&name) {
        return Err(SweepError::UnknownParameter(name.to_string()));
    }
    let d = slot_mut(u, name);
    match field {
        None => {
            // The parameter fixed at the value, still restricted to the obstacles it named.
            let named = d.take().unwrap_or_default();
            *d = Some(RawDistribution {
                distribution: Some(DistributionKind::Fixed),
                value: Some(value),
                fences: named.fences,
                pins: named.pins,
                ..RawDistribution::default()
            });
        }
        Some(f) => {
            let Some(raw) = d.as_mut() else {
                return Err(SweepError::Undeclared(name.to_string()));
            };
            let target = match f {
                "value" => &mut raw.value,
                "min" => &mut raw.min,
                "max" => &mut raw.max,
                "mean" => &mut raw.mean,
                "sd" => &mut raw.sd,
                "mode" => &mut raw.mode,
                other => return Err(SweepError::Field(other.to_string())),
            };
            *target = Some(value);
        }
    }
    Ok(())
}

/// Compile the sweeps into axes.
pub fn compile_sweeps(loc: &Locator, sweeps: &[RawSweep]) -> R<Vec<SweepAxis>> {
    if sweeps.len() > 2 {
        return Err(err(
            loc,
            "sweep[2]",
            format!(
                "at most two sweeps (a grid) are supported, got {}",
                sweeps.len()
            ),
        ));
    }
    let mut axes: Vec<SweepAxis> = Vec::new();
    for (k, s) in sweeps.iter().enumerate() {
        let base = format!("sweep[{k}]");
        if axes.iter().any(|a| a.parameter == s.parameter) {
            return Err(err(
                loc,
                &format!("{base}.parameter"),
                format!("`{}` is already swept", s.parameter),
            ));
        }
        let values = match (&s.values, s.from, s.to, s.steps) {
            (Some(v), None, None, None) => {
                if v.is_empty() || v.len() > 1000 {
                    return Err(err(
                        loc,
                        &format!("{base}.values"),
                        format!("needs 1 to 1000 values, got {}", v.len()),
                    ));
                }
                for (i, &x) in v.iter().enumerate() {
                    finite(loc, &format!("{base}.values[{i}]"), x)?;
                }
                v.clone()
            }
            (None, Some(from), Some(to), Some(steps)) => {
                let from = finite(loc, &format!("{base}.from"), from)?;
                let to = finite(loc, &format!("{base}.to"), to)?;
                if !(2..=1000).contains(&steps) {
                    return Err(err(
                        loc,
                        &format!("{base}.steps"),
                        format!("must lie in [2, 1000], got {steps}"),
                    ));
                }
                (0..steps)
                    .map(|i| from + (to - from) * i as f64 / (steps - 1) as f64)
                    .collect()
            }
            _ => return Err(err(
                loc,
                &base,
                "give either values = [...] or from, to and steps (evenly spaced, ends included)",
            )),
        };
        axes.push(SweepAxis {
            parameter: s.parameter.clone(),
            values,
        });
    }
    let points: usize = axes.iter().map(|a| a.values.len()).product();
    if points > MAX_POINTS {
        return Err(err(
            loc,
            "sweep",
            format!("the grid has {points} points; at most {MAX_POINTS} are allowed"),
        ));
    }
    Ok(axes)
}

/// The parameter values of every grid point (first axis slowest); one empty point without sweeps.
pub fn grid(axes: &[SweepAxis]) -> Vec<Vec<f64>> {
    let mut points = vec![Vec::new()];
    for a in axes {
        points = points
            .into_iter()
            .flat_map(|p| {
                a.values.iter().map(move |&v| {
                    let mut q = p.clone();
                    q.push(v);
                    q
                })
            })
            .collect();
    }
    points
}

/// The perturbations at every grid point. A sweep value that makes the study invalid is reported
/// at the sweep, with the underlying problem.
pub fn compile_points(
    loc: &Locator,
    u: &RawUncertain,
    axes: &[SweepAxis],
    scenario_support: SupportKind,
) -> R<Vec<Perturbations>> {
    let mut out = Vec::new();
    for values in grid(axes) {
        let mut raw = u.clone();
        for (k, (axis, &v)) in axes.iter().zip(&values).enumerate() {
            apply_sweep(&mut raw, &axis.parameter, v)
                .map_err(|e| err(loc, &format!("sweep[{k}].parameter"), e.to_string()))?;
        }
        let p = compile_uncertain(loc, &raw, scenario_support).map_err(|e| {
            let inner = e
                .invalid()
                .map(|i| format!("{}: {}", i.key, i.message))
                .unwrap_or_else(|| e.to_string());
            let at = axes
                .iter()
                .zip(&values)
                .map(|(a, v)| format!("{} = {v}", a.parameter))
                .collect::<Vec<_>>()
                .join(", ");
            // Locate at the sweep whose parameter the problem is about (else the last one).
            let culprit = e.invalid().map(|i| i.key.clone()).unwrap_or_default();
            let k = axes
                .iter()
                .position(|a| {
                    let name = a.parameter.split('.').next().unwrap_or("");
                    culprit.starts_with(&format!("uncertain.{name}"))
                })
                .unwrap_or(axes.len().saturating_sub(1));
            err(loc, &format!("sweep[{k}]"), format!("at {at}: {inner}"))
        })?;
        out.push(p);
    }
    Ok(out)
}

/// Where a study gives parameter `name`: the first sweep of it (a sweep of `name` or of one of
/// its fields) when `swept`, else its `[uncertain.NAME]` table, else a sweep of it.
fn parameter_key(u: &RawUncertain, sweeps: &[RawSweep], name: &str, swept: bool) -> Option<String> {
    let sweep = sweeps
        .iter()
        .position(|s| s.parameter.split('.').next() == Some(name))
        .map(|k| format!("sweep[{k}].parameter"));
    let table = match name {
        "support" => u.support.is_some(),
        _ => DISTRIBUTION_PARAMETERS.contains(&name) && slot(u, name).is_some(),
    }
    .then(|| format!("uncertain.{name}"));
    if swept {
        sweep.or(table)
    } else {
        table.or(sweep)
    }
}

/// The first sample of every sweep point must draw: a value inside its documented range can
/// still leave every draw invalid on this scenario (an actuator factor that takes a pin's speed
/// below the slowest allowed, a noise factor that takes a sensor's jitter past 10 s), which would
/// otherwise stop the run at sample 0. The first sample is the one the run draws first (a pure
/// function of the seed), so a study this accepts does not fail there; the error is located at
/// the parameter the failure names (at its sweep, when swept), with the sweep point's values.
pub fn check_first_samples(
    loc: &Locator,
    u: &RawUncertain,
    sweeps: &[RawSweep],
    axes: &[SweepAxis],
    points: &[Perturbations],
    scene: &crate::scenario::Scene,
    seed: u64,
) -> R<()> {
    use rayon::prelude::*;
    let failed = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            super::sample::draw_scene(scene, p, seed, 0)
                .err()
                .map(|e| (i, e))
        })
        .find_first(Option::is_some);
    let Some(Some((point, e))) = failed else {
        return Ok(());
    };
    let values = grid(axes).swap_remove(point);
    let key = e
        .parameters()
        .iter()
        .find_map(|name| parameter_key(u, sweeps, name, !axes.is_empty()))
        .unwrap_or_else(|| "uncertain".to_string());
    let at = if axes.is_empty() {
        String::new()
    } else {
        format!(
            " at {}",
            axes.iter()
                .zip(&values)
                .map(|(a, v)| format!("{} = {}", a.parameter, num(*v)))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    Err(err(
        loc,
        &key,
        format!("no valid sample can be drawn{at} on this scenario: {e}"),
    ))
}

/// Sensor parameters need a sensor pin: with none in the scenario, the first sensor parameter the
/// study gives (an `[uncertain.sensor_*]` table, else a sweep of one) is a located error.
pub fn check_sensor_parameters(
    loc: &Locator,
    u: &RawUncertain,
    sweeps: &[RawSweep],
    scenario_has_sensor: bool,
) -> R<()> {
    if scenario_has_sensor {
        return Ok(());
    }
    let msg = |name: &str| {
        format!(
            "{name} perturbs sensor pins, but the scenario has no sensor pin (kind = \"sensor_pin\"); remove it or point the study at a scenario with one"
        )
    };
    if let Some(name) = SENSOR_PARAMETERS.iter().find(|n| slot(u, n).is_some()) {
        return Err(err(loc, &format!("uncertain.{name}"), msg(name)));
    }
    for (k, s) in sweeps.iter().enumerate() {
        let name = s.parameter.split('.').next().unwrap_or("");
        if SENSOR_PARAMETERS.contains(&name) {
            return Err(err(loc, &format!("sweep[{k}].parameter"), msg(name)));
        }
    }
    Ok(())
}

/// Every fence, pin and actuator parameter the study gives (an `[uncertain.NAME]` table or a
/// sweep of NAME) must reach something in the scenario, and every name in its `fences = [...]` or
/// `pins = [...]` must be an obstacle it applies to; otherwise a located error says why (at the
/// table, the sweep or the name). Sensor parameters are checked by [`check_sensor_parameters`];
/// the other parameters act on the part, the belt or the feed, which every scenario has.
pub fn check_reach(
    loc: &Locator,
    u: &RawUncertain,
    sweeps: &[RawSweep],
    scene: &crate::scenario::Scene,
) -> R<()> {
    use crate::scenario::{Actuator, Obstacle};
    let names = |keep: &dyn Fn(&Obstacle) -> bool| -> Vec<&str> {
        scene
            .obstacles
            .iter()
            .filter(|o| keep(o))
            .map(|o| o.name())
            .collect()
    };
    let pins = names(&|o| matches!(o, Obstacle::Pin(_)));
    let fences = names(&|o| matches!(o, Obstacle::Fence(_)));
    let dynamic = names(&|o| matches!(o, Obstacle::Pin(p) if p.actuator.is_some()));
    let moving = names(
        &|o| matches!(o, Obstacle::Pin(p) if matches!(p.actuator, Some(Actuator::Moving(_)))),
    );
    let controller: Vec<&str> = scene.controller.iter().map(|_| "controller").collect();
    for name in DISTRIBUTION_PARAMETERS {
        let (reached, kind, hint) = match name {
            "mu_c" => (
                &pins,
                "pins",
                if fences.is_empty() {
                    ""
                } else {
                    "; the scenario's fences keep their own μf: perturb it with [uncertain.fence_mu_f]"
                },
            ),
            "pin_x" | "pin_y" | "pin_radius" => (
                &pins,
                "pins",
                if fences.is_empty() {
                    ""
                } else {
                    "; the fences' geometry is fence_x, fence_y, fence_angle and fence_length"
                },
            ),
            "fence_mu_f" | "fence_angle" | "fence_x" | "fence_y" | "fence_length" => (
                &fences,
                "fences (kind = \"fence\")",
                if name == "fence_mu_f" && !pins.is_empty() {
                    "; the pins' friction is mu_c"
                } else {
                    ""
                },
            ),
            "actuator_speed" => (
                &dynamic,
                "moving or retractable pins (kind = \"moving_pin\", \"retractable_pin\")",
                "",
            ),
            "actuator_accel" | "actuator_settle" => {
                (&moving, "moving pins (kind = \"moving_pin\")", "")
            }
            "controller_latency" => (&controller, "a [controller]", ""),
            _ => continue,
        };
        let at = if slot(u, name).is_some() {
            format!("uncertain.{name}")
        } else if let Some(k) = sweeps
            .iter()
            .position(|s| s.parameter.split('.').next() == Some(name))
        {
            format!("sweep[{k}].parameter")
        } else {
            continue;
        };
        if reached.is_empty() {
            return Err(err(
                loc,
                &at,
                format!(
                    "{name} perturbs {kind}, but the scenario has none, so it would change nothing{hint}; remove it or point the study at a scenario with one"
                ),
            ));
        }
        let Some(raw) = slot(u, name) else { continue };
        let (key, given) = match (&raw.fences, &raw.pins) {
            (Some(f), _) => ("fences", f),
            (None, Some(p)) => ("pins", p),
            (None, None) => continue,
        };
        for (i, n) in given.iter().enumerate() {
            if reached.contains(&n.as_str()) {
                continue;
            }
            let what = match scene.obstacles.iter().find(|o| o.name() == n) {
                Some(Obstacle::Fence(_)) => "is a fence".to_string(),
                Some(Obstacle::Pin(p)) => match p.actuator {
                    Some(Actuator::Moving(_)) => "is a moving pin".to_string(),
                    Some(Actuator::Retractable(_)) => "is a retractable pin".to_string(),
                    None => "is a fixed pin".to_string(),
                },
                None => "names no obstacle of the scenario".to_string(),
            };
            return Err(err(
                loc,
                &format!("uncertain.{name}.{key}[{i}]"),
                format!(
                    "`{n}` {what}; {name} reaches {kind}: {}",
                    reached
                        .iter()
                        .map(|r| format!("`{r}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sweep that names no declared field is refused with the message the study file's error
    /// shows at the sweep.
    #[test]
    fn sweeps_of_undeclared_or_unknown_fields_are_refused() {
        let mut u = RawUncertain::default();
        let e = apply_sweep(&mut u, "shape.sd", 0.1).unwrap_err();
        assert_eq!(e, SweepError::Undeclared("shape".into()));
        assert_eq!(
            e.to_string(),
            "[uncertain.shape] is not declared; declare its distribution, or sweep `shape` itself to fix it at each value"
        );
        assert_eq!(
            apply_sweep(&mut u, "support.width", 0.1),
            Err(SweepError::NoSupport)
        );
        let e = apply_sweep(&mut u, "mu_cc", 0.1).unwrap_err();
        assert_eq!(e, SweepError::UnknownParameter("mu_cc".into()));
        assert!(e
            .to_string()
            .starts_with("unknown parameter `mu_cc`; expected one of mu_c, belt_speed, "));
        assert!(e.to_string().ends_with(", controller_latency, support"));
        apply_sweep(&mut u, "mu_c", 0.5).unwrap();
        let e = apply_sweep(&mut u, "mu_c.median", 0.5).unwrap_err();
        assert_eq!(
            e.to_string(),
            "`median` is not a distribution field; expected value, min, max, mean, sd or mode"
        );
    }
}
