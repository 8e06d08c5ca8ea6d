//! The closed forms of the `ellipsoid` and `tip` fidelities: the normal map of the limit surface
//! H(w) = |f|² + m²/c² = 1 is ξ ∝ (c² f, m), with c = m_max/f_max for the ellipsoid (Lynch, Maekawa
//! & Tanie 1992) and c = a = 1 for Peshkin & Sanderson's COR-locus tip.

use super::solve::{SolveFailure, Solved};
use super::warm::{WarmStick, WarmTwist};
use super::{wrench_of, Fidelity, PartModel, Twist, Wrench};
use crate::geometry::Vec2;
use nalgebra::Vector3;

impl PartModel {
    /// The c of the closed-form normal map for a non-exact fidelity.
    pub(super) fn closed_form_c(&self, fid: Fidelity) -> f64 {
        match fid {
            Fidelity::Tip => 1.0,
            _ => self.c_ellipsoid,
        }
    }

    /// The wrench on the closed-form limit surface of `fid` whose normal is `xi`.
    pub(super) fn closed_form_wrench(&self, fid: Fidelity, xi: Twist) -> Wrench {
        let c = self.closed_form_c(fid);
        // On H(w) = |f|² + m²/c² = 1 with normal ∝ (f, m/c²) ∝ ξ: f = kξv, m = k c² ξω.
        let k = 1.0 / (xi[0] * xi[0] + xi[1] * xi[1] + c * c * xi[2] * xi[2]).sqrt();
        [k * xi[0], k * xi[1], k * c * c * xi[2]]
    }

    /// [`PartModel::twist_for_wrench`] for a closed-form fidelity: ξ = (c² f, m) / ((c² f, m)·w).
    pub(super) fn closed_form_twist_for_wrench(
        &self,
        fid: Fidelity,
        w: Wrench,
        evals: &mut u64,
    ) -> Result<(Solved, WarmTwist), SolveFailure> {
        *evals += 1;
        let c2 = self.closed_form_c(fid).powi(2);
        let wv = Vector3::from(w);
        let xi = Vector3::new(c2 * w[0], c2 * w[1], w[2]);
        let d = wv.dot(&xi);
        if d.is_nan() || d <= 0.0 || !d.is_finite() {
            return Err(SolveFailure::NonFinite);
        }
        let xi: Twist = (xi * (1.0 / d)).into();
        let solved = Solved {
            twist: xi,
            wrench: self.wrench_for_twist(fid, xi, evals),
        };
        let next = WarmTwist {
            twist: xi,
            wrench: w,
            lambda: 0.0,
            hess: None,
        };
        Ok((solved, next))
    }

    /// [`PartModel::stick_twist`] for a closed-form fidelity: the force at `p` whose twist moves
    /// `p` at `v`, solved in closed form.
    pub(super) fn closed_form_stick(
        &self,
        fid: Fidelity,
        p: Vec2,
        v: Vec2,
        evals: &mut u64,
    ) -> Result<(Solved, WarmStick), SolveFailure> {
        // ξ = A w(f) with A = diag(c², c², 1); v_c = B f, B = c² I + q qᵀ, q = ẑ×p (Lynch 1992).
        *evals += 1;
        let c2 = self.closed_form_c(fid).powi(2);
        let q = p.perp();
        let denom = c2 + q.norm2();
        // B⁻¹ v = (v − q (q·v)/(c²+|q|²)) / c²
        let f = (v - q * (q.dot(v) / denom)) / c2;
        let w = wrench_of(f, p);
        let xi = [c2 * w[0], c2 * w[1], w[2]];
        if !Vector3::from(xi).norm().is_finite() {
            return Err(SolveFailure::NonFinite);
        }
        let solved = Solved {
            twist: xi,
            wrench: self.wrench_for_twist(fid, xi, evals),
        };
        Ok((solved, WarmStick::without_hessian(solved)))
    }

    /// The ellipsoid's normal at `w`, not normalised: the exact solve's cold start.
    pub(super) fn ellipsoid_guess(&self, w: Wrench) -> Twist {
        let c2 = self.c_ellipsoid * self.c_ellipsoid;
        [c2 * w[0], c2 * w[1], w[2]]
    }
}

#[cfg(test)]
mod tests {
    use super::super::{point_velocity, Support};
    use super::*;
    use crate::geometry::part_from_spec;

    #[test]
    fn ellipsoid_normal_map_is_linear() {
        let poly = part_from_spec("tripoly2").unwrap();
        let m = PartModel::new(&poly, &Support::Uniform).unwrap();
        let mut ev = 0;
        let w = [0.3, -1.0, 0.2];
        let (s, _) = m
            .twist_for_wrench(Fidelity::Ellipsoid, w, None, 0.0, &mut ev)
            .unwrap();
        assert!((Vector3::from(w).dot(&Vector3::from(s.twist)) - 1.0).abs() < 1e-14);
        let c2 = m.ellipsoid_c().powi(2);
        assert!((s.twist[0] / s.twist[2] - c2 * w[0] / w[2]).abs() < 1e-12);
        // The wrench returned lies on the ellipsoid.
        let wr = s.wrench;
        let h = wr[0] * wr[0] + wr[1] * wr[1] + wr[2] * wr[2] / c2;
        assert!((h - 1.0).abs() < 1e-12);
    }

    #[test]
    fn closed_form_stick_matches_target_velocity() {
        let poly = part_from_spec("square").unwrap();
        let m = PartModel::new(&poly, &Support::Uniform).unwrap();
        let mut ev = 0;
        let p = Vec2::new(0.7, 0.2);
        let v = Vec2::new(-1.0, 0.3);
        for fid in [Fidelity::Tip, Fidelity::Ellipsoid] {
            let (s, _) = m.stick_twist(fid, p, v, None, 0.0, &mut ev).unwrap();
            assert!((point_velocity(s.twist, p) - v).norm() < 1e-13);
        }
    }
}
