//! A design checked under the uncertainty it is planned against ([`Uncertainty`]: the default
//! set, the harsh one, a file's `[uncertain.*]` tables, or none): its perturbations as values for
//! the check the planner runs in memory ([`check_uncertain`]) and as the study file written
//! beside the design ([`Uncertainty::study_text`]) for `pinfeed mc` to run again. Both come from
//! the one typed value, and a test checks that the written file, read back, is the same study.

use crate::mechanics::support::SupportChoice;
use crate::random::distribution::Distribution;
use crate::scenario::Scene;
use crate::study::mc::{Perturbations, Study, StudyError};
use std::path::Path;

/// How wide the default uncertainty's friction interval is on each side of the nominal value.
pub const DEFAULT_FRICTION_HALF_WIDTH: f64 = 0.1;
/// The default uncertainty's placement error of pins and fences, each way in x and y (m).
pub const DEFAULT_PLACEMENT_M: f64 = 0.0005;
/// The default uncertainty's fence angle error, each way (degrees).
pub const DEFAULT_FENCE_ANGLE_DEG: f64 = 0.5;
/// The harsh set's friction interval (`--robust`), at pins and fences alike.
pub const HARSH_FRICTION: (f64, f64) = (0.3, 0.7);

/// Which uncertainty a design is planned against.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum UncertaintySet {
    /// None: the nominal physics (`--nominal`).
    Nominal,
    /// The default: friction ±0.1 around the nominal at pins and fences, pins and fences placed
    /// ±0.5 mm off in x and y, fence angles ±0.5° off, all uniform.
    Default,
    /// The default's placement and angles with friction uniform in [0.3, 0.7] and a random
    /// tripod support per part (`--robust`).
    Robust,
    /// `[uncertain.*]` tables read from a file (`--uncertain FILE`), its path as given.
    File(String),
    /// A friction range and/or tripods asked for on their own (`--mu-c-range`, `--tripod` with
    /// `--nominal`).
    Custom,
}

/// The uncertainty a design is planned and checked against: the perturbations of its verdict's
/// Monte Carlo study (each sample one part through a freshly perturbed line, as `pinfeed mc`
/// runs a study), from which the search takes what its particles can carry (a friction range
/// at the pins and at the fences, tripod supports); the search's pin margin
/// ([`super::Problem::min_margin_m`]) stands for the pins' placement error.
#[derive(Debug, Clone, PartialEq)]
pub struct Uncertainty {
    /// Which set it is.
    pub set: UncertaintySet,
    /// What is uncertain, for a line of every kind of obstacle (a design's line keeps what
    /// reaches it: [`Uncertainty::for_line`]).
    pub perturbations: Perturbations,
}

fn uniform_around(centre: f64, half: f64) -> Distribution {
    Distribution::Uniform {
        min: (centre - half).max(0.0),
        max: centre + half,
    }
}

fn placement(p: &mut Perturbations, metres: f64, angle_deg: f64) {
    let u = |h: f64| Some(Distribution::Uniform { min: -h, max: h });
    p.pin_x = u(metres);
    p.pin_y = u(metres);
    p.fence_x = u(metres);
    p.fence_y = u(metres);
    p.fence_angle = u(angle_deg);
}

impl Uncertainty {
    /// The nominal physics: nothing uncertain.
    pub fn nominal() -> Uncertainty {
        Uncertainty {
            set: UncertaintySet::Nominal,
            perturbations: Perturbations::none(SupportChoice::Uniform),
        }
    }

    /// The default uncertainty around pin friction `mu_c` and fence friction `mu_f`: each
    /// uniform within ±[`DEFAULT_FRICTION_HALF_WIDTH`] (not below 0), pins' and fences' upstream
    /// ends ±[`DEFAULT_PLACEMENT_M`] in x and y, fence angles ±[`DEFAULT_FENCE_ANGLE_DEG`].
    pub fn default_around(mu_c: f64, mu_f: f64) -> Uncertainty {
        let mut p = Perturbations::none(SupportChoice::Uniform);
        p.mu_c = Some(uniform_around(mu_c, DEFAULT_FRICTION_HALF_WIDTH));
        p.fence_mu_f = Some(uniform_around(mu_f, DEFAULT_FRICTION_HALF_WIDTH));
        placement(&mut p, DEFAULT_PLACEMENT_M, DEFAULT_FENCE_ANGLE_DEG);
        Uncertainty {
            set: UncertaintySet::Default,
            perturbations: p,
        }
    }

    /// The harsh set: the default's placement and angle errors, friction uniform in
    /// [`HARSH_FRICTION`] at pins and fences, a random tripod support per part.
    pub fn robust() -> Uncertainty {
        let mut p = Perturbations::none(SupportChoice::Tripod);
        let (min, max) = HARSH_FRICTION;
        p.mu_c = Some(Distribution::Uniform { min, max });
        p.fence_mu_f = Some(Distribution::Uniform { min, max });
        placement(&mut p, DEFAULT_PLACEMENT_M, DEFAULT_FENCE_ANGLE_DEG);
        Uncertainty {
            set: UncertaintySet::Robust,
            perturbations: p,
        }
    }

    /// A friction range (pins, and fences whose μf is the pins' μc unless `fence_mu_f_given`)
    /// and/or random tripods, nothing else: what `--mu-c-range` and `--tripod` planned against
    /// before there were sets. Nominal when neither is asked for.
    pub fn custom(
        mu_c_range: Option<(f64, f64)>,
        tripod: bool,
        fence_mu_f_given: bool,
    ) -> Uncertainty {
        if mu_c_range.is_none() && !tripod {
            return Uncertainty::nominal();
        }
        let support = if tripod {
            SupportChoice::Tripod
        } else {
            SupportChoice::Uniform
        };
        let mut p = Perturbations::none(support);
        let uniform = |(min, max): (f64, f64)| Distribution::Uniform { min, max };
        p.mu_c = mu_c_range.map(uniform);
        p.fence_mu_f = mu_c_range.filter(|_| !fence_mu_f_given).map(uniform);
        Uncertainty {
            set: UncertaintySet::Custom,
            perturbations: p,
        }
    }

    /// `[uncertain.*]` tables read from `file` (its text `source`), as a study declares them.
    pub fn from_file(file: &Path, source: &str) -> Result<Uncertainty, StudyError> {
        let perturbations = crate::study::mc::parse_uncertain(file, source)?;
        Ok(Uncertainty {
            set: UncertaintySet::File(file.display().to_string()),
            perturbations,
        })
    }

    /// Is nothing uncertain?
    pub fn is_nominal(&self) -> bool {
        self.perturbations.slots().iter().all(|(_, d)| d.is_none())
            && self.perturbations.support == SupportChoice::Uniform
    }

    /// The friction range the search's particles draw their pin μc from: the range of
    /// `[uncertain.mu_c]` (None when it is absent or a single value).
    pub fn pins_friction(&self) -> Option<(f64, f64)> {
        range_of(&self.perturbations.mu_c)
    }

    /// The friction range the search's particles draw their fence μf from.
    pub fn fences_friction(&self) -> Option<(f64, f64)> {
        range_of(&self.perturbations.fence_mu_f)
    }

    /// The range of the fences' angle error (degrees) the search's particles plan against.
    pub fn fences_angle(&self) -> Option<(f64, f64)> {
        range_of(&self.perturbations.fence_angle)
    }

    /// Does each part rest on a random tripod?
    pub fn tripod(&self) -> bool {
        self.perturbations.support == SupportChoice::Tripod
    }

    /// The perturbations that reach a line of obstacles of `kinds` (`pin`, `fence`,
    /// `sensor_pin`, `moving_pin`): a study refuses a parameter that reaches nothing, so the
    /// pins' parameters go on a line without pins, the fences' on one without fences, and so on.
    /// None when nothing is left uncertain.
    pub fn for_line(&self, kinds: &[&str]) -> Option<Perturbations> {
        let pins = kinds.iter().any(|k| k.ends_with("pin"));
        let fences = kinds.contains(&"fence");
        let sensors = kinds.contains(&"sensor_pin");
        let movers = kinds.contains(&"moving_pin");
        let mut p = self.perturbations.clone();
        for (name, d) in p.slots_mut() {
            let reached = match name {
                "mu_c" | "pin_x" | "pin_y" | "pin_radius" => pins,
                n if n.starts_with("fence_") => fences,
                n if n.starts_with("sensor_") => sensors,
                n if n.starts_with("actuator_") => movers,
                "controller_latency" => sensors,
                _ => true,
            };
            if !reached {
                *d = None;
            }
        }
        let u = Uncertainty {
            set: self.set.clone(),
            perturbations: p,
        };
        (!u.is_nominal()).then_some(u.perturbations)
    }

    /// The uncertainty in words, e.g. `the default uncertainty: mu_c uniform [0.4, 0.6], …`.
    pub fn describe(&self) -> String {
        let what = match &self.set {
            UncertaintySet::Nominal => return "nominal physics (no uncertainty)".into(),
            UncertaintySet::Default => "the default uncertainty".to_string(),
            UncertaintySet::Robust => "the harsh uncertainty (--robust)".to_string(),
            UncertaintySet::File(f) => format!("the uncertainty of {f}"),
            UncertaintySet::Custom => "the uncertainty asked for".to_string(),
        };
        format!("{what}: {}", describe_perturbations(&self.perturbations))
    }

    /// The study file that runs a design's line under this uncertainty: the line is
    /// `scenario_file` (beside the study), of obstacles of `kinds`; `study_file` is the study's
    /// own name, for its header. None when nothing reaches the line.
    pub fn study_text(
        &self,
        kinds: &[&str],
        scenario_file: &str,
        study_file: &str,
        seed: u64,
        samples: u64,
    ) -> Option<String> {
        let p = self.for_line(kinds)?;
        let mut t = format!(
            "# The design {scenario_file} under the uncertainty it was planned against (written by\n# `pinfeed plan`): {}.\n#\n#   pinfeed mc {study_file}\n\nscenario = \"{scenario_file}\"\nseed = {seed}\nsamples = {samples}\n",
            self.describe().replace('\n', " ")
        );
        for (name, d) in p.slots() {
            if let Some(d) = d {
                t += &format!("\n[uncertain.{name}]\n{}", d.toml_fields());
            }
        }
        match p.support {
            SupportChoice::Uniform => {}
            SupportChoice::Tripod => t += "\n[uncertain.support]\nmodel = \"tripod\"\n",
            SupportChoice::Smooth(s) => {
                t += &format!(
                    "\n[uncertain.support]\nmodel = \"smooth\"\nbumps = {}\nwidth = {:?}\ncontrast = {:?}\npoints = {}\n",
                    s.bumps, s.width, s.contrast, s.points
                )
            }
        }
        Some(t)
    }
}

/// A distribution's range, None when absent or a single value.
fn range_of(d: &Option<Distribution>) -> Option<(f64, f64)> {
    let (lo, hi) = d.as_ref()?.range();
    (hi > lo).then_some((lo, hi))
}

/// `mu_c uniform [0.4, 0.6], pin_x uniform [-0.0005, 0.0005], …, support: a random tripod …`.
pub fn describe_perturbations(p: &Perturbations) -> String {
    let mut parts: Vec<String> = p
        .slots()
        .iter()
        .filter_map(|(name, d)| d.as_ref().map(|d| format!("{name} {}", d.describe())))
        .collect();
    if p.support != SupportChoice::Uniform {
        parts.push(format!("support: {}", p.support.describe()));
    }
    if parts.is_empty() {
        "nothing".into()
    } else {
        parts.join(", ")
    }
}

/// Run `samples` samples of `scene` under `perturbations` with `seed`, in memory (a study built
/// in code, [`Study::of_scene`]): the outcomes and the number of samples.
pub fn check_uncertain(
    scene: &Scene,
    perturbations: Perturbations,
    seed: u64,
    samples: u64,
) -> Result<(crate::engine::OutcomeCounts, u64), StudyError> {
    check_uncertain_from(scene, perturbations, seed, 0, samples)
}

/// Samples `from..to` of the study [`check_uncertain`] runs with `to` samples: as a study's
/// shards, the counts of `0..m` and `m..n` add up to those of `0..n` (a check that wants more
/// samples runs only the new ones).
pub fn check_uncertain_from(
    scene: &Scene,
    perturbations: Perturbations,
    seed: u64,
    from: u64,
    to: u64,
) -> Result<(crate::engine::OutcomeCounts, u64), StudyError> {
    let study = Study::of_scene("design", scene.clone(), seed, to, perturbations)?;
    let n = study.total_samples();
    let from = from.min(n);
    let tallies = crate::study::mc::run::run_range(&study, from..n, &|| {})?;
    let outcomes = tallies.into_values().next().map(|t| t.outcomes);
    Ok((outcomes.unwrap_or_default(), n - from))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The study file a design writes, read back as `pinfeed mc` reads it (its scenario given in
    /// memory), is the study the planner runs: the same perturbations, seed and samples, for
    /// every set and kind of line.
    #[test]
    fn the_written_uncertainty_study_is_the_one_the_planner_runs() {
        let sets = [
            Uncertainty::default_around(0.5, 0.35),
            Uncertainty::robust(),
            Uncertainty::custom(Some((0.3, 0.7)), false, false),
            Uncertainty::custom(None, true, false),
            Uncertainty::custom(Some((0.45, 0.55)), true, true),
            Uncertainty::from_file(
                Path::new("u.toml"),
                "[uncertain.mu_c]\ndistribution = \"normal\"\nmean = 0.5\nsd = 0.05\nmin = 0.3\n\n[uncertain.fence_angle]\ndistribution = \"triangular\"\nmin = -1.0\nmode = 0.0\nmax = 1.0\n\n[uncertain.support]\nmodel = \"smooth\"\nbumps = 4\n",
            )
            .unwrap(),
        ];
        let lines: [(&str, &[&str]); 2] = [
            ("quickstart.toml", &["pin", "pin", "pin"]),
            ("tripoly2_fences.toml", &["fence", "fence"]),
        ];
        for u in &sets {
            for (file, kinds) in lines {
                let scenario =
                    std::fs::read_to_string(crate::project_path(&format!("scenarios/{file}")))
                        .unwrap();
                let Some(typed) = u.for_line(kinds) else {
                    continue;
                };
                let text = u
                    .study_text(kinds, file, "design.uncertain.toml", 17, 321)
                    .expect("what reaches the line is written");
                let read = |_: &Path| Ok(scenario.clone());
                let study = crate::study::mc::parse_with(
                    Path::new("design.uncertain.toml"),
                    &text,
                    None,
                    &read,
                )
                .unwrap_or_else(|e| panic!("{:?} {file}: {e}\n{text}", u.set));
                assert_eq!(study.declared, typed, "{:?} {file}\n{text}", u.set);
                assert_eq!((study.seed, study.samples), (17, 321));
                assert!(study.axes.is_empty());
            }
        }
        // What reaches the line, and only that: a fence line has no pin parameter, a pin line
        // no fence parameter; nothing uncertain writes nothing.
        let d = Uncertainty::default_around(0.5, 0.5);
        let pins = d.for_line(&["pin"]).unwrap();
        assert!(pins.mu_c.is_some() && pins.pin_x.is_some() && pins.fence_mu_f.is_none());
        let fences = d.for_line(&["fence"]).unwrap();
        assert!(fences.mu_c.is_none() && fences.pin_y.is_none() && fences.fence_angle.is_some());
        assert!(Uncertainty::custom(Some((0.3, 0.7)), false, true)
            .for_line(&["fence"])
            .is_none());
        let n = Uncertainty::nominal();
        assert!(n.is_nominal() && n.for_line(&["pin"]).is_none());
        assert!(n.study_text(&["pin"], "a", "b", 1, 1).is_none());
    }

    /// The default set is the documented one: ±0.1 of friction around each nominal value (not
    /// below 0), ±0.5 mm, ±0.5°; the harsh set's friction is [0.3, 0.7] with tripods.
    #[test]
    fn the_default_and_harsh_sets_are_the_documented_ones() {
        let d = Uncertainty::default_around(0.5, 0.05);
        let close = |a: Option<(f64, f64)>, b: (f64, f64)| {
            let a = a.unwrap();
            assert!(
                (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12,
                "{a:?} {b:?}"
            );
        };
        close(d.pins_friction(), (0.4, 0.6));
        close(d.fences_friction(), (0.0, 0.15));
        assert!(!d.tripod());
        assert_eq!(d.perturbations.pin_y.unwrap().range(), (-0.0005, 0.0005));
        assert_eq!(d.perturbations.fence_angle.unwrap().range(), (-0.5, 0.5));
        let r = Uncertainty::robust();
        close(r.pins_friction(), (0.3, 0.7));
        close(r.fences_friction(), (0.3, 0.7));
        assert!(r.tripod());
        assert_eq!(r.perturbations.fence_x, d.perturbations.fence_x);
    }

    /// A file's tables are read with the study's checks, located; naming obstacles of a line
    /// that does not exist yet is refused.
    #[test]
    fn an_uncertainty_file_is_checked_where_it_is_read() {
        let bad = |text: &str, says: &[&str]| {
            let e = Uncertainty::from_file(Path::new("my.toml"), text)
                .unwrap_err()
                .to_string();
            for s in says {
                assert!(e.contains(s), "{e}\nlacks {s}");
            }
        };
        bad(
            "[uncertain.mu_c]\ndistribution = \"uniform\"\nmin = 0.7\nmax = 0.3\n",
            &["my.toml:4", "uncertain.mu_c.max"],
        );
        bad("[uncertain.mu_cc]\nvalue = 1\n", &["my.toml", "mu_cc"]);
        bad("scenario = \"x.toml\"\n", &["my.toml", "scenario"]);
        bad(
            "[uncertain.fence_angle]\ndistribution = \"uniform\"\nmin = -1.0\nmax = 1.0\nfences = [\"f1\"]\n",
            &["my.toml:5", "not designed yet"],
        );
        let ok = Uncertainty::from_file(Path::new("my.toml"), "").unwrap();
        assert!(ok.is_nominal());
    }

    /// A check that wants more samples runs only the new ones: the counts of samples 0..m and
    /// m..n add up to those of 0..n, as a study's shards do.
    #[test]
    fn an_uncertain_check_grows_by_its_new_samples_only() {
        let scene =
            crate::scenario::load(&crate::project_path("scenarios/tripoly2_fences.toml")).unwrap();
        let p = Uncertainty::custom(Some((0.3, 0.7)), true, false)
            .for_line(&["fence"])
            .unwrap();
        let (whole, n) = check_uncertain(&scene, p.clone(), 5, 240).unwrap();
        let (mut parts, m) = check_uncertain_from(&scene, p.clone(), 5, 0, 90).unwrap();
        let (rest, k) = check_uncertain_from(&scene, p, 5, 90, 240).unwrap();
        parts.absorb(&rest);
        assert_eq!((n, m + k), (240, 240));
        assert_eq!(parts, whole);
        assert!(
            whole.success > 0 && whole.success < 240,
            "{whole:?}: a mixed line"
        );
    }
}
