//! A sensor pin reads a push (docs/physics.md#sensing): the pass is read through the sensor's
//! noise model and classified ([`super::sensing::sense_pass`]); the sensor's statistics count it
//! and the decision joins the part's record.

use super::sensing::{sense_pass, SensedDecision, SensedPass};
use super::state::{Sinks, Touch};
use crate::mechanics::{ContactOutcome, TraceSample};
use crate::scenario::{Scene, SensorPin};
use crate::sensing::signal::SignalScale;

/// Read and classify the pass of part `touch.part` against sensor pin `touch.obstacle` (`sensor`,
/// the part at orientation `theta` rad just before contact; `seed`: the run's): the work counters
/// and the sensor's statistics in `sinks` count it, and the decision (as text for the part's
/// record) is returned with the pass.
pub(super) fn sense(
    scene: &Scene,
    seed: u64,
    sinks: &mut Sinks,
    touch: Touch,
    sensor: &SensorPin,
    pass: (&ContactOutcome, &[TraceSample]),
    theta: f64,
) -> (SensedDecision, SensedPass) {
    let (index, j) = (touch.part, touch.obstacle);
    let (out, knots) = pass;
    let scale = SignalScale {
        mass: scene.part.mass,
        belt_speed: scene.belt.speed,
        height: sensor.settings.height,
        metres_per_unit: 1.0,
    };
    let sensed = sense_pass(sensor, out, knots, &scale, theta, seed, index, j);
    let work = &mut sinks.metrics.work;
    work.sensor_readings += 1;
    work.signal_knots += sensed.knots as u64;
    work.classifications += 1;
    if let Some(&(_, k)) = sinks.sensor_pins.iter().find(|(o, _)| *o == j) {
        sinks.metrics.sensors[k].add(&sensed);
    }
    let name = scene.obstacles[j].name();
    let decision = SensedDecision::of(j, name, &sensor.labels, &sensed.classification);
    (decision, sensed)
}
