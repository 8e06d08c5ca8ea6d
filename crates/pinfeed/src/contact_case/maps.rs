//! Configuration maps of a case, end to end: the workflow behind `pinfeed map`.
//!
//! A [`MapRequest`] is a template [`Case`] (part, support, μc, μs, pin radius, tolerance, model,
//! fence; its θ0 and d are not used) with the contact parameters d to map, the θ0 spacing and the
//! band threshold. [`run`] checks every setting, compiles the part (its slides served by tables at
//! the case's μc), loads or builds the map tier for just the base cells the passes fall in (when
//! the request answers from the tier), and computes the maps on a pool of worker threads
//! ([`crate::maps::compute_maps_with`]). [`run_ensemble`] maps an ensemble of members under
//! uncertain physics instead ([`crate::maps::ensemble`]). Each error names the setting at fault by
//! the caller's name for it (`name(field)`: a flag of the command line).

use super::{case_fence, check_geometry, check_inputs, compile_part, settings_and_pin, Case};
use super::{CaseError, ModelChoice};
use crate::geometry::{Polygon, Pose, Vec2};
use crate::maps::ensemble::{
    ensemble_maps_observed, stable_states_deg, EnsembleMaps, EnsembleSpec, InputState,
    PredictedBands,
};
use crate::maps::tier::{self, Loaded, TierInputs, TierSpec};
use crate::maps::{
    compute_maps_with, theta_grid, ConfigurationMap, MapError, MapFence, MapSettings,
};
use crate::mechanics::{ContactSettings, FenceSpec, Fidelity, PartModel, Support};
use std::path::PathBuf;
use std::time::Instant;

/// Most members of an ensemble.
pub const MAX_MEMBERS: usize = 100_000;
/// Most passes (members × d × θ0) of one ensemble.
pub const MAX_PASSES: usize = 20_000_000;

/// Where the map tier's maps are kept and on which grid.
#[derive(Debug, Clone, Default)]
pub struct TierSource {
    /// The grid ([`TierSpec::parse_grid`]); `None`: [`TierSpec::default`].
    pub grid: Option<String>,
    /// The cache folder; `None`: [`tier::default_cache_dir`].
    pub cache_dir: Option<PathBuf>,
}

/// What to map.
#[derive(Debug, Clone)]
pub struct MapRequest {
    /// The template case: part, support, friction, pin radius, tolerance and fence (its θ0 and d
    /// are not used, and its model is the one [`MapRequest::model`] computes with).
    pub case: Case,
    /// How the pushes are answered: a model of the contact, or the map tier.
    pub model: ModelChoice,
    /// The contact parameters d to map (not used with a fence: a fence has one map).
    pub ds: Vec<f64>,
    /// Spacing of the initial orientations θ0 (degrees; divides 360).
    pub theta_step_deg: f64,
    /// Band threshold (degrees).
    pub threshold_deg: f64,
    /// Worker threads (0: one per core).
    pub threads: usize,
    /// The map tier's grid and cache folder (used with [`ModelChoice::Map`]).
    pub tier: TierSource,
}

/// Maps computed for a [`MapRequest`].
#[derive(Debug)]
pub struct MapRun {
    /// The part.
    pub poly: Polygon,
    /// Its contact model (with the slide tables the maps built).
    pub model: PartModel,
    /// The settings every map shares.
    pub settings: MapSettings,
    /// One map per d (one for a fence).
    pub maps: Vec<ConfigurationMap>,
    /// The fence mapped, placed as the case places it, if any.
    pub fence: Option<FenceSpec>,
    /// The map tier the pushes were answered from, if any.
    pub tier: Option<Loaded>,
    /// How many of the passes the tier served, in words (with a tier).
    pub served: Option<String>,
    /// Seconds spent computing the maps (after the tier was ready).
    pub elapsed_s: f64,
    /// Worker threads used.
    pub threads: usize,
}

impl MapRun {
    /// The name of what answered the pushes: `map` or the model's.
    pub fn answered_by(&self) -> &'static str {
        if self.tier.is_some() {
            "map"
        } else {
            self.settings.contact.fidelity.name()
        }
    }

    /// Contacts computed over all maps.
    pub fn contacts(&self) -> usize {
        self.maps.iter().map(|m| m.samples.len()).sum()
    }

    /// Contacts that ended with a status other than ok.
    pub fn non_ok(&self) -> usize {
        self.maps.iter().map(|m| m.non_ok_samples()).sum()
    }
}

/// An ensemble mapped for a [`MapRequest`] under uncertain physics.
#[derive(Debug)]
pub struct EnsembleRun {
    /// The ensemble's specification.
    pub spec: EnsembleSpec,
    /// Its members' final orientations.
    pub maps: EnsembleMaps,
    /// The input states the bands are predicted for: all θ0, then each stable state.
    pub inputs: Vec<InputState>,
    /// The predicted bands per d and input state.
    pub predicted: Vec<PredictedBands>,
    /// The model the members' passes were computed with.
    pub fidelity: Fidelity,
    /// Initial orientations θ0 per d.
    pub thetas: usize,
    /// Passes computed (members × d × θ0).
    pub passes: usize,
    /// Seconds spent on the passes.
    pub elapsed_s: f64,
    /// Worker threads used.
    pub threads: usize,
}

/// A map request that cannot be run; the messages name each setting by the caller's name for it.
#[derive(Debug, thiserror::Error)]
pub enum MapRunError {
    /// A setting of the case.
    #[error(transparent)]
    Case(#[from] CaseError),
    /// A setting of the request, refused (the message names it).
    #[error("{0}")]
    Setting(String),
    /// The maps could not be computed.
    #[error(transparent)]
    Map(#[from] MapError),
    /// The worker threads could not start.
    #[error("starting the worker threads: {0}")]
    Threads(#[from] rayon::ThreadPoolBuildError),
}

/// A pool of `threads` worker threads (0: one per core).
fn pool(threads: usize) -> Result<rayon::ThreadPool, rayon::ThreadPoolBuildError> {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build()
}

/// Check the request's settings; when they hold, its case (with the model its passes are
/// computed with) and the part, compiled.
fn checked(
    req: &MapRequest,
    name: &dyn Fn(&str) -> String,
) -> Result<(Case, Polygon, PartModel), MapRunError> {
    let c = Case {
        model: req.model.computed_with(),
        ..req.case.clone()
    };
    check_inputs(&c, name)?;
    let fenced = c.fence.is_some();
    crate::maps::limits::check(
        req.threads,
        req.ds.len(),
        fenced,
        req.theta_step_deg,
        req.threshold_deg,
    )
    .map_err(|e| MapRunError::Setting(e.describe(|s| name(s.field()))))?;
    let (poly, model) = compile_part(&c.part, &c.support)?;
    if fenced {
        check_geometry(&c, &poly, name)?;
    } else {
        for &d in &req.ds {
            check_geometry(&Case { d, ..c.clone() }, &poly, name)?;
        }
    }
    Ok((c, poly, model))
}

/// Compute the maps of `req` (see the module docs); `tier_progress` follows the map tier's build
/// (base cells built of those needed).
pub fn run(
    req: &MapRequest,
    name: &dyn Fn(&str) -> String,
    tier_progress: crate::progress::Report,
) -> Result<MapRun, MapRunError> {
    let use_tier = req.model == ModelChoice::Map;
    if use_tier && req.case.fence.is_some() {
        return Err(MapRunError::Setting(format!(
            "{} map: the map tier tabulates still pins; use an exact model for a fence",
            name("model")
        )));
    }
    let (c, poly, part_model) = checked(req, name)?;
    let (contact, pin) = settings_and_pin(&c);
    // Every pass of the maps shares the model: its exact slides come from tables.
    let part_model = part_model.with_slide_tables(&[contact.mu_c]);
    let fence = c.fence;
    let settings = MapSettings {
        theta_step_deg: req.theta_step_deg,
        threshold_deg: req.threshold_deg,
        contact,
        pin,
        fence: fence.map(|(angle_deg, length)| MapFence {
            angle_deg,
            length,
            tail: c.fence_tail,
        }),
    };
    // A fence map has one map and no contact parameter (the fence's placement ignores d).
    let ds: Vec<f64> = if fence.is_some() {
        vec![0.0]
    } else {
        req.ds.clone()
    };
    let pool = pool(req.threads)?;
    let tier = if use_tier {
        // Only the base cells the maps' passes fall in are built.
        let grid = theta_grid(req.theta_step_deg).unwrap_or_default();
        let passes: Vec<_> = ds
            .iter()
            .flat_map(|&d| grid.iter().map(move |&t| (t, d)))
            .map(|(t, d)| crate::maps::pass_start(&poly, t, d, pin.radius))
            .collect();
        let support = Support::parse(&c.support, &poly).map_err(CaseError::from)?;
        let spec = tier_spec(&req.tier, name)?;
        let inputs = (&part_model, &support, c.pin_radius, contact);
        Some(pool.install(|| load_tier(inputs, spec, &req.tier, Some(&passes), tier_progress)))
    } else {
        None
    };
    let started = Instant::now();
    let maps = pool.install(|| {
        compute_maps_with(
            &poly,
            &part_model,
            &ds,
            &settings,
            tier.as_ref().map(|l| &*l.map),
        )
    })?;
    let elapsed_s = started.elapsed().as_secs_f64();
    let served = tier
        .as_ref()
        .map(|l| tier::report::served_line(&l.map, &poly, &part_model, &ds, &settings));
    let fence = fence.map(|(angle, length)| case_fence(&poly, &c, angle, length));
    Ok(MapRun {
        poly,
        model: part_model,
        settings,
        maps,
        fence,
        tier,
        served,
        elapsed_s,
        threads: pool.current_num_threads(),
    })
}

/// Map an ensemble of `members` members (seed `seed`) under the uncertain physics `uncertain`
/// (`KEY=VALUE,...`, [`EnsembleSpec::with_settings`]) around the request's case; `on_pass` is
/// called after each pass.
pub fn run_ensemble(
    req: &MapRequest,
    uncertain: &str,
    members: usize,
    seed: u64,
    name: &dyn Fn(&str) -> String,
    on_pass: &(dyn Fn() + Sync),
) -> Result<EnsembleRun, MapRunError> {
    let setting = |s: String| MapRunError::Setting(s);
    if req.model == ModelChoice::Map || req.case.fence.is_some() {
        return Err(setting(format!(
            "{}: an ensemble maps still pins with an exact model (no map tier, no fence)",
            name("uncertain")
        )));
    }
    let (c, poly, _) = checked(req, name)?;
    if c.support.trim() != "uniform" {
        return Err(setting(format!(
            "{}: with {} the support is set by `support=` in the uncertain list; leave it uniform",
            name("support"),
            name("uncertain")
        )));
    }
    if !(1..=MAX_MEMBERS).contains(&members) {
        return Err(setting(format!(
            "{} must lie in [1, {MAX_MEMBERS}], got {members}",
            name("members")
        )));
    }
    let spec = EnsembleSpec::nominal(c.mu_c, c.pin_radius, c.model, c.tol)
        .with_settings(uncertain)
        .map_err(|e| setting(format!("{}: {e}", name("uncertain"))))?;
    let grid = theta_grid(req.theta_step_deg)
        .map_err(|e| setting(format!("{}: {e}", name("theta_step"))))?;
    let passes = members * req.ds.len() * grid.len();
    if passes > MAX_PASSES {
        return Err(setting(format!(
            "{members} members × {} d × {} θ0 = {passes} passes; at most {MAX_PASSES} are allowed in one ensemble",
            req.ds.len(),
            grid.len()
        )));
    }
    let pool = pool(req.threads)?;
    let started = Instant::now();
    let maps = pool
        .install(|| ensemble_maps_observed(&poly, &spec, &req.ds, &grid, seed, members, on_pass))
        .map_err(|e| setting(e.to_string()))?;
    let elapsed_s = started.elapsed().as_secs_f64();
    let states = stable_states_deg(&poly);
    let mut inputs = vec![InputState::All];
    inputs.extend((0..states.len()).map(|index| InputState::State { index }));
    let predicted = maps.predicted(&inputs, &states);
    Ok(EnsembleRun {
        spec,
        maps,
        inputs,
        predicted,
        fidelity: c.model,
        thetas: grid.len(),
        passes,
        elapsed_s,
        threads: pool.current_num_threads(),
    })
}

/// The grid `source` names, checked ([`TierSpec::default`] when it names none).
pub fn tier_spec(
    source: &TierSource,
    name: &dyn Fn(&str) -> String,
) -> Result<TierSpec, MapRunError> {
    match &source.grid {
        Some(g) => {
            TierSpec::parse_grid(g).map_err(|e| MapRunError::Setting(e.describe(&name("map_grid"))))
        }
        None => Ok(TierSpec::default()),
    }
}

/// The map tier of (part model, support, pin radius, contact settings) on the grid `spec`, read
/// from `source`'s cache folder or built and written there — only the base cells of `queries`
/// (pose, pin start) when they are given. Its warnings (a stale or corrupted file) are in
/// [`Loaded::warnings`]; `progress` follows the build.
pub fn load_tier(
    inputs: (&PartModel, &Support, f64, ContactSettings),
    spec: TierSpec,
    source: &TierSource,
    queries: Option<&[(Pose, Vec2)]>,
    progress: crate::progress::Report,
) -> Loaded {
    let (model, support, radius, settings) = inputs;
    let inputs = TierInputs {
        model,
        support,
        radius,
        settings,
        spec,
    };
    let cells: Option<Vec<usize>> = queries.map(|q| {
        q.iter()
            .filter_map(|&(pose, start)| tier::cell_of_query(&inputs, pose, start))
            .collect()
    });
    let dir = (source.cache_dir.clone()).unwrap_or_else(tier::default_cache_dir);
    tier::load_or_build_cells(&inputs, Some(&dir), cells.as_deref(), progress)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(part: &str, ds: &[f64]) -> MapRequest {
        MapRequest {
            case: Case::new(part, 0.0, 0.0, 0.5),
            model: ModelChoice::Model(Fidelity::Exact),
            ds: ds.to_vec(),
            theta_step_deg: 30.0,
            threshold_deg: 5.0,
            threads: 1,
            tier: TierSource::default(),
        }
    }

    fn upper(field: &str) -> String {
        field.to_uppercase()
    }

    #[test]
    fn a_request_maps_each_d_as_the_map_functions_do() {
        let req = request("tripoly2", &[-0.3, 0.2]);
        let run = run(&req, &upper, &crate::progress::silent).unwrap();
        assert_eq!(run.maps.len(), 2);
        assert_eq!(run.contacts(), 24);
        assert_eq!(run.answered_by(), "exact");
        // The same maps as the map functions give over the plain model (tables change no sample
        // beyond the solver's tolerance).
        let (poly, model) = compile_part("tripoly2", "uniform").unwrap();
        let direct = compute_maps_with(&poly, &model, &req.ds, &run.settings, None).unwrap();
        for (a, b) in run.maps.iter().zip(&direct) {
            for (x, y) in a.samples.iter().zip(&b.samples) {
                let gap = (x.theta_final_deg - y.theta_final_deg + 540.0).rem_euclid(360.0) - 180.0;
                assert!(
                    gap.abs() < 1e-6,
                    "{} vs {}",
                    x.theta_final_deg,
                    y.theta_final_deg
                );
            }
        }
    }

    #[test]
    fn refusals_name_the_setting_by_the_callers_name() {
        let mut fenced = request("tripoly2", &[]);
        fenced.case.fence = Some((30.0, None));
        fenced.model = ModelChoice::Map;
        let e = run(&fenced, &upper, &crate::progress::silent).unwrap_err();
        assert!(e.to_string().starts_with("MODEL map"), "{e}");
        let far = request("tripoly2", &[5.0]);
        let e = run(&far, &upper, &crate::progress::silent).unwrap_err();
        assert!(e.to_string().contains("D "), "{e}");
        let ens = request("tripoly2", &[0.1]);
        let e = run_ensemble(&ens, "mu_c=normal:0.5:0.1", 0, 1, &upper, &|| {}).unwrap_err();
        assert!(e.to_string().starts_with("MEMBERS must lie in [1,"), "{e}");
        let e = run_ensemble(&ens, "mu_c=bogus", 5, 1, &upper, &|| {}).unwrap_err();
        assert!(e.to_string().starts_with("UNCERTAIN: "), "{e}");
        let mut grid = request("tripoly2", &[0.1]);
        grid.model = ModelChoice::Map;
        grid.tier.grid = Some("1,2".into());
        let e = run(&grid, &upper, &crate::progress::silent).unwrap_err();
        assert!(e.to_string().starts_with("MAP_GRID"), "{e}");
    }

    #[test]
    fn an_ensemble_counts_its_passes_and_predicts_per_state() {
        let req = request("tripoly1", &[0.2]);
        let ticks = std::sync::atomic::AtomicUsize::new(0);
        let run = run_ensemble(&req, "mu_c=normal:0.5:0.1", 4, 1, &upper, &|| {
            ticks.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        })
        .unwrap();
        assert_eq!(run.passes, 4 * 12);
        assert_eq!(run.thetas, 12);
        assert_eq!(ticks.into_inner(), run.passes);
        // All θ0, then each stable state; bands per (d, input).
        assert_eq!(run.inputs[0], InputState::All);
        assert_eq!(run.predicted.len(), run.inputs.len());
    }
}
