//! Calibration: the uncertainty parameters that best explain measured bands, by maximum likelihood
//! over one reweighted ensemble, with 95% profile-likelihood intervals.
//!
//! **Parameters** φ = (μc mean m, μc spread s, share t of members on a random tripod (or smooth
//! density), pin radius ρ). Under φ a member has μc ~ normal(m, s), the random support with
//! probability t (else uniform pressure) and pin radius ~ normal(ρ, σρ) (σρ fixed, default 0.03
//! part units: the resolution at which ρ is fitted), both truncated at 0; the pose jitter is given,
//! not fitted.
//!
//! **One ensemble, reweighted.** The members are drawn once from a broad *proposal*: μc uniform on
//! the fitted range, the random support with probability ½, pin radius uniform on [0, ρmax]. Each
//! measured row is predicted once ([`super::predict`]). Under φ member i weighs
//! wᵢ(φ) = N(μcᵢ; m, s) · N(ρᵢ; ρ, σρ) · (t or 1 − t)/½ — importance sampling, with common random
//! numbers for every φ — and the row's log-likelihood (`score::RowKernel`) is a function of
//! four weighted sums, so a grid of tens of thousands of φ costs a few seconds and no new contact.
//! The effective number of members at the optimum, (Σw)²/Σw², says how well the proposal covers it.
//!
//! **Estimate and intervals.** The maximum of the log-likelihood over the grid; for each parameter
//! the profile (maximum over the others) and the values where it lies within χ²₁(0.95)/2 = 1.92 of
//! the maximum, ends interpolated linearly between grid points. An interval that reaches the end of
//! the grid is flagged: the data do not bound the parameter there.

use super::measured::Measured;
use super::predict::{predict_observed, Predictions};
use super::score::{RowKernel, ScoreSettings};
use crate::maps::ensemble::EnsembleSpec;
use crate::mechanics::support::SupportChoice;
use crate::mechanics::Fidelity;
use crate::random::distribution::Distribution;
use rayon::prelude::*;
use serde::Serialize;

/// Half the 95% quantile of χ² with one degree of freedom.
pub const PROFILE_DROP: f64 = 1.920_729;

/// How calibration searches.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrationSettings {
    /// Members of the proposal ensemble.
    pub members: usize,
    /// Passes per member and row.
    pub passes: usize,
    /// Seed of the proposal ensemble; the same seed gives the same calibration.
    pub seed: u64,
    /// Range of the fitted μc mean (and of the proposal).
    pub mu_c_range: (f64, f64),
    /// Largest pin radius (part units).
    pub pin_radius_max: f64,
    /// σρ (part units).
    pub pin_radius_sd: f64,
    /// The random support model (tripod or smooth).
    pub support: SupportChoice,
    /// Standard deviation of the pose error added to θ0 on every pass (degrees).
    pub jitter_deg: f64,
    /// The contact model.
    pub fidelity: Fidelity,
    /// Integration tolerance per step.
    pub tol: f64,
    /// How the prediction is scored against the measured bands.
    pub score: ScoreSettings,
}

impl Default for CalibrationSettings {
    fn default() -> Self {
        CalibrationSettings {
            members: 2000,
            passes: 1,
            seed: 1,
            mu_c_range: (0.05, 1.0),
            pin_radius_max: 0.3,
            pin_radius_sd: 0.03,
            support: SupportChoice::Tripod,
            jitter_deg: 0.0,
            fidelity: Fidelity::Exact,
            tol: 1e-6,
            score: ScoreSettings::default(),
        }
    }
}

impl CalibrationSettings {
    /// The proposal ensemble.
    pub fn proposal(&self) -> EnsembleSpec {
        EnsembleSpec {
            mu_c: Distribution::Uniform {
                min: self.mu_c_range.0,
                max: self.mu_c_range.1,
            },
            support: self.support,
            support_share: 0.5,
            pin_radius: Distribution::Uniform {
                min: 0.0,
                max: self.pin_radius_max,
            },
            jitter_deg: self.jitter_deg,
            fidelity: self.fidelity,
            tol: self.tol,
        }
    }

    /// The ensemble of parameters φ = [m, s, t, ρ].
    pub fn spec_at(&self, phi: [f64; 4]) -> EnsembleSpec {
        let [m, s, t, r] = phi;
        EnsembleSpec {
            mu_c: Distribution::Normal {
                mean: m,
                sd: s,
                lo: 0.0,
                hi: 10.0,
            },
            support: self.support,
            support_share: t,
            pin_radius: Distribution::Normal {
                mean: r,
                sd: self.pin_radius_sd,
                lo: 0.0,
                hi: 1e6,
            },
            ..self.proposal()
        }
    }

    /// The grid of each parameter: μc mean every 0.025, μc spread on a geometric ladder, share every
    /// 0.05, pin radius in ten steps.
    pub fn axes(&self) -> [Vec<f64>; 4] {
        let (lo, hi) = self.mu_c_range;
        let steps = ((hi - lo) / 0.025).round() as usize;
        // Grid values rounded to 1e-9, so that 0.45 prints as 0.45.
        let tidy = |x: f64| (x * 1e9).round() / 1e9;
        [
            (0..=steps)
                .map(|k| tidy(lo + (hi - lo) * k as f64 / steps as f64))
                .collect(),
            vec![0.02, 0.03, 0.045, 0.065, 0.09, 0.13, 0.18, 0.25],
            (0..=20).map(|k| k as f64 / 20.0).collect(),
            (0..=10)
                .map(|k| tidy(self.pin_radius_max * k as f64 / 10.0))
                .collect(),
        ]
    }
}

/// One fitted parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Fitted {
    /// The parameter's name.
    pub name: &'static str,
    /// Its estimate: the searched grid's value at the likelihood's maximum.
    pub estimate: f64,
    /// 95% profile-likelihood interval.
    pub lo: f64,
    /// Upper end of the 95% interval.
    pub hi: f64,
    /// The interval reaches the low / high end of the searched grid.
    pub open_low: bool,
    /// The interval reaches the high end of the searched grid.
    pub open_high: bool,
    /// Lowest value of the searched grid.
    pub grid_min: f64,
    /// Highest value of the searched grid.
    pub grid_max: f64,
}

impl Fitted {
    /// Does the interval hold `v`?
    pub fn covers(&self, v: f64) -> bool {
        self.lo <= v + 1e-12 && v <= self.hi + 1e-12
    }
}

/// The result of a calibration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Calibration {
    /// μc mean, μc spread, support share, pin radius.
    pub parameters: Vec<Fitted>,
    /// Log-likelihood (natural log) of the measured bands at the optimum.
    pub log_likelihood: f64,
    /// Effective members at the optimum, (Σw)²/Σw², out of `members`.
    pub effective_members: f64,
    /// Members of the proposal ensemble.
    pub members: usize,
    /// Grid points evaluated.
    pub grid_points: usize,
}

impl Calibration {
    /// The estimate φ̂ = [m, s, t, ρ].
    pub fn estimate(&self) -> [f64; 4] {
        [0, 1, 2, 3].map(|k| self.parameters[k].estimate)
    }
}

/// Names of the parameters, in order.
pub const NAMES: [&str; 4] = ["mu_c_mean", "mu_c_sd", "support_share", "pin_radius"];

/// Log-weights of the members under (m, s, ρ), without the support factor.
fn log_weights(pred: &Predictions, m: f64, s: f64, r: f64, sr: f64) -> Vec<f64> {
    pred.members
        .iter()
        .map(|d| {
            let (a, b) = ((d.mu_c - m) / s, (d.pin_radius - r) / sr);
            -0.5 * (a * a + b * b)
        })
        .collect()
}

/// Log-likelihood at every support share `shares` for fixed (m, s, ρ); also the effective members.
fn shares_log_likelihood(
    pred: &Predictions,
    kernels: &[RowKernel],
    lw: &[f64],
    shares: &[f64],
    score: &ScoreSettings,
) -> Vec<(f64, f64)> {
    let top = lw.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    // No member possible at this grid point: every weight 0 (not NaN).
    let top = if top.is_finite() { top } else { 0.0 };
    // Member weights split by support group (tripod: g = 1).
    let split = |g: bool| -> Vec<f64> {
        pred.members
            .iter()
            .zip(lw)
            .map(|(d, &l)| {
                if d.random_support == g {
                    (l - top).exp()
                } else {
                    0.0
                }
            })
            .collect()
    };
    let (wu, wt) = (split(false), split(true));
    let (pu, pt) = (pred.pass_weights(&wu), pred.pass_weights(&wt));
    let (tot_u, tot_t): (f64, f64) = (pu.iter().sum(), pt.iter().sum());
    // The effective member count (Σw)²/Σw² of a mixture, from weights scaled by their largest
    // (the weights of one group can be 1e-200, whose squares underflow to 0).
    let largest = |w: &[f64]| w.iter().copied().fold(0.0, f64::max);
    let (mu, mt) = (largest(&wu), largest(&wt));
    let scaled_sq = |w: &[f64], m: f64| -> f64 {
        if m > 0.0 {
            w.iter().map(|x| (x / m) * (x / m)).sum()
        } else {
            0.0
        }
    };
    let (sq_u, sq_t) = (scaled_sq(&wu, mu), scaled_sq(&wt, mt));
    let ess_of = |a: f64, b: f64| -> f64 {
        let (ca, cb) = (a * mu, b * mt);
        let m = ca.max(cb);
        if m.is_nan() || m <= 0.0 {
            return 0.0;
        }
        let (ra, rb) = (ca / m, cb / m);
        let part = |r: f64, tot: f64, top: f64| if top > 0.0 { r * tot / top } else { 0.0 };
        let n = (part(ra, tot_u, mu) + part(rb, tot_t, mt)) / pred.passes as f64;
        n * n / (ra * ra * sq_u + rb * rb * sq_t)
    };
    let sums: Vec<([f64; 4], [f64; 4])> =
        kernels.iter().map(|k| (k.sums(&pu), k.sums(&pt))).collect();
    shares
        .iter()
        .map(|&t| {
            let (a, b) = (1.0 - t, t);
            let total = a * tot_u + b * tot_t;
            if total <= 0.0 {
                return (f64::NEG_INFINITY, 0.0);
            }
            let ll = kernels
                .iter()
                .zip(&sums)
                .map(|(k, (su, st))| {
                    let s = [0, 1, 2, 3].map(|q| a * su[q] + b * st[q]);
                    k.log_likelihood(s, total, score)
                })
                .sum();
            (ll, ess_of(a, b))
        })
        .collect()
}

/// The 95% interval of a profile (values `x`, profile `p`), ends interpolated.
fn profile_interval(x: &[f64], p: &[f64], best: f64) -> (f64, f64, bool, bool) {
    let cut = best - PROFILE_DROP;
    let inside: Vec<usize> = (0..x.len()).filter(|&k| p[k] >= cut).collect();
    let (first, last) = (inside[0], *inside.last().expect("the maximum is inside"));
    let cross = |i: usize, o: usize| {
        let f = (p[i] - cut) / (p[i] - p[o]);
        x[i] + (x[o] - x[i]) * f.clamp(0.0, 1.0)
    };
    let lo = if first == 0 {
        x[0]
    } else {
        cross(first, first - 1)
    };
    let hi = if last + 1 == x.len() {
        x[last]
    } else {
        cross(last, last + 1)
    };
    (lo, hi, first == 0, last + 1 == x.len())
}

/// Why a calibration failed ([`calibrate`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CalibrateError {
    /// The proposal ensemble's predictions could not be made (their message, as it is).
    #[error("{0}")]
    Predict(crate::maps::ensemble::EnsembleError),
    /// No point of the parameter grid has a finite log-likelihood.
    #[error("the log-likelihood is not finite anywhere on the grid")]
    NotFinite,
}

/// Calibrate the parameters to `measured`.
pub fn calibrate(
    measured: &Measured,
    s: &CalibrationSettings,
) -> Result<Calibration, CalibrateError> {
    calibrate_observed(measured, s, &crate::progress::silent)
}

/// [`calibrate`], telling `progress` first the proposal's passes run of all those needed, then the
/// likelihood grid's cells done of all.
pub fn calibrate_observed(
    measured: &Measured,
    s: &CalibrationSettings,
    progress: crate::progress::Report,
) -> Result<Calibration, CalibrateError> {
    let pred = predict_observed(
        measured,
        &s.proposal(),
        s.seed,
        s.members,
        s.passes,
        progress,
    )
    .map_err(CalibrateError::Predict)?;
    let kernels: Vec<RowKernel> = measured
        .rows
        .iter()
        .zip(&pred.rows)
        .map(|(row, v)| RowKernel::new(row, v, &s.score))
        .collect();
    let axes = s.axes();
    let (nm, ns, nt, nr) = (axes[0].len(), axes[1].len(), axes[2].len(), axes[3].len());
    // ll[((a · ns + b) · nr + c) · nt + t]
    let tally = crate::progress::Tally::new((nm * ns * nr) as u64, progress);
    let cells: Vec<Vec<(f64, f64)>> = (0..nm * ns * nr)
        .into_par_iter()
        .map(|x| {
            let (a, b, c) = (x / (ns * nr), (x / nr) % ns, x % nr);
            let lw = log_weights(&pred, axes[0][a], axes[1][b], axes[3][c], s.pin_radius_sd);
            let cell = shares_log_likelihood(&pred, &kernels, &lw, &axes[2], &s.score);
            tally.add(1);
            cell
        })
        .collect();
    let at = |a: usize, b: usize, t: usize, c: usize| cells[(a * ns + b) * nr + c][t];
    let mut best = (f64::NEG_INFINITY, [0usize; 4]);
    let mut profiles: [Vec<f64>; 4] = [nm, ns, nt, nr].map(|n| vec![f64::NEG_INFINITY; n]);
    for a in 0..nm {
        for b in 0..ns {
            for t in 0..nt {
                for c in 0..nr {
                    let ll = at(a, b, t, c).0;
                    let idx = [a, b, t, c];
                    for q in 0..4 {
                        profiles[q][idx[q]] = profiles[q][idx[q]].max(ll);
                    }
                    if ll > best.0 {
                        best = (ll, idx);
                    }
                }
            }
        }
    }
    if !best.0.is_finite() {
        return Err(CalibrateError::NotFinite);
    }
    let parameters = (0..4)
        .map(|q| {
            let (lo, hi, open_low, open_high) = profile_interval(&axes[q], &profiles[q], best.0);
            Fitted {
                name: NAMES[q],
                estimate: axes[q][best.1[q]],
                lo,
                hi,
                open_low,
                open_high,
                grid_min: axes[q][0],
                grid_max: *axes[q].last().expect("non-empty axis"),
            }
        })
        .collect();
    let [a, b, t, c] = best.1;
    Ok(Calibration {
        parameters,
        log_likelihood: best.0,
        effective_members: at(a, b, t, c).1,
        members: s.members,
        grid_points: nm * ns * nt * nr,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profile_intervals_interpolate_and_flag_open_ends() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0];
        let p = [-10.0, -2.0, 0.0, -1.0, -5.0];
        let (lo, hi, ol, oh) = profile_interval(&x, &p, 0.0);
        assert!((lo - (2.0 - 1.920_729 / 2.0)).abs() < 1e-5, "{lo}");
        assert!((hi - (3.0 + 0.920_729 / 4.0)).abs() < 1e-5, "{hi}");
        assert!(!ol && !oh);
        let (_, _, ol, _) = profile_interval(&x, &[0.0, -1.0, -3.0, -4.0, -5.0], 0.0);
        assert!(ol);
    }
}
