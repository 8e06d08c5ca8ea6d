//! Monte Carlo robustness studies: how often a line orients its parts when the physics
//! and the build are uncertain.
//!
//! A study file (TOML, docs/study-format.md) points at a scenario and declares uncertain
//! parameters — pin–part friction μc, the support model (uniform, a random tripod, a random smooth
//! density), shape tolerance, pin position and radius errors, entry pose noise, belt speed, sensor
//! pins' noise, bias, timing threshold and jitter, fences' friction μf, angle, position and length,
//! dynamic pins' speed, acceleration and settle time, the controller's latency — and
//! optionally sweeps one or two of them over a grid. For each sweep point, N samples are drawn; a
//! sample is one part through a freshly perturbed line ([`sample`]). Computed per point: the count
//! of each outcome class, the success rate with its 95% Wilson score interval (and the same interval
//! for every other class), contacts per part, and latency quantiles (entry → exit, HDR histogram).
//!
//! Determinism: sample i draws only from streams derived from (seed, i), samples run in parallel
//! with an order-preserving collect, and results are reduced in index order into integer counts and
//! histograms ([`tally`]), so the report does not depend on the thread count. The same holds across
//! machines: `--shard k/n` runs a contiguous range of the sample indices and writes the counts to a
//! self-describing shard file ([`shard`]); `merge` adds shards exactly and writes byte for byte the
//! report one unsharded run writes ([`report`]).
//!
//! * [`raw`], [`compile`]: the study file and its validation (located errors);
//! * [`distribution`], [`perturbations`]: what is uncertain and how it is drawn (the support
//!   models in [`crate::mechanics::support`]);
//! * [`sample`]: one perturbed line and its one part; [`run`]: many samples in parallel;
//! * [`tally`], [`shard`], [`report`]: counts, shard files and merging, the report; [`online`]:
//!   what an online controller decided and predicted, against what happened;
//! * [`hash`]: the study's content hash; [`precision`]: CI half-width against samples and time;
//! * [`sequential`]: `--precision E`, each point run in blocks until its success rate is known to
//!   ± E (an anytime-valid confidence sequence) or the samples are spent.

pub mod compile;
pub use crate::random::distribution;
pub mod error;
pub mod hash;
pub mod online;
pub mod perturbations;
pub mod precision;
pub mod raw;
pub mod report;
pub mod run;
pub mod sample;
pub mod sequential;
pub mod shard;
pub mod tally;

pub use compile::SweepAxis;
pub use error::StudyError;
pub use perturbations::Perturbations;

use crate::scenario::error::Locator;
use crate::scenario::location::KeyPath;
use crate::scenario::Scene;
use std::path::{Path, PathBuf};

/// Default samples per sweep point.
pub const DEFAULT_SAMPLES: u64 = 1000;
/// Largest number of samples per sweep point.
pub const MAX_SAMPLES: u64 = 1_000_000_000;

/// A loaded, validated study.
#[derive(Debug)]
pub struct Study {
    /// Names the report folder.
    pub name: String,
    /// The study file as given.
    pub file: PathBuf,
    /// The scenario file, resolved against the study file's folder.
    pub scenario_file: PathBuf,
    /// The nominal line.
    pub scene: Scene,
    /// Seed of the study's random streams: sample i draws only from streams derived from (seed, i),
    /// so the same seed gives the same samples.
    pub seed: u64,
    /// Samples per sweep point.
    pub samples: u64,
    /// The swept parameters (none, one or two), in the order declared; the first varies slowest.
    pub axes: Vec<SweepAxis>,
    /// Parameter values of each point (one per axis), first axis slowest.
    pub point_values: Vec<Vec<f64>>,
    /// Perturbations of each point.
    pub points: Vec<Perturbations>,
    /// Perturbations as declared, before any sweep.
    pub declared: Perturbations,
    /// Content hash of the study file, the scenario file and the samples per point.
    pub study_hash: u64,
    /// Content hash of the scenario file.
    pub scenario_hash: u64,
    /// The online controller's model of the nominal line (`[controller] mode = "online"`),
    /// built once when the study is read and shared by every sample.
    pub online: Option<crate::engine::prepare::OnlineHandle>,
}

impl Study {
    /// Total samples: points × samples per point.
    pub fn total_samples(&self) -> u64 {
        self.points.len() as u64 * self.samples
    }

    /// What the study may be taken to perturb but does not (printed as warnings; the report is
    /// unchanged): μc varied on a line whose fences no `fence_mu_f` reaches, since μc does not
    /// reach a fence.
    pub fn warnings(&self) -> Vec<String> {
        if !self.points.iter().any(|p| p.mu_c.is_some()) {
            return Vec::new();
        }
        let kept: Vec<String> = self
            .scene
            .obstacles
            .iter()
            .filter_map(|o| match o {
                crate::scenario::Obstacle::Fence(f) => Some(f),
                crate::scenario::Obstacle::Pin(_) => None,
            })
            .filter(|f| {
                !self
                    .points
                    .iter()
                    .any(|p| p.fence_mu_f.is_some() && p.reaches("fence_mu_f", &f.name))
            })
            .map(|f| format!("`{}` (μf {})", f.name, f.mu_f))
            .collect();
        if kept.is_empty() {
            return Vec::new();
        }
        vec![format!(
            "mu_c varies the pins' friction only; the fence(s) {} keep their own μf: declare [uncertain.fence_mu_f] to vary it",
            kept.join(", ")
        )]
    }
}

impl Study {
    /// A study built in code, not read from a file: `samples` samples of `scene` (one part each
    /// through a freshly perturbed copy, as `pinfeed mc` runs a study) under `declared`, with no
    /// sweep, seeded `seed`; `name` names it in reports. What a study file would check when it is
    /// read — that each parameter reaches an obstacle of the scene — is the caller's to know.
    /// Its hashes are of its name, seed, samples and perturbations (a study built in code is not
    /// sharded from a file).
    pub fn of_scene(
        name: &str,
        scene: Scene,
        seed: u64,
        samples: u64,
        declared: Perturbations,
    ) -> Result<Study, StudyError> {
        let online = crate::engine::prepare::online_model(&scene).map_err(StudyError::Scenario)?;
        let what = format!("{name}\n{seed}\n{samples}\n{declared:?}");
        let hash = hash::fnv1a(&[b"pinfeed-mc-study-in-code", what.as_bytes()]);
        let file = PathBuf::from(format!("{name} (built in code)"));
        Ok(Study {
            name: name.to_string(),
            scenario_file: file.clone(),
            file,
            scene,
            seed,
            samples: samples.clamp(1, MAX_SAMPLES),
            axes: Vec::new(),
            point_values: vec![Vec::new()],
            points: vec![declared.clone()],
            declared,
            study_hash: hash,
            scenario_hash: hash,
            online,
        })
    }
}

/// Read and validate a study file; `samples` overrides the file's samples per point.
pub fn load(path: &Path, samples: Option<u64>) -> Result<Study, StudyError> {
    let source = crate::input::read_text(path).map_err(|error| StudyError::Io {
        path: path.to_path_buf(),
        error,
        hint: String::new(),
    })?;
    parse(path, &source, samples)
}

/// Validate study text; `file` locates errors and resolves the scenario path.
pub fn parse(file: &Path, source: &str, samples: Option<u64>) -> Result<Study, StudyError> {
    parse_with(file, source, samples, &|p| crate::input::read_text(p))
}

/// [`parse`], reading the scenario the study names through `read` (given the path resolved
/// against `file`): the bundled studies read their scenarios from the binary this way.
pub fn parse_with(
    file: &Path,
    source: &str,
    samples: Option<u64>,
    read: &dyn Fn(&Path) -> std::io::Result<String>,
) -> Result<Study, StudyError> {
    let loc = Locator::new(file, source);
    let raw: raw::RawStudy = toml::from_str(source).map_err(|e| loc.from_toml(&e))?;
    let at = |k: &str, m: String| -> StudyError { loc.at_key(&KeyPath::parse(k), m).into() };
    let name = match &raw.name {
        Some(n) => {
            let ok = !n.is_empty()
                && n.chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
            if !ok {
                return Err(at(
                    "name",
                    format!("'{n}' must be non-empty and use only letters, digits, '-' and '_' (it names the report folder)"),
                ));
            }
            n.clone()
        }
        None => file
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("study")
            .to_string(),
    };
    let samples = match samples {
        Some(n) => n,
        None => raw.samples.unwrap_or(DEFAULT_SAMPLES),
    };
    if !(1..=MAX_SAMPLES).contains(&samples) {
        return Err(at(
            "samples",
            format!("must lie in [1, {MAX_SAMPLES}] (samples per sweep point), got {samples}"),
        ));
    }
    let scenario_file = normalise(&file.parent().unwrap_or(Path::new("")).join(&raw.scenario));
    let scenario_text = read(&scenario_file).map_err(|e| {
        at(
            "scenario",
            format!(
                "cannot read the scenario {} ({e}); the path is relative to the study file",
                scenario_file.display()
            ),
        )
    })?;
    let scene =
        crate::scenario::parse(&scenario_file, &scenario_text).map_err(StudyError::Scenario)?;
    let has_sensor = scene.obstacles.iter().any(|o| match o {
        crate::scenario::Obstacle::Pin(p) => p.sensor.is_some(),
        crate::scenario::Obstacle::Fence(_) => false,
    });
    compile::check_sensor_parameters(&loc, &raw.uncertain, &raw.sweep, has_sensor)?;
    let declared = compile::compile_uncertain(&loc, &raw.uncertain, scene.part.support)?;
    compile::check_reach(&loc, &raw.uncertain, &raw.sweep, &scene)?;
    let axes = compile::compile_sweeps(&loc, &raw.sweep)?;
    let points = if axes.is_empty() {
        vec![declared.clone()]
    } else {
        compile::compile_points(&loc, &raw.uncertain, &axes, scene.part.support)?
    };
    let seed = raw.seed.unwrap_or(1);
    compile::check_first_samples(
        &loc,
        &raw.uncertain,
        &raw.sweep,
        &axes,
        &points,
        &scene,
        seed,
    )?;
    let samples_text = samples.to_string();
    // The policy file the scenario names shapes every sample: its bytes are hashed too (a study
    // without one hashes what it did before policies existed).
    let policy_text = match scene.controller.as_ref().filter(|c| c.source != "scenario") {
        Some(c) => crate::input::read_text(Path::new(&c.source)).map_err(|e| {
            at(
                "scenario",
                format!("cannot read the policy file {} ({e})", c.source),
            )
        })?,
        None => String::new(),
    };
    let mut parts: Vec<&[u8]> = vec![
        b"pinfeed-mc-study",
        source.as_bytes(),
        scenario_text.as_bytes(),
        samples_text.as_bytes(),
    ];
    let mut scenario_parts: Vec<&[u8]> = vec![scenario_text.as_bytes()];
    if !policy_text.is_empty() {
        parts.push(policy_text.as_bytes());
        scenario_parts.push(policy_text.as_bytes());
    }
    let online = crate::engine::prepare::online_model(&scene).map_err(StudyError::Scenario)?;
    let study_hash = hash::fnv1a(&parts);
    let scenario_hash = hash::fnv1a(&scenario_parts);
    Ok(Study {
        name,
        file: file.to_path_buf(),
        scenario_file,
        scene,
        seed,
        samples,
        point_values: compile::grid(&axes),
        axes,
        points,
        declared,
        study_hash,
        scenario_hash,
        online,
    })
}

/// A file of `[uncertain.*]` tables alone, as a study declares them (docs/study-format.md), for a
/// line that does not exist yet (`pinfeed plan --uncertain FILE`): the perturbations, with the
/// part on uniform pressure unless `[uncertain.support]` says otherwise. What needs the line —
/// `fences = [...]` or `pins = [...]` naming its obstacles — is refused, located; whether a
/// parameter reaches the line is the planner's to decide when it has one.
pub fn parse_uncertain(file: &Path, source: &str) -> Result<Perturbations, StudyError> {
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Tables {
        #[serde(default)]
        uncertain: raw::RawUncertain,
    }
    let loc = Locator::new(file, source);
    let t: Tables = toml::from_str(source).map_err(|e| loc.from_toml(&e))?;
    let p = compile::compile_uncertain(&loc, &t.uncertain, crate::scenario::SupportKind::Uniform)?;
    if let Some(name) = p.only.keys().next() {
        let key = if compile::FENCE_PARAMETERS.contains(&name.as_str()) {
            "fences"
        } else {
            "pins"
        };
        return Err(loc
            .at_key(
                &KeyPath::parse(&format!("uncertain.{name}.{key}")),
                format!(
                    "names obstacles of a line not designed yet; leave `{key}` out (the planner's uncertainty reaches every obstacle of its kind)"
                ),
            )
            .into());
    }
    Ok(p)
}

/// `a/b/../c` → `a/c` (lexically; a leading `..` is kept).
pub(crate) fn normalise(p: &Path) -> PathBuf {
    use std::path::Component;
    let mut out: Vec<Component> = Vec::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out.iter().collect()
}
