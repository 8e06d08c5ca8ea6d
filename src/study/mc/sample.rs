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
//! Random streams (DESIGN.md "determinism"): sample i of a study seeded with s draws ten sub-seeds
//! from `random::stream(s, i)`, in the fixed order μc, belt speed, shape, pin x, pin y, pin radius,
//! pose θ, pose y, support, feed, and each parameter draws from its own ChaCha8 stream seeded with
//! its sub-seed. A parameter's draws therefore never depend on how many draws another one needed
//! (redraws), on the thread count or on sharding, and sample i sees the same underlying numbers at
//! every sweep point (common random numbers).
//!
//! What is drawn, per sample:
//! * μc: one value, used at every pin (replacing each pin's own μc);
//! * belt speed: one value (in the quasi-static model it rescales time: latencies, not outcomes);
//! * shape: an error added to each coordinate of each vertex (part frame, m); the polygon is
//!   re-validated and re-centred on its new centroid; an invalid polygon (self-intersecting, too
//!   wide for the belt, or a sliver that cannot carry the support model) is redrawn and counted,
//!   and after 1000 failures in a row the study stops with an error naming the sample;
//! * support: uniform, a random tripod, or a random smooth density ([`super::smooth_support`]),
//!   on the perturbed polygon;
//! * pins: errors added to each pin's x, y and radius; a pin that would leave the belt, sit within
//!   a + radius of the entry, or get a negative radius is redrawn (counted);
//! * pose: the scenario's own feed draws the entry orientation and lateral offset, then the pose
//!   errors are added; the lateral offset is clamped to keep the part on the belt.

use super::distribution::Distribution;
use super::perturbations::{Perturbations, SupportChoice};
use super::smooth_support::random_smooth_support;
use crate::engine::part_stream::draw_part;
use crate::engine::{self, PartOutcome, RunOptions};
use crate::geometry::{Polygon, Vec2};
use crate::mechanics::{PartModel, Support};
use crate::random::{stream, ChaCha8Rng};
use crate::scenario::{
    Arrival, Feed, Lateral, Obstacle, Orientation, PartSpec, PinObstacle, Scene, SupportKind,
};
use rand::{RngExt, SeedableRng};

/// Redraws of a whole polygon before the study gives up.
pub const MAX_SHAPE_REDRAWS: u32 = 1000;

/// What one sample produced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleResult {
    pub outcome: PartOutcome,
    /// Pin encounters (pushes).
    pub contacts: u32,
    /// Entry → exit (µs), for parts that reach the end of the belt.
    pub latency_us: Option<u64>,
    /// Perturbed polygons redrawn because they were invalid.
    pub shape_redraws: u32,
    /// Other values redrawn (out of their domain: negative friction, pins off the belt, …).
    pub other_redraws: u32,
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
}

impl Streams {
    fn new(seed: u64, sample: u64) -> Streams {
        let mut master = stream(seed, sample);
        let mut next = || ChaCha8Rng::seed_from_u64(master.random::<u64>());
        let mut s = Streams {
            mu_c: next(),
            belt_speed: next(),
            shape: next(),
            pin_x: next(),
            pin_y: next(),
            pin_radius: next(),
            pose_theta: next(),
            pose_y: next(),
            support: next(),
            feed_seed: 0,
        };
        s.feed_seed = master.random::<u64>();
        s
    }
}

/// A drawn scene and the redraws it needed.
pub struct DrawnScene {
    /// The perturbed line with a one-part feed at the drawn pose.
    pub scene: Scene,
    pub shape_redraws: u32,
    pub other_redraws: u32,
}

fn draw_value(
    d: &Option<Distribution>,
    rng: &mut ChaCha8Rng,
    name: &str,
    ok: impl Fn(f64) -> bool,
    redraws: &mut u32,
) -> Result<Option<f64>, String> {
    match d {
        None => Ok(None),
        Some(d) => {
            let (v, n) = d.draw(rng, ok).map_err(|e| format!("{name}: {e}"))?;
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
) -> Result<Polygon, String> {
    let Some(d) = d else {
        return Ok(base.part.polygon.clone());
    };
    let mut last = String::new();
    for _ in 0..MAX_SHAPE_REDRAWS {
        let mut pts = Vec::with_capacity(base.part.polygon.len());
        for v in base.part.polygon.vertices() {
            let (ex, _) = d.draw(rng, |_| true)?;
            let (ey, _) = d.draw(rng, |_| true)?;
            pts.push(Vec2::new(v.x + ex, v.y + ey));
        }
        match Polygon::new(&pts) {
            Ok(p) if 2.0 * p.radius() <= base.belt.width => return Ok(p),
            Ok(p) => {
                last = format!(
                    "the part (2a = {:.6} m) no longer fits the belt ({} m)",
                    2.0 * p.radius(),
                    base.belt.width
                )
            }
            Err(e) => last = e.to_string(),
        }
        *redraws += 1;
    }
    Err(format!(
        "shape: {MAX_SHAPE_REDRAWS} perturbed polygons in a row were invalid (last: {last}); the shape tolerance is too large for this part"
    ))
}

/// The support of one sample on its (perturbed) polygon.
fn draw_support(
    polygon: &Polygon,
    choice: &SupportChoice,
    rng: &mut ChaCha8Rng,
    redraws: &mut u32,
) -> Result<Support, String> {
    Ok(match choice {
        SupportChoice::Uniform => Support::Uniform,
        SupportChoice::Tripod => Support::random_tripod(polygon, rng)?,
        SupportChoice::Smooth(params) => {
            let (s, n) = random_smooth_support(polygon, params, rng)?;
            *redraws += n;
            s
        }
    })
}

/// One obstacle of the perturbed line: a pin with its position and radius errors (redrawn until
/// it lies over the belt, clear of the entry, with a radius ≥ 0) and the sample's μc; any other
/// kind of obstacle unchanged.
#[allow(unreachable_patterns)] // other kinds (fences, issue 5) pass through
fn draw_obstacle(
    ob: &Obstacle,
    p: &Perturbations,
    st: &mut Streams,
    belt: &crate::scenario::Belt,
    radius: f64,
    mu_c: Option<f64>,
    other: &mut u32,
) -> Result<Obstacle, String> {
    let pin = match ob {
        Obstacle::Pin(pin) => pin,
        unchanged => return Ok(unchanged.clone()),
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
                sensor: pin.sensor.clone(),
            }));
        }
        *other += 1;
    }
    Err(format!(
        "pin `{}`: {} perturbed positions in a row left the belt, touched the entry or had a negative radius",
        pin.name,
        super::distribution::MAX_REDRAWS + 1
    ))
}

/// Draw sample `sample` of a study seeded with `seed` at the sweep point `p`: the perturbed scene.
/// A pure function of its arguments.
pub fn draw_scene(
    base: &Scene,
    p: &Perturbations,
    seed: u64,
    sample: u64,
) -> Result<DrawnScene, String> {
    let mut st = Streams::new(seed, sample);
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
    // A perturbed polygon that cannot carry the support (a sliver with no tripod around its
    // centroid) is redrawn like an invalid one.
    let mut attempts = 0;
    let (polygon, model) = loop {
        let polygon = draw_polygon(base, &p.shape, &mut st.shape, &mut shape_redraws)?;
        let model = draw_support(&polygon, &p.support, &mut st.support, &mut other)
            .and_then(|support| PartModel::new(&polygon, &support));
        match model {
            Ok(m) => break (polygon, m),
            Err(_) if p.shape.is_some_and(|d| !d.is_fixed()) && attempts < MAX_SHAPE_REDRAWS => {
                attempts += 1;
                shape_redraws += 1;
            }
            Err(e) => return Err(format!("support: {e}")),
        }
    };
    let radius = polygon.radius();

    let mut obstacles = Vec::with_capacity(base.obstacles.len());
    for ob in &base.obstacles {
        obstacles.push(draw_obstacle(
            ob, p, &mut st, &belt, radius, mu_c, &mut other,
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
        contact: crate::mechanics::ContactSettings {
            mu_c: mu_c.unwrap_or(base.contact.mu_c),
            ..base.contact
        },
        effects: crate::scenario::Effects {
            event_log: false,
            ..base.effects
        },
        output: base.output.clone(),
    };
    // The scenario's feed draws the entry pose (its support is uniform here, so it draws no tripod).
    let entry = draw_part(&scene, st.feed_seed, 0)?;
    let any = |_: f64| true;
    let d_theta = draw_value(
        &p.pose_theta,
        &mut st.pose_theta,
        "pose_theta",
        any,
        &mut other,
    )?;
    let d_y = draw_value(&p.pose_y, &mut st.pose_y, "pose_y", any, &mut other)?;
    let theta = entry.theta + d_theta.unwrap_or(0.0).to_radians();
    let reach = (scene.belt.width / 2.0 - radius).max(0.0);
    let y = (entry.y + d_y.unwrap_or(0.0)).clamp(-reach, reach);
    scene.feed = Feed {
        parts: 1,
        arrival: Arrival::Periodic {
            headway: base.feed.arrival.headway(),
        },
        orientation: Orientation::Stable {
            thetas: vec![crate::geometry::wrap_2pi(theta)],
            weights: vec![1.0],
            jitter: 0.0,
        },
        lateral: Lateral::Fixed(y),
    };
    Ok(DrawnScene {
        scene,
        shape_redraws,
        other_redraws: other,
    })
}

/// Run sample `sample` at sweep point number `point` (perturbations `p`): draw the scene and send its one part down the line.
pub fn run_sample(
    base: &Scene,
    p: &Perturbations,
    point: usize,
    seed: u64,
    sample: u64,
) -> Result<SampleResult, super::StudyError> {
    let fail = |reason: String| super::StudyError::Sample {
        point,
        sample,
        reason,
    };
    let drawn = draw_scene(base, p, seed, sample).map_err(fail)?;
    let opts = RunOptions {
        parts: 1,
        seed: 0,
        sample_paths: 0,
        keep_records: true,
    };
    let run = engine::run(&drawn.scene, &opts, &mut |_| {}).map_err(|source| {
        super::StudyError::Engine {
            point,
            sample,
            source,
        }
    })?;
    let outcome = PartOutcome::ALL
        .into_iter()
        .find(|&o| run.metrics.outcomes.get(o) == 1)
        .expect("one part ends in exactly one class");
    let record = &run.records[0];
    let latency_us = outcome
        .exited()
        .then(|| ((record.end_s - record.arrival_s) * 1e6).round().max(1.0) as u64);
    Ok(SampleResult {
        outcome,
        contacts: record.contacts,
        latency_us,
        shape_redraws: drawn.shape_redraws,
        other_redraws: drawn.other_redraws,
    })
}
