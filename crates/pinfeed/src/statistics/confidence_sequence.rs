//! An anytime-valid confidence sequence for a Bernoulli rate: intervals CSₙ, one after every
//! observation, that all contain the true rate at once with probability at least 1 − α, so they
//! may be watched continuously and the sampling stopped whenever they are narrow enough — what
//! a fixed-n interval (Wilson's) does not allow: checked after every observation, it excludes the
//! true rate at some n far more often than α.
//!
//! The construction is Robbins' beta-binomial mixture (H. Robbins, "Statistical methods related to
//! the law of the iterated logarithm", Ann. Math. Statist. 41(5), 1970), in the form of Howard,
//! Ramdas, McAuliffe & Sekhon, "Time-uniform, nonparametric, nonasymptotic confidence sequences",
//! Ann. Statist. 49(2), 2021: after k successes in n trials, for each candidate p,
//!
//! Mₙ(p) = [B(a + k, b + n − k) / B(a, b)] / [pᵏ (1 − p)ⁿ⁻ᵏ]
//!
//! is a nonnegative martingale with M₀ = 1 under the rate p (the likelihood of a Beta(a, b) mixture
//! of rates over that of p), so by Ville's inequality P(∃n: Mₙ(p) ≥ 1/α) ≤ α and
//! CSₙ = {p : Mₙ(p) < 1/α} is a (1 − α) confidence sequence. With the uniform prior a = b = 1
//! ([`confidence_sequence`]) it reads CSₙ = {p : (n + 1)·C(n, k)·pᵏ(1 − p)ⁿ⁻ᵏ > α}, the sequence
//! Ding, Gandy & Hahn's confidence sequence method (CSM) stops a sequential Monte Carlo test on
//! ("A simple method for implementing Monte Carlo tests", Comput. Stat. 35, 2020), the
//! sequential-testing lineage this follows.
//!
//! log Mₙ(p) is convex in p with its least value, at most 0, at p̂ = k/n, so CSₙ is an interval
//! around p̂ whose ends are the two roots of log Mₙ(p) = ln(1/α); each is found by bisection on its
//! side of p̂ with the martingale evaluated in logarithms (log-beta from [`libm::lgamma`]) and a
//! fixed bound on the steps, so no input (n = 0, k = 0, k = n, NaN) can make it loop.

/// ln B(x, y) = ln Γ(x) + ln Γ(y) − ln Γ(x + y), for x, y > 0, without the cancellation of the
/// three log-gammas when one argument is huge: ln Γ(x) − ln Γ(x + y) for the larger argument x ≥ 10
/// is taken from Stirling's series as −(x − ½)·ln(1 + y/x) − y·ln(x + y) + y plus the difference of
/// the series' remainders (so B(10¹⁵, 1) = 10⁻¹⁵ is not lost to the rounding of ln Γ(10¹⁵) ≈ 3·10¹⁶).
pub fn ln_beta(x: f64, y: f64) -> f64 {
    let (large, small) = if x >= y { (x, y) } else { (y, x) };
    libm::lgamma(small) + ln_gamma_ratio(large, small)
}

/// ln Γ(x) − ln Γ(x + y) for x, y > 0.
fn ln_gamma_ratio(x: f64, y: f64) -> f64 {
    if x < 10.0 {
        return libm::lgamma(x) - libm::lgamma(x + y);
    }
    // ln Γ(z) = (z − ½) ln z − z + ½ ln 2π + ω(z), with Stirling's remainder ω for z ≥ 10 to 1e-13.
    let omega = |z: f64| {
        let r = 1.0 / (z * z);
        (1.0 / 12.0 - r * (1.0 / 360.0 - r * (1.0 / 1260.0 - r / 1680.0))) / z
    };
    -(x - 0.5) * (y / x).ln_1p() - y * (x + y).ln() + y + omega(x) - omega(x + y)
}

/// Bisection steps at most per end (a double has 1074 binary digits below 1; the ends are found to
/// about 1e-16 after some 60 steps, and the search stops when the midpoint stops moving).
const MAX_STEPS: usize = 200;

/// The (1 − `alpha`) confidence sequence of a Bernoulli rate after `k` successes in `n` trials,
/// [low, high]: Robbins' beta-binomial mixture with the uniform prior (a = b = 1; the module
/// documentation gives the construction and the references). Contains k/n; [0, 1] for n = 0, or an
/// `alpha` outside (0, 1) or NaN; `k` above `n` is taken as `n`.
pub fn confidence_sequence(k: u64, n: u64, alpha: f64) -> [f64; 2] {
    confidence_sequence_with_prior(k, n, alpha, 1.0, 1.0)
}

/// [`confidence_sequence`] with a Beta(`a`, `b`) mixing prior (a, b > 0; [0, 1] otherwise): a
/// prior with more mass near a rate makes the sequence narrower there and wider elsewhere
/// (Howard et al. 2021, section 3).
pub fn confidence_sequence_with_prior(k: u64, n: u64, alpha: f64, a: f64, b: f64) -> [f64; 2] {
    let usable = |x: f64| x > 0.0 && x.is_finite();
    let alpha_usable = alpha > 0.0 && alpha < 1.0;
    if n == 0 || !alpha_usable || !usable(a) || !usable(b) {
        return [0.0, 1.0];
    }
    let k = k.min(n);
    let (kf, mf) = (k as f64, (n - k) as f64);
    let log_mixture = ln_beta(a + kf, b + mf) - ln_beta(a, b);
    let threshold = -alpha.ln();
    // ln Mₙ(p) − ln(1/α), with 0·ln 0 = 0: positive outside the sequence, negative inside.
    let excess = |p: f64| {
        let s = if k > 0 { kf * p.ln() } else { 0.0 };
        let f = if k < n { mf * (-p).ln_1p() } else { 0.0 };
        log_mixture - s - f - threshold
    };
    let centre = kf / n as f64;
    if excess(centre) >= 0.0 {
        // Only for α so near 1 that rounding decides: the sequence is the estimate alone.
        return [centre, centre];
    }
    let low = if k == 0 {
        0.0
    } else {
        boundary(&excess, 0.0, centre)
    };
    let high = if k == n {
        1.0
    } else {
        boundary(&excess, 1.0, centre)
    };
    [low, high]
}

/// The root of `excess` between `outside` (where it is positive or infinite) and `inside` (where
/// it is negative), by bisection; returns the last point found outside, so the interval is never
/// narrower than the exact one.
fn boundary(excess: &dyn Fn(f64) -> f64, mut outside: f64, mut inside: f64) -> f64 {
    for _ in 0..MAX_STEPS {
        let mid = 0.5 * (outside + inside);
        if mid == outside || mid == inside {
            break;
        }
        // NaN counts as outside, so a NaN never narrows the interval.
        if excess(mid) < 0.0 {
            inside = mid;
        } else {
            outside = mid;
        }
    }
    outside
}

/// Whether the (1 − `alpha`) [`confidence_sequence`] after `k` successes in `n` trials has a
/// half-width, (high − low)/2, of at most `half_width`: the stopping rule of a run that samples
/// until its rate is known to ± `half_width`. Because the sequence holds at every n at once, the
/// interval at the stop is a valid (1 − α) interval however the stop was chosen. False for a NaN
/// `half_width`.
pub fn precise_enough(k: u64, n: u64, alpha: f64, half_width: f64) -> bool {
    let [low, high] = confidence_sequence(k, n, alpha);
    0.5 * (high - low) <= half_width
}

/// One minus the confidence of the sequences the sequential runs stop on (95%): `mc --precision`
/// and `run --precision`.
pub const ALPHA: f64 = 0.05;

/// Why a sequential run stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stop {
    /// The confidence sequence's half-width reached the precision asked for.
    Precision,
    /// The samples or parts allowed (the cap) were spent first.
    Cap,
}

impl Stop {
    /// `precision` or `cap`.
    pub fn name(self) -> &'static str {
        match self {
            Stop::Precision => "precision",
            Stop::Cap => "cap",
        }
    }
}

/// Check a `--precision` value: a half-width of a rate, in (0, 0.5).
pub fn check_precision(e: f64) -> Result<f64, String> {
    if e > 0.0 && e < 0.5 {
        Ok(e)
    } else {
        Err(format!(
            "--precision must lie in (0, 0.5) (the half-width of the success rate's 95% confidence sequence), got {e}"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::statistics::wilson_interval;
    use rand::RngExt;

    /// (n + 1)·C(n, k)·pᵏ(1 − p)ⁿ⁻ᵏ with the binomial coefficient as an exact product (no log-gamma).
    fn robbins(k: u64, n: u64, p: f64) -> f64 {
        let c: f64 = (1..=k).map(|i| (n - k + i) as f64 / i as f64).product();
        (n + 1) as f64 * c * p.powi(k as i32) * (1.0 - p).powi((n - k) as i32)
    }

    #[test]
    fn log_beta_is_exact_for_small_and_huge_arguments() {
        let cases = [
            (2.0, 3.0, (1.0_f64 / 12.0).ln()),
            (0.5, 0.5, std::f64::consts::PI.ln()),
            (1.0, 1e15, -(1e15_f64.ln())),
            (1e15, 1.0, -(1e15_f64.ln())),
            (1e12 + 1.0, 2.0, -((1e12_f64 + 1.0) * (1e12 + 2.0)).ln()),
            // B(11, 21) = 10!·20!/31!, and a case across the Stirling threshold.
            (11.0, 21.0, ln_fact(10) + ln_fact(20) - ln_fact(31)),
            (
                9.5,
                30.0,
                libm::lgamma(9.5) + libm::lgamma(30.0) - libm::lgamma(39.5),
            ),
        ];
        for (x, y, want) in cases {
            let got = ln_beta(x, y);
            assert!(
                (got - want).abs() < 1e-9 * want.abs().max(1.0),
                "B({x}, {y}): {got} {want}"
            );
        }
    }

    /// ln n! as a sum of logarithms.
    fn ln_fact(n: u64) -> f64 {
        (2..=n).map(|i| (i as f64).ln()).sum()
    }

    #[test]
    fn the_ends_solve_robbins_equation() {
        for (k, n) in [(7u64, 20u64), (1, 3), (0, 10), (10, 10), (30, 40), (2, 50)] {
            let [lo, hi] = confidence_sequence(k, n, 0.05);
            for end in [lo, hi] {
                if end > 0.0 && end < 1.0 {
                    let v = robbins(k, n, end);
                    assert!((v - 0.05).abs() < 1e-9, "{k}/{n}: at {end} {v}");
                }
            }
            // Just inside the ends, the statistic is above α; just outside, below.
            let inside = [lo + 1e-6, hi - 1e-6];
            assert!(inside.iter().all(|&p| robbins(k, n, p) > 0.05), "{k}/{n}");
            assert!(lo == 0.0 || robbins(k, n, lo - 1e-6) < 0.05, "{k}/{n}");
            assert!(hi == 1.0 || robbins(k, n, hi + 1e-6) < 0.05, "{k}/{n}");
        }
        // (n + 1)(1 − p)ⁿ = α at the upper end for k = 0: closed form.
        let [lo, hi] = confidence_sequence(0, 10, 0.05);
        assert_eq!(lo, 0.0);
        assert!((hi - (1.0 - (0.05_f64 / 11.0).powf(0.1))).abs() < 1e-12);
    }

    #[test]
    fn contains_the_estimate_and_narrows_with_n() {
        let mut last = f64::INFINITY;
        for n in [
            4u64,
            40,
            400,
            4_000,
            40_000,
            400_000,
            4_000_000,
            1_000_000_000,
        ] {
            for k in [0, 1, n / 4, n / 2, n - 1, n] {
                let [lo, hi] = confidence_sequence(k, n, 0.05);
                let p = k as f64 / n as f64;
                assert!(0.0 <= lo && lo <= p && p <= hi && hi <= 1.0, "{k}/{n}");
            }
            let [lo, hi] = confidence_sequence(n / 4, n, 0.05);
            assert!(hi - lo < last, "n {n}: width {} after {last}", hi - lo);
            last = hi - lo;
        }
        // A smaller α is a wider sequence.
        let [a, b] = confidence_sequence(30, 100, 0.05);
        let [c, d] = confidence_sequence(30, 100, 0.01);
        assert!(c < a && d > b);
    }

    /// The price of watching continuously: wider than the fixed-n 95% interval.
    #[test]
    fn wider_than_wilson() {
        for (k, n) in [
            (1u64, 1u64),
            (8, 10),
            (50, 100),
            (985, 1000),
            (2_500, 10_000),
            (0, 300),
        ] {
            let [lo, hi] = confidence_sequence(k, n, 0.05);
            let [wlo, whi] = wilson_interval(k, n);
            assert!(
                lo <= wlo && hi >= whi,
                "{k}/{n}: [{lo}, {hi}] against [{wlo}, {whi}]"
            );
            // Strictly wider at every end not pinned at 0 or 1.
            assert!(lo < wlo || wlo == 0.0, "{k}/{n}");
            assert!(hi > whi || whi == 1.0, "{k}/{n}");
            assert!(hi - lo > whi - wlo, "{k}/{n}");
        }
    }

    #[test]
    fn degenerate_inputs_answer_at_once() {
        assert_eq!(confidence_sequence(0, 0, 0.05), [0.0, 1.0]);
        assert_eq!(confidence_sequence(3, 0, 0.05), [0.0, 1.0]);
        for alpha in [0.0, 1.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(confidence_sequence(3, 10, alpha), [0.0, 1.0], "{alpha}");
        }
        assert_eq!(
            confidence_sequence_with_prior(3, 10, 0.05, f64::NAN, 1.0),
            [0.0, 1.0]
        );
        assert_eq!(
            confidence_sequence(12, 10, 0.05),
            confidence_sequence(10, 10, 0.05)
        );
        let [lo, hi] = confidence_sequence(10, 10, 0.05);
        assert!(lo > 0.0 && hi == 1.0);
        let [lo, hi] = confidence_sequence(u64::MAX, u64::MAX, 0.05);
        assert!(lo > 0.99 && hi == 1.0);
        assert!(!precise_enough(3, 10, 0.05, f64::NAN));
        assert!(precise_enough(0, 0, 0.05, 0.5) && !precise_enough(0, 0, 0.05, 0.49));
    }

    /// Bernoulli(`p`) streams of stream `seed`, checked after every observation up to `max`:
    /// whether each ever excluded `p` from `interval` before it stopped (`stop` after n trials
    /// with k successes), and the number of trials at the stop.
    fn watch(
        streams: u64,
        p: f64,
        max: u64,
        interval: &dyn Fn(u64, u64) -> [f64; 2],
        stop: &dyn Fn(u64, u64) -> bool,
    ) -> (Vec<bool>, Vec<u64>) {
        let (mut missed, mut used) = (Vec::new(), Vec::new());
        for s in 0..streams {
            let mut rng = crate::random::stream(53, s);
            let (mut k, mut miss) = (0u64, false);
            let mut n = 0;
            while n < max {
                n += 1;
                k += u64::from(rng.random::<f64>() < p);
                let [lo, hi] = interval(k, n);
                miss |= p < lo || p > hi;
                if stop(k, n) {
                    break;
                }
            }
            missed.push(miss);
            used.push(n);
        }
        (missed, used)
    }

    /// Time-uniform coverage: 200 streams watched after every observation and stopped when the
    /// half-width is at most 0.05 (after about 1000 observations); the stopped interval holds the
    /// true rate in at least 95% of them — indeed in 95% of them no interval ever misses it
    /// (measured: 200 of 200 stopped intervals hold it, 8 of 200 streams miss it at some n) —
    /// while Wilson's fixed-n interval, watched the same way for 1000 observations, misses it at
    /// some n in far more (measured: 103 of 200).
    #[test]
    fn watching_after_every_observation_keeps_coverage() {
        let p = 0.3;
        let cs = |k, n| confidence_sequence(k, n, 0.05);
        let (missed, used) = watch(200, p, 5_000, &cs, &|k, n| precise_enough(k, n, 0.05, 0.05));
        let ever = missed.iter().filter(|&&m| m).count();
        assert!(ever <= 10, "{ever} of 200 streams missed p at some n");
        assert!(
            used.iter().all(|&n| n < 5_000),
            "every stream stopped on precision"
        );
        let mean = used.iter().sum::<u64>() as f64 / 200.0;
        assert!((300.0..1_500.0).contains(&mean), "mean stop {mean}");
        // The stopped intervals, recomputed at the stop, hold p in at least 190 of 200.
        let mut held = 0;
        for (s, &n) in used.iter().enumerate() {
            let mut rng = crate::random::stream(53, s as u64);
            let k = (0..n).filter(|_| rng.random::<f64>() < p).count() as u64;
            let [lo, hi] = cs(k, n);
            held += usize::from(lo <= p && p <= hi);
        }
        assert!(held >= 190, "{held} of 200 stopped intervals hold p");
        let (wilson_missed, _) = watch(200, p, 1_000, &wilson_interval, &|_, _| false);
        let w = wilson_missed.iter().filter(|&&m| m).count();
        assert!(
            w > 40,
            "Wilson watched continuously missed in only {w} of 200"
        );
    }
}
