//! A closed loop (docs/scenario-format.md#closed-loop): a reject gate at the belt's end
//! (`kind = "reject_gate"` in `[[obstacles]]`) that takes off the parts a sensor pin decided are
//! not in the goal, and an optional `[recirculation]` table: the return conveyor that carries
//! them back to the feed, its buffer, and the merge where they re-enter the belt.
//!
//! Checks (each refusal located at its key):
//! * one gate at most, listed after every pin and fence (it stands at the belt's end);
//! * `decided_by` names a sensor pin of the scene; `accept` lists labels of its hypotheses
//!   (default: those whose orientation is in the goal, so a vertex/edge sensor must list them);
//! * `reach` in (0, belt width], `y` over the belt, `actuation` in [0, 10⁴] s, `busy` a time;
//! * `[recirculation]` needs a gate; `buffer` in [1, 10⁶], `max_passes` in [1, 1000],
//!   `merge_gap` a time whose smallest value is positive (two parts never enter at once);
//! * a time is a number of seconds or a table `{ distribution = "fixed" | "uniform" |
//!   "exponential", value | min, max | mean }`, every value in [0, 10⁶] s.

use super::checker::Checker;
use super::raw::{ObstacleKind, RawObstacle, RawRecirculation, RawTime};
use super::scene::{Belt, Goal, Obstacle, PartSpec};
use super::sensors::SensorDraft;
use super::ScenarioError;
use crate::sensing::templates::Hypotheses;
use rand::RngExt;

type R<T> = Result<T, ScenarioError>;

/// Longest time a loop setting takes (s).
pub const MAX_TIME_S: f64 = 1e6;
/// Largest buffer before the merge (parts).
pub const MAX_BUFFER: u64 = 1_000_000;
/// Most passes a part may make.
pub const MAX_PASSES: u32 = 1000;
/// Passes a part may make by default.
pub const DEFAULT_MAX_PASSES: u32 = 10;
/// Default actuation time of a gate (s): an air jet's valve.
pub const DEFAULT_ACTUATION_S: f64 = 0.01;
/// Default time a gate cannot act again after acting (s).
pub const DEFAULT_BUSY_S: f64 = 0.05;

/// A time that may vary from one use to the next (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LoopTime {
    /// Always this long.
    Fixed(f64),
    /// Uniform on [min, max].
    Uniform {
        /// Shortest.
        min: f64,
        /// Longest.
        max: f64,
    },
    /// Exponential with this mean (memoryless: Poisson-like service).
    Exponential {
        /// Mean (s).
        mean: f64,
    },
}

impl LoopTime {
    /// One draw (a fixed function of one uniform from `rng`).
    pub fn draw(&self, rng: &mut impl rand::Rng) -> f64 {
        match *self {
            LoopTime::Fixed(v) => v,
            LoopTime::Uniform { min, max } => min + (max - min) * rng.random::<f64>(),
            LoopTime::Exponential { mean } => -mean * (1.0 - rng.random::<f64>()).ln(),
        }
    }
    /// The mean (s).
    pub fn mean(&self) -> f64 {
        match *self {
            LoopTime::Fixed(v) => v,
            LoopTime::Uniform { min, max } => 0.5 * (min + max),
            LoopTime::Exponential { mean } => mean,
        }
    }
    /// The second moment E\[S²\] (s²), for the Pollaczek–Khinchine formula.
    pub fn second_moment(&self) -> f64 {
        match *self {
            LoopTime::Fixed(v) => v * v,
            LoopTime::Uniform { min, max } => (min * min + min * max + max * max) / 3.0,
            LoopTime::Exponential { mean } => 2.0 * mean * mean,
        }
    }
    /// The smallest value a draw takes (s).
    pub fn least(&self) -> f64 {
        match *self {
            LoopTime::Fixed(v) => v,
            LoopTime::Uniform { min, .. } => min,
            LoopTime::Exponential { .. } => 0.0,
        }
    }
    /// As written in outputs, e.g. `5 s`, `uniform 4–6 s`, `exponential, mean 5 s`.
    pub fn describe(&self) -> String {
        match *self {
            LoopTime::Fixed(v) => format!("{v} s"),
            LoopTime::Uniform { min, max } => format!("uniform {min}–{max} s"),
            LoopTime::Exponential { mean } => format!("exponential, mean {mean} s"),
        }
    }
}

/// What a full buffer does to a part arriving at it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WhenFull {
    /// The part waits on the return conveyor until the buffer has room (counted as blocked).
    Block,
    /// The part is scrapped (counted as dropped).
    Drop,
}

/// What makes the gate take a part off.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RejectOn {
    /// Its sensor pin's decision: a hypothesis outside `accept`, or unknown (by `unknown`).
    Decision,
    /// Any touch of its pin (a contact switch, or a light barrier across the lane): a part that
    /// does not touch the pin passes.
    Contact,
    /// The online controller's belief: a part whose predicted success (at its decision) is
    /// below `min_success` is taken off; one without a decision is `unknown`.
    Belief,
}

/// The reject gate at the belt's end.
#[derive(Debug, Clone, PartialEq)]
pub struct RejectGate {
    /// Its name.
    pub name: String,
    /// The sensor pin (index in `Scene::obstacles`) whose decision commands it; None: it takes
    /// every part it can.
    pub decided_by: Option<usize>,
    /// What takes a part off.
    pub reject_on: RejectOn,
    /// With [`RejectOn::Belief`]: the least predicted success that passes.
    pub min_success: f64,
    /// The labels of the sensor's hypotheses that pass.
    pub accept: Vec<String>,
    /// Does an `unknown` decision reject the part?
    pub unknown_rejects: bool,
    /// Centre of the band across the belt it acts on (m).
    pub y: f64,
    /// Half-width of that band (m).
    pub reach: f64,
    /// From the end of the reading to the gate ready (s): a later decision lets the part pass.
    pub actuation: f64,
    /// Time it cannot act again after acting (s).
    pub busy: LoopTime,
}

/// The return conveyor, its buffer and the merge with the feed.
#[derive(Debug, Clone, PartialEq)]
pub struct Recirculation {
    /// Gate to merge (s).
    pub transit: LoopTime,
    /// Parts the buffer holds (None: unbounded).
    pub buffer: Option<u64>,
    /// What a full buffer does.
    pub when_full: WhenFull,
    /// Passes a part may make.
    pub max_passes: u32,
    /// Least time between two entries at the merge (s).
    pub merge_gap: LoopTime,
    /// How a returning part's pose is drawn: orientation and lateral offset (None: as the
    /// scene's feed draws them). A Monte Carlo sample, whose feed is one fixed pose, sets the
    /// study's nominal feed here.
    pub reentry: Option<(super::Orientation, super::Lateral)>,
}

/// A closed loop: the gate, and the return path if rejected parts go round again.
#[derive(Debug, Clone, PartialEq)]
pub struct ClosedLoop {
    /// The gate.
    pub gate: RejectGate,
    /// The return path (None: rejected parts leave the line).
    pub recirculation: Option<Recirculation>,
}

/// A time at key path `path`.
fn time(c: &Checker, path: &str, t: &RawTime) -> R<LoopTime> {
    let range = |p: &str, v: f64| c.within(p, v, 0.0, MAX_TIME_S, "s");
    match t {
        RawTime::Fixed(v) => Ok(LoopTime::Fixed(range(path, *v)?)),
        RawTime::Table(tb) => {
            let need = |k: &str, v: Option<f64>| -> R<f64> {
                let v = v.ok_or_else(|| {
                    c.err(path, format!("a {} time needs `{k}` (s)", tb.distribution))
                })?;
                range(&format!("{path}.{k}"), v)
            };
            let only = |keys: &[&str]| -> R<()> {
                for (k, given) in [
                    ("value", tb.value.is_some()),
                    ("min", tb.min.is_some()),
                    ("max", tb.max.is_some()),
                    ("mean", tb.mean.is_some()),
                ] {
                    if given && !keys.contains(&k) {
                        return Err(c.err(
                            &format!("{path}.{k}"),
                            format!(
                                "does not apply to a {} time, which takes {}",
                                tb.distribution,
                                keys.join(", ")
                            ),
                        ));
                    }
                }
                Ok(())
            };
            match tb.distribution.as_str() {
                "fixed" => {
                    only(&["value"])?;
                    Ok(LoopTime::Fixed(need("value", tb.value)?))
                }
                "uniform" => {
                    only(&["min", "max"])?;
                    let (min, max) = (need("min", tb.min)?, need("max", tb.max)?);
                    if max < min {
                        return Err(c.err(
                            &format!("{path}.max"),
                            format!("must be at least min ({min} s), got {max}"),
                        ));
                    }
                    Ok(LoopTime::Uniform { min, max })
                }
                "exponential" => {
                    only(&["mean"])?;
                    Ok(LoopTime::Exponential {
                        mean: need("mean", tb.mean)?,
                    })
                }
                other => Err(c.err(
                    &format!("{path}.distribution"),
                    format!("must be \"fixed\", \"uniform\" or \"exponential\", got \"{other}\""),
                )),
            }
        }
    }
}

/// The keys a reject gate takes.
const GATE_KEYS: &str =
    "y, reach, decided_by, reject_on, min_success, accept, unknown, actuation, busy";

/// The gate and return path of a scene: the reject gate of `raw` (if any) and `[recirculation]`.
/// `obstacles` are the compiled pins and fences, `sensors` their sensor pins' drafts.
#[allow(clippy::too_many_arguments)]
pub(super) fn compile(
    c: &Checker,
    raw: &[RawObstacle],
    recirculation: Option<&RawRecirculation>,
    obstacles: &[Obstacle],
    sensors: &[SensorDraft],
    belt: &Belt,
    part: &PartSpec,
    goal: &Goal,
    online: bool,
) -> R<Option<ClosedLoop>> {
    let gates: Vec<usize> = (0..raw.len())
        .filter(|&i| raw[i].kind == ObstacleKind::RejectGate)
        .collect();
    let Some(&i) = gates.first() else {
        return match recirculation {
            Some(_) => Err(c.err(
                "recirculation",
                "a return path needs a reject gate to feed it: add a [[obstacles]] kind = \"reject_gate\"",
            )),
            None => Ok(None),
        };
    };
    if let Some(&second) = gates.get(1) {
        return Err(c.err(
            &format!("obstacles[{second}].kind"),
            format!("a line has one reject gate (obstacles[{i}] is one)"),
        ));
    }
    if i + 1 != raw.len() {
        return Err(c.err(
            &format!("obstacles[{i}].kind"),
            "a reject gate stands at the belt's end: list it after every pin and fence",
        ));
    }
    let gate = gate(c, i, &raw[i], obstacles, sensors, belt, goal, online)?;
    let recirculation = match recirculation {
        Some(rr) => Some(compile_recirculation(c, rr, belt, part)?),
        None => None,
    };
    Ok(Some(ClosedLoop {
        gate,
        recirculation,
    }))
}

#[allow(clippy::too_many_arguments)]
fn gate(
    c: &Checker,
    i: usize,
    ro: &RawObstacle,
    obstacles: &[Obstacle],
    sensors: &[SensorDraft],
    belt: &Belt,
    goal: &Goal,
    online: bool,
) -> R<RejectGate> {
    let path = |k: &str| format!("obstacles[{i}].{k}");
    if ro.x.is_some() {
        return Err(c.err(
            &path("x"),
            format!("does not apply to a reject_gate (it stands at the belt's end, x = belt.length), which takes {GATE_KEYS} (and name)"),
        ));
    }
    super::obstacles::only_keys(c, i, ro, "reject_gate", GATE_KEYS)?;
    let name = match &ro.name {
        Some(n) if n.is_empty() => return Err(c.err(&path("name"), "must not be empty")),
        Some(n) => n.clone(),
        None => format!("gate{}", i + 1),
    };
    if obstacles.iter().any(|o| o.name() == name) {
        return Err(c.err(
            &path("name"),
            format!("'{name}' is used by another obstacle; names must be unique"),
        ));
    }
    let half = belt.width / 2.0;
    let y = match ro.y {
        Some(y) => c.within(&path("y"), y, -half, half, "m; over the belt")?,
        None => 0.0,
    };
    let reach = match ro.reach {
        Some(r) => {
            c.finite(&path("reach"), r)?;
            if !(r > 0.0 && r <= belt.width) {
                return Err(c.err(
                    &path("reach"),
                    format!(
                        "must lie in (0, {}] (m; half-width of the band it acts on, at most the belt width), got {r}",
                        belt.width
                    ),
                ));
            }
            r
        }
        None => belt.width,
    };
    let actuation = match ro.actuation {
        Some(a) => c.within(&path("actuation"), a, 0.0, 1e4, "s")?,
        None => DEFAULT_ACTUATION_S,
    };
    let busy = match &ro.busy {
        Some(t) => time(c, &path("busy"), t)?,
        None => LoopTime::Fixed(DEFAULT_BUSY_S),
    };
    let unknown_rejects = match ro.unknown.as_deref() {
        None | Some("reject") => true,
        Some("pass") => false,
        Some(other) => {
            return Err(c.err(
                &path("unknown"),
                format!("must be \"reject\" or \"pass\", got \"{other}\""),
            ))
        }
    };
    let reject_on = match ro.reject_on.as_deref() {
        None | Some("decision") => RejectOn::Decision,
        Some("contact") => RejectOn::Contact,
        Some("belief") => RejectOn::Belief,
        Some(other) => {
            return Err(c.err(
                &path("reject_on"),
                format!("must be \"decision\", \"contact\" or \"belief\", got \"{other}\""),
            ))
        }
    };
    let min_success = match ro.min_success {
        Some(_) if reject_on != RejectOn::Belief => {
            return Err(c.err(
                &path("min_success"),
                "applies only with reject_on = \"belief\"",
            ))
        }
        Some(m) => c.within(&path("min_success"), m, 0.0, 1.0, "predicted success")?,
        None => 0.5,
    };
    // The gate without a pin; the pin-commanded gates below fill in theirs.
    let pinless = RejectGate {
        name,
        decided_by: None,
        reject_on,
        min_success,
        accept: Vec::new(),
        unknown_rejects,
        y,
        reach,
        actuation,
        busy,
    };
    if reject_on == RejectOn::Belief {
        if !online {
            return Err(c.err(
                &path("reject_on"),
                "\"belief\" needs the online controller ([controller] mode = \"online\"), whose belief predicts each part's success",
            ));
        }
        if let Some(k) = ro
            .decided_by
            .as_ref()
            .map(|_| "decided_by")
            .or(ro.accept.as_ref().map(|_| "accept"))
        {
            return Err(c.err(
                &path(k),
                "does not apply with reject_on = \"belief\": the online controller's prediction decides",
            ));
        }
        return Ok(pinless);
    }
    if ro.reject_on.is_some() && ro.decided_by.is_none() {
        return Err(c.err(
            &path("reject_on"),
            "applies only with decided_by (the pin whose decision or touch commands the gate)",
        ));
    }
    if reject_on == RejectOn::Contact {
        if let Some(k) = decision_key(ro) {
            return Err(c.err(
                &path(k),
                "does not apply with reject_on = \"contact\": any touch rejects the part",
            ));
        }
        let by = ro.decided_by.as_deref().unwrap_or_default();
        let Some(j) = obstacles
            .iter()
            .position(|o| o.name() == by && matches!(o, Obstacle::Pin(_)))
        else {
            return Err(c.err(
                &path("decided_by"),
                format!("'{by}' is not a pin of this scene (reject_on = \"contact\" needs a pin)"),
            ));
        };
        return Ok(RejectGate {
            decided_by: Some(j),
            unknown_rejects: true,
            ..pinless
        });
    }
    let Some(by) = &ro.decided_by else {
        if let Some(k) = decision_key(ro) {
            return Err(c.err(
                &path(k),
                "applies only with decided_by (the sensor pin whose decision commands the gate)",
            ));
        }
        return Ok(pinless);
    };
    let Some(sensor) = sensors.iter().find(|s| s.name == by.as_str()) else {
        let names: Vec<&str> = sensors.iter().map(|s| s.name.as_str()).collect();
        let known = if names.is_empty() {
            "the scene has no sensor pin".to_string()
        } else {
            format!("its sensor pins are {}", names.join(", "))
        };
        return Err(c.err(
            &path("decided_by"),
            format!("'{by}' is not a sensor pin of this scene: {known}"),
        ));
    };
    let (j, hyps) = (sensor.obstacle, &sensor.hypotheses);
    let labels = hyps.labels();
    let accept = match &ro.accept {
        Some(list) => {
            for l in list {
                if !labels.contains(l) {
                    return Err(c.err(
                        &path("accept"),
                        format!(
                            "'{l}' is not a hypothesis of sensor pin '{by}': its labels are {}",
                            labels.join(", ")
                        ),
                    ));
                }
            }
            list.clone()
        }
        None => match hyps {
            Hypotheses::Orientations { labels, degrees } => labels
                .iter()
                .zip(degrees)
                .filter(|(_, d)| goal.matching_set(d.to_radians()).is_some())
                .map(|(l, _)| l.clone())
                .collect(),
            Hypotheses::VertexEdge { .. } => {
                return Err(c.err(
                    &path("decided_by"),
                    format!(
                        "sensor pin '{by}' tells vertex from edge, not orientations: list the labels that pass in `accept`"
                    ),
                ))
            }
        },
    };
    Ok(RejectGate {
        decided_by: Some(j),
        accept,
        ..pinless
    })
}

/// The first of the keys that only a gate commanded by a decision takes, if given.
fn decision_key(ro: &RawObstacle) -> Option<&'static str> {
    if ro.accept.is_some() {
        Some("accept")
    } else if ro.unknown.is_some() {
        Some("unknown")
    } else {
        None
    }
}

fn compile_recirculation(
    c: &Checker,
    rr: &RawRecirculation,
    belt: &Belt,
    part: &PartSpec,
) -> R<Recirculation> {
    let transit = match &rr.transit {
        Some(t) => time(c, "recirculation.transit", t)?,
        None => {
            return Err(c.err(
                "recirculation",
                "a return path needs `transit` (s, or a distribution): the time from the gate back to the merge",
            ))
        }
    };
    let buffer = match rr.buffer {
        Some(b) if (1..=MAX_BUFFER).contains(&b) => Some(b),
        Some(b) => {
            return Err(c.err(
                "recirculation.buffer",
                format!("must lie in [1, {MAX_BUFFER}] parts (leave it out for no limit), got {b}"),
            ))
        }
        None => None,
    };
    let when_full = match rr.when_full.as_deref() {
        None | Some("block") => WhenFull::Block,
        Some("drop") => WhenFull::Drop,
        Some(other) => {
            return Err(c.err(
                "recirculation.when_full",
                format!("must be \"block\" or \"drop\", got \"{other}\""),
            ))
        }
    };
    let max_passes = match rr.max_passes {
        Some(m) if (1..=MAX_PASSES).contains(&m) => m,
        Some(m) => {
            return Err(c.err(
                "recirculation.max_passes",
                format!("must lie in [1, {MAX_PASSES}], got {m}"),
            ))
        }
        None => DEFAULT_MAX_PASSES,
    };
    let merge_gap = match &rr.merge_gap {
        Some(t) => {
            let g = time(c, "recirculation.merge_gap", t)?;
            if g.least() <= 0.0 || matches!(g, LoopTime::Exponential { .. }) {
                return Err(c.err(
                    "recirculation.merge_gap",
                    "its smallest value must be positive (two parts entering at once would collide): a fixed or uniform time above 0",
                ));
            }
            g
        }
        None => LoopTime::Fixed(default_merge_gap(belt, part)),
    };
    Ok(Recirculation {
        transit,
        buffer,
        when_full,
        max_passes,
        merge_gap,
        reentry: None,
    })
}

/// The default least gap between two entries at the merge: the time the belt takes to carry two
/// part diameters (4a), so that two parts entering one after the other do not touch.
pub fn default_merge_gap(belt: &Belt, part: &PartSpec) -> f64 {
    4.0 * part.radius / belt.speed
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The moments the queueing checks use: E[S] and E[S²] of each kind, against sample moments
    /// of many draws (a wrong second moment, e.g. mean² for the exponential, fails).
    #[test]
    fn times_have_the_moments_they_state() {
        use rand::SeedableRng;
        for t in [
            LoopTime::Fixed(2.0),
            LoopTime::Uniform { min: 1.0, max: 3.0 },
            LoopTime::Exponential { mean: 2.0 },
        ] {
            let mut rng = rand::rngs::ChaCha8Rng::seed_from_u64(5);
            let n = 200_000;
            let (mut m1, mut m2) = (0.0, 0.0);
            for _ in 0..n {
                let v = t.draw(&mut rng);
                assert!(v >= t.least());
                m1 += v;
                m2 += v * v;
            }
            let (m1, m2) = (m1 / n as f64, m2 / n as f64);
            assert!((m1 - t.mean()).abs() < 0.02 * t.mean(), "{t:?}: {m1}");
            assert!(
                (m2 - t.second_moment()).abs() < 0.03 * t.second_moment(),
                "{t:?}: {m2}"
            );
        }
    }
}
