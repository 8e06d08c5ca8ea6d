//! One Monte Carlo sample: one part sent through a freshly perturbed copy of the line.
//!
//! Why one part per sample: the draws are then independent and identically distributed, so the
//! success rate is a binomial proportion whose 95% Wilson interval is honest. (A whole line run
//! per sample would give correlated parts within a sample.) The price: a single part never meets
//! another, so part–part collisions — a matter of headway, not of robustness — do not occur;
//! `pinfeed run` measures those. Everything that is per line in reality (pin errors, belt speed)
//! is drawn afresh for every sample, so the success rate is the probability that a random part on
//! a random realisation of the line ends in the goal.
//!
//! Random streams (docs/physics.md#determinism): sample i of a study seeded with s draws fifteen
//! sub-seeds from `random::stream(s, i)`, in the fixed order μc, belt speed, shape, pin x, pin y,
//! pin radius, pose θ, pose y, support, feed, sensor noise, sensor bias, sensor threshold, sensor
//! jitter, sensor readings, and each parameter draws from its own ChaCha8 stream seeded with its
//! sub-seed. (The sensor sub-seeds come last, so a study written before they existed draws the same
//! numbers as it always did.) A parameter's draws therefore never depend on how many draws another one needed
//! (redraws), on the thread count or on sharding, and sample i sees the same underlying numbers at
//! every sweep point (common random numbers). The fence, actuator and controller parameters' nine
//! sub-seeds (fence μf, angle, x, y, length, actuator speed, acceleration, settle, controller
//! latency) come after the readings' seed, and are drawn only at a sweep point that declares one
//! of them: a study without them does no work for them and draws what it always drew.
//!
//! What is drawn, per sample:
//! * μc: one value, used at every pin (replacing each pin's own μc);
//! * belt speed: one value (in the quasi-static model it rescales time: latencies, not outcomes);
//! * shape: an error added to each coordinate of each vertex (part frame, m); the polygon is
//!   re-validated and re-centred on its new centroid; an invalid polygon (self-intersecting, too
//!   wide for the belt, or a sliver that cannot carry the support model) is redrawn and counted,
//!   and after 1000 failures in a row the study stops with an error naming the sample;
//! * support: uniform, a random tripod, or a random smooth density ([`crate::mechanics::support::smooth`]),
//!   on the perturbed polygon;
//! * pins: errors added to each pin's x, y and radius; a pin that would leave the belt, sit within
//!   a + radius of the entry, or get a negative radius is redrawn (counted);
//! * pose: the scenario's own feed draws the entry orientation and lateral offset, then the pose
//!   errors are added; the lateral offset is clamped to keep the part on the belt;
//! * sensors: one value of each sensor parameter, applied to every sensor pin (which is a pin like
//!   any other for the errors above and keeps its sensor): the jitter error is added to the jitter,
//!   the bias error to the force bias (torque bias unchanged: a force channel's zero offset puts no
//!   offset on the torque channels), the threshold replaces the timing threshold, and then the
//!   noise factor multiplies the white-noise σ of every channel and the jitter
//!   ([`SensorSettings::with_noise_factor`]). A value that would make some sensor's settings invalid
//!   (a negative jitter, say) is redrawn (counted). The classifier stays the one trained on the
//!   scenario's nominal sensor: the study measures a classifier whose sensor is not what it assumed;
//! * readings: the sensor's noise in sample i is drawn from the sample's own readings sub-seed,
//!   so readings are independent across samples.
//!
//! * fences: one μf per sample, used at every fence `fence_mu_f` reaches (μc never reaches a
//!   fence); errors added to each fence's angle, upstream end and length, drawn per fence and
//!   redrawn together (counted) until the fence is one the scenario would accept;
//! * actuators: per dynamic pin, factors on the speed (a retractable pin's raise and lower times
//!   are divided by it) and on a moving pin's acceleration, an error added to a moving pin's
//!   settle time, redrawn together (counted) until the actuator is valid; the controller's
//!   latency plus one error per sample.
//!
//! Obstacles are matched exhaustively: a pin (sensor or not) gets the pin errors and, if it is
//! dynamic, the actuator parameters; a fence gets the fence parameters — explicitly, so that a new
//! kind of obstacle cannot slip through this step unnoticed. Fence and actuator parameters reach
//! only the obstacles their `fences`/`pins` selector names, if it names any.

use super::distribution::{Distribution, DrawError, MAX_REDRAWS};
use super::perturbations::Perturbations;
use crate::engine::part_stream::draw_part;
use crate::engine::{self, PartOutcome, RunOptions};
use crate::geometry::{Polygon, PolygonError, Vec2};
use crate::mechanics::limits::short;
use crate::mechanics::support::{draw_support, SupportDrawError};
use crate::mechanics::{PartModel, PartModelError};
use crate::random::{stream, ChaCha8Rng};
use crate::scenario::limits::{num, show, ACTUATOR_TIME};
use crate::scenario::{
    Actuator, Arrival, Controller, Feed, FenceObstacle, Lateral, MovingSpec, Obstacle, Orientation,
    PartSpec, PinObstacle, RetractSpec, Scene, SensorPin, SupportKind,
};
use crate::sensing::settings::SettingError;
use crate::sensing::SensorSettings;
use rand::{RngExt, SeedableRng};
use std::sync::Arc;

/// Redraws of a whole polygon before the study gives up.
pub const MAX_SHAPE_REDRAWS: u32 = 1000;

/// What one sample produced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleResult {
    /// The class the part ended in.
    pub outcome: PartOutcome,
    /// Pin encounters (pushes).
    pub contacts: u32,
    /// Entry → exit (µs), for parts that reach the end of the belt.
    pub latency_us: Option<u64>,
    /// Perturbed polygons redrawn because they were invalid.
    pub shape_redraws: u32,
    /// Other values redrawn (out of their domain: negative friction, pins off the belt, …).
    pub other_redraws: u32,
    /// Readings taken by the line's sensor pins, and those decided correctly (0 without sensors).
    pub sensor_readings: u32,
    /// Of those readings, the ones decided correctly.
    pub sensor_correct: u32,
    /// The online controller's decision on the part (None without one, or without a decision).
    pub online: Option<super::online::OnlineSample>,
    /// A closed loop: the passes the part made (None on an open line).
    pub passes: Option<u32>,
}

/// The per-parameter random streams of one sample.
struct Streams {
    mu_c: ChaCha8Rng,
    belt_speed: ChaCha8Rng,
    shape: ChaCha8Rng,
    pin_x: ChaCha8Rng,
    pin_y: ChaCha8Rng,
    pin_radius: ChaCha8Rng,
    pose_theta: ChaCha8Rng,
    pose_y: ChaCha8Rng,
    support: ChaCha8Rng,
    feed_seed: u64,
    sensor_noise: ChaCha8Rng,
    sensor_bias: ChaCha8Rng,
    sensor_threshold: ChaCha8Rng,
    sensor_jitter: ChaCha8Rng,
    /// Seed of the sample's line run: its sensor readings' noise.
    readings_seed: u64,
    /// The fence and actuator parameters' streams, seeded only when the point declares one.
    obstacles: Option<ObstacleStreams>,
}

/// The streams of the fence, actuator and controller parameters (sub-seeds drawn after every
/// earlier one, in this order).
struct ObstacleStreams {
    fence_mu_f: ChaCha8Rng,
    fence_angle: ChaCha8Rng,
    fence_x: ChaCha8Rng,
    fence_y: ChaCha8Rng,
    fence_length: ChaCha8Rng,
    actuator_speed: ChaCha8Rng,
    actuator_accel: ChaCha8Rng,
    actuator_settle: ChaCha8Rng,
    controller_latency: ChaCha8Rng,
}

/// Sub-streams a sample seeds without fence and actuator parameters (the 14 parameter streams
/// and the feed's and readings' seeds count as one each), and with them.
pub const BASE_STREAMS: u32 = 15;
/// Further sub-streams a sample seeds when a point declares fence or actuator parameters.
pub const OBSTACLE_STREAMS: u32 = 9;

impl Streams {
    /// The sample's streams; `obstacles`: also seed the fence and actuator parameters' streams.
    fn new(seed: u64, sample: u64, obstacles: bool) -> Streams {
        let mut master = stream(seed, sample);
        let mut next = || ChaCha8Rng::seed_from_u64(master.random::<u64>());
        let (mu_c, belt_speed, shape, pin_x, pin_y, pin_radius, pose_theta, pose_y, support) = (
            next(),
            next(),
            next(),
            next(),
            next(),
            next(),
            next(),
            next(),
            next(),
        );
        let feed_seed = master.random::<u64>();
        // Appended after the feed's: every earlier sub-seed is what it was before sensors.
        let mut next = || ChaCha8Rng::seed_from_u64(master.random::<u64>());
        let (sensor_noise, sensor_bias, sensor_threshold, sensor_jitter) =
            (next(), next(), next(), next());
        let readings_seed = master.random::<u64>();
        // Appended after the readings' seed: every earlier sub-seed is what it was before them,
        // and a study without them seeds none.
        let obstacles = obstacles.then(|| {
            let mut next = || ChaCha8Rng::seed_from_u64(master.random::<u64>());
            ObstacleStreams {
                fence_mu_f: next(),
                fence_angle: next(),
                fence_x: next(),
                fence_y: next(),
                fence_length: next(),
                actuator_speed: next(),
                actuator_accel: next(),
                actuator_settle: next(),
                controller_latency: next(),
            }
        });
        Streams {
            mu_c,
            belt_speed,
            shape,
            pin_x,
            pin_y,
            pin_radius,
            pose_theta,
            pose_y,
            support,
            feed_seed,
            sensor_noise,
            sensor_bias,
            sensor_threshold,
            sensor_jitter,
            readings_seed,
            obstacles,
        }
    }

    /// Sub-streams seeded (see [`BASE_STREAMS`]).
    fn seeded(&self) -> u32 {
        BASE_STREAMS + self.obstacles.as_ref().map_or(0, |_| OBSTACLE_STREAMS)
    }
}

/// A drawn scene and the redraws it needed.
pub struct DrawnScene {
    /// The perturbed line with a one-part feed at the drawn pose.
    pub scene: Scene,
    /// Perturbed polygons redrawn because they were invalid.
    pub shape_redraws: u32,
    /// Other values redrawn because they left their domain.
    pub other_redraws: u32,
    /// The seed to run the scene with: it draws the sensor readings' noise (0 when the line has
    /// no sensor pin, as before sensors existed).
    pub run_seed: u64,
    /// Random sub-streams the sample seeded: [`BASE_STREAMS`], plus [`OBSTACLE_STREAMS`] when
    /// the point declares a fence, actuator or controller parameter (the work a study without
    /// them does not do).
    pub streams: u32,
}

/// One sample's values of the sensor parameters (`None`: the scenario's own setting).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct SensorDraw {
    noise: Option<f64>,
    bias: Option<f64>,
    threshold: Option<f64>,
    jitter: Option<f64>,
}

impl SensorDraw {
    fn is_nominal(&self) -> bool {
        *self == SensorDraw::default()
    }

    /// The settings of a sensor under these values (module docs: errors first, then the factor).
    fn apply(&self, s: &SensorSettings) -> SensorSettings {
        let mut out = *s;
        if let Some(b) = self.bias {
            out.bias_force += b;
        }
        if let Some(t) = self.threshold {
            out.threshold = t;
        }
        if let Some(j) = self.jitter {
            out.jitter += j;
        }
        match self.noise {
            Some(f) => out.with_noise_factor(f),
            None => out,
        }
    }
}

/// The sensors of the scene's pins.
fn sensors(scene: &Scene) -> Vec<&SensorPin> {
    scene
        .obstacles
        .iter()
        .filter_map(|o| match o {
            Obstacle::Pin(p) => p.sensor.as_deref(),
            Obstacle::Fence(_) => None,
        })
        .collect()
}

/// Why a sample could not be drawn ([`draw_scene`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SampleError {
    /// A parameter's distribution gave no value in its domain; `range`, when known, says which
    /// range the values left.
    #[error(
        "{name}: {error}{}",
        .range.as_ref().map(|r| format!(": {r}")).unwrap_or_default()
    )]
    Value {
        /// The parameter (`mu_c`, `pin_x`, …).
        name: &'static str,
        /// The failed draw.
        error: DrawError,
        /// The range the values left, when known.
        range: Option<RangeLeft>,
    },
    /// A vertex error of the perturbed polygon could not be drawn.
    #[error("{0}")]
    ShapeDraw(DrawError),
    /// Every perturbed polygon drawn was invalid.
    #[error(
        "shape: {MAX_SHAPE_REDRAWS} perturbed polygons in a row were invalid (last: {}); the shape tolerance is too large for this part",
        .last.as_ref().map(ToString::to_string).unwrap_or_default()
    )]
    Shape {
        /// Why the last one was rejected.
        last: Option<ShapeRejection>,
    },
    /// The part's support could not be drawn.
    #[error("support: {0}")]
    Support(SupportDrawError),
    /// The part's model could not be compiled on its drawn support.
    #[error("support: {0}")]
    Model(PartModelError),
    /// A pin's sensor settings are invalid once perturbed.
    #[error("sensor pin `{pin}`: the perturbed sensor settings are invalid ({error})")]
    SensorSettings {
        /// The pin's name.
        pin: String,
        /// The invalid setting.
        error: SettingError,
    },
    /// Every perturbed position of a pin was invalid.
    #[error(
        "pin `{pin}`: {} perturbed positions in a row left the belt, touched the entry or had a negative radius",
        MAX_REDRAWS + 1
    )]
    Pin {
        /// The pin's name.
        pin: String,
    },
    /// Every perturbed fence was invalid.
    #[error(
        "fence `{fence}`: {} perturbed fences in a row were invalid (an angle not strictly between -90° and 90°, an end off the belt or within a of the entry, or a length out of [1e-6 a, 1e6 a])",
        MAX_REDRAWS + 1
    )]
    Fence {
        /// The fence's name.
        fence: String,
    },
    /// Every perturbed actuator of a pin was invalid.
    #[error(
        "pin `{pin}`: {} perturbed actuators in a row were invalid; on this pin {}",
        MAX_REDRAWS + 1,
        .allowed.iter().map(ToString::to_string).collect::<Vec<_>>().join(", ")
    )]
    Actuator {
        /// The pin's name.
        pin: String,
        /// The values of each actuator parameter reaching the pin that keep its actuator valid.
        allowed: Vec<ActuatorRange>,
    },
    /// The scenario's feed could not draw the part's entry.
    #[error("{0}")]
    Entry(PartModelError),
}

impl SampleError {
    /// The study parameters that may have caused the error, most likely first (the study's error
    /// is located at the first one the study gives).
    pub fn parameters(&self) -> Vec<&'static str> {
        use super::compile::{FENCE_PARAMETERS, SENSOR_PARAMETERS};
        match self {
            SampleError::Value { name, .. } => vec![name],
            SampleError::ShapeDraw(_) | SampleError::Shape { .. } => vec!["shape"],
            SampleError::Support(_) | SampleError::Model(_) => vec!["support", "shape"],
            SampleError::SensorSettings { .. } => SENSOR_PARAMETERS.to_vec(),
            SampleError::Pin { .. } => vec!["pin_x", "pin_y", "pin_radius"],
            SampleError::Fence { .. } => FENCE_PARAMETERS.to_vec(),
            SampleError::Actuator { allowed, .. } => allowed.iter().map(|r| r.parameter).collect(),
            SampleError::Entry(_) => vec!["pose_theta", "pose_y"],
        }
    }

    /// A failed value draw with the range its values left (other errors as they are).
    fn left(self, left: Option<RangeLeft>) -> SampleError {
        match self {
            SampleError::Value { name, error, .. } => SampleError::Value {
                name,
                error,
                range: left,
            },
            other => other,
        }
    }
}

/// The values of one actuator parameter that keep one pin's actuator in the scenario's ranges
/// ([`SampleError::Actuator`]), with the setting they act on.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "{parameter} must lie in [{}, {}] (its {setting} {} {unit} must stay in {} {unit})",
    short(.values.0),
    short(.values.1),
    num(*.nominal),
    show(*.setting_range)
)]
pub struct ActuatorRange {
    /// `actuator_speed`, `actuator_accel` or `actuator_settle`.
    pub parameter: &'static str,
    /// The factors (speed, accel) or errors (settle) that keep the setting in range.
    pub values: (f64, f64),
    /// The setting, in words (`speed`, `raise and lower times`, …).
    pub setting: &'static str,
    /// The scenario's value of the setting (the longer of a retractable pin's two times).
    pub nominal: f64,
    /// The setting's range.
    pub setting_range: (f64, f64),
    /// The setting's unit.
    pub unit: &'static str,
}

/// The actuator parameters' allowed values on actuator `a` (only those in `reached`) on a belt
/// running at `belt_speed`.
fn actuator_ranges(a: Actuator, belt_speed: f64, reached: [bool; 3]) -> Vec<ActuatorRange> {
    use crate::scenario::limits::{max_pin_speed, ACTUATOR_ACCEL, ACTUATOR_SPEED};
    let factor = |parameter, setting, nominal: f64, range: (f64, f64), unit| ActuatorRange {
        parameter,
        values: (range.0 / nominal, range.1 / nominal),
        setting,
        nominal,
        setting_range: range,
        unit,
    };
    let mut out = Vec::new();
    match a {
        Actuator::Moving(m) => {
            let speed = (ACTUATOR_SPEED.0, max_pin_speed(belt_speed));
            if reached[0] {
                out.push(factor("actuator_speed", "speed", m.speed, speed, "m/s"));
            }
            if reached[1] {
                out.push(factor(
                    "actuator_accel",
                    "acceleration",
                    m.accel,
                    ACTUATOR_ACCEL,
                    "m/s²",
                ));
            }
            if reached[2] {
                out.push(ActuatorRange {
                    parameter: "actuator_settle",
                    values: (ACTUATOR_TIME.0 - m.settle, ACTUATOR_TIME.1 - m.settle),
                    setting: "settle time",
                    nominal: m.settle,
                    setting_range: ACTUATOR_TIME,
                    unit: "s",
                });
            }
        }
        Actuator::Retractable(r) if reached[0] => {
            // The times are divided by the factor: t / f ≤ the longest time.
            let t = r.raise_time.max(r.lower_time);
            out.push(ActuatorRange {
                parameter: "actuator_speed",
                values: (t / ACTUATOR_TIME.1, super::compile::ACTUATOR_FACTOR.1),
                setting: "longer raise/lower time, divided by it,",
                nominal: t,
                setting_range: ACTUATOR_TIME,
                unit: "s",
            });
        }
        Actuator::Retractable(_) => {}
    }
    out
}

/// Which range a parameter's values left ([`SampleError::Value`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RangeLeft {
    /// The study's domain of the parameter.
    #[error("{name} must lie in {} ({unit}), it reaches {value}", show(*.domain))]
    Domain {
        /// The parameter.
        name: &'static str,
        /// Its domain.
        domain: (f64, f64),
        /// What it is, in words.
        unit: &'static str,
        /// The end of the distribution outside the domain.
        value: f64,
    },
    /// A sensor's own setting.
    #[error("at {name} = {value} the sensor's {error}")]
    Setting {
        /// The parameter.
        name: &'static str,
        /// The end of the distribution that makes the setting invalid.
        value: f64,
        /// The invalid setting.
        error: SettingError,
    },
    /// The controller's latency plus the error.
    #[error(
        "the controller's latency ({latency} s) plus the error must lie in {} s",
        show(ACTUATOR_TIME)
    )]
    Latency {
        /// The scenario's controller latency (s).
        latency: f64,
    },
}

/// Why a perturbed polygon was rejected ([`SampleError::Shape`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShapeRejection {
    /// The part no longer fits the belt.
    #[error("the part (2a = {width_2a:.6} m) no longer fits the belt ({belt} m)")]
    Belt {
        /// The part's width 2a (m).
        width_2a: f64,
        /// The belt's width (m).
        belt: f64,
    },
    /// The vertices do not make a valid part.
    #[error("{0}")]
    Polygon(PolygonError),
}

/// Draw the sample's sensor parameters; a value that would make any sensor's settings invalid is
/// redrawn (counted in `redraws`).
fn draw_sensor_values(
    base: &Scene,
    p: &Perturbations,
    st: &mut Streams,
    redraws: &mut u32,
) -> Result<SensorDraw, SampleError> {
    if !p.perturbs_sensors() {
        return Ok(SensorDraw::default());
    }
    let sensors = sensors(base);
    let mut pick = |d: &Option<Distribution>,
                    rng: &mut ChaCha8Rng,
                    name: &'static str,
                    set: fn(f64) -> SensorDraw|
     -> Result<Option<f64>, SampleError> {
        let ok = |v: f64| {
            super::compile::in_domain(name, v)
                && sensors
                    .iter()
                    .all(|s| set(v).apply(&s.settings).validate().is_ok())
        };
        draw_value(d, rng, name, ok, redraws).map_err(|e| {
            // Say which range the values left: the study's domain, or a sensor's own setting.
            let (domain, unit) = super::compile::domain(name);
            let why = d.as_ref().and_then(|d| {
                let (lo, hi) = d.range();
                [lo, hi].into_iter().find_map(|value| {
                    if !super::compile::in_domain(name, value) {
                        return Some(RangeLeft::Domain {
                            name,
                            domain,
                            unit,
                            value,
                        });
                    }
                    sensors.iter().find_map(|s| {
                        let error = set(value).apply(&s.settings).validate().err()?;
                        Some(RangeLeft::Setting { name, value, error })
                    })
                })
            });
            e.left(why)
        })
    };
    Ok(SensorDraw {
        noise: pick(&p.sensor_noise, &mut st.sensor_noise, "sensor_noise", |v| {
            SensorDraw {
                noise: Some(v),
                ..SensorDraw::default()
            }
        })?,
        bias: pick(&p.sensor_bias, &mut st.sensor_bias, "sensor_bias", |v| {
            SensorDraw {
                bias: Some(v),
                ..SensorDraw::default()
            }
        })?,
        threshold: pick(
            &p.sensor_threshold,
            &mut st.sensor_threshold,
            "sensor_threshold",
            |v| SensorDraw {
                threshold: Some(v),
                ..SensorDraw::default()
            },
        )?,
        jitter: pick(
            &p.sensor_jitter,
            &mut st.sensor_jitter,
            "sensor_jitter",
            |v| SensorDraw {
                jitter: Some(v),
                ..SensorDraw::default()
            },
        )?,
    })
}

/// A pin's sensor under the sample's sensor values: the same sensor (and trained classifier) with
/// perturbed settings.
fn perturb_sensor(
    pin: &PinObstacle,
    values: &SensorDraw,
) -> Result<Option<Arc<SensorPin>>, SampleError> {
    let Some(sensor) = &pin.sensor else {
        return Ok(None);
    };
    if values.is_nominal() {
        return Ok(Some(Arc::clone(sensor)));
    }
    let settings = values.apply(&sensor.settings);
    settings
        .validate()
        .map_err(|error| SampleError::SensorSettings {
            pin: pin.name.clone(),
            error,
        })?;
    Ok(Some(Arc::new(SensorPin {
        settings,
        ..SensorPin::clone(sensor)
    })))
}

fn draw_value(
    d: &Option<Distribution>,
    rng: &mut ChaCha8Rng,
    name: &'static str,
    ok: impl Fn(f64) -> bool,
    redraws: &mut u32,
) -> Result<Option<f64>, SampleError> {
    match d {
        None => Ok(None),
        Some(d) => {
            let (v, n) = d.draw(rng, ok).map_err(|error| SampleError::Value {
                name,
                error,
                range: None,
            })?;
            *redraws += n;
            Ok(Some(v))
        }
    }
}

/// Obstacles a part pushed by obstacle i could touch (within 2a; as the scenario compiles them).
fn neighbours(obstacles: &[Obstacle], a: f64) -> Vec<Vec<usize>> {
    crate::scenario::obstacles::neighbour_lists(obstacles, a)
}

/// Draw the perturbed polygon (metres, part frame).
fn draw_polygon(
    base: &Scene,
    d: &Option<Distribution>,
    rng: &mut ChaCha8Rng,
    redraws: &mut u32,
) -> Result<Polygon, SampleError> {
    let Some(d) = d else {
        return Ok(base.part.polygon.clone());
    };
    let mut last = None;
    for _ in 0..MAX_SHAPE_REDRAWS {
        let mut pts = Vec::with_capacity(base.part.polygon.len());
        for v in base.part.polygon.vertices() {
            let (ex, _) = d.draw(rng, |_| true).map_err(SampleError::ShapeDraw)?;
            let (ey, _) = d.draw(rng, |_| true).map_err(SampleError::ShapeDraw)?;
            pts.push(Vec2::new(v.x + ex, v.y + ey));
        }
        match Polygon::new(&pts) {
            Ok(p) if 2.0 * p.radius() <= base.belt.width => return Ok(p),
            Ok(p) => {
                last = Some(ShapeRejection::Belt {
                    width_2a: 2.0 * p.radius(),
                    belt: base.belt.width,
                })
            }
            Err(e) => last = Some(ShapeRejection::Polygon(e)),
        }
        *redraws += 1;
    }
    Err(SampleError::Shape { last })
}

/// One obstacle of the perturbed line: a pin (with or without a sensor) with its position and
/// radius errors (redrawn until it lies over the belt, clear of the entry, with a radius ≥ 0), the
/// sample's μc, its sensor under the sample's sensor values and its actuator under the actuator
/// parameters; a fence under the fence parameters ([`draw_fence`]). No catch-all: a new obstacle
/// kind must be handled here.
#[allow(clippy::too_many_arguments)]
fn draw_obstacle(
    ob: &Obstacle,
    p: &Perturbations,
    st: &mut Streams,
    belt: &crate::scenario::Belt,
    radius: f64,
    mu_c: Option<f64>,
    mu_f: Option<f64>,
    sensor_values: &SensorDraw,
    other: &mut u32,
) -> Result<Obstacle, SampleError> {
    let pin = match ob {
        Obstacle::Pin(pin) => pin,
        Obstacle::Fence(fence) => {
            let drawn = match st.obstacles.as_mut() {
                Some(ost) => draw_fence(fence, p, ost, belt, radius, mu_f, other)?,
                None => fence.clone(),
            };
            return Ok(Obstacle::Fence(drawn));
        }
    };
    let actuator = match (pin.actuator, st.obstacles.as_mut()) {
        (Some(a), Some(ost)) => Some(draw_actuator(&pin.name, a, p, ost, belt, other)?),
        (a, _) => a,
    };
    let any = |_: f64| true;
    for _ in 0..=super::distribution::MAX_REDRAWS {
        let mut none = 0;
        let ex = draw_value(&p.pin_x, &mut st.pin_x, "pin_x", any, &mut none)?;
        let ey = draw_value(&p.pin_y, &mut st.pin_y, "pin_y", any, &mut none)?;
        let er = draw_value(
            &p.pin_radius,
            &mut st.pin_radius,
            "pin_radius",
            any,
            &mut none,
        )?;
        let centre = pin.centre + Vec2::new(ex.unwrap_or(0.0), ey.unwrap_or(0.0));
        let r = pin.radius + er.unwrap_or(0.0);
        let valid = r >= 0.0
            && centre.y.abs() <= belt.width / 2.0
            && centre.x > radius + r
            && centre.x < belt.length;
        if valid {
            return Ok(Obstacle::Pin(PinObstacle {
                name: pin.name.clone(),
                centre,
                radius: r,
                mu_c: mu_c.unwrap_or(pin.mu_c),
                sensor: perturb_sensor(pin, sensor_values)?,
                actuator,
            }));
        }
        *other += 1;
    }
    Err(SampleError::Pin {
        pin: pin.name.clone(),
    })
}

/// A fence of the perturbed line: the sample's μf if `fence_mu_f` reaches it, and its angle,
/// upstream end and length errors (each only if its parameter reaches the fence), redrawn together
/// until the fence is one the scenario would accept: angle strictly between −90° and 90°,
/// upstream end over the belt beyond a from the entry, length in [10⁻⁶ a, 10⁶ a], downstream end
/// on the belt.
fn draw_fence(
    fence: &FenceObstacle,
    p: &Perturbations,
    st: &mut ObstacleStreams,
    belt: &crate::scenario::Belt,
    radius: f64,
    mu_f: Option<f64>,
    other: &mut u32,
) -> Result<FenceObstacle, SampleError> {
    let mu_f = match mu_f.filter(|_| p.reaches("fence_mu_f", &fence.name)) {
        Some(m) => m,
        None => fence.mu_f,
    };
    let reached = |d: &Option<Distribution>, name: &str| -> Option<Distribution> {
        d.filter(|_| p.reaches(name, &fence.name))
    };
    let (d_angle, d_x, d_y, d_length) = (
        reached(&p.fence_angle, "fence_angle"),
        reached(&p.fence_x, "fence_x"),
        reached(&p.fence_y, "fence_y"),
        reached(&p.fence_length, "fence_length"),
    );
    if d_angle.is_none() && d_x.is_none() && d_y.is_none() && d_length.is_none() {
        return Ok(FenceObstacle {
            mu_f,
            ..fence.clone()
        });
    }
    let any = |_: f64| true;
    let (lo, hi) = crate::scenario::limits::FENCE_LENGTH_OF_A;
    let slack = 1e-9 * (belt.width + belt.length);
    let half = belt.width / 2.0;
    for _ in 0..=super::distribution::MAX_REDRAWS {
        let mut none = 0;
        let ea = draw_value(&d_angle, &mut st.fence_angle, "fence_angle", any, &mut none)?;
        let ex = draw_value(&d_x, &mut st.fence_x, "fence_x", any, &mut none)?;
        let ey = draw_value(&d_y, &mut st.fence_y, "fence_y", any, &mut none)?;
        let el = draw_value(
            &d_length,
            &mut st.fence_length,
            "fence_length",
            any,
            &mut none,
        )?;
        let drawn = FenceObstacle {
            name: fence.name.clone(),
            start: fence.start + Vec2::new(ex.unwrap_or(0.0), ey.unwrap_or(0.0)),
            angle_rad: fence.angle_rad + ea.unwrap_or(0.0).to_radians(),
            length: fence.length + el.unwrap_or(0.0),
            mu_f,
            // A perturbed fence keeps its tail, which turns it from its drawn angle to 0°.
            tail_radius: fence.tail_radius,
        };
        let end = drawn.far_end();
        let valid = drawn.angle_rad.abs() < std::f64::consts::FRAC_PI_2
            && drawn.start.x > radius
            && drawn.start.x < belt.length
            && drawn.start.y.abs() <= half
            && (lo * radius..=hi * radius).contains(&drawn.length)
            && end.x <= belt.length + slack
            && end.y.abs() <= half + slack;
        if valid {
            return Ok(drawn);
        }
        *other += 1;
    }
    Err(SampleError::Fence {
        fence: fence.name.clone(),
    })
}

/// A dynamic pin's actuator under the sample's actuator parameters (drawn per pin, each only if
/// it reaches the pin): a moving pin's speed and acceleration limits multiplied by their factors
/// and its settle time plus its error; a retractable pin's raise and lower times divided by the
/// speed factor. Redrawn together until the actuator is one the scenario would accept.
fn draw_actuator(
    name: &str,
    a: Actuator,
    p: &Perturbations,
    st: &mut ObstacleStreams,
    belt: &crate::scenario::Belt,
    other: &mut u32,
) -> Result<Actuator, SampleError> {
    use crate::scenario::limits::{contains, max_pin_speed, ACTUATOR_ACCEL, ACTUATOR_TIME};
    let reached = |d: &Option<Distribution>, key: &str| -> Option<Distribution> {
        d.filter(|_| p.reaches(key, name))
    };
    let d_speed = reached(&p.actuator_speed, "actuator_speed");
    let (d_accel, d_settle) = match a {
        Actuator::Moving(_) => (
            reached(&p.actuator_accel, "actuator_accel"),
            reached(&p.actuator_settle, "actuator_settle"),
        ),
        Actuator::Retractable(_) => (None, None),
    };
    if d_speed.is_none() && d_accel.is_none() && d_settle.is_none() {
        return Ok(a);
    }
    let factor = |v: f64| super::compile::in_domain("actuator_speed", v);
    for _ in 0..=super::distribution::MAX_REDRAWS {
        let mut none = 0;
        let fs = draw_value(
            &d_speed,
            &mut st.actuator_speed,
            "actuator_speed",
            factor,
            other,
        )?;
        let fa = draw_value(
            &d_accel,
            &mut st.actuator_accel,
            "actuator_accel",
            factor,
            other,
        )?;
        let es = draw_value(
            &d_settle,
            &mut st.actuator_settle,
            "actuator_settle",
            |_| true,
            &mut none,
        )?;
        let (drawn, valid) = match a {
            Actuator::Moving(m) => {
                let m = MovingSpec {
                    speed: m.speed * fs.unwrap_or(1.0),
                    accel: m.accel * fa.unwrap_or(1.0),
                    settle: m.settle + es.unwrap_or(0.0),
                    ..m
                };
                let valid = (crate::scenario::limits::ACTUATOR_SPEED.0..=max_pin_speed(belt.speed))
                    .contains(&m.speed)
                    && contains(ACTUATOR_ACCEL, m.accel)
                    && contains(ACTUATOR_TIME, m.settle);
                (Actuator::Moving(m), valid)
            }
            Actuator::Retractable(r) => {
                let f = fs.unwrap_or(1.0);
                let r = RetractSpec {
                    raise_time: r.raise_time / f,
                    lower_time: r.lower_time / f,
                    ..r
                };
                let valid =
                    contains(ACTUATOR_TIME, r.raise_time) && contains(ACTUATOR_TIME, r.lower_time);
                (Actuator::Retractable(r), valid)
            }
        };
        if valid {
            return Ok(drawn);
        }
        *other += 1;
    }
    Err(SampleError::Actuator {
        pin: name.to_string(),
        allowed: actuator_ranges(
            a,
            belt.speed,
            [d_speed.is_some(), d_accel.is_some(), d_settle.is_some()],
        ),
    })
}

/// Draw sample `sample` of a study seeded with `seed` at the sweep point `p`: the perturbed scene.
/// A pure function of its arguments.
pub fn draw_scene(
    base: &Scene,
    p: &Perturbations,
    seed: u64,
    sample: u64,
) -> Result<DrawnScene, SampleError> {
    let mut st = Streams::new(seed, sample, p.perturbs_obstacles());
    let mut other = 0u32;
    let mut shape_redraws = 0u32;
    let mu_c = draw_value(
        &p.mu_c,
        &mut st.mu_c,
        "mu_c",
        |v| super::compile::in_domain("mu_c", v),
        &mut other,
    )?;
    let speed = draw_value(
        &p.belt_speed,
        &mut st.belt_speed,
        "belt_speed",
        |v| super::compile::in_domain("belt_speed", v),
        &mut other,
    )?
    .unwrap_or(base.belt.speed);
    let belt = crate::scenario::Belt { speed, ..base.belt };
    let (polygon, model) = draw_part_model(base, p, &mut st, &mut shape_redraws, &mut other)?;
    let radius = polygon.radius();
    let sensor_values = draw_sensor_values(base, p, &mut st, &mut other)?;
    let (mu_f, latency) = draw_fence_friction_and_latency(base, p, &mut st, &mut other)?;

    let mut obstacles = Vec::with_capacity(base.obstacles.len());
    for ob in &base.obstacles {
        obstacles.push(draw_obstacle(
            ob,
            p,
            &mut st,
            &belt,
            radius,
            mu_c,
            mu_f,
            &sensor_values,
            &mut other,
        )?);
    }
    let neighbours = neighbours(&obstacles, radius);

    let mut scene = Scene {
        name: base.name.clone(),
        seed: base.seed,
        belt,
        part: PartSpec {
            label: base.part.label.clone(),
            stable_states: polygon.stable_states(),
            polygon,
            radius,
            model,
            support: SupportKind::Uniform,
            mu_c: mu_c.unwrap_or(base.part.mu_c),
            mu_s: base.part.mu_s,
            mass: base.part.mass,
        },
        feed: base.feed.clone(),
        obstacles,
        neighbours,
        goal: base.goal.clone(),
        controller: base.controller.clone().map(|c| Controller {
            latency: latency.unwrap_or(c.latency),
            ..c
        }),
        contact: crate::mechanics::ContactSettings {
            mu_c: mu_c.unwrap_or(base.contact.mu_c),
            ..base.contact
        },
        effects: crate::scenario::Effects {
            event_log: false,
            ..base.effects
        },
        output: base.output.clone(),
        // One map per sample would cost far more than the sample's few exact contacts.
        map_tier: base.map_tier.filter(|_| p.varies_map_inputs().is_none()),
        // A returning part is drawn from the study's nominal feed (the sample's feed is its
        // first entry's pose).
        closed_loop: base.closed_loop.clone().map(|mut cl| {
            if let Some(r) = cl.recirculation.as_mut() {
                r.reentry = Some((base.feed.orientation.clone(), base.feed.lateral));
            }
            cl
        }),
    };
    scene.feed = draw_entry(&scene, base, p, &mut st, &mut other)?;
    // The run's seed draws the sensor readings and a closed loop's gate, returns and re-entries.
    let run_seed = if sensors(base).is_empty() && base.closed_loop.is_none() {
        0
    } else {
        st.readings_seed
    };
    Ok(DrawnScene {
        scene,
        shape_redraws,
        other_redraws: other,
        run_seed,
        streams: st.seeded(),
    })
}

/// The sample's polygon and its part model: a perturbed polygon that cannot carry the drawn
/// support is redrawn (counted in `shape_redraws`) like an invalid one.
fn draw_part_model(
    base: &Scene,
    p: &Perturbations,
    st: &mut Streams,
    shape_redraws: &mut u32,
    other: &mut u32,
) -> Result<(Polygon, PartModel), SampleError> {
    // A perturbed polygon that cannot carry the support (a sliver with no tripod around its
    // centroid) is redrawn like an invalid one.
    let mut attempts = 0;
    Ok(loop {
        let polygon = draw_polygon(base, &p.shape, &mut st.shape, shape_redraws)?;
        let model = draw_support(&polygon, &p.support, &mut st.support, other)
            .map_err(SampleError::Support)
            .and_then(|support| PartModel::new(&polygon, &support).map_err(SampleError::Model));
        match model {
            Ok(m) => break (polygon, m),
            Err(_) if p.shape.is_some_and(|d| !d.is_fixed()) && attempts < MAX_SHAPE_REDRAWS => {
                attempts += 1;
                *shape_redraws += 1;
            }
            Err(e) => return Err(e),
        }
    })
}

/// The fences' friction and the controller's latency of a sample (None: the scenario's).
fn draw_fence_friction_and_latency(
    base: &Scene,
    p: &Perturbations,
    st: &mut Streams,
    other: &mut u32,
) -> Result<(Option<f64>, Option<f64>), SampleError> {
    Ok(match st.obstacles.as_mut() {
        Some(ost) => (
            draw_value(
                &p.fence_mu_f,
                &mut ost.fence_mu_f,
                "fence_mu_f",
                |v| super::compile::in_domain("fence_mu_f", v),
                other,
            )?,
            match &base.controller {
                Some(c) => draw_value(
                    &p.controller_latency,
                    &mut ost.controller_latency,
                    "controller_latency",
                    |e| {
                        crate::scenario::limits::contains(
                            crate::scenario::limits::ACTUATOR_TIME,
                            c.latency + e,
                        )
                    },
                    other,
                )
                .map_err(|e| e.left(Some(RangeLeft::Latency { latency: c.latency })))?
                .map(|e| c.latency + e),
                None => None,
            },
        ),
        None => (None, None),
    })
}

/// The sample's feed: one part whose entry pose the scenario's feed draws, perturbed by the
/// pose errors and kept on the belt.
fn draw_entry(
    scene: &Scene,
    base: &Scene,
    p: &Perturbations,
    st: &mut Streams,
    other: &mut u32,
) -> Result<Feed, SampleError> {
    // The scenario's feed draws the entry pose (its support is uniform here, so it draws no tripod).
    let entry = draw_part(scene, st.feed_seed, 0).map_err(SampleError::Entry)?;
    let any = |_: f64| true;
    let d_theta = draw_value(&p.pose_theta, &mut st.pose_theta, "pose_theta", any, other)?;
    let d_y = draw_value(&p.pose_y, &mut st.pose_y, "pose_y", any, other)?;
    let theta = entry.theta_rad + d_theta.unwrap_or(0.0).to_radians();
    let reach = (scene.belt.width / 2.0 - scene.part.radius).max(0.0);
    let y = (entry.y + d_y.unwrap_or(0.0)).clamp(-reach, reach);
    Ok(Feed {
        parts: 1,
        arrival: Arrival::Periodic {
            headway: base.feed.arrival.headway(),
        },
        orientation: Orientation::Stable {
            thetas_rad: vec![crate::geometry::wrap_2pi(theta)],
            weights: vec![1.0],
            jitter_rad: 0.0,
        },
        lateral: Lateral::Fixed(y),
    })
}

/// Run sample `sample` at sweep point number `point` (perturbations `p`): draw the scene and send its one part down the line.
///
/// `online` is the online controller's model of `base` (the study's [`super::Study::online`]):
/// every sample's controller is the one designed for the nominal line, whatever physics the
/// sample draws.
pub fn run_sample(
    base: &Scene,
    online: Option<&crate::engine::prepare::OnlineHandle>,
    p: &Perturbations,
    point: usize,
    seed: u64,
    sample: u64,
) -> Result<SampleResult, super::StudyError> {
    let fail = |reason: Box<SampleError>| super::StudyError::Sample {
        point,
        sample,
        reason,
    };
    let drawn = draw_scene(base, p, seed, sample).map_err(|e| fail(Box::new(e)))?;
    let opts = RunOptions {
        parts: 1,
        // The part's pose is fixed in the drawn feed, so the seed draws only sensor readings.
        seed: drawn.run_seed,
        sample_paths: 0,
        keep_records: true,
        online: online.cloned(),
        stop: None,
    };
    let run = engine::run(&drawn.scene, &opts, &mut |_| {}).map_err(|source| {
        super::StudyError::Engine {
            point,
            sample,
            source,
        }
    })?;
    // On a closed loop the one part may pass several times: only its last pass ends in a class
    // (the gate's takings do not), or none when the gate took it off for good (`rejected`).
    let outcome = PartOutcome::ALL
        .into_iter()
        .find(|&o| run.metrics.outcomes.get(o) == 1)
        .unwrap_or(PartOutcome::Rejected);
    let passes = run.summary.closed_loop.as_ref().map(|l| l.passes as u32);
    let record = run.records.last();
    let latency_us = record
        .filter(|_| outcome.exited())
        .map(|r| ((r.end_s - r.arrival_s) * 1e6).round().max(1.0) as u64);
    let sensed = |f: fn(&crate::engine::sensing::SensorStats) -> u64| {
        run.metrics.sensors.iter().map(f).sum::<u64>() as u32
    };
    Ok(SampleResult {
        outcome,
        contacts: record.map_or(0, |r| r.contacts),
        latency_us,
        shape_redraws: drawn.shape_redraws,
        other_redraws: drawn.other_redraws,
        sensor_readings: sensed(|s| s.readings),
        sensor_correct: sensed(|s| s.confusion.correct()),
        online: super::online::OnlineSample::of(&run),
        passes,
    })
}
