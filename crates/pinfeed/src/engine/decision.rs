//! A sensor's decision reaches the rule-table controller (docs/physics.md#controller): the rules
//! of `[[rules]]` turn it into commands queued for the dynamic pins, which [`super::serve`]
//! carries out in the parts' order.

use super::controller::{decision_label, Control, ControlKind, ControlRecord};
use super::metrics::WorkCounters;
use crate::scenario::{Scene, Target};

/// Sensor pin `sensor`'s decision `decision` on part `index` reaches the controller at time `t`:
/// it is logged, and every rule for it queues its command for its pin.
pub(super) fn decide(
    scene: &Scene,
    control: &mut Control,
    work: &mut WorkCounters,
    t: f64,
    index: u64,
    sensor: usize,
    decision: Option<usize>,
) {
    work.decisions += 1;
    let label = decision_label(scene, sensor, decision);
    let name = scene.obstacles[sensor].name().to_string();
    control.log(ControlRecord {
        t,
        part: index,
        obstacle: name,
        kind: ControlKind::Decision,
        what: label,
        motion: None,
    });
    let commands: Vec<(usize, Target)> = control
        .spec
        .rules
        .iter()
        .filter(|r| r.sensor == sensor && r.decides == decision)
        .map(|r| (r.pin, r.target))
        .collect();
    for (pin, target) in commands {
        work.actuator_commands += 1;
        control.queue_command(pin, index, target);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::serve::serve;
    use crate::engine::state::Belt;

    /// tripoly1_sensing's first rule fires on its decision: the decision is logged and its
    /// command queued for its pin and that part; `unknown`, which no rule names, queues nothing. Served
    /// with the part gone from the belt, the command is dropped and counted.
    #[test]
    fn a_decision_queues_its_rules_commands_and_a_gone_part_drops_them() {
        let path = &crate::project_path("scenarios/tripoly1_sensing.toml");
        let scene = crate::scenario::load(path).unwrap();
        let mut control = Control::new(&scene, true, None).expect("dynamic pins");
        let rule = control.spec.rules[0].clone();
        let mut work = WorkCounters::default();
        assert!(control.spec.rules.iter().all(|r| r.decides.is_some()));
        decide(&scene, &mut control, &mut work, 1.0, 7, rule.sensor, None);
        assert!(control.queues.iter().all(|q| q.is_empty()));
        decide(
            &scene,
            &mut control,
            &mut work,
            2.0,
            7,
            rule.sensor,
            rule.decides,
        );
        let fired = control.spec.rules.iter();
        let fired = fired.filter(|r| r.sensor == rule.sensor && r.decides == rule.decides);
        let fired = fired.count() as u64;
        assert_eq!((work.decisions, work.actuator_commands), (2, fired));
        assert_eq!(control.queues[rule.pin].get(&7), Some(&rule.target));
        let log = control.log.as_ref().unwrap();
        assert_eq!(log.len(), 2);
        assert!(log
            .iter()
            .all(|r| r.kind == ControlKind::Decision && r.part == 7));
        let k = control.stats_of[rule.pin].unwrap();
        assert_eq!(control.summary.actuators[k].commands, fired);
        serve(&scene, &mut control, &mut Belt::new(), &mut work, 3.0);
        assert!(control.queues[rule.pin].is_empty());
        assert_eq!(control.summary.actuators[k].dropped, fired);
        assert_eq!(control.summary.actuators[k].moves, 0);
    }
}
