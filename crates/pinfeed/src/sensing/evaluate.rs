//! What a sensor can tell: classifiers scored on simulated trials, with confusion matrices,
//! accuracy (95% Wilson interval) and the mutual information between state and decision.
//!
//! An evaluation fixes a push ([`Problem`]: setup, part model, hypotheses, declared uncertainty),
//! builds each hypothesis's template ensemble once ([`build_templates`], streams
//! [`super::templates::template_stream`]), and trains every requested classifier once per sensor
//! point (a [`SensorPoint`]: the sensor of one noise level or kind, and the classifiers to score on
//! it). Each trial i then
//! 1. picks its hypothesis — cycling (`i mod k`) or uniformly from stream `(seed, TRUTH_STREAMS + i)`;
//! 2. draws its true push with [`draw_pass`] from stream `(seed, TRIAL_STREAMS + i)` (never a
//!    template's stream: a classifier is not scored on its own templates);
//! 3. is read by every sensor point from stream `(seed, READING_STREAMS + i)`, the same stream at
//!    every point (common random numbers: the noise at factor 2 is the noise at factor 1 doubled,
//!    so accuracy against noise is not blurred by independent draws), and each reading is decided by
//!    that point's classifiers.
//!
//! The truth of a trial is its hypothesis; for [`Hypotheses::VertexEdge`] it is the contact model's
//! own first-contact feature class ([`vertex_edge_class`]) of the true push, and a push that never
//! touches is left unscored (counted in [`Evaluation::unscored`]). An F/T reading of a push that
//! never touched decides "unknown".
//!
//! Determinism: trials run in parallel (rayon) and their confusion counts are summed — integer
//! addition, so the result is the same bytes on any number of threads.
//!
//! Mutual information is the plug-in estimate from the confusion matrix, "unknown" a decision of
//! its own: I = Σ p(s,d) log₂ p(s,d)/(p(s)p(d)) in bits. It is biased upwards on few trials (by about
//! (k−1)(m−1)/(2n ln 2) bits for k states, m decisions, n trials), which the report states.

use super::classify::{self, Classifier, ClassifierOptions, Decision};
pub use super::confusion::Confusion;
use super::reading::read;
use super::settings::{SensorKind, SensorSettings};
use super::templates::{
    build_templates, draw_pass, vertex_edge_class, Hypotheses, PushSetup, TemplateSet, Uncertainty,
    TRIAL_STREAMS,
};
use crate::mechanics::PartModel;
use crate::random::stream;
use rand::RngExt;
use rayon::prelude::*;
use serde::Serialize;

/// First stream index of the trials' readings.
pub const READING_STREAMS: u64 = 1 << 41;
/// First stream index of the trials' uniform draws of their hypothesis.
pub const TRUTH_STREAMS: u64 = 1 << 42;
/// Most trials in one evaluation (time and the stream layout: trial streams stay below 2⁴¹).
pub const MAX_TRIALS: usize = 1_000_000;
/// Most templates per hypothesis.
pub const MAX_TEMPLATES: usize = 4096;

/// How each trial's hypothesis is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TruthDraw {
    /// Trial i gets hypothesis i mod k (equal counts, ±1).
    Cycle,
    /// Uniformly at random, from the trial's own stream.
    Uniform,
}

/// The push being sensed.
#[derive(Debug, Clone, Copy)]
pub struct Problem<'a> {
    /// The push.
    pub setup: &'a PushSetup,
    /// The part's model under uniform support (tripod supports are drawn per push when declared).
    pub model: &'a PartModel,
    /// The hypotheses to tell apart.
    pub hypotheses: &'a Hypotheses,
    /// The declared uncertainty of μc, the support and the pose.
    pub uncertainty: &'a Uncertainty,
}

/// One sensor setting to score and the classifiers to score on it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorPoint {
    /// The factor applied to the base sensor's noise ([`SensorSettings::with_noise_factor`]).
    pub noise_factor: f64,
    /// The sensor at this noise factor.
    pub sensor: SensorSettings,
    /// Names of the classifiers scored at this point.
    pub classifiers: Vec<String>,
}

/// Evaluation settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    /// Templates built per hypothesis (1 to [`MAX_TEMPLATES`]).
    pub templates_per_hypothesis: usize,
    /// Trials: simulated pushes, each read at every sensor point and classified by every
    /// classifier there (1 to [`MAX_TRIALS`]).
    pub trials: usize,
    /// How each trial's hypothesis is chosen.
    pub truth: TruthDraw,
    /// Seed of the templates' and trials' streams; the same seed gives the same evaluation.
    pub seed: u64,
    /// Options of the classifiers.
    pub options: ClassifierOptions,
}

/// One classifier at one sensor point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cell {
    /// The classifier's name.
    pub classifier: String,
    /// The sensor kind's name (`ft`, `timing`).
    pub sensor: &'static str,
    /// The factor on the sensor's noise.
    pub noise_factor: f64,
    /// Trials counted.
    pub trials: u64,
    /// Trials decided correctly.
    pub correct: u64,
    /// Trials decided "unknown".
    pub unknown: u64,
    /// `correct / trials` ("unknown" counts as wrong; 0 without trials).
    pub accuracy: f64,
    /// 95% Wilson interval of the accuracy, [low, high].
    pub accuracy_ci95: [f64; 2],
    /// Plug-in mutual information between true state and decision (bits).
    pub mutual_information_bits: f64,
    /// The confusion matrix.
    pub confusion: Confusion,
}

impl Cell {
    fn new(classifier: &str, point: &SensorPoint, confusion: Confusion) -> Cell {
        Cell {
            classifier: classifier.to_string(),
            sensor: point.sensor.kind.name(),
            noise_factor: point.noise_factor,
            trials: confusion.total(),
            correct: confusion.correct(),
            unknown: confusion.unknown(),
            accuracy: confusion.accuracy(),
            accuracy_ci95: confusion.accuracy_ci95(),
            mutual_information_bits: confusion.mutual_information_bits(),
            confusion,
        }
    }
}

/// The scores of every classifier at every sensor point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Evaluation {
    /// The hypotheses' labels.
    pub labels: Vec<String>,
    /// Templates built per hypothesis (vertex/edge: a class that never occurred has none).
    pub template_counts: Vec<usize>,
    /// Trials: simulated pushes, each read at every sensor point.
    pub trials: usize,
    /// Trials with no truth (vertex/edge: the pin never touched).
    pub unscored: u64,
    /// Scored trials per true hypothesis.
    pub truth_counts: Vec<u64>,
    /// H(state) of the scored trials (bits): the ceiling of every mutual information.
    pub state_entropy_bits: f64,
    /// Chance accuracy: the share of the most frequent true hypothesis.
    pub chance_accuracy: f64,
    /// One cell per sensor point and classifier, points in order.
    pub cells: Vec<Cell>,
}

impl Evaluation {
    /// The cells of one classifier, in sensor-point order.
    pub fn of(&self, classifier: &str) -> impl Iterator<Item = &Cell> {
        let name = classifier.to_string();
        self.cells.iter().filter(move |c| c.classifier == name)
    }
}

/// Why an evaluation could not be run ([`evaluate_with`], [`trial_pass`]); a failed step's
/// message is printed as it is.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EvaluateError {
    /// No hypotheses to draw a trial for.
    #[error("no hypotheses")]
    NoHypotheses,
    /// A trial count out of range.
    #[error("trials must lie in [1, {MAX_TRIALS}], got {trials}")]
    Trials {
        /// The count given.
        trials: usize,
    },
    /// A template count out of range.
    #[error("templates per hypothesis must lie in [1, {MAX_TEMPLATES}], got {templates}")]
    Templates {
        /// The count given.
        templates: usize,
    },
    /// A template or trial pass could not be drawn.
    #[error("{0}")]
    Pass(super::templates::PassError),
    /// A classifier could not be built by the factory.
    #[error("{0}")]
    Classifier(classify::BuildError),
}

/// A classifier factory: [`classify::build`] or a test double.
pub type Factory<'f> = dyn Fn(&str, &TemplateSet, &SensorSettings) -> Result<Box<dyn Classifier>, classify::BuildError>
    + Sync
    + 'f;

/// The classifiers that apply to a sensor kind and hypotheses (the default list): an F/T sensor
/// feeds the thesis's method, the matched filter and the contact duration it shows; a timing sensor
/// only the durations; vertex/edge adds the thesis's zero-crossing rule.
pub fn applicable(kind: SensorKind, hyps: &Hypotheses) -> Vec<String> {
    let names: &[&str] = match (kind, hyps) {
        (SensorKind::Timing, _) => &["timing"],
        (SensorKind::Ft, Hypotheses::Orientations { .. }) => {
            &["sign-matrix", "likelihood", "timing"]
        }
        (SensorKind::Ft, Hypotheses::VertexEdge { .. }) => &["zero-crossings", "likelihood"],
    };
    names.iter().map(|s| s.to_string()).collect()
}

/// The sensor points of a noise sweep: `base` with each factor, scored by `classifiers`.
pub fn noise_sweep(
    base: &SensorSettings,
    factors: &[f64],
    classifiers: &[String],
) -> Vec<SensorPoint> {
    factors
        .iter()
        .map(|&f| SensorPoint {
            noise_factor: f,
            sensor: base.with_noise_factor(f),
            classifiers: classifiers.to_vec(),
        })
        .collect()
}

/// The hypothesis (or, for vertex/edge, the orientation index) trial `i` is drawn for.
fn trial_choice(i: usize, count: usize, truth: TruthDraw, seed: u64) -> usize {
    match truth {
        TruthDraw::Cycle => i % count,
        TruthDraw::Uniform => {
            let mut rng = stream(seed, TRUTH_STREAMS + i as u64);
            rng.random_range(0..count)
        }
    }
}

/// The true push of trial `i`: its truth (None: unscored) and its pass.
pub fn trial_pass(
    problem: &Problem,
    config: &Config,
    i: usize,
) -> Result<(Option<usize>, super::templates::Pass), EvaluateError> {
    let (degrees, vertex_edge) = match problem.hypotheses {
        Hypotheses::Orientations { degrees, .. } => (degrees, false),
        Hypotheses::VertexEdge { degrees } => (degrees, true),
    };
    if degrees.is_empty() {
        return Err(EvaluateError::NoHypotheses);
    }
    let j = trial_choice(i, degrees.len(), config.truth, config.seed);
    let pass = draw_pass(
        problem.setup,
        problem.model,
        problem.uncertainty,
        degrees[j],
        config.seed,
        TRIAL_STREAMS + i as u64,
    )
    .map_err(EvaluateError::Pass)?;
    let truth = if vertex_edge {
        pass.signal.first_feature.map(vertex_edge_class)
    } else {
        Some(j)
    };
    Ok((truth, pass))
}

/// Builds the templates, trains the classifiers with `factory`, runs the trials and scores them.
/// Returns the templates too (for figures).
pub fn evaluate_with(
    problem: &Problem,
    points: &[SensorPoint],
    config: &Config,
    factory: &Factory,
) -> Result<(TemplateSet, Evaluation), EvaluateError> {
    evaluate_observed(problem, points, config, factory, &crate::progress::silent)
}

/// [`evaluate_with`], telling `progress` the trials run of all (none while the templates are
/// built).
pub fn evaluate_observed(
    problem: &Problem,
    points: &[SensorPoint],
    config: &Config,
    factory: &Factory,
    progress: crate::progress::Report,
) -> Result<(TemplateSet, Evaluation), EvaluateError> {
    if config.trials == 0 || config.trials > MAX_TRIALS {
        return Err(EvaluateError::Trials {
            trials: config.trials,
        });
    }
    if config.templates_per_hypothesis == 0 || config.templates_per_hypothesis > MAX_TEMPLATES {
        return Err(EvaluateError::Templates {
            templates: config.templates_per_hypothesis,
        });
    }
    let tally = crate::progress::Tally::new(config.trials as u64, progress);
    let templates = build_templates(
        problem.setup,
        problem.model,
        problem.hypotheses,
        problem.uncertainty,
        config.templates_per_hypothesis,
        config.seed,
    )
    .map_err(EvaluateError::Pass)?;
    let labels = templates.labels.clone();
    let k = labels.len();
    // Trained classifiers, per point.
    let mut trained: Vec<Vec<Box<dyn Classifier>>> = Vec::with_capacity(points.len());
    for p in points {
        let mut v = Vec::with_capacity(p.classifiers.len());
        for name in &p.classifiers {
            v.push(factory(name, &templates, &p.sensor).map_err(EvaluateError::Classifier)?);
        }
        trained.push(v);
    }
    let empty = || {
        (
            points
                .iter()
                .map(|p| vec![Confusion::new(&labels); p.classifiers.len()])
                .collect::<Vec<_>>(),
            0u64,
        )
    };
    type Acc = (Vec<Vec<Confusion>>, u64);
    let merge = |mut a: Acc, b: Acc| -> Acc {
        for (x, y) in a.0.iter_mut().zip(&b.0) {
            for (cx, cy) in x.iter_mut().zip(y) {
                cx.merge(cy);
            }
        }
        a.1 += b.1;
        a
    };
    let (matrices, unscored) = (0..config.trials)
        .into_par_iter()
        .map(|i| -> Result<Acc, EvaluateError> {
            let mut acc = empty();
            let (truth, pass) = trial_pass(problem, config, i)?;
            tally.add(1);
            let Some(truth) = truth else {
                acc.1 = 1;
                return Ok(acc);
            };
            for (pi, p) in points.iter().enumerate() {
                let mut rng = stream(config.seed, READING_STREAMS + i as u64);
                let reading = read(&pass.signal, &p.sensor, &mut rng);
                for (ci, c) in trained[pi].iter().enumerate() {
                    let decision = match &reading {
                        Some(r) => c.classify(r).decision,
                        None => Decision::Unknown,
                    };
                    acc.0[pi][ci].add(truth, decision);
                }
            }
            Ok(acc)
        })
        .try_reduce(empty, |a, b| Ok(merge(a, b)))?;
    let mut cells = Vec::new();
    for (pi, p) in points.iter().enumerate() {
        for (ci, name) in p.classifiers.iter().enumerate() {
            cells.push(Cell::new(name, p, matrices[pi][ci].clone()));
        }
    }
    let reference = matrices
        .iter()
        .flatten()
        .next()
        .cloned()
        .unwrap_or_else(|| Confusion::new(&labels));
    let truth_counts: Vec<u64> = (0..k).map(|h| reference.row_total(h)).collect();
    let scored: u64 = truth_counts.iter().sum();
    let chance_accuracy = if scored == 0 {
        0.0
    } else {
        truth_counts.iter().copied().max().unwrap_or(0) as f64 / scored as f64
    };
    let evaluation = Evaluation {
        labels,
        template_counts: templates.members.iter().map(Vec::len).collect(),
        trials: config.trials,
        unscored,
        state_entropy_bits: reference.state_entropy_bits(),
        truth_counts,
        chance_accuracy,
        cells,
    };
    Ok((templates, evaluation))
}

/// [`evaluate_with`] with the real classifiers ([`classify::build`]).
pub fn evaluate(
    problem: &Problem,
    points: &[SensorPoint],
    config: &Config,
) -> Result<(TemplateSet, Evaluation), EvaluateError> {
    let options = config.options;
    let factory = move |name: &str, t: &TemplateSet, s: &SensorSettings| {
        classify::build(name, t, s, &options)
    };
    evaluate_with(problem, points, config, &factory)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(k: usize) -> Vec<String> {
        (0..k).map(|h| format!("h{h}")).collect()
    }

    #[test]
    fn information_of_perfect_and_blind_decisions() {
        let mut perfect = Confusion::new(&labels(4));
        let mut blind = Confusion::new(&labels(4));
        for i in 0..400 {
            perfect.add(i % 4, Decision::Hypothesis(i % 4));
            blind.add(i % 4, Decision::Hypothesis(0));
        }
        assert!((perfect.mutual_information_bits() - 2.0).abs() < 1e-12);
        assert_eq!(blind.mutual_information_bits(), 0.0);
        assert_eq!(perfect.accuracy(), 1.0);
        assert_eq!(blind.accuracy(), 0.25);
        // An out-of-range decision counts as unknown.
        blind.add(1, Decision::Hypothesis(9));
        assert_eq!(blind.unknown(), 1);
    }
}
