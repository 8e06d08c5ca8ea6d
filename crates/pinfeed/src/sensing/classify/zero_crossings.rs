//! `zero-crossings`: vertex vs edge contact by the thesis's rule (ch. 5.7.2, eq. 5-3).
//!
//! **What the thesis specifies.** A degree-6 polynomial (chosen "by trial and error") is fitted by
//! least squares to the force profile over the contact; its first derivative is taken; the number
//! of its zero crossings (slope sign changes: maxima and minima of the fit) is counted; three or
//! more → vertex contact (the "spike" a catching vertex adds: maximum → minimum → maximum), fewer →
//! edge. The thesis applied it to the x-direction force (fig. 5-14 a–b: the spike and its three
//! crossings are in Fx; Fy "with no noticeable difference").
//!
//! **What we had to choose:** the profile is Fx (the force along the belt, as in fig. 5-14), raw
//! (the thesis mentions no smoothing for this rule), with the sensor's known bias and drift removed;
//! the contact is the span found by the shared |F| detector ([`super::common`]); the fit's abscissa
//! is the contact mapped onto [−1, 1] for conditioning (the fit itself is unchanged by the map); a
//! zero crossing is a strict sign change of the derivative between consecutive points of a
//! [`GRID`]-point grid over the open contact (a root where the derivative touches zero without
//! changing sign is no crossing; roots closer than the grid step merge). No posterior (None).
//!
//! The hypotheses must be labelled `vertex` and `edge` (see `Hypotheses::VertexEdge`); the rule
//! uses no template (the labels only tell which index is which).

use super::common::{self, polyfit};
use super::{Classification, Classifier, Decision};
use crate::sensing::reading::Reading;
use crate::sensing::settings::{SensorSettings, CHANNELS};
use crate::sensing::templates::TemplateSet;

/// Degree of the fitted polynomial (thesis ch. 5.7.2).
pub const DEGREE: usize = 6;
/// Crossings that mark a vertex contact (eq. 5-3).
pub const VERTEX_CROSSINGS: usize = 3;
/// Grid points over the contact at which the derivative's sign is examined.
pub const GRID: usize = 2001;

/// The `zero-crossings` classifier: vertex or edge contact by the zero crossings of a fitted force
/// profile's slope.
pub struct ZeroCrossings {
    vertex: usize,
    edge: usize,
    sensor: SensorSettings,
}

/// Zero crossings of the derivative of the degree-6 least-squares fit to `y` (equally spaced
/// samples); `None` with fewer than 7 points or a non-finite value.
pub fn derivative_zero_crossings(y: &[f64]) -> Option<usize> {
    let x: Vec<f64> = (0..y.len()).map(|k| k as f64).collect();
    let p = polyfit(&x, y, DEGREE)?;
    let d = common::derivative(&p);
    let mut count = 0;
    let mut prev = 0i8;
    for i in 1..GRID - 1 {
        let u = -1.0 + 2.0 * i as f64 / (GRID - 1) as f64;
        let s = common::sign(common::eval(&d, u));
        if s != 0 {
            if prev != 0 && s != prev {
                count += 1;
            }
            prev = s;
        }
    }
    Some(count)
}

/// The Fx profile over the detected contact of a reading (bias removed), or `None`.
fn profile(values: &[[f64; CHANNELS]], sensor: &SensorSettings) -> Option<Vec<f64>> {
    let (b, e) = common::Detector::new(sensor).detect(values)?;
    Some(values[b..=e].iter().map(|v| v[0]).collect())
}

/// Why zero-crossings cannot be trained on a template set ([`ZeroCrossings::new`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ZeroCrossingsError {
    /// The hypotheses are not exactly `vertex` and `edge`.
    #[error(
        "zero-crossings tells vertex from edge contact: it needs the hypotheses \
         [\"vertex\", \"edge\"], got {labels:?}"
    )]
    Labels {
        /// The template set's hypothesis labels.
        labels: Vec<String>,
    },
}

impl ZeroCrossings {
    /// Train on `templates` for `sensor`; Err (the reason) when the labels are not `vertex` and
    /// `edge` or the templates cannot be used.
    pub fn new(
        templates: &TemplateSet,
        sensor: &SensorSettings,
    ) -> Result<Self, ZeroCrossingsError> {
        let find = |l: &str| templates.labels.iter().position(|x| x == l);
        match (find("vertex"), find("edge"), templates.labels.len()) {
            (Some(vertex), Some(edge), 2) => Ok(ZeroCrossings {
                vertex,
                edge,
                sensor: *sensor,
            }),
            _ => Err(ZeroCrossingsError::Labels {
                labels: templates.labels.clone(),
            }),
        }
    }
}

impl Classifier for ZeroCrossings {
    fn name(&self) -> &'static str {
        "zero-crossings"
    }

    fn classify(&self, r: &Reading) -> Classification {
        let Reading::Ft(s) = r else {
            return Classification::unknown();
        };
        let Some(n) = common::clean_values(s, &self.sensor)
            .and_then(|v| profile(&v, &self.sensor))
            .and_then(|y| derivative_zero_crossings(&y))
        else {
            return Classification::unknown();
        };
        Classification {
            decision: Decision::Hypothesis(if n >= VERTEX_CROSSINGS {
                self.vertex
            } else {
                self.edge
            }),
            posterior: None,
        }
    }
}
