//! `[obstacles.sensor]` of a `sensor_pin`: validation of the sensor's settings and hypotheses
//! when the file is read (into a [`SensorDraft`]), and training of its classifier on simulated
//! templates when the scene is built ([`super::SceneDraft::build`];
//! docs/scenario-format.md#sensor-pins; docs/physics.md#sensing).
//!
//! The templates model what the sensor expects: the part reaching the pin as fed — orientation
//! one of the hypotheses (with the feed's orientation jitter), lateral offset drawn from the
//! feed's lateral distribution (as a spread of d about the pin's offset from the feed's mean),
//! the pin's μc, the scene's support model (random tripods when `support = "tripod"`) and fidelity.
//! A sensor placed after other obstacles sees parts those obstacles have moved; the templates do not
//! know that, and the summary's confusion matrix shows what it costs. Templates are drawn from the
//! scene's seed on streams of their own, so the same file always trains the same classifier.

use super::checker::Checker;
use super::error::KeyLocation;
use super::raw::{RawHypotheses, RawSensor};
use super::scene::{
    Feed, Lateral, Obstacle, Orientation, PartSpec, PinObstacle, Scene, SensorPin, SupportKind,
};
use super::ScenarioError;
use crate::random::distribution::Distribution;
use crate::sensing::classify::{self, ClassifierOptions};
use crate::sensing::templates::{build_templates, Hypotheses, PushSetup, Uncertainty};
use crate::sensing::{SensorKind, SensorSettings};

type R<T> = Result<T, ScenarioError>;

/// Templates per hypothesis: default and the most a file may ask for (training time is bounded).
const DEFAULT_TEMPLATES: u64 = 32;
const MAX_TEMPLATES: u64 = 1024;

/// A sensor's own settings, validated with its obstacle (its hypotheses are resolved against the
/// part and the feed by [`draft`], once those are compiled).
#[derive(Debug, Clone)]
pub(super) struct ValidSensor {
    pub settings: SensorSettings,
    pub classifier: String,
    pub hypotheses: Option<Vec<f64>>,
    pub vertex_edge: bool,
    pub templates: usize,
    pub reject_below: f64,
}

/// A sensor pin's settings and hypotheses, validated and still to be trained: what a
/// [`super::SceneDraft`] holds for each sensor pin, and [`super::SceneDraft::build`] trains into
/// the pin's [`SensorPin`].
#[derive(Debug, Clone, PartialEq)]
pub struct SensorDraft {
    /// The sensor's pin: its index among the scene's obstacles.
    pub obstacle: usize,
    /// The sensor's pin: its name.
    pub name: String,
    /// Sample rate, noise, bias, filtering and quantisation of the sensor.
    pub settings: SensorSettings,
    /// Classifier name (one of [`crate::sensing::classify::NAMES`]).
    pub classifier: String,
    /// The states the classifier is to tell apart; their labels are the ones rules name.
    pub hypotheses: Hypotheses,
    /// Simulated templates per hypothesis to train on.
    pub templates: usize,
    /// Decide "unknown" below this posterior (in [0, 1]; 0 never rejects).
    pub reject_below: f64,
    /// Where training errors are located in the file.
    at: TrainingKeys,
}

/// The keys a sensor's training errors name, located in the file when it was read.
#[derive(Debug, Clone, PartialEq)]
struct TrainingKeys {
    sensor: KeyLocation,
    hypotheses: KeyLocation,
    classifier: KeyLocation,
}

/// Validates `[obstacles.<i>.sensor]`.
pub(super) fn validate(c: &Checker, i: usize, raw: &RawSensor) -> R<ValidSensor> {
    let path = |k: &str| format!("obstacles[{i}].sensor.{k}");
    let d = SensorSettings::default();
    let kind = raw.kind.unwrap_or_default();
    let settings = SensorSettings {
        kind,
        rate: raw.rate.unwrap_or(d.rate),
        height: raw.height.unwrap_or(d.height),
        noise_force: raw.noise_force.unwrap_or(d.noise_force),
        noise_torque: raw.noise_torque.unwrap_or(d.noise_torque),
        bias_force: raw.bias_force.unwrap_or(d.bias_force),
        bias_torque: raw.bias_torque.unwrap_or(d.bias_torque),
        drift_force: raw.drift_force.unwrap_or(d.drift_force),
        drift_torque: raw.drift_torque.unwrap_or(d.drift_torque),
        resolution_force: raw.resolution_force.unwrap_or(d.resolution_force),
        resolution_force_z: raw.resolution_force_z.unwrap_or(d.resolution_force_z),
        resolution_torque: raw.resolution_torque.unwrap_or(d.resolution_torque),
        lowpass: raw.lowpass,
        threshold: raw.threshold.unwrap_or(d.threshold),
        jitter: raw.jitter.unwrap_or(d.jitter),
    };
    if let Err(e) = settings.validate() {
        return Err(c.err(&path(e.field), e.message));
    }
    let classifier = raw.classifier.clone().unwrap_or_else(|| {
        match kind {
            SensorKind::Ft => "likelihood",
            SensorKind::Timing => "timing",
        }
        .to_string()
    });
    if !classify::NAMES.contains(&classifier.as_str()) {
        return Err(c.err(
            &path("classifier"),
            format!(
                "unknown classifier '{classifier}'; known: {}",
                classify::NAMES.join(", ")
            ),
        ));
    }
    let (hypotheses, vertex_edge) = match &raw.hypotheses {
        None => (None, false),
        Some(RawHypotheses::Named(n)) if n == "stable" => (None, false),
        Some(RawHypotheses::Named(n)) if n == "vertex-edge" => (None, true),
        Some(RawHypotheses::Named(n)) => {
            return Err(c.err(
                &path("hypotheses"),
                format!("must be \"stable\", \"vertex-edge\" or a list of orientations in degrees, got \"{n}\""),
            ))
        }
        Some(RawHypotheses::Degrees(list)) => {
            Hypotheses::orientations(list.clone())
                .map_err(|e| c.err(&path("hypotheses"), e.to_string()))?;
            (Some(list.clone()), false)
        }
    };
    if classifier == "zero-crossings" && !vertex_edge {
        return Err(c.err(
            &path("classifier"),
            "zero-crossings decides vertex or edge contact only: set hypotheses = \"vertex-edge\"",
        ));
    }
    if vertex_edge && !matches!(classifier.as_str(), "zero-crossings" | "likelihood") {
        return Err(c.err(
            &path("classifier"),
            format!("classifier '{classifier}' cannot decide vertex/edge hypotheses; use zero-crossings or likelihood"),
        ));
    }
    let templates = raw.templates.unwrap_or(DEFAULT_TEMPLATES);
    if !(1..=MAX_TEMPLATES).contains(&templates) {
        return Err(c.err(
            &path("templates"),
            format!("must lie in [1, {MAX_TEMPLATES}] (templates per hypothesis), got {templates}"),
        ));
    }
    let reject_below = c.within(
        &path("reject_below"),
        raw.reject_below.unwrap_or(0.0),
        0.0,
        1.0,
        "a posterior probability",
    )?;
    Ok(ValidSensor {
        settings,
        classifier,
        hypotheses,
        vertex_edge,
        templates: templates as usize,
        reject_below,
    })
}

/// Resolves the hypotheses of the sensor of `pin` (obstacle `i`) against the part and the feed,
/// and locates the keys its training errors name: the sensor as [`super::SceneDraft`] holds it.
pub(super) fn draft(
    c: &Checker,
    i: usize,
    valid: &ValidSensor,
    pin: &PinObstacle,
    part: &PartSpec,
    feed: &Feed,
) -> R<SensorDraft> {
    let key = |k: &str| format!("obstacles[{i}].sensor{k}");
    let hypotheses = if valid.vertex_edge {
        match &feed.orientation {
            // Parts fed in their stable states meet the pin in those states.
            Orientation::Stable {
                thetas_rad: thetas, ..
            } => Hypotheses::VertexEdge {
                degrees: thetas.iter().map(|t| t.to_degrees()).collect(),
            },
            Orientation::Uniform => Hypotheses::vertex_edge_sweep(),
        }
    } else {
        match &valid.hypotheses {
            Some(degrees) => Hypotheses::orientations(degrees.clone()),
            None => Hypotheses::stable_states(&part.polygon),
        }
        .map_err(|e| c.err(&key(".hypotheses"), e.to_string()))?
    };
    Ok(SensorDraft {
        obstacle: i,
        name: pin.name.clone(),
        settings: valid.settings,
        classifier: valid.classifier.clone(),
        hypotheses,
        templates: valid.templates,
        reject_below: valid.reject_below,
        at: TrainingKeys {
            sensor: c.locate(&key("")),
            hypotheses: c.locate(&key(".hypotheses")),
            classifier: c.locate(&key(".classifier")),
        },
    })
}

/// Mean and standard deviation of the feed's lateral offset (m).
fn lateral_moments(l: &Lateral) -> (f64, f64) {
    match *l {
        Lateral::Fixed(y) => (y, 0.0),
        Lateral::Uniform { min, max } => (0.5 * (min + max), (max - min) / 12f64.sqrt()),
        Lateral::Normal { mean, sd, .. } => (mean, sd),
    }
}

#[cfg(test)]
thread_local! {
    /// How many sensors [`train`] has trained on this thread: tests check that a refused file
    /// trains none.
    pub(super) static TRAINED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// Trains the sensor `draft` for `scene` (whose obstacle `draft.obstacle` is the sensor's pin).
pub(super) fn train(scene: &Scene, draft: &SensorDraft) -> R<SensorPin> {
    #[cfg(test)]
    TRAINED.with(|n| n.set(n.get() + 1));
    let Obstacle::Pin(pin) = &scene.obstacles[draft.obstacle] else {
        unreachable!("a sensor draft names a pin");
    };
    let (part, feed, contact) = (&scene.part, &scene.feed, &scene.contact);
    let a = part.radius;
    let (y_mean, y_sd) = lateral_moments(&feed.lateral);
    let template_d = (pin.centre.y - y_mean) / a;
    let template_d_sd = y_sd / a;
    let theta_sd_deg = match &feed.orientation {
        Orientation::Stable {
            jitter_rad: jitter, ..
        } => jitter.to_degrees(),
        Orientation::Uniform => 0.0,
    };
    let setup = PushSetup {
        polygon: part.polygon.clone(),
        d: template_d,
        pin_radius: pin.radius,
        mu_c: pin.mu_c,
        mu_s: part.mu_s,
        fidelity: contact.fidelity,
        tol: contact.tol,
        mass: part.mass,
        belt_speed: scene.belt.speed,
        height: draft.settings.height,
    };
    let unc = Uncertainty {
        mu_c: Distribution::Fixed(pin.mu_c),
        tripod: part.support == SupportKind::Tripod,
        theta_sd_deg,
        d_sd: template_d_sd,
    };
    // Templates of sensor i draw from streams of their own (salted by the obstacle index).
    let template_seed = scene.seed ^ (0x5e05_0000_0000_0000 | draft.obstacle as u64);
    let set = build_templates(
        &setup,
        &part.model,
        &draft.hypotheses,
        &unc,
        draft.templates,
        template_seed,
    )
    .map_err(|e| {
        draft
            .at
            .sensor
            .error(format!("cannot simulate the templates: {e}"))
    })?;
    if let Some(h) = set.members.iter().position(|m| m.is_empty()) {
        return Err(draft.at.hypotheses.error(format!(
            "hypothesis '{}' never occurs at this pin (no template could be simulated): the pin at d = {template_d:.3} cannot tell it",
            set.labels[h]
        )));
    }
    let options = ClassifierOptions {
        reject_below: draft.reject_below,
    };
    let classifier = classify::build(&draft.classifier, &set, &draft.settings, &options)
        .map_err(|e| draft.at.classifier.error(e.to_string()))?;
    Ok(SensorPin {
        settings: draft.settings,
        classifier_name: draft.classifier.clone(),
        labels: set.labels.clone(),
        hypotheses: draft.hypotheses.clone(),
        templates_per_hypothesis: draft.templates,
        reject_below: draft.reject_below,
        template_d,
        template_d_sd,
        classifier: std::sync::Arc::from(classifier),
    })
}
