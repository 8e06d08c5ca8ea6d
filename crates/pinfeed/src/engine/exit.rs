//! A part leaves the line: at the belt's end, where the goal classifies its orientation
//! ([`exit`]), or taken off anywhere with the outcome a stage found ([`finish`]): its metrics,
//! record, sample path and the controller's decision statistics are written once.

use super::controller::Control;
use super::outcome::{Cause, PartOutcome};
use super::results::{PartRecord, SamplePath};
use super::state::{ActivePart, Belt, Sinks};
use super::trace::TraceKind;
use crate::geometry::wrap_deg;
use crate::scenario::{Obstacle, Scene};

/// Part `index` reaches the belt's end at time `t`: success if its orientation is in the goal,
/// else wrong orientation. A part already gone is left alone.
pub(super) fn exit(
    scene: &Scene,
    control: Option<&mut Control>,
    belt: &mut Belt,
    sinks: &mut Sinks,
    t: f64,
    index: u64,
) {
    let Some(part) = belt.active.get(&index) else {
        return;
    };
    let pose = part.motion.world_pose(t, scene.belt.speed);
    let (call, predicted) = (part.gate_call, part.predicted);
    if let Some(lp) = belt.closed_loop.as_mut() {
        if lp.gate_takes(index, t, pose.y, call, predicted) {
            divert(scene, belt, sinks, index, t);
            return;
        }
    }
    let outcome = if scene.goal.matching_set(pose.theta_rad).is_some() {
        PartOutcome::Success
    } else {
        PartOutcome::WrongOrientation
    };
    finish(
        scene,
        control,
        belt,
        sinks,
        index,
        t,
        (outcome, Cause::None),
    );
}

/// Take part `index` off the line at time `t` with `end` (its outcome and cause), if it is still
/// on the belt.
pub(super) fn finish(
    scene: &Scene,
    control: Option<&mut Control>,
    belt: &mut Belt,
    sinks: &mut Sinks,
    index: u64,
    t: f64,
    (outcome, cause): (PartOutcome, Cause),
) {
    let Some(mut part) = belt.active.remove(&index) else {
        return;
    };
    if let Some(lp) = belt.closed_loop.as_mut() {
        lp.finished(index, t, outcome);
    }
    let pose = part.motion.world_pose(t, scene.belt.speed);
    let theta_deg = wrap_deg(pose.theta_rad.to_degrees());
    let end = match outcome.exited() {
        true => TraceKind::Exit { outcome, pose },
        false => TraceKind::Loss {
            outcome,
            cause,
            pose,
        },
    };
    sinks.note(t, Some(index), end);
    sinks.last_end = Some((outcome, pose));
    sinks
        .metrics
        .finish(outcome, t, theta_deg, t - part.arrival);
    if let Some(c) = control {
        c.count_decisions(scene, &part.decided, outcome);
        if let Some(p) = part.predicted {
            c.calibrate(p, outcome == PartOutcome::Success);
        }
    }
    count_untouched(scene, sinks, &part, pose.x);
    sinks.metrics.cause(outcome, cause);
    if let Some(records) = sinks.records.as_mut() {
        records.push(PartRecord {
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
        sinks.paths.push(SamplePath {
            part: index,
            outcome,
            poses,
        });
    }
    belt.finished += 1;
}

/// The closed loop's gate takes part `index` off the belt at its end at time `t`: it goes to the
/// return path (or out of the line); the sensors it passed count it, and it ends in no outcome
/// class (the loop counts it).
fn divert(scene: &Scene, belt: &mut Belt, sinks: &mut Sinks, index: u64, t: f64) {
    let Some(mut part) = belt.active.remove(&index) else {
        return;
    };
    count_untouched(scene, sinks, &part, scene.belt.length);
    let pose = part.motion.world_pose(t, scene.belt.speed);
    sinks.note(t, Some(index), TraceKind::Reject { pose });
    let lp = belt.closed_loop.as_mut().expect("a gate");
    lp.rejected(index, t, part.model.take(), &mut belt.queue);
    belt.finished += 1;
}

/// A part leaving the line at world x `x` has gone past every sensor pin upstream of it: those
/// that did not read it count it as untouched.
fn count_untouched(scene: &Scene, sinks: &mut Sinks, part: &ActivePart, x: f64) {
    for &(j, k) in &sinks.sensor_pins {
        let passed = match &scene.obstacles[j] {
            Obstacle::Pin(p) => p.centre.x < x,
            Obstacle::Fence(_) => false,
        };
        if passed && !part.sensed.iter().any(|d| d.obstacle == j) {
            sinks.metrics.sensors[k].untouched += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Pose;

    fn quickstart() -> Scene {
        crate::scenario::load(&crate::project_path("scenarios/quickstart.toml")).unwrap()
    }

    /// A belt holding part 0 at rest at the belt's end (x = length) with orientation `deg`.
    fn belt_with_part_at_end(scene: &Scene, deg: f64) -> Belt {
        let mut belt = Belt::new();
        let pose = Pose::new(scene.belt.length, 0.0, deg.to_radians());
        belt.active
            .insert(0, ActivePart::entering(1.0, pose, None, false));
        belt
    }

    /// The quickstart's goal is 16° ± 3°: a part at 17° exits as a success, one at 40° with the
    /// wrong orientation; each is counted once, with its record, however often its exit comes.
    #[test]
    fn exit_classifies_the_part_by_the_goal_and_counts_it_once() {
        let scene = quickstart();
        for (deg, outcome) in [
            (17.0, PartOutcome::Success),
            (40.0, PartOutcome::WrongOrientation),
        ] {
            let mut belt = belt_with_part_at_end(&scene, deg);
            let mut sinks = Sinks::for_scene(&scene, true, None);
            exit(&scene, None, &mut belt, &mut sinks, 2.0, 0);
            exit(&scene, None, &mut belt, &mut sinks, 3.0, 0);
            assert!(belt.active.is_empty());
            assert_eq!(belt.finished, 1);
            assert_eq!(sinks.metrics.outcomes.total(), 1);
            assert_eq!(sinks.metrics.outcomes.get(outcome), 1, "{deg}°");
            let records = sinks.records.as_ref().unwrap();
            assert_eq!(records.len(), 1);
            assert_eq!((records[0].outcome, records[0].end_s), (outcome, 2.0));
            assert_eq!(records[0].arrival_s, 1.0);
            assert_eq!(sinks.last_end.map(|(o, _)| o), Some(outcome));
        }
    }

    /// A part taken off with an outcome and cause keeps them in its record, and a run that keeps
    /// no records writes none.
    #[test]
    fn finish_writes_the_outcome_and_cause_and_keeps_records_only_when_asked() {
        let scene = quickstart();
        for keep in [true, false] {
            let mut belt = belt_with_part_at_end(&scene, 17.0);
            let mut sinks = Sinks::for_scene(&scene, keep, None);
            let end = (PartOutcome::Jam, Cause::TravelLimit);
            finish(&scene, None, &mut belt, &mut sinks, 0, 2.0, end);
            assert_eq!(sinks.metrics.outcomes.get(PartOutcome::Jam), 1);
            assert_eq!(belt.finished, 1);
            match sinks.records {
                Some(r) => assert_eq!((r[0].outcome, r[0].cause), end),
                None => assert!(!keep),
            }
        }
    }
}
