//! Arrival (docs/physics.md#the-line): part i enters the belt with the pose and support its own
//! random stream draws (or as a forced [`Entry`] says), the next arrival is scheduled, and the
//! part's first event is planned and its motion checked against the other parts.

use super::controller::Control;
use super::event_queue::EventKind;
use super::line::Entry;
use super::online_decide::online_arrival;
use super::part_stream::{arrival_gap, draw_part, draw_reentry, PartDraw};
use super::plan::ride_on;
use super::results::{EngineError, RunOptions};
use super::state::{ActivePart, Belt, Sinks};
use super::trace::TraceKind;
use crate::geometry::Pose;
use crate::scenario::{Arrival, Scene};

/// Part `index` arrives at time `t`: drawn from the feed (or `entry`), it goes on the belt.
/// With a closed loop's merge it joins the parts waiting there instead (see [`merge`]).
#[allow(clippy::too_many_arguments)]
pub(super) fn arrival(
    scene: &Scene,
    opts: &RunOptions,
    entry: Option<Entry>,
    control: Option<&Control>,
    belt: &mut Belt,
    sinks: &mut Sinks,
    t: f64,
    index: u64,
) -> Result<(), EngineError> {
    if let Some(lp) = belt.closed_loop.as_mut().filter(|l| l.merges()) {
        lp.new_part(index, t);
        schedule_next(scene, opts, belt, t, index);
        return merge(scene, opts, control, belt, sinks, t);
    }
    let metrics = &mut sinks.metrics;
    let mut x0 = 0.0;
    let d = match entry {
        Some(e) => {
            x0 = e.x;
            metrics.work.tripods_drawn += u64::from(e.model.is_some());
            PartDraw {
                gap: 0.0,
                theta_rad: e.theta_rad,
                y: e.y,
                model: e.model,
            }
        }
        None => fresh_part(scene, opts.seed, index, metrics)?,
    };
    if let Some(lp) = belt.closed_loop.as_mut() {
        lp.open_entry(index, t);
    }
    schedule_next(scene, opts, belt, t, index);
    let pose = Pose::new(x0, d.y, d.theta_rad);
    enter(
        scene,
        opts,
        control,
        belt,
        sinks,
        t,
        (index, index, 0),
        pose,
        d.model,
    );
    Ok(())
}

/// Part `index` as the feed draws it (its random tripod counted).
fn fresh_part(
    scene: &Scene,
    seed: u64,
    index: u64,
    metrics: &mut super::metrics::Metrics,
) -> Result<PartDraw, EngineError> {
    let d =
        draw_part(scene, seed, index).map_err(|reason| EngineError::PartDraw { index, reason })?;
    if d.model.is_some() {
        metrics.work.tripods_drawn += 1;
    }
    Ok(d)
}

/// The feed's next part after part `index` (arrived at `t`), unless it was the last.
fn schedule_next(scene: &Scene, opts: &RunOptions, belt: &mut Belt, t: f64, index: u64) {
    if index + 1 < opts.parts {
        let next = match scene.feed.arrival {
            Arrival::Periodic { headway } => (index + 1) as f64 * headway,
            Arrival::Poisson { .. } => t + arrival_gap(scene, opts.seed, index + 1),
        };
        belt.queue
            .schedule(next, EventKind::Arrival { part: index + 1 });
    }
}

/// A closed loop's merge at `t`: when it is free and a part waits, the part enters the belt as
/// the next entry (a returning one with a new pose and its own support, a new one as the feed
/// drew it).
pub(super) fn merge(
    scene: &Scene,
    opts: &RunOptions,
    control: Option<&Control>,
    belt: &mut Belt,
    sinks: &mut Sinks,
    t: f64,
) -> Result<(), EngineError> {
    let metrics = &mut sinks.metrics;
    let Some(lp) = belt.closed_loop.as_mut() else {
        return Ok(());
    };
    let Some(e) = lp.merge(t, &mut belt.queue) else {
        return Ok(());
    };
    let (theta, y, model) = match e.model {
        Some(model) => {
            let (theta, y) = draw_reentry(scene, opts.seed, e.part, e.pass);
            (theta, y, model)
        }
        None => {
            let d = fresh_part(scene, opts.seed, e.part, metrics)?;
            (d.theta_rad, d.y, d.model)
        }
    };
    let pose = Pose::new(0.0, y, theta);
    let id = (e.entry, e.part, e.pass);
    enter(scene, opts, control, belt, sinks, t, id, pose, model);
    Ok(())
}

/// Entry `entry` (part `part` on its pass `pass`, 0 for its first) goes on the belt at `t` at
/// world pose `pose` with its own support `model` (if any): it is counted in and traced, its
/// first event is planned and its motion checked against the other parts.
#[allow(clippy::too_many_arguments)]
fn enter(
    scene: &Scene,
    opts: &RunOptions,
    control: Option<&Control>,
    belt: &mut Belt,
    sinks: &mut Sinks,
    t: f64,
    (entry, part, pass): (u64, u64, u32),
    pose: Pose,
    model: Option<crate::mechanics::PartModel>,
) {
    sinks.metrics.arrival(t);
    let entered = match pass {
        0 => TraceKind::Arrival { part, pose },
        _ => TraceKind::Reentry { part, pass, pose },
    };
    sinks.note(t, Some(entry), entered);
    let sampled = (entry as usize) < opts.sample_paths;
    let mut item = ActivePart::entering(t, pose, model, sampled);
    let work = &mut sinks.metrics.work;
    online_arrival(scene, control, &mut belt.queue, t, entry, &mut item);
    ride_on(scene, control, belt, work, entry, item, t);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Part 0 of a run of `parts` (the first one's path sampled) arrives at time 0 as `entry`
    /// says on the quickstart line (periodic feed, 4 s headway).
    fn arrive(parts: u64) -> (Belt, super::super::metrics::Metrics) {
        let path = &crate::project_path("scenarios/quickstart.toml");
        let scene = crate::scenario::load(path).unwrap();
        let opts = RunOptions {
            parts,
            sample_paths: 1,
            ..RunOptions::from_scene(&scene)
        };
        let entry = Entry {
            theta_rad: 0.5,
            y: 0.001,
            x: 0.0,
            model: None,
        };
        let mut belt = Belt::new();
        let mut sinks = Sinks::for_scene(&scene, false, None);
        arrival(
            &scene,
            &opts,
            Some(entry),
            None,
            &mut belt,
            &mut sinks,
            0.0,
            0,
        )
        .unwrap();
        (belt, sinks.metrics)
    }

    /// The part enters at the entry's pose with its path started and is counted in; its first
    /// event (a pin's contact begin) is scheduled at the end of its known motion, and the next
    /// part's arrival one headway after its own.
    #[test]
    fn an_arrival_puts_the_part_on_the_belt_and_schedules_the_next() {
        let (mut belt, metrics) = arrive(2);
        assert_eq!(metrics.parts_in, 1);
        let part = &belt.active[&0];
        assert_eq!(part.motion.world_pose(0.0, 1.0), Pose::new(0.0, 0.001, 0.5));
        assert_eq!(
            part.path.as_deref(),
            Some(&[(0.0, Pose::new(0.0, 0.001, 0.5))][..])
        );
        let until = part.motion.until();
        let own = belt.queue.pop().unwrap();
        assert_eq!(own.time, until);
        assert!(matches!(own.kind, EventKind::ContactBegin { part: 0, .. }));
        let next = belt.queue.pop().unwrap();
        assert_eq!(
            (next.time, next.kind),
            (4.0, EventKind::Arrival { part: 1 })
        );
        assert!(belt.queue.pop().is_none());
    }

    /// The last part of a run schedules no further arrival.
    #[test]
    fn the_last_arrival_schedules_no_other() {
        let (mut belt, _) = arrive(1);
        let ev = belt.queue.pop().unwrap();
        assert!(!matches!(ev.kind, EventKind::Arrival { .. }), "{ev:?}");
        assert!(belt.queue.pop().is_none());
    }
}
