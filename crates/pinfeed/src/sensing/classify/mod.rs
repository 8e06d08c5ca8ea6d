//! Classifiers: a reading and the hypotheses' simulated templates → a decision (and a posterior
//! where the method has one), with "unknown" allowed.
//!
//! One interface for every method: [`build`] trains a classifier by name on a [`TemplateSet`] and
//! the sensor's settings (templates aligned, fits and noise model precomputed once), and
//! [`Classifier::classify`] decides one [`Reading`]. Methods:
//! * `sign-matrix` — the thesis's empirical method (ch. 5, app. D), the baseline;
//! * `timing` — contact duration(s) against the templates' durations, jitter and model spread
//!   giving a posterior;
//! * `likelihood` — a matched filter over the template ensembles with the sensor's noise model,
//!   posterior over hypotheses, reject option below a posterior threshold;
//! * `zero-crossings` — vertex vs edge by the thesis's rule (≥ 3 zero crossings of the derivative
//!   of a degree-6 fit), for the `vertex`/`edge` hypotheses.

pub mod common;
pub mod likelihood;
pub mod sign_matrix;
pub mod timing;
pub mod zero_crossings;

use super::reading::Reading;
use super::settings::{SensorSettings, SettingError};
use super::templates::TemplateSet;
use serde::Serialize;

/// A classifier's decision.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Decision {
    /// The index of the chosen hypothesis.
    Hypothesis(usize),
    /// No decision (posterior below the reject threshold, no contact detected, scores tied).
    Unknown,
}

/// A decision and, where the method has one, the posterior over the hypotheses (sums to 1).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Classification {
    /// The decision: a hypothesis or unknown.
    pub decision: Decision,
    /// Posterior over the hypotheses (in label order, sums to 1); `None` for methods without one.
    pub posterior: Option<Vec<f64>>,
}

impl Classification {
    /// No decision and no posterior.
    pub fn unknown() -> Classification {
        Classification {
            decision: Decision::Unknown,
            posterior: None,
        }
    }
}

/// Options shared by the classifiers.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ClassifierOptions {
    /// Reject option: decide "unknown" when the largest posterior is below this (0: never reject).
    pub reject_below: f64,
}

impl Default for ClassifierOptions {
    fn default() -> Self {
        ClassifierOptions { reject_below: 0.0 }
    }
}

/// A trained classifier.
pub trait Classifier: Send + Sync {
    /// The method's name (as [`build`] takes it).
    fn name(&self) -> &'static str;
    /// Decide one reading.
    fn classify(&self, reading: &Reading) -> Classification;
}

/// The names [`build`] accepts.
pub const NAMES: [&str; 4] = ["sign-matrix", "timing", "likelihood", "zero-crossings"];

/// Why a classifier could not be built ([`build`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BuildError {
    /// A name that is no classifier.
    #[error("unknown classifier '{name}'; known: {}", NAMES.join(", "))]
    Unknown {
        /// The name given.
        name: String,
    },
    /// Invalid sensor settings.
    #[error("{name}: sensor settings: {error}")]
    Sensor {
        /// The classifier.
        name: String,
        /// The invalid setting.
        error: SettingError,
    },
    /// A rejection threshold out of [0, 1].
    #[error("{name}: reject_below must lie in [0, 1], got {value}")]
    RejectBelow {
        /// The classifier.
        name: String,
        /// The threshold given.
        value: f64,
    },
    /// Labels and template ensembles that do not match one to one.
    #[error("{name}: {labels} labels but {ensembles} template ensembles")]
    Ensembles {
        /// The classifier.
        name: String,
        /// Number of labels.
        labels: usize,
        /// Number of template ensembles.
        ensembles: usize,
    },
    /// Templates that would hold too many samples at the sensor's rate.
    #[error(
        "{name}: the templates would hold {samples} samples at {rate} Hz (at most {}): lower the rate or the number of templates",
        super::reading::MAX_TEMPLATE_SAMPLES
    )]
    Samples {
        /// The classifier.
        name: String,
        /// The samples the templates would hold.
        samples: usize,
        /// The sensor's rate (Hz).
        rate: f64,
    },
    /// Zero-crossings cannot be trained on these templates.
    #[error("{0}")]
    ZeroCrossings(zero_crossings::ZeroCrossingsError),
    /// No hypotheses.
    #[error("{name}: no hypotheses")]
    NoHypotheses {
        /// The classifier.
        name: String,
    },
    /// A hypothesis without templates.
    #[error("{name}: hypothesis '{label}' has no templates (an empty ensemble cannot be matched)")]
    EmptyEnsemble {
        /// The classifier.
        name: String,
        /// The hypothesis's label.
        label: String,
    },
}

/// Trains the classifier `name` (one of [`NAMES`]) on `templates` for readings of `sensor`.
///
/// Errors: an unknown name (the message lists the known ones), invalid sensor settings or
/// options, labels and ensembles that do not match, a hypothesis with an empty ensemble (for the
/// template-based methods), hypotheses other than `vertex`/`edge` for `zero-crossings`. Templates
/// whose contact the detector cannot see at this noise level are no error: such a classifier
/// answers Unknown.
pub fn build(
    name: &str,
    templates: &TemplateSet,
    sensor: &SensorSettings,
    options: &ClassifierOptions,
) -> Result<Box<dyn Classifier>, BuildError> {
    let owned = || name.to_string();
    if !NAMES.contains(&name) {
        return Err(BuildError::Unknown { name: owned() });
    }
    sensor.validate().map_err(|error| BuildError::Sensor {
        name: owned(),
        error,
    })?;
    if !(0.0..=1.0).contains(&options.reject_below) {
        return Err(BuildError::RejectBelow {
            name: owned(),
            value: options.reject_below,
        });
    }
    if templates.labels.len() != templates.members.len() {
        return Err(BuildError::Ensembles {
            name: owned(),
            labels: templates.labels.len(),
            ensembles: templates.members.len(),
        });
    }
    // Training samples every template at the sensor's rate: bound the work and the memory.
    let samples: usize = templates
        .members
        .iter()
        .flatten()
        .map(|s| super::reading::samples_needed(s, sensor.rate))
        .sum();
    if samples > super::reading::MAX_TEMPLATE_SAMPLES {
        return Err(BuildError::Samples {
            name: owned(),
            samples,
            rate: sensor.rate,
        });
    }
    if name == "zero-crossings" {
        return Ok(Box::new(
            zero_crossings::ZeroCrossings::new(templates, sensor)
                .map_err(BuildError::ZeroCrossings)?,
        ));
    }
    if templates.labels.is_empty() {
        return Err(BuildError::NoHypotheses { name: owned() });
    }
    if let Some(h) = templates.members.iter().position(|m| m.is_empty()) {
        return Err(BuildError::EmptyEnsemble {
            name: owned(),
            label: templates.labels[h].clone(),
        });
    }
    Ok(match name {
        "sign-matrix" => Box::new(sign_matrix::SignMatrixClassifier::new(templates, sensor)),
        "timing" => Box::new(timing::Timing::new(templates, sensor, options)),
        _ => Box::new(likelihood::Likelihood::new(templates, sensor, options)),
    })
}
