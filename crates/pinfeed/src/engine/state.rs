//! The run state the stages share, grouped by concern: the parts on the belt and their pending
//! events ([`Belt`]), and what the run has produced so far ([`Sinks`]). Each stage takes only
//! the pieces it reads and writes.

use super::event_queue::{Event, EventKind, EventQueue};
use super::metrics::Metrics;
use super::motion::Motion;
use super::outcome::PartOutcome;
use super::results::{CapturedPush, PartRecord, SamplePath};
use super::sensing::{SensedDecision, SensorStats};
use super::sequential::SequentialStop;
use super::trace::{TraceEvent, TraceKind};
use crate::geometry::Pose;
use crate::mechanics::PartModel;
use crate::scenario::{Obstacle, PinObstacle, Scene};
use std::collections::BTreeMap;

/// A part on the belt: where it came in, how it moves now, and what has happened to it.
pub(super) struct ActivePart {
    pub(super) arrival: f64,
    pub(super) theta_in: f64,
    pub(super) y_in: f64,
    pub(super) motion: Motion,
    /// The obstacle whose push ended last (its pin has passed; it cannot touch the part again: a
    /// still pin's path is behind the part, and a dynamic pin only moves for the next part once
    /// this one has cleared it, see [`super::serve`]).
    pub(super) last_obstacle: Option<usize>,
    pub(super) contacts: u32,
    /// Touches in a row that pushed nothing (grazes): bounded, so that two obstacles that each
    /// only graze the part cannot hand it back and forth for ever at one instant.
    pub(super) grazes: u32,
    /// Own contact model (random tripod), else the scene's.
    pub(super) model: Option<PartModel>,
    pub(super) path: Option<Vec<(f64, Pose)>>,
    /// Sensor pins that have read this part (obstacle index) and their decisions.
    pub(super) sensed: Vec<SensedDecision>,
    /// Decisions taken on this part for the controller: (sensor, decision, true state).
    pub(super) decided: Vec<(usize, Option<usize>, Option<usize>)>,
    /// The part's events are valid from this sequence number on: a part planned again after an
    /// actuator moved leaves its older contact, exit and collision events stale.
    pub(super) valid_from: u64,
    /// Online controller: the part's belief, the sensors still to speak, the prediction its
    /// decision was taken with.
    pub(super) belief: Option<crate::sensing::belief::Belief>,
    pub(super) sensors_left: u32,
    pub(super) predicted: Option<f64>,
    /// A closed loop's gate: its call on this part, once its sensor pin has read it.
    pub(super) gate_call: Option<super::closed_loop::GateCall>,
}

impl ActivePart {
    /// A part entering at time `t` at world pose `pose` with its own contact model (if any),
    /// riding the belt; `path` starts its sample path.
    pub(super) fn entering(t: f64, pose: Pose, model: Option<PartModel>, path: bool) -> Self {
        ActivePart {
            arrival: t,
            theta_in: pose.theta_rad,
            y_in: pose.y,
            motion: Motion::Free {
                t0: t,
                pose,
                until: t,
            },
            last_obstacle: None,
            contacts: 0,
            grazes: 0,
            model,
            path: path.then(|| vec![(t, pose)]),
            sensed: Vec::new(),
            decided: Vec::new(),
            valid_from: 0,
            belief: None,
            sensors_left: 0,
            predicted: None,
            gate_call: None,
        }
    }
}

/// The belt: the pending events, the parts on it (by index in the stream) and how many have
/// left it.
pub(super) struct Belt {
    pub(super) queue: EventQueue,
    pub(super) active: BTreeMap<u64, ActivePart>,
    pub(super) finished: u64,
    /// A closed loop's gate, return path and merge (None: an open line).
    pub(super) closed_loop: Option<super::closed_loop::LoopState>,
    /// New parts fed so far (arrivals processed).
    pub(super) fed: u64,
    /// `run --precision`: the rule that stops the feed (None: the feed runs to its parts).
    pub(super) stop: Option<SequentialStop>,
}

impl Belt {
    /// An empty belt with nothing scheduled.
    pub(super) fn new() -> Belt {
        Belt {
            queue: EventQueue::new(),
            active: BTreeMap::new(),
            finished: 0,
            closed_loop: None,
            fed: 0,
            stop: None,
        }
    }

    /// Has `run --precision`'s rule stopped the feed?
    pub(super) fn feed_stopped(&self) -> bool {
        self.stop.as_ref().is_some_and(SequentialStop::stopped)
    }

    /// Is event `kind` (taken off the queue with sequence number `seq`) stale: planned before a
    /// part it concerns was planned again?
    pub(super) fn stale(&self, seq: u64, kind: &EventKind) -> bool {
        let older = |part: &u64| self.active.get(part).is_some_and(|p| seq < p.valid_from);
        match kind {
            EventKind::ContactBegin { part, .. } | EventKind::Exit { part } => older(part),
            EventKind::Collision { first, second } => older(first) || older(second),
            _ => false,
        }
    }
}

/// What the run produces: the metrics and the records it keeps as asked.
pub(super) struct Sinks {
    pub(super) metrics: Metrics,
    /// Every part's record, when the run keeps them.
    pub(super) records: Option<Vec<PartRecord>>,
    /// Every event, when the scene logs them.
    pub(super) events: Vec<Event>,
    pub(super) paths: Vec<SamplePath>,
    /// Every push as asked for, when the run captures them ([`super::run_capturing`]).
    pub(super) captured: Option<Vec<CapturedPush>>,
    /// How and where the last part to finish left the line ([`super::run_single`]).
    pub(super) last_end: Option<(PartOutcome, Pose)>,
    /// Sensor pins (obstacle index, index into `metrics.sensors`); empty in a passive scene.
    pub(super) sensor_pins: Vec<(usize, usize)>,
    /// The trace's events not yet handed on, when the run is traced ([`super::trace`]).
    pub(super) trace: Option<Vec<TraceEvent>>,
}

impl Sinks {
    /// Empty sinks for a run of `scene`: statistics for every obstacle and sensor pin, records
    /// when the run keeps them (`keep_records`), captured pushes when `captured` is given.
    pub(super) fn for_scene(
        scene: &Scene,
        keep_records: bool,
        captured: Option<Vec<CapturedPush>>,
    ) -> Sinks {
        let names = scene
            .obstacles
            .iter()
            .map(|o| o.name().to_string())
            .collect();
        let mut metrics = Metrics::new(names, scene.output.histogram_bin_deg);
        let mut sensor_pins = Vec::new();
        for (j, o) in scene.obstacles.iter().enumerate() {
            if let Obstacle::Pin(PinObstacle {
                name,
                sensor: Some(sensor),
                ..
            }) = o
            {
                sensor_pins.push((j, metrics.sensors.len()));
                metrics.sensors.push(SensorStats::new(name, sensor));
            }
        }
        Sinks {
            metrics,
            records: keep_records.then(Vec::new),
            events: Vec::new(),
            paths: Vec::new(),
            captured,
            last_end: None,
            sensor_pins,
            trace: None,
        }
    }

    /// Note `kind` at `t` of `entry` in the trace, when the run is traced (else nothing).
    #[inline]
    pub(super) fn note(&mut self, t: f64, entry: Option<u64>, kind: TraceKind) {
        if let Some(trace) = self.trace.as_mut() {
            trace.push(TraceEvent { t, entry, kind });
        }
    }
}

/// An event of one part at one obstacle: a contact begin or end.
#[derive(Debug, Clone, Copy)]
pub(super) struct Touch {
    /// Time of the event (s).
    pub(super) t: f64,
    /// Index of the part in the stream.
    pub(super) part: u64,
    /// Index of the obstacle in `Scene::obstacles`.
    pub(super) obstacle: usize,
}
