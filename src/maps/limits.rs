//! The bounds of one map command (`pinfeed map`): how many contact parameters, contacts and
//! worker threads, and the θ0 step and band threshold, checked before any push with errors that
//! name the command's flags.

use super::MapError;
use crate::mechanics::limits::num;

/// Most contact parameters in one map command.
pub const MAX_DS: usize = 1000;
/// Most contacts (maps × θ0 samples) in one map command: bounds the memory (about 100 bytes each)
/// and the time.
pub const MAX_CONTACTS: usize = 3_600_000;
/// Most worker threads.
pub const MAX_THREADS: usize = 1024;

/// A map command out of its bounds.
#[derive(Debug, thiserror::Error)]
pub enum MapLimitError {
    /// `--threads` above the limit (the value).
    #[error("--threads must lie in [0, {MAX_THREADS}] (0: one per core), got {0}")]
    Threads(usize),
    /// More `--d` values than allowed (the count).
    #[error("--d takes at most {MAX_DS} contact parameters, got {0}")]
    Ds(usize),
    /// `--theta-step` not a finite number of degrees in (0, 360] (the value).
    #[error("--theta-step: theta step must be a finite number of degrees in (0, 360] dividing 360, got {}", num(*.0))]
    ThetaStep(f64),
    /// `--theta-step` does not make a valid θ0 grid.
    #[error("--theta-step: {0}")]
    Grid(MapError),
    /// Too many contacts in one command.
    #[error("{maps} maps × {samples} θ0 samples = {} contacts; at most {MAX_CONTACTS} are allowed in one command (raise --theta-step or give fewer --d)", maps * samples)]
    Contacts {
        /// Maps asked for (one per d).
        maps: usize,
        /// θ0 samples per map.
        samples: usize,
    },
    /// `--threshold` not a finite number of degrees in (0, 360] (the value).
    #[error("--threshold must be a finite number of degrees in (0, 360], got {}", num(*.0))]
    Threshold(f64),
}

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
