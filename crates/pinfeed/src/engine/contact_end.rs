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
use super::trace::TraceKind;
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
    let obstacle = j as u32;
    sinks.note(t, Some(index), TraceKind::ContactEnd { obstacle });
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::contact::contact_begin;
    use crate::engine::event_queue::EventKind;
    use crate::engine::plan::ride_on;
    use crate::engine::state::ActivePart;

    /// The quickstart's scene with part 0 entered at orientation 1 rad and held by the first
    /// pin it meets; returns the belt, the sinks and its contact end.
    fn held_part() -> (Scene, Belt, Sinks, Touch) {
        let path = &crate::project_path("scenarios/quickstart.toml");
        let scene = crate::scenario::load(path).unwrap();
        let mut belt = Belt::new();
        let mut sinks = Sinks::for_scene(&scene, true, None);
        let part = ActivePart::entering(0.0, Pose::new(0.0, 0.0, 1.0), None, false);
        ride_on(
            &scene,
            None,
            &mut belt,
            &mut sinks.metrics.work,
            0,
            part,
            0.0,
        );
        let ev = belt.queue.pop().unwrap();
        let EventKind::ContactBegin { part: 0, obstacle } = ev.kind else {
            panic!("the part meets a pin first: {ev:?}");
        };
        let touch = Touch {
            t: ev.time,
            part: 0,
            obstacle: obstacle as usize,
        };
        contact_begin(&scene, 1, None, None, &mut belt, &mut sinks, touch);
        let ev = belt.queue.pop().unwrap();
        assert_eq!(ev.kind, EventKind::ContactEnd { part: 0, obstacle });
        let end = Touch {
            t: ev.time,
            ..touch
        };
        (scene, belt, sinks, end)
    }

    /// At the end of a push that does not stop it, the part rides on from where the push left it,
    /// with the pushing pin behind it: free from the end time, its next event planned (not the
    /// same pin again), and the pin's busy time counting the push.
    #[test]
    fn contact_end_puts_the_part_back_on_the_belt() {
        let (scene, mut belt, mut sinks, end) = held_part();
        let Motion::Held(plan) = &belt.active[&0].motion else {
            panic!("held");
        };
        let (busy, pose_end) = (plan.t_end - plan.t_begin, plan.outcome.pose_final);
        let x_end = pose_end.x + plan.s_end;
        assert!(busy > 0.0);
        contact_end(&scene, None, &mut belt, &mut sinks, end);
        let part = &belt.active[&0];
        let Motion::Free { t0, pose, until } = part.motion else {
            panic!("the part rides on");
        };
        assert_eq!((t0, pose.x, pose.y), (end.t, x_end, pose_end.y));
        assert!(until >= end.t);
        assert_eq!(part.last_obstacle, Some(end.obstacle));
        assert_eq!(sinks.metrics.obstacles[end.obstacle].busy_s, busy);
        assert_eq!(belt.finished, 0);
        let next = belt.queue.pop().expect("the part's next event");
        assert_eq!(next.time, until);
        assert_ne!(
            next.kind,
            EventKind::ContactBegin {
                part: 0,
                obstacle: end.obstacle as u32
            }
        );
    }

    /// A push that ends in a stop (here a jam at the travel limit) takes the part off the line at
    /// its end, with the stop's outcome and cause.
    #[test]
    fn contact_end_takes_a_stopped_part_off_the_line() {
        let (scene, mut belt, mut sinks, end) = held_part();
        let Motion::Held(plan) = &mut belt.active.get_mut(&0).unwrap().motion else {
            panic!("held");
        };
        plan.stop = Some(Stop::Jam {
            cause: Cause::TravelLimit,
        });
        contact_end(&scene, None, &mut belt, &mut sinks, end);
        assert!(belt.active.is_empty());
        assert_eq!(belt.finished, 1);
        assert_eq!(sinks.metrics.outcomes.get(PartOutcome::Jam), 1);
        let record = &sinks.records.as_ref().unwrap()[0];
        assert_eq!((record.cause, record.end_s), (Cause::TravelLimit, end.t));
    }
}
