//! The scenario file as written: serde structs mirroring the TOML, one per section, each with
//! `deny_unknown_fields` so a misspelt key is an error (no `flatten`, which would defeat it).
//! Values are checked and converted in [`super::compile`]; this layer only fixes names and types.
//! Units are SI (m, s) and degrees, as documented in docs/scenario-format.md.

use crate::mechanics::Fidelity;
use serde::Deserialize;

/// The whole file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScenario {
    /// Name used for the results folder (default: the file name without `.toml`).
    pub name: Option<String>,
    /// Seed of the run (default 1).
    pub seed: Option<u64>,
    pub belt: Option<RawBelt>,
    pub part: Option<RawPart>,
    pub feed: Option<RawFeed>,
    #[serde(default)]
    pub obstacles: Vec<RawObstacle>,
    pub goal: Option<RawGoal>,
    #[serde(default)]
    pub model: RawModel,
    #[serde(default)]
    pub effects: RawEffects,
    #[serde(default)]
    pub output: RawOutput,
    pub controller: Option<RawController>,
    #[serde(default)]
    pub rules: Vec<RawRule>,
}

/// `[belt]`: speed (m/s), width (m, the belt spans y ∈ [−width/2, width/2]) and usable length (m,
/// parts enter at x = 0 and leave at x = length).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBelt {
    pub speed: f64,
    pub width: f64,
    pub length: f64,
}

/// How the part's weight rests on the belt.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum SupportKind {
    /// Uniform pressure over the footprint.
    #[default]
    Uniform,
    /// A random tripod per part, drawn from the part's own random stream.
    Tripod,
}

/// `[part]`: a named shape or a vertex list, scaled to metres.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPart {
    pub shape: Option<String>,
    pub vertices: Option<Vec<[f64; 2]>>,
    /// Metres per unit of the shape's coordinates.
    pub scale: Option<f64>,
    /// Pin–part friction coefficient (default 0.5; a pin may override it).
    pub mu_c: Option<f64>,
    /// Part–belt friction coefficient (default 0.3; scales forces only).
    pub mu_s: Option<f64>,
    /// Part mass (kg, default 0.05): turns the contact model's forces into newtons for sensors.
    pub mass: Option<f64>,
    #[serde(default)]
    pub support: SupportKind,
}

/// Arrival process.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ArrivalKind {
    Periodic,
    Poisson,
}

/// Distribution of the initial orientation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OrientationKind {
    Uniform,
    Stable,
}

/// Distribution of the lateral offset of the centroid at entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LateralKind {
    Fixed,
    Uniform,
    Normal,
}

/// `[feed]`: how many parts, when and how they arrive.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFeed {
    pub parts: u64,
    pub arrival: ArrivalKind,
    /// Seconds between arrivals (the mean, for Poisson).
    pub headway: Option<f64>,
    /// Arrivals per second (alternative to headway).
    pub rate: Option<f64>,
    pub orientation: OrientationKind,
    /// Relative weights of the stable states (orientation = "stable"), in the order `pinfeed part` lists them.
    pub weights: Option<Vec<f64>>,
    /// Standard deviation of a normal perturbation of the orientation (degrees).
    pub jitter: Option<f64>,
    pub lateral: Option<RawLateral>,
}

/// `[feed.lateral]`: the centroid's y at entry (m).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLateral {
    pub distribution: LateralKind,
    pub value: Option<f64>,
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub mean: Option<f64>,
    pub sd: Option<f64>,
}

/// Kinds of obstacle. `pin` and `fence` are simulated; the others are reserved names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObstacleKind {
    Pin,
    SensorPin,
    MovingPin,
    RetractablePin,
    Fence,
}

/// `[[obstacles]]`: one element over the belt. A pin takes x, y, radius and mu_c; a fence takes
/// x, y (its upstream end), angle, length and mu_f. Which keys apply is checked in
/// [`super::compile`].
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawObstacle {
    pub kind: ObstacleKind,
    pub name: Option<String>,
    /// Position of the pin's centre, or of the fence's upstream end (m, world frame).
    pub x: Option<f64>,
    pub y: Option<f64>,
    /// Pin radius (m; 0 is a point pin).
    pub radius: Option<f64>,
    /// Pin–part friction for this pin (default: the part's mu_c).
    pub mu_c: Option<f64>,
    /// Fence angle from the belt direction (degrees, strictly between −90 and 90; positive fences
    /// run downstream to the left and deflect parts to the left).
    pub angle: Option<f64>,
    /// Fence length along the fence (m).
    pub length: Option<f64>,
    /// Fence–part friction (default: the part's mu_c).
    pub mu_f: Option<f64>,
    /// `[obstacles.sensor]`: the sensor of a `sensor_pin` (or of a `moving_pin`).
    pub sensor: Option<RawSensor>,
    /// A moving pin's lateral range [min, max] (m), speed (m/s) and acceleration (m/s²) limits,
    /// settle time (s) and the pieces an acceleration phase is resolved into.
    pub travel: Option<[f64; 2]>,
    pub speed: Option<f64>,
    pub accel: Option<f64>,
    pub settle: Option<f64>,
    pub pieces: Option<u32>,
    /// A retractable pin's state before any command, and its switching times (s).
    pub raised: Option<bool>,
    pub raise_time: Option<f64>,
    pub lower_time: Option<f64>,
}

/// `[controller]`: how decisions become actuator commands (docs/scenario-format.md#controller-and-rules).
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RawController {
    /// Computation time from the end of a reading to the commands (s, default 0.01).
    pub latency: Option<f64>,
    /// Decisions with a posterior below this count as no decision (default 0).
    pub min_posterior: Option<f64>,
    /// `skip` (default) or `move`: what a command that cannot finish before its part arrives does.
    pub on_late: Option<String>,
    /// A policy file (rules written by `pinfeed plan`), relative to the scenario file.
    pub policy: Option<String>,
    /// `policy` (default: the rules) or `online` (replanning from a belief per part).
    pub mode: Option<String>,
    /// What the online controller considers possible about a part.
    pub belief: Option<RawBelief>,
}

/// `[controller.belief]` (docs/scenario-format.md#online-controller).
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RawBelief {
    pub mu_c: Option<Vec<f64>>,
    pub support: Option<Vec<SupportKind>>,
    pub offsets: Option<usize>,
    pub samples: Option<usize>,
    pub targets: Option<usize>,
}

/// `[[rules]]`: when `sensor` decides `decides`, bring `pin` to `y` (a moving pin) or `raised`
/// (a retractable pin) for that part.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRule {
    pub sensor: String,
    pub decides: String,
    pub pin: String,
    pub y: Option<f64>,
    pub raised: Option<bool>,
}

/// A policy file: the part it was planned for, and its rules.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPolicy {
    pub part: String,
    #[serde(default)]
    pub rules: Vec<RawRule>,
}

/// `[obstacles.sensor]` of a sensor pin (docs/scenario-format.md#sensor-pins; defaults in
/// [`crate::sensing::settings`]). Units: N, N·mm, m, s, Hz.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RawSensor {
    /// `ft` (force/torque, default) or `timing`.
    #[serde(rename = "type")]
    pub kind: Option<crate::sensing::SensorKind>,
    pub rate: Option<f64>,
    pub height: Option<f64>,
    pub noise_force: Option<f64>,
    pub noise_torque: Option<f64>,
    pub bias_force: Option<f64>,
    pub bias_torque: Option<f64>,
    pub drift_force: Option<f64>,
    pub drift_torque: Option<f64>,
    pub resolution_force: Option<f64>,
    pub resolution_force_z: Option<f64>,
    pub resolution_torque: Option<f64>,
    pub lowpass: Option<f64>,
    pub threshold: Option<f64>,
    pub jitter: Option<f64>,
    /// Classifier name (default `likelihood` for F/T, `timing` for a timing sensor).
    pub classifier: Option<String>,
    /// `"stable"` (the part's stable states, default), `"vertex-edge"`, or a list of degrees.
    pub hypotheses: Option<RawHypotheses>,
    /// Templates per hypothesis (default 32).
    pub templates: Option<u64>,
    /// Reject option: decide "unknown" below this posterior (default 0: never).
    pub reject_below: Option<f64>,
}

/// The hypotheses of a sensor: a name or a list of orientations (degrees).
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum RawHypotheses {
    Named(String),
    Degrees(Vec<f64>),
}

/// `[goal]`: which final orientations count as correct.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawGoal {
    /// Every exiting part counts as correctly oriented.
    #[serde(default)]
    pub any: bool,
    #[serde(default)]
    pub sets: Vec<RawGoalSet>,
}

/// `[[goal.sets]]`: a named set of target orientations (degrees) with a tolerance (degrees).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawGoalSet {
    pub name: Option<String>,
    pub orientations: Vec<f64>,
    pub tolerance: Option<f64>,
}

/// `[model]`: the contact model's fidelity and accuracy.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawModel {
    pub fidelity: Option<RawFidelity>,
    /// The map tier's grid (`fidelity = "map"` only): [θ0 base cells, d base cells, refinement
    /// depth].
    pub map_grid: Option<[u32; 3]>,
    pub tol: Option<f64>,
    /// Largest pin travel in contact, in units of a, before a part counts as jammed.
    pub max_travel: Option<f64>,
}

/// `[model] fidelity`: a contact-model fidelity, or `map`: the certified map tier over the exact
/// model (see `maps::tier`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RawFidelity {
    Tip,
    Ellipsoid,
    Exact,
    Map,
}

impl RawFidelity {
    /// The contact model's fidelity (the map tier's table and fallbacks are the exact model's).
    pub fn contact_fidelity(self) -> Fidelity {
        match self {
            RawFidelity::Tip => Fidelity::Tip,
            RawFidelity::Ellipsoid => Fidelity::Ellipsoid,
            RawFidelity::Exact | RawFidelity::Map => Fidelity::Exact,
        }
    }
}

/// `[effects]`: optional work the engine does only when switched on.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawEffects {
    /// Detect part–part overlap (default true; only ever runs while two parts share the belt).
    pub collisions: Option<bool>,
    /// Check that a part pushed by one obstacle does not touch another (default true; only runs
    /// for obstacles close enough to interact).
    pub obstacle_sweeps: Option<bool>,
    /// Keep a log of every event (default false; for debugging and tests).
    pub event_log: Option<bool>,
}

/// `[output]`: what files a run writes.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawOutput {
    /// Folder under which `<scenario name>/` is written (default "pinfeed-out/runs").
    pub dir: Option<String>,
    /// Write one CSV row per part (default false).
    pub parts_csv: Option<bool>,
    /// Write the final-orientation histogram as SVG (default true).
    pub histogram_svg: Option<bool>,
    /// Histogram bin width, degrees (default 5).
    pub histogram_bin: Option<f64>,
    /// How many sample parts `--draw` shows (default 4).
    pub draw_parts: Option<u32>,
}
