//! The exact stick solve: the twist whose velocity at a contact point p equals a given v,
//! ξ(ω) = (v − ω ẑ×p, ω), with ω minimising D (zero support moment about p). A one-dimensional
//! convex problem, solved by Newton's method safeguarded by bisection of a bracket (as Numerical
//! Recipes' rtsafe), warm-started by a first-order prediction ([`WarmStick`]).

use super::solve::{SolveFailure, Solved, NEWTON_TOL};
use super::warm::{linearised, WarmStick};
use super::{hessian, point_velocity, quad_form, Fidelity, PartModel};
use crate::geometry::Vec2;
use crate::mechanics::limit_surface::Dissipation;
use nalgebra::Vector3;

impl PartModel {
    /// [`PartModel::stick_twist`] for the exact fidelity.
    pub(super) fn exact_stick(
        &self,
        p: Vec2,
        v: Vec2,
        warm: Option<&WarmStick>,
        gap: f64,
        evals: &mut u64,
    ) -> Result<(Solved, WarmStick), SolveFailure> {
        // ξ(ω) = (v + ω q, ω), q = −ẑ×p, so that the velocity at p is v for every ω.
        let q = -p.perp();
        let e = Vector3::new(q.x, q.y, 1.0);
        let xi_of = |om: f64| Vector3::new(v.x + om * q.x, v.y + om * q.y, om);
        let mut om = match warm {
            Some(w) if w.twist[2].is_finite() => w.predict(&e, &xi_of(w.twist[2])),
            _ => {
                let mut dummy = 0;
                self.stick_twist(Fidelity::Ellipsoid, p, v, None, 0.0, &mut dummy)
                    .map(|(s, _)| {
                        s.twist[2] / point_velocity(s.twist, p).norm().max(1e-300) * v.norm()
                    })
                    .unwrap_or(0.0)
            }
        };
        let done = |xi: Vector3<f64>, d: &Dissipation| {
            let solved = Solved {
                twist: xi.into(),
                wrench: d.grad,
            };
            (
                solved,
                WarmStick {
                    twist: xi.into(),
                    wrench: d.grad,
                    hess: Some(d.hess),
                },
            )
        };
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        let vscale = v.norm() / (1.0 + q.norm());
        let mut residual = f64::INFINITY;
        let mut last_step = f64::INFINITY;
        for it in 0..200u32 {
            let xi = xi_of(om);
            *evals += 1;
            let d = self.dissipation(xi.into(), true);
            let grad = Vector3::from(d.grad);
            let g = e.dot(&grad);
            let hss = quad_form(&hessian(&d.hess), &e, &e);
            if !g.is_finite() {
                return Err(SolveFailure::NonFinite);
            }
            residual = g.abs() / (grad.norm() * e.norm()).max(1e-300);
            if residual <= NEWTON_TOL {
                return Ok(done(xi, &d));
            }
            if residual <= gap && hss > 0.0 && hss.is_finite() {
                let xin = xi_of(om - g / hss);
                return Ok(done(xin, &linearised(&d, &xi, &xin)));
            }
            if g > 0.0 {
                hi = hi.min(om);
            } else {
                lo = lo.max(om);
            }
            // A bracket closed to rounding: the minimum sits on a kink (a point support) or is found.
            if hi - lo <= 1e-15 * (1.0 + om.abs()) {
                return Ok(done(xi, &d));
            }
            let mut next = if hss > 0.0 && hss.is_finite() {
                om - g / hss
            } else {
                f64::NAN
            };
            // Safeguard (as in Numerical Recipes' rtsafe): bisect when the Newton step leaves the
            // bracket or fails to halve the step before it (a stiff, kink-like minimum, e.g. a
            // support patch, makes Newton bounce between the bracket's ends).
            let newton_step = (next - om).abs();
            let slow = newton_step > 0.5 * last_step && lo.is_finite() && hi.is_finite();
            last_step = if newton_step.is_finite() {
                newton_step
            } else {
                f64::INFINITY
            };
            if slow {
                next = f64::NAN;
            }
            if !(next > lo && next < hi && next.is_finite()) {
                next = if lo.is_finite() && hi.is_finite() {
                    0.5 * (lo + hi)
                } else if lo.is_finite() {
                    lo + vscale.max(1.0) * 2f64.powi(it as i32)
                } else {
                    hi - vscale.max(1.0) * 2f64.powi(it as i32)
                };
            }
            om = next;
        }
        Err(SolveFailure::NoConvergence {
            iterations: 200,
            residual,
        })
    }
}
