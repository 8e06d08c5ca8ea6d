//! Contact end (docs/physics.md#the-line): the push is over. A push that stops the part
//! (multi-contact, jam, off the belt, solver) takes it off the line; otherwise the part rides on
//! from where the push left it, unless it lies beyond the belt's edge, and its next event is
//! planned and its new motion checked against the other parts.

use super::controller::Control;
use super::exit::finish;
use super::motion::{Motion, Stop};
use super::outcome::{Cause, PartOutcome};
use super::plan::ride_on;
use super::state::{Belt, Sinks, Touch};
use crate::geometry::Pose;
use crate::scenario::Scene;

/// The push of part `touch.part` by obstacle `touch.obstacle` ends at `touch.t`: the obstacle's
/// busy time counts it, and the part is taken off or put back on the belt.
pub(super) fn contact_end(
    scene: &Scene,
    control: Option<&mut Control>,
    belt: &mut Belt,
    sinks: &mut Sinks,
    touch: Touch,
) {
    let (t, index, j) = (touch.t, touch.part, touch.obstacle);
    let Some(mut part) = belt.active.remove(&index) else {
        return;
    };
    let Motion::Held(plan) = &part.motion else {
        unreachable!("contact end for a free part");
    };
    sinks.metrics.obstacles[j].busy_s += (plan.t_end - plan.t_begin).max(0.0);
    if let Some(stop) = plan.stop.clone() {
        belt.active.insert(index, part);
        let end = match stop {
            Stop::MultiContact { cause } => (PartOutcome::MultiContact, cause),
            Stop::Jam { cause } => (PartOutcome::Jam, cause),
            Stop::OffBelt => (PartOutcome::OffBelt, Cause::None),
            Stop::Solver { cause } => (PartOutcome::Solver, cause),
        };
        finish(scene, control, belt, sinks, index, t, end);
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
    if pose.y.abs() > scene.belt.width / 2.0 {
        belt.active.insert(index, part);
        let end = (PartOutcome::OffBelt, Cause::None);
        finish(scene, control, belt, sinks, index, t, end);
        return;
    }
    let work = &mut sinks.metrics.work;
    ride_on(scene, control.as_deref(), belt, work, index, part, t);
}
