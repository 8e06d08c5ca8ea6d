//! Confusion matrices of a classifier's decisions against the truth, with the figures drawn from
//! them: accuracy with its 95% Wilson interval and the plug-in mutual information between state and
//! decision (used by `pinfeed sense` and by sensor pins in the line).

use super::classify::Decision;
use crate::statistics::wilson_interval;
use serde::Serialize;

/// A confusion matrix: rows the true hypotheses, columns the decisions, the last column "unknown".
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Confusion {
    /// The hypotheses' labels, in row order.
    pub labels: Vec<String>,
    /// `counts[true][decided]`, k rows of k + 1 columns (the last: unknown).
    pub counts: Vec<Vec<u64>>,
}

impl Confusion {
    /// An empty matrix over `labels`.
    pub fn new(labels: &[String]) -> Confusion {
        let k = labels.len();
        Confusion {
            labels: labels.to_vec(),
            counts: vec![vec![0; k + 1]; k],
        }
    }

    /// Number of hypotheses.
    pub fn k(&self) -> usize {
        self.labels.len()
    }

    /// Count one trial. A decision naming no hypothesis counts as unknown.
    pub fn add(&mut self, truth: usize, decision: Decision) {
        let k = self.k();
        let col = match decision {
            Decision::Hypothesis(h) if h < k => h,
            _ => k,
        };
        self.counts[truth][col] += 1;
    }

    /// Add another matrix over the same labels.
    pub fn merge(&mut self, other: &Confusion) {
        for (r, o) in self.counts.iter_mut().zip(&other.counts) {
            for (a, b) in r.iter_mut().zip(o) {
                *a += b;
            }
        }
    }

    /// Trials whose truth was hypothesis `h`.
    pub fn row_total(&self, h: usize) -> u64 {
        self.counts[h].iter().sum()
    }

    /// Trials counted.
    pub fn total(&self) -> u64 {
        self.counts.iter().flatten().sum()
    }

    /// Trials decided correctly (the diagonal).
    pub fn correct(&self) -> u64 {
        (0..self.k()).map(|h| self.counts[h][h]).sum()
    }

    /// Trials decided "unknown".
    pub fn unknown(&self) -> u64 {
        let k = self.k();
        self.counts.iter().map(|r| r[k]).sum()
    }

    /// Share of trials decided correctly ("unknown" counts as wrong); 0 without trials.
    pub fn accuracy(&self) -> f64 {
        let n = self.total();
        if n == 0 {
            0.0
        } else {
            self.correct() as f64 / n as f64
        }
    }

    /// 95% Wilson interval of the accuracy (widened by rounding so it always holds the estimate:
    /// at 100% the formula's upper bound can round to 1 − 2⁻⁵³).
    pub fn accuracy_ci95(&self) -> [f64; 2] {
        let [lo, hi] = wilson_interval(self.correct(), self.total());
        if self.total() == 0 {
            return [lo, hi];
        }
        let p = self.accuracy();
        [lo.min(p), hi.max(p)]
    }

    /// Plug-in mutual information I(state; decision) in bits, "unknown" a decision of its own.
    pub fn mutual_information_bits(&self) -> f64 {
        let n = self.total() as f64;
        if n == 0.0 {
            return 0.0;
        }
        let rows: Vec<f64> = self
            .counts
            .iter()
            .map(|r| r.iter().sum::<u64>() as f64)
            .collect();
        let cols: Vec<f64> = (0..=self.k())
            .map(|c| self.counts.iter().map(|r| r[c]).sum::<u64>() as f64)
            .collect();
        let mut i = 0.0;
        for (s, r) in self.counts.iter().enumerate() {
            for (d, &c) in r.iter().enumerate() {
                if c > 0 {
                    let c = c as f64;
                    i += c / n * (c * n / (rows[s] * cols[d])).log2();
                }
            }
        }
        i.max(0.0)
    }

    /// Entropy H(state) in bits of the trials' truths: the most information any decision can carry.
    pub fn state_entropy_bits(&self) -> f64 {
        let n = self.total() as f64;
        if n == 0.0 {
            return 0.0;
        }
        (0..self.k())
            .map(|h| self.row_total(h) as f64 / n)
            .filter(|&p| p > 0.0)
            .map(|p| -p * p.log2())
            .sum()
    }
}
