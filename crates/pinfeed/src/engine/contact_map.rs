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
use crate::maps::tier::{self, lazy, Fallback, LazyMap, Loaded, TierInputs, TierSpec};
use crate::mechanics::{ContactOutcome, ContactSettings, PinPath, Recorder, Support};
use crate::scenario::{Obstacle, Scene};
use crate::sensing::signal::KnotRecorder;
use std::path::Path;
use std::sync::Arc;

/// The maps of a scene's pins, by obstacle index (None for fences): lazy maps, which build a
/// base cell when a push first falls in it ([`LazyMap`]).
pub struct LineMaps {
    /// The scene's grid.
    spec: TierSpec,
    by_obstacle: Vec<Option<PinMap>>,
}

/// The inputs of the map of a pin of `scene` with this radius and μc on the grid `spec`.
fn map_inputs(scene: &Scene, spec: TierSpec, radius: f64, mu_c: f64) -> TierInputs<'_> {
    static UNIFORM: Support = Support::Uniform;
    TierInputs {
        model: &scene.part.model,
        support: &UNIFORM,
        radius,
        settings: ContactSettings {
            mu_c,
            ..scene.contact
        },
        spec,
    }
}

/// The map inputs of each pin of a scene that uses the tier, by obstacle index.
fn pin_inputs(scene: &Scene) -> impl Iterator<Item = (usize, TierInputs<'_>)> {
    scene
        .obstacles
        .iter()
        .enumerate()
        .filter_map(|(j, o)| match o {
            Obstacle::Pin(p) => scene
                .map_tier
                .map(|spec| (j, map_inputs(scene, spec, p.radius, p.mu_c))),
            Obstacle::Fence(_) => None,
        })
}

/// Load or build the whole map of every pin of a scene that uses the tier (nothing otherwise),
/// from and into the cache folder `dir`; each pin with where its map came from. The line then
/// uses these maps (nothing is left to build during the run).
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
    pin_inputs(scene)
        .map(|(j, inputs)| {
            let report = |done, total| progress(j, done, total);
            let loaded = tier::shared_observed(&inputs, dir, &report);
            lazy::register(&loaded);
            (j, loaded)
        })
        .collect()
}

/// The map of one pin as the line will use it: built cells from the cache, the others built
/// when a push first falls in them.
pub struct PinMap {
    /// The obstacle index of the pin.
    pub obstacle: usize,
    /// The pin's radius (the map's).
    pub radius: f64,
    /// The pin's μc.
    pub mu_c: f64,
    /// Its map.
    pub map: Arc<LazyMap>,
    /// What went wrong reading its cache file (a refused file), in words; never fatal.
    pub warnings: Vec<String>,
}

/// The maps of every pin of a scene that uses the tier (nothing otherwise), as a line will use
/// them: read from the cache folder `dir` where it holds them (whole or in part), never built
/// here — the line builds the base cells its pushes reach ([`LazyMap`]); [`persist`] writes them
/// back.
pub fn load(scene: &Scene, dir: Option<&Path>) -> Vec<PinMap> {
    pin_inputs(scene)
        .map(|(j, inputs)| {
            let (map, warnings) = lazy::lazy_shared(&inputs, dir);
            PinMap {
                obstacle: j,
                radius: inputs.radius,
                mu_c: inputs.settings.mu_c,
                map,
                warnings,
            }
        })
        .collect()
}

/// What [`persist`] did with one map.
#[derive(Debug, Clone)]
pub struct Persisted {
    /// The map's key.
    pub key: tier::TierKey,
    /// Base cells built in this process (by the line, as its pushes reached them).
    pub built: u64,
    /// Wall time of those builds, summed (s).
    pub seconds: f64,
    /// Base cells built now (loaded or built in this process), of all.
    pub cells: (u64, u64),
    /// The cache file written (None: no folder, or nothing new to write).
    pub written: Option<std::path::PathBuf>,
    /// Why the file could not be written, in words; never fatal.
    pub warning: Option<String>,
}

/// Write back to their cache files the maps of a scene's pins that gained base cells in this
/// process (each map once); one entry per map.
pub fn persist(scene: &Scene) -> Vec<Persisted> {
    let mut seen = std::collections::BTreeSet::new();
    let mut out = Vec::new();
    for (_, inputs) in pin_inputs(scene) {
        let Some(map) = lazy::existing(&inputs) else {
            continue;
        };
        if !seen.insert(map.key()) {
            continue;
        }
        let (built, seconds) = map.built_now();
        let mut p = Persisted {
            key: map.key(),
            built,
            seconds,
            cells: map.cells_built(),
            written: None,
            warning: None,
        };
        match map.persist() {
            Ok(file) => p.written = file,
            Err(e) => p.warning = Some(e.to_string()),
        }
        out.push(p);
    }
    out
}

impl LineMaps {
    /// The maps of a scene that uses the tier (this process's lazy maps, else what the default
    /// cache folder holds), None otherwise.
    pub fn for_scene(scene: &Scene) -> Option<LineMaps> {
        let spec = scene.map_tier?;
        let mut by_obstacle: Vec<Option<PinMap>> =
            (0..scene.obstacles.len()).map(|_| None).collect();
        for pin in load(scene, Some(&tier::default_cache_dir())) {
            for w in &pin.warnings {
                eprintln!("warning: {w}");
            }
            let j = pin.obstacle;
            by_obstacle[j] = Some(pin);
        }
        Some(LineMaps { spec, by_obstacle })
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
            (Pusher::Pin { centre, .. }, Some(pin)) => {
                let inputs = map_inputs(scene, maps.spec, pin.radius, pin.mu_c);
                pin.map.answer(&inputs, req.pose, *centre)
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
