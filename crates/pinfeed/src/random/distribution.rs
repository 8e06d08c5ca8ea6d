//! Distributions of one uncertain number, and how a value is drawn from them.
//!
//! Every draw is a fixed function of one uniform u ∈ [0, 1) or one standard normal z taken from the
//! parameter's own stream (inverse CDF for `triangular`, `mean + sd·z` for `normal`), so the same
//! sample index gives the same u or z at every sweep point: sweeping a scale (`sd`, `max`) scales
//! the same underlying draw (common random numbers), and the sensitivity curve is not blurred by
//! independent noise between points.
//!
//! A value outside the parameter's physical domain (a negative friction, a negative pin radius) is
//! redrawn; [`Distribution::draw`] reports how many redraws it needed and gives up after
//! [`MAX_REDRAWS`] with an error instead of looping or panicking.

use rand::RngExt;
use rand_distr::{Distribution as _, StandardNormal};

/// Redraws before a draw is declared impossible.
pub const MAX_REDRAWS: u32 = 1000;

/// Why no value could be drawn ([`Distribution::draw`]): [`MAX_REDRAWS`] redraws in a row fell
/// outside the allowed range.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error(
    "{} draws in a row from {} fell outside the allowed range",
    MAX_REDRAWS + 1,
    .distribution.describe()
)]
pub struct DrawError {
    /// The distribution drawn from.
    pub distribution: Distribution,
}

/// A compiled distribution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Distribution {
    /// Always this value.
    Fixed(f64),
    /// Uniform on [min, max].
    Uniform {
        /// Lower end.
        min: f64,
        /// Upper end.
        max: f64,
    },
    /// Normal, optionally truncated to [lo, hi] by redrawing.
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation.
        sd: f64,
        /// Lower truncation (−∞ when not truncated).
        lo: f64,
        /// Upper truncation (+∞ when not truncated).
        hi: f64,
    },
    /// Triangular on [min, max] with its peak at `mode` (drawn by inverse CDF).
    Triangular {
        /// Lower end.
        min: f64,
        /// The peak, in [min, max].
        mode: f64,
        /// Upper end.
        max: f64,
    },
}

impl Distribution {
    /// One value, before any domain check.
    fn raw_draw(&self, rng: &mut impl rand::Rng) -> f64 {
        match *self {
            Distribution::Fixed(v) => v,
            Distribution::Uniform { min, max } => min + (max - min) * rng.random::<f64>(),
            Distribution::Normal { mean, sd, .. } => {
                let z: f64 = StandardNormal.sample(rng);
                mean + sd * z
            }
            Distribution::Triangular { min, mode, max } => {
                let u: f64 = rng.random();
                let (w, left) = (max - min, mode - min);
                if w <= 0.0 {
                    min
                } else if u * w < left {
                    min + (u * w * left).sqrt()
                } else {
                    max - ((1.0 - u) * w * (max - mode)).sqrt()
                }
            }
        }
    }

    /// Draw a value accepted by `ok` (the parameter's domain, and the normal's truncation).
    /// Returns the value and the number of redraws.
    pub fn draw(
        &self,
        rng: &mut impl rand::Rng,
        ok: impl Fn(f64) -> bool,
    ) -> Result<(f64, u32), DrawError> {
        for redraws in 0..=MAX_REDRAWS {
            let v = self.raw_draw(rng);
            let truncated = match *self {
                Distribution::Normal { lo, hi, .. } => (lo..=hi).contains(&v),
                _ => true,
            };
            if truncated && ok(v) {
                return Ok((v, redraws));
            }
        }
        Err(DrawError {
            distribution: *self,
        })
    }

    /// Smallest and largest value the distribution can produce.
    pub fn range(&self) -> (f64, f64) {
        match *self {
            Distribution::Fixed(v) => (v, v),
            Distribution::Uniform { min, max } | Distribution::Triangular { min, max, .. } => {
                (min, max)
            }
            Distribution::Normal { lo, hi, .. } => (lo, hi),
        }
    }

    /// The largest value a draw takes in practice: the range's top, but for a normal no more
    /// than 8 standard deviations above its mean (its truncation bound may be unset, 1e6).
    pub fn practical_max(&self) -> f64 {
        match *self {
            Distribution::Normal { mean, sd, hi, .. } => hi.min(mean + 8.0 * sd),
            _ => self.range().1,
        }
    }

    /// The probability that one raw draw lands in the distribution's own truncation: the normal
    /// mass of `[lo, hi]` (1 for the other kinds, and for a normal with sd 0, whose mean lies in
    /// its truncation).
    pub fn truncation_mass(&self) -> f64 {
        match *self {
            Distribution::Normal { mean, sd, lo, hi } if sd > 0.0 => {
                let cdf = |x: f64| 0.5 * libm::erfc(-(x - mean) / (sd * std::f64::consts::SQRT_2));
                (cdf(hi) - cdf(lo)).max(0.0)
            }
            _ => 1.0,
        }
    }

    /// Is the distribution a single value?
    pub fn is_fixed(&self) -> bool {
        matches!(self, Distribution::Fixed(_))
    }

    /// The distribution as the keys of a study's `[uncertain.NAME]` table (docs/study-format.md),
    /// one `key = value` a line, every number written so that it reads back exactly.
    pub fn toml_fields(&self) -> String {
        let num = |v: f64| {
            if v == f64::INFINITY {
                "inf".to_string()
            } else if v == f64::NEG_INFINITY {
                "-inf".to_string()
            } else {
                format!("{v:?}")
            }
        };
        match *self {
            Distribution::Fixed(v) => format!("distribution = \"fixed\"\nvalue = {}\n", num(v)),
            Distribution::Uniform { min, max } => format!(
                "distribution = \"uniform\"\nmin = {}\nmax = {}\n",
                num(min),
                num(max)
            ),
            Distribution::Normal { mean, sd, lo, hi } => {
                let mut s = format!(
                    "distribution = \"normal\"\nmean = {}\nsd = {}\n",
                    num(mean),
                    num(sd)
                );
                if lo.is_finite() {
                    s += &format!("min = {}\n", num(lo));
                }
                if hi.is_finite() {
                    s += &format!("max = {}\n", num(hi));
                }
                s
            }
            Distribution::Triangular { min, mode, max } => format!(
                "distribution = \"triangular\"\nmin = {}\nmode = {}\nmax = {}\n",
                num(min),
                num(mode),
                num(max)
            ),
        }
    }

    /// A short description: `uniform [0.3, 0.7]`, `normal (mean 0, sd 0.0002)`.
    pub fn describe(&self) -> String {
        match *self {
            Distribution::Fixed(v) => format!("fixed {v}"),
            Distribution::Uniform { min, max } => format!("uniform [{min}, {max}]"),
            Distribution::Normal { mean, sd, lo, hi } => {
                let mut s = format!("normal (mean {mean}, sd {sd})");
                if lo.is_finite() || hi.is_finite() {
                    s.push_str(&format!(" truncated to [{lo}, {hi}]"));
                }
                s
            }
            Distribution::Triangular { min, mode, max } => {
                format!("triangular [{min}, {max}] with mode {mode}")
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::stream;

    #[test]
    fn draws_stay_in_range_and_scale_together() {
        let d = Distribution::Triangular {
            min: -1.0,
            mode: 0.5,
            max: 2.0,
        };
        let mut rng = stream(3, 0);
        for _ in 0..1000 {
            let (v, _) = d.draw(&mut rng, |_| true).unwrap();
            assert!((-1.0..=2.0).contains(&v));
        }
        // Common random numbers: doubling sd doubles the draw.
        let a = Distribution::Normal {
            mean: 0.0,
            sd: 1.0,
            lo: f64::NEG_INFINITY,
            hi: f64::INFINITY,
        };
        let b = Distribution::Normal {
            mean: 0.0,
            sd: 2.0,
            lo: f64::NEG_INFINITY,
            hi: f64::INFINITY,
        };
        let (va, _) = a.draw(&mut stream(5, 7), |_| true).unwrap();
        let (vb, _) = b.draw(&mut stream(5, 7), |_| true).unwrap();
        assert!((vb - 2.0 * va).abs() < 1e-12);
    }

    #[test]
    fn impossible_domain_is_an_error_not_a_loop() {
        let d = Distribution::Uniform {
            min: -2.0,
            max: -1.0,
        };
        let e = d.draw(&mut stream(1, 1), |v| v >= 0.0).unwrap_err();
        assert_eq!(e, DrawError { distribution: d });
        assert_eq!(
            e.to_string(),
            "1001 draws in a row from uniform [-2, -1] fell outside the allowed range"
        );
        let n = Distribution::Normal {
            mean: 0.0,
            sd: 1.0,
            lo: 0.0,
            hi: f64::INFINITY,
        };
        let (v, _) = n.draw(&mut stream(1, 2), |_| true).unwrap();
        assert!(v >= 0.0);
    }
}
