//! [`Support`]: how the belt carries the part's weight (uniform pressure or weighted points, e.g. a
//! random tripod), its command-line spelling, and the limit-surface data a [`PartModel`] compiles
//! from it.
//!
//! [`PartModel`]: super::PartModel

use crate::geometry::{Polygon, Vec2};
use crate::mechanics::limit_surface::points::PointSupport;
use crate::mechanics::limit_surface::uniform::UniformSurface;

/// How the part's weight is carried by the belt (docs/physics.md#support).
#[derive(Debug, Clone, PartialEq)]
pub enum Support {
    /// Uniform pressure over the footprint (the thesis's assumption).
    Uniform,
    /// Weighted support points in the part frame of the *caller's* units (e.g. a tripod).
    Points {
        /// The support points, part frame (centroid origin, part axes), caller's length units.
        points: Vec<Vec2>,
        /// The share of the load each point carries, one per point: non-negative (normalised to
        /// a total of 1 when the model is compiled).
        weights: Vec<f64>,
    },
}

impl Support {
    /// A random tripod (docs/physics.md#support): three points drawn uniformly inside the part whose triangle
    /// contains the centroid; each carries the centroid's barycentric weight (static equilibrium).
    /// Points are in the polygon's part frame (centroid origin). Each weight is at least 2%, so the
    /// tripod is never degenerate.
    pub fn random_tripod(poly: &Polygon, rng: &mut impl rand::Rng) -> Result<Support, TripodError> {
        use rand::RngExt;
        let v = poly.vertices();
        let (mut lo, mut hi) = (v[0], v[0]);
        for p in v {
            lo = Vec2::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Vec2::new(hi.x.max(p.x), hi.y.max(p.y));
        }
        let draw = |rng: &mut dyn FnMut() -> f64| -> Option<Vec2> {
            for _ in 0..10_000 {
                let p = Vec2::new(lo.x + (hi.x - lo.x) * rng(), lo.y + (hi.y - lo.y) * rng());
                if poly.contains(p) {
                    return Some(p);
                }
            }
            None
        };
        let mut uni = || rng.random::<f64>();
        for _ in 0..100_000 {
            let (Some(a), Some(b), Some(c)) = (draw(&mut uni), draw(&mut uni), draw(&mut uni))
            else {
                break;
            };
            let area = (b - a).cross(c - a);
            if area.abs() < 1e-12 {
                continue;
            }
            // Barycentric coordinates of the centroid (origin).
            let o = Vec2::ZERO;
            let wa = (b - o).cross(c - o) / area;
            let wb = (c - o).cross(a - o) / area;
            let wc = (a - o).cross(b - o) / area;
            if wa >= 0.02 && wb >= 0.02 && wc >= 0.02 {
                return Ok(Support::Points {
                    points: vec![a, b, c],
                    weights: vec![wa, wb, wc],
                });
            }
        }
        Err(TripodError)
    }

    /// Parse a support specification: `uniform` or `tripod:SEED`.
    pub fn parse(spec: &str, poly: &Polygon) -> Result<Support, SupportSpecError> {
        let s = spec.trim();
        if s == "uniform" {
            return Ok(Support::Uniform);
        }
        if let Some(seed) = s.strip_prefix("tripod:") {
            let seed: u64 = seed.trim().parse().map_err(|_| SupportSpecError::Seed {
                spec: s.to_string(),
            })?;
            let mut rng = crate::random::stream(seed, 0);
            return Support::random_tripod(poly, &mut rng).map_err(SupportSpecError::Tripod);
        }
        Err(SupportSpecError::Unknown {
            spec: s.to_string(),
        })
    }
}

/// Why a support specification is refused ([`Support::parse`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SupportSpecError {
    /// `tripod:SEED` whose seed is not a whole number.
    #[error("support '{spec}': the tripod seed must be a whole number")]
    Seed {
        /// The specification (trimmed).
        spec: String,
    },
    /// Neither `uniform` nor `tripod:SEED`.
    #[error("unknown support '{spec}'; expected 'uniform' or 'tripod:SEED'")]
    Unknown {
        /// The specification (trimmed).
        spec: String,
    },
    /// No tripod could be drawn ([`Support::random_tripod`]).
    #[error(transparent)]
    Tripod(#[from] TripodError),
}

/// [`Support::random_tripod`] found no tripod: the part is too thin (or its centroid too close
/// to its outline) for three points inside it whose triangle carries the centroid with every
/// weight at least 2%.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("could not draw a tripod inside the part that carries its centroid")]
pub struct TripodError;

/// A support compiled for the normalised part (a = 1): the data its dissipation is evaluated from.
#[derive(Clone)]
pub(super) enum SupportData {
    Uniform(UniformSurface),
    Points(PointSupport),
}

impl SupportData {
    /// Compile `support` for the part `unit` (the caller's polygon scaled by `1/scale`).
    pub(super) fn new(
        unit: &Polygon,
        scale: f64,
        support: &Support,
    ) -> Result<SupportData, crate::mechanics::limit_surface::points::PointSupportError> {
        Ok(match support {
            Support::Uniform => SupportData::Uniform(UniformSurface::new(unit)),
            Support::Points { points, weights } => {
                let pts: Vec<Vec2> = points.iter().map(|&p| p / scale).collect();
                SupportData::Points(PointSupport::new(pts, weights.clone())?)
            }
        })
    }

    /// m_max / f_max of the ellipsoid approximation (normalised units).
    pub(super) fn ellipsoid_c(&self) -> f64 {
        match self {
            SupportData::Uniform(u) => u.ellipsoid_c(),
            SupportData::Points(p) => p.ellipsoid_c(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;

    #[test]
    fn a_random_tripod_carries_the_centroid() {
        let poly = part_from_spec("tripoly2").unwrap();
        let Support::Points { points, weights } = Support::parse("tripod:7", &poly).unwrap() else {
            panic!("a tripod has points");
        };
        assert_eq!(points.len(), 3);
        assert!(points.iter().all(|&p| poly.contains(p)));
        assert!(weights.iter().all(|&w| w >= 0.02));
        assert!((weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let centre = points
            .iter()
            .zip(&weights)
            .fold(Vec2::ZERO, |c, (&p, &w)| c + p * w);
        assert!(centre.norm() < 1e-12);
    }

    #[test]
    fn specifications_parse() {
        let poly = part_from_spec("square").unwrap();
        assert_eq!(Support::parse(" uniform ", &poly), Ok(Support::Uniform));
        assert_eq!(
            Support::parse("tripod:3", &poly),
            Support::parse("tripod: 3", &poly)
        );
        assert!(Support::parse("tripod:x", &poly).is_err());
        assert!(Support::parse("points", &poly).is_err());
    }
}
