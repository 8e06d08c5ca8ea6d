//! Judging a prediction against measured bands.
//!
//! **Per row.** The prediction is the row's pooled passes ([`super::predict`]), each weighted by its
//! member's weight (1 for a plain ensemble). Its *predicted bands* are the smallest arcs holding 90%
//! of it. The row is *overlapping* if a predicted band shares an angle with the measured band; the
//! *centre offset* is the signed rotation from the centre of the nearest predicted band
//! (overlapping ones first) to the measured band's centre; the *predicted probability* is the share
//! of passes that end inside the measured band.
//!
//! **Containment.** The *contained share* is the predicted mass inside the measured band, as a
//! share of the predicted mass the band competes for: the whole circle for inputs `state:K` and
//! `theta:…`, and for input `all` (one band of several, no θ0) the band widened by the window at
//! each end. The row is *contained* when that share is at least [`ScoreSettings::contained_share`]
//! (default 80%: the range of 20 trials drawn from the predicted distribution itself holds at
//! least 80% of it 93% of the time, 90% only 61% of the time). The share is an estimate from a
//! finite ensemble, so it comes with a 95% interval: the 2.5% and 97.5% quantiles over
//! [`RESAMPLES`] bootstrap resamples of the ensemble's members (each member with all its passes and
//! its weight; the resamples are the same for every row, so the interval of the *count* of
//! contained rows, taken over the same resamples, accounts for rows that share members). The
//! verdict is *contained* when the whole interval is at or above the threshold, *not contained*
//! when it is below, and *undecided* when it straddles it: a verdict that is decided does not flip
//! with the ensemble's seed except by chance outside the interval.
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
    /// Least contained share (predicted mass inside the measured band) of a contained row.
    pub contained_share: f64,
}

/// Bootstrap resamples of the members behind the intervals of the containment verdicts.
pub const RESAMPLES: usize = 1000;
/// Default [`ScoreSettings::contained_share`].
pub const CONTAINED_SHARE: f64 = 0.8;
/// Seed of the bootstrap resamples (fixed: the interval is a function of the ensemble).
const RESAMPLE_SEED: u64 = 0xB007_57A9;

impl ScoreSettings {
    /// The settings, each checked against its range: the kernel's sd in [0.01, 90]°, the floor's
    /// weight in [1e-9, 1], the window in [0, 180]° and the contained share in [0.01, 1]. The
    /// error names the field (`kernel`, `floor`, `window`, `contained_share`).
    pub fn checked(
        kernel_deg: f64,
        floor: f64,
        window_deg: f64,
        contained_share: f64,
    ) -> Result<ScoreSettings, crate::mechanics::limits::OutOfRange> {
        use crate::mechanics::limits::in_range;
        in_range("kernel", kernel_deg, 0.01, 90.0, "degrees")?;
        in_range("floor", floor, 1e-9, 1.0, "weight of the uniform floor")?;
        in_range("window", window_deg, 0.0, 180.0, "degrees each side")?;
        in_range(
            "contained_share",
            contained_share,
            0.01,
            1.0,
            "share of the mass",
        )?;
        Ok(ScoreSettings {
            kernel_deg,
            floor,
            window_deg,
            contained_share,
        })
    }
}

impl Default for ScoreSettings {
    fn default() -> Self {
        ScoreSettings {
            kernel_deg: 2.0,
            floor: 0.01,
            window_deg: 20.0,
            contained_share: CONTAINED_SHARE,
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
pub(crate) struct RowKernel {
    /// n (the trial count; 2 when not given).
    pub n: u32,
    /// Widths (degrees) of the band widened by h/2 and of the window (360 without one).
    band_width: f64,
    window_width: f64,
    /// Per pass: density at min (at the centre for n = 1), density at max, mass in the widened
    /// band, mass in the window.
    pub at_min: Vec<f64>,
    /// Per pass: density at the band's max.
    pub at_max: Vec<f64>,
    /// Per pass: mass in the widened band.
    pub in_band: Vec<f64>,
    /// Per pass: mass in the window.
    pub in_window: Vec<f64>,
}

impl RowKernel {
    /// The kernel of `row` for its passes' final orientations `values` (degrees).
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
    /// 1-based line in the measured-bands file.
    pub line: usize,
    /// The part spec.
    pub part: String,
    /// Contact parameter d (units of a).
    pub d: f64,
    /// The input state, as written.
    pub input: String,
    /// Start of the measured band (degrees).
    pub min_deg: f64,
    /// End of the measured band (degrees).
    pub max_deg: f64,
    /// Trials the band summarises, if given.
    pub trials: Option<u32>,
    /// The contained share is at least the threshold (the point estimate).
    pub contained: bool,
    /// Predicted mass inside the measured band, as a share of the mass it competes for.
    pub contained_share: f64,
    /// 95% bootstrap interval of `contained_share` over the members.
    pub contained_share_ci95: [f64; 2],
    /// The verdict with its uncertainty: contained, not_contained or undecided.
    pub containment: Verdict,
    /// A predicted band shares an angle with the measured band.
    pub overlapping: bool,
    /// Measured centre minus the nearest predicted band's centre (degrees, signed).
    pub centre_offset_deg: Option<f64>,
    /// Weighted share of the passes that end inside the measured band.
    pub predicted_probability: f64,
    /// The row's log-likelihood (natural log; higher is better).
    pub log_score: f64,
    /// The row's predicted bands and the share of the circle they cover.
    pub predicted: PredictedBands,
}

/// A containment verdict that knows its sampling uncertainty.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// The whole 95% interval of the contained share is at or above the threshold.
    Contained,
    /// The whole interval is below it.
    NotContained,
    /// The interval straddles the threshold: more members would decide it.
    Undecided,
}

impl Verdict {
    /// The verdict for a contained share with 95% interval `ci95` against `threshold`.
    pub fn of(ci95: [f64; 2], threshold: f64) -> Verdict {
        if ci95[0] >= threshold {
            Verdict::Contained
        } else if ci95[1] < threshold {
            Verdict::NotContained
        } else {
            Verdict::Undecided
        }
    }
    /// The verdict in the report's table (`yes`, `no`, `undecided`).
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Contained => "yes",
            Verdict::NotContained => "no",
            Verdict::Undecided => "undecided",
        }
    }
}

/// Counts and totals over all rows.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Measured rows scored.
    pub rows: usize,
    /// Rows whose contained share is at least the threshold (point estimates).
    pub contained: usize,
    /// 95% bootstrap interval of that count.
    pub contained_ci95: [usize; 2],
    /// Rows with verdict contained, not contained and undecided.
    pub verdict_contained: usize,
    /// Rows with verdict not contained.
    pub verdict_not_contained: usize,
    /// Rows with verdict undecided.
    pub verdict_undecided: usize,
    /// The threshold of the contained share.
    pub contained_share: f64,
    /// Rows with a predicted band overlapping the measured one.
    pub overlapping: usize,
    /// Mean over rows of the share of the circle the predicted bands cover.
    pub coverage: f64,
    /// Sum of the rows' log-likelihoods (natural log; higher is better).
    pub log_score: f64,
    /// Mean log score per row (`log_score` over `rows`).
    pub mean_log_score: f64,
}

/// Score every row: `predicted[r]` are row r's passes (θf, degrees; index member · `passes` + q),
/// `weights` one weight per pass (all 1 for a plain ensemble). Returns the rows and the bootstrap
/// interval of the count of contained rows.
pub fn score_rows(
    measured: &Measured,
    predicted: &[Vec<f64>],
    weights: &[f64],
    passes: usize,
    s: &ScoreSettings,
) -> (Vec<RowScore>, [usize; 2]) {
    let total: f64 = weights.iter().sum();
    let masses: Vec<MemberMasses> = measured
        .rows
        .iter()
        .zip(predicted)
        .map(|(row, values)| MemberMasses::new(row, values, weights, passes, s))
        .collect();
    let (intervals, count) = bootstrap(&masses, s.contained_share);
    let rows = measured
        .rows
        .iter()
        .zip(predicted)
        .zip(masses.iter().zip(intervals))
        .map(|((row, values), (m, ci95))| {
            let kernel = RowKernel::new(row, values, s);
            let log_score = kernel.log_likelihood(kernel.sums(weights), total, s);
            let share = m.share(None);
            let containment = Containment {
                share,
                ci95,
                threshold: s.contained_share,
            };
            judge(row, values, weights, log_score, containment)
        })
        .collect();
    (rows, count)
}

/// Per member, the weight of its passes inside a row's measured band and in the arc the band
/// competes for (the circle, or for input `all` the band ± the window).
#[derive(Debug, Clone)]
struct MemberMasses {
    inside: Vec<f64>,
    reference: Vec<f64>,
}

impl MemberMasses {
    fn new(
        row: &MeasuredRow,
        values: &[f64],
        w: &[f64],
        passes: usize,
        s: &ScoreSettings,
    ) -> MemberMasses {
        let reference_arc = match row.input {
            InputState::All => row.band.widened(s.window_deg),
            _ => Arc::full(),
        };
        let members = values.len() / passes.max(1);
        let mut m = MemberMasses {
            inside: vec![0.0; members],
            reference: vec![0.0; members],
        };
        for (k, (&v, &wk)) in values.iter().zip(w).enumerate() {
            let i = (k / passes.max(1)).min(members.saturating_sub(1));
            if reference_arc.width >= 360.0 || reference_arc.contains_angle(v) {
                m.reference[i] += wk;
                if row.band.contains_angle(v) {
                    m.inside[i] += wk;
                }
            }
        }
        m
    }

    /// The contained share with every member once (`None`) or `counts[i]` times.
    fn share(&self, counts: Option<&[u32]>) -> f64 {
        let (mut inside, mut reference) = (0.0, 0.0);
        for i in 0..self.inside.len() {
            let c = counts.map_or(1.0, |c| c[i] as f64);
            inside += c * self.inside[i];
            reference += c * self.reference[i];
        }
        if reference > 0.0 {
            (inside / reference).min(1.0)
        } else {
            0.0
        }
    }
}

/// The 2.5% and 97.5% quantiles of sorted `x`.
fn interval<T: Copy>(sorted: &[T]) -> [T; 2] {
    let n = sorted.len();
    let at = |q: f64| sorted[((q * (n - 1) as f64).round() as usize).min(n - 1)];
    [at(0.025), at(0.975)]
}

/// Bootstrap over members: per row the 95% interval of the contained share, and the interval of
/// the count of rows at or above `threshold`, over the same [`RESAMPLES`] resamples.
fn bootstrap(masses: &[MemberMasses], threshold: f64) -> (Vec<[f64; 2]>, [usize; 2]) {
    use rand::RngExt;
    use rayon::prelude::*;
    let members = masses.first().map_or(0, |m| m.inside.len());
    if members == 0 {
        let point: Vec<f64> = masses.iter().map(|m| m.share(None)).collect();
        let count = point.iter().filter(|&&p| p >= threshold).count();
        return (point.iter().map(|&p| [p, p]).collect(), [count, count]);
    }
    let shares: Vec<Vec<f64>> = (0..RESAMPLES as u64)
        .into_par_iter()
        .map(|b| {
            let mut rng = crate::random::stream(RESAMPLE_SEED, b);
            let mut counts = vec![0u32; members];
            for _ in 0..members {
                counts[rng.random_range(0..members)] += 1;
            }
            masses.iter().map(|m| m.share(Some(&counts))).collect()
        })
        .collect();
    let per_row = (0..masses.len())
        .map(|r| {
            let mut x: Vec<f64> = shares.iter().map(|b| b[r]).collect();
            x.sort_by(f64::total_cmp);
            interval(&x)
        })
        .collect();
    let mut counts: Vec<usize> = shares
        .iter()
        .map(|b| b.iter().filter(|&&p| p >= threshold).count())
        .collect();
    counts.sort_unstable();
    (per_row, interval(&counts))
}

/// A row's contained share, its interval and the threshold.
struct Containment {
    share: f64,
    ci95: [f64; 2],
    threshold: f64,
}

/// Containment, overlap, offset and probability of one row.
fn judge(row: &MeasuredRow, values: &[f64], w: &[f64], log_score: f64, c: Containment) -> RowScore {
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
        contained: c.share >= c.threshold,
        contained_share: c.share,
        contained_share_ci95: c.ci95,
        containment: Verdict::of(c.ci95, c.threshold),
        overlapping: bands.iter().any(|b| b.arc.overlaps(m)),
        centre_offset_deg: nearest.map(|b| signed_difference(b.arc.centre(), m.centre())),
        predicted_probability: if total > 0.0 { inside / total } else { 0.0 },
        log_score,
        predicted,
    }
}

/// The summary of scored rows; `contained_ci95` is the count's interval from [`score_rows`] and
/// `threshold` the contained share of a contained row.
pub fn summarise(rows: &[RowScore], contained_ci95: [usize; 2], threshold: f64) -> Summary {
    let n = rows.len();
    let log_score: f64 = rows.iter().map(|r| r.log_score).sum();
    let verdicts = |v: Verdict| rows.iter().filter(|r| r.containment == v).count();
    Summary {
        rows: n,
        contained: rows.iter().filter(|r| r.contained).count(),
        contained_ci95,
        verdict_contained: verdicts(Verdict::Contained),
        verdict_not_contained: verdicts(Verdict::NotContained),
        verdict_undecided: verdicts(Verdict::Undecided),
        contained_share: threshold,
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
