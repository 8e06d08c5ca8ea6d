//! The compiled uncertain parameters of one sweep point: which distribution each parameter follows
//! and which support model the part gets. Units: metres and m/s as in scenarios; `pose_theta` is in
//! degrees as written and converted when drawn.

use super::distribution::Distribution;
use crate::mechanics::support::SupportChoice;
use std::collections::BTreeMap;

/// The uncertain parameters at one sweep point; `None` keeps the scenario's nominal value.
#[derive(Debug, Clone, PartialEq)]
pub struct Perturbations {
    /// μc at every pin.
    pub mu_c: Option<Distribution>,
    /// Belt speed (m/s).
    pub belt_speed: Option<Distribution>,
    /// Error of each vertex coordinate (m).
    pub shape: Option<Distribution>,
    /// Error added to each pin's x (m).
    pub pin_x: Option<Distribution>,
    /// Error added to each pin's y (m).
    pub pin_y: Option<Distribution>,
    /// Error added to each pin's radius (m).
    pub pin_radius: Option<Distribution>,
    /// Error added to the entry orientation (degrees).
    pub pose_theta: Option<Distribution>,
    /// Error added to the entry lateral offset (m).
    pub pose_y: Option<Distribution>,
    /// Factor on every sensor's white-noise σ and timing jitter (one draw per sample, applied to
    /// every sensor pin).
    pub sensor_noise: Option<Distribution>,
    /// Error added to every sensor's force bias (N, each force channel).
    pub sensor_bias: Option<Distribution>,
    /// Every sensor's timing threshold (N, its value).
    pub sensor_threshold: Option<Distribution>,
    /// Error added to every sensor's timing jitter (s).
    pub sensor_jitter: Option<Distribution>,
    /// Fence–part friction μf (one draw per sample, at every fence it reaches).
    pub fence_mu_f: Option<Distribution>,
    /// Error added to each fence's angle (degrees), drawn per fence.
    pub fence_angle: Option<Distribution>,
    /// Error added to each fence's upstream end x (m), drawn per fence.
    pub fence_x: Option<Distribution>,
    /// Error added to each fence's upstream end y (m), drawn per fence.
    pub fence_y: Option<Distribution>,
    /// Error added to each fence's length (m), drawn per fence.
    pub fence_length: Option<Distribution>,
    /// Factor on each dynamic pin's speed (a moving pin's limit, a retractable pin's raise and
    /// lower rates), drawn per pin.
    pub actuator_speed: Option<Distribution>,
    /// Factor on each moving pin's acceleration limit, drawn per pin.
    pub actuator_accel: Option<Distribution>,
    /// Error added to each moving pin's settle time (s), drawn per pin.
    pub actuator_settle: Option<Distribution>,
    /// Error added to the controller's latency (s), one draw per sample.
    pub controller_latency: Option<Distribution>,
    /// The obstacles a fence or actuator parameter is restricted to (`fences = [...]`,
    /// `pins = [...]`), by parameter name; a parameter absent here reaches every obstacle it
    /// applies to.
    pub only: BTreeMap<String, Vec<String>>,
    /// How the part's weight rests on the belt (uniform, a random tripod or a random smooth
    /// density).
    pub support: SupportChoice,
}

impl Perturbations {
    /// Nothing perturbed, the part resting on `support`: the start of a study built in code
    /// ([`super::Study::of_scene`]), whose fields are then set.
    pub fn none(support: SupportChoice) -> Perturbations {
        Perturbations {
            mu_c: None,
            belt_speed: None,
            shape: None,
            pin_x: None,
            pin_y: None,
            pin_radius: None,
            pose_theta: None,
            pose_y: None,
            sensor_noise: None,
            sensor_bias: None,
            sensor_threshold: None,
            sensor_jitter: None,
            fence_mu_f: None,
            fence_angle: None,
            fence_x: None,
            fence_y: None,
            fence_length: None,
            actuator_speed: None,
            actuator_accel: None,
            actuator_settle: None,
            controller_latency: None,
            only: BTreeMap::new(),
            support,
        }
    }

    /// Every distribution parameter by name, in [`super::compile::DISTRIBUTION_PARAMETERS`]'s
    /// order.
    pub fn slots(&self) -> [(&'static str, &Option<Distribution>); 21] {
        [
            ("mu_c", &self.mu_c),
            ("belt_speed", &self.belt_speed),
            ("shape", &self.shape),
            ("pin_x", &self.pin_x),
            ("pin_y", &self.pin_y),
            ("pin_radius", &self.pin_radius),
            ("pose_theta", &self.pose_theta),
            ("pose_y", &self.pose_y),
            ("sensor_noise", &self.sensor_noise),
            ("sensor_bias", &self.sensor_bias),
            ("sensor_threshold", &self.sensor_threshold),
            ("sensor_jitter", &self.sensor_jitter),
            ("fence_mu_f", &self.fence_mu_f),
            ("fence_angle", &self.fence_angle),
            ("fence_x", &self.fence_x),
            ("fence_y", &self.fence_y),
            ("fence_length", &self.fence_length),
            ("actuator_speed", &self.actuator_speed),
            ("actuator_accel", &self.actuator_accel),
            ("actuator_settle", &self.actuator_settle),
            ("controller_latency", &self.controller_latency),
        ]
    }

    /// [`Self::slots`], to change them.
    pub fn slots_mut(&mut self) -> [(&'static str, &mut Option<Distribution>); 21] {
        [
            ("mu_c", &mut self.mu_c),
            ("belt_speed", &mut self.belt_speed),
            ("shape", &mut self.shape),
            ("pin_x", &mut self.pin_x),
            ("pin_y", &mut self.pin_y),
            ("pin_radius", &mut self.pin_radius),
            ("pose_theta", &mut self.pose_theta),
            ("pose_y", &mut self.pose_y),
            ("sensor_noise", &mut self.sensor_noise),
            ("sensor_bias", &mut self.sensor_bias),
            ("sensor_threshold", &mut self.sensor_threshold),
            ("sensor_jitter", &mut self.sensor_jitter),
            ("fence_mu_f", &mut self.fence_mu_f),
            ("fence_angle", &mut self.fence_angle),
            ("fence_x", &mut self.fence_x),
            ("fence_y", &mut self.fence_y),
            ("fence_length", &mut self.fence_length),
            ("actuator_speed", &mut self.actuator_speed),
            ("actuator_accel", &mut self.actuator_accel),
            ("actuator_settle", &mut self.actuator_settle),
            ("controller_latency", &mut self.controller_latency),
        ]
    }

    /// Does any parameter act on sensor pins?
    pub fn perturbs_sensors(&self) -> bool {
        self.sensor_noise.is_some()
            || self.sensor_bias.is_some()
            || self.sensor_threshold.is_some()
            || self.sensor_jitter.is_some()
    }

    /// Does any parameter act on fences, actuators or the controller? (Without one, a sample
    /// seeds no stream for them and draws nothing for them.)
    pub fn perturbs_obstacles(&self) -> bool {
        [
            &self.fence_mu_f,
            &self.fence_angle,
            &self.fence_x,
            &self.fence_y,
            &self.fence_length,
            &self.actuator_speed,
            &self.actuator_accel,
            &self.actuator_settle,
            &self.controller_latency,
        ]
        .iter()
        .any(|d| d.is_some())
    }

    /// Does parameter `name` reach the obstacle named `obstacle` (of a kind it applies to)?
    pub fn reaches(&self, name: &str, obstacle: &str) -> bool {
        self.only
            .get(name)
            .is_none_or(|names| names.iter().any(|n| n == obstacle))
    }

    /// The first parameter that gives samples different map-tier inputs (a map is per part,
    /// support, pin radius and μc: `maps::tier::TierInputs`), if any: with it each sample would
    /// build a map for its few contacts, so samples run the exact model instead.
    pub fn varies_map_inputs(&self) -> Option<&'static str> {
        let varies = |d: &Option<Distribution>| d.is_some_and(|d| !d.is_fixed());
        if varies(&self.mu_c) {
            Some("mu_c")
        } else if varies(&self.shape) {
            Some("shape")
        } else if varies(&self.pin_radius) {
            Some("pin_radius")
        } else if self.support != SupportChoice::Uniform {
            Some("support")
        } else {
            None
        }
    }

    /// One line per parameter that is not nominal, e.g. `mu_c: uniform [0.3, 0.7]`.
    pub fn describe(&self) -> Vec<String> {
        let mut out = Vec::new();
        let named = [
            ("mu_c", &self.mu_c, ""),
            ("belt_speed", &self.belt_speed, " m/s"),
            ("shape", &self.shape, " m per vertex coordinate"),
            ("pin_x", &self.pin_x, " m added"),
            ("pin_y", &self.pin_y, " m added"),
            ("pin_radius", &self.pin_radius, " m added"),
            ("pose_theta", &self.pose_theta, "° added"),
            ("pose_y", &self.pose_y, " m added"),
            (
                "sensor_noise",
                &self.sensor_noise,
                " × every sensor's noise σ and jitter",
            ),
            (
                "sensor_bias",
                &self.sensor_bias,
                " N added to the force bias",
            ),
            ("sensor_threshold", &self.sensor_threshold, " N"),
            ("sensor_jitter", &self.sensor_jitter, " s added"),
            ("fence_mu_f", &self.fence_mu_f, ""),
            ("fence_angle", &self.fence_angle, "° added"),
            ("fence_x", &self.fence_x, " m added"),
            ("fence_y", &self.fence_y, " m added"),
            ("fence_length", &self.fence_length, " m added"),
            ("actuator_speed", &self.actuator_speed, " × the speed"),
            (
                "actuator_accel",
                &self.actuator_accel,
                " × the acceleration",
            ),
            ("actuator_settle", &self.actuator_settle, " s added"),
            ("controller_latency", &self.controller_latency, " s added"),
        ];
        for (name, d, unit) in named {
            if let Some(d) = d {
                let only = match self.only.get(name) {
                    Some(names) => format!(" (only {})", names.join(", ")),
                    None => String::new(),
                };
                out.push(format!("{name}: {}{unit}{only}", d.describe()));
            }
        }
        out.push(format!("support: {}", self.support.describe()));
        out
    }
}
