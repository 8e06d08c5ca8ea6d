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
use crate::sensing::belief::Belief;
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
    // The belief's probabilities once, for the choice, its entropy and its marginal.
    let (p, h1) = belief.probabilities_and_entropy();
    let choice = model.choose_from(&p);
    part.predicted = Some(choice.predicted);
    let h0 = model.prior_entropy_bits();
    let action = &model.actions[choice.action];
    let truth = part.decided.iter().find_map(|d| d.2);
    let states = model
        .hypotheses
        .iter()
        .map(|h| h.state)
        .max()
        .map_or(0, |m| m + 1);
    let group: Vec<usize> = model.hypotheses.iter().map(|h| h.state).collect();
    let marginal = Belief::marginal_of(&p, &group, states);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::online::OnlineModel;
    use crate::engine::prepare::OnlineHandle;
    use crate::geometry::Pose;
    use crate::scenario::raw::SupportKind;
    use crate::scenario::BeliefSpec;
    use crate::sensing::belief::Update;
    use std::sync::Arc;

    /// tripoly2's online line with a small belief (2 μc × 2 supports × 2 offsets × its states,
    /// 2 members each) in which the first sensor touches every other hypothesis (h odd; the
    /// small model's members all touch it), its controller and a belt holding part 3 at `x` (m),
    /// entered at t = 0.
    fn line_with_part_at(x: f64) -> (Scene, Control, Belt) {
        let path = &crate::project_path("scenarios/tripoly2_online.toml");
        let text = std::fs::read_to_string(path).unwrap();
        let cut = text.find("[controller.belief]").unwrap();
        let end = text[cut..].find("[goal]").unwrap() + cut;
        let text = format!("{}{}", &text[..cut], &text[end..])
            .replace("mode = \"online\"", "mode = \"policy\"");
        let scene = crate::scenario::parse(path, &text).unwrap();
        let spec = BeliefSpec {
            mu_c: vec![0.3, 0.7],
            support: vec![SupportKind::Uniform, SupportKind::Tripod],
            offsets: 2,
            samples: 2,
            targets: 5,
        };
        let mut model = OnlineModel::build(&scene, &spec).unwrap();
        let n = model.hypotheses.len();
        model.sensors[0].p_touch = (0..n).map(|h| (h % 2) as f64).collect();
        let control = Control::new(&scene, true, Some(OnlineHandle(Arc::new(model)))).unwrap();
        let mut belt = Belt::new();
        let pose = Pose::new(x, 0.0, 0.0);
        belt.active
            .insert(3, ActivePart::entering(0.0, pose, None, false));
        (scene, control, belt)
    }

    fn events(queue: &mut EventQueue) -> Vec<(f64, EventKind)> {
        std::iter::from_fn(|| queue.pop().map(|e| (e.time, e.kind))).collect()
    }

    /// A part entering takes the model's prior and, for each sensor pin, a check when it could
    /// first be clear of the pin riding the belt.
    #[test]
    fn an_entering_part_takes_the_prior_and_a_check_per_sensor() {
        let (scene, control, mut belt) = line_with_part_at(0.0);
        let model = control.online_model().unwrap().clone();
        let part = belt.active.get_mut(&3).unwrap();
        online_arrival(&scene, Some(&control), &mut belt.queue, 0.0, 3, part);
        assert_eq!(part.belief.as_ref(), Some(&model.prior));
        assert_eq!(part.sensors_left as usize, model.sensors.len());
        let got = events(&mut belt.queue);
        assert_eq!(got.len(), model.sensors.len());
        for (s, (t, kind)) in model.sensors.iter().zip(got) {
            let clear = sensor_clear_x(&scene, s.obstacle);
            assert!(clear > 0.0);
            assert!((t - clear / scene.belt.speed).abs() < 1e-12, "{t}");
            let obstacle = s.obstacle as u32;
            assert_eq!(kind, EventKind::Unread { part: 3, obstacle });
        }
        // No controller (or one without a model): nothing happens.
        let part = belt.active.get_mut(&3).unwrap();
        part.belief = None;
        online_arrival(&scene, None, &mut belt.queue, 0.0, 3, part);
        assert!(part.belief.is_none() && belt.queue.is_empty());
    }

    /// A part past a sensor pin without touching it: the belief removes what would have touched
    /// (the same update as the belief's own), the pass is counted, and the last sensor to speak
    /// schedules the decision after the latency. A part still short of the pin is looked at
    /// again when it could be clear, its belief untouched.
    #[test]
    fn a_pass_without_contact_is_evidence_and_a_part_short_of_the_pin_is_checked_later() {
        let (scene, mut control, _) = line_with_part_at(0.0);
        let model = control.online_model().unwrap().clone();
        let sm = &model.sensors[0];
        let j = sm.obstacle;
        let clear = sensor_clear_x(&scene, j);
        // Short of the pin: rescheduled when it could be clear.
        let (_, _, mut belt) = line_with_part_at(clear - 0.01);
        let part = belt.active.get_mut(&3).unwrap();
        part.belief = Some(model.prior.clone());
        part.sensors_left = 1;
        unread(&scene, Some(&mut control), &mut belt, 0.0, 3, j);
        let got = events(&mut belt.queue);
        assert_eq!(got.len(), 1);
        assert!((got[0].0 - 0.01 / scene.belt.speed).abs() < 1e-12);
        assert!(matches!(got[0].1, EventKind::Unread { part: 3, .. }));
        assert_eq!(belt.active[&3].belief.as_ref(), Some(&model.prior));
        // Past it: the update and the decision.
        let (_, _, mut belt) = line_with_part_at(clear + 0.01);
        let part = belt.active.get_mut(&3).unwrap();
        part.belief = Some(model.prior.clone());
        part.sensors_left = 1;
        unread(&scene, Some(&mut control), &mut belt, 2.0, 3, j);
        let mut expected = model.prior.clone();
        assert_ne!(
            expected.observe_no_contact(&sm.p_touch),
            Update::Inconsistent
        );
        assert_eq!(belt.active[&3].belief.as_ref(), Some(&expected));
        let (p, prior) = (expected.probabilities(), model.prior.probabilities());
        let kept: f64 = (0..p.len()).filter(|h| h % 2 == 0).map(|h| prior[h]).sum();
        for h in 0..p.len() {
            // Exactly the hypotheses that would have touched are gone; the rest keep their odds.
            let want = if h % 2 == 1 { 0.0 } else { prior[h] / kept };
            assert!(
                (p[h] - want).abs() < 1e-12,
                "hypothesis {h}: {} against {want}",
                p[h]
            );
        }
        assert_eq!(
            control.online.as_ref().unwrap().summary.no_contact_passes,
            1
        );
        let got = events(&mut belt.queue);
        assert_eq!(got.len(), 1);
        assert!((got[0].0 - (2.0 + control.latency())).abs() < 1e-12);
        assert!(matches!(got[0].1, EventKind::Decision { part: 3, .. }));
    }

    /// The decision queues, for each dynamic pin, the target of the joint command the model
    /// chooses under the part's belief, logs it and counts it; a part that is gone (or has no
    /// belief) takes none.
    #[test]
    fn the_decision_queues_the_models_choice_for_each_dynamic_pin() {
        let (scene, mut control, mut belt) = line_with_part_at(0.3);
        let model = control.online_model().unwrap().clone();
        belt.active.get_mut(&3).unwrap().belief = Some(model.prior.clone());
        let mut work = WorkCounters::default();
        assert!(decide_online(
            &scene,
            &mut control,
            &mut belt.active,
            &mut work,
            5.0,
            3
        ));
        let choice = model.choose(&model.prior);
        for (&pin, &target) in model.pins.iter().zip(&model.actions[choice.action]) {
            assert_eq!(control.queues[pin].get(&3), Some(&target));
        }
        assert_eq!(belt.active[&3].predicted, Some(choice.predicted));
        assert_eq!(work.decisions, 1);
        assert_eq!(work.actuator_commands, model.pins.len() as u64);
        let online = control.online.as_ref().unwrap();
        assert_eq!(
            (online.summary.decisions, online.chosen[choice.action]),
            (1, 1)
        );
        let log = control.log.as_ref().unwrap();
        assert!(log.len() == 1 && log[0].kind == ControlKind::Decision && log[0].part == 3);
        // Gone (part 9), or without a belief: counted as a decision point, nothing taken.
        for index in [9, 3] {
            belt.active.get_mut(&3).unwrap().belief = None;
            let active = &mut belt.active;
            assert!(!decide_online(
                &scene,
                &mut control,
                active,
                &mut work,
                6.0,
                index
            ));
        }
        assert_eq!(work.actuator_commands, model.pins.len() as u64);
    }
}
