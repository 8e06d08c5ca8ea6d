//! The compiled scene: everything a run needs, validated, in SI units and radians, never mutated
//! (DESIGN.md "model vs state"). Run state lives in [`crate::engine`].

pub use super::raw::SupportKind;
use crate::geometry::{Polygon, StableState, Vec2};
use crate::mechanics::{ContactSettings, PartModel};

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
#[derive(Debug)]
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
    /// A stable state chosen with the given (normalised) weights, plus normal jitter.
    Stable {
        thetas: Vec<f64>,
        weights: Vec<f64>,
        jitter: f64,
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

/// A fixed pin over the belt.
#[derive(Debug, Clone, PartialEq)]
pub struct PinObstacle {
    pub name: String,
    /// Centre, world frame (m).
    pub centre: Vec2,
    /// Radius (m).
    pub radius: f64,
    /// Pin–part friction.
    pub mu_c: f64,
}

/// An element over the belt. Only fixed pins exist so far; sensor pins, moving pins and fences
/// are reserved kinds in the file format and will become variants here.
#[derive(Debug, Clone, PartialEq)]
pub enum Obstacle {
    Pin(PinObstacle),
}

impl Obstacle {
    pub fn name(&self) -> &str {
        match self {
            Obstacle::Pin(p) => &p.name,
        }
    }
    /// A disc containing the obstacle (centre, radius), for broad-phase tests.
    pub fn bounding_disc(&self) -> (Vec2, f64) {
        match self {
            Obstacle::Pin(p) => (p.centre, p.radius),
        }
    }
}

/// A named set of target orientations (radians) with a tolerance (radians).
#[derive(Debug, Clone, PartialEq)]
pub struct GoalSet {
    pub name: String,
    pub orientations: Vec<f64>,
    pub tolerance: f64,
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
    /// The index of the first goal set containing `theta` (radians), `Some(0)` for `Any`.
    pub fn matching_set(&self, theta: f64) -> Option<usize> {
        match self {
            Goal::Any => Some(0),
            Goal::Sets(sets) => sets.iter().position(|s| {
                s.orientations
                    .iter()
                    .any(|&o| crate::geometry::wrap_pi(theta - o).abs() <= s.tolerance)
            }),
        }
    }
}

/// Optional work, switched per scene (DESIGN.md "effects are opt-in").
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
#[derive(Debug)]
pub struct Scene {
    pub name: String,
    pub seed: u64,
    pub belt: Belt,
    pub part: PartSpec,
    pub feed: Feed,
    pub obstacles: Vec<Obstacle>,
    /// For each obstacle, the other obstacles a part in contact with it could touch
    /// (centre distance ≤ 2a + both radii), ascending.
    pub neighbours: Vec<Vec<usize>>,
    pub goal: Goal,
    /// Contact-model settings; a pin's own μc replaces `mu_c` for its contacts.
    pub contact: ContactSettings,
    pub effects: Effects,
    pub output: OutputOptions,
}
