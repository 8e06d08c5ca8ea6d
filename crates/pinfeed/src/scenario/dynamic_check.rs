//! Validation of dynamic pins (`kind = "moving_pin"`, `"retractable_pin"`), of `[controller]`
//! and of `[[rules]]` or a policy file (docs/scenario-format.md#moving-and-retractable-pins,
//! #controller-and-rules). Every refusal names the file, the line and the key.
//!
//! * a moving pin's `travel` = [min, max] lies over the belt (|y| ≤ width/2) and holds its home
//!   `y`; `speed` and `accel` are positive and finite ([`super::limits::ACTUATOR_SPEED`],
//!   [`super::limits::ACTUATOR_ACCEL`]), the speed at most [`super::limits::max_pin_speed`]; `settle` ≥ 0; `pieces` in 1..=64;
//! * a retractable pin's times are ≥ 0 and finite;
//! * a rule names a sensor pin, one of that sensor's hypothesis labels (or `unknown`), a dynamic
//!   pin, and a target that fits the pin (`y` within a moving pin's travel, `raised` for a
//!   retractable one); two rules may not give the same pin two targets for the same decision;
//! * a policy file must be written for the scenario's part.

use super::checker::Checker;
use super::dynamic::{
    Actuator, BeliefSpec, ControlMode, Controller, MovingSpec, OnLate, RetractSpec, Rule, Target,
};
use super::error::Locator;
use super::limits;
use super::raw::{ObstacleKind, RawController, RawObstacle, RawPolicy, RawRule};
use super::scene::{Belt, Obstacle};
use super::sensors::SensorDraft;
use super::ScenarioError;
use std::path::Path;

type R<T> = Result<T, ScenarioError>;

/// The actuator of obstacle `i` (of kind `kind`, home at lateral `home`), if it has one.
pub(super) fn actuator(
    c: &Checker,
    i: usize,
    ro: &RawObstacle,
    kind: ObstacleKind,
    home: f64,
    belt: &Belt,
) -> R<Option<Actuator>> {
    let path = |k: &str| format!("obstacles[{i}].{k}");
    match kind {
        ObstacleKind::MovingPin => {
            let need = |k: &str, v: Option<f64>| -> R<f64> {
                let v = v.ok_or_else(|| {
                    c.err(
                        &format!("obstacles[{i}]"),
                        format!("a moving pin needs travel ([min, max] m), speed (m/s) and accel (m/s²); `{k}` is missing"),
                    )
                })?;
                c.finite(&path(k), v)
            };
            let Some(travel) = ro.travel else {
                return Err(c.err(
                    &format!("obstacles[{i}]"),
                    "a moving pin needs travel ([min, max] m over the belt), speed (m/s) and accel (m/s²); `travel` is missing",
                ));
            };
            let half = belt.width / 2.0;
            for v in travel {
                c.within(
                    &path("travel"),
                    v,
                    -half,
                    half,
                    "m; the pin's travel must stay over the belt",
                )?;
            }
            if !(travel[0] <= home && home <= travel[1]) {
                return Err(c.err(
                    &path("travel"),
                    format!(
                        "must be [min, max] with min ≤ y ≤ max (the home y = {home} m), got [{}, {}]",
                        travel[0], travel[1]
                    ),
                ));
            }
            let speed = need("speed", ro.speed)?;
            let speed = c.within(
                &path("speed"),
                speed,
                limits::ACTUATOR_SPEED.0,
                limits::max_pin_speed(belt.speed),
                &format!(
                    "m/s; at most {} belt speeds, belt.speed = {} m/s",
                    crate::mechanics::MAX_LATERAL_SPEED,
                    limits::num(belt.speed)
                ),
            )?;
            let accel = need("accel", ro.accel)?;
            let accel = c.range(&path("accel"), accel, limits::ACTUATOR_ACCEL, "m/s²")?;
            let settle = match ro.settle {
                Some(s) => c.range(&path("settle"), s, limits::ACTUATOR_TIME, "s")?,
                None => 0.0,
            };
            let pieces = ro.pieces.unwrap_or(8);
            if !(1..=64).contains(&pieces) {
                return Err(c.err(
                    &path("pieces"),
                    format!("must lie in [1, 64] (constant-speed pieces per acceleration phase), got {pieces}"),
                ));
            }
            Ok(Some(Actuator::Moving(MovingSpec {
                home,
                travel,
                speed,
                accel,
                settle,
                pieces: pieces as usize,
            })))
        }
        ObstacleKind::RetractablePin => {
            let time = |k: &str, v: Option<f64>| -> R<f64> {
                match v {
                    Some(t) => c.range(&path(k), t, limits::ACTUATOR_TIME, "s"),
                    None => Ok(0.1),
                }
            };
            Ok(Some(Actuator::Retractable(RetractSpec {
                raised: ro.raised.unwrap_or(true),
                raise_time: time("raise_time", ro.raise_time)?,
                lower_time: time("lower_time", ro.lower_time)?,
            })))
        }
        _ => Ok(None),
    }
}

/// The scene's controller from `[controller]`, `[[rules]]` and the policy file, if any.
/// `sensors` are the scene's sensor pins, untrained: rules name their hypotheses' labels;
/// `policy_text`: the policy file's text given in memory (None: read from its file).
#[allow(clippy::too_many_arguments)] // one per section of the file the controller checks against
pub(super) fn controller(
    c: &Checker,
    loc: &Locator,
    raw: Option<&RawController>,
    rules: &[RawRule],
    obstacles: &[Obstacle],
    sensors: &[SensorDraft],
    part_label: &str,
    policy_text: Option<&str>,
) -> R<Option<Controller>> {
    let dynamic = obstacles
        .iter()
        .any(|o| matches!(o, Obstacle::Pin(p) if p.actuator.is_some()));
    if raw.is_none() && rules.is_empty() {
        return Ok(None);
    }
    let rc = raw.cloned().unwrap_or_default();
    if !dynamic {
        let at = if rules.is_empty() {
            "controller"
        } else {
            "rules[0]"
        };
        return Err(c.err(
            at,
            "a controller needs a dynamic pin to drive: add an obstacle of kind \"moving_pin\" or \"retractable_pin\"",
        ));
    }
    let latency = match rc.latency {
        Some(l) => c.range("controller.latency", l, limits::ACTUATOR_TIME, "s")?,
        None => 0.01,
    };
    let min_posterior = match rc.min_posterior {
        Some(p) => c.within("controller.min_posterior", p, 0.0, 1.0, "a probability")?,
        None => 0.0,
    };
    let on_late = match rc.on_late.as_deref() {
        None | Some("skip") => OnLate::Skip,
        Some("move") => OnLate::Move,
        Some(other) => {
            return Err(c.err(
                "controller.on_late",
                format!("must be \"skip\" (leave the pin as it is for that part) or \"move\" (move anyway; the part may meet a moving pin), got \"{other}\""),
            ))
        }
    };
    let mode = control_mode(c, &rc, obstacles, sensors)?;
    let mut compiled = compile_rules(c, "rules", rules, obstacles, sensors, on_late)?;
    check_conflicts(c, &compiled, 0)?;
    let mut source = "scenario".to_string();
    if let Some(file) = &rc.policy {
        let path = loc.file.parent().unwrap_or(Path::new(".")).join(file);
        let ctx = PolicyCtx {
            obstacles,
            sensors,
            part_label,
            on_late,
        };
        compiled = policy(c, &path, policy_text, compiled, &ctx)?;
        source = path.display().to_string();
    }
    Ok(Some(Controller {
        latency,
        min_posterior,
        on_late,
        rules: compiled.into_iter().map(|(_, r)| r).collect(),
        source,
        mode,
        belief_at: None,
    }))
}

/// `[controller] mode` and `[controller.belief]`.
fn control_mode(
    c: &Checker,
    rc: &RawController,
    obstacles: &[Obstacle],
    sensors: &[SensorDraft],
) -> R<ControlMode> {
    match rc.mode.as_deref() {
        None | Some("policy") => {
            if rc.belief.is_some() {
                return Err(c.err(
                    "controller.belief",
                    "a belief is used by the online controller only: set [controller] mode = \"online\" or remove [controller.belief]",
                ));
            }
            Ok(ControlMode::Policy)
        }
        Some("online") => {
            let rb = rc.belief.clone().unwrap_or_default();
            let count = |key: &str, v: Option<usize>, dflt: usize, r: (f64, f64)| -> R<usize> {
                match v {
                    None => Ok(dflt),
                    Some(n) => c
                        .within(&format!("controller.belief.{key}"), n as f64, r.0, r.1, "a count")
                        .map(|_| n),
                }
            };
            let mu_c = match rb.mu_c {
                None => Vec::new(),
                Some(v) => {
                    if v.is_empty() || v.len() > limits::BELIEF_MU_VALUES {
                        return Err(c.err(
                            "controller.belief.mu_c",
                            format!(
                                "must list 1 to {} friction values, got {}",
                                limits::BELIEF_MU_VALUES,
                                v.len()
                            ),
                        ));
                    }
                    for (i, &m) in v.iter().enumerate() {
                        c.range(&format!("controller.belief.mu_c[{i}]"), m, limits::FRICTION, "friction")?;
                        if v[..i].contains(&m) {
                            return Err(c.err(
                                &format!("controller.belief.mu_c[{i}]"),
                                format!("{m} is listed twice; each friction value is one hypothesis, list it once"),
                            ));
                        }
                    }
                    v
                }
            };
            // Left out: the part's own support. An empty list is refused like an empty `mu_c`
            // (it would silently mean the same as leaving the key out).
            let given_empty = rb.support.as_ref().is_some_and(|v| v.is_empty());
            let support = rb.support.unwrap_or_default();
            if given_empty {
                return Err(c.err(
                    "controller.belief.support",
                    "must list 1 or 2 support classes, \"uniform\" and/or \"tripod\", got none (leave the key out for the part's own support)",
                ));
            }
            if support.len() > 2 {
                return Err(c.err(
                    "controller.belief.support",
                    "lists support classes, \"uniform\" and/or \"tripod\", each once",
                ));
            }
            if let Some(i) = (1..support.len()).find(|&i| support[..i].contains(&support[i])) {
                return Err(c.err(
                    &format!("controller.belief.support[{i}]"),
                    "lists support classes, \"uniform\" and/or \"tripod\", each once; this one is listed twice",
                ));
            }
            let first_dynamic = obstacles
                .iter()
                .filter(|o| matches!(o, Obstacle::Pin(p) if p.actuator.is_some()))
                .map(|o| o.x_range()[0])
                .fold(f64::INFINITY, f64::min);
            let sensors: Vec<&Obstacle> = sensors.iter().map(|s| &obstacles[s.obstacle]).collect();
            if sensors.is_empty() {
                return Err(c.err(
                    "controller.mode",
                    "the online controller needs a sensor pin to update its belief from: add an obstacle of kind \"sensor_pin\"",
                ));
            }
            if let Some(s) = sensors.iter().find(|o| o.x_range()[1] >= first_dynamic) {
                return Err(c.err(
                    "controller.mode",
                    format!(
                        "the online controller decides once every sensor has read the part, so every sensor pin must stand upstream of every dynamic pin; sensor \"{}\" is not",
                        s.name()
                    ),
                ));
            }
            Ok(ControlMode::Online(BeliefSpec {
                mu_c,
                support,
                offsets: count("offsets", rb.offsets, 5, limits::BELIEF_OFFSETS)?,
                samples: count("samples", rb.samples, 4, limits::BELIEF_SAMPLES)?,
                targets: count("targets", rb.targets, 25, limits::BELIEF_TARGETS)?,
            }))
        }
        Some(other) => Err(c.err(
            "controller.mode",
            format!("must be \"policy\" (look decisions up in the rules) or \"online\" (replan from a belief per part), got \"{other}\""),
        )),
    }
}

/// What a policy's rules are checked against: the scene's obstacles and sensors, its part and
/// its controller's `on_late`.
struct PolicyCtx<'a> {
    obstacles: &'a [Obstacle],
    sensors: &'a [SensorDraft],
    part_label: &'a str,
    on_late: OnLate,
}

/// The scenario's rules followed by those of the policy file at `path` (its text `given` in
/// memory, or read from the file); a policy's errors (and a rule of it that contradicts an
/// earlier one) are located in that file.
fn policy(
    c: &Checker,
    path: &Path,
    given: Option<&str>,
    mut compiled: Vec<(String, Rule)>,
    ctx: &PolicyCtx,
) -> R<Vec<(String, Rule)>> {
    let PolicyCtx {
        obstacles,
        sensors,
        part_label,
        on_late,
    } = *ctx;
    let source = match given {
        Some(text) => text.to_string(),
        None => crate::input::read_text(path).map_err(|e| {
            c.err(
                "controller.policy",
                format!("cannot read the policy file {}: {e}", path.display()),
            )
        })?,
    };
    let ploc = Locator::of(
        path,
        &source,
        "a policy file (the part it was planned for, then its [[rules]])",
    );
    let pc = Checker::new(&ploc);
    let raw: RawPolicy = toml::from_str(&source).map_err(|e| ploc.from_toml(&e))?;
    if raw.part != part_label {
        return Err(pc.err(
            "part",
            format!(
                "this policy was planned for part \"{}\", but the scenario's part is \"{part_label}\"",
                raw.part
            ),
        ));
    }
    let from = compiled.len();
    compiled.extend(compile_rules(
        &pc, "rules", &raw.rules, obstacles, sensors, on_late,
    )?);
    check_conflicts(&pc, &compiled, from)?;
    Ok(compiled)
}

fn compile_rules(
    c: &Checker,
    section: &str,
    rules: &[RawRule],
    obstacles: &[Obstacle],
    sensor_drafts: &[SensorDraft],
    on_late: OnLate,
) -> R<Vec<(String, Rule)>> {
    let find = |name: &str| {
        obstacles
            .iter()
            .position(|o| o.name() == name)
            .and_then(|j| match &obstacles[j] {
                Obstacle::Pin(p) => Some((j, p)),
                Obstacle::Fence(_) => None,
            })
    };
    let mut out = Vec::new();
    for (k, r) in rules.iter().enumerate() {
        let path = |key: &str| format!("{section}[{k}].{key}");
        let sensors: Vec<&str> = sensor_drafts.iter().map(|s| s.name.as_str()).collect();
        let sensor_of = |j: usize| sensor_drafts.iter().find(|s| s.obstacle == j);
        let Some((sj, sensor)) = find(&r.sensor).and_then(|(j, _)| Some((j, sensor_of(j)?))) else {
            return Err(c.err(
                &path("sensor"),
                format!(
                    "\"{}\" is not a sensor pin of this scenario (sensor pins: {})",
                    r.sensor,
                    list(&sensors)
                ),
            ));
        };
        let labels = sensor.hypotheses.labels();
        let decides = if r.decides == "unknown" {
            None
        } else {
            let Some(h) = labels.iter().position(|l| *l == r.decides) else {
                return Err(c.err(
                    &path("decides"),
                    format!(
                        "\"{}\" is not a hypothesis of sensor \"{}\" (its hypotheses: {}, or \"unknown\")",
                        r.decides,
                        r.sensor,
                        list(&labels.iter().map(String::as_str).collect::<Vec<_>>())
                    ),
                ));
            };
            Some(h)
        };
        let dynamic: Vec<&str> = obstacles
            .iter()
            .filter(|o| matches!(o, Obstacle::Pin(p) if p.actuator.is_some()))
            .map(|o| o.name())
            .collect();
        let Some((pj, pin)) = find(&r.pin).filter(|(_, p)| p.actuator.is_some()) else {
            return Err(c.err(
                &path("pin"),
                format!(
                    "\"{}\" is not a moving or retractable pin of this scenario (dynamic pins: {})",
                    r.pin,
                    list(&dynamic)
                ),
            ));
        };
        let target = match (pin.actuator.expect("filtered"), r.y, r.raised) {
            (Actuator::Moving(m), Some(y), None) => {
                let y = c.within(
                    &path("y"),
                    y,
                    m.travel[0],
                    m.travel[1],
                    "m; within the pin's travel",
                )?;
                Target::Y(y)
            }
            (Actuator::Retractable(_), None, Some(up)) => Target::Raised(up),
            (Actuator::Moving(_), ..) => {
                return Err(c.err(
                    &path("pin"),
                    format!(
                        "\"{}\" is a moving pin: give `y` (m) and no `raised`",
                        r.pin
                    ),
                ))
            }
            (Actuator::Retractable(_), ..) => {
                return Err(c.err(
                    &path("pin"),
                    format!(
                        "\"{}\" is a retractable pin: give `raised` (true or false) and no `y`",
                        r.pin
                    ),
                ))
            }
        };
        if on_late == OnLate::Move && matches!(target, Target::Raised(_)) {
            return Err(c.err(
                "controller.on_late",
                "\"move\" applies to moving pins only: a retractable pin rising under a part would strike it from below; use \"skip\"",
            ));
        }
        out.push((
            path("pin"),
            Rule {
                sensor: sj,
                decides,
                pin: pj,
                target,
            },
        ));
    }
    Ok(out)
}

/// Two rules may not send one pin to two places on the same decision: each rule from index
/// `from` on (the rules `c` locates) is checked against every earlier one.
fn check_conflicts(c: &Checker, rules: &[(String, Rule)], from: usize) -> R<()> {
    for (i, (at, r)) in rules.iter().enumerate().skip(from) {
        if let Some((_, q)) = rules[..i]
            .iter()
            .find(|(_, q)| q.sensor == r.sensor && q.decides == r.decides && q.pin == r.pin)
        {
            if q.target != r.target {
                return Err(c.err(at, "another rule already sends this pin elsewhere on the same decision of the same sensor"));
            }
        }
    }
    Ok(())
}

fn list(names: &[&str]) -> String {
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}
