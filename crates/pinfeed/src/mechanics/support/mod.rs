//! How a part's weight rests on the belt when it is drawn at random: the choice of support model
//! ([`SupportChoice`]: uniform pressure, a random tripod, a random smooth density) and the draw of
//! one support from it ([`draw_support`]). Monte Carlo studies draw one per sample, ensemble maps one
//! per member, validation and calibration one per synthetic part.
//!
//! * [`smooth`]: the random smooth pressure density (docs/physics.md#support).

pub mod smooth;

use super::Support;
use super::TripodError;
use crate::geometry::Polygon;
use crate::random::ChaCha8Rng;
use smooth::{random_smooth_support, SmoothSupportError};

/// Parameters of the random smooth pressure density (see [`smooth`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SmoothParams {
    /// Number of Gaussian bumps added to the uniform base pressure.
    pub bumps: usize,
    /// Bump standard deviation in units of the part's a.
    pub width: f64,
    /// Largest bump height relative to the base pressure.
    pub contrast: f64,
    /// Approximate number of support points.
    pub points: usize,
}

impl Default for SmoothParams {
    fn default() -> Self {
        SmoothParams {
            bumps: 3,
            width: 0.3,
            contrast: 2.0,
            points: 48,
        }
    }
}

/// How the part's weight rests on the belt in a sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SupportChoice {
    /// Uniform pressure over the footprint.
    Uniform,
    /// A random tripod per sample.
    Tripod,
    /// A random smooth density per sample.
    Smooth(SmoothParams),
}

impl SupportChoice {
    /// The choice in words, as reports print it (e.g. `uniform pressure`).
    pub fn describe(&self) -> String {
        match self {
            SupportChoice::Uniform => "uniform pressure".into(),
            SupportChoice::Tripod => "a random tripod per sample".into(),
            SupportChoice::Smooth(p) => format!(
                "a random smooth density per sample ({} bumps of width {} a, contrast {}, {} points)",
                p.bumps, p.width, p.contrast, p.points
            ),
        }
    }
}

/// Why a support could not be drawn ([`draw_support`]); prints the failed draw's message as it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum SupportDrawError {
    /// No random tripod carrying the centroid was found.
    #[error("{0}")]
    Tripod(TripodError),
    /// No random smooth density was found.
    #[error("{0}")]
    Smooth(SmoothSupportError),
}

impl From<TripodError> for SupportDrawError {
    fn from(e: TripodError) -> Self {
        SupportDrawError::Tripod(e)
    }
}

impl From<SmoothSupportError> for SupportDrawError {
    fn from(e: SmoothSupportError) -> Self {
        SupportDrawError::Smooth(e)
    }
}

/// The support of one sample on its (perturbed) polygon; smooth densities redrawn because their
/// tilt made the pressure negative are counted in `redraws`.
pub fn draw_support(
    polygon: &Polygon,
    choice: &SupportChoice,
    rng: &mut ChaCha8Rng,
    redraws: &mut u32,
) -> Result<Support, SupportDrawError> {
    Ok(match choice {
        SupportChoice::Uniform => Support::Uniform,
        SupportChoice::Tripod => Support::random_tripod(polygon, rng)?,
        SupportChoice::Smooth(params) => {
            let (s, n) = random_smooth_support(polygon, params, rng)?;
            *redraws += n;
            s
        }
    })
}
