//! What a sensor reports for one pass: the sampled, noisy F/T signal or the contact instants
//! (the reading model is documented in [`super::settings`]).
//!
//! Randomness: every reading draws from the RNG it is given (the caller derives it from its own
//! seeded stream: per part and sensor in the line, per trial in `pinfeed sense`), in a fixed order —
//! the sampling phase, then per sample the channels in order, then the timing jitter — so a reading
//! is a pure function of (signal, settings, stream).

use super::settings::{SensorKind, SensorSettings, CHANNELS};
use super::signal::ContactSignal;
use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};
use serde::Serialize;

/// A sampled F/T signal: sample k is at time `t0 + k·dt` (s since the pass began).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sampled {
    /// Time of the first sample (s since the pass began).
    pub t0: f64,
    /// Sampling period (s).
    pub dt: f64,
    /// Channels Fx, Fy, Fz (N), Tx, Ty, Tz (N·mm) per sample.
    pub values: Vec<[f64; CHANNELS]>,
}

impl Sampled {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.values.len()
    }
    /// No samples?
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
    /// Time of sample k.
    pub fn time(&self, k: usize) -> f64 {
        self.t0 + k as f64 * self.dt
    }
    /// One channel as a vector.
    pub fn channel(&self, c: usize) -> Vec<f64> {
        self.values.iter().map(|v| v[c]).collect()
    }
}

/// Contact instants reported by a timing sensor: each detected contact as (begin, end) in seconds
/// since the pass began, jitter included. Empty when |F| never crossed the threshold.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct ContactTimes {
    /// Each detected contact as (begin, end) (s since the pass began).
    pub intervals: Vec<(f64, f64)>,
}

impl ContactTimes {
    /// Total detected contact time (s).
    pub fn duration(&self) -> f64 {
        self.intervals.iter().map(|(b, e)| e - b).sum()
    }
    /// The detected durations, in order.
    pub fn durations(&self) -> Vec<f64> {
        self.intervals.iter().map(|(b, e)| e - b).collect()
    }
}

/// One sensor's reading of one pass.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Reading {
    /// A force/torque sensor's sampled signal.
    Ft(Sampled),
    /// A timing sensor's contact instants.
    Timing(ContactTimes),
}

/// Time (s) sampled before the first contact and after the last one: a fifth of the contact time,
/// at least 20 ms and 10 sample periods (a detector needs quiet on both sides of the contact).
pub fn padding(signal: &ContactSignal, rate: f64) -> f64 {
    (0.2 * signal.duration()).max(0.02).max(10.0 / rate)
}

/// The largest number of samples one reading may hold (memory bound: 2·10⁵ samples of 6 channels,
/// 9.6 MB; e.g. 200 s of contact at 1 kHz). A longer window is not read (the sensor reports nothing).
pub const MAX_SAMPLES: usize = 200_000;
/// The most samples a classifier's training may draw over all its templates (10⁷ samples of 6
/// channels: bounded time and memory); a larger set is refused with a message naming the sizes.
pub const MAX_TEMPLATE_SAMPLES: usize = 10_000_000;

/// Samples a reading of `signal` at `rate` would hold (0 without contact).
pub fn samples_needed(signal: &ContactSignal, rate: f64) -> usize {
    match signal.span() {
        Some((b, e)) => (((e - b) + 2.0 * padding(signal, rate)) * rate).ceil() as usize + 1,
        None => 0,
    }
}

/// The sampling window of a reading of `signal` at `rate` with sampling phase `phase` ∈ [0, 1)
/// (a fraction of the period): the time of sample 0 and the number of samples, covering the
/// contact and [`padding`] either side. `None` when the pin never touched or the window would
/// exceed [`MAX_SAMPLES`].
pub fn window(signal: &ContactSignal, rate: f64, phase: f64) -> Option<(f64, usize)> {
    let (b, e) = signal.span()?;
    let pad = padding(signal, rate);
    let dt = 1.0 / rate;
    let start = b - pad;
    let n = (((e + pad) - start) / dt).ceil() as usize + 1;
    (n <= MAX_SAMPLES).then_some((start + phase * dt, n))
}

/// The sensor's first-order low-pass (if any), in place: y_k = y_{k−1} + α (x_k − y_{k−1}),
/// y_0 = x_0, α = 1 − e^{−2π f_c / rate}.
pub fn lowpass(values: &mut [[f64; CHANNELS]], sensor: &SensorSettings) {
    let Some(fc) = sensor.lowpass else { return };
    let a = 1.0 - (-2.0 * std::f64::consts::PI * fc / sensor.rate).exp();
    for k in 1..values.len() {
        let prev = values[k - 1];
        for (x, p) in values[k].iter_mut().zip(prev) {
            *x = p + a * (*x - p);
        }
    }
}

/// The noise-free reading of `signal` (the sensor's low-pass applied, nothing else) over the
/// [`window`] with sampling phase `phase`: the time of sample 0 and the samples. What a classifier's
/// templates look like to this sensor.
pub fn sample_clean(
    signal: &ContactSignal,
    sensor: &SensorSettings,
    phase: f64,
) -> Option<(f64, Vec<[f64; CHANNELS]>)> {
    let (t0, n) = window(signal, sensor.rate, phase)?;
    let dt = 1.0 / sensor.rate;
    let mut values = signal.sample(t0, dt, n);
    lowpass(&mut values, sensor);
    Some((t0, values))
}

/// Samples `signal` with `sensor` (noise, bias, drift, low-pass, quantisation) over the
/// [`window`], with a sampling phase drawn uniformly; `None` when the pin never touched or the
/// window would exceed [`MAX_SAMPLES`].
pub fn sample_ft(
    signal: &ContactSignal,
    sensor: &SensorSettings,
    rng: &mut impl rand::Rng,
) -> Option<Sampled> {
    let phase: f64 = rng.random::<f64>();
    let (t0, n) = window(signal, sensor.rate, phase)?;
    let dt = 1.0 / sensor.rate;
    let mut values = signal.sample(t0, dt, n);
    // The channels' settings, looked up once rather than per sample.
    let noise: [f64; CHANNELS] = std::array::from_fn(|c| sensor.noise(c));
    let bias: [f64; CHANNELS] = std::array::from_fn(|c| sensor.bias(c));
    let drift: [f64; CHANNELS] = std::array::from_fn(|c| sensor.drift(c));
    let resolution: [f64; CHANNELS] = std::array::from_fn(|c| sensor.resolution(c));
    for (k, v) in values.iter_mut().enumerate() {
        let elapsed = k as f64 * dt;
        for (c, x) in v.iter_mut().enumerate() {
            let noise = if noise[c] > 0.0 {
                let z: f64 = StandardNormal.sample(rng);
                noise[c] * z
            } else {
                0.0
            };
            *x += bias[c] + drift[c] * elapsed + noise;
        }
    }
    lowpass(&mut values, sensor);
    if resolution.iter().any(|&q| q > 0.0) {
        for v in &mut values {
            for (x, &q) in v.iter_mut().zip(&resolution) {
                if q > 0.0 {
                    *x = q * round_half_away(*x / q);
                }
            }
        }
    }
    Some(Sampled { t0, dt, values })
}

/// `y.round()` (to the nearest integer, halves away from zero), bit for bit, without the call to
/// the library's `round` the baseline x86-64 target makes: below 2⁵² the integer part is the
/// truncating conversion's, the fraction `|y| − t` is exact (Sterbenz), and so is `t + 1`.
#[inline]
fn round_half_away(y: f64) -> f64 {
    let a = y.abs();
    // From 2⁵² on every f64 is an integer; NaN and ±∞ pass through as `round` leaves them.
    if a >= 4_503_599_627_370_496.0 || a.is_nan() {
        return y;
    }
    let t = a as i64 as f64;
    let r = if a - t >= 0.5 { t + 1.0 } else { t };
    r.copysign(y)
}

/// The contact instants of a timing sensor: where the clean |F| crosses the threshold (located to
/// 1e-9 s by bisection between the signal's knots), each with Gaussian jitter.
pub fn sample_timing(
    signal: &ContactSignal,
    sensor: &SensorSettings,
    rng: &mut impl rand::Rng,
) -> ContactTimes {
    let mut intervals = Vec::new();
    for &(b, e) in &signal.contacts {
        // Crossings of |F| = threshold inside [b, e], scanned on a grid fine enough for the
        // contact (256 cells) and refined by bisection.
        let above = |t: f64| signal.force_magnitude(t) >= sensor.threshold;
        let n = 256;
        let h = (e - b) / n as f64;
        let mut begin: Option<f64> = None;
        let mut prev = above(b);
        if prev {
            begin = Some(b);
        }
        for k in 1..=n {
            let t = if k == n { e } else { b + k as f64 * h };
            let now = above(t);
            if now != prev {
                let tc = bisect(&above, t - h, t, prev);
                if now {
                    begin = Some(tc);
                } else if let Some(tb) = begin.take() {
                    intervals.push((tb, tc));
                }
            }
            prev = now;
        }
        if let Some(tb) = begin {
            intervals.push((tb, e));
        }
    }
    let mut jittered = Vec::with_capacity(intervals.len());
    for (tb, te) in intervals {
        let (zb, ze): (f64, f64) = (StandardNormal.sample(rng), StandardNormal.sample(rng));
        let (jb, je) = (tb + sensor.jitter * zb, te + sensor.jitter * ze);
        jittered.push((jb, je.max(jb)));
    }
    ContactTimes {
        intervals: jittered,
    }
}

fn bisect(above: &impl Fn(f64) -> bool, mut lo: f64, mut hi: f64, lo_state: bool) -> f64 {
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if above(mid) == lo_state {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-9 {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// The reading of `sensor` for one pass: F/T samples or contact instants by the sensor's kind.
/// `None` for an F/T sensor whose pin never touched (nothing to read) or whose window is too long.
pub fn read(
    signal: &ContactSignal,
    sensor: &SensorSettings,
    rng: &mut impl rand::Rng,
) -> Option<Reading> {
    match sensor.kind {
        SensorKind::Ft => sample_ft(signal, sensor, rng).map(Reading::Ft),
        SensorKind::Timing => Some(Reading::Timing(sample_timing(signal, sensor, rng))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    #[test]
    fn round_half_away_is_round_bit_for_bit() {
        let two52 = 4_503_599_627_370_496.0_f64;
        let mut cases = vec![
            0.0,
            0.5,
            1.5,
            2.5,
            0.499_999_999_999_999_94,
            1.0 - f64::EPSILON / 2.0,
            two52 - 0.5,
            two52 - 1.0,
            two52,
            two52 + 1.0,
            2.0 * two52,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            f64::INFINITY,
            1e-3 / 3e-3,
            0.0125 / 0.001,
        ];
        let mut rng = crate::random::stream(7, 0);
        for _ in 0..200_000 {
            cases.push(f64::from_bits(rng.random::<u64>()));
            cases.push(rng.random::<f64>() * 100.0);
            cases.push((rng.random_range(0..2000) as f64) * 0.5);
            cases.push(rng.random::<f64>() * 1e16);
        }
        for y in cases.iter().flat_map(|&y| [y, -y]) {
            let (a, b) = (round_half_away(y), y.round());
            assert!(
                a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                "{y:e}: {a:e} vs {b:e}"
            );
        }
    }
}
