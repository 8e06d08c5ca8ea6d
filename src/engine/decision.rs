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
