//! The online controller in the event engine (docs/physics.md#controller): a sensor pin's reading becomes a
//! decision, the decision (after the controller's computation latency) becomes commands for the
//! dynamic pins through the rules, and each command becomes an actuator motion with its real
//! timing ([`super::actuator`]).
//!
//! Each dynamic pin serves the parts in their order: a pin moves for part p only when every
//! earlier part still within its reach (centroid short of x_pin + a + ρ) is known to clear it,
//! and the move must be over (settled) before part p can reach the pin (its centroid at
//! x_pin − a − ρ, riding the belt from where it is now — a part held by an obstacle only comes
//! later, so the deadline is safe). A command that cannot finish in time is a **late
//! actuation**, counted, and handled as `[controller] on_late` says: `skip` leaves the pin as it
//! is for that part, `move` moves anyway (the part may then meet a pin in motion, which the
//! contact model follows with its true velocity). A command whose part is gone is dropped.
//!
//! When a pin's timeline changes, every free part that could still reach it is planned again:
//! its pending contact or exit event goes stale (the part remembers the sequence number from
//! which its events are valid, and older ones are dropped when they come off the queue), and its
//! part–part checks run again. A scene without dynamic pins has no controller and does none of
//! this (`work.decisions`, `work.actuator_commands`, `work.replans`, `work.stale_events` stay 0).

use super::actuator::Track;
use super::event_queue::EventKind;
use super::line::Line;
use super::motion::Motion;
use super::outcome::PartOutcome;
use crate::geometry::Vec2;
use crate::mechanics::PinPath;
use crate::scenario::{Actuator, Controller, Obstacle, OnLate, PinObstacle, Scene, Target};
use serde::Serialize;
use std::collections::BTreeMap;

/// What the controller did, for the event log and the animation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ControlRecord {
    /// Seconds.
    pub t: f64,
    pub part: u64,
    /// The sensor (for a decision) or the dynamic pin (for an actuation).
    pub obstacle: String,
    /// `decision`, `actuation`, `late`, `dropped`.
    pub kind: &'static str,
    /// The decision's label, or the target (`y=0.012` / `raised` / `withdrawn`).
    pub what: String,
    /// An actuation's motion: start, ready (s), and a moving pin's lateral positions (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionRecord>,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MotionRecord {
    pub t_start: f64,
    pub t_ready: f64,
    pub from: f64,
    pub to: f64,
}

/// Per dynamic pin: commands and motion.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct ActuatorStats {
    pub name: String,
    pub commands: u64,
    /// Commands carried out by a motion (a command for the state the pin is in needs none).
    pub moves: u64,
    pub late: u64,
    pub dropped: u64,
    /// Lateral travel of a moving pin (m).
    pub travel_m: f64,
    /// Time in motion (s), and as a share of the simulated time.
    pub busy_s: f64,
    pub utilisation: f64,
}

/// Parts per decision and how many of them ended well.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct DecisionStats {
    pub parts: u64,
    pub success: u64,
    /// Decisions that differ from the part's true state, and of those the parts that failed.
    pub wrong: u64,
    pub wrong_failed: u64,
}

/// The controller's part of the summary.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct ControllerSummary {
    /// "scenario" or the policy file.
    pub rules_from: String,
    pub latency_s: f64,
    pub on_late: &'static str,
    /// Per sensor and decision (`<sensor>=<label>`, `unknown` for none).
    pub decisions: BTreeMap<String, DecisionStats>,
    pub misclassified: u64,
    pub misclassified_failed: u64,
    pub late_actuations: u64,
    pub actuators: Vec<ActuatorStats>,
}

/// The controller's run state.
pub(super) struct Control {
    spec: Controller,
    /// Per obstacle: its timeline if it is a dynamic pin.
    pub(super) tracks: Vec<Option<Track>>,
    /// Per obstacle: targets waiting for their part's turn, by part.
    queues: Vec<BTreeMap<u64, Target>>,
    pub(super) summary: ControllerSummary,
    /// Per obstacle: index into `summary.actuators`.
    stats_of: Vec<Option<usize>>,
    pub(super) log: Option<Vec<ControlRecord>>,
}

impl Control {
    /// The controller of a scene with dynamic pins (None without: a passive or sensing-only
    /// scene runs none of this).
    pub(super) fn new(scene: &Scene, keep_log: bool) -> Option<Control> {
        let mut tracks = Vec::new();
        let mut stats_of = Vec::new();
        let mut summary = ControllerSummary::default();
        for o in &scene.obstacles {
            let track = match o {
                Obstacle::Pin(PinObstacle {
                    actuator: Some(Actuator::Moving(m)),
                    ..
                }) => Some(Track::moving(*m)),
                Obstacle::Pin(PinObstacle {
                    actuator: Some(Actuator::Retractable(r)),
                    ..
                }) => Some(Track::retractable(*r)),
                _ => None,
            };
            stats_of.push(track.as_ref().map(|_| {
                summary.actuators.push(ActuatorStats {
                    name: o.name().to_string(),
                    ..ActuatorStats::default()
                });
                summary.actuators.len() - 1
            }));
            tracks.push(track);
        }
        if tracks.iter().all(Option::is_none) {
            return None;
        }
        let spec = scene.controller.clone().unwrap_or(Controller {
            latency: 0.0,
            min_posterior: 0.0,
            on_late: OnLate::Skip,
            rules: Vec::new(),
            source: "none".into(),
        });
        summary.rules_from = spec.source.clone();
        summary.latency_s = spec.latency;
        summary.on_late = spec.on_late.name();
        Some(Control {
            queues: vec![BTreeMap::new(); tracks.len()],
            spec,
            tracks,
            summary,
            stats_of,
            log: keep_log.then(Vec::new),
        })
    }

    pub(super) fn latency(&self) -> f64 {
        self.spec.latency
    }

    /// The decision a reading stands for once the posterior threshold is applied.
    pub(super) fn decision(
        &self,
        hypothesis: Option<usize>,
        posterior: Option<f64>,
    ) -> Option<usize> {
        hypothesis.filter(|_| posterior.is_none_or(|p| p >= self.spec.min_posterior))
    }

    /// A part has finished with `outcome`: count its decisions and, for a wrong one, whether the
    /// part failed.
    pub(super) fn count_decisions(
        &mut self,
        scene: &Scene,
        decided: &[(usize, Option<usize>, Option<usize>)],
        outcome: PartOutcome,
    ) {
        let ok = outcome == PartOutcome::Success;
        for &(sensor, decision, truth) in decided {
            let label = decision_label(scene, sensor, decision);
            let wrong = decision.is_some() && truth.is_some() && decision != truth;
            let row = self
                .summary
                .decisions
                .entry(format!("{}={label}", scene.obstacles[sensor].name()))
                .or_default();
            row.parts += 1;
            row.success += u64::from(ok);
            row.wrong += u64::from(wrong);
            row.wrong_failed += u64::from(wrong && !ok);
            self.summary.misclassified += u64::from(wrong);
            self.summary.misclassified_failed += u64::from(wrong && !ok);
        }
    }

    fn log(&mut self, r: ControlRecord) {
        if let Some(l) = self.log.as_mut() {
            l.push(r);
        }
    }

    /// Close the summary at the end of the run (`span`: simulated time, s).
    pub(super) fn finish(&mut self, span: f64) -> ControllerSummary {
        for a in &mut self.summary.actuators {
            a.utilisation = if span > 0.0 { a.busy_s / span } else { 0.0 };
        }
        self.summary.late_actuations = self.summary.actuators.iter().map(|a| a.late).sum();
        self.summary.clone()
    }
}

/// A decision of sensor pin `sensor` as its hypothesis label, or `unknown`.
fn decision_label(scene: &Scene, sensor: usize, decision: Option<usize>) -> String {
    match (decision, &scene.obstacles[sensor]) {
        (Some(h), Obstacle::Pin(p)) => p
            .sensor
            .as_ref()
            .map_or_else(|| "?".into(), |s| s.labels[h].clone()),
        _ => "unknown".into(),
    }
}

fn describe_target(t: Target) -> String {
    match t {
        Target::Y(y) => format!("y={y}"),
        Target::Raised(true) => "raised".into(),
        Target::Raised(false) => "withdrawn".into(),
    }
}

impl Line<'_> {
    /// Where pin `j` stands at time `t0` and the path it follows from then on.
    pub(super) fn pin_motion(&self, j: usize, pin: &PinObstacle, t0: f64) -> (Vec2, PinPath) {
        match (&self.control, &pin.actuator) {
            (Some(c), Some(Actuator::Moving(m))) => {
                let track = c.tracks[j].as_ref().expect("a moving pin has a track");
                let y = track.y_at(t0, pin.centre.y);
                let path = track.path_from(t0, self.speed(), m.pieces);
                (Vec2::new(pin.centre.x, y), path)
            }
            _ => (pin.centre, PinPath::constant(0.0)),
        }
    }

    /// Is obstacle `j` present at time `t` (a withdrawn or moving-in retractable pin is not)?
    pub(super) fn present_at(&self, j: usize, t: f64) -> bool {
        match &self.control {
            Some(c) => c.tracks[j].as_ref().is_none_or(|tr| tr.present_at(t)),
            None => true,
        }
    }

    /// Where obstacle `j` can be during [ta, tb], as a capsule (None: absent throughout).
    pub(super) fn capsule_during(&self, j: usize, ta: f64, tb: f64) -> Option<(Vec2, Vec2, f64)> {
        let ob = &self.scene.obstacles[j];
        let Some(track) = self.control.as_ref().and_then(|c| c.tracks[j].as_ref()) else {
            return Some(ob.capsule());
        };
        let Obstacle::Pin(pin) = ob else {
            return Some(ob.capsule());
        };
        match track {
            Track::Moving { .. } => {
                let (lo, hi) = track.y_span(ta, tb, pin.centre.y);
                Some((
                    Vec2::new(pin.centre.x, lo),
                    Vec2::new(pin.centre.x, hi),
                    pin.radius,
                ))
            }
            Track::Retractable { .. } => track
                .present_during(ta, tb)
                .then_some((pin.centre, pin.centre, pin.radius)),
        }
    }

    /// A sensor's decision on part `index` reaches the controller: the rules turn it into
    /// commands.
    pub(super) fn decide(&mut self, t: f64, index: u64, sensor: usize, decision: Option<usize>) {
        let Some(c) = self.control.as_mut() else {
            return;
        };
        self.metrics.work.decisions += 1;
        let label = decision_label(self.scene, sensor, decision);
        let name = self.scene.obstacles[sensor].name().to_string();
        c.log(ControlRecord {
            t,
            part: index,
            obstacle: name,
            kind: "decision",
            what: label,
            motion: None,
        });
        let commands: Vec<(usize, Target)> = c
            .spec
            .rules
            .iter()
            .filter(|r| r.sensor == sensor && r.decides == decision)
            .map(|r| (r.pin, r.target))
            .collect();
        for (pin, target) in commands {
            self.metrics.work.actuator_commands += 1;
            c.queues[pin].insert(index, target);
            if let Some(k) = c.stats_of[pin] {
                c.summary.actuators[k].commands += 1;
            }
        }
        self.serve(t);
    }

    /// Carry out every queued command whose turn has come (see the module notes).
    pub(super) fn serve(&mut self, now: f64) {
        let Some(c) = self.control.as_ref() else {
            return;
        };
        let pending: Vec<usize> = (0..c.queues.len())
            .filter(|&j| !c.queues[j].is_empty())
            .collect();
        for j in pending {
            while self.serve_next(j, now) {}
        }
    }

    /// Serve the first queued command of pin `j` if its turn has come; true if one was taken.
    fn serve_next(&mut self, j: usize, now: f64) -> bool {
        let v = self.speed();
        let Obstacle::Pin(pin) = &self.scene.obstacles[j] else {
            return false;
        };
        let reach = self.scene.part.radius + pin.radius;
        let x_pin = pin.centre.x;
        let c = self.control.as_ref().expect("serving needs a controller");
        let Some((&part, &target)) = c.queues[j].first_key_value() else {
            return false;
        };
        // No later part may be in contact with the pin (it came first: wait until it is done).
        let later_in_use = self
            .active
            .range(part + 1..)
            .any(|(_, q)| matches!(&q.motion, Motion::Held(plan) if plan.obstacle == j));
        if later_in_use {
            return false;
        }
        // Every earlier part still within reach must be known to clear the pin.
        let mut t_free = now;
        for qp in self.active.range(..part).map(|(_, p)| p) {
            let x = qp.motion.world_pose(now, v).x;
            if x >= x_pin + reach {
                continue;
            }
            match qp.motion {
                Motion::Free { t0, pose, until } => {
                    let t_clear = t0 + (x_pin + reach - pose.x) / v;
                    if until < t_clear {
                        return false; // it meets an obstacle first: wait
                    }
                    t_free = t_free.max(t_clear);
                }
                // Held by an obstacle: when it clears is not known yet.
                Motion::Held(_) => return false,
            }
        }
        let c = self.control.as_mut().expect("serving needs a controller");
        c.queues[j].remove(&part);
        let name = pin.name.clone();
        let k = c.stats_of[j].expect("a dynamic pin has statistics");
        let Some(p) = self.active.get(&part) else {
            c.summary.actuators[k].dropped += 1;
            c.log(ControlRecord {
                t: now,
                part,
                obstacle: name,
                kind: "dropped",
                what: describe_target(target),
                motion: None,
            });
            return true;
        };
        // The earliest time the part can reach the pin: riding the belt from where it is. A part
        // already held by this pin is too late for any motion: a pin in use never moves.
        let x_part = p.motion.world_pose(now, v).x;
        let in_use = matches!(&p.motion, Motion::Held(plan) if plan.obstacle == j);
        let t_reach = if in_use {
            f64::NEG_INFINITY
        } else {
            now + (x_pin - reach - x_part) / v
        };
        let track = c.tracks[j].as_mut().expect("a dynamic pin has a track");
        let t_start = t_free.max(track.ready_at());
        let (duration, travel) = track.cost(target);
        let late = t_start + duration > t_reach;
        let from = match track.final_target() {
            Target::Y(y) => y,
            Target::Raised(up) => f64::from(u8::from(up)),
        };
        if late {
            c.summary.actuators[k].late += 1;
            self.metrics.work.late_actuations += 1;
        }
        // A late move that could only start once the part is past the pin is pointless.
        let passed_by_then = t_start >= t_reach + 2.0 * reach / v;
        let carry_out = duration > 0.0
            && (!late || (c.spec.on_late == OnLate::Move && !in_use && !passed_by_then));
        if carry_out {
            track.command(t_start, target);
            let a = &mut c.summary.actuators[k];
            a.moves += 1;
            a.travel_m += travel;
            a.busy_s += duration;
            let to = match target {
                Target::Y(y) => y,
                Target::Raised(up) => f64::from(u8::from(up)),
            };
            c.log(ControlRecord {
                t: now,
                part,
                obstacle: name,
                kind: if late { "late" } else { "actuation" },
                what: describe_target(target),
                motion: Some(MotionRecord {
                    t_start,
                    t_ready: t_start + duration,
                    from,
                    to,
                }),
            });
            self.replan_near(j, now);
        } else if late {
            c.log(ControlRecord {
                t: now,
                part,
                obstacle: name,
                kind: "late",
                what: format!("{} skipped", describe_target(target)),
                motion: None,
            });
        }
        true
    }

    /// Pin `j`'s timeline has changed: plan again every free part that could still reach it.
    fn replan_near(&mut self, j: usize, now: f64) {
        let v = self.speed();
        let [_, x_max] = self.scene.obstacles[j].x_range();
        let reach = self.scene.part.radius;
        let parts: Vec<u64> = self
            .active
            .iter()
            .filter(|(_, p)| {
                matches!(p.motion, Motion::Free { .. })
                    && p.motion.world_pose(now, v).x < x_max + reach
            })
            .map(|(&k, _)| k)
            .collect();
        let oldest = self
            .active
            .values()
            .filter_map(|p| match p.motion {
                Motion::Free { t0, .. } => Some(t0),
                Motion::Held(_) => None,
            })
            .fold(now, f64::min);
        if let Some(track) = self.control.as_mut().and_then(|c| c.tracks[j].as_mut()) {
            track.forget_before(oldest);
        }
        for index in parts {
            let Some(mut part) = self.active.remove(&index) else {
                continue;
            };
            self.metrics.work.replans += 1;
            part.valid_from = self.queue.next_seq();
            self.plan_next(index, &mut part, now);
            self.active.insert(index, part);
            self.check_pairs(index, now);
        }
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
