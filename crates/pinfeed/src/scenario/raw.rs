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
    /// `[belt]` (required).
    pub belt: Option<RawBelt>,
    /// `[part]` (required).
    pub part: Option<RawPart>,
    /// `[feed]` (required).
    pub feed: Option<RawFeed>,
    /// `[[obstacles]]`: pins and fences, in file order (their default names count in this order).
    #[serde(default)]
    pub obstacles: Vec<RawObstacle>,
    /// `[goal]`: which final orientations count as correct (default: none are goals).
    pub goal: Option<RawGoal>,
    /// `[model]`: contact-model fidelity and accuracy.
    #[serde(default)]
    pub model: RawModel,
    /// `[effects]`: optional engine work (collisions, sweeps, event log).
    #[serde(default)]
    pub effects: RawEffects,
    /// `[output]`: which files a run writes.
    #[serde(default)]
    pub output: RawOutput,
    /// `[controller]`: how sensor decisions become actuator commands.
    pub controller: Option<RawController>,
    /// `[[rules]]`: sensor decision → pin target rules for the policy controller.
    #[serde(default)]
    pub rules: Vec<RawRule>,
    /// `[recirculation]`: the return path of the parts a reject gate takes off the belt
    /// (docs/scenario-format.md#closed-loop).
    pub recirculation: Option<RawRecirculation>,
}

/// A time (s) given as a number (always that long) or as a distribution table.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum RawTime {
    /// Always this many seconds.
    Fixed(f64),
    /// `{ distribution = "fixed" | "uniform" | "exponential", value | min, max | mean }`.
    Table(RawTimeTable),
}

/// A time's distribution table (see [`RawTime`]).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTimeTable {
    /// `fixed`, `uniform` or `exponential`.
    pub distribution: String,
    /// The value of `fixed` (s).
    pub value: Option<f64>,
    /// The lower end of `uniform` (s).
    pub min: Option<f64>,
    /// The upper end of `uniform` (s).
    pub max: Option<f64>,
    /// The mean of `exponential` (s).
    pub mean: Option<f64>,
}

/// `[recirculation]`: the return conveyor from the reject gate back to the feed.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRecirculation {
    /// Transit time from the gate to the merge with the feed (s, or a distribution).
    pub transit: Option<RawTime>,
    /// Parts the buffer before the merge holds (default: unbounded).
    pub buffer: Option<u64>,
    /// `block` (default: a part finding the buffer full waits on the return conveyor) or
    /// `drop` (it is scrapped).
    pub when_full: Option<String>,
    /// Passes a part may make; a part rejected on its last pass is scrapped (default 10).
    pub max_passes: Option<u32>,
    /// Least time between two parts entering the belt at the merge (s, or a distribution;
    /// default: the time the belt takes to carry two part diameters).
    pub merge_gap: Option<RawTime>,
}

/// `[belt]`: speed (m/s), width (m, the belt spans y ∈ [−width/2, width/2]) and usable length (m,
/// parts enter at x = 0 and leave at x = length).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBelt {
    /// Belt speed (m/s, in [1e-4, 10]).
    pub speed: f64,
    /// Belt width (m, in [1e-9, 1000], at least the part's 2a).
    pub width: f64,
    /// Usable belt length (m, in [1e-9, 10⁴]).
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
    /// A named part (`tripoly1`, `tripoly2`, `square`, `rect:W:H`, `ngon:N`, `lshape`); exactly one of `shape` and `vertices` is given.
    pub shape: Option<String>,
    /// The part's vertices `[x, y]` in shape units (scaled by `scale`), instead of `shape`.
    pub vertices: Option<Vec<[f64; 2]>>,
    /// Metres per unit of the shape's coordinates.
    pub scale: Option<f64>,
    /// A part file's unit when the file does not state it (`mm`, `inch`, ...; docs/cad.md).
    pub units: Option<String>,
    /// A part file's chordal tolerance of flattened arcs (mm; docs/cad.md).
    pub flatten: Option<f64>,
    /// Pin–part friction coefficient (default 0.5; a pin may override it).
    pub mu_c: Option<f64>,
    /// Part–belt friction coefficient (default 0.3; scales forces only).
    pub mu_s: Option<f64>,
    /// Part mass (kg, default 0.05): turns the contact model's forces into newtons for sensors.
    pub mass: Option<f64>,
    /// How the weight rests on the belt (default uniform pressure).
    #[serde(default)]
    pub support: SupportKind,
}

/// Arrival process.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ArrivalKind {
    /// Parts arrive every `headway` seconds, the first at t = 0.
    Periodic,
    /// Arrivals form a Poisson process with mean spacing `headway`.
    Poisson,
}

/// Distribution of the initial orientation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OrientationKind {
    /// Uniform on [0°, 360°).
    Uniform,
    /// One of the part's stable states, drawn by `weights`, plus `jitter`.
    Stable,
}

/// Distribution of the lateral offset of the centroid at entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LateralKind {
    /// Always `value`.
    Fixed,
    /// Uniform on [`min`, `max`].
    Uniform,
    /// Normal with `mean` and `sd`, redrawn until the part lies on the belt.
    Normal,
}

/// `[feed]`: how many parts, when and how they arrive.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFeed {
    /// Number of parts (1 to 10⁹).
    pub parts: u64,
    /// Periodic or Poisson arrivals.
    pub arrival: ArrivalKind,
    /// Seconds between arrivals (the mean, for Poisson).
    pub headway: Option<f64>,
    /// Arrivals per second (alternative to headway).
    pub rate: Option<f64>,
    /// How the entry orientation is drawn.
    pub orientation: OrientationKind,
    /// Relative weights of the stable states (orientation = "stable"), in the order `pinfeed part` lists them.
    pub weights: Option<Vec<f64>>,
    /// Standard deviation of a normal perturbation of the orientation (degrees).
    pub jitter: Option<f64>,
    /// `[feed.lateral]`: the entry offset (default fixed at 0).
    pub lateral: Option<RawLateral>,
}

/// `[feed.lateral]`: the centroid's y at entry (m).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLateral {
    /// Which distribution the offset follows; it decides which of the keys below apply.
    pub distribution: LateralKind,
    /// The offset for `fixed` (m).
    pub value: Option<f64>,
    /// Lower bound for `uniform` (m).
    pub min: Option<f64>,
    /// Upper bound for `uniform` (m).
    pub max: Option<f64>,
    /// Mean for `normal` (m).
    pub mean: Option<f64>,
    /// Standard deviation for `normal` (m, at most the belt width).
    pub sd: Option<f64>,
}

/// Kinds of obstacle. `pin` and `fence` are simulated; the others are reserved names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObstacleKind {
    /// A fixed pin.
    Pin,
    /// A fixed pin carrying a force/torque or timing sensor (`[obstacles.sensor]`).
    SensorPin,
    /// A pin that moves across the belt under the controller's commands.
    MovingPin,
    /// A pin that the controller raises or withdraws per part.
    RetractablePin,
    /// A straight fence (a segment with no thickness).
    Fence,
    /// A reject gate at the belt's end (an air jet or a diverter) that takes off the parts a
    /// sensor pin decided are not in the goal.
    RejectGate,
}

/// `[[obstacles]]`: one element over the belt. A pin takes x, y, radius and mu_c; a fence takes
/// x, y (its upstream end), angle, length and mu_f. Which keys apply is checked in
/// [`super::compile`].
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawObstacle {
    /// What the obstacle is; decides which keys apply.
    pub kind: ObstacleKind,
    /// A unique name (default `pinN` / `fenceN`, N the position in the list).
    pub name: Option<String>,
    /// Position along the belt of the pin's centre, or of the fence's upstream end (m, world frame).
    pub x: Option<f64>,
    /// Lateral position of the pin's centre, or of the fence's upstream end (m, |y| ≤ width/2).
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
    /// Radius of the fence's curved tail (m): an arc tangent to the fence at its downstream end
    /// that turns it parallel to the belt (default: none, the fence ends abruptly).
    pub tail_radius: Option<f64>,
    /// `[obstacles.sensor]`: the sensor of a `sensor_pin` (or of a `moving_pin`).
    pub sensor: Option<RawSensor>,
    /// Moving pin: its lateral range [min, max] (m, over the belt, holding the home `y`).
    pub travel: Option<[f64; 2]>,
    /// Moving pin: speed limit (m/s, in [1e-6, 10³] and at most 1000 × belt speed).
    pub speed: Option<f64>,
    /// Moving pin: acceleration limit (m/s², in [1e-6, 10⁶]).
    pub accel: Option<f64>,
    /// Moving pin: settle time after each move (s, in [0, 10⁴], default 0).
    pub settle: Option<f64>,
    /// Moving pin: constant-speed pieces per acceleration phase for the contact model (1 to 64, default 8).
    pub pieces: Option<u32>,
    /// Retractable pin: its state before any command (default true: raised).
    pub raised: Option<bool>,
    /// Retractable pin: time to raise (s, in [0, 10⁴], default 0.1).
    pub raise_time: Option<f64>,
    /// Retractable pin: time to withdraw (s, in [0, 10⁴], default 0.1).
    pub lower_time: Option<f64>,
    /// Reject gate: the sensor pin whose decision commands it (default: none, the gate takes
    /// every part it can).
    pub decided_by: Option<String>,
    /// Reject gate: what takes a part off: `decision` (default: its sensor pin's decision),
    /// `contact` (the part touched the `decided_by` pin: a contact switch) or `belief` (the online
    /// controller's predicted success is below `min_success`).
    pub reject_on: Option<String>,
    /// Reject gate with `reject_on = "belief"`: the least predicted success that passes (default
    /// 0.5).
    pub min_success: Option<f64>,
    /// Reject gate: the sensor's hypotheses that pass (default: those in the goal).
    pub accept: Option<Vec<String>>,
    /// Reject gate: what an `unknown` decision does: `reject` (default) or `pass`.
    pub unknown: Option<String>,
    /// Reject gate: half-width of the band across the belt it acts on, about its `y` (m).
    pub reach: Option<f64>,
    /// Reject gate: time from the end of the reading to the gate ready to act (s).
    pub actuation: Option<f64>,
    /// Reject gate: time it cannot act again after acting (s, or a distribution).
    pub busy: Option<RawTime>,
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
    /// Pin–part friction hypotheses (1 to 16 values in [0, 5]; default the part's mu_c).
    pub mu_c: Option<Vec<f64>>,
    /// Support hypotheses (default: the part's support).
    pub support: Option<Vec<SupportKind>>,
    /// Lateral-offset bins over the feed's lateral range (1 to 41, default 5).
    pub offsets: Option<usize>,
    /// Simulated members per hypothesis (1 to 64, default 4).
    pub samples: Option<usize>,
    /// Positions per moving pin over its travel in the action grid (2 to 101, default 25).
    pub targets: Option<usize>,
}

/// `[[rules]]`: when `sensor` decides `decides`, bring `pin` to `y` (a moving pin) or `raised`
/// (a retractable pin) for that part.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRule {
    /// Name of the sensor pin whose decision triggers the rule.
    pub sensor: String,
    /// The decision that triggers it: a hypothesis label such as `"135°"`, or `"unknown"`.
    pub decides: String,
    /// Name of the moving or retractable pin the rule commands.
    pub pin: String,
    /// Target y of a moving pin (m, within its travel).
    pub y: Option<f64>,
    /// Target state of a retractable pin (true: raised).
    pub raised: Option<bool>,
}

/// A policy file: the part it was planned for, and its rules.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPolicy {
    /// Name of the part the policy was planned for; must be the scenario's part.
    pub part: String,
    /// The policy's rules, as `[[rules]]` in a scenario.
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
    /// Sample rate (Hz, in [1, 10⁵]).
    pub rate: Option<f64>,
    /// Height of the sensor origin above the contact (m, in [0, 10]); torques are taken about it.
    pub height: Option<f64>,
    /// White-noise standard deviation per force channel (N, in [0, 10⁶]).
    pub noise_force: Option<f64>,
    /// White-noise standard deviation per torque channel (N·mm, in [0, 10⁹]).
    pub noise_torque: Option<f64>,
    /// Constant force bias (N, within ±10⁶).
    pub bias_force: Option<f64>,
    /// Constant torque bias (N·mm, within ±10⁹).
    pub bias_torque: Option<f64>,
    /// Force drift (N/s, within ±10⁶).
    pub drift_force: Option<f64>,
    /// Torque drift (N·mm/s, within ±10⁹).
    pub drift_torque: Option<f64>,
    /// Quantisation step of Fx, Fy (N, in [0, 10³]; 0: none).
    pub resolution_force: Option<f64>,
    /// Quantisation step of Fz (N, in [0, 10³]; 0: none).
    pub resolution_force_z: Option<f64>,
    /// Quantisation step of the torques (N·mm, in [0, 10⁶]; 0: none).
    pub resolution_torque: Option<f64>,
    /// Cut-off of a first-order low-pass filter before quantisation (Hz, in [10⁻³, 10⁶]; default none).
    pub lowpass: Option<f64>,
    /// Timing sensor: the force magnitude that marks contact (N, in [10⁻⁹, 10⁶]).
    pub threshold: Option<f64>,
    /// Timing sensor: standard deviation of each reported instant (s, in [0, 10]).
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
    /// `"stable"` or `"vertex-edge"`.
    Named(String),
    /// Explicit orientations (degrees).
    Degrees(Vec<f64>),
}

/// `[goal]`: which final orientations count as correct.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawGoal {
    /// Every exiting part counts as correctly oriented.
    #[serde(default)]
    pub any: bool,
    /// Named sets of target orientations; a part is correct if it matches any of them.
    #[serde(default)]
    pub sets: Vec<RawGoalSet>,
}

/// `[[goal.sets]]`: a named set of target orientations (degrees) with a tolerance (degrees).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawGoalSet {
    /// Name of the set in reports (default: its position).
    pub name: Option<String>,
    /// Target orientations (degrees, within ±360).
    pub orientations: Vec<f64>,
    /// Tolerance around each target (degrees, in [0, 180], default 5).
    pub tolerance: Option<f64>,
}

/// `[model]`: the contact model's fidelity and accuracy.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawModel {
    /// Contact-model fidelity (default exact).
    pub fidelity: Option<RawFidelity>,
    /// The map tier's grid (`fidelity = "map"` only): [θ0 base cells, d base cells, refinement
    /// depth].
    pub map_grid: Option<[u32; 3]>,
    /// Integration tolerance of the contact model (in [1e-10, 0.01], default 1e-6).
    pub tol: Option<f64>,
    /// Largest pin travel in contact, in units of a, before a part counts as jammed.
    pub max_travel: Option<f64>,
}

/// `[model] fidelity`: a contact-model fidelity, or `map`: the certified map tier over the exact
/// model (see `maps::tier`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RawFidelity {
    /// The tip model (docs/physics.md#fidelity-tiers).
    Tip,
    /// The ellipsoidal limit-surface model.
    Ellipsoid,
    /// The exact limit-surface model.
    Exact,
    /// The certified map tier over the exact model.
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
