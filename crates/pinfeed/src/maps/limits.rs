//! The bounds of one map command (`pinfeed map`): how many contact parameters, contacts and
//! worker threads, and the θ0 step and band threshold, checked before any push with errors that
//! name each setting ([`Setting`]; `pinfeed map` renders them with its flags).

use super::MapError;
use crate::mechanics::limits::num;

/// Most contact parameters in one map command.
pub const MAX_DS: usize = 1000;
/// Most contacts (maps × θ0 samples) in one map command: bounds the memory (about 100 bytes each)
/// and the time.
pub const MAX_CONTACTS: usize = 3_600_000;
/// Most worker threads.
pub const MAX_THREADS: usize = 1024;

/// A setting of a map command that a [`MapLimitError`] names. The library names it by its field
/// ([`Setting::field`]); a caller with names of its own (the flags of `pinfeed map`) renders the
/// error with [`MapLimitError::describe`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    /// Worker threads.
    Threads,
    /// The contact parameters, one map each.
    D,
    /// The θ0 step (degrees).
    ThetaStep,
    /// The band threshold (degrees).
    Threshold,
}

impl Setting {
    /// The setting's field name.
    pub fn field(self) -> &'static str {
        match self {
            Setting::Threads => "threads",
            Setting::D => "d",
            Setting::ThetaStep => "theta_step",
            Setting::Threshold => "threshold",
        }
    }
}

/// A map command out of its bounds. Its `Display` names each setting by its field;
/// [`MapLimitError::describe`] by the caller's names.
#[derive(Debug)]
pub enum MapLimitError {
    /// Threads above the limit (the value).
    Threads(usize),
    /// More contact parameters than allowed (the count).
    Ds(usize),
    /// A θ0 step that is not a finite number of degrees in (0, 360] (the value).
    ThetaStep(f64),
    /// A θ0 step that does not make a valid θ0 grid.
    Grid(MapError),
    /// Too many contacts in one command.
    Contacts {
        /// Maps asked for (one per d).
        maps: usize,
        /// θ0 samples per map.
        samples: usize,
    },
    /// A band threshold that is not a finite number of degrees in (0, 360] (the value).
    Threshold(f64),
}

impl MapLimitError {
    /// The message, with each setting named by `name`.
    pub fn describe(&self, name: impl Fn(Setting) -> String) -> String {
        use MapLimitError as E;
        match self {
            E::Threads(v) => format!(
                "{} must lie in [0, {MAX_THREADS}] (0: one per core), got {v}",
                name(Setting::Threads)
            ),
            E::Ds(v) => format!(
                "{} takes at most {MAX_DS} contact parameters, got {v}",
                name(Setting::D)
            ),
            E::ThetaStep(v) => format!(
                "{}: theta step must be a finite number of degrees in (0, 360] dividing 360, got {}",
                name(Setting::ThetaStep),
                num(*v)
            ),
            E::Grid(e) => format!("{}: {e}", name(Setting::ThetaStep)),
            E::Contacts { maps, samples } => format!(
                "{maps} maps × {samples} θ0 samples = {} contacts; at most {MAX_CONTACTS} are \
                 allowed in one command (raise {} or give fewer {})",
                maps * samples,
                name(Setting::ThetaStep),
                name(Setting::D)
            ),
            E::Threshold(v) => format!(
                "{} must be a finite number of degrees in (0, 360], got {}",
                name(Setting::Threshold),
                num(*v)
            ),
        }
    }
}

impl std::fmt::Display for MapLimitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.describe(|s| s.field().to_string()))
    }
}

impl std::error::Error for MapLimitError {}

/// Refuse out-of-range map settings: `ds` contact parameters (one map for a fence), `threads`,
/// the θ0 step and the band threshold (degrees).
pub fn check(
    threads: usize,
    ds: usize,
    fence: bool,
    theta_step: f64,
    threshold: f64,
) -> Result<(), MapLimitError> {
    if threads > MAX_THREADS {
        return Err(MapLimitError::Threads(threads));
    }
    if ds > MAX_DS {
        return Err(MapLimitError::Ds(ds));
    }
    if !(theta_step.is_finite() && theta_step > 0.0 && theta_step <= 360.0) {
        return Err(MapLimitError::ThetaStep(theta_step));
    }
    let grid = super::theta_grid(theta_step).map_err(MapLimitError::Grid)?;
    let maps = if fence { 1 } else { ds };
    if maps * grid.len() > MAX_CONTACTS {
        return Err(MapLimitError::Contacts {
            maps,
            samples: grid.len(),
        });
    }
    if !(threshold.is_finite() && threshold > 0.0 && threshold <= 360.0) {
        return Err(MapLimitError::Threshold(threshold));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_setting_by_its_field_or_by_the_callers_name() {
        let cases = [
            (
                check(MAX_THREADS + 1, 1, false, 1.0, 5.0),
                "threads must lie in [0, ",
            ),
            (check(1, MAX_DS + 1, false, 1.0, 5.0), "d takes at most "),
            (
                check(1, 1, false, f64::NAN, 5.0),
                "theta_step: theta step must be",
            ),
            (check(1, 1, false, 7.0, 5.0), "theta_step: "),
            (
                check(1, 1, false, 1.0, 0.0),
                "threshold must be a finite number",
            ),
            (
                check(1, MAX_DS, false, 0.05, 5.0),
                "1000 maps × 7200 θ0 samples",
            ),
        ];
        for (result, start) in cases {
            let e = result.unwrap_err();
            let text = e.to_string();
            assert!(text.starts_with(start), "{text}");
            assert!(!text.contains("--"), "{text}");
            let flags = e.describe(|s| format!("--{}", s.field().replace('_', "-")));
            assert!(flags.contains("--"), "{flags}");
            assert_eq!(
                flags
                    .replace("--theta-step", "theta_step")
                    .replace("--", ""),
                text
            );
        }
        assert!(check(2, 3, false, 1.0, 5.0).is_ok());
    }
}
