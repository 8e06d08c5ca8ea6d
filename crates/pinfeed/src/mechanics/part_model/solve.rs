//! The exact slide solve: the twist normal to the limit surface of the real pressure distribution
//! at a wrench w, ξ = argmin D(ξ) subject to w·ξ = 1, by Newton's method on the plane w·ξ = 1 with
//! the analytic Hessian and a line search on the directional derivative, warm-started from the
//! previous instant (`warm.rs`). Also what every solve returns ([`Solved`], [`SolveFailure`])
//! and the stopping rules shared with the stick solve ([`final_gap`]).

use super::warm::{linearised, predict_twist, WarmTwist};
use super::{hessian, quad_form, PartModel, Twist, Wrench};
use crate::mechanics::limit_surface::Dissipation;
use nalgebra::{Vector2, Vector3};
use serde::Serialize;
use std::fmt;

/// Why a convex sub-problem could not be solved.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SolveFailure {
    /// Newton's method stopped before reaching the tolerance; `residual` is the relative optimality gap.
    NoConvergence {
        /// Newton iterations taken.
        iterations: u32,
        /// The relative optimality gap when the solve stopped (dimensionless, ≥ 0).
        residual: f64,
    },
    /// A non-finite number appeared.
    NonFinite,
}

impl fmt::Display for SolveFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SolveFailure::NoConvergence {
                iterations,
                residual,
            } => write!(
                f,
                "limit-surface solve did not converge ({iterations} iterations, residual {residual:.2e})"
            ),
            SolveFailure::NonFinite => write!(f, "limit-surface solve produced a non-finite number"),
        }
    }
}

/// A solved twist with the contact wrench on the limit surface it corresponds to
/// (in units of μs m g; the friction load on the part is its negative).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solved {
    /// The twist ξ = (vx, vy, ω), part frame, normalised units (a = 1).
    pub twist: Twist,
    /// The wrench (fx, fy, m) on the limit surface whose normal is ξ (units of μs m g; m about
    /// the centroid in units of a).
    pub wrench: Wrench,
}

/// Relative optimality gap at which a Newton solve stops (see also the rounding-floor test).
pub(super) const NEWTON_TOL: f64 = 1e-12;
/// The most Newton iterations a slide solve takes.
const NEWTON_MAX: u32 = 60;

/// The `final_gap` of the exact solves for integration tolerance `tol`: below this relative
/// optimality gap a solve takes its last Newton step without evaluating D at its end (see
/// `linearised`), since the gap after that step is O(gap²). Measured over 10⁶ solves on the
/// reference parts, a step from a gap g left at most ≈ 100 g², so √(1e-6 tol) leaves a gap below
/// 1e-4 tol: far below what the integration needs (`pinfeed bench contact`: the self-error at
/// tol 1e-6 is the same to three digits as with every step evaluated). A larger gap would save a
/// few more evaluations (8% at √(1e-4 tol)) but makes the answer jump by up to 100 g² where a
/// solve's last evaluation decides between one step and two: rounding-level changes of the input
/// (a part scaled by 10⁻⁶) would then move a grazing separation by more than 1e-6 a.
pub fn final_gap(tol: f64) -> f64 {
    (1e-6 * tol).sqrt().clamp(1e-9, 1e-4)
}

/// The plane w·ξ = 1 of a slide solve in coordinates z: ξ = ξ0 + z₁ e1 + z₂ e2, with ξ0 = w/|w|²
/// and e1, e2 an orthonormal basis of the directions orthogonal to w.
struct Plane {
    xi0: Vector3<f64>,
    e1: Vector3<f64>,
    e2: Vector3<f64>,
}

impl Plane {
    /// The plane of the wrench `w`, whose length is `wn` (> 0).
    fn new(w: &Vector3<f64>, wn: f64) -> Plane {
        let wh = w * (1.0 / wn);
        let (e1, e2) = orthonormal_complement(&wh);
        let xi0 = wh * (1.0 / wn);
        Plane { xi0, e1, e2 }
    }

    /// The twist at coordinates `z`.
    fn at(&self, z: Vector2<f64>) -> Vector3<f64> {
        self.xi0 + self.e1 * z.x + self.e2 * z.y
    }

    /// The components of `v` along e1 and e2: the coordinates of a twist on the plane, or the
    /// gradient of D restricted to it.
    fn in_plane(&self, v: &Vector3<f64>) -> Vector2<f64> {
        Vector2::new(self.e1.dot(v), self.e2.dot(v))
    }

    /// The Newton step of D restricted to the plane at a point with gradient `gr` (in plane) and
    /// Hessian `hess`; minus the gradient where the restricted Hessian is not positive definite.
    /// Also whether the Newton step was defined.
    fn newton_step(&self, hess: &[[f64; 3]; 3], gr: Vector2<f64>) -> (Vector2<f64>, bool) {
        let h = hessian(hess);
        let h11 = quad_form(&h, &self.e1, &self.e1);
        let h12 = quad_form(&h, &self.e1, &self.e2);
        let h22 = quad_form(&h, &self.e2, &self.e2);
        let det = h11 * h22 - h12 * h12;
        let solvable = det > 0.0 && h11 > 0.0 && det.is_finite();
        let dz = if solvable {
            Vector2::new(
                -(h22 * gr.x - h12 * gr.y) / det,
                -(-h12 * gr.x + h11 * gr.y) / det,
            )
        } else {
            -gr
        };
        (dz, solvable)
    }
}

/// Where a line search ended: the accepted coordinates, twist and its dissipation.
type Accepted = (Vector2<f64>, Vector3<f64>, Dissipation);

impl PartModel {
    /// [`PartModel::twist_for_wrench`] for the exact fidelity.
    pub(super) fn exact_twist_for_wrench(
        &self,
        w: Wrench,
        warm: Option<&WarmTwist>,
        gap: f64,
        evals: &mut u64,
    ) -> Result<(Solved, WarmTwist), SolveFailure> {
        let w = Vector3::from(w);
        let wn = w.norm();
        if wn.is_nan() || wn <= 0.0 || !wn.is_finite() {
            return Err(SolveFailure::NonFinite);
        }
        let plane = Plane::new(&w, wn);
        let start = self.slide_start(&w, warm);
        let done = |xi: Vector3<f64>, d: &Dissipation| {
            let solved = Solved {
                twist: xi.into(),
                wrench: d.grad,
            };
            let next = WarmTwist {
                twist: xi.into(),
                wrench: w.into(),
                lambda: Vector3::from(d.grad).dot(&w) / w.dot(&w),
                hess: Some(d.hess),
            };
            (solved, next)
        };
        let mut z = plane.in_plane(&start);
        let mut xi = plane.at(z);
        *evals += 1;
        let mut d = self.dissipation(xi.into(), true);
        let mut residual = f64::INFINITY;
        for it in 0..NEWTON_MAX {
            let prev_residual = residual;
            let gr = plane.in_plane(&Vector3::from(d.grad));
            let gnorm = Vector3::from(d.grad).norm();
            residual = gr.norm() / gnorm.max(1e-300);
            if !residual.is_finite() {
                return Err(SolveFailure::NonFinite);
            }
            // Converged, or at the rounding floor of the gradient (small and no longer improving).
            if residual <= NEWTON_TOL || (residual <= 1e-9 && residual > 0.5 * prev_residual) {
                return Ok(done(xi, &d));
            }
            let (mut dz, solvable) = plane.newton_step(&d.hess, gr);
            let slope = gr.dot(&dz);
            if solvable && slope < 0.0 && residual <= gap {
                let xin = plane.at(z + dz);
                let dn = linearised(&d, &xi, &xin);
                return Ok(done(xin, &dn));
            }
            if slope >= 0.0 {
                dz = -gr;
            }
            let slope0 = gr.dot(&dz);
            // Converged to rounding: the Newton step no longer moves the twist.
            let step_len = dz.norm();
            if step_len <= 1e-14 * xi.norm() {
                return Ok(done(xi, &d));
            }
            match self.line_search(&plane, z, dz, slope0, evals)? {
                Some((zn, xin, dn)) => (z, xi, d) = (zn, xin, dn),
                None if residual <= 1e-9 => return Ok(done(xi, &d)),
                None => {
                    return Err(SolveFailure::NoConvergence {
                        iterations: it + 1,
                        residual,
                    })
                }
            }
        }
        if residual <= 1e-9 {
            return Ok(done(xi, &d));
        }
        Err(SolveFailure::NoConvergence {
            iterations: NEWTON_MAX,
            residual,
        })
    }

    /// Where the slide solve for wrench `w` starts: the first-order prediction from `warm`, else
    /// its twist, else the ellipsoid's normal, each scaled onto w·ξ = 1.
    fn slide_start(&self, w: &Vector3<f64>, warm: Option<&WarmTwist>) -> Vector3<f64> {
        let predicted = warm.and_then(|p| predict_twist(p, w));
        match (predicted, warm) {
            (Some(x), _) => x,
            (None, Some(p)) if w.dot(&Vector3::from(p.twist)) > 0.0 => {
                let t = Vector3::from(p.twist);
                t * (1.0 / w.dot(&t))
            }
            _ => {
                let g = Vector3::from(self.ellipsoid_guess((*w).into()));
                g * (1.0 / w.dot(&g))
            }
        }
    }

    /// Line search from `z` along `dz` (slope `slope0` < 0 there) on the directional derivative
    /// φ'(t) = ∇D(ξ(z + t dz))·dz, which is monotone for convex D. Unlike the value of D it stays
    /// informative near the optimum, where decreases fall below the rounding of D on
    /// ill-conditioned (needle-like) parts. `None` when 40 trials found no acceptable step.
    fn line_search(
        &self,
        plane: &Plane,
        z: Vector2<f64>,
        dz: Vector2<f64>,
        slope0: f64,
        evals: &mut u64,
    ) -> Result<Option<Accepted>, SolveFailure> {
        let mut t = 1.0;
        for _ in 0..40 {
            let zn = z + dz * t;
            let xin = plane.at(zn);
            *evals += 1;
            let dn = self.dissipation(xin.into(), true);
            let slope_t = plane.in_plane(&Vector3::from(dn.grad)).dot(&dz);
            if !slope_t.is_finite() {
                return Err(SolveFailure::NonFinite);
            }
            if slope_t <= 0.9 * slope0.abs() {
                return Ok(Some((zn, xin, dn)));
            }
            // Overshot: secant on φ' between 0 (slope0 < 0) and t (slope_t > 0), safeguarded.
            let tn = t * (-slope0) / (slope_t - slope0);
            t = tn.clamp(0.1 * t, 0.7 * t);
        }
        Ok(None)
    }
}

/// Two unit vectors orthogonal to the unit vector `w` and to each other.
fn orthonormal_complement(w: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    // Pick the coordinate axis least aligned with w.
    let a = if w.x.abs() <= w.y.abs() && w.x.abs() <= w.z.abs() {
        Vector3::x()
    } else if w.y.abs() <= w.z.abs() {
        Vector3::y()
    } else {
        Vector3::z()
    };
    let e1 = a - w * a.dot(w);
    let e1 = e1 * (1.0 / e1.norm());
    (e1, w.cross(&e1))
}

#[cfg(test)]
mod tests {
    use super::super::warm::WarmStick;
    use super::super::{point_velocity, wrench_of, Fidelity, Support};
    use super::*;
    use crate::geometry::{part_from_spec, Vec2};

    fn rel_diff(a: Twist, b: Twist) -> f64 {
        let (a, b) = (Vector3::from(a), Vector3::from(b));
        (a - b).norm() / b.norm()
    }

    /// A path of solves as an integration makes them: a wrench (or a stick velocity) turning in
    /// small steps, each solve warm-started by the one before. With the final Newton step taken
    /// unevaluated (`final_gap` of tol 1e-6) every twist and wrench agrees with the fully
    /// converged solve (gap 0) to 1e-8 relative, and the path costs fewer evaluations.
    #[test]
    fn an_unevaluated_final_step_keeps_the_solves_within_a_hundredth_of_the_tolerance() {
        for name in ["tripoly1", "square", "lshape"] {
            let m = PartModel::new(&part_from_spec(name).unwrap(), &Support::Uniform).unwrap();
            let p = Vec2::new(0.45, -0.2);
            let (mut ev_fast, mut ev_full) = (0u64, 0u64);
            let (mut wf, mut wc): (Option<WarmTwist>, Option<WarmTwist>) = (None, None);
            let (mut sf, mut sc): (Option<WarmStick>, Option<WarmStick>) = (None, None);
            for k in 0..200 {
                let a = 0.01 * k as f64;
                let f = Vec2::new(-a.cos(), 0.3 * a.sin() - 0.4);
                let w = wrench_of(f, p);
                let gap = final_gap(1e-6);
                let (fast, nf) = m
                    .twist_for_wrench(Fidelity::Exact, w, wf.as_ref(), gap, &mut ev_fast)
                    .unwrap();
                let (full, nc) = m
                    .twist_for_wrench(Fidelity::Exact, w, wc.as_ref(), 0.0, &mut ev_full)
                    .unwrap();
                (wf, wc) = (Some(nf), Some(nc));
                assert!(rel_diff(fast.twist, full.twist) < 1e-8, "{name} {k}");
                assert!(rel_diff(fast.wrench, full.wrench) < 1e-8, "{name} {k}");
                let v = Vec2::new(-1.0, 0.0).rotate(-a);
                let (fast, nf) = m
                    .stick_twist(Fidelity::Exact, p, v, sf.as_ref(), gap, &mut ev_fast)
                    .unwrap();
                let (full, nc) = m
                    .stick_twist(Fidelity::Exact, p, v, sc.as_ref(), 0.0, &mut ev_full)
                    .unwrap();
                (sf, sc) = (Some(nf), Some(nc));
                assert!(rel_diff(fast.twist, full.twist) < 1e-8, "{name} stick {k}");
                assert!((point_velocity(fast.twist, p) - v).norm() < 1e-12);
            }
            assert!(ev_fast < ev_full, "{name}: {ev_fast} vs {ev_full}");
        }
    }

    #[test]
    fn orthonormal_basis() {
        let w = Vector3::new(0.2, -0.5, 0.84).normalize();
        let (a, b) = orthonormal_complement(&w);
        assert!(a.dot(&w).abs() < 1e-15 && b.dot(&w).abs() < 1e-15 && a.dot(&b).abs() < 1e-15);
        assert!((a.norm() - 1.0).abs() < 1e-15 && (b.norm() - 1.0).abs() < 1e-15);
    }
}
