//! The plan checked on the line: the emitted scenario parsed and run by the discrete-event engine
//! ([`crate::engine::run`]), whose success rate (with its 95% Wilson interval) is printed beside the
//! plan's prediction.

use crate::engine::{run, RunOptions, Summary};
use std::path::Path;

/// Why a plan could not be checked.
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    #[error("the emitted scenario does not compile: {0}")]
    Scenario(#[from] crate::scenario::ScenarioError),
    #[error("the line could not run the plan: {0}")]
    Engine(#[from] crate::engine::EngineError),
}

/// Run `parts` parts of the scenario `toml` (named `path` in messages) with `seed`.
pub fn check(toml: &str, path: &Path, parts: u64, seed: u64) -> Result<Summary, CheckError> {
    let scene = crate::scenario::parse(path, toml)?;
    let opts = RunOptions {
        parts,
        seed,
        sample_paths: 0,
        keep_records: false,
    };
    let res = run(&scene, &opts, &mut |_| {})?;
    Ok(res.summary)
}

/// The belt length the emitted layout occupies (m): [`crate::study::compare`]'s footprint, from
/// the most upstream point of any obstacle (a moving pin's whole travel included) to the most
/// downstream one, plus the part's length. None if the scenario does not compile (the check
/// reports why) or has no obstacle.
pub fn footprint_m(toml: &str, path: &Path) -> Option<f64> {
    let scene = crate::scenario::parse(path, toml).ok()?;
    let [a, b] = crate::study::compare::obstacle_span(&scene)?;
    Some(b - a + crate::study::compare::part_length(&scene.part.polygon))
}
