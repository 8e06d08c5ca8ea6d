//! Limit surface of a support by N weighted points (docs/physics.md#support; a tripod is the case N = 3 with barycentric loads).
//!
//! Part frame, centroid at the origin; weights are the normalised loads (sum 1, μs = 1). For a
//! twist ξ = [vx, vy, ω] the point x_i slides at u_i = v + ω ẑ×x_i.
//!
//! Ideal points make D non-differentiable wherever the centre of rotation sits on a loaded point
//! (the limit surface has facets, and at such a pivot the contact force is indeterminate). Real
//! supports are small contact patches, so each point is modelled as a uniform disc patch of radius
//! ε = 1e-3 × (largest |x_i|): its dissipation is √(|u_i|² + (c ω)²) with c = 2ε/3, exact when the
//! patch spins about its own centre (the mean distance over a disc is 2ε/3) and within O(ε²ω²/|u|)
//! of |u_i| otherwise. Then, with g_i = (u_i, c ω) and A_i ξ = g_i,
//!
//! * D(ξ) = Σ w_i |g_i|,
//! * ∇D(ξ) = Σ w_i A_iᵀ ĝ_i, A_iᵀ(a, b, e) = (a, b, x_i b − y_i a + c e) (the load on the part is −∇D),
//! * H(ξ) = Σ w_i A_iᵀ (I − ĝ_i ĝ_iᵀ) A_i / |g_i|,
//!
//! smooth and convex for every ξ ≠ 0, so the same Newton solver serves uniform and point supports.
//! Results differ from ideal points by O(ε) in the pivoting phases and not at all elsewhere.

use super::Dissipation;
use crate::geometry::Vec2;

/// A support by weighted points in the part frame.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSupport {
    /// Support points, part frame (centroid at the origin).
    pub points: Vec<Vec2>,
    /// Normalised loads: non-negative, summing to 1.
    pub weights: Vec<f64>,
    /// Effective spin radius c = 2ε/3 of each contact patch (see the module docs).
    pub spin_radius: f64,
}

/// Why a point support is refused ([`PointSupport::new`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PointSupportError {
    /// No points.
    #[error("a point support needs at least one point")]
    Empty,
    /// Not one weight per point.
    #[error("{points} support points but {weights} weights")]
    Lengths {
        /// Number of points.
        points: usize,
        /// Number of weights.
        weights: usize,
    },
    /// A point with a non-finite coordinate.
    #[error("support point {index} ({x}, {y}) is not finite")]
    Point {
        /// Index of the point.
        index: usize,
        /// Its x coordinate.
        x: f64,
        /// Its y coordinate.
        y: f64,
    },
    /// A negative or non-finite weight.
    #[error("support weight {index} is {weight}; weights must be finite and non-negative")]
    Weight {
        /// Index of the weight.
        index: usize,
        /// Its value.
        weight: f64,
    },
    /// The weights sum to zero (or to a non-finite total).
    #[error("support weights sum to {total}; at least one must be positive (and the sum finite)")]
    Total {
        /// The sum of the weights.
        total: f64,
    },
}

/// Patch radius as a fraction of the largest support-point radius.
pub const PATCH_FRACTION: f64 = 1e-3;

impl PointSupport {
    /// Build from points and non-negative loads (any positive total; they are normalised to sum 1).
    /// Rejects an empty set, mismatched lengths, non-finite points, and negative, non-finite or
    /// all-zero weights.
    pub fn new(points: Vec<Vec2>, weights: Vec<f64>) -> Result<Self, PointSupportError> {
        if points.is_empty() {
            return Err(PointSupportError::Empty);
        }
        if points.len() != weights.len() {
            return Err(PointSupportError::Lengths {
                points: points.len(),
                weights: weights.len(),
            });
        }
        if let Some(i) = points.iter().position(|p| !p.is_finite()) {
            return Err(PointSupportError::Point {
                index: i,
                x: points[i].x,
                y: points[i].y,
            });
        }
        if let Some(i) = weights.iter().position(|w| !w.is_finite() || *w < 0.0) {
            return Err(PointSupportError::Weight {
                index: i,
                weight: weights[i],
            });
        }
        let total: f64 = weights.iter().sum();
        if total <= 0.0 || !total.is_finite() {
            return Err(PointSupportError::Total { total });
        }
        let weights = weights.into_iter().map(|w| w / total).collect();
        let reach = points.iter().map(|p| p.norm()).fold(0.0, f64::max);
        let eps = PATCH_FRACTION * if reach > 0.0 { reach } else { 1.0 };
        Ok(PointSupport {
            points,
            weights,
            spin_radius: 2.0 * eps / 3.0,
        })
    }

    /// D, ∇D and (if `hessian`) H at twist ξ = [vx, vy, ω] (part frame); see the module docs.
    pub fn eval(&self, xi: [f64; 3], hessian: bool) -> Dissipation {
        let (vx, vy, om) = (xi[0], xi[1], xi[2]);
        let c = self.spin_radius;
        let mut out = Dissipation::ZERO;
        for (p, &w) in self.points.iter().zip(&self.weights) {
            if w == 0.0 {
                continue;
            }
            let (x, y) = (p.x, p.y);
            let g = [vx - om * y, vy + om * x, c * om];
            let speed = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
            if speed == 0.0 {
                continue;
            }
            out.value += w * speed;
            let ws = w / speed;
            let at = |a: [f64; 3]| [a[0], a[1], x * a[1] - y * a[0] + c * a[2]];
            let grad = at(g);
            for (o, g) in out.grad.iter_mut().zip(grad) {
                *o += ws * g;
            }
            if hessian {
                // Aᵀ(I − ĝĝᵀ)A / |g| = (AᵀA − (Aᵀĝ)(Aᵀĝ)ᵀ) / |g|, with AᵀA from the columns of A.
                let cols = [
                    at([1.0, 0.0, 0.0]),
                    at([0.0, 1.0, 0.0]),
                    at([0.0, 0.0, 1.0]),
                ];
                // The upper triangle, mirrored: each product's factors swap, so the lower
                // triangle's terms are the same numbers.
                let s2 = speed * speed;
                for i in 0..3 {
                    for j in i..3 {
                        let ata = cols[0][i] * cols[0][j]
                            + cols[1][i] * cols[1][j]
                            + cols[2][i] * cols[2][j];
                        let term = ws * (ata - grad[i] * grad[j] / s2);
                        out.hess[i][j] += term;
                        if j != i {
                            out.hess[j][i] += term;
                        }
                    }
                }
            }
        }
        out
    }

    /// c = m_max / f_max of the ellipsoid approximation: Σ w_i |x_i| (length units).
    pub fn ellipsoid_c(&self) -> f64 {
        self.points
            .iter()
            .zip(&self.weights)
            .map(|(p, w)| w * p.norm())
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_are_normalised() {
        let s = PointSupport::new(
            vec![Vec2::new(1.0, 0.0), Vec2::new(0.0, 2.0)],
            vec![1.0, 3.0],
        )
        .unwrap();
        assert_eq!(s.weights, vec![0.25, 0.75]);
        assert!((s.ellipsoid_c() - (0.25 + 1.5)).abs() < 1e-15);
    }

    #[test]
    fn a_point_at_rest_contributes_no_gradient() {
        // Ideal points: rotation about the support point itself: D = 0 there, the other carries all.
        let mut s = PointSupport::new(
            vec![Vec2::new(0.5, 0.5), Vec2::new(-0.5, 0.5)],
            vec![1.0, 1.0],
        )
        .unwrap();
        s.spin_radius = 0.0;
        // COR at (0.5, 0.5) with ω = 1: v = −ω ẑ×r = (0.5, −0.5).
        let d = s.eval([0.5, -0.5, 1.0], true);
        assert!(d.grad.iter().all(|g| g.is_finite()));
        assert!(d.hess.iter().flatten().all(|h| h.is_finite()));
        // The moving point is at (−0.5, 0.5): u = (0.5, −0.5) + (−0.5, −0.5) = (0, −1).
        assert!((d.value - 0.5).abs() < 1e-15);
        assert!(d.grad[0].abs() < 1e-15 && (d.grad[1] + 0.5).abs() < 1e-15);
        // x × û = (−0.5, 0.5) × (0, −1) = 0.5, times the weight 0.5.
        assert!((d.grad[2] - 0.25).abs() < 1e-15);
        // A zero weight point is ignored entirely.
        let mut z =
            PointSupport::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)], vec![0.0, 1.0]).unwrap();
        z.spin_radius = 0.0;
        let d = z.eval([0.0, 0.0, 1.0], true);
        assert!((d.value - 1.0).abs() < 1e-15 && (d.grad[2] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn a_pivoting_patch_spins() {
        // With the default patch, a point at the centre of rotation dissipates w·c|ω| and resists
        // with a moment w·c·sgn(ω): the limit surface is smooth there, not a facet.
        let s = PointSupport::new(
            vec![Vec2::new(0.5, 0.5), Vec2::new(-0.5, 0.5)],
            vec![1.0, 1.0],
        )
        .unwrap();
        let c = s.spin_radius;
        assert!((c - 2.0 / 3.0 * PATCH_FRACTION * 0.5f64.sqrt()).abs() < 1e-18);
        let d = s.eval([1.0, -1.0, 2.0], true); // COR at (0.5, 0.5)
        let moving = (1.0f64 * 4.0 + (c * 2.0).powi(2)).sqrt(); // |(0, −2, 2c)|
        assert!((d.value - 0.5 * (2.0 * c + moving)).abs() < 1e-15);
        // The resting patch adds 0.5·c to the moment (its g = (0, 0, 2c), Aᵀĝ = (0, 0, c)).
        let moving_moment = 0.5 * ((-0.5) * (-2.0) - 0.5 * 0.0 + c * 2.0 * c) / moving;
        assert!((d.grad[2] - (0.5 * c + moving_moment)).abs() < 1e-15);
        // The Hessian is finite and positive semidefinite with Hξ = 0.
        let xi = [1.0, -1.0, 2.0];
        for i in 0..3 {
            let hx: f64 = (0..3).map(|j| d.hess[i][j] * xi[j]).sum();
            assert!(hx.abs() < 1e-9, "row {i}: {hx}");
        }
    }
}
