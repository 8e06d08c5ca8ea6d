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
    /// Uniform pressure, or a random tripod per part.
    pub support: SupportKind,
    /// Default pin–part friction coefficient (a pin's own `mu_c` overrides it).
    pub mu_c: f64,
    /// Part–belt friction coefficient (scales the contact forces only, not the motion).
    pub mu_s: f64,
    /// Mass (kg): sensors turn forces into newtons with it.
    pub mass: f64,
    /// The part's stable states (uniform support), in the order `pinfeed part` lists them.
    pub stable_states: Vec<StableState>,
}

/// Arrival process of the feed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Arrival {
    /// One part every `headway` seconds, the first at t = 0.
    Periodic {
        /// Seconds between arrivals (> 0).
        headway: f64,
    },
    /// Exponential gaps with mean `headway` seconds, the first at t = 0.
    Poisson {
        /// Mean seconds between arrivals (> 0).
        headway: f64,
    },
}

impl Arrival {
    /// Mean time between arrivals (s).
    pub fn headway(&self) -> f64 {
        match *self {
            Arrival::Periodic { headway } | Arrival::Poisson { headway } => headway,
        }
    }

    /// The same arrival process with (mean) time `headway` (s) between arrivals.
    pub fn with_headway(self, headway: f64) -> Arrival {
        match self {
            Arrival::Periodic { .. } => Arrival::Periodic { headway },
            Arrival::Poisson { .. } => Arrival::Poisson { headway },
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
        /// The stable states' orientations (radians), in the order of `PartSpec::stable_states`.
        thetas_rad: Vec<f64>,
        /// One weight per state, normalised to sum to 1.
        weights: Vec<f64>,
        /// Standard deviation of the normal jitter added to the state (radians, ≥ 0).
        jitter_rad: f64,
    },
}

/// Distribution of the centroid's lateral position at entry (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Lateral {
    /// Always this offset (m).
    Fixed(f64),
    /// Uniform on [min, max] (m).
    Uniform {
        /// Lower bound (m).
        min: f64,
        /// Upper bound (m).
        max: f64,
    },
    /// Normal, redrawn until it falls within [lo, hi] (the belt minus the part's radius).
    Normal {
        /// Mean (m).
        mean: f64,
        /// Standard deviation (m).
        sd: f64,
        /// Lowest accepted draw (m).
        lo: f64,
        /// Highest accepted draw (m).
        hi: f64,
    },
}

/// The feed: number of parts and how each is drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct Feed {
    /// Number of parts to run (≥ 1).
    pub parts: u64,
    /// When parts arrive.
    pub arrival: Arrival,
    /// How each part's entry orientation is drawn.
    pub orientation: Orientation,
    /// How each part's entry lateral offset is drawn.
    pub lateral: Lateral,
}

/// A fixed pin over the belt, with an optional sensor (`kind = "sensor_pin"` in the file).
#[derive(Debug, Clone, PartialEq)]
pub struct PinObstacle {
    /// Unique obstacle name (from the file, or `pinN`).
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
    /// Sample rate, noise, bias, filtering and quantisation of the sensor.
    pub settings: SensorSettings,
    /// Classifier name (one of [`crate::sensing::classify::NAMES`]).
    pub classifier_name: String,
    /// The states the classifier tells apart.
    pub hypotheses: Hypotheses,
    /// One display label per hypothesis (e.g. `"135°"`), in the order of `hypotheses`.
    pub labels: Vec<String>,
    /// Simulated templates per hypothesis the classifier was trained on.
    pub templates_per_hypothesis: usize,
    /// Decide "unknown" below this posterior (in [0, 1]; 0 never rejects).
    pub reject_below: f64,
    /// The contact parameter d the templates were simulated at (units of a: the pin against the
    /// feed's mean lateral offset).
    pub template_d: f64,
    /// Standard deviation of d the templates were drawn with (units of a, from the feed's lateral spread).
    pub template_d_sd: f64,
    /// The trained classifier, shared by every run of the scene.
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
    /// Unique obstacle name (from the file, or `fenceN`).
    pub name: String,
    /// Upstream end, world frame (m).
    pub start: Vec2,
    /// Angle from the belt direction (radians, strictly inside (−π/2, π/2)).
    pub angle_rad: f64,
    /// Length (m, > 0).
    pub length: f64,
    /// Fence–part friction μf.
    pub mu_f: f64,
    /// Radius of the fence's curved tail (m), if it ends in one: an arc tangent to the fence at
    /// its downstream end that turns it parallel to the belt (docs/physics.md#fences).
    pub tail_radius: Option<f64>,
}

impl FenceObstacle {
    /// Downstream end of the straight part, world frame (m): where a tail begins.
    pub fn end(&self) -> Vec2 {
        self.start + Vec2::from_angle(self.angle_rad) * self.length
    }
    /// The fence's far end, world frame (m): its tail's end, or [`Self::end`] without a tail.
    pub fn far_end(&self) -> Vec2 {
        self.spec().far_end()
    }
    /// How far (m) the fence strays from the chord between its start and its far end: 0 for a
    /// straight fence (a little more than the exact figure for a tailed one, from 64 points of its
    /// arc and their sagitta).
    pub fn chord_offset(&self) -> f64 {
        let spec = self.spec();
        let Some((_, r, _, _)) = spec.tail_arc() else {
            return 0.0;
        };
        let pts = spec.polyline(64);
        let (p, q) = (self.start, self.far_end());
        let dir = (q - p).normalized();
        let sag = r * (1.0 - (self.angle_rad / 128.0).cos());
        pts.iter()
            .map(|&x| (x - p).cross(dir).abs())
            .fold(0.0, f64::max)
            + sag
    }
    /// The fence as the contact model takes it (world frame, metres).
    pub fn spec(&self) -> FenceSpec {
        FenceSpec {
            start: self.start,
            angle_rad: self.angle_rad,
            length: self.length,
            mu_f: self.mu_f,
            tail_radius: self.tail_radius,
        }
    }
}

/// An element over the belt: a pin (with an optional sensor and an optional actuator: the file
/// format's `pin`, `sensor_pin`, `moving_pin` and `retractable_pin`) or a fence.
#[derive(Debug, Clone, PartialEq)]
pub enum Obstacle {
    /// A pin (fixed, sensing, moving or retractable).
    Pin(PinObstacle),
    /// A straight fence.
    Fence(FenceObstacle),
}

impl Obstacle {
    /// The obstacle's unique name.
    pub fn name(&self) -> &str {
        match self {
            Obstacle::Pin(p) => &p.name,
            Obstacle::Fence(f) => &f.name,
        }
    }
    /// The obstacle as a capsule: the points within `radius` of the segment [p, q] (world, m). A
    /// pin is a disc (p = q = its centre), a moving pin the whole of its travel; a fence is its
    /// segment (radius 0), a tailed fence the chord from its start to its tail's end with the
    /// radius that holds the whole fence ([`FenceObstacle::chord_offset`]).
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
            Obstacle::Fence(f) => (f.start, f.far_end(), f.chord_offset()),
        }
    }
    /// The obstacle's extent along the belt, [x_min, x_max] (m). A fence (with or without a tail)
    /// runs monotonically in x and in y from its start to its far end.
    pub fn x_range(&self) -> [f64; 2] {
        let (p, q, r) = match self {
            Obstacle::Fence(f) => (f.start, f.far_end(), 0.0),
            _ => self.capsule(),
        };
        [p.x.min(q.x) - r, p.x.max(q.x) + r]
    }
    /// The obstacle's extent across the belt, [y_min, y_max] (m).
    pub fn y_range(&self) -> [f64; 2] {
        let (p, q, r) = match self {
            Obstacle::Fence(f) => (f.start, f.far_end(), 0.0),
            _ => self.capsule(),
        };
        [p.y.min(q.y) - r, p.y.max(q.y) + r]
    }
}

/// A named set of target orientations (radians) with a tolerance (radians).
#[derive(Debug, Clone, PartialEq)]
pub struct GoalSet {
    /// Name of the set in reports.
    pub name: String,
    /// Target orientations (radians).
    pub orientations_rad: Vec<f64>,
    /// Tolerance around each target (radians, ≥ 0).
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
    /// Detect part–part overlap while two or more parts share the belt.
    pub collisions: bool,
    /// Check obstacles within reach of a pushing one for a second contact.
    pub obstacle_sweeps: bool,
    /// Record every event (written to `events.json`).
    pub event_log: bool,
}

/// Output options.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputOptions {
    /// Folder under which `<scene name>/` is written (relative to the working folder).
    pub dir: String,
    /// Write one CSV row per part.
    pub parts_csv: bool,
    /// Write the final-orientation histogram as SVG.
    pub histogram_svg: bool,
    /// Histogram bin width (degrees).
    pub histogram_bin_deg: f64,
    /// How many sample parts `--draw` shows (1 to 20).
    pub draw_parts: u32,
}

/// A compiled, validated scenario.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Scene name (names the results folder).
    pub name: String,
    /// Seed of the run; part i draws from its own stream (seed, i), so the same seed gives the same parts.
    pub seed: u64,
    /// The belt's speed and extent.
    pub belt: Belt,
    /// The part's geometry and contact model.
    pub part: PartSpec,
    /// How many parts arrive, when and how posed.
    pub feed: Feed,
    /// Pins and fences, in file order (indices used throughout the engine).
    pub obstacles: Vec<Obstacle>,
    /// For each obstacle, the other obstacles a part in contact with it could touch (their
    /// distance, between the pins' discs and the fences' segments, is at most 2a), ascending.
    pub neighbours: Vec<Vec<usize>>,
    /// Which final orientations count as correct.
    pub goal: Goal,
    /// Contact-model settings; a pin's own μc replaces `mu_c` for its contacts.
    pub contact: ContactSettings,
    /// Optional engine work switched on.
    pub effects: Effects,
    /// Which files a run writes.
    pub output: OutputOptions,
    /// The controller driving the dynamic pins (`[controller]` and `[[rules]]`), if any.
    pub controller: Option<Controller>,
    /// `[model] fidelity = "map"`: the map tier's grid (None: the contact model answers every
    /// push).
    pub map_tier: Option<crate::maps::tier::TierSpec>,
    /// A reject gate at the belt's end and the return path of the parts it takes off
    /// (docs/scenario-format.md#closed-loop); None: an open line.
    pub closed_loop: Option<super::closed_loop::ClosedLoop>,
}
