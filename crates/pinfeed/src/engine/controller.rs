//! The online controller in the event engine (docs/physics.md#controller): a sensor pin's reading becomes a
//! decision, the decision (after the controller's computation latency) becomes commands for the
//! dynamic pins through the rules, and each command becomes an actuator motion with its real
//! timing (`super::actuator`).
//!
//! Each dynamic pin serves the parts in their order: a pin moves for part p only when every
//! earlier part still within its reach (centroid short of x_pin + a + ρ) is known to clear it,
//! and the move must be over (settled) before part p can reach the pin (its centroid at
//! x_pin − a − ρ, riding the belt from where it is now — a part held by an obstacle only comes
//! later, so the deadline is safe). A command that cannot finish in time is a **late
//! actuation**, counted, and handled as `[controller] on_late` says: `skip` leaves the pin as it
//! is for that part, `move` moves anyway (the part may then meet a pin in motion, which the
//! contact model follows with its true velocity). A command whose part is gone is dropped.
//!
//! When a pin's timeline changes, every free part that could still reach it is planned again:
//! its pending contact or exit event goes stale (the part remembers the sequence number from
//! which its events are valid, and older ones are dropped when they come off the queue), and its
//! part–part checks run again. A scene without dynamic pins has no controller and does none of
//! this (`work.decisions`, `work.actuator_commands`, `work.replans`, `work.stale_events` stay 0).
//!
//! This module holds the controller's state (`Control`: the rules, the dynamic pins'
//! timelines and command queues) and what it reports; the stages that drive it are
//! `super::decision` (the rules), `super::online_decide` (the belief and the online decision)
//! and `super::serve` (the dynamic pins serving their commands).

use super::actuator::Track;
use super::online::OnlineModel;
use super::outcome::PartOutcome;
use crate::geometry::Vec2;
use crate::mechanics::PinPath;
use crate::scenario::{
    Actuator, ControlMode, Controller, Obstacle, OnLate, PinObstacle, Scene, Target,
};
use crate::sensing::belief::Update;
use serde::Serialize;
use std::collections::BTreeMap;
use std::sync::Arc;

/// What the controller did, for the event log and the animation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ControlRecord {
    /// Seconds.
    pub t: f64,
    /// Index of the part in the stream (0-based).
    pub part: u64,
    /// The sensor (for a decision) or the dynamic pin (for an actuation).
    pub obstacle: String,
    /// What the controller did.
    pub kind: ControlKind,
    /// The decision's label, or the target (`y=0.012` / `raised` / `withdrawn`).
    pub what: String,
    /// An actuation's motion: start, ready (s), and a moving pin's lateral positions (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub motion: Option<MotionRecord>,
}

/// What a [`ControlRecord`] records (written as `decision`, `actuation`, `late`, `dropped`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ControlKind {
    /// A sensor pin's decision about a part.
    Decision,
    /// A command to a dynamic pin, carried out in time.
    Actuation,
    /// A command that could not finish before its part arrived.
    Late,
    /// A decision dropped (a stale event, or a part that left first).
    Dropped,
}

/// What the controller runs: the rule table or online replanning (written as `policy`, `online`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ControllerMode {
    /// The rules of `[[rules]]` and the policy file.
    #[default]
    Policy,
    /// Online replanning from a belief.
    Online,
}

impl ControllerMode {
    /// The mode's name in outputs: `policy` or `online`.
    pub fn name(self) -> &'static str {
        match self {
            ControllerMode::Policy => "policy",
            ControllerMode::Online => "online",
        }
    }
}

/// An actuation's motion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MotionRecord {
    /// When the motion starts (s).
    pub t_start: f64,
    /// When the pin is ready: motion and settle time over (s).
    pub t_ready: f64,
    /// Where it starts: a moving pin's y (m), or a retractable pin's state (1 raised, 0 withdrawn).
    pub from: f64,
    /// Where it ends, in the same terms as `from`.
    pub to: f64,
}

/// Per dynamic pin: commands and motion.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct ActuatorStats {
    /// The pin's name.
    pub name: String,
    /// Commands it was given.
    pub commands: u64,
    /// Commands carried out by a motion (a command for the state the pin is in needs none).
    pub moves: u64,
    /// Commands that could not finish before their part could reach the pin.
    pub late: u64,
    /// Commands dropped because their part was no longer on the line when the pin's turn came.
    pub dropped: u64,
    /// Lateral travel of a moving pin (m).
    pub travel_m: f64,
    /// Time in motion (s).
    pub busy_s: f64,
    /// `busy_s` as a share of the simulated time, in [0, 1].
    pub utilisation: f64,
}

/// Parts per decision and how many of them ended well.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct DecisionStats {
    /// Parts that got this decision.
    pub parts: u64,
    /// Of those, parts that ended in success.
    pub success: u64,
    /// Decisions that differ from the part's true state.
    pub wrong: u64,
    /// Of the wrong decisions, the parts that failed.
    pub wrong_failed: u64,
}

/// One bin of the online controller's calibration: parts whose predicted success fell in
/// [lo, hi), their mean prediction and the share that ended in the goal.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct CalibrationBin {
    /// Lower edge of the predicted-success bin, in [0, 1].
    pub lo: f64,
    /// Upper edge (exclusive) of the bin.
    pub hi: f64,
    /// Parts whose prediction fell in the bin.
    pub parts: u64,
    /// Their mean predicted success.
    pub predicted_mean: f64,
    /// The share of them that ended in the goal.
    pub observed: f64,
}

/// What the online controller did (docs/physics.md#belief-and-online-replanning).
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct OnlineSummary {
    /// Hypotheses of the model (states × offsets × μ values × support classes).
    pub hypotheses: usize,
    /// Joint actions (commands of all dynamic pins together) the model chooses from.
    pub actions: usize,
    /// Line runs the model's build took (a run through one stretch of the line counts one).
    pub model_runs: u64,
    /// Contact-model evaluations of the model's success runs.
    pub model_evaluations: u64,
    /// Decisions taken (one per part once every sensor has spoken).
    pub decisions: u64,
    /// Mean entropy of the belief before any observation (bits).
    pub entropy_prior_bits: f64,
    /// Mean entropy of the belief at the decision (bits).
    pub entropy_posterior_bits: f64,
    /// Observations no hypothesis explained (the belief was left as it was).
    pub inconsistent: u64,
    /// Passes of a sensor without contact used as evidence.
    pub no_contact_passes: u64,
    /// Mean predicted success of the decisions.
    pub predicted_mean: f64,
    /// Observed success of the parts that got decisions.
    pub observed: f64,
    /// Predicted against observed, in ten bins of the prediction (empty bins left out).
    pub calibration: Vec<CalibrationBin>,
    /// How often each joint command was chosen (`pin=target, …`).
    pub chosen: BTreeMap<String, u64>,
    /// Per sensor: the power its matched-filter likelihood (over the hypotheses' templates) is
    /// raised to, calibrated on held-out members (0: not used).
    pub temper: BTreeMap<String, f64>,
    /// Per sensor: the power of the sensor classifier's posterior over the states (0: not used).
    pub classifier_power: BTreeMap<String, f64>,
    /// Decisions whose most probable stable state (the belief's marginal) is the part's true
    /// state (out of `state_known`).
    pub state_correct: u64,
    /// Decisions whose part has a known true state.
    pub state_known: u64,
    /// What the model says this line can do, per support class the belief declares: the best
    /// single command with no information, and with a belief certain of the hypothesis.
    pub bounds: Vec<ModelBound>,
}

/// The model's bounds for one support class (see [`crate::engine::online::OnlineModel::bounds`]).
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct ModelBound {
    /// Support class (`uniform` or `tripod`).
    pub support: String,
    /// Best success probability of a single command with no information.
    pub no_information: f64,
    /// Best success probability with a belief certain of the hypothesis.
    pub certain_hypothesis: f64,
}

/// The controller's part of the summary.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct ControllerSummary {
    /// "scenario" or the policy file.
    pub rules_from: String,
    /// Decision latency (s).
    pub latency_s: f64,
    /// What a late command does (written as `skip` or `move`).
    pub on_late: OnLate,
    /// Per sensor and decision (`<sensor>=<label>`, `unknown` for none).
    pub decisions: BTreeMap<String, DecisionStats>,
    /// Decisions that differ from the part's true state, over all sensors.
    pub misclassified: u64,
    /// Of those, the parts that failed.
    pub misclassified_failed: u64,
    /// Late actuations, over all dynamic pins.
    pub late_actuations: u64,
    /// Per dynamic pin, in obstacle order.
    pub actuators: Vec<ActuatorStats>,
    /// The rule table or online replanning.
    pub mode: ControllerMode,
    /// The online controller's record (online mode only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub online: Option<OnlineSummary>,
}

/// Running sums behind [`OnlineSummary`].
pub(super) struct OnlineRun {
    model: Arc<OnlineModel>,
    pub(super) summary: OnlineSummary,
    /// Per calibration bin: parts, Σ predicted, successes.
    bins: [(u64, f64, u64); 10],
    /// Per joint command of the model: how often it was chosen; and the names of the model's
    /// pins, to describe the commands in the summary at the end.
    pub(super) chosen: Vec<u64>,
    pin_names: Vec<String>,
}

/// The controller's run state.
pub(super) struct Control {
    pub(super) spec: Controller,
    /// Per obstacle: its timeline if it is a dynamic pin.
    pub(super) tracks: Vec<Option<Track>>,
    /// Per obstacle: targets waiting for their part's turn, by part.
    pub(super) queues: Vec<BTreeMap<u64, Target>>,
    pub(super) summary: ControllerSummary,
    /// Per obstacle: index into `summary.actuators`.
    pub(super) stats_of: Vec<Option<usize>>,
    pub(super) log: Option<Vec<ControlRecord>>,
    /// The online controller's model and record (online mode only).
    pub(super) online: Option<OnlineRun>,
}

impl Control {
    /// The controller of a scene with dynamic pins (None without: a passive or sensing-only
    /// scene runs none of this).
    pub(super) fn new(
        scene: &Scene,
        keep_log: bool,
        online: Option<super::prepare::OnlineHandle>,
    ) -> Option<Control> {
        let mut tracks = Vec::new();
        let mut stats_of = Vec::new();
        let mut summary = ControllerSummary::default();
        for o in &scene.obstacles {
            let track = match o {
                Obstacle::Pin(PinObstacle {
                    actuator: Some(Actuator::Moving(m)),
                    ..
                }) => Some(Track::moving(*m)),
                Obstacle::Pin(PinObstacle {
                    actuator: Some(Actuator::Retractable(r)),
                    ..
                }) => Some(Track::retractable(*r)),
                _ => None,
            };
            stats_of.push(track.as_ref().map(|_| {
                summary.actuators.push(ActuatorStats {
                    name: o.name().to_string(),
                    ..ActuatorStats::default()
                });
                summary.actuators.len() - 1
            }));
            tracks.push(track);
        }
        if tracks.iter().all(Option::is_none) {
            return None;
        }
        let spec = scene.controller.clone().unwrap_or(Controller {
            latency: 0.0,
            min_posterior: 0.0,
            on_late: OnLate::Skip,
            rules: Vec::new(),
            source: "none".into(),
            mode: ControlMode::Policy,
            belief_at: None,
        });
        summary.rules_from = spec.source.clone();
        summary.latency_s = spec.latency;
        summary.on_late = spec.on_late;
        let online = online.as_ref().map(|h| OnlineRun {
            chosen: vec![0; h.0.actions.len()],
            pin_names: h
                .0
                .pins
                .iter()
                .map(|&j| scene.obstacles[j].name().to_string())
                .collect(),
            model: h.0.clone(),
            summary: OnlineSummary {
                hypotheses: h.0.hypotheses.len(),
                actions: h.0.actions.len(),
                model_runs: h.0.runs,
                model_evaluations: h.0.evaluations,
                temper: h
                    .0
                    .sensors
                    .iter()
                    .map(|sm| (scene.obstacles[sm.obstacle].name().to_string(), sm.temper))
                    .collect(),
                classifier_power: h
                    .0
                    .sensors
                    .iter()
                    .map(|sm| {
                        let name = scene.obstacles[sm.obstacle].name().to_string();
                        (name, sm.classifier_power)
                    })
                    .collect(),
                bounds: {
                    let mut classes = Vec::new();
                    for x in &h.0.hypotheses {
                        if !classes.contains(&x.support) {
                            classes.push(x.support);
                        }
                    }
                    classes
                        .into_iter()
                        .map(|c| {
                            let (blind, informed) = h.0.bounds(Some(c));
                            ModelBound {
                                support: format!("{c:?}").to_lowercase(),
                                no_information: blind,
                                certain_hypothesis: informed,
                            }
                        })
                        .collect()
                },
                ..OnlineSummary::default()
            },
            bins: [(0, 0.0, 0); 10],
        });
        summary.mode = if online.is_some() {
            ControllerMode::Online
        } else {
            ControllerMode::Policy
        };
        Some(Control {
            online,
            queues: vec![BTreeMap::new(); tracks.len()],
            spec,
            tracks,
            summary,
            stats_of,
            log: keep_log.then(Vec::new),
        })
    }

    pub(super) fn latency(&self) -> f64 {
        self.spec.latency
    }

    /// The online controller's model (online mode only).
    pub(super) fn online_model(&self) -> Option<&Arc<OnlineModel>> {
        self.online.as_ref().map(|o| &o.model)
    }

    /// An observation the belief could not take (no hypothesis explains it).
    pub(super) fn count_update(&mut self, u: Update, no_contact: bool) {
        if let Some(o) = self.online.as_mut() {
            o.summary.inconsistent += u64::from(u == Update::Inconsistent);
            o.summary.no_contact_passes += u64::from(no_contact);
        }
    }

    /// A part decided online has finished: its prediction against its outcome.
    pub(super) fn calibrate(&mut self, predicted: f64, success: bool) {
        if let Some(o) = self.online.as_mut() {
            let k = ((predicted * 10.0) as usize).min(9);
            o.bins[k].0 += 1;
            o.bins[k].1 += predicted;
            o.bins[k].2 += u64::from(success);
        }
    }

    /// The decision a reading stands for once the posterior threshold is applied.
    pub(super) fn decision(
        &self,
        hypothesis: Option<usize>,
        posterior: Option<f64>,
    ) -> Option<usize> {
        hypothesis.filter(|_| posterior.is_none_or(|p| p >= self.spec.min_posterior))
    }

    /// A part has finished with `outcome`: count its decisions and, for a wrong one, whether the
    /// part failed.
    pub(super) fn count_decisions(
        &mut self,
        scene: &Scene,
        decided: &[(usize, Option<usize>, Option<usize>)],
        outcome: PartOutcome,
    ) {
        let ok = outcome == PartOutcome::Success;
        for &(sensor, decision, truth) in decided {
            let label = decision_label(scene, sensor, decision);
            let wrong = decision.is_some() && truth.is_some() && decision != truth;
            let row = self
                .summary
                .decisions
                .entry(format!("{}={label}", scene.obstacles[sensor].name()))
                .or_default();
            row.parts += 1;
            row.success += u64::from(ok);
            row.wrong += u64::from(wrong);
            row.wrong_failed += u64::from(wrong && !ok);
            self.summary.misclassified += u64::from(wrong);
            self.summary.misclassified_failed += u64::from(wrong && !ok);
        }
    }

    /// Queue `target` for dynamic pin `pin`, for part `part`'s turn.
    pub(super) fn queue_command(&mut self, pin: usize, part: u64, target: Target) {
        self.queues[pin].insert(part, target);
        if let Some(k) = self.stats_of[pin] {
            self.summary.actuators[k].commands += 1;
        }
    }

    /// Keep `r` in the control log, when the run keeps one.
    pub(super) fn log(&mut self, r: ControlRecord) {
        if let Some(l) = self.log.as_mut() {
            l.push(r);
        }
    }

    /// Close the summary at the end of the run (`span`: simulated time, s).
    pub(super) fn finish(&mut self, span: f64) -> ControllerSummary {
        for a in &mut self.summary.actuators {
            a.utilisation = if span > 0.0 { a.busy_s / span } else { 0.0 };
        }
        self.summary.late_actuations = self.summary.actuators.iter().map(|a| a.late).sum();
        if let Some(o) = self.online.as_mut() {
            let s = &mut o.summary;
            let n = s.decisions.max(1) as f64;
            s.entropy_prior_bits /= n;
            s.entropy_posterior_bits /= n;
            let parts: u64 = o.bins.iter().map(|b| b.0).sum();
            let pred: f64 = o.bins.iter().map(|b| b.1).sum();
            let ok: u64 = o.bins.iter().map(|b| b.2).sum();
            s.predicted_mean = pred / parts.max(1) as f64;
            s.observed = ok as f64 / parts.max(1) as f64;
            s.calibration = o
                .bins
                .iter()
                .enumerate()
                .filter(|(_, b)| b.0 > 0)
                .map(|(k, b)| CalibrationBin {
                    lo: k as f64 / 10.0,
                    hi: (k + 1) as f64 / 10.0,
                    parts: b.0,
                    predicted_mean: b.1 / b.0 as f64,
                    observed: b.2 as f64 / b.0 as f64,
                })
                .collect();
            s.chosen = o
                .chosen
                .iter()
                .enumerate()
                .filter(|(_, &n)| n > 0)
                .map(|(a, &n)| (describe_action(&o.pin_names, &o.model.actions[a]), n))
                .collect();
            self.summary.online = Some(s.clone());
        }
        self.summary.clone()
    }
}

/// A joint command as `pin=target, …` (the online summary's and the control log's words).
pub(super) fn describe_action(pin_names: &[String], action: &[Target]) -> String {
    pin_names
        .iter()
        .zip(action)
        .map(|(name, t)| format!("{name}={}", describe_target(*t)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A decision of sensor pin `sensor` as its hypothesis label, or `unknown`.
pub(super) fn decision_label(scene: &Scene, sensor: usize, decision: Option<usize>) -> String {
    match (decision, &scene.obstacles[sensor]) {
        (Some(h), Obstacle::Pin(p)) => p
            .sensor
            .as_ref()
            .map_or_else(|| "?".into(), |s| s.labels[h].clone()),
        _ => "unknown".into(),
    }
}

/// A command's target as `y=…` (m, every digit: a policy can be written back from it),
/// `raised` or `withdrawn`.
pub(super) fn describe_target(t: Target) -> String {
    match t {
        Target::Y(y) => format!("y={y}"),
        Target::Raised(true) => "raised".into(),
        Target::Raised(false) => "withdrawn".into(),
    }
}

/// Where pin `j` stands at time `t0` and the path it follows from then on (`speed`: the belt's,
/// m/s): a moving pin as `control`'s timeline commands it, any other pin where the scene puts it.
pub(super) fn pin_motion(
    control: Option<&Control>,
    speed: f64,
    j: usize,
    pin: &PinObstacle,
    t0: f64,
) -> (Vec2, PinPath) {
    match (control, &pin.actuator) {
        (Some(c), Some(Actuator::Moving(m))) => {
            let track = c.tracks[j].as_ref().expect("a moving pin has a track");
            let y = track.y_at(t0, pin.centre.y);
            let path = track.path_from(t0, speed, m.pieces);
            (Vec2::new(pin.centre.x, y), path)
        }
        _ => (pin.centre, PinPath::constant(0.0)),
    }
}

/// Is obstacle `j` present at time `t` (a withdrawn or moving-in retractable pin is not)?
pub(super) fn present_at(control: Option<&Control>, j: usize, t: f64) -> bool {
    match control {
        Some(c) => c.tracks[j].as_ref().is_none_or(|tr| tr.present_at(t)),
        None => true,
    }
}

/// Where obstacle `j` of `scene` can be during [ta, tb], as a capsule (None: absent throughout).
pub(super) fn capsule_during(
    control: Option<&Control>,
    scene: &Scene,
    j: usize,
    ta: f64,
    tb: f64,
) -> Option<(Vec2, Vec2, f64)> {
    let ob = &scene.obstacles[j];
    let Some(track) = control.and_then(|c| c.tracks[j].as_ref()) else {
        return Some(ob.capsule());
    };
    let Obstacle::Pin(pin) = ob else {
        return Some(ob.capsule());
    };
    match track {
        Track::Moving { .. } => {
            let (lo, hi) = track.y_span(ta, tb, pin.centre.y);
            Some((
                Vec2::new(pin.centre.x, lo),
                Vec2::new(pin.centre.x, hi),
                pin.radius,
            ))
        }
        Track::Retractable { .. } => track
            .present_during(ta, tb)
            .then_some((pin.centre, pin.centre, pin.radius)),
    }
}

#[cfg(test)]
mod tests {

    use super::*;

    fn scene(name: &str) -> Scene {
        crate::scenario::load(&crate::project_path(&format!("scenarios/{name}.toml"))).unwrap()
    }

    /// A line without dynamic pins runs no controller (it pays nothing for it); a line with
    /// dynamic pins gets one timeline and one actuator record per dynamic pin, with its mode.
    #[test]
    fn only_lines_with_dynamic_pins_get_a_controller() {
        for name in ["quickstart", "tripoly1", "tripoly1_fences", "crowded_belt"] {
            assert!(Control::new(&scene(name), false, None).is_none(), "{name}");
        }
        for (name, mode) in [
            ("tripoly1_sensing", ControllerMode::Policy),
            ("tripoly1_online", ControllerMode::Online),
        ] {
            let mut s = scene(name);
            // A small belief: the controller's set-up, not the model, is under test.
            if let Some(ControlMode::Online(spec)) = s.controller.as_mut().map(|c| &mut c.mode) {
                spec.mu_c.truncate(1);
                spec.support.truncate(1);
                spec.samples = 1;
                spec.offsets = spec.offsets.min(2);
            }
            let online = crate::engine::prepare::online_model(&s).unwrap();
            let c = Control::new(&s, true, online).expect("dynamic pins");
            let dynamic = s
                .obstacles
                .iter()
                .filter(|o| matches!(o, Obstacle::Pin(p) if p.actuator.is_some()))
                .count();
            assert!(dynamic > 0);
            assert_eq!(c.tracks.iter().filter(|t| t.is_some()).count(), dynamic);
            assert_eq!(c.summary.actuators.len(), dynamic);
            assert_eq!(c.summary.mode, mode, "{name}");
            assert!(c.log.as_ref().is_some_and(|l| l.is_empty()));
        }
    }
}
