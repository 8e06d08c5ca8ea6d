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
}

impl RunOptions {
    /// The scene's own settings: its number of parts and seed, nothing recorded.
    pub fn from_scene(scene: &Scene) -> RunOptions {
        RunOptions {
            parts: scene.feed.parts,
            seed: scene.seed,
            sample_paths: 0,
            keep_records: false,
        }
    }
}

/// Why a run could not be carried out.
#[derive(Debug, Error)]
pub enum EngineError {
    #[error("part {index}: {reason}")]
    PartDraw { index: u64, reason: String },
    /// An event time came out non-finite (NaN or ±∞): the scene's numbers leave f64. Validated
    /// scenarios never get here; the engine refuses instead of panicking.
    #[error("an event time is not finite ({kind:?} at {time} s; {refused} event(s) refused): the scene's numbers are out of range (see docs/scenario-format.md)")]
    NonFiniteTime {
        time: f64,
        kind: EventKind,
        refused: u64,
    },
}

/// One finished part.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PartRecord {
    pub part: u64,
    pub arrival_s: f64,
    pub end_s: f64,
    pub outcome: &'static str,
    /// Cause behind multi_contact or solver, else empty.
    pub cause: &'static str,
    pub contacts: u32,
    pub theta_in_deg: f64,
    pub theta_out_deg: f64,
    pub y_in_m: f64,
    pub y_out_m: f64,
    /// Sensor decisions, `pin=decision (posterior)` separated by `; ` (empty without sensors).
    pub sensed: String,
}

/// The path of a sample part: world poses at successive instants (s, pose).
#[derive(Debug, Clone, PartialEq)]
pub struct SamplePath {
    pub part: u64,
    pub outcome: PartOutcome,
    pub poses: Vec<(f64, Pose)>,
}

/// One push as the line asked for it (see [`super::line::run_capturing`]): the part's own model
/// when it has one (a random tripod), the obstacle, the pose at the first touch and the settings,
/// and whether the line recorded its path.
#[derive(Clone)]
pub struct CapturedPush {
    /// The obstacle's index in the scene.
    pub obstacle: usize,
    pub model: Option<PartModel>,
    pub pusher: Pusher,
    pub pose: Pose,
    pub settings: ContactSettings,
    pub recorded: bool,
}

/// Everything a run produces.
#[derive(Debug, Clone)]
pub struct RunResult {
    pub summary: Summary,
    pub metrics: Metrics,
    /// Per-part records, if asked for.
    pub records: Vec<PartRecord>,
    /// Every event taken off the queue, if the scene's event log is on.
    pub events: Vec<Event>,
    pub paths: Vec<SamplePath>,
    /// What the controller did (decisions, actuations, late ones), when the event log is on or
    /// sample paths are recorded; empty without dynamic pins.
    pub control: Vec<super::controller::ControlRecord>,
}
