//! The evaluation of a checked request with the policy for classifiers that cannot be trained,
//! the placement search, and the typed result.

use super::{Checked, Request, SenseError};
use crate::sensing::classify::{self, Classifier, ClassifierOptions};
use crate::sensing::evaluate::{
    applicable, evaluate_observed, noise_sweep, Config, Evaluation, Factory, Problem, SensorPoint,
    TruthDraw,
};
use crate::sensing::placement::{self, Placement};
use crate::sensing::templates::{Hypotheses, TemplateSet};
use crate::sensing::{SensorKind, SensorSettings};
use serde::Serialize;
use std::sync::Mutex;

/// The declared uncertainty, as reported.
#[derive(Debug, Serialize)]
pub struct UncertaintyReport {
    /// The distribution of μc, in words.
    pub mu_c: String,
    /// A random tripod support per push.
    pub tripod: bool,
    /// Standard deviation of the orientation (degrees).
    pub theta_jitter_deg: f64,
    /// Standard deviation of d (units of a).
    pub d_jitter: f64,
}

/// A default classifier that could not be trained here, and why.
#[derive(Debug, Serialize, Clone)]
pub struct Skipped {
    /// The classifier's name.
    pub classifier: String,
    /// Why it could not be trained.
    pub reason: String,
}

/// A classifier that could not be trained at one sweep point, and why.
#[derive(Debug, Serialize, Clone)]
pub struct Untrained {
    /// The classifier's name.
    pub classifier: String,
    /// The noise factor of the sweep point.
    pub noise_factor: f64,
    /// Why it could not be trained there.
    pub reason: String,
}

/// The JSON document of `pinfeed sense --json` (and `sense.json`).
#[derive(Debug, Serialize)]
pub struct SenseReport {
    /// The command that regenerates this report.
    pub command: String,
    /// The part spec, as given.
    pub part: String,
    /// Metres per part unit.
    pub scale_m_per_unit: f64,
    /// The part's circumradius a (m).
    pub a_m: f64,
    /// Part mass (kg).
    pub mass_kg: f64,
    /// Belt speed (m/s).
    pub belt_speed_m_s: f64,
    /// Lateral offset of the pin (units of a).
    pub d: f64,
    /// Pin radius (m).
    pub pin_radius_m: f64,
    /// Pin–part friction μc (nominal).
    pub mu_c: f64,
    /// Part–belt friction μs.
    pub mu_s: f64,
    /// The contact model's fidelity name.
    pub model: String,
    /// The hypotheses told apart.
    pub hypotheses: Hypotheses,
    /// The sensor at noise factor 1.
    pub sensor: SensorSettings,
    /// The declared uncertainty.
    pub uncertainty: UncertaintyReport,
    /// Templates built per hypothesis (asked for).
    pub templates_per_hypothesis: usize,
    /// Trials: simulated pushes, each read at every sensor point.
    pub trials: usize,
    /// How each trial's hypothesis is chosen.
    pub truth: TruthDraw,
    /// Seed of the random streams.
    pub seed: u64,
    /// The noise factors of the sweep.
    pub noise_factors: Vec<f64>,
    /// The classifiers reported (those asked for, less the skipped).
    pub classifiers: Vec<String>,
    /// Default classifiers that could be trained nowhere, left out.
    pub skipped: Vec<Skipped>,
    /// Sweep points where a classifier could not be trained (it decided "unknown" there).
    pub untrained: Vec<Untrained>,
    /// The scores of every classifier at every noise factor.
    pub evaluation: Evaluation,
    /// The placement search's result, when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub placement: Option<Placement>,
}

/// A classifier that decides nothing: stands in for a default classifier that could not be trained
/// (its cells are dropped from the report and the reason listed).
pub struct Placeholder;
impl Classifier for Placeholder {
    fn name(&self) -> &'static str {
        "skipped"
    }
    fn classify(&self, _: &crate::sensing::Reading) -> classify::Classification {
        classify::Classification::unknown()
    }
}

/// The noise sweep evaluated: the templates, the cells of the classifiers kept, and the ones
/// skipped (trainable nowhere) or untrained at some sweep points.
pub struct Evaluated {
    /// The templates of every hypothesis.
    pub templates: TemplateSet,
    /// The scores of the classifiers kept.
    pub evaluation: Evaluation,
    /// The classifiers reported (the ones asked for less the skipped).
    pub classifiers: Vec<String>,
    /// Default classifiers trainable nowhere, left out.
    pub skipped: Vec<Skipped>,
    /// Classifiers that could not be trained at some sweep points.
    pub untrained: Vec<Untrained>,
}

/// The noise sweep as evaluated, with the classifiers that could not be trained at some points.
pub struct Sweep {
    /// The templates of every hypothesis.
    pub templates: TemplateSet,
    /// The scores of every classifier at every sweep point.
    pub evaluation: Evaluation,
    /// (classifier, sensor point, reason) per failed training.
    pub failures: Vec<(String, SensorSettings, String)>,
    /// The sweep points (noise factor, sensor, classifiers).
    pub points: Vec<SensorPoint>,
}

impl Sweep {
    /// The policy for untrainable classifiers: one that can be trained nowhere is an error when
    /// asked for by name (`explicit`) and skipped otherwise (its cells dropped); one that fails
    /// at some sweep points only is listed as untrained there.
    pub fn policy(self, checked: &Checked) -> Result<Evaluated, SenseError> {
        let Sweep {
            templates,
            mut evaluation,
            failures,
            points,
        } = self;
        let mut skipped: Vec<Skipped> = Vec::new();
        let mut untrained: Vec<Untrained> = Vec::new();
        for name in &checked.classifiers {
            let fails: Vec<_> = failures.iter().filter(|f| &f.0 == name).collect();
            if fails.len() == points.len() {
                let reason = fails.first().map_or(String::new(), |f| f.2.clone());
                if checked.explicit {
                    return Err(SenseError::Untrainable(reason));
                }
                skipped.push(Skipped {
                    classifier: name.clone(),
                    reason,
                });
            } else {
                for f in fails {
                    let factor = points
                        .iter()
                        .find(|pt| pt.sensor == f.1)
                        .map_or(f64::NAN, |pt| pt.noise_factor);
                    untrained.push(Untrained {
                        classifier: name.clone(),
                        noise_factor: factor,
                        reason: f.2.clone(),
                    });
                }
            }
        }
        evaluation
            .cells
            .retain(|c| !skipped.iter().any(|s| s.classifier == c.classifier));
        let classifiers: Vec<String> = checked
            .classifiers
            .iter()
            .filter(|c| !skipped.iter().any(|s| &s.classifier == *c))
            .cloned()
            .collect();
        Ok(Evaluated {
            templates,
            evaluation,
            classifiers,
            skipped,
            untrained,
        })
    }
}

impl Checked {
    /// The evaluation settings of a request.
    pub fn config(&self, r: &Request) -> Config {
        Config {
            templates_per_hypothesis: r.templates,
            trials: r.trials,
            truth: self.truth,
            seed: r.seed,
            options: ClassifierOptions {
                reject_below: r.reject_below,
            },
        }
    }

    /// The push problem of the request.
    pub fn problem(&self) -> Problem<'_> {
        Problem {
            setup: &self.setup,
            model: &self.model,
            hypotheses: &self.hyps,
            uncertainty: &self.unc,
        }
    }

    /// Evaluate every classifier over the noise sweep (`progress` counts trials). A classifier
    /// that cannot be trained at a sweep point (e.g. its contact detector's threshold, raised with
    /// the noise, exceeds every template's force) decides "unknown" there and is recorded;
    /// [`Sweep::policy`] decides what to report.
    pub fn evaluate(
        &self,
        r: &Request,
        progress: crate::progress::Report,
    ) -> Result<Sweep, SenseError> {
        let config = self.config(r);
        let options = config.options;
        let failures: Mutex<Vec<(String, SensorSettings, String)>> = Mutex::new(Vec::new());
        let factory = |name: &str, t: &TemplateSet, s: &SensorSettings| match classify::build(
            name, t, s, &options,
        ) {
            Ok(c) => Ok(c),
            Err(e) => {
                failures
                    .lock()
                    .expect("lock")
                    .push((name.to_string(), *s, e.to_string()));
                Ok(Box::new(Placeholder) as Box<dyn Classifier>)
            }
        };
        let points = noise_sweep(&self.sensor, &r.noise, &self.classifiers);
        let (templates, evaluation) =
            evaluate_observed(&self.problem(), &points, &config, &factory, progress)
                .map_err(SenseError::Evaluate)?;
        Ok(Sweep {
            templates,
            evaluation,
            failures: failures.into_inner().expect("lock"),
            points,
        })
    }

    /// Whether a vertex/edge evaluation never saw one of its hypotheses because the pin is a
    /// point (which first meets the part on an edge almost always).
    pub fn point_pin_misses_vertices(&self, e: &Evaluation) -> bool {
        matches!(self.hyps, Hypotheses::VertexEdge { .. })
            && e.truth_counts.contains(&0)
            && self.setup.pin_radius == 0.0
    }

    /// The placement search: d over the request's grid, every sensor kind at nominal noise with
    /// its default classifiers (one that cannot be trained decides "unknown"); `progress` hears
    /// each offset's rows.
    pub fn place(
        &self,
        r: &Request,
        progress: &mut dyn FnMut(f64, &[placement::Row]),
    ) -> Result<Placement, SenseError> {
        let config = self.config(r);
        let pts: Vec<SensorPoint> = [SensorKind::Ft, SensorKind::Timing]
            .iter()
            .map(|&k| SensorPoint {
                noise_factor: 1.0,
                sensor: SensorSettings {
                    kind: k,
                    ..self.sensor
                },
                classifiers: applicable(k, &self.hyps),
            })
            .collect();
        let lenient = |name: &str, t: &TemplateSet, s: &SensorSettings| {
            classify::build(name, t, s, &config.options)
                .or_else(|_| Ok(Box::new(Placeholder) as Box<dyn Classifier>))
        };
        let lenient: &Factory = &lenient;
        placement::search_with(
            &self.problem(),
            &r.placement_d,
            &pts,
            &config,
            lenient,
            progress,
        )
        .map_err(SenseError::Evaluate)
    }

    /// The report of the request, its evaluation and placement; `command` regenerates it.
    pub fn report(
        &self,
        r: &Request,
        command: String,
        e: Evaluated,
        placement: Option<Placement>,
    ) -> (SenseReport, TemplateSet) {
        let report = SenseReport {
            command,
            part: self.part_name.clone(),
            scale_m_per_unit: r.scale,
            a_m: self.setup.polygon.radius(),
            mass_kg: r.mass,
            belt_speed_m_s: r.belt_speed,
            d: r.d,
            pin_radius_m: self.setup.pin_radius,
            mu_c: r.mu_c,
            mu_s: r.mu_s,
            model: self.setup.fidelity.name().to_string(),
            hypotheses: self.hyps.clone(),
            sensor: self.sensor,
            uncertainty: UncertaintyReport {
                mu_c: self.unc.mu_c.describe(),
                tripod: self.unc.tripod,
                theta_jitter_deg: self.unc.theta_sd_deg,
                d_jitter: self.unc.d_sd,
            },
            templates_per_hypothesis: r.templates,
            trials: r.trials,
            truth: self.truth,
            seed: r.seed,
            noise_factors: r.noise.clone(),
            classifiers: e.classifiers,
            skipped: e.skipped,
            untrained: e.untrained,
            evaluation: e.evaluation,
            placement,
        };
        (report, e.templates)
    }
}
