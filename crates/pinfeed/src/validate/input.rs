//! The inputs of a validation or calibration, checked: the member count, the ensemble of nominal
//! values with the uncertain parameters applied, and the measured file read for that ensemble.
//! The errors name each setting by its field ([`Setting`]); `pinfeed validate` and `pinfeed
//! calibrate` render them with their flags.

use crate::maps::ensemble::EnsembleSpec;
use crate::mechanics::{limits, Fidelity};
use crate::scenario::limits::{num, show};
use crate::validate::measured::{self, Measured, MeasuredError};
use std::path::{Path, PathBuf};

/// Most members of a validation or calibration ensemble.
pub const MAX_MEMBERS: usize = 1_000_000;

/// A setting of a validation or calibration that an [`InputError`] can name. The library names
/// it by its field ([`Setting::field`]); a caller with names of its own (the flags of `pinfeed
/// validate` and `pinfeed calibrate`) renders the error with [`InputError::describe`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    /// The ensemble's member count.
    Members,
    /// The member count of calibration's scoring ensemble.
    ScoreMembers,
    /// The nominal pin–part friction μc.
    MuC,
    /// The nominal pin radius (part units).
    PinRadius,
    /// The uncertain parameters (`KEY=VALUE,...`).
    Uncertain,
}

impl Setting {
    /// The setting's field name.
    pub fn field(self) -> &'static str {
        match self {
            Setting::Members => "members",
            Setting::ScoreMembers => "score_members",
            Setting::MuC => "mu_c",
            Setting::PinRadius => "pin_radius",
            Setting::Uncertain => "uncertain",
        }
    }
}

/// An input that cannot be validated or calibrated against. Its `Display` names each setting by
/// its field; [`InputError::describe`] by the caller's names.
#[derive(Debug, Clone, PartialEq)]
pub enum InputError {
    /// A member count outside [1, [`MAX_MEMBERS`]].
    Members {
        /// The setting ([`Setting::Members`] or [`Setting::ScoreMembers`]).
        setting: Setting,
        /// The count given.
        members: usize,
    },
    /// A μc outside its physical range.
    MuC(f64),
    /// A pin radius that is negative or not finite.
    PinRadius(f64),
    /// The uncertain parameters (`KEY=VALUE,...`) are refused.
    Uncertain(crate::maps::ensemble::SettingsError),
    /// The measured-bands file is refused.
    Measured(MeasuredError),
    /// The ensemble's largest pin radius exceeds [`limits::PIN_RADIUS_A`]·a of a part in the file.
    PinRadiusForPart {
        /// The part spec.
        part: String,
        /// The measured-bands file.
        file: PathBuf,
        /// The part's circumradius a (part units).
        a: f64,
        /// The largest pin radius allowed for it (part units).
        max: f64,
        /// The pin radius given (part units).
        radius: f64,
    },
}

impl InputError {
    /// The message, with each setting named by `name`.
    pub fn describe(&self, name: impl Fn(Setting) -> String) -> String {
        match self {
            InputError::Members { setting, members } => {
                format!(
                    "{} must lie in [1, {MAX_MEMBERS}], got {members}",
                    name(*setting)
                )
            }
            InputError::MuC(v) => format!(
                "{} must lie in {}, got {v}",
                name(Setting::MuC),
                show(limits::MU_C)
            ),
            InputError::PinRadius(v) => format!(
                "{} must be a finite number ≥ 0, got {v}",
                name(Setting::PinRadius)
            ),
            InputError::Uncertain(e) => format!("{}: {e}", name(Setting::Uncertain)),
            InputError::Measured(e) => e.to_string(),
            InputError::PinRadiusForPart {
                part,
                file,
                a,
                max,
                radius,
            } => format!(
                "{} (or the largest pin_radius of {}) must lie in [0, {}] for part {part} of {} \
                 (part units: at most {}·a, a = {}), got {}",
                name(Setting::PinRadius),
                name(Setting::Uncertain),
                num(*max),
                file.display(),
                limits::PIN_RADIUS_A,
                num(*a),
                num(*radius)
            ),
        }
    }
}

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.describe(|s| s.field().to_string()))
    }
}

impl std::error::Error for InputError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            InputError::Measured(e) => e.source(),
            _ => None,
        }
    }
}

impl From<MeasuredError> for InputError {
    fn from(e: MeasuredError) -> Self {
        InputError::Measured(e)
    }
}

/// Check a member count, named by `setting` ([`Setting::Members`], [`Setting::ScoreMembers`]).
pub fn check_members(setting: Setting, members: usize) -> Result<(), InputError> {
    if !(1..=MAX_MEMBERS).contains(&members) {
        return Err(InputError::Members { setting, members });
    }
    Ok(())
}

/// The ensemble of the nominal values (μc, pin radius in part units, fidelity and integration
/// tolerance) with `uncertain` (`KEY=VALUE,...`, as `pinfeed map --uncertain`) applied.
pub fn ensemble_spec(
    mu_c: f64,
    pin_radius: f64,
    model: Fidelity,
    tol: f64,
    uncertain: Option<&str>,
) -> Result<EnsembleSpec, InputError> {
    if !crate::scenario::limits::contains(limits::MU_C, mu_c) {
        return Err(InputError::MuC(mu_c));
    }
    if !(pin_radius.is_finite() && pin_radius >= 0.0) {
        return Err(InputError::PinRadius(pin_radius));
    }
    let spec = EnsembleSpec::nominal(mu_c, pin_radius, model, tol);
    match uncertain {
        None => Ok(spec),
        Some(u) => spec.with_settings(u).map_err(InputError::Uncertain),
    }
}

/// Load the measured file for an ensemble (its largest pin radius sets the reach of d).
/// The pin radius may be at most the range `map` and `contact` allow for each part
/// ([`limits::PIN_RADIUS_A`]·a). `part` (`--part`) replaces the file's part column.
pub fn load_measured(
    path: &Path,
    spec: &EnsembleSpec,
    part: Option<&str>,
) -> Result<Measured, InputError> {
    let m = measured::load_for(path, spec.max_pin_radius(), part)?;
    let r = spec.max_pin_radius();
    for (part, poly) in &m.parts {
        let rmax = limits::PIN_RADIUS_A * poly.radius();
        if r > rmax {
            return Err(InputError::PinRadiusForPart {
                part: part.clone(),
                file: path.to_path_buf(),
                a: poly.radius(),
                max: rmax,
                radius: r,
            });
        }
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_setting_by_its_field_or_by_the_callers_name() {
        let spec = |mu: f64, r: f64, u: Option<&str>| {
            ensemble_spec(mu, r, Fidelity::Exact, 1e-6, u).map(|_| ())
        };
        let cases = [
            (
                check_members(Setting::ScoreMembers, 0),
                "score_members must lie in [1, ",
            ),
            (
                check_members(Setting::Members, MAX_MEMBERS + 1),
                "members must lie in [1, ",
            ),
            (spec(9.0, 0.0, None), "mu_c must lie in [0, 5], got 9"),
            (
                spec(0.5, f64::NAN, None),
                "pin_radius must be a finite number ≥ 0, got NaN",
            ),
            (
                spec(0.5, 0.0, Some("foo=1")),
                "uncertain: unknown uncertain parameter 'foo'",
            ),
        ];
        for (result, start) in cases {
            let e = result.unwrap_err();
            let text = e.to_string();
            assert!(text.starts_with(start), "{text}");
            assert!(!text.contains("--"), "{text}");
            // The caller's names replace the field names and nothing else.
            let renamed = e.describe(|s| format!("<{}>", s.field()));
            let field = start.split(' ').next().unwrap().trim_end_matches(':');
            assert_eq!(renamed, text.replacen(field, &format!("<{field}>"), 1));
        }
        assert!(check_members(Setting::Members, 1).is_ok());
        assert!(spec(0.5, 0.0, None).is_ok());
    }
}
