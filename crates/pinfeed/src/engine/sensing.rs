//! Sensor pins in the line (docs/physics.md#sensing; issue "Sensor pins"): a push against a pin with a sensor is
//! computed once with a knot recorder, its clean signal read through the sensor's noise model on
//! a stream of its own, and classified with the sensor's trained classifier; the decision joins the
//! part's record and the sensor's statistics.
//!
//! Truth: the simulator knows which hypothesis each part really is — for orientation hypotheses the
//! one nearest (on the circle) to the part's orientation when the pin touches it, for vertex/edge
//! the contact model's own first-contact feature — so the summary gives each sensor's confusion
//! matrix against it. Parts that pass the sensor pin without touching it are counted apart.
//!
//! Randomness: the reading of part i by obstacle j draws from stream (seed, 2⁶² | i·2¹⁶ | j), apart
//! from every part's own stream (seed, i), so sensing never shifts what a part draws, and the run
//! stays a pure function of (scene, seed).
//!
//! A scene with no sensor pin runs none of this: its `work.sensor_readings`, `work.signal_knots` and
//! `work.classifications` stay 0 (a test checks it).

use crate::mechanics::{ContactOutcome, TraceSample};
use crate::random::stream;
use crate::scenario::SensorPin;
use crate::sensing::classify::{Classification, Decision};
use crate::sensing::confusion::Confusion;
use crate::sensing::reading::read;
use crate::sensing::signal::{ContactSignal, SignalScale};
use crate::sensing::templates::{vertex_edge_class, Hypotheses};
use serde::Serialize;

/// First stream index of sensor readings (parts use 0, 1, 2, …).
const SENSOR_STREAMS: u64 = 1 << 62;

/// The stream of the reading of part `part` by obstacle `obstacle`.
pub fn reading_stream(part: u64, obstacle: usize) -> u64 {
    SENSOR_STREAMS | (part << 16) | (obstacle as u64 & 0xffff)
}

/// One sensed pass.
#[derive(Debug, Clone, PartialEq)]
pub struct SensedPass {
    /// The hypothesis the part really is (None: no hypothesis applies, e.g. no first feature).
    pub truth: Option<usize>,
    /// What the sensor's classifier decided, with its posterior.
    pub classification: Classification,
    /// Knots the signal was built from.
    pub knots: usize,
    /// The reading itself (None: nothing detectable), for the online controller's belief.
    pub reading: Option<crate::sensing::reading::Reading>,
}

/// Reads and classifies one pass of part `part` (pose θ `theta` rad just before contact) against
/// sensor pin `obstacle`.
#[allow(clippy::too_many_arguments)]
pub fn sense_pass(
    sensor: &SensorPin,
    outcome: &ContactOutcome,
    knots: &[TraceSample],
    scale: &SignalScale,
    theta: f64,
    seed: u64,
    part: u64,
    obstacle: usize,
) -> SensedPass {
    let signal = ContactSignal::new(outcome, knots, scale);
    let mut rng = stream(seed, reading_stream(part, obstacle));
    let reading = read(&signal, &sensor.settings, &mut rng);
    let classification = match &reading {
        Some(r) => sensor.classifier.classify(r),
        None => Classification::unknown(),
    };
    let truth = match &sensor.hypotheses {
        Hypotheses::Orientations { degrees, .. } => nearest(degrees, theta.to_degrees()),
        Hypotheses::VertexEdge { .. } => signal.first_feature.map(vertex_edge_class),
    };
    SensedPass {
        truth,
        classification,
        knots: knots.len(),
        reading,
    }
}

/// Index of the orientation nearest `deg` on the circle.
pub fn nearest(degrees: &[f64], deg: f64) -> Option<usize> {
    let dist = |a: f64| {
        let d = (a - deg).rem_euclid(360.0);
        d.min(360.0 - d)
    };
    degrees
        .iter()
        .enumerate()
        .min_by(|(_, a), (_, b)| dist(**a).total_cmp(&dist(**b)))
        .map(|(i, _)| i)
}

/// A sensor's statistics over a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorStats {
    /// The sensor pin's name.
    pub name: String,
    /// Name of the sensor's classifier.
    pub classifier: String,
    /// Passes read.
    pub readings: u64,
    /// Parts that went past the pin without touching it.
    pub untouched: u64,
    /// Readings whose truth matches no hypothesis (a vertex/edge pass with no first feature).
    pub unmatched: u64,
    /// Decisions against the truth, over the readings that have one.
    pub confusion: Confusion,
}

impl SensorStats {
    /// Empty statistics for sensor pin `name`.
    pub fn new(name: &str, sensor: &SensorPin) -> SensorStats {
        SensorStats {
            name: name.to_string(),
            classifier: sensor.classifier_name.clone(),
            readings: 0,
            untouched: 0,
            unmatched: 0,
            confusion: Confusion::new(&sensor.labels),
        }
    }

    /// Counts one sensed pass.
    pub fn add(&mut self, p: &SensedPass) {
        self.readings += 1;
        match p.truth.filter(|&t| t < self.confusion.k()) {
            Some(t) => self.confusion.add(t, p.classification.decision),
            None => self.unmatched += 1,
        }
    }
}

/// One sensor pin's decision on a part, as the part's record keeps it (written `pin=label
/// (posterior)`, `pin=label` or `pin=unknown`; records join several with `; `).
#[derive(Debug, Clone, PartialEq)]
pub struct SensedDecision {
    /// The sensor pin's index among the scene's obstacles.
    pub obstacle: usize,
    /// The sensor pin's name.
    pub sensor: String,
    /// The decided hypothesis's label; None: no decision (`unknown`).
    pub label: Option<String>,
    /// The classifier's posterior of the decided hypothesis, when it gives one.
    pub posterior: Option<f64>,
}

impl SensedDecision {
    /// Sensor pin `obstacle` (named `sensor`, with hypothesis `labels`) decided `c`.
    pub fn of(obstacle: usize, sensor: &str, labels: &[String], c: &Classification) -> Self {
        let (label, posterior) = match c.decision {
            Decision::Hypothesis(h) => {
                (Some(labels[h].clone()), c.posterior.as_ref().map(|p| p[h]))
            }
            Decision::Unknown => (None, None),
        };
        SensedDecision {
            obstacle,
            sensor: sensor.to_string(),
            label,
            posterior,
        }
    }

    /// The decision alone: `0° (0.998)`, `0°` without a posterior, `unknown` without a decision.
    pub fn decision_text(&self) -> String {
        match (&self.label, self.posterior) {
            (Some(l), Some(p)) => format!("{l} ({p:.3})"),
            (Some(l), None) => l.clone(),
            (None, _) => "unknown".into(),
        }
    }
}

impl std::fmt::Display for SensedDecision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}={}", self.sensor, self.decision_text())
    }
}

/// A part record's decisions as one text field (`probe=0° (0.998); b=unknown`), as the per-part
/// CSV and JSON write them.
pub fn serialize_sensed<S: serde::Serializer>(
    decisions: &[SensedDecision],
    s: S,
) -> Result<S::Ok, S::Error> {
    let text = decisions
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join("; ");
    s.serialize_str(&text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_decision_is_written_with_its_posterior_or_as_unknown() {
        let labels = vec!["0°".to_string(), "135°".to_string()];
        let decided = Classification {
            decision: Decision::Hypothesis(1),
            posterior: Some(vec![0.0025, 0.9975]),
        };
        let d = SensedDecision::of(3, "probe", &labels, &decided);
        assert_eq!(d.to_string(), "probe=135° (0.998)");
        let bare = Classification {
            decision: Decision::Hypothesis(0),
            posterior: None,
        };
        assert_eq!(
            SensedDecision::of(3, "probe", &labels, &bare).to_string(),
            "probe=0°"
        );
        let none = Classification {
            decision: Decision::Unknown,
            posterior: Some(vec![0.5, 0.5]),
        };
        let u = SensedDecision::of(3, "b", &labels, &none);
        assert_eq!((u.label.as_deref(), u.posterior), (None, None));
        assert_eq!(u.to_string(), "b=unknown");
    }

    #[test]
    fn nearest_wraps_round_the_circle() {
        let d = [0.0, 135.0, 225.0];
        assert_eq!(nearest(&d, 355.0), Some(0));
        assert_eq!(nearest(&d, 170.0), Some(1));
        assert_eq!(nearest(&d, 190.0), Some(2));
        assert_eq!(nearest(&d, -20.0), Some(0));
    }

    #[test]
    fn reading_streams_are_distinct_from_part_streams() {
        assert!(reading_stream(0, 0) >= SENSOR_STREAMS);
        assert_ne!(reading_stream(1, 0), reading_stream(0, 1));
        assert_ne!(reading_stream(3, 2), reading_stream(2, 3));
    }
}
