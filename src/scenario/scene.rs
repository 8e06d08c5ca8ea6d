//! The compiled scene: everything a run needs, validated, in SI units and radians, never mutated
//! (the model, apart from the state). Run state lives in [`crate::engine`].

use super::dynamic::{Actuator, Controller};
pub use super::raw::SupportKind;
use crate::geometry::{Polygon, StableState, Vec2};
use crate::mechanics::{ContactSettings, FenceSpec, PartModel};
use crate::sensing::classify::Classifier;
use crate::sensing::templates::Hypotheses;
use crate::sensing::SensorSettings;
use std::sync::Arc;

/// The belt: parts enter at x = 0 and leave at x = `length`; it spans y ∈ [−width/2, width/2].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Belt {
    /// m/s, > 0.
    pub speed: f64,
    /// m.
    pub width: f64,
    /// m.
    pub length: f64,
}

/// The part: its polygon in metres (centroid at the origin) and its contact model.
#[derive(Debug, Clone)]
pub struct PartSpec {
    /// How the part was named in the file (`tripoly2`, or `vertices`).
    pub label: String,
    /// The polygon in metres, part frame.
    pub polygon: Polygon,
    /// `a` in metres.
    pub radius: f64,
    /// Compiled once for uniform support; a tripod part gets its own model per part.
    pub model: PartModel,
    pub support: SupportKind,
    pub mu_c: f64,
    pub mu_s: f64,
    /// Mass (kg): sensors turn forces into newtons with it.
    pub mass: f64,
    pub stable_states: Vec<StableState>,
}

/// Arrival process of the feed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Arrival {
    /// One part every `headway` seconds, the first at t = 0.
    Periodic { headway: f64 },
    /// Exponential gaps with mean `headway` seconds, the first at t = 0.
    Poisson { headway: f64 },
}

impl Arrival {
    /// Mean time between arrivals (s).
    pub fn headway(&self) -> f64 {
        match *self {
            Arrival::Periodic { headway } | Arrival::Poisson { headway } => headway,
        }
    }
}

/// Distribution of the entry orientation.
#[derive(Debug, Clone, PartialEq)]
pub enum Orientation {
    /// θ uniform on [0, 2π).
    Uniform,
    /// A stable state chosen with the given (normalised) weights, plus normal jitter (its sd).
    Stable {
        thetas_rad: Vec<f64>,
        weights: Vec<f64>,
        jitter_rad: f64,
    },
}

/// Distribution of the centroid's lateral position at entry (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Lateral {
    Fixed(f64),
    Uniform {
        min: f64,
        max: f64,
    },
    /// Normal, redrawn until it falls within [lo, hi] (the belt minus the part's radius).
    Normal {
        mean: f64,
        sd: f64,
        lo: f64,
        hi: f64,
    },
}

/// The feed: number of parts and how each is drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct Feed {
    pub parts: u64,
    pub arrival: Arrival,
    pub orientation: Orientation,
    pub lateral: Lateral,
}

/// A fixed pin over the belt, with an optional sensor (`kind = "sensor_pin"` in the file).
#[derive(Debug, Clone, PartialEq)]
pub struct PinObstacle {
    pub name: String,
    /// Centre, world frame (m).
    pub centre: Vec2,
    /// Radius (m).
    pub radius: f64,
    /// Pin–part friction.
    pub mu_c: f64,
    /// The pin's sensor and its trained classifier, if it has one.
    pub sensor: Option<Arc<SensorPin>>,
    /// What moves the pin (a moving or retractable pin), if anything; `centre` is then its home.
    pub actuator: Option<Actuator>,
}

/// A pin's sensor: its settings, its hypotheses and the classifier trained on their templates
/// (compiled once with the scene; see [`super::sensors`]).
#[derive(Clone)]
pub struct SensorPin {
    pub settings: SensorSettings,
    /// Classifier name (one of [`crate::sensing::classify::NAMES`]).
    pub classifier_name: String,
    pub hypotheses: Hypotheses,
    pub labels: Vec<String>,
    pub templates_per_hypothesis: usize,
    pub reject_below: f64,
    /// The contact parameter d the templates were simulated at (the pin against the feed's
    /// mean lateral offset), and the spread of d they were drawn with.
    pub template_d: f64,
    pub template_d_sd: f64,
    pub classifier: Arc<dyn Classifier>,
}

impl std::fmt::Debug for SensorPin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SensorPin")
            .field("settings", &self.settings)
            .field("classifier", &self.classifier_name)
            .field("hypotheses", &self.hypotheses)
            .field("templates_per_hypothesis", &self.templates_per_hypothesis)
            .field("template_d", &self.template_d)
            .finish()
    }
}

impl PartialEq for SensorPin {
    /// Two sensors are equal when everything they were compiled from is (the trained classifier
    /// is a function of it).
    fn eq(&self, o: &Self) -> bool {
        self.settings == o.settings
            && self.classifier_name == o.classifier_name
            && self.hypotheses == o.hypotheses
            && self.templates_per_hypothesis == o.templates_per_hypothesis
            && self.reject_below == o.reject_below
            && self.template_d == o.template_d
            && self.template_d_sd == o.template_d_sd
    }
}

/// A fixed fence over the belt (docs/physics.md#fences): the segment from `start` (its upstream end) along
/// `angle` for `length`.
///
/// Side: parts meet the fence's upstream face. A positive angle runs downstream to the left (+y):
/// parts arriving from its right slide along it to the left. A negative angle mirrors that: the
/// fence runs downstream to the right and deflects parts to the right. The sign of the angle is the
/// only "side" a fence has.
#[derive(Debug, Clone, PartialEq)]
pub struct FenceObstacle {
    pub name: String,
    /// Upstream end, world frame (m).
    pub start: Vec2,
    /// Angle from the belt direction (radians, strictly inside (−π/2, π/2)).
    pub angle_rad: f64,
    /// Length (m, > 0).
    pub length: f64,
    /// Fence–part friction μf.
    pub mu_f: f64,
}

impl FenceObstacle {
    /// Downstream end, world frame (m).
    pub fn end(&self) -> Vec2 {
        self.start + Vec2::from_angle(self.angle_rad) * self.length
    }
    /// The fence as the contact model takes it (world frame, metres).
    pub fn spec(&self) -> FenceSpec {
        FenceSpec {
            start: self.start,
            angle_rad: self.angle_rad,
            length: self.length,
            mu_f: self.mu_f,
        }
    }
}

/// An element over the belt: a pin (with an optional sensor and an optional actuator: the file
/// format's `pin`, `sensor_pin`, `moving_pin` and `retractable_pin`) or a fence.
#[derive(Debug, Clone, PartialEq)]
pub enum Obstacle {
    Pin(PinObstacle),
    Fence(FenceObstacle),
}

impl Obstacle {
    pub fn name(&self) -> &str {
        match self {
            Obstacle::Pin(p) => &p.name,
            Obstacle::Fence(f) => &f.name,
        }
    }
    /// The obstacle as a capsule: the points within `radius` of the segment [p, q] (world, m). A
    /// pin is a disc (p = q = its centre), a moving pin the whole of its travel; a fence is its
    /// segment (radius 0).
    pub fn capsule(&self) -> (Vec2, Vec2, f64) {
        match self {
            Obstacle::Pin(PinObstacle {
                centre,
                radius,
                actuator: Some(Actuator::Moving(m)),
                ..
            }) => (
                Vec2::new(centre.x, m.travel[0]),
                Vec2::new(centre.x, m.travel[1]),
                *radius,
            ),
            Obstacle::Pin(p) => (p.centre, p.centre, p.radius),
            Obstacle::Fence(f) => (f.start, f.end(), 0.0),
        }
    }
    /// The obstacle's extent along the belt, [x_min, x_max] (m).
    pub fn x_range(&self) -> [f64; 2] {
        let (p, q, r) = self.capsule();
        [p.x.min(q.x) - r, p.x.max(q.x) + r]
    }
    /// The obstacle's extent across the belt, [y_min, y_max] (m).
    pub fn y_range(&self) -> [f64; 2] {
        let (p, q, r) = self.capsule();
        [p.y.min(q.y) - r, p.y.max(q.y) + r]
    }
}

/// A named set of target orientations (radians) with a tolerance (radians).
#[derive(Debug, Clone, PartialEq)]
pub struct GoalSet {
    pub name: String,
    pub orientations_rad: Vec<f64>,
    pub tolerance_rad: f64,
}

/// Which final orientations count as correct.
#[derive(Debug, Clone, PartialEq)]
pub enum Goal {
    /// Every exiting part is correct.
    Any,
    /// A part is correct when its orientation is within tolerance of an angle of any set.
    Sets(Vec<GoalSet>),
}

impl Goal {
    /// The index of the first goal set containing `theta_rad`, `Some(0)` for `Any`.
    pub fn matching_set(&self, theta_rad: f64) -> Option<usize> {
        match self {
            Goal::Any => Some(0),
            Goal::Sets(sets) => sets.iter().position(|s| {
                s.orientations_rad
                    .iter()
                    .any(|&o| crate::geometry::wrap_pi(theta_rad - o).abs() <= s.tolerance_rad)
            }),
        }
    }
}

/// Optional work, switched per scene (effects are opt-in: a scene pays only for what it asks for).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Effects {
    pub collisions: bool,
    pub obstacle_sweeps: bool,
    pub event_log: bool,
}

/// Output options.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputOptions {
    pub dir: String,
    pub parts_csv: bool,
    pub histogram_svg: bool,
    /// Histogram bin width (degrees).
    pub histogram_bin_deg: f64,
    pub draw_parts: u32,
}

/// A compiled, validated scenario.
#[derive(Debug, Clone)]
pub struct Scene {
    pub name: String,
    pub seed: u64,
    pub belt: Belt,
    pub part: PartSpec,
    pub feed: Feed,
    pub obstacles: Vec<Obstacle>,
    /// For each obstacle, the other obstacles a part in contact with it could touch (their
    /// distance, between the pins' discs and the fences' segments, is at most 2a), ascending.
    pub neighbours: Vec<Vec<usize>>,
    pub goal: Goal,
    /// Contact-model settings; a pin's own μc replaces `mu_c` for its contacts.
    pub contact: ContactSettings,
    pub effects: Effects,
    pub output: OutputOptions,
    /// The controller driving the dynamic pins (`[controller]` and `[[rules]]`), if any.
    pub controller: Option<Controller>,
    /// `[model] fidelity = "map"`: the map tier's grid (None: the contact model answers every
    /// push).
    pub map_tier: Option<crate::maps::tier::TierSpec>,
}

impl Scene {
    /// The online controller's model, when `[controller] mode = "online"`.
    pub fn online_model(&self) -> Option<&std::sync::Arc<crate::engine::online::OnlineModel>> {
        self.controller.as_ref()?.online.as_ref().map(|h| &h.0)
    }
}
