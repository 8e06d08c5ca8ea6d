//! What a run of the line takes beyond the scene and what it gives back: [`RunOptions`],
//! [`RunResult`] (summary, metrics, per-part [`PartRecord`]s, sample paths, event log) and the
//! [`EngineError`]s that stop a run.

use super::event_queue::{Event, EventKind};
use super::metrics::{Metrics, Summary};
use super::motion::Pusher;
use super::outcome::PartOutcome;
use crate::geometry::Pose;
use crate::mechanics::{ContactSettings, PartModel};
use crate::scenario::Scene;
use serde::Serialize;
use thiserror::Error;

/// What a run needs beyond the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOptions {
    /// Number of parts (default: the scene's).
    pub parts: u64,
    /// Seed (default: the scene's).
    pub seed: u64,
    /// Record the paths of the first `sample_paths` parts (for drawing).
    pub sample_paths: usize,
    /// Keep one record per part (for the per-part CSV).
    pub keep_records: bool,
    /// The online controller's model (`[controller] mode = "online"`). None: the run builds it
    /// from the scene it is given ([`super::prepare::online_model`], kept per process). A caller
    /// that changes a scene before running it (its physics, feed or seed) passes the model of the
    /// scene as written, which the controller was designed with.
    pub online: Option<super::prepare::OnlineHandle>,
    /// `run --precision`: stop feeding new parts once the rate is known to this precision
    /// ([`super::sequential`]); `parts` is then the cap. None: feed `parts` parts.
    pub stop: Option<super::sequential::Precision>,
}

impl RunOptions {
    /// The scene's own settings: its number of parts and seed, nothing recorded.
    pub fn from_scene(scene: &Scene) -> RunOptions {
        RunOptions {
            parts: scene.feed.parts,
            seed: scene.seed,
            sample_paths: 0,
            keep_records: false,
            online: None,
            stop: None,
        }
    }
}

/// Why a run could not be carried out.
#[derive(Debug, Error)]
pub enum EngineError {
    /// Part `index` could not be drawn from the feed (its random tripod support or the part model built on it failed).
    #[error("part {index}: {reason}")]
    PartDraw {
        /// Index of the part in the stream.
        index: u64,
        /// Why it could not be drawn.
        reason: crate::mechanics::PartModelError,
    },
    /// The online controller's model cannot be built for the scene (located at its
    /// `[controller.belief]`).
    #[error("{0}")]
    OnlineModel(crate::scenario::ScenarioError),
    /// An event time came out non-finite (NaN or ±∞): the scene's numbers leave f64. Validated
    /// scenarios never get here; the engine refuses instead of panicking.
    #[error("an event time is not finite ({kind:?} at {time} s; {refused} event(s) refused): the scene's numbers are out of range (see docs/scenario-format.md)")]
    NonFiniteTime {
        /// The event's time (s): NaN or ±∞.
        time: f64,
        /// The event that carried it.
        kind: EventKind,
        /// Events refused this way in the run so far.
        refused: u64,
    },
}

/// One finished part.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartRecord {
    /// Index of the part in the stream (0-based).
    pub part: u64,
    /// Arrival time (s).
    pub arrival_s: f64,
    /// Time the part finished: exited, or failed (s).
    pub end_s: f64,
    /// How the part ended (written as its name: `success`, `wrong_orientation`, …).
    pub outcome: crate::engine::PartOutcome,
    /// Cause behind multi_contact, jam or solver (written as its name), else [`Cause::None`](crate::engine::Cause::None)
    /// (written empty).
    pub cause: crate::engine::Cause,
    /// Obstacle encounters (pushes) of the part.
    pub contacts: u32,
    /// Orientation at entry (degrees, [0, 360)).
    pub theta_in_deg: f64,
    /// Orientation at the end (degrees, [0, 360)).
    pub theta_out_deg: f64,
    /// Lateral position of the centroid at entry (m).
    pub y_in_m: f64,
    /// Lateral position of the centroid at the end (m).
    pub y_out_m: f64,
    /// The sensor pins' decisions on the part, in the order they read it (none without
    /// sensors); written as one field, `pin=decision (posterior)` separated by `; `.
    #[serde(serialize_with = "super::sensing::serialize_sensed")]
    pub sensed: Vec<super::sensing::SensedDecision>,
}

/// The path of a sample part: world poses at successive instants (s, pose).
#[derive(Debug, Clone, PartialEq)]
pub struct SamplePath {
    /// Index of the part in the stream.
    pub part: u64,
    /// How the part ended.
    pub outcome: PartOutcome,
    /// World poses (x, y in m, θ in radians) at successive times (s), ascending.
    pub poses: Vec<(f64, Pose)>,
}

/// One push as the line asked for it (see [`super::line::run_capturing`]): the part's own model
/// when it has one (a random tripod), the obstacle, the pose at the first touch and the settings,
/// and whether the line recorded its path.
#[derive(Clone)]
pub struct CapturedPush {
    /// The obstacle's index in the scene.
    pub obstacle: usize,
    /// The part's own contact model (a random tripod), None for the scene's model.
    pub model: Option<PartModel>,
    /// The pin or fence that pushed.
    pub pusher: Pusher,
    /// The part's world pose at the first touch.
    pub pose: Pose,
    /// The contact-model settings of the push (the pin's μc, tolerance, fidelity).
    pub settings: ContactSettings,
    /// Whether the line recorded the push's path as it computed it.
    pub recorded: bool,
}

/// Everything a run produces.
#[derive(Debug, Clone)]
pub struct RunResult {
    /// The deterministic summary of the run.
    pub summary: Summary,
    /// The raw accumulators the summary was built from.
    pub metrics: Metrics,
    /// Per-part records, if asked for.
    pub records: Vec<PartRecord>,
    /// Every event taken off the queue, if the scene's event log is on.
    pub events: Vec<Event>,
    /// Paths of the first `RunOptions::sample_paths` parts.
    pub paths: Vec<SamplePath>,
    /// What the controller did (decisions, actuations, late ones), when the event log is on or
    /// sample paths are recorded; empty without dynamic pins.
    pub control: Vec<super::controller::ControlRecord>,
}
