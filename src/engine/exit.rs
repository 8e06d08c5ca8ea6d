//! A part leaves the line: at the belt's end, where the goal classifies its orientation
//! ([`exit`]), or taken off anywhere with the outcome a stage found ([`finish`]): its metrics,
//! record, sample path and the controller's decision statistics are written once.

use super::controller::Control;
use super::outcome::{Cause, PartOutcome};
use super::results::{PartRecord, SamplePath};
use super::state::{ActivePart, Belt, Sinks};
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
    let pose = part.motion.world_pose(t, scene.belt.speed);
    let theta_deg = wrap_deg(pose.theta_rad.to_degrees());
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
