//! A random smooth pressure density under the part, as weighted support points (docs/physics.md#support; the contact model's point support treats each point
//! as a small patch).
//!
//! Construction, in the part frame (centroid at the origin, metres):
//! 1. **Points**: the centres of a square lattice over the polygon's bounding box that fall inside
//!    the polygon, with spacing h = √(area / N) for the requested N (refined until at least 12 points
//!    are inside). Each point stands for one lattice cell of equal area.
//! 2. **Smooth random field**: p(x) = 1 + Σₖ aₖ exp(−|x − cₖ|² / (2 s²)), K bumps with centres cₖ
//!    uniform inside the polygon, heights aₖ uniform in [0, contrast] and width s = width·a.
//! 3. **Equilibrium**: a rigid part resting on a flat belt is in moment balance, so its centre of
//!    pressure lies under the centroid. The field is multiplied by the plane 1 + g·x that puts it
//!    there: g = −M⁻¹ m with m = Σ pᵢ xᵢ and M = Σ pᵢ xᵢ xᵢᵀ (exact for the discrete points). A
//!    plane is what a slightly tilted contact would add, so the density stays smooth. If the tilted
//!    density would fall below 5% of its mean anywhere, the bumps are redrawn (counted).

use crate::geometry::{Polygon, Vec2};
use crate::mechanics::Support;
use rand::RngExt;

use super::SmoothParams;

/// Lower-left and upper-right corners of the polygon's bounding box.
fn bounding_box(poly: &Polygon) -> (Vec2, Vec2) {
    let v = poly.vertices();
    v.iter().fold((v[0], v[0]), |(lo, hi), p| {
        (
            Vec2::new(lo.x.min(p.x), lo.y.min(p.y)),
            Vec2::new(hi.x.max(p.x), hi.y.max(p.y)),
        )
    })
}

/// Lattice points inside the polygon (part frame), about `n` of them.
pub fn lattice_points(poly: &Polygon, n: usize) -> Vec<Vec2> {
    let (lo, hi) = bounding_box(poly);
    let mut h = (poly.area() / n.max(1) as f64).sqrt();
    loop {
        let nx = ((hi.x - lo.x) / h).ceil().max(1.0) as usize;
        let ny = ((hi.y - lo.y) / h).ceil().max(1.0) as usize;
        // Centre the lattice on the bounding box.
        let x0 = 0.5 * (lo.x + hi.x) - 0.5 * (nx as f64 - 1.0) * h;
        let y0 = 0.5 * (lo.y + hi.y) - 0.5 * (ny as f64 - 1.0) * h;
        let mut pts = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let p = Vec2::new(x0 + i as f64 * h, y0 + j as f64 * h);
                if poly.contains(p) {
                    pts.push(p);
                }
            }
        }
        if pts.len() >= 12 || h < 1e-6 * poly.radius() {
            return pts;
        }
        h *= 0.8;
    }
}

fn point_inside(poly: &Polygon, rng: &mut impl rand::Rng) -> Option<Vec2> {
    let (lo, hi) = bounding_box(poly);
    for _ in 0..10_000 {
        let p = Vec2::new(
            lo.x + (hi.x - lo.x) * rng.random::<f64>(),
            lo.y + (hi.y - lo.y) * rng.random::<f64>(),
        );
        if poly.contains(p) {
            return Some(p);
        }
    }
    None
}

/// Why no smooth random support could be drawn ([`random_smooth_support`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum SmoothSupportError {
    /// Fewer than three lattice points fit inside the part.
    #[error("the part is too thin for a lattice of support points")]
    TooThin,
    /// No point inside the part was found for a bump's centre.
    #[error("could not place a pressure bump inside the part")]
    Bump,
    /// The support points lie on a line, so no tilt centres the pressure.
    #[error("the support points are collinear")]
    Collinear,
    /// Every density drawn needed a tilt that made the pressure negative somewhere.
    #[error("100 smooth densities in a row needed a tilt that made the pressure negative; lower support.contrast or widen support.width")]
    Negative,
}

/// Draw a smooth random support. Returns the support and the number of redraws.
pub fn random_smooth_support(
    poly: &Polygon,
    params: &SmoothParams,
    rng: &mut impl rand::Rng,
) -> Result<(Support, u32), SmoothSupportError> {
    let points = lattice_points(poly, params.points);
    if points.len() < 3 {
        return Err(SmoothSupportError::TooThin);
    }
    let s = params.width * poly.radius();
    for redraws in 0..100u32 {
        let mut bumps = Vec::with_capacity(params.bumps);
        for _ in 0..params.bumps {
            let c = point_inside(poly, rng).ok_or(SmoothSupportError::Bump)?;
            bumps.push((c, params.contrast * rng.random::<f64>()));
        }
        let field: Vec<f64> = points
            .iter()
            .map(|&x| {
                1.0 + bumps
                    .iter()
                    .map(|&(c, a)| a * (-(x - c).norm2() / (2.0 * s * s)).exp())
                    .sum::<f64>()
            })
            .collect();
        // Tilt g = −M⁻¹ m puts the centre of pressure on the centroid.
        let (mut mx, mut my, mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (x, &p) in points.iter().zip(&field) {
            mx += p * x.x;
            my += p * x.y;
            sxx += p * x.x * x.x;
            sxy += p * x.x * x.y;
            syy += p * x.y * x.y;
        }
        let det = sxx * syy - sxy * sxy;
        if det.abs() <= 1e-300 {
            return Err(SmoothSupportError::Collinear);
        }
        let gx = -(syy * mx - sxy * my) / det;
        let gy = -(-sxy * mx + sxx * my) / det;
        let weights: Vec<f64> = points
            .iter()
            .zip(&field)
            .map(|(x, &p)| p * (1.0 + gx * x.x + gy * x.y))
            .collect();
        let mean = weights.iter().sum::<f64>() / weights.len() as f64;
        if weights.iter().all(|&w| w >= 0.05 * mean) {
            return Ok((
                Support::Points {
                    points: points.clone(),
                    weights,
                },
                redraws,
            ));
        }
    }
    Err(SmoothSupportError::Negative)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;
    use crate::random::stream;

    #[test]
    fn centre_of_pressure_is_the_centroid_and_weights_positive() {
        for name in ["tripoly2", "lshape", "square"] {
            let poly = part_from_spec(name).unwrap();
            for i in 0..20 {
                let (sup, _) =
                    random_smooth_support(&poly, &SmoothParams::default(), &mut stream(9, i))
                        .unwrap();
                let Support::Points { points, weights } = sup else {
                    panic!("points expected")
                };
                assert!(points.len() >= 12, "{name}: {}", points.len());
                let total: f64 = weights.iter().sum();
                let cx: f64 = points.iter().zip(&weights).map(|(p, w)| p.x * w).sum();
                let cy: f64 = points.iter().zip(&weights).map(|(p, w)| p.y * w).sum();
                assert!((cx / total).abs() < 1e-12 && (cy / total).abs() < 1e-12);
                assert!(weights.iter().all(|&w| w > 0.0));
                assert!(points.iter().all(|&p| poly.contains(p)));
            }
        }
    }

    #[test]
    fn densities_differ_between_samples() {
        let poly = part_from_spec("tripoly2").unwrap();
        let p = SmoothParams::default();
        let a = random_smooth_support(&poly, &p, &mut stream(1, 0)).unwrap();
        let b = random_smooth_support(&poly, &p, &mut stream(1, 1)).unwrap();
        let c = random_smooth_support(&poly, &p, &mut stream(1, 0)).unwrap();
        assert_ne!(a.0, b.0);
        assert_eq!(a.0, c.0);
    }
}
