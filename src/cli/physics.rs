//! The physics flags of one pin pass that `contact` and `map` share: one definition, so each has
//! one meaning, one unit, one default and one help text in both commands.

use anyhow::{bail, Result};
use clap::Args;
use pinfeed::contact_case::{Case, ModelChoice};
use pinfeed::mechanics::{ContactSettings, Fidelity};
use std::path::PathBuf;

/// The curved tail of `--fence` (both commands have a `--fence` flag of their own).
#[derive(Debug, Clone, Args)]
pub struct TailArgs {
    /// End the fence in a curved tail of this radius (part units, 0.01a to 1000a): a circular arc
    /// tangent to the fence that turns it parallel to the belt (docs/physics.md#fences).
    #[arg(
        long,
        value_name = "RADIUS",
        requires = "fence",
        allow_hyphen_values = true
    )]
    pub tail: Option<f64>,
}

/// Friction, fidelity (with the map tier's cache and grid), pin radius, support and tolerance.
#[derive(Debug, Clone, Args)]
pub struct PushArgs {
    /// Pin–part friction coefficient μc, in [0, 5].
    #[arg(long, default_value_t = 0.5, allow_hyphen_values = true)]
    pub mu_c: f64,
    /// Fidelity: exact, ellipsoid or tip; or map (the certified map tier over exact, still pins
    /// only).
    #[arg(long, default_value = "exact")]
    pub model: ModelChoice,
    /// With --model map: the folder of the map cache files (default $XDG_CACHE_HOME/pinfeed/maps
    /// or ~/.cache/pinfeed/maps).
    #[arg(long, value_name = "DIR", env = "PINFEED_CACHE")]
    pub cache_dir: Option<PathBuf>,
    /// With --model map: the map's grid, θ0 base cells, d base cells, refinement depth
    /// (default 36,12,4).
    #[arg(long, value_name = "T,D,DEPTH")]
    pub map_grid: Option<String>,
    /// Pin radius in part units (the coordinates the part is given in), as in every command;
    /// 0: point pin.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub pin_radius: f64,
    /// Support: uniform or tripod:SEED.
    #[arg(long, default_value = "uniform")]
    pub support: String,
    /// Integration tolerance (absolute, radians / units of a, per step).
    #[arg(long, default_value_t = 1e-6, allow_hyphen_values = true)]
    pub tol: f64,
}

impl PushArgs {
    /// The fidelity of `--model` where the map tier does not apply (`what`: where, for the
    /// message).
    pub fn fidelity(&self, what: &str) -> Result<Fidelity> {
        match self.model {
            ModelChoice::Model(f) => Ok(f),
            ModelChoice::Map => bail!("--model map: {what}; use exact, ellipsoid or tip"),
        }
    }

    /// A still-pin case of `part` with these physics and fidelity `model`, at θ0 = 0 and d = 0,
    /// with the default μs and no fence (the caller sets what its command adds).
    pub fn case(&self, part: String, model: Fidelity) -> Case {
        Case {
            part,
            theta0_deg: 0.0,
            d: 0.0,
            mu_c: self.mu_c,
            mu_s: ContactSettings::default().mu_s,
            model,
            pin_radius: self.pin_radius,
            pin_speed: 0.0,
            pin_stop: None,
            pin_stop_after_touch: None,
            support: self.support.clone(),
            tol: self.tol,
            fence: None,
            fence_tail: None,
        }
    }
}
