//! Impact with friction by Stronge's energetic coefficient of restitution
//! (docs/physics.md#dynamic-tier; Stronge 1990, 2000).
//!
//! At a single point contact with inverse effective mass matrix A = [[A_nn, A_nt], [A_nt, A_tt]]
//! (`ContactFrame::delassus`), the contact velocity u = (u_n, u_t) changes with the contact impulse
//! P = (p, P_t) as u = u⁰ + A P. The impact is resolved with the normal impulse p as the
//! independent variable: dP_t/dp is −σμ while the contact slips in direction σ = sgn u_t, and
//! −A_nt/A_tt (the ratio that keeps u_t = 0) while it sticks, which is consistent iff
//! |A_nt| ≤ μ A_tt. Within each regime u is linear in p:
//!
//! ```text
//! du_n/dp = k_n = A_nn + A_nt dP_t/dp,    du_t/dp = k_t = A_nt + A_tt dP_t/dp.
//! ```
//!
//! Slip ends where u_t reaches 0; the contact then sticks if |A_nt| ≤ μ A_tt, or else slips on in
//! the direction σ' = sgn A_nt (reversal, since then sgn A_nt = −σ). Compression ends where
//! u_n = 0, after the normal force has done the work W_c = ∫ u_n dp (< 0); restitution ends at the
//! impulse p_f where the normal force's work in restitution W_r = ∫ u_n dp equals −e² W_c. Every
//! piece of every integral is a quadratic in p, so p_f is found in closed form, piece by piece.
//!
//! Energy: the kinetic energy changes by W_n + W_t with W_n = (1 − e²) W_c ≤ 0 and
//! W_t = ∫ u_t dP_t ≤ 0 (friction opposes slip; zero while sticking), so no impact gains energy,
//! for every e ∈ [0, 1] and μ ≥ 0: the reason this law, not Newton's or Poisson's coefficient
//! (which can gain energy with friction when the slip reverses or stops, Wang & Mason 1992,
//! Stronge 1990), is used.

use super::body::Body;
use super::contact::ContactFrame;
use super::{within, InvalidInput};

/// One regime of an impact.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub enum ImpactPhase {
    /// Slipping with u_t of sign `sign` (±1), from normal impulse `from` to `to`.
    Slip {
        /// The sign of the slip velocity.
        sign: f64,
        /// Normal impulse at the start.
        from: f64,
        /// Normal impulse at the end.
        to: f64,
    },
    /// Sticking (u_t = 0), from normal impulse `from` to `to`.
    Stick {
        /// Normal impulse at the start.
        from: f64,
        /// Normal impulse at the end.
        to: f64,
    },
}

/// The resolved impact.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ImpactResult {
    /// Normal impulse p_f ≥ 0.
    pub p_n: f64,
    /// Tangential impulse P_t.
    pub p_t: f64,
    /// Normal impulse at the end of compression.
    pub p_c: f64,
    /// Contact velocities after the impact (u_n, u_t).
    pub u_after: (f64, f64),
    /// Work of the normal force in compression (≤ 0).
    pub work_compression: f64,
    /// Work of the normal force in restitution (≥ 0; −e² of the compression's).
    pub work_restitution: f64,
    /// Work of the tangential force (≤ 0).
    pub work_tangential: f64,
    /// The regimes in order.
    pub phases: Vec<ImpactPhase>,
}

impl ImpactResult {
    /// Did the slip reverse during the impact?
    pub fn reversed(&self) -> bool {
        let signs: Vec<f64> = self
            .phases
            .iter()
            .filter_map(|p| match p {
                ImpactPhase::Slip { sign, .. } => Some(*sign),
                ImpactPhase::Stick { .. } => None,
            })
            .collect();
        signs.windows(2).any(|w| w[0] != w[1])
    }

    /// Did the contact stick at some point of the impact?
    pub fn stuck(&self) -> bool {
        self.phases
            .iter()
            .any(|p| matches!(p, ImpactPhase::Stick { .. }))
    }
}

/// Why an impact could not be resolved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImpactError {
    /// A coefficient out of range.
    #[error(transparent)]
    Input(#[from] InvalidInput),
    /// The bodies are separating (u_n > 0): nothing to resolve.
    #[error("the contact is opening (u_n = {u_n})")]
    NotClosing {
        /// The normal velocity.
        u_n: f64,
    },
    /// The matrix A is not positive definite (or not finite).
    #[error("the inverse effective mass matrix {a:?} is not positive definite")]
    Matrix {
        /// (A_nn, A_nt, A_tt).
        a: [f64; 3],
    },
    /// More regime changes than a positive definite A allows (never expected).
    #[error("the impact did not end after {phases} regimes")]
    Phases {
        /// The regimes resolved.
        phases: usize,
    },
}

/// Resolve an impact with Stronge's energetic restitution (see the module docs): matrix
/// `a` = (A_nn, A_nt, A_tt), pre-impact contact velocity `u0` = (u_n, u_t) with u_n ≤ 0,
/// friction `mu` ≥ 0 and energetic coefficient of restitution `e` ∈ [0, 1]. At u_n = 0 the
/// impulse is zero unless the slip drives the contact closed (k_n ≤ 0 while slipping: Painlevé's
/// configuration), when it is an impact without collision (a tangential impact): compression
/// while the slip lasts, then stick or reversal, then restitution.
pub fn stronge_impact(
    a: [f64; 3],
    u0: (f64, f64),
    mu: f64,
    e: f64,
) -> Result<ImpactResult, ImpactError> {
    within("mu_c", mu, 0.0, f64::MAX, "[0, ∞), finite")?;
    within("restitution", e, 0.0, 1.0, "[0, 1]")?;
    let [ann, ant, att] = a;
    if !(a.iter().all(|x| x.is_finite()) && ann > 0.0 && att > 0.0 && ann * att > ant * ant) {
        return Err(ImpactError::Matrix { a });
    }
    let (mut un, mut ut) = u0;
    if un > 0.0 || un.is_nan() {
        return Err(ImpactError::NotClosing { u_n: un });
    }
    let stick_ok = ant.abs() <= mu * att;
    // The regime from a state with u_t = 0: stick, or slip in the direction sgn A_nt.
    let from_rest = || -> Option<f64> {
        if stick_ok {
            None
        } else {
            Some(ant.signum())
        }
    };
    let tiny = 1e-14 * (un.abs() + ut.abs());
    let mut slip: Option<f64> = if ut.abs() <= tiny {
        ut = 0.0;
        from_rest()
    } else {
        Some(ut.signum())
    };
    let (mut p, mut pt) = (0.0, 0.0);
    let (mut wc, mut wr, mut wt) = (0.0, 0.0, 0.0);
    let mut compressing = true;
    let mut p_c = 0.0;
    let mut phases = Vec::new();
    for _ in 0..8 {
        let dpt = match slip {
            Some(s) => -s * mu,
            None => -ant / att,
        };
        let kn = ann + ant * dpt;
        let kt = match slip {
            Some(_) => ant + att * dpt,
            None => 0.0,
        };
        // Candidate lengths of this piece: slip stopping, compression ending, restitution ending.
        let mut len = f64::INFINITY;
        let mut ends = End::None;
        if let Some(s) = slip {
            if s * kt < 0.0 {
                let d = -ut / kt;
                if d < len {
                    (len, ends) = (d, End::SlipStops);
                }
            }
        }
        if compressing {
            if kn > 0.0 {
                let d = -un / kn;
                if d <= len {
                    (len, ends) = (d, End::Compression);
                }
            }
        } else {
            let rest = -e * e * wc - wr;
            // un d + ½ kn d² = rest, the root where the work first reaches `rest` (stable form).
            let disc = un * un + 2.0 * kn * rest;
            let d = if disc >= 0.0 {
                let den = un + disc.sqrt();
                if den > 0.0 {
                    2.0 * rest / den
                } else {
                    0.0
                }
            } else {
                // u_n falls back to 0 before the work is done: restitution ends there.
                -un / kn
            };
            if d <= len {
                (len, ends) = (d, End::Restitution);
            }
        }
        if !len.is_finite() {
            return Err(ImpactError::Phases {
                phases: phases.len(),
            });
        }
        let len = len.max(0.0);
        let work_n = un * len + 0.5 * kn * len * len;
        if compressing {
            wc += work_n;
        } else {
            wr += work_n;
        }
        wt += dpt * (ut * len + 0.5 * kt * len * len);
        phases.push(match slip {
            Some(sign) => ImpactPhase::Slip {
                sign,
                from: p,
                to: p + len,
            },
            None => ImpactPhase::Stick {
                from: p,
                to: p + len,
            },
        });
        p += len;
        pt += dpt * len;
        un += kn * len;
        ut += kt * len;
        match ends {
            End::SlipStops => {
                ut = 0.0;
                slip = from_rest();
            }
            End::Compression => {
                un = 0.0;
                p_c = p;
                compressing = false;
                if e == 0.0 {
                    break;
                }
            }
            End::Restitution => break,
            End::None => unreachable!("a finite piece has an end"),
        }
    }
    if compressing {
        return Err(ImpactError::Phases {
            phases: phases.len(),
        });
    }
    Ok(ImpactResult {
        p_n: p,
        p_t: pt,
        p_c,
        u_after: (un, ut),
        work_compression: wc,
        work_restitution: wr,
        work_tangential: wt,
        phases,
    })
}

/// What ends a piece of an impact.
#[derive(Debug, Clone, Copy, PartialEq)]
enum End {
    None,
    SlipStops,
    Compression,
    Restitution,
}

/// Apply an impact at `frame` to the twist `qd` of `body` (obstacle fixed): the new twist
/// q̇ + M⁻¹ Jᵀ (p_n, P_t) and the resolved impact.
pub fn apply_impact(
    body: &Body,
    frame: &ContactFrame,
    qd: [f64; 3],
    mu: f64,
    e: f64,
) -> Result<([f64; 3], ImpactResult), ImpactError> {
    let u0 = frame.velocity(qd);
    let r = stronge_impact(frame.delassus(body), u0, mu, e)?;
    let dq = body.inverse_mass_times(frame.generalised(r.p_n, r.p_t));
    Ok(([qd[0] + dq[0], qd[1] + dq[1], qd[2] + dq[2]], r))
}
