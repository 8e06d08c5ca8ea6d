//! The study file as written: serde structs mirroring the TOML (docs/study-format.md), each with
//! `deny_unknown_fields` so a misspelt key is a located error. Values are checked in
//! [`super::compile`]; this layer only fixes names and types.
//!
//! ```toml
//! scenario = "../scenarios/quickstart.toml"   # relative to this file
//! seed = 1
//! samples = 1000                              # per sweep point
//!
//! [uncertain.mu_c]                            # one table per uncertain parameter
//! distribution = "uniform"
//! min = 0.3
//! max = 0.7
//!
//! [uncertain.support]
//! model = "tripod"
//!
//! [[sweep]]
//! parameter = "shape.sd"
//! values = [0.0, 0.0002, 0.0005]
//! ```

use serde::Deserialize;

/// The whole study file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawStudy {
    /// Names the report folder (default: the file name without `.toml`).
    pub name: Option<String>,
    /// The scenario file, relative to the study file.
    pub scenario: String,
    /// Seed of the study's random streams (default 1).
    pub seed: Option<u64>,
    /// Samples per sweep point (default 1000).
    pub samples: Option<u64>,
    /// `[uncertain]`: the uncertain parameters (none by default).
    #[serde(default)]
    pub uncertain: RawUncertain,
    /// `[[sweep]]`: the swept parameters (none by default).
    #[serde(default)]
    pub sweep: Vec<RawSweep>,
}

/// `[uncertain]`: every parameter is optional; a missing one keeps the scenario's nominal value.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawUncertain {
    /// Pin–part friction μc (its value; one draw per sample, used at every pin).
    pub mu_c: Option<RawDistribution>,
    /// Belt speed (m/s, its value).
    pub belt_speed: Option<RawDistribution>,
    /// Error added to each coordinate of each vertex of the part (m).
    pub shape: Option<RawDistribution>,
    /// Error added to each pin's x (m).
    pub pin_x: Option<RawDistribution>,
    /// Error added to each pin's y (m).
    pub pin_y: Option<RawDistribution>,
    /// Error added to each pin's radius (m).
    pub pin_radius: Option<RawDistribution>,
    /// Error added to the entry orientation drawn by the scenario's feed (degrees).
    pub pose_theta: Option<RawDistribution>,
    /// Error added to the entry lateral offset drawn by the scenario's feed (m).
    pub pose_y: Option<RawDistribution>,
    /// How the part's weight rests on the belt.
    pub support: Option<RawSupport>,
    /// Factor multiplying every sensor's white-noise σ (force and torque) and timing jitter.
    pub sensor_noise: Option<RawDistribution>,
    /// Added to every sensor's force bias (N, each force channel).
    pub sensor_bias: Option<RawDistribution>,
    /// Every sensor's timing threshold (N, its value).
    pub sensor_threshold: Option<RawDistribution>,
    /// Added to every sensor's timing jitter (s).
    pub sensor_jitter: Option<RawDistribution>,
    /// Fence–part friction μf (its value; one draw per sample, used at every fence).
    pub fence_mu_f: Option<RawDistribution>,
    /// Error added to each fence's angle (degrees), drawn per fence.
    pub fence_angle: Option<RawDistribution>,
    /// Errors added to each fence's upstream end, x and y (m), drawn per fence.
    pub fence_x: Option<RawDistribution>,
    /// Error added to each fence's upstream end y (m), drawn per fence.
    pub fence_y: Option<RawDistribution>,
    /// Error added to each fence's length (m), drawn per fence.
    pub fence_length: Option<RawDistribution>,
    /// Factor on each dynamic pin's speed (a moving pin's speed limit; a retractable pin's
    /// raise and lower rates), drawn per pin.
    pub actuator_speed: Option<RawDistribution>,
    /// Factor on each moving pin's acceleration limit, drawn per pin.
    pub actuator_accel: Option<RawDistribution>,
    /// Error added to each moving pin's settle time (s), drawn per pin.
    pub actuator_settle: Option<RawDistribution>,
    /// Error added to the controller's latency (s), one draw per sample.
    pub controller_latency: Option<RawDistribution>,
}

/// Kinds of distribution.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DistributionKind {
    /// Always `value`.
    Fixed,
    /// Uniform on [min, max].
    Uniform,
    /// Normal with `mean` and `sd`, optionally truncated to [min, max].
    Normal,
    /// Triangular on [min, max] with its peak at `mode`.
    Triangular,
}

/// A distribution of one number: `fixed` (value), `uniform` (min, max), `normal` (mean, sd,
/// optional min/max truncation), `triangular` (min, mode, max).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDistribution {
    /// The kind of distribution (required).
    pub distribution: Option<DistributionKind>,
    /// `fixed`: the value.
    pub value: Option<f64>,
    /// `uniform`, `triangular`: the lower end; `normal`: optional lower truncation.
    pub min: Option<f64>,
    /// `uniform`, `triangular`: the upper end; `normal`: optional upper truncation.
    pub max: Option<f64>,
    /// `normal`: the mean.
    pub mean: Option<f64>,
    /// `normal`: the standard deviation.
    pub sd: Option<f64>,
    /// `triangular`: the peak, between `min` and `max`.
    pub mode: Option<f64>,
    /// Fence parameters only: the fences (by name) it perturbs (default: every fence).
    pub fences: Option<Vec<String>>,
    /// Actuator parameters only: the dynamic pins (by name) it perturbs (default: every one the
    /// parameter applies to).
    pub pins: Option<Vec<String>>,
}

/// Support models.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SupportModel {
    /// Uniform pressure over the footprint.
    Uniform,
    /// A random tripod per sample (docs/physics.md#support).
    Tripod,
    /// A random smooth pressure density per sample (see [`crate::mechanics::support::smooth`]).
    Smooth,
}

/// `[uncertain.support]`.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSupport {
    /// The support model (required).
    pub model: Option<SupportModel>,
    /// Smooth: number of Gaussian bumps (default 3).
    pub bumps: Option<f64>,
    /// Smooth: bump width (standard deviation) in units of the part's a (default 0.3).
    pub width: Option<f64>,
    /// Smooth: largest bump height relative to the base pressure (default 2).
    pub contrast: Option<f64>,
    /// Smooth: number of support points (default 48).
    pub points: Option<f64>,
}

/// `[[sweep]]`: one swept parameter. `parameter` is `NAME` (the parameter fixed at each value) or
/// `NAME.FIELD` (one field of its distribution, e.g. `shape.sd`, `mu_c.max`, `support.width`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSweep {
    /// `NAME` or `NAME.FIELD` of the swept parameter.
    pub parameter: String,
    /// The values, listed (or give `from`, `to` and `steps`).
    pub values: Option<Vec<f64>>,
    /// First value of an evenly spaced sweep.
    pub from: Option<f64>,
    /// Last value of an evenly spaced sweep (included).
    pub to: Option<f64>,
    /// Number of values of an evenly spaced sweep, ends included.
    pub steps: Option<u32>,
}
