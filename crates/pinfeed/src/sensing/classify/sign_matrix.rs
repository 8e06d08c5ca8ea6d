//! `sign-matrix`: the thesis's empirical method (ch. 5.5, eq. 5-2, tables 5-1 and 5-2; app. D),
//! the baseline.
//!
//! **What the thesis specifies.** The raw F/T data are smoothed by a simple moving average (app.
//! D1: each value replaced by the mean of itself and the n − 1 before it); Fx and Fy are the
//! profiles compared (Fz and Tz discarded; the matrix holds Fx and Fy only); a cubic is fitted to
//! each profile by least squares (app. D2) and its 1st, 2nd and 3rd derivatives are taken; five
//! regions of points along each profile are selected and averaged; the sign matrix \[S\] (eq. 5-2)
//! is 4 × 10: columns are the five regions of Fx then the five of Fy, row 1 the signs of the
//! averaged profile values, rows 2 and 3 the signs of the averaged 1st and 2nd derivatives, row 4
//! the sign of the (constant) 3rd derivative in each profile's first column and 0 in the other
//! four. Two matrices are scored by the number of equal elements, out of 40 (so the eight zeros of
//! row 4 always match); the simulated profile with the higher score is the decision. The
//! simulated profiles are compared over the "period of contact" (iterations, not time), so
//! profiles are compared on the contact's own normalised time.
//!
//! **What we had to choose** (the thesis is silent):
//! * moving-average degree n = 5, the only value the thesis gives (app. D1's example); the first
//!   n − 1 values average what is available instead of repeating the first points;
//! * the contact is found by the shared |F| threshold detector ([`super::common`]) on the
//!   reading and, for the templates, on their noise-free samples processed the same way;
//! * the known bias and drift of the sensor settings are removed first (a tared sensor);
//! * the five regions are the five equal fifths of the detected contact; row 1 averages the
//!   smoothed samples in each fifth, rows 2–3 average the fitted cubic's derivatives over the
//!   same samples; the fit's abscissa is the contact mapped onto [−1, 1] (signs are unchanged);
//! * a sign is −1, 0 or +1 with no dead band (an average of exactly zero is 0);
//! * each hypothesis has an ensemble of simulated profiles, not one: its score is the mean /40
//!   score over its members (the thesis's single nominal profile is the one-member case);
//! * ties for the highest score → Unknown. The method has no posterior (None).

use super::common::{self, polyfit, sign};
use super::{Classification, Classifier, Decision};
use crate::sensing::reading::{self, Reading};
use crate::sensing::settings::{SensorSettings, CHANNELS};
use crate::sensing::templates::TemplateSet;

/// Moving-average degree (thesis app. D1's example).
pub const MA_DEGREE: usize = 5;
/// Number of regions per profile.
pub const REGIONS: usize = 5;

/// The 4 × 10 sign matrix (row-major).
pub type SignMatrix = [[i8; 2 * REGIONS]; 4];

/// The `sign-matrix` classifier: the thesis's sign patterns of the smoothed Fx and Fy profiles.
pub struct SignMatrixClassifier {
    /// Per hypothesis, the members' sign matrices.
    matrices: Vec<Vec<SignMatrix>>,
    sensor: SensorSettings,
}

/// Simple moving average of degree n (app. D1), trailing.
pub fn moving_average(x: &[f64], n: usize) -> Vec<f64> {
    let n = n.max(1);
    let mut out = Vec::with_capacity(x.len());
    let mut sum = 0.0;
    for k in 0..x.len() {
        sum += x[k];
        if k >= n {
            sum -= x[k - n];
        }
        out.push(sum / (k + 1).min(n) as f64);
    }
    out
}

/// The sign matrix of a contact: `values` the reading (bias removed), `contact` the detected span.
pub fn sign_matrix(values: &[[f64; CHANNELS]], contact: (usize, usize)) -> Option<SignMatrix> {
    let (b, e) = contact;
    if e < b + REGIONS.max(4) || e >= values.len() {
        return None;
    }
    let mut s: SignMatrix = [[0; 2 * REGIONS]; 4];
    for (col0, ch) in [(0usize, 0usize), (REGIONS, 1)] {
        let raw: Vec<f64> = values.iter().map(|v| v[ch]).collect();
        let smooth = moving_average(&raw, MA_DEGREE);
        let y = &smooth[b..=e];
        let x: Vec<f64> = (b..=e).map(|k| k as f64).collect();
        let p = polyfit(&x, y, 3)?;
        let d1 = common::derivative(&p);
        let d2 = common::derivative(&d1);
        let d3 = common::derivative(&d2);
        let n = y.len();
        for r in 0..REGIONS {
            let lo = r * n / REGIONS;
            let hi = ((r + 1) * n / REGIONS).max(lo + 1);
            let (mut v, mut g1, mut g2) = (0.0, 0.0, 0.0);
            for i in lo..hi {
                let u = common::scale(x[i], x[0], x[n - 1]);
                v += y[i];
                g1 += common::eval(&d1, u);
                g2 += common::eval(&d2, u);
            }
            s[0][col0 + r] = sign(v);
            s[1][col0 + r] = sign(g1);
            s[2][col0 + r] = sign(g2);
        }
        s[3][col0] = sign(common::eval(&d3, 0.0));
    }
    Some(s)
}

/// Matching elements of two sign matrices, out of 40.
pub fn score(a: &SignMatrix, b: &SignMatrix) -> usize {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .filter(|(x, y)| x == y)
        .count()
}

impl SignMatrixClassifier {
    /// Train on `templates` for `sensor` (a template whose contact the detector does not see is
    /// left out; a hypothesis left without templates scores −∞, see [`Self::scores`]).
    pub fn new(templates: &TemplateSet, sensor: &SensorSettings) -> Self {
        let thr = common::Detector::new(sensor);
        let mut matrices = Vec::new();
        for members in &templates.members {
            let mut mh = Vec::new();
            for s in members {
                let Some((_, v)) = reading::sample_clean(s, sensor, 0.5) else {
                    continue;
                };
                if let Some(m) = thr.detect(&v).and_then(|c| sign_matrix(&v, c)) {
                    mh.push(m);
                }
            }
            matrices.push(mh);
        }
        SignMatrixClassifier {
            matrices,
            sensor: *sensor,
        }
    }

    /// The mean /40 score of `m` against each hypothesis (−∞ for a hypothesis none of whose
    /// templates has a contact the detector sees: at that noise level it cannot be matched).
    pub fn scores(&self, m: &SignMatrix) -> Vec<f64> {
        self.matrices
            .iter()
            .map(|mh| {
                if mh.is_empty() {
                    f64::NEG_INFINITY
                } else {
                    mh.iter().map(|t| score(m, t) as f64).sum::<f64>() / mh.len() as f64
                }
            })
            .collect()
    }
}

impl Classifier for SignMatrixClassifier {
    fn name(&self) -> &'static str {
        "sign-matrix"
    }

    fn classify(&self, r: &Reading) -> Classification {
        let Reading::Ft(s) = r else {
            return Classification::unknown();
        };
        let Some(v) = common::clean_values(s, &self.sensor) else {
            return Classification::unknown();
        };
        let Some(m) = common::Detector::new(&self.sensor)
            .detect(&v)
            .and_then(|c| sign_matrix(&v, c))
        else {
            return Classification::unknown();
        };
        let decision = match common::unique_argmax(&self.scores(&m), 1e-9) {
            Some(h) => Decision::Hypothesis(h),
            None => Decision::Unknown,
        };
        Classification {
            decision,
            posterior: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moving_average_matches_the_definition() {
        let x = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let m = moving_average(&x, 5);
        assert_eq!(m[0], 1.0);
        assert_eq!(m[4], 3.0);
        assert_eq!(m[5], 4.0);
    }

    #[test]
    fn a_rising_convex_profile_has_the_expected_signs() {
        // Fx = t² on the contact (rising, convex), Fy = −1 (constant negative).
        let mut v = vec![[0.0; CHANNELS]; 120];
        for (k, s) in v.iter_mut().enumerate().take(110).skip(10) {
            let t = (k - 10) as f64 / 100.0 + 0.2;
            s[0] = t * t;
            s[1] = -1.0;
        }
        let m = sign_matrix(&v, (15, 109)).unwrap();
        assert_eq!(&m[0][..5], &[1, 1, 1, 1, 1]);
        assert_eq!(&m[1][..5], &[1, 1, 1, 1, 1]);
        assert_eq!(&m[2][..5], &[1, 1, 1, 1, 1]);
        assert_eq!(&m[0][5..], &[-1, -1, -1, -1, -1]);
        assert_eq!(score(&m, &m), 40);
    }
}
