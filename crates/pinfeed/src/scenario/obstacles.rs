//! Validation and compilation of `[[obstacles]]`: pins and fences (docs/scenario-format.md;
//! docs/physics.md#fences fences, §7 the line), and the neighbour lists the engine uses to look for a second
//! obstacle during a push.
//!
//! Rules that keep a run well defined:
//! * a **pin** lies over the belt (|y| ≤ width/2), downstream of the entry by more than a + radius
//!   (so no part enters touching it) and before the exit (x < length);
//! * a **fence** is the segment from its upstream end (x, y) along `angle` (degrees from the belt
//!   direction, strictly between −90 and 90: positive fences run downstream to the left and deflect
//!   parts to the left, negative ones mirror that) for `length` (m > 0), with friction `mu_f` ≥ 0
//!   (default: the part's `mu_c`). Both ends lie over the belt (|y| ≤ width/2), the upstream end
//!   beyond a from the entry (x > a: since x grows along any allowed angle, no part enters touching
//!   the fence) and the downstream end no further than the exit (x ≤ length). An optional
//!   `tail_radius` (m, 10⁻² a to 10³ a) ends it in a circular arc tangent to it that turns it
//!   parallel to the belt; the tail's end is then the downstream end;
//! * each kind takes only its own keys: a pin's `radius`/`mu_c` on a fence (or a fence's
//!   `angle`/`length`/`mu_f` on a pin) is refused, naming the keys that kind takes;
//! * names are unique (default `pinN` / `fenceN`, N the 1-based position in the list).
//!
//! Two obstacles are neighbours when their distance (between the pins' discs and the fences'
//! segments) is at most 2a: only then can a part touching one touch the other.

use super::checker::Checker;
use super::dynamic_check;
use super::raw::{ObstacleKind, RawObstacle};
use super::scene::{Belt, FenceObstacle, Obstacle, PinObstacle};
use super::ScenarioError;
use crate::geometry::segment::segment_distance;
use crate::geometry::Vec2;

type R<T> = Result<T, ScenarioError>;

/// Compiled obstacles, their neighbour lists (ascending indices), and the sensor pins' own
/// settings (obstacle index and validated settings: their hypotheses depend on the feed, see
/// [`super::sensors::draft`]).
pub(super) type Compiled = (
    Vec<Obstacle>,
    Vec<Vec<usize>>,
    Vec<(usize, super::sensors::ValidSensor)>,
);

pub(super) fn compile_obstacles(
    c: &Checker,
    raw: &[RawObstacle],
    belt: &Belt,
    part_radius: f64,
    part_mu_c: f64,
) -> R<Compiled> {
    let mut obstacles: Vec<Obstacle> = Vec::new();
    let mut sensors = Vec::new();
    for (i, ro) in raw.iter().enumerate() {
        let at = At {
            c,
            i,
            belt,
            part_radius,
            part_mu_c,
        };
        let sensing = matches!(ro.kind, ObstacleKind::SensorPin | ObstacleKind::MovingPin);
        if ro.sensor.is_some() && !sensing {
            return Err(c.err(
                &format!("obstacles[{i}].sensor"),
                "only a kind = \"sensor_pin\" or \"moving_pin\" has a sensor",
            ));
        }
        let ob = match ro.kind {
            ObstacleKind::Fence => Obstacle::Fence(fence(&at, ro)?),
            // Not an obstacle a part meets: compiled with the closed loop (it is listed last).
            ObstacleKind::RejectGate => continue,
            kind => {
                let mut p = pin(&at, ro, kind)?;
                p.actuator = dynamic_check::actuator(c, i, ro, kind, p.centre.y, belt)?;
                let wants_sensor = kind == ObstacleKind::SensorPin || ro.sensor.is_some();
                if wants_sensor {
                    let raw_sensor = ro.sensor.clone().unwrap_or_default();
                    sensors.push((i, super::sensors::validate(c, i, &raw_sensor)?));
                }
                Obstacle::Pin(p)
            }
        };
        if obstacles.iter().any(|o| o.name() == ob.name()) {
            return Err(c.err(
                &format!("obstacles[{i}].name"),
                format!(
                    "'{}' is used by another obstacle; names must be unique",
                    ob.name()
                ),
            ));
        }
        obstacles.push(ob);
    }
    let neighbours = neighbour_lists(&obstacles, part_radius);
    Ok((obstacles, neighbours, sensors))
}

/// For each obstacle, the others a part of circumradius `a` touching it could touch: those within
/// 2a (between pin discs and fence segments), ascending.
pub fn neighbour_lists(obstacles: &[Obstacle], a: f64) -> Vec<Vec<usize>> {
    obstacles
        .iter()
        .enumerate()
        .map(|(i, p)| {
            obstacles
                .iter()
                .enumerate()
                .filter(|&(j, q)| j != i && obstacle_distance(p, q) <= 2.0 * a)
                .map(|(j, _)| j)
                .collect()
        })
        .collect()
}

/// Distance between two obstacles (0 when they overlap), m.
pub fn obstacle_distance(a: &Obstacle, b: &Obstacle) -> f64 {
    let (p1, q1, r1) = a.capsule();
    let (p2, q2, r2) = b.capsule();
    (segment_distance(p1, q1, p2, q2) - r1 - r2).max(0.0)
}

/// Refuse the keys of the other kind.
pub(super) fn only_keys(c: &Checker, i: usize, ro: &RawObstacle, kind: &str, takes: &str) -> R<()> {
    let given = [
        ("y", ro.y.is_some()),
        ("radius", ro.radius.is_some()),
        ("mu_c", ro.mu_c.is_some()),
        ("angle", ro.angle.is_some()),
        ("length", ro.length.is_some()),
        ("mu_f", ro.mu_f.is_some()),
        ("tail_radius", ro.tail_radius.is_some()),
        ("travel", ro.travel.is_some()),
        ("speed", ro.speed.is_some()),
        ("accel", ro.accel.is_some()),
        ("settle", ro.settle.is_some()),
        ("pieces", ro.pieces.is_some()),
        ("raised", ro.raised.is_some()),
        ("raise_time", ro.raise_time.is_some()),
        ("lower_time", ro.lower_time.is_some()),
        ("decided_by", ro.decided_by.is_some()),
        ("reject_on", ro.reject_on.is_some()),
        ("min_success", ro.min_success.is_some()),
        ("accept", ro.accept.is_some()),
        ("unknown", ro.unknown.is_some()),
        ("reach", ro.reach.is_some()),
        ("actuation", ro.actuation.is_some()),
        ("busy", ro.busy.is_some()),
    ];
    for (k, present) in given {
        if present && !takes.split(", ").any(|t| t == k) {
            return Err(c.err(
                &format!("obstacles[{i}].{k}"),
                format!("does not apply to a {kind}, which takes {takes} (and name)"),
            ));
        }
    }
    Ok(())
}

/// Obstacle `i` of a scene with this belt and part: checks on its keys.
struct At<'c, 'a, 'b> {
    c: &'c Checker<'a, 'b>,
    i: usize,
    belt: &'c Belt,
    part_radius: f64,
    part_mu_c: f64,
}

impl At<'_, '_, '_> {
    fn path(&self, k: &str) -> String {
        format!("obstacles[{}].{k}", self.i)
    }
    /// A required number; `needs` lists what this kind needs (for the missing-key message).
    fn need(&self, k: &str, v: Option<f64>, needs: &str) -> R<f64> {
        let v = v.ok_or_else(|| {
            self.c.err(
                &format!("obstacles[{}]", self.i),
                format!("{needs}; `{k}` is missing"),
            )
        })?;
        self.c.finite(&self.path(k), v)
    }
    /// x strictly inside (lo, belt.length): `what` names the point, `beyond` says what lo is.
    fn x_within(&self, x: f64, lo: f64, what: &str, beyond: &str) -> R<f64> {
        let length = self.belt.length;
        if x > lo && x < length {
            return Ok(x);
        }
        Err(self.c.err(
            &self.path("x"),
            format!(
                "{what} must lie in ({lo:.6}, {length}) m: beyond {beyond} from the entry at x = 0 and before the exit at belt.length, got {x}",
            ),
        ))
    }
    /// y over the belt.
    fn y_over(&self, y: f64) -> R<f64> {
        let half = self.belt.width / 2.0;
        self.c
            .within(&self.path("y"), y, -half, half, "m; over the belt")
    }
    /// A friction coefficient, or the part's μc.
    fn friction(&self, k: &str, v: Option<f64>) -> R<f64> {
        match v {
            Some(m) => self.c.range(
                &self.path(k),
                m,
                super::limits::FRICTION,
                "friction coefficient",
            ),
            None => Ok(self.part_mu_c),
        }
    }
    /// The given name, or `<prefix>N`.
    fn name(&self, given: &Option<String>, prefix: &str) -> R<String> {
        match given {
            Some(n) if !n.is_empty() => Ok(n.clone()),
            Some(_) => Err(self.c.err(&self.path("name"), "must not be empty")),
            None => Ok(format!("{prefix}{}", self.i + 1)),
        }
    }
}

fn pin(at: &At, ro: &RawObstacle, kind: ObstacleKind) -> R<PinObstacle> {
    let (what, takes, needs) = match kind {
        ObstacleKind::MovingPin => (
            "moving_pin",
            "x, y, radius, mu_c, travel, speed, accel, settle, pieces, sensor",
            "a moving pin needs x, y (its home, m), radius (m), travel ([min, max] m), speed (m/s) and accel (m/s²)",
        ),
        ObstacleKind::RetractablePin => (
            "retractable_pin",
            "x, y, radius, mu_c, raised, raise_time, lower_time",
            "a retractable pin needs x, y and radius (m)",
        ),
        ObstacleKind::SensorPin => ("sensor_pin", "x, y, radius, mu_c, sensor", "a pin needs x, y and radius (m)"),
        _ => ("pin", "x, y, radius, mu_c", "a pin needs x, y and radius (m)"),
    };
    only_keys(at.c, at.i, ro, what, takes)?;
    let radius = at.need("radius", ro.radius, needs)?;
    let radius = at.c.within(
        &at.path("radius"),
        radius,
        0.0,
        at.belt.width,
        "m; 0 is a point pin, at most the belt width",
    )?;
    let x = at.need("x", ro.x, needs)?;
    let x = at.x_within(x, radius + at.part_radius, "the pin's centre", "a + radius")?;
    let y = at.y_over(at.need("y", ro.y, needs)?)?;
    Ok(PinObstacle {
        name: at.name(&ro.name, "pin")?,
        centre: Vec2::new(x, y),
        radius,
        mu_c: at.friction("mu_c", ro.mu_c)?,
        sensor: None,
        actuator: None,
    })
}

fn fence(at: &At, ro: &RawObstacle) -> R<FenceObstacle> {
    let (c, belt) = (at.c, at.belt);
    only_keys(
        c,
        at.i,
        ro,
        "fence",
        "x, y, angle, length, mu_f, tail_radius",
    )?;
    let needs = "a fence needs x, y (its upstream end, m), angle (degrees) and length (m)";
    let x = at.need("x", ro.x, needs)?;
    let x = at.x_within(x, at.part_radius, "the fence's upstream end", "a")?;
    let y = at.y_over(at.need("y", ro.y, needs)?)?;
    let angle = at.need("angle", ro.angle, needs)?;
    if !(angle > -90.0 && angle < 90.0) {
        return Err(c.err(
            &at.path("angle"),
            format!("must lie strictly between -90 and 90 (degrees from the belt direction; positive fences run downstream to the left and deflect parts to the left), got {angle}"),
        ));
    }
    let length = at.need("length", ro.length, needs)?;
    let (lo, hi) = super::limits::FENCE_LENGTH_OF_A;
    let (min_length, max_length) = (lo * at.part_radius, hi * at.part_radius);
    let length = c.finite(&at.path("length"), length)?;
    if !(min_length..=max_length).contains(&length) {
        return Err(c.err(
            &at.path("length"),
            format!(
                "must lie in [{}, {}] m (10⁻⁶ a to 10⁶ a, a = {} m: a shorter fence is a point, a longer one a slide of more than 10⁶ part sizes), got {}",
                super::limits::num(min_length),
                super::limits::num(max_length),
                super::limits::num(at.part_radius),
                super::limits::num(length)
            ),
        ));
    }
    let tail_radius = match ro.tail_radius {
        None => None,
        Some(r) => {
            let (lo, hi) = super::limits::FENCE_TAIL_RADIUS_OF_A;
            let (min_r, max_r) = (lo * at.part_radius, hi * at.part_radius);
            let r = c.finite(&at.path("tail_radius"), r)?;
            if !(min_r..=max_r).contains(&r) {
                return Err(c.err(
                    &at.path("tail_radius"),
                    format!(
                        "must lie in [{}, {}] m (10⁻² a to 10³ a, a = {} m: a sharper tail is the fence's corner, a wider one turns the fence over more than a thousand part sizes), got {}",
                        crate::mechanics::limits::short(min_r),
                        crate::mechanics::limits::short(max_r),
                        crate::mechanics::limits::short(at.part_radius),
                        super::limits::num(r)
                    ),
                ));
            }
            Some(r)
        }
    };
    let f = FenceObstacle {
        name: at.name(&ro.name, "fence")?,
        start: Vec2::new(x, y),
        angle_rad: angle.to_radians(),
        length,
        mu_f: at.friction("mu_f", ro.mu_f)?,
        tail_radius,
    };
    let end = f.far_end();
    let half = belt.width / 2.0;
    // A little slack for ends placed exactly on an edge by trigonometry.
    let slack = 1e-9 * (belt.width + belt.length);
    if end.x > belt.length + slack || end.y.abs() > half + slack {
        return Err(c.err(
            &at.path("length"),
            format!(
                "the fence's downstream end{} ({:.6}, {:.6}) m lies off the belt (it must keep x ≤ belt.length = {} and |y| ≤ width/2 = {half}): shorten the fence{} or change its angle, got length {length}",
                if f.tail_radius.is_some() { " (its tail's end)" } else { "" },
                end.x, end.y, belt.length,
                if f.tail_radius.is_some() { " or its tail" } else { "" }
            ),
        ));
    }
    Ok(f)
}
