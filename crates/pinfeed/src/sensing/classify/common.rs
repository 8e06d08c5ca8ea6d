//! Helpers shared by the classifiers: the reading's baseline removal, contact detection on an F/T
//! reading, noise-free template sampling, and least-squares polynomial fits (thesis app. D2, with
//! nalgebra).
//!
//! **Contact detection** (the thesis detects contact by eye; every choice here is ours): the
//! horizontal force magnitude |(Fx, Fy)| is smoothed by a centred moving average of w samples and
//! compared with a threshold T = max(sensor threshold, [`DETECT_SIGMAS`] · σ/√w), σ = √(σ_n² +
//! q²/12) the per-channel noise of Fx/Fy (white noise σ_n, quantisation step q). The window w is
//! the smallest of at least [`MIN_WINDOW`] samples that brings 6σ/√w down to the sensor's
//! threshold, capped at [`MAX_WINDOW_S`] seconds: quiet sensors keep sharp edges, noisy ones
//! average longer before the threshold has to rise. The contact is the span from the first sample
//! above T to the last one. With T six smoothed standard deviations above zero a quiet reading
//! crosses it with probability ≈ e⁻¹⁸ per sample, so the detector reports no contact rather than a
//! false one — when the noise grows without bound the F/T classifiers answer Unknown.

use crate::sensing::reading::Sampled;
use crate::sensing::settings::{SensorSettings, CHANNELS};
use nalgebra::{DMatrix, DVector};

/// Fewest samples in the centred moving average applied to (Fx, Fy) before thresholding.
pub const MIN_WINDOW: usize = 5;
/// Longest smoothing window (s).
pub const MAX_WINDOW_S: f64 = 0.05;
/// Threshold in smoothed noise standard deviations.
pub const DETECT_SIGMAS: f64 = 6.0;

/// The contact detector for readings of one sensor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detector {
    /// Samples in the centred moving average (odd).
    pub window: usize,
    /// |F| threshold (N).
    pub threshold: f64,
}

impl Detector {
    /// The detector for `sensor`: the window grows with the noise (within fixed limits) so that the
    /// threshold sits well above the smoothed noise.
    pub fn new(sensor: &SensorSettings) -> Detector {
        let sd = noise_var(sensor, 0).max(noise_var(sensor, 1)).sqrt();
        let want = (DETECT_SIGMAS * sd / sensor.threshold).powi(2).ceil();
        let cap = (MAX_WINDOW_S * sensor.rate).floor().max(MIN_WINDOW as f64);
        let w = want.clamp(MIN_WINDOW as f64, cap) as usize;
        let window = w | 1;
        Detector {
            window,
            threshold: sensor
                .threshold
                .max(DETECT_SIGMAS * sd / (window as f64).sqrt()),
        }
    }

    /// The detected contact: first and last sample index (inclusive) where the smoothed
    /// |(Fx, Fy)| reaches the threshold; `None` when it never does.
    pub fn detect(&self, values: &[[f64; CHANNELS]]) -> Option<(usize, usize)> {
        detect(values, self.threshold, self.window)
    }

    /// The first sample of the detected contact, as [`Detector::detect`] finds it, reading no
    /// further into `values` than that sample's window; `None` when the threshold is never
    /// reached.
    pub fn first(&self, values: &[[f64; CHANNELS]]) -> Option<usize> {
        detect_first(values, self.threshold, self.window)
    }
}

/// Effective (white + quantisation) noise variance of channel `c`.
pub fn noise_var(sensor: &SensorSettings, c: usize) -> f64 {
    let q = sensor.resolution(c);
    sensor.noise(c).powi(2) + q * q / 12.0
}

/// The reading's channels with the sensor's known bias and drift removed (borrowed when there is
/// none); `None` when it is empty or holds a non-finite value.
pub fn clean_values<'a>(
    s: &'a Sampled,
    sensor: &SensorSettings,
) -> Option<std::borrow::Cow<'a, [[f64; CHANNELS]]>> {
    use std::borrow::Cow;
    if s.values.is_empty() || !s.dt.is_finite() || s.dt <= 0.0 || !s.t0.is_finite() {
        return None;
    }
    // Chunk by chunk without an early exit inside a chunk, so that the test vectorises.
    let finite = |c: &[[f64; CHANNELS]]| c.iter().flatten().fold(true, |a, x| a & x.is_finite());
    if !s.values.chunks(64).all(finite) {
        return None;
    }
    if (0..CHANNELS).all(|c| sensor.bias(c) == 0.0 && sensor.drift(c) == 0.0) {
        return Some(Cow::Borrowed(&s.values));
    }
    let out = s
        .values
        .iter()
        .enumerate()
        .map(|(k, v)| {
            let t = k as f64 * s.dt;
            std::array::from_fn(|c| v[c] - sensor.bias(c) - sensor.drift(c) * t)
        })
        .collect();
    Some(Cow::Owned(out))
}

/// The contact in samples: first and last index (inclusive) where |(Fx, Fy)| smoothed by a
/// centred moving average of `window` samples reaches `threshold`; `None` when it never does.
pub fn detect(values: &[[f64; CHANNELS]], threshold: f64, window: usize) -> Option<(usize, usize)> {
    let n = values.len();
    if n == 0 {
        return None;
    }
    // Prefix sums make any window O(1) per sample.
    let mut px = Vec::with_capacity(n + 1);
    let mut py = Vec::with_capacity(n + 1);
    let (mut sx, mut sy) = (0.0, 0.0);
    px.push(0.0);
    py.push(0.0);
    for v in values {
        sx += v[0];
        sy += v[1];
        px.push(sx);
        py.push(sy);
    }
    let h = window / 2;
    // |mean| ≥ threshold ⇔ |sum|² ≥ (threshold · count)².
    let above = |k: usize| {
        let lo = k.saturating_sub(h);
        let hi = (k + h).min(n - 1);
        let m = (hi - lo + 1) as f64;
        let fx = px[hi + 1] - px[lo];
        let fy = py[hi + 1] - py[lo];
        fx * fx + fy * fy >= (threshold * m).powi(2)
    };
    let first = (0..n).find(|&k| above(k))?;
    let last = (first..n).rev().find(|&k| above(k))?;
    Some((first, last))
}

/// The first index of [`detect`]'s contact: the same prefix sums and comparisons, each prefix
/// sum computed only once a window needs it, so the scan stops at the first sample above the
/// threshold.
pub fn detect_first(values: &[[f64; CHANNELS]], threshold: f64, window: usize) -> Option<usize> {
    let n = values.len();
    if n == 0 {
        return None;
    }
    let h = window / 2;
    let mut px = Vec::with_capacity(n + 1);
    let mut py = Vec::with_capacity(n + 1);
    let (mut sx, mut sy) = (0.0, 0.0);
    px.push(0.0);
    py.push(0.0);
    for k in 0..n {
        let lo = k.saturating_sub(h);
        let hi = (k + h).min(n - 1);
        while px.len() < hi + 2 {
            let v = values[px.len() - 1];
            sx += v[0];
            sy += v[1];
            px.push(sx);
            py.push(sy);
        }
        let m = (hi - lo + 1) as f64;
        let fx = px[hi + 1] - px[lo];
        let fy = py[hi + 1] - py[lo];
        if fx * fx + fy * fy >= (threshold * m).powi(2) {
            return Some(k);
        }
    }
    None
}

/// A least-squares polynomial fit (thesis app. D2: the normal equations' minimiser, computed here by
/// SVD for conditioning) of `y` against `x`, with x mapped affinely onto [−1, 1]. Coefficients in
/// increasing degree of the scaled variable; `None` when there are fewer points than coefficients,
/// or a value is not finite.
pub fn polyfit(x: &[f64], y: &[f64], degree: usize) -> Option<Vec<f64>> {
    let n = x.len();
    let m = degree + 1;
    if n != y.len() || n < m || x.iter().chain(y).any(|v| !v.is_finite()) {
        return None;
    }
    let (lo, hi) = (x[0].min(x[n - 1]), x[0].max(x[n - 1]));
    if hi <= lo {
        return None;
    }
    let a = DMatrix::from_fn(n, m, |i, j| scale(x[i], lo, hi).powi(j as i32));
    let b = DVector::from_column_slice(y);
    let svd = a.svd(true, true);
    let sol = svd.solve(&b, 1e-12).ok()?;
    let coef: Vec<f64> = sol.iter().copied().collect();
    coef.iter().all(|c| c.is_finite()).then_some(coef)
}

/// Maps x from [lo, hi] onto [−1, 1].
pub fn scale(x: f64, lo: f64, hi: f64) -> f64 {
    2.0 * (x - lo) / (hi - lo) - 1.0
}

/// The derivative's coefficients.
pub fn derivative(p: &[f64]) -> Vec<f64> {
    p.iter()
        .enumerate()
        .skip(1)
        .map(|(j, c)| j as f64 * c)
        .collect()
}

/// Evaluates a polynomial (increasing degree) by Horner's rule.
pub fn eval(p: &[f64], x: f64) -> f64 {
    p.iter().rev().fold(0.0, |acc, c| acc * x + c)
}

/// Sign in {−1, 0, 1}.
pub fn sign(x: f64) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

/// Index of the largest finite value when it is unique (others more than `tie` below); `None` on a
/// tie or when nothing is finite.
pub fn unique_argmax(v: &[f64], tie: f64) -> Option<usize> {
    let (i, &best) = v
        .iter()
        .enumerate()
        .filter(|(_, x)| x.is_finite())
        .max_by(|a, b| a.1.total_cmp(b.1))?;
    let rivals = v
        .iter()
        .enumerate()
        .filter(|&(j, &x)| j != i && x.is_finite() && x >= best - tie)
        .count();
    (rivals == 0).then_some(i)
}

/// Normalises log-likelihoods into a posterior (equal priors); `None` when none is finite. The
/// posterior is the one belief type's ([`crate::sensing::belief::Belief`]): a uniform prior
/// updated by the likelihoods (a NaN counts as excluded).
pub fn posterior(ll: &[f64]) -> Option<Vec<f64>> {
    use crate::sensing::belief::{Belief, Update};
    let finite: Vec<f64> = ll
        .iter()
        .map(|&x| if x.is_finite() { x } else { f64::NEG_INFINITY })
        .collect();
    let mut b = Belief::new(&vec![1.0; ll.len()])?;
    (b.observe_log_likelihood(&finite) == Update::Updated).then(|| b.probabilities())
}

/// Below this, exp(x) is exactly +0 in floating point (e^x < the smallest subnormal's half, at
/// x ≈ −745.13).
pub const EXP_UNDERFLOW: f64 = -750.0;

/// log Σ exp(v), −∞ for an empty or all −∞ slice. A term more than −[`EXP_UNDERFLOW`] below the
/// largest is left out: its exponential is +0, which leaves the sum as it was (the largest term
/// itself is 1), so the result is that of the full sum bit for bit.
pub fn log_sum_exp(v: &[f64]) -> f64 {
    let m = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !m.is_finite() {
        return m;
    }
    m + v
        .iter()
        .filter(|&&x| x - m >= EXP_UNDERFLOW || x.is_nan())
        .map(|x| (x - m).exp())
        .sum::<f64>()
        .ln()
}

/// A decision from a posterior with the reject option: the arg-max when it reaches `reject_below`
/// and is unique, Unknown otherwise.
pub fn decide(post: Option<Vec<f64>>, reject_below: f64) -> super::Classification {
    use super::{Classification, Decision};
    let Some(p) = post else {
        return Classification::unknown();
    };
    let decision = match unique_argmax(&p, 0.0) {
        Some(i) if p[i] >= reject_below => Decision::Hypothesis(i),
        _ => Decision::Unknown,
    };
    Classification {
        decision,
        posterior: Some(p),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reading with a non-finite value anywhere (in a whole chunk of the test or in the last,
    /// shorter one) is refused; a finite one is taken as it is.
    #[test]
    fn clean_values_refuse_a_non_finite_value_anywhere() {
        let sensor = SensorSettings::default();
        let s = Sampled {
            t0: 0.0,
            dt: 1e-3,
            values: (0..150).map(|k| [k as f64 * 0.01; CHANNELS]).collect(),
        };
        assert_eq!(clean_values(&s, &sensor).unwrap().len(), 150);
        for k in [0, 1, 63, 64, 100, 127, 128, 149] {
            for c in 0..CHANNELS {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let mut t = s.clone();
                    t.values[k][c] = bad;
                    assert!(
                        clean_values(&t, &sensor).is_none(),
                        "sample {k}, channel {c}"
                    );
                }
            }
        }
    }

    #[test]
    fn polyfit_recovers_a_cubic() {
        let x: Vec<f64> = (0..50).map(|i| i as f64 * 0.1).collect();
        let y: Vec<f64> = x.iter().map(|&t| 1.0 - 2.0 * t + 0.5 * t * t * t).collect();
        let p = polyfit(&x, &y, 3).unwrap();
        for (&t, &v) in x.iter().zip(&y) {
            assert!((eval(&p, scale(t, 0.0, 4.9)) - v).abs() < 1e-9);
        }
        assert!(polyfit(&x[..3], &y[..3], 3).is_none());
    }

    #[test]
    fn detection_finds_a_pulse_and_ignores_quiet() {
        let mut v = vec![[0.0; CHANNELS]; 100];
        for s in v.iter_mut().take(70).skip(30) {
            s[0] = 0.2;
        }
        assert_eq!(detect(&v, 0.05, 5), Some((29, 70)));
        assert_eq!(detect(&vec![[0.0; CHANNELS]; 10], 0.05, 5), None);
        assert_eq!(detect(&[], 0.05, 5), None);
    }

    /// The early-stopping scan finds [`detect`]'s first sample on pulses, noise and edges.
    #[test]
    fn first_detection_is_the_full_scans_first() {
        use rand::RngExt;
        let mut rng = crate::random::stream(5, 2);
        for n in [1usize, 2, 5, 17, 300] {
            for _ in 0..50 {
                let v: Vec<[f64; CHANNELS]> = (0..n)
                    .map(|k| {
                        let pulse = if k > n / 3 && k < n / 2 { 0.3 } else { 0.0 };
                        std::array::from_fn(|_| pulse + rng.random_range(-0.08..0.08))
                    })
                    .collect();
                for w in [1, 5, 9] {
                    assert_eq!(
                        detect_first(&v, 0.05, w),
                        detect(&v, 0.05, w).map(|d| d.0),
                        "n {n}, w {w}"
                    );
                }
            }
        }
        let mut v = vec![[0.0; CHANNELS]; 100];
        v[99][1] = 1.0;
        assert_eq!(detect_first(&v, 0.05, 5), Some(97));
        assert_eq!(detect_first(&v[..99], 0.05, 5), None);
    }

    /// Terms far below the largest add exactly nothing: the sum over them is the full sum's bits.
    #[test]
    fn log_sum_exp_leaves_out_only_vanishing_terms() {
        let full = |v: &[f64]| {
            let m = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            m + v.iter().map(|x| (x - m).exp()).sum::<f64>().ln()
        };
        for v in [
            vec![0.0, -749.0, -751.0, -1e6, 3.0],
            vec![-2000.0, -1.5, -760.5, -745.0, -1.5 - 744.9],
            vec![1e5, 1e5 - 700.0, 1e5 - 800.0, f64::NEG_INFINITY],
            vec![-3.0],
        ] {
            assert_eq!(log_sum_exp(&v).to_bits(), full(&v).to_bits(), "{v:?}");
        }
        assert!((-800.0f64).exp() == 0.0 && (EXP_UNDERFLOW).exp() == 0.0);
        assert!((-745.0f64).exp() > 0.0);
        assert_eq!(log_sum_exp(&[]), f64::NEG_INFINITY);
        assert!(log_sum_exp(&[0.0, f64::NAN]).is_nan());
    }

    #[test]
    fn posterior_and_ties() {
        let p = posterior(&[0.0, 0.0, f64::NEG_INFINITY]).unwrap();
        assert_eq!(p, vec![0.5, 0.5, 0.0]);
        assert_eq!(unique_argmax(&p, 0.0), None);
        assert_eq!(unique_argmax(&[1.0, 2.0], 0.0), Some(1));
        assert!(posterior(&[f64::NAN]).is_none());
    }
}
