//! Several line designs for one part side by side (`pinfeed compare`: pin layouts measured
//! against fence designs). Each scene runs its own feed (its headway, orientation and lateral
//! distributions, seed and number of parts) unless the user imposes one on all
//! ([`crate::scenario::FeedOverrides`]), so a design's row does not depend on which other files
//! are compared, nor on their order; scenes whose feeds agree see the same parts in the same order
//! ([`crate::scenario::shared_feed`]). The runs are independent and go in parallel, each a pure
//! function of its scene, so the rows do not depend on the thread count.
//!
//! Per scene:
//! * **goal**: what counts as a success, each goal set's orientations and tolerance (designs with
//!   different goal windows are not measured against the same target);
//! * **success rate** with its 95% Wilson interval (as `pinfeed run`);
//! * **footprint**: the belt length the design occupies — from the most upstream point of any
//!   obstacle (a pin's disc, a fence's segment) to the most downstream one, plus the part's length
//!   (its largest dimension, the greatest distance between two of its vertices), the room a part
//!   needs to clear the last obstacle. None without obstacles. Beside it, the same across the belt
//!   (**across**: the obstacles' y span plus the part's length) and the belt's width: fences trade
//!   belt length for width;
//! * **throughput of oriented parts** (successes per minute over the steady window, as `run`);
//! * **latency**: mean and 99th percentile of entry → exit time of the parts that exit, from the
//!   run's HDR histogram (3 significant digits);
//! * **contacts per part** and every outcome class that happened besides success (collisions,
//!   jams, …), with every outcome count in the JSON;
//! * its **obstacles** by kind ([`ObstacleKinds`]: "1 sensor pin + 2 moving pins").

use crate::engine::prepare::OnlineHandle;
use crate::engine::{self, EngineError, OutcomeCounts, RunOptions};
use crate::geometry::Polygon;
use crate::scenario::{Actuator, FeedOverrides, Goal, Obstacle, Scene};
use rayon::prelude::*;
use serde::Serialize;
use thiserror::Error;

/// One scene's line of the comparison.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComparisonRow {
    /// The scene's name and the file it came from.
    pub scenario: String,
    /// The scenario file, as given.
    pub file: String,
    /// Number of pins on the line (of every kind).
    pub pins: usize,
    /// Number of fences on the line.
    pub fences: usize,
    /// The obstacles by kind.
    pub obstacle_kinds: ObstacleKinds,
    /// Seed of the run's part stream.
    pub seed: u64,
    /// Parts fed in.
    pub parts_in: u64,
    /// (Mean) time between arrivals (s): the file's, or `--headway`.
    pub headway_s: f64,
    /// What counts as a success: the goal sets; empty when every exiting part does (`any`).
    pub goal: Vec<GoalWindow>,
    /// Share of parts that ended in success, in [0, 1].
    pub success_rate: f64,
    /// 95% Wilson interval of the success rate, [low, high].
    pub success_ci95: [f64; 2],
    /// [first, last] x of the obstacles (m).
    pub obstacle_span_m: Option<[f64; 2]>,
    /// The part's largest dimension (m).
    pub part_length_m: f64,
    /// Obstacle span plus the part's length (m).
    pub footprint_m: Option<f64>,
    /// [lowest, highest] y of the obstacles (m).
    pub obstacle_y_span_m: Option<[f64; 2]>,
    /// Obstacle y span plus the part's length (m).
    pub across_m: Option<f64>,
    /// The belt's width (m).
    pub belt_width_m: f64,
    /// Oriented parts per minute over the steady window (None without one).
    pub throughput_ok_per_min: Option<f64>,
    /// Mean entry → exit time of the exiting parts (s).
    pub latency_mean_s: Option<f64>,
    /// 99th percentile of entry → exit time (s).
    pub latency_p99_s: Option<f64>,
    /// Mean contacts per part.
    pub contacts_per_part: f64,
    /// Parts that jammed.
    pub jams: u64,
    /// Count per outcome class (of the passes, on a closed loop).
    pub outcomes: OutcomeCounts,
    /// A closed loop's purity, passes and scrap (absent from the JSON on an open line). On a
    /// closed loop `parts_in` counts the new parts, `success_rate` the parts delivered in the
    /// goal per new part and `throughput_ok_per_min` the loop's oriented parts per minute.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub closed_loop: Option<LoopRow>,
}

/// What a closed loop adds to its row.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LoopRow {
    /// Delivered parts in the goal / delivered parts.
    pub purity: f64,
    /// Its 95% Wilson interval.
    pub purity_ci95: [f64; 2],
    /// Mean passes per delivered part.
    pub passes_per_delivered: f64,
    /// Parts scrapped (last pass or a full buffer).
    pub scrapped: u64,
    /// Parts delivered per minute over the loop's steady window.
    pub delivered_per_min: Option<f64>,
}

/// A line's obstacles by kind (the file format's `pin`, `sensor_pin`, `moving_pin`,
/// `retractable_pin` and `fence`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ObstacleKinds {
    /// Fixed pins without a sensor.
    pub fixed_pins: usize,
    /// Fixed pins with a sensor.
    pub sensor_pins: usize,
    /// Pins that move across the belt.
    pub moving_pins: usize,
    /// Pins raised or withdrawn per part.
    pub retractable_pins: usize,
    /// Fences.
    pub fences: usize,
}

impl ObstacleKinds {
    /// Count `scene`'s obstacles by kind.
    pub fn of(scene: &Scene) -> ObstacleKinds {
        let mut k = ObstacleKinds::default();
        for o in &scene.obstacles {
            *match o {
                Obstacle::Fence(_) => &mut k.fences,
                Obstacle::Pin(p) => match (&p.actuator, &p.sensor) {
                    (Some(Actuator::Moving(_)), _) => &mut k.moving_pins,
                    (Some(Actuator::Retractable(_)), _) => &mut k.retractable_pins,
                    (None, Some(_)) => &mut k.sensor_pins,
                    (None, None) => &mut k.fixed_pins,
                },
            } += 1;
        }
        k
    }
}

impl std::fmt::Display for ObstacleKinds {
    /// "1 sensor pin + 2 moving pins", "3 pins", "2 pins + 1 fence", "none".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kinds = [
            (self.sensor_pins, "sensor pin"),
            (self.moving_pins, "moving pin"),
            (self.retractable_pins, "retractable pin"),
            (self.fixed_pins, "pin"),
            (self.fences, "fence"),
        ];
        let named: Vec<String> = kinds
            .iter()
            .filter(|(n, _)| *n > 0)
            .map(|&(n, kind)| format!("{n} {kind}{}", if n == 1 { "" } else { "s" }))
            .collect();
        if named.is_empty() {
            f.write_str("none")
        } else {
            f.write_str(&named.join(" + "))
        }
    }
}

/// One goal set of a scene: a part succeeds when its final orientation is within
/// `tolerance_deg` of one of `orientations_deg`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GoalWindow {
    /// The goal set's name.
    pub name: String,
    /// Its goal orientations (degrees).
    pub orientations_deg: Vec<f64>,
    /// Largest distance to a goal orientation that still succeeds (degrees).
    pub tolerance_deg: f64,
}

/// A scene's goal sets in degrees (none for `any`), rounded to 10⁻⁹° so that the degrees of the
/// scenario file come back as written (not 3.0000000000000004 after radians and back).
pub fn goal_windows(goal: &Goal) -> Vec<GoalWindow> {
    let deg = |rad: f64| (rad.to_degrees() * 1e9).round() / 1e9;
    match goal {
        Goal::Any => Vec::new(),
        Goal::Sets(sets) => sets
            .iter()
            .map(|s| GoalWindow {
                name: s.name.clone(),
                orientations_deg: s.orientations_rad.iter().map(|&o| deg(o)).collect(),
                tolerance_deg: deg(s.tolerance_rad),
            })
            .collect(),
    }
}

/// The greatest distance between two vertices of a polygon (its units).
pub fn part_length(poly: &Polygon) -> f64 {
    let v = poly.vertices();
    let mut best: f64 = 0.0;
    for (i, &p) in v.iter().enumerate() {
        for &q in &v[i + 1..] {
            best = best.max((q - p).norm());
        }
    }
    best
}

/// [first, last] x of a scene's obstacles (m), None without obstacles.
pub fn obstacle_span(scene: &Scene) -> Option<[f64; 2]> {
    span(scene, Obstacle::x_range)
}

fn span(scene: &Scene, range: fn(&Obstacle) -> [f64; 2]) -> Option<[f64; 2]> {
    scene
        .obstacles
        .iter()
        .map(range)
        .reduce(|a, b| [a[0].min(b[0]), a[1].max(b[1])])
}

/// The designs of a comparison: what [`designs`] returns.
#[derive(Debug)]
pub struct Designs {
    /// The scenes, in the order given, each with its own feed and the overrides applied.
    pub scenes: Vec<Scene>,
    /// Where each scene came from (as given).
    pub files: Vec<String>,
    /// Each scene's online controller's model, built from the file as written (None without one).
    pub online: Vec<Option<OnlineHandle>>,
    /// What the user imposed on every feed.
    pub overrides: FeedOverrides,
}

/// Why the designs of a comparison cannot be set up.
#[derive(Debug, Error)]
pub enum DesignsError {
    /// A scenario file is refused (or its online model cannot be built).
    #[error(transparent)]
    Scenario(#[from] crate::scenario::ScenarioError),
    /// No scenario file was given.
    #[error("compare needs at least one scenario file")]
    Empty,
    /// An override out of range.
    #[error(transparent)]
    Override(#[from] crate::scenario::OverrideError),
    /// A design is for another part than the first one.
    #[error("{file} cannot run on the part stream of {first}: {reason}")]
    Stream {
        /// The design refused.
        file: String,
        /// The first design's file.
        first: String,
        /// Why (a different part).
        reason: crate::scenario::FeedMismatch,
    },
}

/// Read the scenario files `paths`, check that they describe one part, and impose `overrides` on
/// each one's feed; a closed loop is followed by its open line (`<name>-open`: the same scene
/// without its gate and return path). Each online controller's model is built from its file as written, before the
/// overrides: the controller was designed for its own feed.
pub fn designs(
    paths: &[std::path::PathBuf],
    overrides: FeedOverrides,
) -> Result<Designs, DesignsError> {
    overrides.check()?;
    let (mut scenes, mut files, mut online) = (Vec::new(), Vec::new(), Vec::new());
    for path in paths {
        let scene = crate::scenario::load(path)?;
        let model = crate::engine::prepare::online_model(&scene)?;
        // A closed loop runs beside its open line: the same scene without gate or return path.
        let open = scene.closed_loop.is_some().then(|| Scene {
            name: format!("{}-open", scene.name),
            closed_loop: None,
            ..scene.clone()
        });
        online.push(model.clone());
        scenes.push(scene);
        files.push(path.display().to_string());
        if let Some(open) = open {
            online.push(model);
            scenes.push(open);
            files.push(format!("{} (open)", path.display()));
        }
    }
    let first = scenes.first().ok_or(DesignsError::Empty)?.clone();
    for (scene, file) in scenes.iter_mut().zip(&files) {
        crate::scenario::same_part(&first, scene).map_err(|reason| DesignsError::Stream {
            file: file.clone(),
            first: files[0].clone(),
            reason,
        })?;
        overrides.apply(scene);
    }
    Ok(Designs {
        scenes,
        files,
        online,
        overrides,
    })
}

/// Run every scene with its own feed's number of parts; one row per scene, in order.
/// `files` names where each scene came from; `online` holds, per scene, the online controller's
/// model of the scene as written, before it was given the shared part stream
/// ([`crate::engine::prepare::online_model`]; None: built from the scene run).
pub fn compare(
    scenes: &[Scene],
    files: &[String],
    online: &[Option<OnlineHandle>],
) -> Result<Vec<ComparisonRow>, EngineError> {
    compare_observed(scenes, files, online, &crate::progress::silent)
}

/// [`compare`], telling `progress` the parts finished over all scenes of all.
pub fn compare_observed(
    scenes: &[Scene],
    files: &[String],
    online: &[Option<OnlineHandle>],
    progress: crate::progress::Report,
) -> Result<Vec<ComparisonRow>, EngineError> {
    let total = scenes.iter().map(|s| s.feed.parts).sum();
    let tally = crate::progress::Tally::new(total, progress);
    scenes
        .par_iter()
        .zip(files.par_iter())
        .enumerate()
        .map(|(k, (scene, file))| {
            let opts = RunOptions {
                online: online.get(k).cloned().flatten(),
                ..RunOptions::from_scene(scene)
            };
            let mut reported = 0;
            let r = engine::run(scene, &opts, &mut |finished| {
                tally.add(finished - reported);
                reported = finished;
            })?;
            let s = &r.summary;
            let span = obstacle_span(scene);
            let y_span = self::span(scene, Obstacle::y_range);
            let length = part_length(&scene.part.polygon);
            let hist = &r.metrics.latency_us;
            let kinds = ObstacleKinds::of(scene);
            let mut row = ComparisonRow {
                scenario: scene.name.clone(),
                file: file.clone(),
                pins: scene.obstacles.len() - kinds.fences,
                fences: kinds.fences,
                obstacle_kinds: kinds,
                seed: s.seed,
                parts_in: s.parts_in,
                headway_s: scene.feed.arrival.headway(),
                goal: goal_windows(&scene.goal),
                success_rate: s.success_rate,
                success_ci95: s.success_ci95,
                obstacle_span_m: span,
                part_length_m: length,
                footprint_m: span.map(|[a, b]| b - a + length),
                obstacle_y_span_m: y_span,
                across_m: y_span.map(|[a, b]| b - a + length),
                belt_width_m: scene.belt.width,
                throughput_ok_per_min: s.throughput_ok_per_min,
                latency_mean_s: (!hist.is_empty()).then(|| {
                    // The histogram's mean is of bucket midpoints: keep it within the range.
                    (hist.mean() * 1e-6).clamp(r.metrics.latency_min, r.metrics.latency_max)
                }),
                latency_p99_s: s.latency_s.map(|l| l.p99),
                contacts_per_part: s.contacts_per_part,
                jams: s.outcomes.jam,
                outcomes: s.outcomes,
                closed_loop: None,
            };
            if let Some(l) = &s.closed_loop {
                let ok = l.fates.delivered_ok;
                row.parts_in = l.new_parts;
                row.success_rate = ok as f64 / l.new_parts.max(1) as f64;
                row.success_ci95 = crate::statistics::wilson_interval(ok, l.new_parts);
                row.throughput_ok_per_min = l.oriented_per_min;
                row.closed_loop = Some(LoopRow {
                    purity: l.purity,
                    purity_ci95: l.purity_ci95,
                    passes_per_delivered: l.passes_per_delivered.mean,
                    scrapped: l.fates.scrapped_max_passes + l.fates.scrapped_full,
                    delivered_per_min: l.delivered_per_min,
                });
            }
            Ok(row)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obstacles_are_named_by_kind() {
        let k = |sensor_pins, moving_pins, fixed_pins, fences| {
            ObstacleKinds {
                fixed_pins,
                sensor_pins,
                moving_pins,
                retractable_pins: 0,
                fences,
            }
            .to_string()
        };
        assert_eq!(k(1, 2, 0, 0), "1 sensor pin + 2 moving pins");
        assert_eq!(k(0, 0, 3, 0), "3 pins");
        assert_eq!(k(0, 0, 1, 2), "1 pin + 2 fences");
        assert_eq!(k(0, 0, 0, 0), "none");
    }

    #[test]
    fn part_length_is_the_largest_dimension() {
        let p = crate::geometry::part_from_spec("tripoly2").unwrap();
        // The hypotenuse of the 2 × 1 right triangle.
        assert!((part_length(&p) - 5f64.sqrt()).abs() < 1e-12);
        // A square's diagonal.
        let sq = crate::geometry::part_from_spec("square").unwrap();
        let v = sq.vertices();
        assert!((part_length(&sq) - (v[2] - v[0]).norm()).abs() < 1e-12);
        assert!(part_length(&sq) > (v[1] - v[0]).norm() * 1.4);
    }
}
