//! The stream of parts (docs/physics.md#the-line): what part `i` looks like when it enters, drawn from its own
//! random stream `random::stream(seed, i)` (docs/physics.md#determinism) so that a run does not depend
//! on event order, sharding or how many parts are simulated.
//!
//! Draw order within a part's stream (fixed, so adding a draw at the end never changes earlier
//! ones): the gap before its arrival (Poisson only), the orientation (a stable state by weight, then
//! jitter; or uniform), the lateral offset, and — only for `support = "tripod"` — its tripod.

use crate::geometry::wrap_2pi;
use crate::mechanics::{PartModel, Support};
use crate::random::{stream, ChaCha8Rng};
use crate::scenario::{Arrival, Lateral, Orientation, Scene, SupportKind};
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};

/// One part as it enters the belt.
pub struct PartDraw {
    /// Seconds between the previous part's arrival and this one's (Poisson), or the headway.
    pub gap: f64,
    /// Entry orientation θ (radians, [0, 2π)).
    pub theta_rad: f64,
    /// Entry lateral offset of the centroid (m).
    pub y: f64,
    /// The part's own contact model (random tripod), when the scene asks for one.
    pub model: Option<PartModel>,
}

/// The gap before part `index` arrives (its stream's first draw; Poisson only, else the headway).
pub fn arrival_gap(scene: &Scene, seed: u64, index: u64) -> f64 {
    let mut rng = stream(seed, index);
    draw_gap(scene, &mut rng)
}

fn draw_gap(scene: &Scene, rng: &mut ChaCha8Rng) -> f64 {
    match scene.feed.arrival {
        Arrival::Periodic { headway } => headway,
        Arrival::Poisson { headway } => {
            let u: f64 = rng.random();
            -headway * (1.0 - u).ln()
        }
    }
}

/// Draw part `index` of a run seeded with `seed`.
pub fn draw_part(
    scene: &Scene,
    seed: u64,
    index: u64,
) -> Result<PartDraw, crate::mechanics::PartModelError> {
    let mut rng = stream(seed, index);
    let gap = draw_gap(scene, &mut rng);
    let theta = draw_orientation(&scene.feed.orientation, &mut rng);
    let y = draw_lateral(&scene.feed.lateral, &mut rng);
    let model = match scene.part.support {
        SupportKind::Uniform => None,
        SupportKind::Tripod => {
            let support = Support::random_tripod(&scene.part.polygon, &mut rng)?;
            Some(PartModel::new(&scene.part.polygon, &support)?)
        }
    };
    Ok(PartDraw {
        gap,
        theta_rad: theta,
        y,
        model,
    })
}

/// The pose of part `part` entering the belt again on pass `pass` (≥ 1) of a closed loop: its
/// orientation and lateral offset drawn as the feed draws them, from a stream of its own (the
/// part keeps its support: a warped part stays warped).
pub fn draw_reentry(scene: &Scene, seed: u64, part: u64, pass: u32) -> (f64, f64) {
    let mut rng = crate::random::substream(seed, REENTRY_PURPOSE + u64::from(pass), part);
    let own = (scene.closed_loop.as_ref())
        .and_then(|cl| cl.recirculation.as_ref())
        .and_then(|r| r.reentry.as_ref());
    let (orientation, lateral) = match own {
        Some((o, l)) => (o, l),
        None => (&scene.feed.orientation, &scene.feed.lateral),
    };
    let theta = draw_orientation(orientation, &mut rng);
    (theta, draw_lateral(lateral, &mut rng))
}

/// The purposes of [`crate::random::substream`] from this one up are the re-entries' (one per
/// pass).
const REENTRY_PURPOSE: u64 = 0x5245_0000;

fn draw_orientation(orientation: &Orientation, rng: &mut ChaCha8Rng) -> f64 {
    match orientation {
        Orientation::Uniform => std::f64::consts::TAU * rng.random::<f64>(),
        Orientation::Stable {
            thetas_rad: thetas,
            weights,
            jitter_rad: jitter,
        } => {
            let u: f64 = rng.random();
            let mut acc = 0.0;
            let mut pick = thetas.len() - 1;
            for (i, w) in weights.iter().enumerate() {
                acc += w;
                if u < acc {
                    pick = i;
                    break;
                }
            }
            let z: f64 = StandardNormal.sample(rng);
            wrap_2pi(thetas[pick] + jitter * z)
        }
    }
}

fn draw_lateral(lateral: &Lateral, rng: &mut ChaCha8Rng) -> f64 {
    match *lateral {
        Lateral::Fixed(y) => y,
        Lateral::Uniform { min, max } => min + (max - min) * rng.random::<f64>(),
        Lateral::Normal { mean, sd, lo, hi } => {
            for _ in 0..64 {
                let z: f64 = StandardNormal.sample(rng);
                let y = mean + sd * z;
                if (lo..=hi).contains(&y) {
                    return y;
                }
            }
            mean.clamp(lo, hi)
        }
    }
}
