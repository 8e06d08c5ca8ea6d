//! The plan checked on the line: the emitted scenario parsed and run by the discrete-event engine
//! ([`crate::engine::run`]), whose success rate (with its 95% Wilson interval) is printed beside the
//! plan's prediction.

use crate::engine::{run, RunOptions, Summary};
use std::path::Path;

/// Why a plan could not be checked.
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    /// The emitted scenario does not compile.
    #[error("the emitted scenario does not compile: {0}")]
    Scenario(#[from] crate::scenario::ScenarioError),
    /// The engine refused to run the plan.
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
        online: None,
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

/// The Monte Carlo study that runs a plan under the uncertainty it was planned against
/// (`--mu-c-range` → `[uncertain.mu_c]` uniform for the line's pins, and `[uncertain.fence_mu_f]`
/// over the same range for its fences when their μf is the nominal μc (`fence_mu_f_given`
/// false, no `--mu-f`); `--tripod` → `[uncertain.support]` tripod): each sample sends one part
/// through a freshly perturbed copy of the line, as `pinfeed mc` does. `obstacles` are the
/// kinds of the line's obstacles (`pin`, `fence`, …). None for a plan without declared
/// uncertainty.
pub fn uncertainty_study(
    problem: &super::Problem,
    obstacles: &[&str],
    fence_mu_f_given: bool,
    scenario_file: &str,
    study_file: &str,
    samples: u64,
) -> Option<String> {
    if problem.mu_c_range.is_none() && !problem.tripod {
        return None;
    }
    let mut t = format!(
        "# The plan {scenario_file} under the uncertainty it was planned against (written by\n# `pinfeed plan`):\n#\n#   pinfeed mc {study_file}\n\nscenario = \"{scenario_file}\"\nseed = {}\nsamples = {samples}\n",
        problem.seed
    );
    if let Some((lo, hi)) = problem.mu_c_range {
        // A study parameter that reaches nothing is refused: μc only where the line has pins.
        if obstacles.iter().any(|&k| k != "fence") {
            t += &format!(
                "\n[uncertain.mu_c]\ndistribution = \"uniform\"\nmin = {lo}\nmax = {hi}\n"
            );
        }
        if !fence_mu_f_given && obstacles.contains(&"fence") {
            t += &format!(
                "\n# The fences' μf is the nominal μc: it is as uncertain.\n[uncertain.fence_mu_f]\ndistribution = \"uniform\"\nmin = {lo}\nmax = {hi}\n"
            );
        }
    }
    if problem.tripod {
        t += "\n[uncertain.support]\nmodel = \"tripod\"\n";
    }
    Some(t)
}

/// The outcomes and the number of samples of the study `study` (a study without sweeps; its
/// scenario `scenario`; both written to `dir` under `scenario_file` and `study_file` first).
pub fn check_uncertain(
    scenario: &str,
    study: &str,
    dir: &Path,
    scenario_file: &str,
    study_file: &str,
) -> Result<(crate::engine::OutcomeCounts, u64), UncertainCheckError> {
    std::fs::create_dir_all(dir)?;
    crate::output::write_atomic(dir.join(scenario_file), scenario)?;
    let path = dir.join(study_file);
    crate::output::write_atomic(&path, study)?;
    let study = crate::study::mc::load(&path, None)?;
    let n = study.total_samples();
    let tallies = crate::study::mc::run::run_range(&study, 0..n, &|| {})?;
    let outcomes = tallies.into_values().next().map(|t| t.outcomes);
    Ok((outcomes.unwrap_or_default(), n))
}

/// Why the plan could not be run under its uncertainty.
#[derive(Debug, thiserror::Error)]
pub enum UncertainCheckError {
    /// The study file could not be written.
    #[error("writing the study: {0}")]
    Io(#[from] std::io::Error),
    /// The Monte Carlo study failed.
    #[error("the plan's uncertainty study failed: {0}")]
    Study(#[from] crate::study::mc::StudyError),
}
