//! The force/torque signal of one pin pass, taken from the push itself (docs/physics.md#sensing; thesis ch. 5).
//!
//! The contact model's [`Recorder`] receives a knot at the start of every contact, at every
//! accepted integration step, and on both sides of every event (mode switch, feature change), so the
//! knots resolve the force to the integrator's own error control: where the motion changes fast the
//! steps are short. Recording only observes: the step sequence and the outcome are those of the same
//! push without a recorder (a test checks this bit for bit). Between knots of one smooth stretch
//! (one feature, one mode) each channel is interpolated with a monotone cubic (Fritsch–Carlson
//! PCHIP), so sampling at any sensor rate costs no further solves; at an event the signal jumps, and
//! outside contact it is zero. `tests/sensing_signal.rs` measures the interpolation against a push
//! resolved with 10⁴× tighter tolerance.
//!
//! Units and frames: time t in seconds since the pass began (pin travel / belt speed), world axes
//! (x along belt travel, y left, z up). The force on the pin is F = −f, with f the force the pin
//! applies to the part (the contact model's force, in units of μs m g, times μs m g in newtons).
//! The torques about the sensor origin, on the pin's axis at height h above the contact plane, are
//! T = r × F with r = (p − c_pin, −h) (docs/physics.md#sensing; for a point pin p = c_pin), in N·mm:
//! Tx = h Fy, Ty = −h Fx, Tz = r_x F_y − r_y F_x (the contact friction's moment on a disc pin).

use super::settings::CHANNELS;
use crate::geometry::Vec2;
use crate::mechanics::{ContactFeature, ContactOutcome, Mode, Recorder, TraceSample};
use serde::Serialize;

/// Standard gravity (m/s²).
pub const GRAVITY: f64 = 9.80665;

/// Collects the knots of a pass (a [`Recorder`]): every sample the integrator reports.
#[derive(Debug, Default, Clone)]
pub struct KnotRecorder {
    /// Every sample the integrator reported, in order.
    pub samples: Vec<TraceSample>,
}

impl Recorder for KnotRecorder {
    fn record(&mut self, sample: &TraceSample) {
        self.samples.push(*sample);
    }
}

/// Physical constants that turn the contact model's dimensionless force into a sensor signal.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SignalScale {
    /// Part mass (kg).
    pub mass: f64,
    /// Belt speed (m/s): time = travel / speed.
    pub belt_speed: f64,
    /// Height (m) of the sensor origin above the contact plane.
    pub height: f64,
    /// Metres per unit of the caller's lengths (the trace's units).
    pub metres_per_unit: f64,
}

/// One smooth stretch of force: knot times and channel values.
#[derive(Debug, Clone, PartialEq, Serialize)]
struct Run {
    t: Vec<f64>,
    v: Vec<[f64; CHANNELS]>,
    /// PCHIP slopes per knot and channel.
    m: Vec<[f64; CHANNELS]>,
}

/// The clean (noise-free, continuous-time) signal of one pass.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactSignal {
    runs: Vec<Run>,
    /// Contact intervals [t_begin, t_end] (s since the pass began), in order.
    pub contacts: Vec<(f64, f64)>,
    /// The part feature the pin first touched (vertex or edge), if it touched.
    pub first_feature: Option<ContactFeature>,
    /// Number of knots (integrator samples) the signal was built from.
    pub knots: usize,
}

/// The channel values of one trace sample: force on the pin (N) and torques about the sensor
/// origin (N·mm).
pub fn channels(sample: &TraceSample, scale: &SignalScale) -> [f64; CHANNELS] {
    let weight = scale.mass * GRAVITY;
    let f: Vec2 = -(sample.force * weight);
    let r = (sample.contact_point - sample.pin_centre) * scale.metres_per_unit;
    let h = scale.height;
    // T = r × F with r = (r.x, r.y, −h), F = (Fx, Fy, 0); N·m → N·mm.
    let tx = h * f.y;
    let ty = -h * f.x;
    let tz = r.x * f.y - r.y * f.x;
    [f.x, f.y, 0.0, 1e3 * tx, 1e3 * ty, 1e3 * tz]
}

impl ContactSignal {
    /// Builds the signal of a pass from its outcome and the knots its recorder collected.
    pub fn new(outcome: &ContactOutcome, samples: &[TraceSample], scale: &SignalScale) -> Self {
        let to_t = |s: f64| s * scale.metres_per_unit / scale.belt_speed;
        // Contact intervals: consecutive segments that join end to start form one contact.
        let mut contacts: Vec<(f64, f64)> = Vec::new();
        for seg in &outcome.segments {
            let (b, e) = (to_t(seg.s_begin), to_t(seg.s_end));
            match contacts.last_mut() {
                Some(last) if (b - last.1).abs() <= 1e-12 * b.abs().max(1.0) => last.1 = e,
                _ => contacts.push((b, e)),
            }
        }
        let mut runs: Vec<Run> = Vec::new();
        let mut key: Option<(ContactFeature, Mode)> = None;
        for sm in samples {
            let t = to_t(sm.s);
            let k = (sm.feature, sm.mode);
            let same = key == Some(k)
                && runs
                    .last()
                    .and_then(|r| r.t.last())
                    .is_some_and(|&tl| t > tl);
            if !same {
                runs.push(Run {
                    t: Vec::new(),
                    v: Vec::new(),
                    m: Vec::new(),
                });
                key = Some(k);
            }
            let run = runs.last_mut().expect("a run was opened");
            run.t.push(t);
            run.v.push(channels(sm, scale));
        }
        for run in &mut runs {
            run.m = pchip_slopes(&run.t, &run.v);
        }
        ContactSignal {
            runs,
            contacts,
            first_feature: outcome.segments.first().map(|s| s.feature),
            knots: samples.len(),
        }
    }

    /// Is the pin touching the part at time t?
    pub fn in_contact(&self, t: f64) -> bool {
        self.contacts.iter().any(|&(b, e)| t >= b && t <= e)
    }

    /// Total time in contact (s).
    pub fn duration(&self) -> f64 {
        self.contacts.iter().map(|(b, e)| e - b).sum()
    }

    /// First contact begin and last contact end (s), if the pin touched.
    pub fn span(&self) -> Option<(f64, f64)> {
        Some((self.contacts.first()?.0, self.contacts.last()?.1))
    }

    /// The clean channels at time t: zero outside contact, the interpolated force inside.
    pub fn at(&self, t: f64) -> [f64; CHANNELS] {
        if !self.in_contact(t) {
            return [0.0; CHANNELS];
        }
        // The last run whose knots cover t (a later run starts where an event put the state).
        let run =
            self.runs.iter().rev().find(|r| {
                r.t.first().is_some_and(|&a| a <= t) && r.t.last().is_some_and(|&b| t <= b)
            });
        match run {
            Some(r) => r.eval(t),
            // A contact instant covered by no run of two knots: the nearest knot's value.
            None => self.nearest(t),
        }
    }

    /// The clean channels at t0, t0 + dt, …, n samples: the same values as [`Self::at`] at each
    /// instant, found by walking the contacts and runs once instead of searching them per sample.
    ///
    /// The sample times never decrease (`dt` ≥ 0), so the knot interval of the current run is
    /// found by walking forward from the previous sample's, not by a binary search.
    pub fn sample(&self, t0: f64, dt: f64, n: usize) -> Vec<[f64; CHANNELS]> {
        let mut walk = Walk::default();
        (0..n).map(|k| walk.at(self, t0 + k as f64 * dt)).collect()
    }

    /// [`Self::at`] at each of `times`, bit for bit: walked as by [`Self::sample`] while the
    /// times do not decrease (and the contacts and runs follow each other in time, as a pass
    /// records them), else searched per time.
    pub fn at_each(&self, times: impl IntoIterator<Item = f64>) -> Vec<[f64; CHANNELS]> {
        let ordered = self
            .contacts
            .windows(2)
            .all(|w| w[0].0 <= w[1].0 && w[0].1 <= w[1].1)
            && self.runs.windows(2).all(|w| w[0].t[0] <= w[1].t[0]);
        let mut walk = Walk::default();
        let mut last = f64::NEG_INFINITY;
        times
            .into_iter()
            .map(|t| {
                if ordered && t >= last {
                    last = t;
                    walk.at(self, t)
                } else {
                    self.at(t)
                }
            })
            .collect()
    }

    fn nearest(&self, t: f64) -> [f64; CHANNELS] {
        let mut best = (f64::INFINITY, [0.0; CHANNELS]);
        for r in &self.runs {
            for (ti, vi) in r.t.iter().zip(&r.v) {
                if (ti - t).abs() < best.0 {
                    best = ((ti - t).abs(), *vi);
                }
            }
        }
        best.1
    }

    /// |(Fx, Fy, Fz)| at time t (N).
    pub fn force_magnitude(&self, t: f64) -> f64 {
        let v = self.at(t);
        (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
    }

    /// The knots (time, channels) in order, for plots and tests.
    pub fn knot_values(&self) -> Vec<(f64, [f64; CHANNELS])> {
        self.runs
            .iter()
            .flat_map(|r| r.t.iter().copied().zip(r.v.iter().copied()))
            .collect()
    }
}

/// Where a walk through a signal at times that never decrease stands: the current contact `c`,
/// the current run `r` and the number `p` of its knots at or before the last time.
#[derive(Default)]
struct Walk {
    c: usize,
    r: usize,
    p: usize,
}

impl Walk {
    /// The clean channels at `t`, not before the previous call's time.
    fn at(&mut self, signal: &ContactSignal, t: f64) -> [f64; CHANNELS] {
        let (contacts, runs) = (&signal.contacts, &signal.runs);
        while self.c < contacts.len() && contacts[self.c].1 < t {
            self.c += 1;
        }
        if self.c == contacts.len() || contacts[self.c].0 > t {
            return [0.0; CHANNELS];
        }
        // The last run starting at or before t; runs follow each other in time, so it is the
        // last run covering t if any run does.
        while self.r + 1 < runs.len() && runs[self.r + 1].t[0] <= t {
            self.r += 1;
            self.p = 0;
        }
        match runs.get(self.r) {
            Some(run) if run.t[0] <= t && t <= run.t[run.t.len() - 1] => {
                run.eval_walk(t, &mut self.p)
            }
            _ => signal.at(t),
        }
    }
}

impl Run {
    fn eval(&self, t: f64) -> [f64; CHANNELS] {
        // Binary search for the number of knots at or before t.
        self.eval_interval(t, self.t.partition_point(|&x| x <= t))
    }

    /// [`Self::eval`] for times that never decrease from one call to the next: `p` holds the
    /// number of knots at or before the previous call's t (0 before the first call) and is walked
    /// forward to this t's, the count the binary search of [`Self::eval`] finds.
    fn eval_walk(&self, t: f64, p: &mut usize) -> [f64; CHANNELS] {
        while *p < self.t.len() && self.t[*p] <= t {
            *p += 1;
        }
        self.eval_interval(t, *p)
    }

    /// The interpolant at t, where `p` knots lie at or before t.
    fn eval_interval(&self, t: f64, p: usize) -> [f64; CHANNELS] {
        let n = self.t.len();
        if n == 1 {
            return self.v[0];
        }
        // The interval [t_i, t_{i+1}] holding t.
        let i = match p {
            0 => 0,
            p => (p - 1).min(n - 2),
        };
        let (t0, t1) = (self.t[i], self.t[i + 1]);
        let h = t1 - t0;
        if h <= 0.0 {
            return self.v[i + 1];
        }
        let u = ((t - t0) / h).clamp(0.0, 1.0);
        let (h00, h10, h01, h11) = (
            (1.0 + 2.0 * u) * (1.0 - u) * (1.0 - u),
            u * (1.0 - u) * (1.0 - u),
            u * u * (3.0 - 2.0 * u),
            u * u * (u - 1.0),
        );
        std::array::from_fn(|c| {
            h00 * self.v[i][c]
                + h10 * h * self.m[i][c]
                + h01 * self.v[i + 1][c]
                + h11 * h * self.m[i + 1][c]
        })
    }
}

/// Fritsch–Carlson monotone slopes (PCHIP, as in Fritsch & Carlson 1980 / Moler's `pchip`) per
/// channel: the interpolant never overshoots the knots, so a force that stays inside the friction
/// cone at the knots cannot be carried far outside it between them.
fn pchip_slopes(t: &[f64], v: &[[f64; CHANNELS]]) -> Vec<[f64; CHANNELS]> {
    let n = t.len();
    let mut m = vec![[0.0; CHANNELS]; n];
    if n < 2 {
        return m;
    }
    for c in 0..CHANNELS {
        let delta: Vec<f64> = (0..n - 1)
            .map(|i| {
                let h = t[i + 1] - t[i];
                if h > 0.0 {
                    (v[i + 1][c] - v[i][c]) / h
                } else {
                    0.0
                }
            })
            .collect();
        if n == 2 {
            m[0][c] = delta[0];
            m[1][c] = delta[0];
            continue;
        }
        for i in 1..n - 1 {
            let (d0, d1) = (delta[i - 1], delta[i]);
            if d0 * d1 <= 0.0 {
                m[i][c] = 0.0;
            } else {
                let (h0, h1) = (t[i] - t[i - 1], t[i + 1] - t[i]);
                let (w1, w2) = (2.0 * h1 + h0, h1 + 2.0 * h0);
                m[i][c] = (w1 + w2) / (w1 / d0 + w2 / d1);
            }
        }
        m[0][c] = end_slope(t[1] - t[0], t[2] - t[1], delta[0], delta[1]);
        m[n - 1][c] = end_slope(
            t[n - 1] - t[n - 2],
            t[n - 2] - t[n - 3],
            delta[n - 2],
            delta[n - 3],
        );
    }
    m
}

/// The one-sided three-point end slope of PCHIP, kept shape-preserving.
fn end_slope(h0: f64, h1: f64, d0: f64, d1: f64) -> f64 {
    if h0 + h1 <= 0.0 {
        return d0;
    }
    let d = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if d * d0 <= 0.0 {
        0.0
    } else if d0 * d1 <= 0.0 && d.abs() > 3.0 * d0.abs() {
        3.0 * d0
    } else {
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pchip_reproduces_knots_and_a_straight_line() {
        let t = vec![0.0, 0.5, 1.5, 2.0];
        let v: Vec<[f64; CHANNELS]> = t.iter().map(|&x| [2.0 * x + 1.0; CHANNELS]).collect();
        let m = pchip_slopes(&t, &v);
        let run = Run { t, v, m };
        for &x in &[0.0, 0.25, 0.5, 1.0, 1.7, 2.0] {
            let y = run.eval(x);
            assert!((y[0] - (2.0 * x + 1.0)).abs() < 1e-12, "{x}: {}", y[0]);
        }
    }

    /// A run through `t` with channel c of knot j equal to f(t_j, c).
    fn run_of(t: &[f64], f: impl Fn(f64, usize) -> f64) -> Run {
        let v: Vec<[f64; CHANNELS]> = t
            .iter()
            .map(|&x| std::array::from_fn(|c| f(x, c)))
            .collect();
        let m = pchip_slopes(t, &v);
        Run {
            t: t.to_vec(),
            v,
            m,
        }
    }

    #[test]
    fn forward_sampling_matches_at_bit_for_bit() {
        // Three contacts with gaps between them; the second holds two runs that meet at an
        // event (the signal jumps), the third a single knot; uneven knot spacing throughout.
        let runs = vec![
            run_of(&[0.010, 0.0103, 0.011, 0.0125, 0.0131, 0.020], |x, c| {
                (x * 300.0 + c as f64).sin()
            }),
            run_of(&[0.030, 0.0301, 0.0302, 0.034], |x, c| {
                (x * 1e3).powi(2) - c as f64
            }),
            run_of(&[0.034, 0.0355, 0.036, 0.0361, 0.041], |x, c| {
                (c as f64 + 1.0) * (x * 500.0).cos()
            }),
            run_of(&[0.050], |_, c| c as f64 - 2.5),
        ];
        let signal = ContactSignal {
            runs,
            contacts: vec![(0.010, 0.020), (0.030, 0.041), (0.050, 0.050)],
            first_feature: None,
            knots: 16,
        };
        for (t0, dt, n) in [
            (0.0, 1e-4, 700),
            (0.00987, 1.0 / 3000.0, 150),
            (0.0300, 1e-4, 200),
            (0.0, 1e-3, 60),
        ] {
            let forward = signal.sample(t0, dt, n);
            for (k, v) in forward.iter().enumerate() {
                let t = t0 + k as f64 * dt;
                let at = signal.at(t);
                assert_eq!(v.map(f64::to_bits), at.map(f64::to_bits), "t = {t}");
            }
        }
        // Any times, rising (as a classifier's lag grid), at a phase, or going back.
        let phased: Vec<f64> = (0..400)
            .map(|j| 0.012 + (j as f64 - 12.0 + -3.0 + 0.25) * 1e-4)
            .collect();
        let back: Vec<f64> = (0..300).map(|j| ((j * 37) % 300) as f64 * 2e-4).collect();
        for times in [phased, back] {
            let each = signal.at_each(times.iter().copied());
            for (v, &t) in each.iter().zip(&times) {
                assert_eq!(
                    v.map(f64::to_bits),
                    signal.at(t).map(f64::to_bits),
                    "t = {t}"
                );
            }
        }
        // Samples land on knots and inside every run.
        let hits = signal
            .sample(0.0, 1e-4, 700)
            .iter()
            .filter(|v| v.iter().any(|x| *x != 0.0))
            .count();
        assert!(hits > 150, "{hits}");
    }

    #[test]
    fn the_walk_finds_the_interval_the_search_finds() {
        let run = run_of(&[0.0, 0.1, 0.15, 0.4, 1.0, 1.01], |x, c| {
            x * x * (c as f64 + 1.0)
        });
        let mut p = 0;
        for k in -20..=220 {
            let t = k as f64 * 0.005;
            let walked = run.eval_walk(t, &mut p);
            assert_eq!(
                walked.map(f64::to_bits),
                run.eval(t).map(f64::to_bits),
                "t = {t}"
            );
            assert_eq!(p, run.t.partition_point(|&x| x <= t));
        }
    }

    #[test]
    fn pchip_does_not_overshoot_a_step() {
        let t = vec![0.0, 1.0, 2.0, 3.0];
        let v: Vec<[f64; CHANNELS]> = [0.0, 0.0, 1.0, 1.0]
            .iter()
            .map(|&y| [y; CHANNELS])
            .collect();
        let m = pchip_slopes(&t, &v);
        let run = Run { t, v, m };
        for k in 0..=300 {
            let y = run.eval(k as f64 / 100.0)[0];
            assert!((-1e-12..=1.0 + 1e-12).contains(&y), "overshoot {y}");
        }
    }
}
