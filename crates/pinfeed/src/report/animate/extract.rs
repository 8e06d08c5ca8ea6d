//! An [`Animation`] filled from a line run: the sample parts' paths, the obstacles, and the sensor
//! readings, decisions and controller actions of the parts shown.

use super::model::*;
use crate::engine::controller::ControlKind;
use crate::engine::controller::ControlRecord;
use crate::engine::RunResult;
use crate::geometry::{Pose, Vec2};
use crate::scenario::{Actuator, Obstacle, PinObstacle, Scene};

/// How many parts `pinfeed run --animate` shows by default: enough that several share the belt.
pub const DEFAULT_PARTS: usize = 10;

/// Fill an [`Animation`] from a run: the first `n_parts` sample paths (by part index; record at
/// least that many with `RunOptions::sample_paths`), every obstacle (pins still and raised: one
/// knot), and, when the run kept per-part records, each sensor pin's reading (at contact begin)
/// and decision (at contact end) of the parts shown. The shown span runs from the first arrival
/// to the last end plus a tenth, so the last part's outcome colour shows.
pub fn from_run(scene: &Scene, result: &RunResult, n_parts: usize) -> Animation {
    let mut paths: Vec<_> = result.paths.iter().collect();
    paths.sort_by_key(|p| p.part);
    paths.truncate(n_parts.min(MAX_PARTS));
    let parts: Vec<AnimPart> = paths
        .iter()
        .map(|p| AnimPart {
            part: p.part,
            outcome: p.outcome,
            poses: p.poses.clone(),
        })
        .collect();
    let times = parts.iter().flat_map(|p| p.poses.iter().map(|q| q.0));
    let t_first = times.clone().fold(f64::INFINITY, f64::min);
    let t_last = times.fold(f64::NEG_INFINITY, f64::max);
    let (t_start, t_end) = if t_first.is_finite() && t_last.is_finite() {
        let span = (t_last - t_first).max(1e-3);
        (t_first, t_last + 0.1 * span)
    } else {
        (0.0, scene.belt.length / scene.belt.speed)
    };
    let obstacles = scene
        .obstacles
        .iter()
        .map(|o| match o {
            Obstacle::Pin(p) => AnimObstacle {
                name: p.name.clone(),
                shape: AnimShape::Pin {
                    x: p.centre.x,
                    radius: p.radius,
                },
                sensor: p.sensor.is_some(),
                track: pin_track(p, &result.control, t_start),
            },
            Obstacle::Fence(f) => AnimObstacle {
                name: f.name.clone(),
                shape: AnimShape::Fence {
                    p0: f.start,
                    p1: f.end(),
                    tail: f
                        .spec()
                        .tail_arc()
                        .map(|(_, r, _, _)| (r, f.far_end(), f.angle_rad > 0.0)),
                },
                sensor: false,
                track: Vec::new(),
            },
        })
        .collect();
    let mut marks = Vec::new();
    for rec in &result.records {
        let Some(part) = parts.iter().find(|p| p.part == rec.part) else {
            continue;
        };
        for sensed in &rec.sensed {
            let (name, decision) = (sensed.sensor.as_str(), sensed.decision_text());
            let Some(Obstacle::Pin(pin)) = scene.obstacles.iter().find(|o| o.name() == name) else {
                continue;
            };
            let reach = scene.part.radius + pin.radius;
            if let Some((tb, te)) = contact_interval(&part.poses, pin.centre, reach) {
                marks.push(AnimMark {
                    t: tb,
                    at: pin.centre,
                    kind: MarkKind::Reading,
                    text: format!("{name}: reading"),
                });
                // With a controller its own decision records say when decisions were taken.
                if result.control.is_empty() {
                    marks.push(AnimMark {
                        t: te,
                        at: pin.centre,
                        kind: MarkKind::Decision,
                        text: format!("part {} → {decision}", part.part),
                    });
                }
            }
        }
    }
    marks.extend(control_marks(scene, &result.control, &parts));
    Animation {
        title: format!("{} — {} on the line", scene.name, part_name(scene)),
        belt_length: scene.belt.length,
        belt_width: scene.belt.width,
        belt_speed: scene.belt.speed,
        outline: scene.part.polygon.vertices().to_vec(),
        obstacles,
        parts,
        marks,
        t_start,
        t_end,
    }
}

/// A pin's knots (time, centre y, raised?): where it starts and, for a dynamic pin, each motion the
/// controller carried out (a retractable pin is withdrawn while in transit).
fn pin_track(pin: &PinObstacle, control: &[ControlRecord], t_start: f64) -> Vec<(f64, f64, bool)> {
    let home = pin.centre.y;
    let mut track = vec![(
        t_start,
        home,
        !matches!(pin.actuator, Some(Actuator::Retractable(r)) if !r.raised),
    )];
    for rec in control.iter().filter(|r| r.obstacle == pin.name) {
        let Some(m) = rec.motion else { continue };
        match pin.actuator {
            Some(Actuator::Moving(_)) => {
                track.push((m.t_start, m.from, true));
                track.push((m.t_ready, m.to, true));
            }
            Some(Actuator::Retractable(_)) => {
                track.push((m.t_start, home, false));
                track.push((m.t_ready, home, m.to > 0.5));
            }
            None => {}
        }
    }
    track.sort_by(|a, b| a.0.total_cmp(&b.0));
    track
}

/// The controller's decisions, actuations and late commands for the animated parts, as marks at
/// the sensor or the pin concerned.
fn control_marks(scene: &Scene, control: &[ControlRecord], parts: &[AnimPart]) -> Vec<AnimMark> {
    control
        .iter()
        .filter(|r| parts.iter().any(|p| p.part == r.part))
        .filter_map(|r| {
            let Some(Obstacle::Pin(pin)) = scene.obstacles.iter().find(|o| o.name() == r.obstacle)
            else {
                return None;
            };
            let what = target_in_mm(&r.what);
            let (kind, text) = match r.kind {
                ControlKind::Decision => (MarkKind::Decision, format!("part {} → {what}", r.part)),
                ControlKind::Actuation => (
                    MarkKind::Actuation,
                    format!("{} {what} for part {}", r.obstacle, r.part),
                ),
                ControlKind::Late => (
                    MarkKind::Late,
                    format!("late: {} {what} for part {}", r.obstacle, r.part),
                ),
                ControlKind::Dropped => return None,
            };
            let at = match r.motion {
                Some(m) if matches!(pin.actuator, Some(Actuator::Moving(_))) => {
                    Vec2::new(pin.centre.x, m.from)
                }
                _ => pin.centre,
            };
            Some(AnimMark {
                t: r.t,
                at,
                kind,
                text,
            })
        })
        .collect()
}

/// The first run of recorded poses whose centroid lies within `reach` (part radius + pin
/// radius) of a pin: its first and last times — contact begin and end, since a path records the
/// pose at both and the pins stand beyond reach of the entry.
fn contact_interval(poses: &[(f64, Pose)], pin: Vec2, reach: f64) -> Option<(f64, f64)> {
    let near = |p: &Pose| (p.position() - pin).norm() <= reach * (1.0 + 1e-9) + 1e-12;
    let i = poses.iter().position(|(_, p)| near(p))?;
    let mut j = i;
    while j + 1 < poses.len() && near(&poses[j + 1].1) {
        j += 1;
    }
    Some((poses[i].0, poses[j].0))
}

/// The part as a title names it: its shape's name, or `a part of N vertices` for a vertex list
/// (whose label is the key it came from, `vertices`).
fn part_name(scene: &Scene) -> String {
    match scene.part.label.as_str() {
        "vertices" => format!("a part of {} vertices", scene.part.polygon.len()),
        name => name.to_string(),
    }
}

/// A control record's words with a moving pin's target `y=0.027487370837451` (m, every digit,
/// as the control log keeps it) shown as `y=+27.49 mm`, the unit `plan` prints pins in; other
/// words as they are.
fn target_in_mm(what: &str) -> String {
    let Some(rest) = what.strip_prefix("y=") else {
        return what.to_string();
    };
    let (number, tail) = rest.split_at(rest.find(' ').unwrap_or(rest.len()));
    match number.parse::<f64>() {
        Ok(y) => format!("y={:+.2} mm{tail}", y * 1e3),
        Err(_) => what.to_string(),
    }
}

#[cfg(test)]
mod tests {
    /// Issue 57 item 16: a mover's target read `y=0.027487370837451` in the animation.
    #[test]
    fn targets_read_in_mm_to_two_decimals() {
        use super::target_in_mm;
        assert_eq!(target_in_mm("y=0.027487370837451"), "y=+27.49 mm");
        assert_eq!(target_in_mm("y=-0.0004 skipped"), "y=-0.40 mm skipped");
        assert_eq!(target_in_mm("raised"), "raised");
        assert_eq!(target_in_mm("probe=a"), "probe=a");
    }
}
