//! The feeder line as a discrete-event simulation (docs/physics.md#the-line; the data flow in `src/lib.rs`).
//!
//! Parts arrive (periodic or Poisson, at x = 0 with a random orientation and lateral offset), ride
//! the belt, are pushed by pins and fences and leave at x = belt length. Each part is, at any time,
//! either free (riding the belt) or held (being pushed); see [`super::motion`]. Its next event is
//! always known: from a free state the first touch (belt frame) over every obstacle gives the next
//! contact begin, else the exit — for a pin the first-contact ray cast the contact model uses, for
//! a fence [`crate::mechanics::fence_first_touch`]; the earliest obstacle wins. At contact begin the
//! contact model ([`crate::mechanics::push`], [`crate::mechanics::push_fence`]) gives the whole
//! push and so the contact end. Events are processed in time order, ties by sequence number
//! ([`super::event_queue`]).
//!
//! Detection (never silent mis-simulation):
//! * **two obstacles at once**: when a push starts, each obstacle close enough to the pushing one
//!   to be reached (distance between pin discs and fence segments ≤ 2a, precomputed per scene) is
//!   checked against the part's recorded path during the push; a touch ends the push there as
//!   `multi_contact`. The contact model itself reports a pin in a concave notch (also
//!   `multi_contact`). See [`super::contact`].
//! * **part–part overlap**: whenever a part's motion changes (arrival, contact begin, contact end),
//!   its new motion is checked against every other part on the belt over the time both motions are
//!   known (until the earlier of their next events). Every interval of time in which two parts
//!   coexist starts at such a change of one of them, so every overlap is found. A broad phase
//!   (bounding capsules in the belt frame) skips distant pairs; close pairs are resolved in time
//!   with [`super::overlap::first_touch`]. The first overlap schedules a collision event; both
//!   parts are taken off the line then, unless one of them has already gone.
//!   Only while two or more parts share the belt does this run (`work.part_part_checks`). See
//!   [`super::pairs`].
//! * **off the belt**: after a push, a centroid outside |y| ≤ width/2 means the part falls off. A
//!   fence carries parts across the belt, so during a fence push whose reach (the fence's lateral
//!   extent plus a: the centroid stays within a of the contact on the fence) crosses an edge the
//!   recorded path is checked too, and the part falls off where its centroid crosses the edge
//!   ([`super::contact`]).
//! * **jam**: an obstacle that holds the part for good: a pin still pushing it after the contact
//!   model's travel limit (cause `travel_limit`), or a fence at α + atan μf ≥ 90° against which the
//!   part stops in the world while the belt slips under it (cause `fence_angle`, docs/physics.md#fences). A real
//!   line would stop there; the simulator counts the part and takes it off at that instant, so the
//!   parts behind it are still measured.
//! * **solver**: any other failure of the contact model, with its cause.
//!
//! Every part that enters ends in exactly one class ([`super::outcome`]); the run asserts it. What a
//! run takes and gives is in [`super::results`].

use super::contact_map::LineMaps;
use super::controller::Control;
use super::event_queue::{Event, EventKind, EventQueue};
use super::metrics::Metrics;
use super::motion::{Motion, Stop};
use super::outcome::{Cause, PartOutcome};
use super::part_stream::{arrival_gap, draw_part};
use super::results::{CapturedPush, EngineError, PartRecord, RunOptions, RunResult, SamplePath};
use super::sensing::{sense_pass, SensedDecision, SensedPass, SensorStats};
use crate::geometry::{wrap_deg, Pose};
use crate::mechanics::{
    fence_first_touch, pin_first_touch, ContactOutcome, PartModel, TraceSample,
};
use crate::scenario::{Arrival, Obstacle, PinObstacle, Scene, SensorPin};
use crate::sensing::signal::SignalScale;
use std::collections::BTreeMap;

/// A part on the belt: where it came in, how it moves now, and what has happened to it.
pub(super) struct ActivePart {
    arrival: f64,
    theta_in: f64,
    y_in: f64,
    pub(super) motion: Motion,
    /// The obstacle whose push ended last (its pin has passed; it cannot touch the part again: a
    /// still pin's path is behind the part, and a dynamic pin only moves for the next part once
    /// this one has cleared it, see [`super::controller`]).
    pub(super) last_obstacle: Option<usize>,
    pub(super) contacts: u32,
    /// Touches in a row that pushed nothing (grazes): bounded, so that two obstacles that each
    /// only graze the part cannot hand it back and forth for ever at one instant.
    pub(super) grazes: u32,
    /// Own contact model (random tripod), else the scene's.
    pub(super) model: Option<PartModel>,
    pub(super) path: Option<Vec<(f64, Pose)>>,
    /// Sensor pins that have read this part (obstacle index) and their decisions.
    pub(super) sensed: Vec<super::sensing::SensedDecision>,
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
}

/// The run state: the scene it runs, the event queue, the parts on the belt and what they have
/// produced so far. Its event handlers live here and beside it in [`super::contact`] (contact
/// begin) and [`super::pairs`] (part–part checks).
pub(super) struct Line<'a> {
    pub(super) scene: &'a Scene,
    opts: &'a RunOptions,
    pub(super) queue: EventQueue,
    pub(super) active: BTreeMap<u64, ActivePart>,
    pub(super) metrics: Metrics,
    records: Vec<PartRecord>,
    events: Vec<Event>,
    paths: Vec<SamplePath>,
    finished: u64,
    /// Sensor pins (obstacle index, index into `metrics.sensors`); empty in a passive scene.
    sensor_pins: Vec<(usize, usize)>,
    /// The controller and the dynamic pins' timelines (None without dynamic pins).
    pub(super) control: Option<Control>,
    /// The pins' maps (None unless `[model] fidelity = "map"`).
    pub(super) maps: Option<LineMaps>,
    /// Every push as asked for, when the run captures them ([`run_capturing`]).
    pub(super) captured: Option<Vec<CapturedPush>>,
    /// A forced first part ([`run_entry`]): its pose and support instead of the feed's draw.
    entry: Option<Entry>,
    /// How and where the last part to finish left the line ([`run_single`]).
    last_end: Option<(PartOutcome, Pose)>,
}

/// One part with a given entry pose and support, for [`run_entry`].
#[derive(Debug, Clone)]
pub struct Entry {
    /// Orientation at entry (radians).
    pub theta_rad: f64,
    /// Lateral offset of the centroid at entry (m).
    pub y: f64,
    /// Position of the centroid along the belt at entry (m; 0 is the line's start). The part
    /// arrives at time 0 wherever it enters, so a start past 0 suits a line whose pins stand
    /// still (the online model's stages), not one whose pins keep time.
    pub x: f64,
    /// The part's own contact model (a tripod), else the scene's.
    pub model: Option<PartModel>,
}

/// Run the line with one part entering as `entry` says (instead of a draw from the feed), keeping
/// its record and, with `capture`, every push it met: what the online controller's model
/// predicts a hypothesis does on the line ([`super::online`]). Same engine, same detection.
pub fn run_entry(
    scene: &Scene,
    entry: Entry,
    capture: bool,
) -> Result<(PartRecord, Vec<CapturedPush>), EngineError> {
    let opts = RunOptions {
        parts: 1,
        seed: scene.seed,
        sample_paths: 0,
        keep_records: true,
        online: None,
    };
    let (mut r, captured) = run_inner(
        scene,
        &opts,
        &mut |_| {},
        capture.then(Vec::new),
        Some(entry),
    )?;
    let record = r.records.pop().expect("one part, one record");
    Ok((record, captured))
}

/// How a part entering as [`Entry`] says left a line, with no summary or record assembled: the
/// online model runs the line this way hundreds of thousands of times.
#[derive(Debug, Clone)]
pub struct SingleRun {
    /// How the part left the line.
    pub outcome: PartOutcome,
    /// The part's world pose when it left (at the belt's end when it exited).
    pub pose: Pose,
    /// Contact-model evaluations the run took (the work counter of the same name).
    pub model_evaluations: u64,
}

/// Run one part entering as `entry` says through `scene`, and return only how and where it
/// left (see [`SingleRun`]).
pub fn run_single(scene: &Scene, entry: Entry) -> Result<SingleRun, EngineError> {
    let opts = RunOptions {
        parts: 1,
        seed: scene.seed,
        sample_paths: 0,
        keep_records: false,
        online: None,
    };
    let line = simulate(scene, &opts, &mut |_| {}, None, Some(entry))?;
    let (outcome, pose) = line.last_end.expect("one part, one end");
    Ok(SingleRun {
        outcome,
        pose,
        model_evaluations: line.metrics.work.model_evaluations,
    })
}

/// Run the line: a pure function of (scene, options). `progress` is called with the number of
/// finished parts from time to time.
///
/// ```
/// use pinfeed::engine::{run, PartOutcome, RunOptions};
/// use std::path::Path;
///
/// let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/quickstart.toml");
/// let scene = pinfeed::scenario::load(&path).unwrap();
/// let opts = RunOptions { parts: 100, ..RunOptions::from_scene(&scene) };
/// let result = run(&scene, &opts, &mut |_| {}).unwrap();
/// assert_eq!(result.summary.parts_in, 100);
/// // The quickstart line orients every part.
/// assert_eq!(result.summary.outcomes.get(PartOutcome::Success), 100);
/// ```
pub fn run(
    scene: &Scene,
    opts: &RunOptions,
    progress: &mut dyn FnMut(u64),
) -> Result<RunResult, EngineError> {
    run_with(scene, opts, progress, None).map(|(r, _)| r)
}

/// As [`run`], also returning every push the line asked of the contact model (or the map tier),
/// in order: what `pinfeed bench line` runs again as a bare batch to see what the line adds.
pub fn run_capturing(
    scene: &Scene,
    opts: &RunOptions,
) -> Result<(RunResult, Vec<CapturedPush>), EngineError> {
    run_with(scene, opts, &mut |_| {}, Some(Vec::new()))
}

fn run_with(
    scene: &Scene,
    opts: &RunOptions,
    progress: &mut dyn FnMut(u64),
    captured: Option<Vec<CapturedPush>>,
) -> Result<(RunResult, Vec<CapturedPush>), EngineError> {
    run_inner(scene, opts, progress, captured, None)
}

fn run_inner(
    scene: &Scene,
    opts: &RunOptions,
    progress: &mut dyn FnMut(u64),
    captured: Option<Vec<CapturedPush>>,
    entry: Option<Entry>,
) -> Result<(RunResult, Vec<CapturedPush>), EngineError> {
    let mut line = simulate(scene, opts, progress, captured, entry)?;
    let fidelity = match scene.map_tier {
        Some(_) => "map",
        None => scene.contact.fidelity.name(),
    };
    let mut summary = line.metrics.summary(&scene.name, opts.seed, fidelity);
    let mut control_log = Vec::new();
    if let Some(c) = line.control.as_mut() {
        summary.controller = Some(c.finish(summary.simulated_time_s));
        control_log = c.log.take().unwrap_or_default();
    }
    let result = RunResult {
        summary,
        metrics: line.metrics,
        records: line.records,
        events: line.events,
        paths: line.paths,
        control: control_log,
    };
    Ok((result, line.captured.unwrap_or_default()))
}

/// Process every event of the run and return the line as it ends.
fn simulate<'a>(
    scene: &'a Scene,
    opts: &'a RunOptions,
    progress: &mut dyn FnMut(u64),
    captured: Option<Vec<CapturedPush>>,
    entry: Option<Entry>,
) -> Result<Line<'a>, EngineError> {
    let online = match &opts.online {
        Some(m) => Some(m.clone()),
        None => super::prepare::online_model(scene).map_err(EngineError::OnlineModel)?,
    };
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
    let mut line = Line {
        scene,
        opts,
        queue: EventQueue::new(),
        active: BTreeMap::new(),
        metrics,
        records: Vec::new(),
        events: Vec::new(),
        paths: Vec::new(),
        finished: 0,
        sensor_pins,
        control: Control::new(
            scene,
            scene.effects.event_log || opts.sample_paths > 0,
            online,
        ),
        maps: LineMaps::for_scene(scene),
        captured,
        entry,
        last_end: None,
    };
    if opts.parts > 0 {
        line.queue.schedule(0.0, EventKind::Arrival { part: 0 });
    }
    loop {
        if let Some((time, kind)) = line.queue.first_refused() {
            return Err(EngineError::NonFiniteTime {
                time,
                kind,
                refused: line.queue.refused(),
            });
        }
        let Some(ev) = line.queue.pop() else { break };
        line.handle(ev)?;
        if line.finished % 256 == 0 {
            progress(line.finished);
        }
    }
    progress(line.finished);
    assert!(
        line.active.is_empty(),
        "parts left on the belt after the last event"
    );
    assert_eq!(
        line.metrics.outcomes.total(),
        line.metrics.parts_in,
        "conservation: every part that enters ends in exactly one class"
    );
    assert_eq!(line.metrics.parts_in, opts.parts);
    Ok(line)
}

impl Line<'_> {
    pub(super) fn speed(&self) -> f64 {
        self.scene.belt.speed
    }

    fn handle(&mut self, ev: Event) -> Result<(), EngineError> {
        if self.control.is_some() && self.stale(ev.seq, &ev.kind) {
            self.metrics.work.stale_events += 1;
            return Ok(());
        }
        self.metrics.work.events += 1;
        self.metrics.last_event = self.metrics.last_event.max(ev.time);
        if self.scene.effects.event_log {
            self.events.push(ev);
        }
        let t = ev.time;
        match ev.kind {
            EventKind::Arrival { part } => self.arrival(t, part)?,
            EventKind::ContactBegin { part, obstacle } => {
                self.contact_begin(t, part, obstacle as usize)
            }
            EventKind::ContactEnd { part, obstacle } => {
                self.contact_end(t, part, obstacle as usize)
            }
            EventKind::Exit { part } => self.exit(t, part),
            EventKind::Collision { first, second } => {
                if self.active.contains_key(&first) && self.active.contains_key(&second) {
                    self.finish(first, t, PartOutcome::Collision, Cause::None);
                    self.finish(second, t, PartOutcome::Collision, Cause::None);
                }
            }
            EventKind::Decision {
                part,
                obstacle,
                hypothesis,
            } => {
                let h = (hypothesis != u32::MAX).then_some(hypothesis as usize);
                self.decide(t, part, obstacle as usize, h);
            }
            EventKind::Unread { part, obstacle } => self.unread(t, part, obstacle as usize),
        }
        // A part that moved on may have freed a dynamic pin for the next command.
        if self.control.is_some() {
            self.serve(t);
        }
        Ok(())
    }

    fn arrival(&mut self, t: f64, index: u64) -> Result<(), EngineError> {
        let mut x0 = 0.0;
        let d = match self.entry.take() {
            Some(e) => {
                x0 = e.x;
                super::part_stream::PartDraw {
                    gap: 0.0,
                    theta_rad: e.theta_rad,
                    y: e.y,
                    model: e.model,
                }
            }
            None => draw_part(self.scene, self.opts.seed, index)
                .map_err(|reason| EngineError::PartDraw { index, reason })?,
        };
        if d.model.is_some() {
            self.metrics.work.tripods_drawn += 1;
        }
        self.metrics.arrival(t);
        if index + 1 < self.opts.parts {
            let next = match self.scene.feed.arrival {
                Arrival::Periodic { headway } => (index + 1) as f64 * headway,
                Arrival::Poisson { .. } => t + arrival_gap(self.scene, self.opts.seed, index + 1),
            };
            self.queue
                .schedule(next, EventKind::Arrival { part: index + 1 });
        }
        let pose = Pose::new(x0, d.y, d.theta_rad);
        let mut part = ActivePart {
            arrival: t,
            theta_in: d.theta_rad,
            y_in: d.y,
            motion: Motion::Free {
                t0: t,
                pose,
                until: t,
            },
            last_obstacle: None,
            contacts: 0,
            grazes: 0,
            model: d.model,
            path: ((index as usize) < self.opts.sample_paths).then(|| vec![(t, pose)]),
            sensed: Vec::new(),
            decided: Vec::new(),
            valid_from: 0,
            belief: None,
            sensors_left: 0,
            predicted: None,
        };
        self.online_arrival(t, index, &mut part);
        self.plan_next(index, &mut part, t);
        self.active.insert(index, part);
        self.check_pairs(index, t);
        Ok(())
    }

    /// From a free state, find the next event: the first obstacle the part will touch (first-contact
    /// ray cast for a pin, first touch of a fence, in the belt frame exactly as the contact model
    /// finds them), or the exit.
    pub(super) fn plan_next(&mut self, index: u64, part: &mut ActivePart, now: f64) {
        let Motion::Free { t0, pose, .. } = part.motion else {
            unreachable!("plan_next on a held part");
        };
        let v = self.speed();
        let a = self.scene.part.radius;
        let scene = self.scene;
        let model = part.model.as_ref().unwrap_or(&scene.part.model);
        let mut best: Option<(f64, usize)> = None;
        for (j, ob) in scene.obstacles.iter().enumerate() {
            if Some(j) == part.last_obstacle {
                continue;
            }
            // Out of lateral reach, or already behind the part: the obstacle's path misses it.
            let ([x_min, x_max], [y_min, y_max]) = (ob.x_range(), ob.y_range());
            if y_min > pose.y + a || y_max < pose.y - a || x_max < pose.x - a {
                continue;
            }
            // Farther ahead than the earliest touch found so far: the part must ride at least
            // x_min − (x + a) of belt before it can touch (an obstacle moves across the belt
            // only), so this one cannot come first, nor tie.
            if best.is_some_and(|(b, _)| x_min - (pose.x + a) > b) {
                continue;
            }
            self.metrics.work.ray_casts += 1;
            let travel = match ob {
                // Along the pin's path (a moving pin's commanded motion from t0 on); a
                // retractable pin withdrawn when the part would reach it lets it pass.
                Obstacle::Pin(pin) => {
                    let (start, path) = self.pin_motion(j, pin, t0);
                    pin_first_touch(model, pose, start, pin.radius, &path)
                        .filter(|&tr| self.present_at(j, t0 + tr / v))
                }
                Obstacle::Fence(fence) => fence_first_touch(model, pose, &fence.spec()),
            };
            if let Some(tr) = travel {
                if best.is_none_or(|(b, _)| tr < b) {
                    best = Some((tr, j));
                }
            }
        }
        let length = self.scene.belt.length;
        let t_exit = if pose.x >= length {
            now
        } else {
            (t0 + (length - pose.x) / v).max(now)
        };
        let until = match best {
            Some((travel, j)) if t0 + travel / v < t_exit => {
                let tb = (t0 + travel / v).max(now);
                self.queue.schedule(
                    tb,
                    EventKind::ContactBegin {
                        part: index,
                        obstacle: j as u32,
                    },
                );
                tb
            }
            _ => {
                self.queue.schedule(t_exit, EventKind::Exit { part: index });
                t_exit
            }
        };
        part.motion = Motion::Free { t0, pose, until };
    }

    fn contact_end(&mut self, t: f64, index: u64, j: usize) {
        let Some(mut part) = self.active.remove(&index) else {
            return;
        };
        let Motion::Held(plan) = &part.motion else {
            unreachable!("contact end for a free part");
        };
        self.metrics.obstacles[j].busy_s += (plan.t_end - plan.t_begin).max(0.0);
        if let Some(stop) = plan.stop.clone() {
            self.active.insert(index, part);
            let (outcome, cause) = match stop {
                Stop::MultiContact { cause } => (PartOutcome::MultiContact, cause),
                Stop::Jam { cause } => (PartOutcome::Jam, cause),
                Stop::OffBelt => (PartOutcome::OffBelt, Cause::None),
                Stop::Solver { cause } => (PartOutcome::Solver, cause),
            };
            self.finish(index, t, outcome, cause);
            return;
        }
        let end = plan.outcome.pose_final;
        let pose = Pose::new(end.x + plan.s_end, end.y, end.theta_rad);
        if let Some(path) = part.path.as_mut() {
            path.push((t, pose));
        }
        part.motion = Motion::Free {
            t0: t,
            pose,
            until: t,
        };
        part.last_obstacle = Some(j);
        if pose.y.abs() > self.scene.belt.width / 2.0 {
            self.active.insert(index, part);
            self.finish(index, t, PartOutcome::OffBelt, Cause::None);
            return;
        }
        self.plan_next(index, &mut part, t);
        self.active.insert(index, part);
        self.check_pairs(index, t);
    }

    fn exit(&mut self, t: f64, index: u64) {
        let Some(part) = self.active.get(&index) else {
            return;
        };
        let pose = part.motion.world_pose(t, self.speed());
        let outcome = if self.scene.goal.matching_set(pose.theta_rad).is_some() {
            PartOutcome::Success
        } else {
            PartOutcome::WrongOrientation
        };
        self.finish(index, t, outcome, Cause::None);
    }

    /// Take part `index` off the line at time `t` with `outcome`.
    pub(super) fn finish(&mut self, index: u64, t: f64, outcome: PartOutcome, cause: Cause) {
        let Some(mut part) = self.active.remove(&index) else {
            return;
        };
        let pose = part.motion.world_pose(t, self.speed());
        let theta_deg = wrap_deg(pose.theta_rad.to_degrees());
        self.last_end = Some((outcome, pose));
        self.metrics.finish(outcome, t, theta_deg, t - part.arrival);
        if let Some(c) = self.control.as_mut() {
            c.count_decisions(self.scene, &part.decided, outcome);
            if let Some(p) = part.predicted {
                c.calibrate(p, outcome == PartOutcome::Success);
            }
        }
        self.count_untouched(&part, pose.x);
        self.metrics.cause(outcome, cause);
        if self.opts.keep_records {
            self.records.push(PartRecord {
                part: index,
                arrival_s: part.arrival,
                end_s: t,
                outcome,
                cause,
                contacts: part.contacts,
                theta_in_deg: wrap_deg(part.theta_in.to_degrees()),
                theta_out_deg: theta_deg,
                y_in_m: part.y_in,
                y_out_m: pose.y,
                sensed: std::mem::take(&mut part.sensed),
            });
        }
        if let Some(mut poses) = part.path {
            if poses.last().is_none_or(|&(tl, _)| tl < t) {
                poses.push((t, pose));
            }
            self.paths.push(SamplePath {
                part: index,
                outcome,
                poses,
            });
        }
        self.finished += 1;
    }

    /// Read and classify a pass against a sensor pin: the sensor's statistics count it, and the
    /// decision (as text for the part's record) is returned (see [`super::sensing`]).
    pub(super) fn sense(
        &mut self,
        index: u64,
        j: usize,
        sensor: &SensorPin,
        out: &ContactOutcome,
        knots: &[TraceSample],
        theta: f64,
    ) -> (super::sensing::SensedDecision, SensedPass) {
        let scale = SignalScale {
            mass: self.scene.part.mass,
            belt_speed: self.speed(),
            height: sensor.settings.height,
            metres_per_unit: 1.0,
        };
        let sensed = sense_pass(sensor, out, knots, &scale, theta, self.opts.seed, index, j);
        self.metrics.work.sensor_readings += 1;
        self.metrics.work.signal_knots += sensed.knots as u64;
        self.metrics.work.classifications += 1;
        if let Some(&(_, k)) = self.sensor_pins.iter().find(|(o, _)| *o == j) {
            self.metrics.sensors[k].add(&sensed);
        }
        let name = self.scene.obstacles[j].name();
        let decision = SensedDecision::of(j, name, &sensor.labels, &sensed.classification);
        (decision, sensed)
    }

    /// A part leaving the line at world x `x` has gone past every sensor pin upstream of it:
    /// those that did not read it count it as untouched.
    fn count_untouched(&mut self, part: &ActivePart, x: f64) {
        for &(j, k) in &self.sensor_pins {
            let passed = match &self.scene.obstacles[j] {
                Obstacle::Pin(p) => p.centre.x < x,
                Obstacle::Fence(_) => false,
            };
            if passed && !part.sensed.iter().any(|d| d.obstacle == j) {
                self.metrics.sensors[k].untouched += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quickstart() -> Scene {
        crate::scenario::load(std::path::Path::new("scenarios/quickstart.toml")).unwrap()
    }

    fn entry(theta_rad: f64) -> Entry {
        Entry {
            theta_rad,
            y: 0.0,
            x: 0.0,
            model: None,
        }
    }

    /// A line without obstacles only carries the part: it leaves at the belt's end with the
    /// orientation and offset it entered with, and the contact model is never called.
    #[test]
    fn an_empty_line_carries_the_part_unchanged_and_calls_no_model() {
        let mut scene = quickstart();
        scene.obstacles.clear();
        for theta in [0.0, 1.0, 4.0] {
            let r = run_single(&scene, entry(theta)).unwrap();
            assert!(r.outcome.exited(), "{:?}", r.outcome);
            assert_eq!(r.pose.theta_rad.rem_euclid(std::f64::consts::TAU), theta);
            assert_eq!(r.pose.y, 0.0);
            assert_eq!(r.model_evaluations, 0);
        }
    }

    /// The same entry through the same line ends the same way to the bit, and a part that meets
    /// the quickstart's pins is pushed: the model is called and the orientation changes.
    #[test]
    fn a_pushed_part_ends_the_same_way_every_time() {
        let scene = quickstart();
        let a = run_single(&scene, entry(1.0)).unwrap();
        let b = run_single(&scene, entry(1.0)).unwrap();
        assert_eq!(
            (a.outcome, a.pose, a.model_evaluations),
            (b.outcome, b.pose, b.model_evaluations)
        );
        assert!(a.model_evaluations > 0);
        assert_ne!(a.pose.theta_rad.rem_euclid(std::f64::consts::TAU), 1.0);
    }
}
