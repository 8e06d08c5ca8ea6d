//! Limit surface of a support by N weighted points (SPEC §2: "a finite set of weighted support
//! points"; a tripod is the case N = 3 with barycentric loads).
//!
//! Part frame, centroid at the origin; weights are the normalised loads (sum 1, μs = 1). For a
//! twist ξ = [vx, vy, ω] the point x_i slides at u_i = v + ω ẑ×x_i and, exactly,
//!
//! * D(ξ) = Σ w_i |u_i|,
//! * ∇D(ξ) = Σ w_i J(x_i)ᵀ û_i, J(x) = [[1, 0, −y], [0, 1, x]] (the load on the part is −∇D),
//! * H(ξ) = Σ w_i J(x_i)ᵀ (I − û_i û_iᵀ) J(x_i) / |u_i|.
//!
//! D is not differentiable where a loaded point is at rest (the centre of rotation sits on it):
//! such a point (|u_i| ≤ 1e-300 (|v_x| + |v_y| + |ω| (|x_i| + |y_i|))) contributes nothing to
//! ∇D and H; its contribution to ∇D is then one element of the subdifferential (the point's static
//! friction is undetermined).

use super::Dissipation;
use crate::geometry::Vec2;

/// A support by weighted points in the part frame.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSupport {
    /// Support points, part frame (centroid at the origin).
    pub points: Vec<Vec2>,
    /// Normalised loads: non-negative, summing to 1.
    pub weights: Vec<f64>,
}

/// A point whose speed is at most this fraction of the twist's scale at that point counts as at
/// rest.
const AT_REST: f64 = 1e-300;

impl PointSupport {
    /// Build from points and non-negative loads (any positive total; they are normalised to sum 1).
    /// Rejects an empty set, mismatched lengths, non-finite points, and negative, non-finite or
    /// all-zero weights.
    pub fn new(points: Vec<Vec2>, weights: Vec<f64>) -> Result<Self, String> {
        if points.is_empty() {
            return Err("a point support needs at least one point".to_string());
        }
        if points.len() != weights.len() {
            return Err(format!(
                "{} support points but {} weights",
                points.len(),
                weights.len()
            ));
        }
        if let Some(i) = points.iter().position(|p| !p.is_finite()) {
            return Err(format!(
                "support point {i} ({}, {}) is not finite",
                points[i].x, points[i].y
            ));
        }
        if let Some(i) = weights.iter().position(|w| !w.is_finite() || *w < 0.0) {
            return Err(format!(
                "support weight {i} is {}; weights must be finite and non-negative",
                weights[i]
            ));
        }
        let total: f64 = weights.iter().sum();
        if total <= 0.0 || !total.is_finite() {
            return Err(format!(
                "support weights sum to {total}; at least one must be positive (and the sum finite)"
            ));
        }
        let weights = weights.into_iter().map(|w| w / total).collect();
        Ok(PointSupport { points, weights })
    }

    /// D, ∇D and (if `hessian`) H at twist ξ = [vx, vy, ω] (part frame), exact sums.
    pub fn eval(&self, xi: [f64; 3], hessian: bool) -> Dissipation {
        let (vx, vy, om) = (xi[0], xi[1], xi[2]);
        let vscale = vx.abs() + vy.abs();
        let mut out = Dissipation::ZERO;
        for (p, &w) in self.points.iter().zip(&self.weights) {
            let (x, y) = (p.x, p.y);
            let ux = vx - om * y;
            let uy = vy + om * x;
            let speed = ux.hypot(uy);
            out.value += w * speed;
            if speed <= AT_REST * (vscale + om.abs() * (x.abs() + y.abs())) || w == 0.0 {
                continue;
            }
            let ws = w / speed;
            out.grad[0] += ws * ux;
            out.grad[1] += ws * uy;
            out.grad[2] += ws * (x * uy - y * ux);
            if hessian {
                // Jᵀ u⊥ with u⊥ = ẑ×u; H += w/|u|³ (Jᵀu⊥)(Jᵀu⊥)ᵀ.
                let a = [-uy, ux, x * ux + y * uy];
                let wh = ws / (speed * speed);
                for (i, ai) in a.iter().enumerate() {
                    for (j, aj) in a.iter().enumerate() {
                        out.hess[i][j] += wh * ai * aj;
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
        // Rotation about the support point itself: D = 0 there, and the other point carries all.
        let s = PointSupport::new(
            vec![Vec2::new(0.5, 0.5), Vec2::new(-0.5, 0.5)],
            vec![1.0, 1.0],
        )
        .unwrap();
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
        let z = PointSupport::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)], vec![0.0, 1.0]).unwrap();
        let d = z.eval([0.0, 0.0, 1.0], true);
        assert!((d.value - 1.0).abs() < 1e-15 && (d.grad[2] - 1.0).abs() < 1e-15);
    }
}
