//! Small statistics shared by the layers that report rates: the line's success rate, Monte Carlo
//! studies, sensor accuracies; and output analysis (docs/output-analysis.md): where a series'
//! warm-up ends ([`mser5`]), an interval for the mean of a correlated series ([`batch_means()`]),
//! and an interval for a rate that may be watched after every sample ([`confidence_sequence()`]).

pub mod batch_means;
pub mod confidence_sequence;
pub mod mser;
pub mod quantiles;

pub use batch_means::{batch_means, BatchMeans};
pub use confidence_sequence::{confidence_sequence, precise_enough};
pub use mser::{mser5, Mser, MserVerdict};
pub use quantiles::{normal_quantile, t_quantile};

/// The 50th, 90th and 99th percentiles (s) of a latency histogram recorded in whole µs, each
/// clamped into [`min`, `max`] (s), the smallest and largest latencies it summarises: an HDR
/// histogram reports a quantile as the highest value equivalent to its bucket (3 significant
/// digits), which can lie above the largest value recorded (or, for `min`, its bucket's top above
/// the least). A percentile outside the range it summarises is never reported.
pub fn latency_percentiles(h: &hdrhistogram::Histogram<u64>, min: f64, max: f64) -> [f64; 3] {
    [0.5, 0.9, 0.99].map(|p| (h.value_at_quantile(p) as f64 * 1e-6).clamp(min, max.max(min)))
}

/// The 95% Wilson score interval for `k` successes in `n` trials.
pub fn wilson_interval(k: u64, n: u64) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    let z = 1.959_963_984_540_054_f64;
    let n = n as f64;
    let p = k as f64 / n;
    let z2 = z * z;
    let denom = 1.0 + z2 / n;
    let centre = (p + z2 / (2.0 * n)) / denom;
    let half = z / denom * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    [(centre - half).max(0.0), (centre + half).min(1.0)]
}

/// The one-sided 95% Wilson lower bound of a proportion (`k` successes in `n` trials): the
/// smallest p the score test at z = 1.6449 (the normal's 95% quantile) does not reject,
/// (p̂ + z²/2n − z·√(p̂(1−p̂)/n + z²/4n²)) / (1 + z²/n); 0 for no trials. Designs are ranked by it
/// (Kehoe et al., T-ASE 2015, rank grasps by a lower confidence bound from Monte Carlo).
pub fn wilson_lower_one_sided(k: u64, n: u64) -> f64 {
    if n == 0 {
        return 0.0;
    }
    let z = 1.644_853_626_951_472_f64;
    let n = n as f64;
    let p = k as f64 / n;
    let z2 = z * z;
    let centre = p + z2 / (2.0 * n);
    let half = z * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    ((centre - half) / (1.0 + z2 / n)).max(0.0)
}

/// Series the output-analysis tests share.
#[cfg(test)]
pub(crate) mod testing {
    use rand_distr::{Distribution, StandardNormal};

    /// `n` observations of the AR(1) series xₜ = φ·xₜ₋₁ + σεₜ (ε standard normal, σ = `sd`)
    /// started in its stationary law, mean 0, from random stream (53, `seed`).
    pub fn ar1(seed: u64, phi: f64, n: usize, sd: f64) -> Vec<f64> {
        let mut rng = crate::random::stream(53, seed);
        let mut z = || -> f64 { StandardNormal.sample(&mut rng) };
        let mut x = sd * z() / (1.0 - phi * phi).sqrt();
        (0..n)
            .map(|_| {
                let now = x;
                x = phi * x + sd * z();
                now
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 28 item 4f: one latency of 13.3613 s (the quickstart line with one part) has an HDR
    /// bucket whose top is 13.3693 s; its percentiles are that latency, not the bucket's top.
    #[test]
    fn latency_percentiles_never_exceed_the_maximum() {
        let mut h =
            hdrhistogram::Histogram::<u64>::new_with_bounds(1, 1_000_000_000_000, 3).unwrap();
        h.record(13_361_300).unwrap();
        assert!(
            h.value_at_quantile(0.99) as f64 * 1e-6 > 13.3613,
            "the bucket rounds up"
        );
        assert_eq!(latency_percentiles(&h, 13.3613, 13.3613), [13.3613; 3]);
        for us in [1_000_000, 2_000_000, 13_361_300] {
            h.record(us).unwrap();
        }
        let [p50, p90, p99] = latency_percentiles(&h, 1.0, 13.3613);
        assert!(1.0 <= p50 && p50 <= p90 && p90 <= p99 && p99 <= 13.3613);
    }

    #[test]
    fn the_one_sided_lower_bound_is_the_score_test_bound() {
        // The bound is the p at which the one-sided score statistic (p̂ − p)/√(p(1−p)/n) equals
        // z: solve it for a few cases and compare.
        for (k, n) in [
            (8u64, 10u64),
            (985, 1000),
            (9_950, 10_000),
            (1, 3),
            (50, 50),
        ] {
            let lb = wilson_lower_one_sided(k, n);
            let phat = k as f64 / n as f64;
            let z = (phat - lb) / (lb * (1.0 - lb) / n as f64).sqrt();
            assert!((z - 1.644_853_6).abs() < 1e-6, "{k}/{n}: {lb} gives z {z}");
            // Looser than the two-sided 95% interval's lower end, tighter than the estimate.
            assert!(lb > wilson_interval(k, n)[0] && lb < phat, "{k}/{n}");
        }
        assert_eq!(wilson_lower_one_sided(0, 10), 0.0);
        assert_eq!(wilson_lower_one_sided(0, 0), 0.0);
    }

    #[test]
    fn wilson_matches_reference_values() {
        // 8 of 10: Wilson 95% interval (0.4902, 0.9433).
        let [lo, hi] = wilson_interval(8, 10);
        assert!(
            (lo - 0.4902).abs() < 1e-4 && (hi - 0.9433).abs() < 1e-4,
            "{lo} {hi}"
        );
        let [lo, hi] = wilson_interval(0, 20);
        assert_eq!(lo, 0.0);
        assert!((hi - 0.1611).abs() < 1e-4);
    }
}
