//! The online controller's stages (docs/physics.md#belief-and-online-replanning): a part enters
//! with the model's prior belief, each sensor pin's reading (or a pass without contact) updates
//! it, and once every sensor has spoken the decision picks the joint command of the dynamic pins
//! that maximises P(goal), queued for [`super::serve`] like a rule's commands.

use super::controller::{describe_action, Control, ControlKind, ControlRecord};
use super::event_queue::{EventKind, EventQueue};
use super::metrics::WorkCounters;
use super::sensing::SensedPass;
use super::state::{ActivePart, Belt};
use crate::scenario::{Obstacle, Scene};
use std::collections::BTreeMap;

/// Part `index` enters at time `t` (online mode): it takes the prior belief, and for each sensor
/// pin a check is scheduled for when it could first be past the pin riding the belt (a pass
/// without contact is evidence too).
pub(super) fn online_arrival(
    scene: &Scene,
    control: Option<&Control>,
    queue: &mut EventQueue,
    t: f64,
    index: u64,
    part: &mut ActivePart,
) {
    let Some(model) = control.and_then(|c| c.online_model()) else {
        return;
    };
    let v = scene.belt.speed;
    part.belief = Some(model.prior.clone());
    part.sensors_left = model.sensors.len() as u32;
    for s in &model.sensors {
        let clear = sensor_clear_x(scene, s.obstacle);
        queue.schedule(
            t + (clear - part.motion.world_pose(t, v).x).max(0.0) / v,
            EventKind::Unread {
                part: index,
                obstacle: s.obstacle as u32,
            },
        );
    }
}

/// The centroid x beyond which a part can no longer touch sensor pin `j`.
fn sensor_clear_x(scene: &Scene, j: usize) -> f64 {
    let a = scene.part.radius;
    match &scene.obstacles[j] {
        Obstacle::Pin(p) => p.centre.x + p.radius + a,
        Obstacle::Fence(_) => scene.obstacles[j].x_range()[1] + a,
    }
}

/// Sensor pin `j`'s reading `sensed` of part `index` (online mode), over at `t_end`: the belief
/// takes the reading and the classifier's posterior over the states; once every sensor has
/// spoken the decision is scheduled after the controller's latency.
pub(super) fn online_reading(
    control: &mut Control,
    queue: &mut EventQueue,
    part: &mut ActivePart,
    index: u64,
    j: usize,
    sensed: &SensedPass,
    t_end: f64,
) {
    let t_ready = t_end + control.latency();
    let Some(model) = control.online_model().cloned() else {
        return;
    };
    let Some(sm) = model.sensor(j) else {
        return;
    };
    if let Some(b) = part.belief.as_mut() {
        let posterior = sensed.classification.posterior.as_deref();
        let ll = sm.log_likelihood(sensed.reading.as_ref(), posterior);
        let u = b.observe_reading(&sm.p_touch, ll.as_deref());
        control.count_update(u, false);
    }
    sensor_spoke(queue, part, index, j, t_ready);
}

/// Sensor pin `j` has spoken about part `index`: the last one to speak schedules the decision
/// at `t_ready`.
fn sensor_spoke(queue: &mut EventQueue, part: &mut ActivePart, index: u64, j: usize, t_ready: f64) {
    part.sensors_left = part.sensors_left.saturating_sub(1);
    if part.sensors_left == 0 {
        queue.schedule(
            t_ready,
            EventKind::Decision {
                part: index,
                obstacle: j as u32,
                hypothesis: u32::MAX,
            },
        );
    }
}

/// Has part `index` gone past sensor pin `j` without touching it by time `t`? Then that is
/// evidence; a part still short of the pin (held upstream) is checked again later.
pub(super) fn unread(
    scene: &Scene,
    control: Option<&mut Control>,
    belt: &mut Belt,
    t: f64,
    index: u64,
    j: usize,
) {
    let v = scene.belt.speed;
    let clear = sensor_clear_x(scene, j);
    let Some(part) = belt.active.get_mut(&index) else {
        return;
    };
    if part.sensed.iter().any(|d| d.obstacle == j) {
        return;
    }
    let x = part.motion.world_pose(t, v).x;
    if x < clear {
        // Held upstream (or pushed back): look again when it could be clear riding the belt.
        let dt = ((clear - x) / v).max(1e-6);
        belt.queue.schedule(
            t + dt,
            EventKind::Unread {
                part: index,
                obstacle: j as u32,
            },
        );
        return;
    }
    let Some(c) = control else {
        return;
    };
    if let Some(model) = c.online_model().cloned() {
        if let (Some(sm), Some(b)) = (model.sensor(j), part.belief.as_mut()) {
            let u = b.observe_no_contact(&sm.p_touch);
            c.count_update(u, true);
        }
        let latency = c.latency();
        sensor_spoke(&mut belt.queue, part, index, j, t + latency);
    }
}

/// The online decision for part `index` at time `t`: the joint command of the dynamic pins that
/// maximises P(goal) under its belief, queued like a rule's commands. Returns whether it was
/// taken (false: no model, or the part or its belief is gone).
pub(super) fn decide_online(
    scene: &Scene,
    control: &mut Control,
    active: &mut BTreeMap<u64, ActivePart>,
    work: &mut WorkCounters,
    t: f64,
    index: u64,
) -> bool {
    let Some(model) = control.online_model().cloned() else {
        return false;
    };
    work.decisions += 1;
    let Some(part) = active.get_mut(&index) else {
        return false;
    };
    let Some(belief) = part.belief.as_ref() else {
        return false;
    };
    let choice = model.choose(belief);
    part.predicted = Some(choice.predicted);
    let (h0, h1) = (model.prior.entropy_bits(), belief.entropy_bits());
    let action = &model.actions[choice.action];
    let truth = part.decided.iter().find_map(|d| d.2);
    let states = model
        .hypotheses
        .iter()
        .map(|h| h.state)
        .max()
        .map_or(0, |m| m + 1);
    let group: Vec<usize> = model.hypotheses.iter().map(|h| h.state).collect();
    let marginal = belief.marginal(&group, states);
    let map_state = (0..states).max_by(|&a, &b| marginal[a].total_cmp(&marginal[b]));
    if let Some(o) = control.online.as_mut() {
        if let Some(t) = truth {
            o.summary.state_known += 1;
            o.summary.state_correct += u64::from(map_state == Some(t));
        }
        o.summary.decisions += 1;
        o.summary.entropy_prior_bits += h0;
        o.summary.entropy_posterior_bits += h1;
        o.chosen[choice.action] += 1;
    }
    if control.log.is_some() {
        let names: Vec<String> = model
            .pins
            .iter()
            .map(|&j| scene.obstacles[j].name().to_string())
            .collect();
        let described = describe_action(&names, action);
        control.log(ControlRecord {
            t,
            part: index,
            obstacle: "online".into(),
            kind: ControlKind::Decision,
            what: format!(
                "{described} (P = {:.3}; entropy {h0:.2} → {h1:.2} bits)",
                choice.predicted
            ),
            motion: None,
        });
    }
    for (&pin, &target) in model.pins.iter().zip(action) {
        work.actuator_commands += 1;
        control.queue_command(pin, index, target);
    }
    true
}
