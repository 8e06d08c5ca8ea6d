//! Configuration maps (thesis §2.17 and chapter 3; docs/physics.md#configuration-maps): initial orientation θ0 → final
//! orientation θf of a part after one pass of a pin at contact parameter d — or of a fence (docs/physics.md#fences,
//! [`MapFence`]; placed by [`fence_pass_start`]) — and what the thesis reads off them.
//!
//! * [`sample`]: θ0 on a regular grid over [0°, 360°), one contact per sample (pure, parallel,
//!   independent of the thread count), from the start convention of [`start`].
//! * [`bands`]: bands B_j of final angles (eq. 2-15/2-16, circular-aware), their mean, standard
//!   deviation and adjusted interval mean ± sd (eq. 3-2), and COM_j ranges (eq. 2-18).
//! * [`tier`]: the certified map tier — whole pin pushes tabulated over θ0 × d, interpolated where
//!   certified, the exact model elsewhere, cached on disk (`[model] fidelity = "map"`).
//! * [`runs`]: maximal circular runs of θ0 samples: the initial-angle sets K_j of each band
//!   (eq. 2-17, possibly several runs) and the no-contact intervals NC_j (eq. 3-1).
//!
//! A no-contact sample is one where the pin never touches the part (θf = θ0 by definition). NC
//! intervals are the maximal runs of consecutive no-contact samples on the θ0 grid (read
//! circularly); this is the thesis's grouping of eq. 3-1 with neighbours taken along the grid, so
//! the union of the NC intervals is exactly the set of no-contact samples, no more. Samples whose
//! contact ended with a non-ok status (e.g. the part still riding the pin at the travel limit) keep
//! the pose where the computation stopped, are grouped like the others and carry their status.
//!
//! Angles are degrees, wrapped to [0°, 360°); an interval [a, b] with b < a straddles 0°/360°.
//! Lengths (final centroid y, contact length) are in the part's units, belt frame.

pub mod arcs;
pub mod bands;
pub mod ensemble;
pub mod limits;
pub mod runs;
pub mod sample;
pub mod start;
pub mod tier;

pub use bands::{circular_clusters, find_bands};
pub use sample::{sample_maps, theta_grid};
pub use start::{fence_pass_start, pass_start};

use crate::geometry::Polygon;
use crate::mechanics::{ContactSettings, ContactStatus, Fidelity, PartModel, Pin};
use serde::{Serialize, Serializer};

/// Bad input to a map computation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MapError {
    /// Not a finite step in (0, 360] degrees (the value given).
    #[error("theta step must be a finite number of degrees in (0, 360], got {0}")]
    ThetaStep(f64),
    /// The step (degrees) does not divide 360.
    #[error("theta step {0}° does not divide 360° into a whole number of samples")]
    ThetaStepNotDividing(f64),
    /// The step gives more θ0 samples per map than allowed (the count).
    #[error("theta step gives {0} samples per map; at most {max} are allowed", max = sample::MAX_SAMPLES)]
    TooManySamples(usize),
    /// Not a finite threshold in (0, 360] degrees (the value given).
    #[error("band threshold must be a finite number of degrees in (0, 360], got {0}")]
    Threshold(f64),
    /// |d| is beyond the reach at which the pin can touch the part.
    #[error("contact parameter d = {d} is out of range: |d| must be at most {limit:.4} (beyond it the pin cannot touch the part)")]
    ContactParameter {
        /// The contact parameter given (units of a).
        d: f64,
        /// The largest |d| at which the pin touches (units of a).
        limit: f64,
    },
    /// The list of contact parameters is empty.
    #[error("no contact parameter d given")]
    NoContactParameter,
    /// The same contact parameter twice (the value).
    #[error("contact parameter d = {0} is given twice")]
    RepeatedContactParameter(f64),
    /// A fence angle not strictly between −90 and 90 degrees (the value).
    #[error("fence angle must lie strictly between -90 and 90 degrees, got {0}")]
    FenceAngle(f64),
    /// A fence length that is not positive (part units; the value).
    #[error("fence length must be a positive number (part units), got {0}")]
    FenceLength(f64),
    /// A fence tail radius outside [10⁻² a, 10³ a] (part units; the value).
    #[error("fence tail radius must lie in [{}, {}] (part units: 0.01a to 1000a, a = {}), got {}", crate::mechanics::limits::num(*lo), crate::mechanics::limits::num(*hi), crate::mechanics::limits::num(*a), crate::mechanics::limits::num(*value))]
    FenceTail {
        /// The smallest radius allowed.
        lo: f64,
        /// The largest radius allowed.
        hi: f64,
        /// The part's circumradius a.
        a: f64,
        /// The radius given.
        value: f64,
    },
}

/// A fence to map instead of a pin (docs/physics.md#fences): its friction is the settings' `mu_c`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MapFence {
    /// Angle from the belt direction (degrees, strictly between −90 and 90; positive fences deflect
    /// parts to the left).
    pub angle_deg: f64,
    /// Length in the part's units (default 20a).
    pub length: Option<f64>,
    /// Radius of the fence's curved tail in the part's units (None: no tail).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tail: Option<f64>,
}

/// What a map is computed with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapSettings {
    /// Spacing of the θ0 grid (degrees); must divide 360.
    pub theta_step_deg: f64,
    /// Band threshold T (degrees): neighbouring final angles at least T apart start a new band.
    pub threshold_deg: f64,
    /// The contact model's settings (fidelity, friction, tolerance).
    pub contact: ContactSettings,
    /// The pin (its radius, in part units).
    pub pin: Pin,
    /// A fence instead of the pin (`pin` is then unused; `contact.mu_c` is the fence friction).
    pub fence: Option<MapFence>,
}

impl MapSettings {
    /// A point pin with contact friction `mu_c` and otherwise default contact settings.
    pub fn point_pin(
        fidelity: Fidelity,
        mu_c: f64,
        theta_step_deg: f64,
        threshold_deg: f64,
    ) -> Self {
        MapSettings {
            theta_step_deg,
            threshold_deg,
            contact: ContactSettings {
                fidelity,
                mu_c,
                ..ContactSettings::default()
            },
            pin: Pin::point(),
            fence: None,
        }
    }
}

/// One sample of a map: a pin pass at one initial orientation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MapSample {
    /// Initial orientation θ0 (degrees, on the grid).
    pub theta0_deg: f64,
    /// Final orientation θf (degrees, [0, 360)); exactly θ0 when there is no contact.
    pub theta_final_deg: f64,
    /// Signed total rotation (degrees, not wrapped).
    pub rotation_deg: f64,
    /// Did the pin touch the part?
    pub contact: bool,
    /// Final centroid y (belt frame, part units; 0 without contact).
    pub com_final_y: f64,
    /// Pin travel in contact (part units).
    pub contact_length: f64,
    /// Index of the band holding this sample (None for no contact).
    pub band: Option<usize>,
    /// How the contact computation ended.
    #[serde(serialize_with = "status_name")]
    pub status: ContactStatus,
}

fn status_name<S: Serializer>(status: &ContactStatus, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(status.name())
}

/// One band B_j with its statistics (see [`bands`] for the definitions).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Band {
    /// Lower end of the final-angle arc (degrees; max < min when it straddles 0°).
    pub final_min_deg: f64,
    /// Upper end of the final-angle arc (degrees).
    pub final_max_deg: f64,
    /// Arc length from min to max (degrees).
    pub width_deg: f64,
    /// Mean final angle of the band (degrees, circular).
    pub mean_deg: f64,
    /// Standard deviation of the band's final angles (degrees).
    pub sd_deg: f64,
    /// Lower end of the thesis's adjusted band, mean − sd (eq. 3-2; degrees, wrapped).
    pub adjusted_min_deg: f64,
    /// Upper end of the adjusted band, mean + sd (degrees, wrapped).
    pub adjusted_max_deg: f64,
    /// K_j: the θ0 runs feeding this band, [first, last] (degrees, on the grid).
    pub initial_ranges_deg: Vec<[f64; 2]>,
    /// COM_j: smallest final centroid y (part units).
    pub com_y_min: f64,
    /// Largest final centroid y (part units).
    pub com_y_max: f64,
    /// Number of samples in the band.
    pub samples: usize,
}

/// The configuration map for one contact parameter d.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConfigurationMap {
    /// The contact parameter: the pin's lateral offset from the centroid's line (units of a).
    pub d: f64,
    /// One sample per grid θ0, in grid order.
    pub samples: Vec<MapSample>,
    /// Bands ordered by their lower end.
    pub bands: Vec<Band>,
    /// NC_j: runs of no-contact θ0, [first, last] (degrees, on the grid).
    pub no_contact_ranges_deg: Vec<[f64; 2]>,
    /// The fence of a fence map (its `d` is then 0: a fence map has no contact parameter).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fence: Option<MapFence>,
}

impl ConfigurationMap {
    /// How the map is labelled in tables: `+0.3` for a pin map, `fence 45°` (`fence 45°:3`
    /// with a length) for a fence map.
    pub fn label(&self) -> String {
        match self.fence {
            None => format!("{:+}", self.d),
            Some(f) => {
                let fence = match f.length {
                    None => format!("fence {}°", f.angle_deg),
                    Some(l) => format!("fence {}°:{l}", f.angle_deg),
                };
                match f.tail {
                    None => fence,
                    Some(r) => format!("{fence} tail {r}"),
                }
            }
        }
    }
}

impl ConfigurationMap {
    /// Derive bands and NC intervals from a full grid of samples (in grid order).
    pub fn from_samples(
        d: f64,
        mut samples: Vec<MapSample>,
        threshold_deg: f64,
    ) -> Result<ConfigurationMap, MapError> {
        check_threshold(threshold_deg)?;
        let (bands, band_of) = find_bands(&samples, threshold_deg);
        for (s, b) in samples.iter_mut().zip(band_of) {
            s.band = b;
        }
        let grid: Vec<f64> = samples.iter().map(|s| s.theta0_deg).collect();
        let no_contact: Vec<bool> = samples.iter().map(|s| !s.contact).collect();
        let no_contact_ranges_deg = runs::circular_ranges(&no_contact, &grid);
        Ok(ConfigurationMap {
            d,
            samples,
            bands,
            no_contact_ranges_deg,
            fence: None,
        })
    }

    /// Number of samples whose contact computation did not end `ok`.
    pub fn non_ok_samples(&self) -> usize {
        self.samples.iter().filter(|s| !s.status.is_ok()).count()
    }
}

fn check_threshold(threshold_deg: f64) -> Result<(), MapError> {
    if !(threshold_deg.is_finite() && threshold_deg > 0.0 && threshold_deg <= 360.0) {
        return Err(MapError::Threshold(threshold_deg));
    }
    Ok(())
}

/// Compute the configuration maps of `poly` (compiled as `model`) for each d in `ds`, in order.
/// Validates every input before any contact is computed. Runs on the current rayon pool.
pub fn compute_maps(
    poly: &Polygon,
    model: &PartModel,
    ds: &[f64],
    settings: &MapSettings,
) -> Result<Vec<ConfigurationMap>, MapError> {
    compute_maps_with(poly, model, ds, settings, None)
}

/// [`compute_maps`] with a still pin's passes answered by the certified map `tier` where it can
/// (`pinfeed map --model map`).
pub fn compute_maps_with(
    poly: &Polygon,
    model: &PartModel,
    ds: &[f64],
    settings: &MapSettings,
    tier: Option<&tier::TierMap>,
) -> Result<Vec<ConfigurationMap>, MapError> {
    if ds.is_empty() {
        return Err(MapError::NoContactParameter);
    }
    check_threshold(settings.threshold_deg)?;
    if let Some(f) = settings.fence {
        if !(f.angle_deg.is_finite() && f.angle_deg.abs() < 90.0) {
            return Err(MapError::FenceAngle(f.angle_deg));
        }
        if let Some(l) = f.length {
            if !(l.is_finite() && l > 0.0) {
                return Err(MapError::FenceLength(l));
            }
        }
        if let Some(r) = f.tail {
            let a = poly.radius();
            let (lo, hi) = crate::mechanics::limits::FENCE_TAIL_RADIUS_A;
            if !(r >= lo * a && r <= hi * a) {
                return Err(MapError::FenceTail {
                    lo: lo * a,
                    hi: hi * a,
                    a,
                    value: r,
                });
            }
        }
    }
    for (i, &d) in ds.iter().enumerate() {
        sample::check_contact_parameter(poly, d, settings.pin.radius)?;
        if ds[..i].contains(&d) {
            return Err(MapError::RepeatedContactParameter(d));
        }
    }
    let grid = theta_grid(settings.theta_step_deg)?;
    let rows = sample_maps(poly, model, ds, &grid, settings, tier);
    ds.iter()
        .zip(rows)
        .map(|(&d, row)| {
            let mut m = ConfigurationMap::from_samples(d, row, settings.threshold_deg)?;
            m.fence = settings.fence;
            Ok(m)
        })
        .collect()
}
