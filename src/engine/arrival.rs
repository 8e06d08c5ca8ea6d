//! Arrival (docs/physics.md#the-line): part i enters the belt with the pose and support its own
//! random stream draws (or as a forced [`Entry`] says), the next arrival is scheduled, and the
//! part's first event is planned and its motion checked against the other parts.

use super::controller::Control;
use super::event_queue::EventKind;
use super::line::Entry;
use super::metrics::Metrics;
use super::online_decide::online_arrival;
use super::part_stream::{arrival_gap, draw_part, PartDraw};
use super::plan::ride_on;
use super::results::{EngineError, RunOptions};
use super::state::{ActivePart, Belt};
use crate::geometry::Pose;
use crate::scenario::{Arrival, Scene};

/// Part `index` arrives at time `t`: drawn from the feed (or `entry`), it goes on the belt.
#[allow(clippy::too_many_arguments)]
pub(super) fn arrival(
    scene: &Scene,
    opts: &RunOptions,
    entry: Option<Entry>,
    control: Option<&Control>,
    belt: &mut Belt,
    metrics: &mut Metrics,
    t: f64,
    index: u64,
) -> Result<(), EngineError> {
    let mut x0 = 0.0;
    let d = match entry {
        Some(e) => {
            x0 = e.x;
            PartDraw {
                gap: 0.0,
                theta_rad: e.theta_rad,
                y: e.y,
                model: e.model,
            }
        }
        None => draw_part(scene, opts.seed, index)
            .map_err(|reason| EngineError::PartDraw { index, reason })?,
    };
    if d.model.is_some() {
        metrics.work.tripods_drawn += 1;
    }
    metrics.arrival(t);
    if index + 1 < opts.parts {
        let next = match scene.feed.arrival {
            Arrival::Periodic { headway } => (index + 1) as f64 * headway,
            Arrival::Poisson { .. } => t + arrival_gap(scene, opts.seed, index + 1),
        };
        belt.queue
            .schedule(next, EventKind::Arrival { part: index + 1 });
    }
    let pose = Pose::new(x0, d.y, d.theta_rad);
    let sampled = (index as usize) < opts.sample_paths;
    let mut part = ActivePart::entering(t, pose, d.model, sampled);
    let work = &mut metrics.work;
    online_arrival(scene, control, &mut belt.queue, t, index, &mut part);
    ride_on(scene, control, belt, work, index, part, t);
    Ok(())
}
