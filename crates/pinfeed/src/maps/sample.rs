//! Sampling a configuration map: one pin pass per initial orientation θ0 on a regular grid over
//! [0°, 360°), for each contact parameter d (docs/physics.md#configuration-maps, thesis eq. 2-14: θf = f(θi, d; μc, pressure)).
//!
//! Every sample is an independent call of the pure contact model ([`push`], or [`push_fence`] for
//! a fence map) from the standard start ([`super::pass_start`], [`super::fence_pass_start`]). The (d, θ0) pairs are flattened into one list, computed with rayon and
//! collected in index order, so the result is the same bit for bit at any thread count.

use super::{MapError, MapSample, MapSettings};
use crate::geometry::{wrap_deg, Polygon};
use crate::mechanics::{push, push_fence, PartModel};
use rayon::prelude::*;

/// Largest number of θ0 samples per map (a step of 0.001°).
pub const MAX_SAMPLES: usize = 360_000;

/// The θ0 grid k·step, k = 0 … 360/step − 1 (degrees). The step must divide 360 into a whole number
/// of samples (to 1e-9 relative), so that the grid closes on itself around the circle.
pub fn theta_grid(step_deg: f64) -> Result<Vec<f64>, MapError> {
    if !(step_deg.is_finite() && step_deg > 0.0 && step_deg <= 360.0) {
        return Err(MapError::ThetaStep(step_deg));
    }
    let n = (360.0 / step_deg).round();
    if n < 1.0 || (n * step_deg - 360.0).abs() > 360.0 * 1e-9 {
        return Err(MapError::ThetaStepNotDividing(step_deg));
    }
    let n = n as usize;
    if n > MAX_SAMPLES {
        return Err(MapError::TooManySamples(n));
    }
    Ok((0..n).map(|k| k as f64 * step_deg).collect())
}

/// Largest |d| at which a pin of radius `pin_radius` (the polygon's units) can still touch the part.
pub fn max_contact_parameter(poly: &Polygon, pin_radius: f64) -> f64 {
    1.0 + pin_radius / poly.radius()
}

/// Check one contact parameter: finite and within reach of the part.
pub fn check_contact_parameter(poly: &Polygon, d: f64, pin_radius: f64) -> Result<(), MapError> {
    let limit = max_contact_parameter(poly, pin_radius);
    if !d.is_finite() || d.abs() > limit {
        return Err(MapError::ContactParameter { d, limit });
    }
    Ok(())
}

/// One pin (or fence) pass at (θ0, d) from the standard start. `band` is left empty.
pub fn sample_one(
    poly: &Polygon,
    model: &PartModel,
    theta0_deg: f64,
    d: f64,
    settings: &MapSettings,
) -> MapSample {
    sample_one_with(poly, model, theta0_deg, d, settings, None)
}

/// [`sample_one`], a still pin's pass answered by the certified map `tier` where it can (the
/// exact model elsewhere; see [`super::tier::push_with_map`]).
pub fn sample_one_with(
    poly: &Polygon,
    model: &PartModel,
    theta0_deg: f64,
    d: f64,
    settings: &MapSettings,
    tier: Option<&super::tier::TierMap>,
) -> MapSample {
    let (pin, contact) = (&settings.pin, &settings.contact);
    let (pose, start) = super::pass_start(poly, theta0_deg, d, pin.radius);
    let out = match settings.fence {
        None => match tier {
            Some(t) => super::tier::push_with_map(t, model, pose, start, pin.radius, contact).0,
            None => push(model, pose, start, pin, contact, None),
        },
        Some(f) => {
            let fence = super::fence_pass_start(poly, d, f.angle_deg, f.length, contact.mu_c)
                .with_tail(f.tail);
            push_fence(model, pose, &fence, contact, None)
        }
    };
    // Without contact the orientation is untouched by definition: θf = θ0 exactly.
    let theta_final_deg = if out.contact {
        wrap_deg(theta0_deg + out.rotation_rad.to_degrees())
    } else {
        theta0_deg
    };
    MapSample {
        theta0_deg,
        theta_final_deg,
        rotation_deg: out.rotation_rad.to_degrees(),
        contact: out.contact,
        com_final_y: out.pose_final.y,
        contact_length: out.contact_length,
        band: None,
        status: out.status,
    }
}

/// Sample the maps of all `ds` on the θ0 grid `grid` (degrees): `result[i][k]` is `(ds[i], grid[k])`.
/// Runs on the current rayon pool; the output does not depend on its size.
pub fn sample_maps(
    poly: &Polygon,
    model: &PartModel,
    ds: &[f64],
    grid: &[f64],
    settings: &MapSettings,
    tier: Option<&super::tier::TierMap>,
) -> Vec<Vec<MapSample>> {
    let n = grid.len();
    let flat: Vec<MapSample> = (0..ds.len() * n)
        .into_par_iter()
        .map(|i| sample_one_with(poly, model, grid[i % n], ds[i / n], settings, tier))
        .collect();
    let mut rows = Vec::with_capacity(ds.len());
    let mut it = flat.into_iter();
    for _ in ds {
        rows.push(it.by_ref().take(n).collect());
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_is_exact_multiples_and_closes() {
        let g = theta_grid(1.0).unwrap();
        assert_eq!(g.len(), 360);
        assert_eq!(g[359], 359.0);
        let g = theta_grid(0.1).unwrap();
        assert_eq!(g.len(), 3600);
        assert_eq!(g[7], 7.0 * 0.1);
        assert_eq!(theta_grid(360.0).unwrap(), vec![0.0]);
    }

    #[test]
    fn bad_steps_are_refused() {
        for s in [0.0, -1.0, f64::NAN, f64::INFINITY, 361.0] {
            assert!(matches!(theta_grid(s), Err(MapError::ThetaStep(_))), "{s}");
        }
        for s in [0.7, 7.0, 100.0] {
            assert!(
                matches!(theta_grid(s), Err(MapError::ThetaStepNotDividing(_))),
                "{s}"
            );
        }
        assert!(matches!(theta_grid(1e-4), Err(MapError::TooManySamples(_))));
    }

    #[test]
    fn contact_parameter_range_grows_with_the_pin() {
        let poly = crate::geometry::part_from_spec("tripoly1").unwrap();
        assert!(check_contact_parameter(&poly, 1.0, 0.0).is_ok());
        assert!(check_contact_parameter(&poly, -1.01, 0.0).is_err());
        assert!(check_contact_parameter(&poly, f64::NAN, 0.0).is_err());
        let a = poly.radius();
        assert!(check_contact_parameter(&poly, -1.2, 0.25 * a).is_ok());
    }
}
