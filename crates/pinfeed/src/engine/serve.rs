//! Actuator serving (docs/physics.md#controller): each dynamic pin carries out its queued
//! commands in the parts' order, as `super::controller`'s module notes say: a pin moves for part p
//! only when every earlier part within its reach is known to clear it, and a command that cannot
//! finish before its part arrives is late. When a pin's timeline changes, every free part that
//! could still reach it is planned again.

use super::controller::{describe_target, Control, ControlKind, ControlRecord, MotionRecord};
use super::metrics::WorkCounters;
use super::motion::Motion;
use super::plan::ride_on;
use super::state::Belt;
use crate::scenario::{Obstacle, OnLate, Scene, Target};

/// Carry out every queued command whose turn has come (see the module notes).
pub(super) fn serve(
    scene: &Scene,
    control: &mut Control,
    belt: &mut Belt,
    work: &mut WorkCounters,
    now: f64,
) {
    let pending: Vec<usize> = (0..control.queues.len())
        .filter(|&j| !control.queues[j].is_empty())
        .collect();
    for j in pending {
        while serve_next(scene, control, belt, work, j, now) {}
    }
}

/// Serve the first queued command of pin `j` if its turn has come; true if one was taken.
fn serve_next(
    scene: &Scene,
    c: &mut Control,
    belt: &mut Belt,
    work: &mut WorkCounters,
    j: usize,
    now: f64,
) -> bool {
    let v = scene.belt.speed;
    let Obstacle::Pin(pin) = &scene.obstacles[j] else {
        return false;
    };
    let reach = scene.part.radius + pin.radius;
    let x_pin = pin.centre.x;
    let Some((&part, &target)) = c.queues[j].first_key_value() else {
        return false;
    };
    // No later part may be in contact with the pin (it came first: wait until it is done).
    let later_in_use = belt
        .active
        .range(part + 1..)
        .any(|(_, q)| matches!(&q.motion, Motion::Held(plan) if plan.obstacle == j));
    if later_in_use {
        return false;
    }
    // Every earlier part still within reach must be known to clear the pin.
    let mut t_free = now;
    for qp in belt.active.range(..part).map(|(_, p)| p) {
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
    c.queues[j].remove(&part);
    let name = pin.name.clone();
    let k = c.stats_of[j].expect("a dynamic pin has statistics");
    let Some(p) = belt.active.get(&part) else {
        c.summary.actuators[k].dropped += 1;
        c.log(ControlRecord {
            t: now,
            part,
            obstacle: name,
            kind: ControlKind::Dropped,
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
        work.late_actuations += 1;
    }
    // A late move that could only start once the part is past the pin is pointless.
    let passed_by_then = t_start >= t_reach + 2.0 * reach / v;
    let carry_out =
        duration > 0.0 && (!late || (c.spec.on_late == OnLate::Move && !in_use && !passed_by_then));
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
            kind: if late {
                ControlKind::Late
            } else {
                ControlKind::Actuation
            },
            what: describe_target(target),
            motion: Some(MotionRecord {
                t_start,
                t_ready: t_start + duration,
                from,
                to,
            }),
        });
        replan_near(scene, c, belt, work, j, now);
    } else if late {
        c.log(ControlRecord {
            t: now,
            part,
            obstacle: name,
            kind: ControlKind::Late,
            what: format!("{} skipped", describe_target(target)),
            motion: None,
        });
    }
    true
}

/// Pin `j`'s timeline has changed: plan again every free part that could still reach it.
fn replan_near(
    scene: &Scene,
    control: &mut Control,
    belt: &mut Belt,
    work: &mut WorkCounters,
    j: usize,
    now: f64,
) {
    let v = scene.belt.speed;
    let [_, x_max] = scene.obstacles[j].x_range();
    let reach = scene.part.radius;
    let parts: Vec<u64> = belt
        .active
        .iter()
        .filter(|(_, p)| {
            matches!(p.motion, Motion::Free { .. }) && p.motion.world_pose(now, v).x < x_max + reach
        })
        .map(|(&k, _)| k)
        .collect();
    let oldest = belt
        .active
        .values()
        .filter_map(|p| match p.motion {
            Motion::Free { t0, .. } => Some(t0),
            Motion::Held(_) => None,
        })
        .fold(now, f64::min);
    if let Some(track) = control.tracks[j].as_mut() {
        track.forget_before(oldest);
    }
    for index in parts {
        let Some(mut part) = belt.active.remove(&index) else {
            continue;
        };
        work.replans += 1;
        part.valid_from = belt.queue.next_seq();
        ride_on(scene, Some(control), belt, work, index, part, now);
    }
}
