//! The map tier in the line (`[model] fidelity = "map"`, see [`crate::maps::tier`]): each pin's
//! push is answered from the map of (part, pin radius, μc, tolerance, …) where the map can vouch
//! for it, else by the exact contact model, and `work.map_tier` counts which and why.
//!
//! The exact model answers (and the fallback is counted by reason) when the push's path is
//! recorded as it is computed (a sensor pin's signal, a neighbouring obstacle's sweep, a drawn
//! part), for a fence, for a pin moving across the belt, for a part with its own random tripod,
//! when the pin starts inside the part, and where the map is not certified. A push served while
//! another part shares the belt keeps no trace: if the overlap check later needs its path, the
//! exact model records it then (`work.pushes_rerun`), as for any unforeseen look. A scene without
//! the tier runs exactly as before: no maps, no counters.

use super::metrics::MapTierCounters;
use super::motion::Pusher;
use super::state::ActivePart;
use crate::geometry::Pose;
use crate::maps::tier::{self, Fallback, Loaded, TierInputs, TierMap};
use crate::mechanics::{ContactOutcome, ContactSettings, PinPath, Recorder, Support};
use crate::scenario::{Obstacle, Scene};
use crate::sensing::signal::KnotRecorder;
use std::path::Path;
use std::sync::Arc;

/// The maps of a scene's pins, by obstacle index (None for fences).
pub struct LineMaps {
    by_obstacle: Vec<Option<Arc<TierMap>>>,
}

/// The inputs of the map of pin `pin` of `scene` (radius and μc are the pin's).
fn inputs_for<'s>(scene: &'s Scene, radius: f64, mu_c: f64) -> Option<TierInputs<'s>> {
    static UNIFORM: Support = Support::Uniform;
    let spec = scene.map_tier?;
    Some(TierInputs {
        model: &scene.part.model,
        support: &UNIFORM,
        radius,
        settings: ContactSettings {
            mu_c,
            ..scene.contact
        },
        spec,
    })
}

/// Load or build the maps of every pin of a scene that uses the tier (nothing otherwise), from
/// and into the cache folder `dir`; each pin with where its map came from.
pub fn prepare(scene: &Scene, dir: Option<&Path>) -> Vec<(usize, Loaded)> {
    prepare_observed(scene, dir, &|_, _, _| {})
}

/// [`prepare`], telling `progress` (pin number, base cells built, of those missing) as each
/// pin's map is built.
pub fn prepare_observed(
    scene: &Scene,
    dir: Option<&Path>,
    progress: &(dyn Fn(usize, u64, u64) + Sync),
) -> Vec<(usize, Loaded)> {
    scene
        .obstacles
        .iter()
        .enumerate()
        .filter_map(|(j, o)| match o {
            Obstacle::Pin(p) => inputs_for(scene, p.radius, p.mu_c).map(|i| (j, i)),
            Obstacle::Fence(_) => None,
        })
        .map(|(j, inputs)| {
            let report = |done, total| progress(j, done, total);
            (j, tier::shared_observed(&inputs, dir, &report))
        })
        .collect()
}

impl LineMaps {
    /// The maps of a scene that uses the tier (from this process's maps or the default cache
    /// folder), None otherwise.
    pub fn for_scene(scene: &Scene) -> Option<LineMaps> {
        scene.map_tier?;
        let mut by_obstacle = vec![None; scene.obstacles.len()];
        for (j, loaded) in prepare(scene, Some(&tier::default_cache_dir())) {
            for w in &loaded.warnings {
                eprintln!("warning: {w}");
            }
            by_obstacle[j] = Some(loaded.map);
        }
        Some(LineMaps { by_obstacle })
    }
}

/// What the line asks of one push.
pub(super) struct PushRequest<'p> {
    pub j: usize,
    pub pusher: &'p Pusher,
    pub pose: Pose,
    pub settings: &'p ContactSettings,
    /// Something will look at the path.
    pub record: bool,
    /// Something will certainly look at it (a sensor, a sweep, a drawing), not only perhaps (the
    /// overlap check with another part).
    pub must_record: bool,
}

/// The push of `part`: from `maps` where the scene uses the tier and the map can answer (each
/// answer or fallback counted in `counters`), else from the contact model (recording its path
/// into `knots` if asked). Returns the outcome and whether its path was recorded.
pub(super) fn push_contact(
    scene: &Scene,
    maps: Option<&LineMaps>,
    counters: &mut MapTierCounters,
    part: &ActivePart,
    req: PushRequest,
    knots: &mut KnotRecorder,
) -> (ContactOutcome, bool) {
    let model = part.model.as_ref().unwrap_or(&scene.part.model);
    if let Some(maps) = maps {
        let answer = match (req.pusher, &maps.by_obstacle[req.j]) {
            _ if req.must_record => Err(Fallback::Trace),
            _ if part.model.is_some() => Err(Fallback::PartSupport),
            (Pusher::Fence(_), _) | (_, None) => Err(Fallback::Fence),
            (Pusher::Pin { path, .. }, _) if *path != PinPath::constant(0.0) => {
                Err(Fallback::MovingPin)
            }
            (Pusher::Pin { centre, radius, .. }, Some(map)) => {
                map.answer(model, req.pose, *centre, *radius)
            }
        };
        match answer {
            Ok(out) => {
                counters.served += 1;
                return (out, false);
            }
            Err(why) => counters.count(why),
        }
    }
    let recorder = req.record.then_some(knots as &mut dyn Recorder);
    (
        req.pusher.push(model, req.pose, req.settings, recorder),
        req.record,
    )
}
