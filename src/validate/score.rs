//! Judging a prediction against measured bands.
//!
//! **Per row.** The prediction is the row's pooled passes ([`super::predict`]), each weighted by its
//! member's weight (1 for a plain ensemble). Its *predicted bands* are the smallest arcs holding 90%
//! of it. The row is *contained* if one predicted band holds the whole measured band, *overlapping*
//! if one shares an angle with it; the *centre offset* is the signed rotation from the centre of the
//! nearest predicted band (overlapping ones first) to the measured band's centre; the *predicted
//! probability* is the share of passes that end inside the measured band.
//!
//! **Log score.** The predicted density of θf is the passes smoothed by a wrapped normal kernel of
//! sd h (default 2°: it stands for the measurement error of a band end), mixed with a uniform floor
//! of weight ε (default 1%: no measurement is ever impossible): f = (1 − ε) Σ wᵢ K_h(θ − θᵢ)/Σ wᵢ + ε/360.
//! A band [min, max] summarising n trials is the range of n draws, whose likelihood is
//! n(n − 1) f(min) f(max) P^(n−2) with P the predicted mass of the band widened by h/2 at each end
//! (one trial, n = 1: f at the band's centre; no trial count given: n = 2, the ends only). For input
//! `all` (a thesis-style table: bands of the whole map, no θ0), a band is one of several and its
//! trials are those that ended near it, so f and P are conditioned on the measured band widened by
//! the window (default 20°) at each end. The log score is the sum over rows of the log-likelihood
//! (natural log; higher is better). It is a proper score: no prediction scores better in expectation
//! than the distribution the measurements came from — a prediction cannot buy a good score by
//! covering the whole circle, which is also why the summary reports the share of the circle the
//! predicted bands cover.

use super::measured::{Measured, MeasuredRow};
use crate::maps::arcs::{signed_difference, Arc, MassArc};
use crate::maps::ensemble::{InputState, PredictedBands};
use serde::Serialize;

/// Smoothing of the log score.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ScoreSettings {
    /// Kernel sd h (degrees).
    pub kernel_deg: f64,
    /// Weight ε of the uniform floor.
    pub floor: f64,
    /// Window for input `all` (degrees each side).
    pub window_deg: f64,
}

impl Default for ScoreSettings {
    fn default() -> Self {
        ScoreSettings {
            kernel_deg: 2.0,
            floor: 0.01,
            window_deg: 20.0,
        }
    }
}

/// Complementary error function (Numerical Recipes' `erfcc`, fractional error < 1.2e-7).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let r = t * poly.exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

/// Standard normal CDF.
fn normal_cdf(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

/// Kernel density at `x` of one pass at `theta` (per degree).
fn kernel_density(theta: f64, x: f64, h: f64) -> f64 {
    let u = signed_difference(theta, x) / h;
    (-0.5 * u * u).exp() / (h * (2.0 * std::f64::consts::PI).sqrt())
}

/// Kernel mass of one pass at `theta` inside `arc`.
fn kernel_mass(theta: f64, arc: &Arc, h: f64) -> f64 {
    if arc.width >= 360.0 {
        return 1.0;
    }
    let dc = signed_difference(arc.centre(), theta);
    normal_cdf((arc.width / 2.0 - dc) / h) - normal_cdf((-arc.width / 2.0 - dc) / h)
}

/// A row's likelihood as a function of the weights: each pass's contributions to the four sums.
#[derive(Debug, Clone, PartialEq)]
pub struct RowKernel {
    /// n (the trial count; 2 when not given).
    pub n: u32,
    /// Widths (degrees) of the band widened by h/2 and of the window (360 without one).
    band_width: f64,
    window_width: f64,
    /// Per pass: density at min (at the centre for n = 1), density at max, mass in the widened
    /// band, mass in the window.
    pub at_min: Vec<f64>,
    pub at_max: Vec<f64>,
    pub in_band: Vec<f64>,
    pub in_window: Vec<f64>,
}

impl RowKernel {
    pub fn new(row: &MeasuredRow, values: &[f64], s: &ScoreSettings) -> RowKernel {
        let h = s.kernel_deg;
        let n = row.trials.unwrap_or(2);
        let band = row.band.widened(h / 2.0);
        let window = match row.input {
            InputState::All => row.band.widened(s.window_deg),
            _ => Arc::full(),
        };
        let (x_min, x_max) = if n == 1 {
            (row.band.centre(), row.band.centre())
        } else {
            (row.min_deg, row.max_deg)
        };
        RowKernel {
            n,
            band_width: band.width,
            window_width: window.width,
            at_min: values
                .iter()
                .map(|&t| kernel_density(t, x_min, h))
                .collect(),
            at_max: values
                .iter()
                .map(|&t| kernel_density(t, x_max, h))
                .collect(),
            in_band: values.iter().map(|&t| kernel_mass(t, &band, h)).collect(),
            in_window: values.iter().map(|&t| kernel_mass(t, &window, h)).collect(),
        }
    }

    /// Weighted sums [Σ w·at_min, Σ w·at_max, Σ w·in_band, Σ w·in_window] over passes.
    pub fn sums(&self, w: &[f64]) -> [f64; 4] {
        let mut s = [0.0; 4];
        for (k, &wk) in w.iter().enumerate() {
            s[0] += wk * self.at_min[k];
            s[1] += wk * self.at_max[k];
            s[2] += wk * self.in_band[k];
            s[3] += wk * self.in_window[k];
        }
        s
    }

    /// The row's log-likelihood from the weighted sums and the total weight.
    pub fn log_likelihood(&self, sums: [f64; 4], total: f64, s: &ScoreSettings) -> f64 {
        let e = s.floor;
        let mix = |v: f64, uniform: f64| (1.0 - e) * v / total + e * uniform;
        let window = mix(sums[3], self.window_width / 360.0);
        let f_min = mix(sums[0], 1.0 / 360.0) / window;
        let f_max = mix(sums[1], 1.0 / 360.0) / window;
        let p = (mix(sums[2], self.band_width / 360.0) / window).min(1.0);
        let n = self.n as f64;
        if self.n == 1 {
            f_min.ln()
        } else {
            (n * (n - 1.0)).ln() + f_min.ln() + f_max.ln() + (n - 2.0) * p.ln()
        }
    }
}

/// The verdict on one measured row.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RowScore {
    pub line: usize,
    pub part: String,
    pub d: f64,
    pub input: String,
    pub min_deg: f64,
    pub max_deg: f64,
    pub trials: Option<u32>,
    pub contained: bool,
    pub overlapping: bool,
    /// Measured centre minus the nearest predicted band's centre (degrees, signed).
    pub centre_offset_deg: Option<f64>,
    pub predicted_probability: f64,
    pub log_score: f64,
    /// The row's predicted bands and the share of the circle they cover.
    pub predicted: PredictedBands,
}

/// Counts and totals over all rows.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    pub rows: usize,
    pub contained: usize,
    pub overlapping: usize,
    /// Mean over rows of the share of the circle the predicted bands cover.
    pub coverage: f64,
    pub log_score: f64,
    pub mean_log_score: f64,
}

/// Score every row: `predicted[r]` are row r's passes (θf, degrees), `weights` one weight per pass
/// (all 1 for a plain ensemble).
pub fn score_rows(
    measured: &Measured,
    predicted: &[Vec<f64>],
    weights: &[f64],
    s: &ScoreSettings,
) -> Vec<RowScore> {
    let total: f64 = weights.iter().sum();
    measured
        .rows
        .iter()
        .zip(predicted)
        .map(|(row, values)| {
            let kernel = RowKernel::new(row, values, s);
            let log_score = kernel.log_likelihood(kernel.sums(weights), total, s);
            judge(row, values, weights, log_score)
        })
        .collect()
}

/// Containment, overlap, offset and probability of one row.
fn judge(row: &MeasuredRow, values: &[f64], w: &[f64], log_score: f64) -> RowScore {
    let predicted = PredictedBands::of(row.d, row.input.label(), values, w);
    let bands = &predicted.bands;
    let m = &row.band;
    let nearest = bands.iter().min_by(|a, b| {
        let key = |x: &MassArc| {
            (
                !x.arc.overlaps(m),
                signed_difference(x.arc.centre(), m.centre()).abs(),
            )
        };
        let (ka, kb) = (key(a), key(b));
        ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
    });
    let total: f64 = w.iter().sum();
    let inside: f64 = values
        .iter()
        .zip(w)
        .filter(|(v, _)| m.contains_angle(**v))
        .map(|(_, w)| w)
        .sum();
    RowScore {
        line: row.line,
        part: row.part.clone(),
        d: row.d,
        input: row.input.label(),
        min_deg: row.min_deg,
        max_deg: row.max_deg,
        trials: row.trials,
        contained: bands.iter().any(|b| b.arc.contains(m)),
        overlapping: bands.iter().any(|b| b.arc.overlaps(m)),
        centre_offset_deg: nearest.map(|b| signed_difference(b.arc.centre(), m.centre())),
        predicted_probability: if total > 0.0 { inside / total } else { 0.0 },
        log_score,
        predicted,
    }
}

/// The summary of scored rows.
pub fn summarise(rows: &[RowScore]) -> Summary {
    let n = rows.len();
    let log_score: f64 = rows.iter().map(|r| r.log_score).sum();
    Summary {
        rows: n,
        contained: rows.iter().filter(|r| r.contained).count(),
        overlapping: rows.iter().filter(|r| r.overlapping).count(),
        coverage: rows.iter().map(|r| r.predicted.coverage).sum::<f64>() / n.max(1) as f64,
        log_score,
        mean_log_score: log_score / n.max(1) as f64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_cdf_matches_reference_values() {
        assert!((normal_cdf(0.0) - 0.5).abs() < 1e-7);
        assert!((normal_cdf(1.96) - 0.975_002_1).abs() < 1e-6);
        assert!((normal_cdf(-1.0) - 0.158_655_25).abs() < 1e-6);
    }

    #[test]
    fn kernel_mass_handles_arcs_across_zero() {
        let arc = Arc::from_ends(350.0, 10.0);
        assert!(kernel_mass(0.0, &arc, 2.0) > 0.999);
        assert!((kernel_mass(350.0, &arc, 2.0) - 0.5).abs() < 1e-6);
        assert!(kernel_mass(180.0, &arc, 2.0) < 1e-12);
    }
}
