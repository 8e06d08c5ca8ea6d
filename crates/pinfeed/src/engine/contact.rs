//! Contact begin: a part touches an obstacle and the contact model gives the whole push (docs/physics.md#fences,
//! #the-line).
//!
//! In order: the obstacle becomes a [`Pusher`] with its contact settings ([`pusher_for`]); the push
//! is run (recording its knots for a sensor pin); a grazing touch lets the part ride on, a pin
//! inside the part ends it as `multi_contact`; otherwise the push becomes a [`ContactPlan`] whose
//! [`Stop`] comes from the contact status ([`stop_of`]). The plan is then cut short where a
//! neighbouring obstacle touches the part during the push (`sweep_neighbours`, the
//! `second_obstacle` multi-contact) and where a fence carries the part's centroid across the belt's
//! edge ([`edge_crossing`], off the belt). A sample part's path records the push
//! (`record_path`).

use super::contact_map::{push_contact, LineMaps, PushRequest};
use super::controller::{capsule_during, pin_motion, Control};
use super::event_queue::{EventKind, EventQueue};
use super::exit::finish;
use super::metrics::WorkCounters;
use super::motion::{ContactPlan, Motion, Pusher, Stop};
use super::online_decide::online_reading;
use super::outcome::{Cause, PartOutcome};
use super::overlap::{capsule_clearance, first_touch};
use super::pairs::check_pairs;
use super::plan::ride_on;
use super::reading::sense;
use super::results::CapturedPush;
use super::sensing::SensedPass;
use super::state::{ActivePart, Belt, Sinks, Touch};
use super::trace::TraceKind;
use crate::geometry::{Pose, Vec2};
use crate::mechanics::{
    ContactOutcome, ContactSettings, ContactStatus, PartModel, PinPath, SolveFailure,
};
use crate::scenario::{Obstacle, RejectOn, Scene, SensorPin};
use crate::sensing::classify::Decision;
use crate::sensing::signal::KnotRecorder;

/// Grazing touches in a row after which a part is taken off as a `solver` outcome (cause
/// `grazing_loop`) rather than handed between obstacles for ever.
const MAX_GRAZES: u32 = 16;

/// Part `touch.part` touches obstacle `touch.obstacle` at `touch.t`: run the push (from `maps`
/// where the tier answers it) and hold the part until it ends, or take it off the line at once.
/// A sensor pin reads the push (`seed`: the run's) and, with a controller, schedules its decision.
pub(super) fn contact_begin(
    scene: &Scene,
    seed: u64,
    maps: Option<&LineMaps>,
    control: Option<&mut Control>,
    belt: &mut Belt,
    sinks: &mut Sinks,
    touch: Touch,
) {
    let (t, index, j) = (touch.t, touch.part, touch.obstacle);
    let v = scene.belt.speed;
    let Some(mut part) = belt.active.remove(&index) else {
        return; // the part has already left the line
    };
    let Motion::Free { t0, pose, .. } = part.motion else {
        unreachable!("contact begin for a held part");
    };
    let obstacle = &scene.obstacles[j];
    let placed = match obstacle {
        Obstacle::Pin(pin) => Some(pin_motion(control.as_deref(), v, j, pin, t0)),
        Obstacle::Fence(_) => None,
    };
    let (pusher, settings) = pusher_for(obstacle, &scene.contact, placed);
    // The push is recorded as it is computed when anything will look at its path: a sensor
    // pin's signal, a neighbouring obstacle, a fence's edge crossing, a drawn path, or another
    // part on the belt (its overlap check). Never computed twice — except that a push the map
    // tier answers keeps no path, and the overlap check records it if it turns out to need it
    // (see `contact_map`).
    let sensor = sensor_of(obstacle);
    let must_record = sensor.is_some() || must_look_at_path(scene, j, &part);
    let record = must_record || may_look_at_path(scene, belt);
    let mut knots = KnotRecorder::default();
    let request = PushRequest {
        j,
        pusher: &pusher,
        pose,
        settings: &settings,
        record,
        must_record,
    };
    if let Some(list) = sinks.captured.as_mut() {
        list.push(CapturedPush {
            obstacle: j,
            model: part.model.clone(),
            pusher: pusher.clone(),
            pose,
            settings,
            recorded: record,
        });
    }
    let counters = &mut sinks.metrics.work.map_tier;
    let (out, record) = push_contact(scene, maps, counters, &part, request, &mut knots);
    let model = part.model.as_ref().unwrap_or(&scene.part.model);
    sinks.metrics.work.contact_solves += 1;
    sinks.metrics.work.model_evaluations += out.evaluations;
    let obstacle = j as u32;
    let touched = match out.contact || matches!(out.status, ContactStatus::PinInsidePart) {
        true => TraceKind::ContactBegin { obstacle },
        false => TraceKind::Graze { obstacle },
    };
    sinks.note(t, Some(index), touched);
    if matches!(out.status, ContactStatus::PinInsidePart) {
        belt.active.insert(index, part);
        let end = (PartOutcome::MultiContact, Cause::PinInsidePart);
        finish(scene, control, belt, sinks, index, t, end);
        return;
    }
    if !out.contact {
        graze(scene, control, belt, sinks, touch, part);
        return;
    }
    part.grazes = 0;
    let mut reading = None;
    if let Some(sensor) = sensor {
        let pass = (&out, knots.samples.as_slice());
        let (decision, sensed) = sense(scene, seed, sinks, touch, sensor, pass, pose.theta_rad);
        let hypothesis = match sensed.classification.decision {
            Decision::Hypothesis(h) => Some(h as u32),
            Decision::Unknown => None,
        };
        let read = TraceKind::Reading {
            obstacle,
            hypothesis,
        };
        sinks.note(t, Some(index), read);
        part.sensed.push(decision);
        reading = Some(sensed);
    }
    let mut plan = plan_of(j, (t0, pose), pusher, settings, out, t, v);
    let work = &mut sinks.metrics.work;
    if record {
        plan.set_trace(&knots.samples);
        work.traces_recorded += u64::from(sensor.is_none());
    }
    let capsules =
        |nb: usize| capsule_during(control.as_deref(), scene, nb, plan.t_begin, plan.t_end);
    let capsules: Vec<Option<(Vec2, Vec2, f64)>> =
        scene.neighbours[j].iter().map(|&nb| capsules(nb)).collect();
    if let Some(tm) = sweep_neighbours(scene, &mut plan, model, &capsules, work) {
        plan.t_end = tm.max(t);
        plan.stop = Some(Stop::MultiContact {
            cause: Cause::SecondObstacle,
        });
    }
    if let Some(tm) = fence_off_belt(scene, &mut plan, model, work) {
        plan.t_end = tm.max(t);
        plan.stop = Some(Stop::OffBelt);
    }
    part.contacts += 1;
    sinks.metrics.contacts += 1;
    sinks.metrics.obstacles[j].contacts += 1;
    let work = &mut sinks.metrics.work;
    if let Some(path) = part.path.as_mut() {
        record_path(&mut plan, model, v, path, work);
    }
    let gate = scene.closed_loop.as_ref().map(|cl| &cl.gate);
    if let Some(g) = gate.filter(|g| g.decided_by == Some(j)) {
        match g.reject_on {
            RejectOn::Contact => part.gate_call = Some(g.call_touched(plan.t_end)),
            RejectOn::Decision if reading.is_some() => {
                let label = part.sensed.last().and_then(|d| d.label.as_deref());
                part.gate_call = Some(g.call(label, plan.t_end));
            }
            // No pin commands a gate on the belief (it has no `decided_by`).
            RejectOn::Decision | RejectOn::Belief => {}
        }
    }
    if let Some(sensed) = reading {
        schedule_decision(
            control,
            &mut belt.queue,
            index,
            &mut part,
            j,
            &sensed,
            plan.t_end,
        );
    }
    hold(scene, belt, work, touch, part, plan);
}

/// With a controller, a reading becomes a decision once the reading is over (the end of the
/// push, `t_end`) and the controller has computed (its latency).
fn schedule_decision(
    control: Option<&mut Control>,
    queue: &mut EventQueue,
    index: u64,
    part: &mut ActivePart,
    j: usize,
    sensed: &SensedPass,
    t_end: f64,
) {
    let Some(c) = control else {
        return;
    };
    if c.online_model().is_some() {
        // Online: the decided label is kept for the sensor's statistics only; the belief
        // takes the reading itself and the classifier's posterior over the states.
        let decision = match sensed.classification.decision {
            Decision::Hypothesis(h) => Some(h),
            Decision::Unknown => None,
        };
        part.decided.push((j, decision, sensed.truth));
        online_reading(c, queue, part, index, j, sensed, t_end);
        return;
    }
    let c12 = &sensed.classification;
    let h = match c12.decision {
        Decision::Hypothesis(h) => Some(h),
        Decision::Unknown => None,
    };
    let posterior = h.and_then(|h| c12.posterior.as_ref().map(|p| p[h]));
    let decision = c.decision(h, posterior);
    part.decided.push((j, decision, sensed.truth));
    queue.schedule(
        t_end + c.latency(),
        EventKind::Decision {
            part: index,
            obstacle: j as u32,
            hypothesis: decision.map_or(u32::MAX, |h| h as u32),
        },
    );
}

/// Will anything certainly look at the path of a push by obstacle `j` of this part (so that it
/// is recorded as it is computed)?
fn must_look_at_path(scene: &Scene, j: usize, part: &ActivePart) -> bool {
    let sweeps = scene.effects.obstacle_sweeps && !scene.neighbours[j].is_empty();
    let fence_edge = matches!(scene.obstacles[j], Obstacle::Fence(_)) && {
        let [y_min, y_max] = scene.obstacles[j].y_range();
        let (half, a) = (scene.belt.width / 2.0, scene.part.radius);
        y_min - a < -half || y_max + a > half
    };
    sweeps || fence_edge || part.path.is_some()
}

/// May the overlap check with another part on the belt look at the path of a push?
fn may_look_at_path(scene: &Scene, belt: &Belt) -> bool {
    scene.effects.collisions && !belt.active.is_empty()
}

/// The model found only a grazing touch: the obstacle passes without pushing, and the part
/// rides on (unless it has grazed too often in a row).
fn graze(
    scene: &Scene,
    control: Option<&mut Control>,
    belt: &mut Belt,
    sinks: &mut Sinks,
    touch: Touch,
    mut part: ActivePart,
) {
    let (t, index) = (touch.t, touch.part);
    part.grazes += 1;
    if part.grazes > MAX_GRAZES {
        belt.active.insert(index, part);
        let end = (PartOutcome::Solver, Cause::GrazingLoop);
        finish(scene, control, belt, sinks, index, t, end);
        return;
    }
    part.last_obstacle = Some(touch.obstacle);
    let work = &mut sinks.metrics.work;
    ride_on(scene, control.as_deref(), belt, work, index, part, t);
}

/// Hold the part `touch.part` in `plan` from `touch.t`: its contact end is scheduled and its new
/// motion checked against the other parts.
fn hold(
    scene: &Scene,
    belt: &mut Belt,
    work: &mut WorkCounters,
    touch: Touch,
    mut part: ActivePart,
    plan: ContactPlan,
) {
    let (t, index) = (touch.t, touch.part);
    let (t_end, j) = (plan.t_end, plan.obstacle);
    part.motion = Motion::Held(Box::new(plan));
    belt.queue.schedule(
        t_end,
        EventKind::ContactEnd {
            part: index,
            obstacle: j as u32,
        },
    );
    belt.active.insert(index, part);
    check_pairs(scene, belt, work, index, t);
}

/// The obstacle as the contact model takes it, with the settings of its push: a pin's own μc
/// replaces the scene's; a fence's own μf replaces the contact friction inside `push_fence`. A
/// pin stands at `placed`'s centre at the anchor time and follows its path (default: where the
/// scene puts it, still).
pub fn pusher_for(
    obstacle: &Obstacle,
    contact: &ContactSettings,
    placed: Option<(Vec2, PinPath)>,
) -> (Pusher, ContactSettings) {
    match obstacle {
        Obstacle::Pin(pin) => (
            {
                let (centre, path) = placed.unwrap_or((pin.centre, PinPath::constant(0.0)));
                Pusher::Pin {
                    centre,
                    radius: pin.radius,
                    path,
                }
            },
            ContactSettings {
                mu_c: pin.mu_c,
                ..*contact
            },
        ),
        Obstacle::Fence(fence) => (Pusher::Fence(fence.spec()), *contact),
    }
}

/// The sensor on an obstacle, if it is a sensor pin.
fn sensor_of(obstacle: &Obstacle) -> Option<&SensorPin> {
    match obstacle {
        Obstacle::Pin(p) => p.sensor.as_deref(),
        Obstacle::Fence(_) => None,
    }
}

/// Why the line stops a part at the end of a push with contact status `status` (None: it rides
/// on).
pub fn stop_of(status: &ContactStatus) -> Option<Stop> {
    let solver = |cause| Some(Stop::Solver { cause });
    match status {
        ContactStatus::Ok => None,
        ContactStatus::MultiContact { .. } => Some(Stop::MultiContact {
            cause: Cause::Notch,
        }),
        ContactStatus::TravelLimit { .. } => Some(Stop::Jam {
            cause: Cause::TravelLimit,
        }),
        ContactStatus::Jam { .. } => Some(Stop::Jam {
            cause: Cause::FenceAngle,
        }),
        ContactStatus::Solver { failure, .. } => solver(match failure {
            SolveFailure::NoConvergence { .. } => Cause::NoConvergence,
            SolveFailure::NonFinite => Cause::NonFinite,
        }),
        ContactStatus::PinInsidePart => solver(Cause::PinInsidePart),
        ContactStatus::EvaluationLimit { .. } => solver(Cause::EvaluationLimit),
        ContactStatus::EventLimit { .. } => solver(Cause::EventLimit),
        ContactStatus::StepTooSmall { .. } => solver(Cause::StepTooSmall),
        ContactStatus::SelfCheck { .. } => solver(Cause::SelfCheck),
        ContactStatus::Metastable { .. } => solver(Cause::Metastable),
    }
}

/// The plan of a push by obstacle `j` of a part at world pose `pose_ref` at anchor time `t_ref`,
/// touched at time `t_begin`: its contact spans the pin travel from first touch to the end of the
/// last contact; `speed` is the belt's (m/s).
pub(super) fn plan_of(
    j: usize,
    (t_ref, pose_ref): (f64, Pose),
    pusher: Pusher,
    settings: ContactSettings,
    outcome: ContactOutcome,
    t_begin: f64,
    speed: f64,
) -> ContactPlan {
    let s_touch = outcome.travel_to_contact;
    let s_end = outcome
        .segments
        .last()
        .map(|s| s.s_end)
        .unwrap_or(s_touch + outcome.contact_length)
        .max(s_touch);
    let stop = stop_of(&outcome.status);
    ContactPlan {
        obstacle: j,
        t_ref,
        pose_ref,
        pusher,
        settings,
        outcome,
        s_touch,
        s_end,
        t_begin,
        t_end: (t_ref + s_end / speed).max(t_begin),
        stop,
        trace: None,
    }
}

/// Record the push's trace if it was not recorded as it was computed (a second computation,
/// counted).
pub(super) fn ensure_trace(plan: &mut ContactPlan, model: &PartModel, work: &mut WorkCounters) {
    if plan.ensure_trace(model) {
        work.pushes_rerun += 1;
    }
}

/// The earliest time in the push at which another obstacle within reach of the pushing one (the
/// scene's neighbour list) touches the part, following its recorded path; None if none does or
/// the scene does not sweep obstacles.
pub(super) fn sweep_neighbours(
    scene: &Scene,
    plan: &mut ContactPlan,
    model: &PartModel,
    capsules: &[Option<(Vec2, Vec2, f64)>],
    work: &mut WorkCounters,
) -> Option<f64> {
    let neighbours = &scene.neighbours[plan.obstacle];
    if !scene.effects.obstacle_sweeps || neighbours.is_empty() {
        return None;
    }
    ensure_trace(plan, model, work);
    let v = scene.belt.speed;
    let held = Motion::Held(Box::new(plan.clone()));
    let poly = &scene.part.polygon;
    let a = scene.part.radius;
    let breaks = plan.step_times(v);
    let mut earliest: Option<f64> = None;
    // Where each neighbour can be during the push (a withdrawn retractable pin is not there).
    for &(p, q, radius) in capsules.iter().flatten() {
        work.obstacle_sweep_checks += 1;
        let end = earliest.unwrap_or(plan.t_end);
        let mut evals = 0;
        let hit = first_touch(
            plan.t_begin,
            end,
            &breaks,
            &mut |tau| {
                let pose = held.world_pose(tau, v);
                capsule_clearance(p, q, radius, &poly.world_vertices(&pose))
            },
            &|ta, tb| {
                let (p, q) = (held.world_pose(ta, v), held.world_pose(tb, v));
                (q.position() - p.position()).norm() + a * (q.theta_rad - p.theta_rad).abs()
            },
            1e-6 * a,
            &mut evals,
        );
        work.clearance_evaluations += evals;
        if let Some(tm) = hit {
            earliest = Some(earliest.map_or(tm, |e: f64| e.min(tm)));
        }
    }
    earliest
}

/// A fence carries the part across the belt: the time its centroid crosses an edge of the belt
/// during the push, if the fence's reach (its lateral extent plus a) crosses one at all.
fn fence_off_belt(
    scene: &Scene,
    plan: &mut ContactPlan,
    model: &PartModel,
    work: &mut WorkCounters,
) -> Option<f64> {
    let obstacle = &scene.obstacles[plan.obstacle];
    let Obstacle::Fence(_) = obstacle else {
        return None;
    };
    let half = scene.belt.width / 2.0;
    let [y_min, y_max] = obstacle.y_range();
    let a = scene.part.radius;
    let reach_crosses_edge = y_min - a < -half || y_max + a > half;
    if !reach_crosses_edge {
        return None;
    }
    ensure_trace(plan, model, work);
    edge_crossing(plan, scene.belt.speed, half)
}

/// The first time in (t_begin, t_end] at which the held part's centroid lies beyond |y| = `half`
/// (the belt's edge), following the recorded path (linear between steps, as everywhere in the
/// line).
pub fn edge_crossing(plan: &ContactPlan, speed: f64, half: f64) -> Option<f64> {
    let held = Motion::Held(Box::new(plan.clone()));
    let times = plan.path_times(speed);
    let beyond = |t: f64| held.world_pose(t, speed).y.abs() - half;
    let mut prev = (times[0], beyond(times[0]));
    if prev.1 > 0.0 {
        return Some(prev.0);
    }
    for &t in &times[1..] {
        let g = beyond(t);
        if g > 0.0 {
            // Linear between the steps: the crossing of |y| = half (g ≤ 0 before, > 0 now).
            let u = prev.1 / (prev.1 - g);
            return Some(prev.0 + u * (t - prev.0));
        }
        prev = (t, g);
    }
    None
}

/// Append the push's world poses (at first touch, each recorded step and the end) to a sample
/// part's path; `speed` is the belt's (m/s).
fn record_path(
    plan: &mut ContactPlan,
    model: &PartModel,
    speed: f64,
    path: &mut Vec<(f64, Pose)>,
    work: &mut WorkCounters,
) {
    ensure_trace(plan, model, work);
    let held = Motion::Held(Box::new(plan.clone()));
    let times = plan.path_times(speed);
    path.extend(times.iter().map(|&tau| (tau, held.world_pose(tau, speed))));
}
