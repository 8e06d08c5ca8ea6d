//! Non-overlapping batch means: a confidence interval for the mean of a stationary but correlated
//! series (a simulation's output after its warm-up, [`super::mser5`]), where the textbook interval
//! of independent observations is far too narrow (Law & Kelton, "Simulation Modeling and
//! Analysis", 3rd ed. 2000, section 9.5.3; Schmeiser, "Batch size effects in the analysis of
//! simulation output", Oper. Res. 30(3), 1982, on choosing 10 to 30 batches).
//!
//! The series is cut into `b` batches of m = ⌊len/b⌋ consecutive observations (the first len mod b
//! observations, the earliest, are left out). If m is long against the series' correlation time,
//! the batch means Y₁ … Y_b are nearly independent and nearly normal, so
//! Ȳ ± t(0.975, b − 1)·S/√b, with S² the batch means' sample variance, is a 95% interval for the
//! mean. The lag-1 autocorrelation of the batch means is reported as a check: well above 0, the
//! batches are too short.

use super::t_quantile;

/// The result of [`batch_means`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BatchMeans {
    /// The grand mean of the batch means (that of the observations used); NaN without any.
    pub mean: f64,
    /// Half the width of the 95% interval: t(0.975, b − 1)·S/√b (infinite with fewer than two
    /// batches).
    pub half_width: f64,
    /// The 95% interval, [mean − half_width, mean + half_width].
    pub ci95: [f64; 2],
    /// Batches used (0 when the series is shorter than the batches asked for).
    pub batches: usize,
    /// Observations per batch.
    pub batch_size: usize,
    /// Lag-1 autocorrelation of the batch means (NaN with fewer than three batches).
    pub lag1: f64,
}

/// The non-overlapping batch means 95% interval of the mean of `series` with `batches` batches
/// (the module documentation gives the method and the references). With fewer than two batches
/// (or fewer observations than batches) the interval is the whole line.
pub fn batch_means(series: &[f64], batches: usize) -> BatchMeans {
    let size = series.len().checked_div(batches).unwrap_or(0);
    if batches < 2 || size == 0 {
        let mean = series.iter().sum::<f64>() / series.len() as f64;
        return BatchMeans {
            mean,
            half_width: f64::INFINITY,
            ci95: [f64::NEG_INFINITY, f64::INFINITY],
            batches: if size == 0 { 0 } else { batches },
            batch_size: size,
            lag1: f64::NAN,
        };
    }
    let used = &series[series.len() - batches * size..];
    let y: Vec<f64> = used
        .chunks_exact(size)
        .map(|c| c.iter().sum::<f64>() / size as f64)
        .collect();
    let b = batches as f64;
    let mean = y.iter().sum::<f64>() / b;
    let ss: f64 = y.iter().map(|v| (v - mean) * (v - mean)).sum();
    let half_width = t_quantile(0.975, batches as u64 - 1) * (ss / (b - 1.0) / b).sqrt();
    let lag1 = if batches >= 3 && ss > 0.0 {
        y.windows(2)
            .map(|w| (w[0] - mean) * (w[1] - mean))
            .sum::<f64>()
            / ss
    } else {
        f64::NAN
    };
    BatchMeans {
        mean,
        half_width,
        ci95: [mean - half_width, mean + half_width],
        batches,
        batch_size: size,
        lag1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::statistics::testing::ar1;

    #[test]
    fn a_worked_example() {
        // 0, then 1 ..= 12 in 3 batches of 4 (the leading 0 left out): means 2.5, 6.5, 10.5,
        // S = 4, half-width t(0.975, 2)·4/√3.
        let x: Vec<f64> = (0..=12).map(f64::from).collect();
        let bm = batch_means(&x, 3);
        assert_eq!((bm.batches, bm.batch_size, bm.mean), (3, 4, 6.5));
        let want = 4.302_652_729_749_464 * 4.0 / 3.0_f64.sqrt();
        assert!((bm.half_width - want).abs() < 1e-9, "{}", bm.half_width);
        assert_eq!(bm.ci95, [6.5 - bm.half_width, 6.5 + bm.half_width]);
        // Lag 1: ((−4)(0) + (0)(4)) / 32 = 0.
        assert_eq!(bm.lag1, 0.0);
    }

    #[test]
    fn too_few_batches_or_observations() {
        let bm = batch_means(&[1.0, 2.0, 3.0], 1);
        assert_eq!((bm.mean, bm.half_width), (2.0, f64::INFINITY));
        let bm = batch_means(&[1.0, 2.0, 3.0], 5);
        assert_eq!((bm.batches, bm.batch_size), (0, 0));
        assert!(bm.half_width.is_infinite());
        assert!(batch_means(&[], 0).mean.is_nan());
    }

    /// AR(1) with φ = 0.9 (correlation time about 10 observations, variance of the mean 19 times
    /// that of independent observations): over 400 seeds the 20-batch interval covers the true
    /// mean about 95% of the time (measured: 380 of 400), the naive interval x̄ ± 1.96·s/√n about
    /// 35% (P(|Z| < 1.96/√19); measured: 124 of 400).
    #[test]
    fn covers_the_mean_of_a_correlated_series() {
        let (mut batch, mut naive) = (0, 0);
        for seed in 0..400 {
            let x = ar1(7_000 + seed, 0.9, 20_000, 1.0);
            let bm = batch_means(&x, 20);
            batch += usize::from(bm.ci95[0] <= 0.0 && 0.0 <= bm.ci95[1]);
            assert!(bm.lag1.abs() < 0.8, "seed {seed}: lag-1 {}", bm.lag1);
            let n = x.len() as f64;
            let mean = x.iter().sum::<f64>() / n;
            let s2 = x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
            naive += usize::from(mean.abs() <= 1.959_964 * (s2 / n).sqrt());
        }
        assert!(
            (368..=392).contains(&batch),
            "batch means covered {batch} of 400"
        );
        assert!(naive < 240, "the naive interval covered {naive} of 400");
    }
}
