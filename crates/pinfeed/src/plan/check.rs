//! A design checked under the uncertainty it was planned against: the perturbations, as values
//! ([`uncertainty`]) for the check the planner runs in memory ([`check_uncertain`]) and as the
//! study file written beside the design ([`uncertainty_study`]) for `pinfeed mc` to run again.
//! Both come from one description of the uncertainty (`Uncertain`), and a test checks that the
//! written file, read back, is the same study.

use crate::mechanics::support::SupportChoice;
use crate::random::distribution::Distribution;
use crate::scenario::Scene;
use crate::study::mc::{Perturbations, Study, StudyError};

/// The uncertainty a plan was planned against, as it reaches the line: μc uniform over a range at
/// the pins, the fences' μf over the same range where it is the nominal μc, and random tripods.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Uncertain {
    /// `[uncertain.mu_c]` uniform on this range (the line has pins).
    mu_c: Option<(f64, f64)>,
    /// `[uncertain.fence_mu_f]` uniform on this range (the line has fences whose μf is μc).
    fence_mu_f: Option<(f64, f64)>,
    /// `[uncertain.support]` tripod.
    tripod: bool,
}

impl Uncertain {
    /// The uncertainty of `problem` on a line of obstacles of `obstacles` kinds (`pin`, `fence`,
    /// …); `fence_mu_f_given`: the fences have a μf of their own (`--mu-f`). None for a plan
    /// without declared uncertainty.
    fn of(
        problem: &super::Problem,
        obstacles: &[&str],
        fence_mu_f_given: bool,
    ) -> Option<Uncertain> {
        if problem.mu_c_range.is_none() && !problem.tripod {
            return None;
        }
        let range = problem.mu_c_range;
        Some(Uncertain {
            // A study parameter that reaches nothing is refused: μc only where the line has pins.
            mu_c: range.filter(|_| obstacles.iter().any(|&k| k != "fence")),
            fence_mu_f: range.filter(|_| !fence_mu_f_given && obstacles.contains(&"fence")),
            tripod: problem.tripod,
        })
    }
}

/// The perturbations of a plan's uncertainty check: see [`uncertainty_study`], whose file is the
/// same study. None for a plan without declared uncertainty.
pub fn uncertainty(
    problem: &super::Problem,
    obstacles: &[&str],
    fence_mu_f_given: bool,
) -> Option<Perturbations> {
    let u = Uncertain::of(problem, obstacles, fence_mu_f_given)?;
    let support = if u.tripod {
        SupportChoice::Tripod
    } else {
        SupportChoice::Uniform
    };
    let mut p = Perturbations::none(support);
    let uniform = |(min, max): (f64, f64)| Distribution::Uniform { min, max };
    p.mu_c = u.mu_c.map(uniform);
    p.fence_mu_f = u.fence_mu_f.map(uniform);
    Some(p)
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
    let u = Uncertain::of(problem, obstacles, fence_mu_f_given)?;
    let mut t = format!(
        "# The plan {scenario_file} under the uncertainty it was planned against (written by\n# `pinfeed plan`):\n#\n#   pinfeed mc {study_file}\n\nscenario = \"{scenario_file}\"\nseed = {}\nsamples = {samples}\n",
        problem.seed
    );
    if let Some((lo, hi)) = u.mu_c {
        t += &format!("\n[uncertain.mu_c]\ndistribution = \"uniform\"\nmin = {lo}\nmax = {hi}\n");
    }
    if let Some((lo, hi)) = u.fence_mu_f {
        t += &format!(
            "\n# The fences' μf is the nominal μc: it is as uncertain.\n[uncertain.fence_mu_f]\ndistribution = \"uniform\"\nmin = {lo}\nmax = {hi}\n"
        );
    }
    if u.tripod {
        t += "\n[uncertain.support]\nmodel = \"tripod\"\n";
    }
    Some(t)
}

/// Run `samples` samples of `scene` under `perturbations` with `seed`, in memory (a study built
/// in code, [`Study::of_scene`]): the outcomes and the number of samples.
pub fn check_uncertain(
    scene: &Scene,
    perturbations: Perturbations,
    seed: u64,
    samples: u64,
) -> Result<(crate::engine::OutcomeCounts, u64), StudyError> {
    let study = Study::of_scene("design", scene.clone(), seed, samples, perturbations)?;
    let n = study.total_samples();
    let tallies = crate::study::mc::run::run_range(&study, 0..n, &|| {})?;
    let outcomes = tallies.into_values().next().map(|t| t.outcomes);
    Ok((outcomes.unwrap_or_default(), n))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::Problem;
    use std::path::Path;

    /// The study file a design writes, read back as `pinfeed mc` reads it (its scenario given in
    /// memory), is the study the planner runs: the same perturbations, seed and samples.
    #[test]
    fn the_written_uncertainty_study_is_the_one_the_planner_runs() {
        /// (scenario, obstacle kinds, μc range, tripod, fences' μf given)
        type Case<'a> = (&'a str, &'a [&'a str], Option<(f64, f64)>, bool, bool);
        let cases: [Case; 6] = [
            (
                "quickstart.toml",
                &["pin", "pin", "pin"],
                Some((0.3, 0.7)),
                false,
                false,
            ),
            ("quickstart.toml", &["pin", "pin", "pin"], None, true, false),
            (
                "quickstart.toml",
                &["pin", "pin", "pin"],
                Some((0.45, 0.55)),
                true,
                false,
            ),
            (
                "tripoly2_fences.toml",
                &["fence", "fence"],
                Some((0.3, 0.7)),
                true,
                false,
            ),
            (
                "tripoly2_fences.toml",
                &["fence", "fence"],
                None,
                true,
                true,
            ),
            (
                "tripoly2_fences.toml",
                &["fence", "fence"],
                Some((0.3, 0.7)),
                false,
                true,
            ),
        ];
        for (file, kinds, range, tripod, mu_f_given) in cases {
            let scenario =
                std::fs::read_to_string(crate::project_path(&format!("scenarios/{file}"))).unwrap();
            let mut p = Problem::new("tripoly2");
            p.mu_c_range = range;
            p.tripod = tripod;
            p.seed = 17;
            let typed = uncertainty(&p, kinds, mu_f_given);
            let text = uncertainty_study(&p, kinds, mu_f_given, file, "design.uncertain.toml", 321);
            let (Some(typed), Some(text)) = (typed, text) else {
                panic!("{file} {range:?} {tripod}: a declared uncertainty gives both");
            };
            let read = |_: &Path| Ok(scenario.clone());
            let study = crate::study::mc::parse_with(
                Path::new("design.uncertain.toml"),
                &text,
                None,
                &read,
            )
            .unwrap_or_else(|e| panic!("{file} {range:?} {tripod}: {e}\n{text}"));
            assert_eq!(study.declared, typed, "{file} {range:?} {tripod}\n{text}");
            assert_eq!((study.seed, study.samples), (17, 321));
            assert!(study.axes.is_empty());
        }
        // No declared uncertainty: neither.
        let p = Problem::new("tripoly2");
        assert!(uncertainty(&p, &["pin"], false).is_none());
        assert!(uncertainty_study(&p, &["pin"], false, "a", "b", 1).is_none());
    }
}
