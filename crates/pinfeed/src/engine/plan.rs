//! The next event of a free part (docs/physics.md#the-line): the first obstacle it will touch,
//! else its exit at the belt's end ([`plan_next`]); a part put (back) on the belt is planned and
//! checked against the other parts ([`ride_on`]).

use super::controller::{pin_motion, present_at, Control};
use super::event_queue::{EventKind, EventQueue};
use super::metrics::WorkCounters;
use super::motion::Motion;
use super::pairs::check_pairs;
use super::state::{ActivePart, Belt};
use crate::mechanics::{fence_first_touch, pin_first_touch};
use crate::scenario::{Obstacle, Scene};

/// Put free part `index` (back) on the belt at `now`: its next event is planned and its motion
/// checked against the other parts.
pub(super) fn ride_on(
    scene: &Scene,
    control: Option<&Control>,
    belt: &mut Belt,
    work: &mut WorkCounters,
    index: u64,
    mut part: ActivePart,
    now: f64,
) {
    plan_next(scene, control, work, &mut belt.queue, index, &mut part, now);
    belt.active.insert(index, part);
    check_pairs(scene, belt, work, index, now);
}

/// From a free state, find the next event of part `index` and schedule it: the first obstacle
/// the part will touch (first-contact ray cast for a pin, first touch of a fence, in the belt
/// frame exactly as the contact model finds them; a dynamic pin where `control`'s timeline puts
/// it), or the exit. The part's motion is known until then.
pub(super) fn plan_next(
    scene: &Scene,
    control: Option<&Control>,
    work: &mut WorkCounters,
    queue: &mut EventQueue,
    index: u64,
    part: &mut ActivePart,
    now: f64,
) {
    let Motion::Free { t0, pose, .. } = part.motion else {
        unreachable!("plan_next on a held part");
    };
    let v = scene.belt.speed;
    let a = scene.part.radius;
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
        work.ray_casts += 1;
        let travel = match ob {
            // Along the pin's path (a moving pin's commanded motion from t0 on); a
            // retractable pin withdrawn when the part would reach it lets it pass.
            Obstacle::Pin(pin) => {
                let (start, path) = pin_motion(control, v, j, pin, t0);
                pin_first_touch(model, pose, start, pin.radius, &path)
                    .filter(|&tr| present_at(control, j, t0 + tr / v))
            }
            Obstacle::Fence(fence) => fence_first_touch(model, pose, &fence.spec()),
        };
        if let Some(tr) = travel {
            if best.is_none_or(|(b, _)| tr < b) {
                best = Some((tr, j));
            }
        }
    }
    let length = scene.belt.length;
    let t_exit = if pose.x >= length {
        now
    } else {
        (t0 + (length - pose.x) / v).max(now)
    };
    let until = match best {
        Some((travel, j)) if t0 + travel / v < t_exit => {
            let tb = (t0 + travel / v).max(now);
            queue.schedule(
                tb,
                EventKind::ContactBegin {
                    part: index,
                    obstacle: j as u32,
                },
            );
            tb
        }
        _ => {
            queue.schedule(t_exit, EventKind::Exit { part: index });
            t_exit
        }
    };
    part.motion = Motion::Free { t0, pose, until };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Pose;

    fn quickstart() -> Scene {
        crate::scenario::load(&crate::project_path("scenarios/quickstart.toml")).unwrap()
    }

    /// Part 0 riding the belt from x = 0.1 m at time 2 s, planned on `scene`.
    fn plan(scene: &Scene) -> (EventQueue, ActivePart, WorkCounters) {
        let mut part = ActivePart::entering(2.0, Pose::new(0.1, 0.0, 0.5), None, false);
        let (mut queue, mut work) = (EventQueue::new(), WorkCounters::default());
        plan_next(scene, None, &mut work, &mut queue, 0, &mut part, 2.0);
        (queue, part, work)
    }

    /// On a line without obstacles the part's next event is its exit, when its centroid reaches
    /// the belt's end riding the belt; no obstacle is cast against.
    #[test]
    fn without_obstacles_the_next_event_is_the_exit() {
        let mut scene = quickstart();
        scene.obstacles.clear();
        let (mut queue, part, work) = plan(&scene);
        let t_exit = 2.0 + (scene.belt.length - 0.1) / scene.belt.speed;
        let ev = queue.pop().unwrap();
        assert_eq!((ev.time, ev.kind), (t_exit, EventKind::Exit { part: 0 }));
        assert!(queue.pop().is_none());
        assert_eq!(part.motion.until(), t_exit);
        assert_eq!(work.ray_casts, 0);
    }

    /// On the quickstart line the part meets a pin before the belt's end: the contact begin is
    /// scheduled, and the pin it has just left is not cast against again.
    #[test]
    fn a_pin_in_the_way_comes_before_the_exit_and_the_last_one_is_skipped() {
        let scene = quickstart();
        let (mut queue, part, work) = plan(&scene);
        let ev = queue.pop().unwrap();
        let EventKind::ContactBegin { part: 0, obstacle } = ev.kind else {
            panic!("a contact begin: {ev:?}");
        };
        assert_eq!(part.motion.until(), ev.time);
        assert!(work.ray_casts > 0);
        let mut again = ActivePart::entering(2.0, Pose::new(0.1, 0.0, 0.5), None, false);
        again.last_obstacle = Some(obstacle as usize);
        let (mut queue, mut work2) = (EventQueue::new(), WorkCounters::default());
        plan_next(&scene, None, &mut work2, &mut queue, 0, &mut again, 2.0);
        let next = queue.pop().unwrap();
        assert_ne!(next.kind, ev.kind);
        assert!(next.time >= ev.time);
    }
}
