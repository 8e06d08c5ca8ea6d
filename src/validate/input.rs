//! The inputs of a validation or calibration, checked: the member count, the ensemble of nominal
//! values with the uncertain parameters applied, and the measured file read for that ensemble.
//! The messages name the flags of `pinfeed validate` and `pinfeed calibrate` that carry each value.

use crate::maps::ensemble::EnsembleSpec;
use crate::mechanics::{limits, Fidelity};
use crate::scenario::limits::{num, show};
use crate::validate::measured::{self, Measured, MeasuredError};
use std::path::{Path, PathBuf};

/// Most members of a validation or calibration ensemble.
pub const MAX_MEMBERS: usize = 1_000_000;

/// An input that cannot be validated or calibrated against.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InputError {
    /// A member count (given by `flag`) outside [1, [`MAX_MEMBERS`]].
    #[error("{flag} must lie in [1, {MAX_MEMBERS}], got {members}")]
    Members {
        /// The flag.
        flag: &'static str,
        /// The count given.
        members: usize,
    },
    /// A μc outside its physical range.
    #[error("--mu-c must lie in {}, got {}", show(limits::MU_C), .0)]
    MuC(f64),
    /// A pin radius that is negative or not finite.
    #[error("--pin-radius must be a finite number ≥ 0, got {0}")]
    PinRadius(f64),
    /// The uncertain parameters (`KEY=VALUE,...`) are refused.
    #[error("--uncertain: {0}")]
    Uncertain(crate::maps::ensemble::SettingsError),
    /// The measured-bands file is refused.
    #[error(transparent)]
    Measured(#[from] MeasuredError),
    /// The ensemble's largest pin radius exceeds [`limits::PIN_RADIUS_A`]·a of a part in the file.
    #[error("--pin-radius (or the largest pin_radius of --uncertain) must lie in [0, {}] for part {part} of {} (part units: at most {}·a, a = {}), got {}", num(*max), file.display(), limits::PIN_RADIUS_A, num(*a), num(*radius))]
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

/// Check a member count given by `flag` (`--members`, `--score-members`).
pub fn check_members(flag: &'static str, members: usize) -> Result<(), InputError> {
    if !(1..=MAX_MEMBERS).contains(&members) {
        return Err(InputError::Members { flag, members });
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
