//! Warm starts: what an exact solve leaves for the next one of the same kind ([`WarmTwist`],
//! [`WarmStick`]), and the first-order predictions made from it — the implicit-function step of
//! the optimality conditions ([`kkt_delta`]) and D linearised about a solution ([`linearised`]).

use super::solve::{Solved, NEWTON_TOL};
use super::{hessian, quad_form, Twist, Wrench};
use crate::mechanics::limit_surface::Dissipation;
use nalgebra::{Matrix3, Vector3};

/// What a twist solve leaves behind for the next one: the solution, the wrench it answered, the
/// multiplier λ (∇D = λ w at the optimum) and the Hessian of D there. With these the next solve
/// starts from a first-order prediction (implicit function theorem on ∇D(ξ) = λ w, w·ξ = 1):
/// [H −w; wᵀ 0] [dξ; dλ] = [λ dw; −dw·ξ].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WarmTwist {
    /// The solution ξ (part frame, normalised units), with w·ξ = 1.
    pub twist: Twist,
    /// The wrench direction w it answered (any length; units of μs m g).
    pub wrench: Wrench,
    /// The multiplier λ ≥ 0 of ∇D(ξ) = λ w (0 for the closed forms).
    pub lambda: f64,
    /// The Hessian of D at ξ, row-major (`None` for the closed forms).
    pub hess: Option<[[f64; 3]; 3]>,
}

/// What a stick solve leaves behind for the next one: the solution, its wrench and the Hessian of
/// D there (`None` for the closed forms).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WarmStick {
    /// The solution ξ (part frame, normalised units).
    pub twist: Twist,
    /// ∇D at ξ: the wrench on the limit surface (units of μs m g).
    pub wrench: Wrench,
    /// The Hessian of D at ξ, row-major (`None` for the closed forms).
    pub hess: Option<[[f64; 3]; 3]>,
}

impl WarmStick {
    /// The warm start of a solve that has no Hessian (the closed forms).
    pub(super) fn without_hessian(s: Solved) -> WarmStick {
        WarmStick {
            twist: s.twist,
            wrench: s.wrench,
            hess: None,
        }
    }

    /// The first-order prediction of the next stick solve's ω: the new problem's twist at the
    /// previous ω is `xi`, the new constraint direction `e`; one Newton step on D linearised about
    /// the previous solution (∇D(ξ) ≈ ∇D₀ + H₀ (ξ − ξ₀)). Without a Hessian, or when the step
    /// is not defined, the previous ω; likewise when the previous ω already meets the solve's
    /// tolerance to first order (so that a state the solve holds exactly, e.g. the pure
    /// translation of a push through the centroid, is not moved by rounding).
    pub(super) fn predict(&self, e: &Vector3<f64>, xi: &Vector3<f64>) -> f64 {
        let om = self.twist[2];
        let Some(h) = self.hess else {
            return om;
        };
        let h = hessian(&h);
        let grad = linear_grad(
            &Vector3::from(self.wrench),
            &h,
            &Vector3::from(self.twist),
            xi,
        );
        let g = e.dot(&grad);
        if g.abs() <= NEWTON_TOL * grad.norm() * e.norm() {
            return om;
        }
        let hss = quad_form(&h, e, e);
        let next = om - g / hss;
        if hss > 0.0 && next.is_finite() {
            next
        } else {
            om
        }
    }
}

/// First-order prediction of the twist for wrench `w` from the previous solution (see
/// [`WarmTwist`]), normalised to w·ξ = 1; `None` without a Hessian or if the system is singular.
pub(super) fn predict_twist(p: &WarmTwist, w: &Vector3<f64>) -> Option<Vector3<f64>> {
    let dw = w - Vector3::from(p.wrench);
    let (dxi, _) = kkt_delta(p, dw.into())?;
    let xi = Vector3::from(p.twist) + Vector3::from(dxi);
    let c = w.dot(&xi);
    (c > 0.0 && c.is_finite()).then(|| xi * (1.0 / c))
}

/// The first-order change (dξ, dλ) of a solution `p` of ∇D(ξ) = λ w, w·ξ = 1 when its wrench
/// changes by `dw`: [H −w; wᵀ 0] [dξ; dλ] = [λ dw; −dw·ξ] (Gaussian elimination with pivoting);
/// `None` without a Hessian or if the system is singular. The predictor of the warm starts and the
/// derivatives of the slide tables (`mechanics::slide_table`).
pub(crate) fn kkt_delta(p: &WarmTwist, dw: [f64; 3]) -> Option<(Twist, f64)> {
    let h = p.hess?;
    let w0 = p.wrench;
    let mut a = [
        [h[0][0], h[0][1], h[0][2], -w0[0], p.lambda * dw[0]],
        [h[1][0], h[1][1], h[1][2], -w0[1], p.lambda * dw[1]],
        [h[2][0], h[2][1], h[2][2], -w0[2], p.lambda * dw[2]],
        [
            w0[0],
            w0[1],
            w0[2],
            0.0,
            -Vector3::from(dw).dot(&Vector3::from(p.twist)),
        ],
    ];
    eliminate::<0>(&mut a)?;
    eliminate::<1>(&mut a)?;
    eliminate::<2>(&mut a)?;
    eliminate::<3>(&mut a)?;
    let dxi = [a[0][4] / a[0][0], a[1][4] / a[1][1], a[2][4] / a[2][2]];
    Some((dxi, a[3][4] / a[3][3]))
}

/// Column `COL` of [`kkt_delta`]'s Gauss–Jordan elimination with partial pivoting (a constant
/// column, so that every loop has fixed bounds and unrolls); `None` at a zero pivot.
#[inline(always)]
fn eliminate<const COL: usize>(a: &mut [[f64; 5]; 4]) -> Option<()> {
    // The row of the largest |a[i][COL]|, the last of equals (as `Iterator::max_by` with
    // `total_cmp` picks it): on non-negative floats the bit patterns order as the values.
    let mut piv = COL;
    let mut best = a[COL][COL].abs().to_bits();
    for (i, row) in a.iter().enumerate().skip(COL + 1) {
        let b = row[COL].abs().to_bits();
        if b >= best {
            (piv, best) = (i, b);
        }
    }
    if a[piv][COL].abs() < 1e-300 {
        return None;
    }
    if piv != COL {
        a.swap(COL, piv);
    }
    let pivot_row = a[COL];
    for (r, row) in a.iter_mut().enumerate() {
        if r != COL {
            let f = row[COL] / pivot_row[COL];
            for (x, p) in row[COL..].iter_mut().zip(&pivot_row[COL..]) {
                *x -= f * p;
            }
        }
    }
    Some(())
}

/// D, ∇D and H at `to`, to first order from their values `d` at `from`: ∇D(to) ≈ ∇D(from) +
/// H (to − from); H is kept.
pub(super) fn linearised(d: &Dissipation, from: &Vector3<f64>, to: &Vector3<f64>) -> Dissipation {
    let grad = Vector3::from(d.grad);
    Dissipation {
        value: d.value + grad.dot(&(to - from)),
        grad: linear_grad(&grad, &hessian(&d.hess), from, to).into(),
        hess: d.hess,
    }
}

/// ∇D at `to` to first order from ∇D = `grad` and H = `hess` at `from`. (nalgebra's product
/// H dx sums each row left to right, j = 0, 1, 2, as a dot product does.)
fn linear_grad(
    grad: &Vector3<f64>,
    hess: &Matrix3<f64>,
    from: &Vector3<f64>,
    to: &Vector3<f64>,
) -> Vector3<f64> {
    grad + hess * (to - from)
}

#[cfg(test)]
mod tests {
    use super::super::{Fidelity, PartModel, Support};
    use super::*;
    use crate::geometry::{part_from_spec, Vec2};

    /// A stick solve warm-started from the solve before it is predicted to first order: along
    /// a slowly turning velocity it needs fewer evaluations than one started from the previous ω
    /// alone, and the same answer.
    #[test]
    fn the_stick_prediction_saves_evaluations() {
        let m = PartModel::new(&part_from_spec("tripoly2").unwrap(), &Support::Uniform).unwrap();
        let p = Vec2::new(0.3, 0.35);
        let (mut ev_pred, mut ev_plain) = (0u64, 0u64);
        let mut warm: Option<WarmStick> = None;
        let mut plain: Option<WarmStick> = None;
        for k in 0..100 {
            let v = Vec2::new(-1.0, 0.2).rotate(-0.02 * k as f64);
            let (a, next) = m
                .stick_twist(Fidelity::Exact, p, v, warm.as_ref(), 0.0, &mut ev_pred)
                .unwrap();
            warm = Some(next);
            // The previous ω alone: a warm start without its Hessian.
            let (b, next) = m
                .stick_twist(Fidelity::Exact, p, v, plain.as_ref(), 0.0, &mut ev_plain)
                .unwrap();
            plain = Some(WarmStick { hess: None, ..next });
            let (a, b) = (Vector3::from(a.twist), Vector3::from(b.twist));
            assert!((a - b).norm() / b.norm() < 1e-10, "{k}");
        }
        assert!(ev_pred < ev_plain, "{ev_pred} vs {ev_plain}");
    }
}
