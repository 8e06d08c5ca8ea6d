//! Measured bands against the model: `pinfeed validate` and `pinfeed calibrate`.
//!
//! * [`measured`]: the measured-bands CSV and its located errors;
//! * [`input`]: the member count, the ensemble and the measured file, checked;
//! * [`predict`]: an ensemble's passes for every measured row ([`crate::maps::ensemble`]);
//! * [`score`]: containment, overlap, centre offset, predicted probability, coverage, log score;
//! * [`calibrate`]: maximum-likelihood fit of μc centre and spread, tripod share and pin radius
//!   over one reweighted ensemble, with profile-likelihood intervals;
//! * [`synthetic`]: a measured-bands file drawn from hidden parameters, to check the two against.

pub mod calibrate;
pub mod input;
pub mod measured;
pub mod predict;
pub mod score;
pub mod synthetic;

use crate::maps::ensemble::{EnsembleError, EnsembleSpec};
use measured::Measured;
use predict::Predictions;
use score::{RowScore, ScoreSettings, Summary};

/// Default members of a validation ensemble.
pub const DEFAULT_MEMBERS: usize = 500;

/// Score `measured` against `members` members of the ensemble `spec` seeded with `seed`.
pub fn validate(
    measured: &Measured,
    spec: &EnsembleSpec,
    seed: u64,
    members: usize,
    passes: usize,
    score: &ScoreSettings,
) -> Result<(Vec<RowScore>, Summary, Predictions), EnsembleError> {
    let draw = (seed, members, passes);
    validate_observed(measured, spec, draw, score, &crate::progress::silent)
}

/// [`validate`] with `draw` = (seed, members, passes), telling `progress` the passes run of all
/// those needed.
pub fn validate_observed(
    measured: &Measured,
    spec: &EnsembleSpec,
    (seed, members, passes): (u64, usize, usize),
    score: &ScoreSettings,
    progress: crate::progress::Report,
) -> Result<(Vec<RowScore>, Summary, Predictions), EnsembleError> {
    let pred = predict::predict_observed(measured, spec, seed, members, passes, progress)?;
    let weights = vec![1.0; pred.members.len() * passes];
    let (rows, count) = score::score_rows(measured, &pred.rows, &weights, passes, score);
    let summary = score::summarise(&rows, count, score.contained_share);
    Ok((rows, summary, pred))
}
