//! What an online controller (docs/physics.md#belief-and-online-replanning) did over a study's
//! samples: its decisions, the success it predicted against the success observed (in ten bins of
//! the prediction: the belief's calibration under the study's uncertainty), the belief's entropy
//! before any observation and at the decision, and how often its most probable stable state was
//! the part's true one.
//!
//! Every quantity is an integer count or a sum of fixed-point values (predictions in millionths,
//! entropies in millionths of a bit), so tallies add exactly and shards merge to the numbers one
//! run gives, as the rest of [`super::tally`].

use crate::engine::controller::CalibrationBin;
use crate::engine::RunResult;
use crate::statistics::wilson_interval;
use serde::{Deserialize, Serialize};

/// Bins of the predicted success: [k/10, (k+1)/10), the last one closed.
pub const BINS: usize = 10;
/// Fixed-point scale of predictions and entropies.
const SCALE: f64 = 1e6;

/// One sample's decision, when its part reached one, in the tally's fixed point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OnlineSample {
    /// The predicted probability of the goal for the chosen command (millionths).
    pub predicted_micro: u64,
    /// Entropy of the belief before any observation and at the decision (millionths of a bit).
    pub entropy_prior_microbits: u64,
    /// Entropy of the belief at the decision (millionths of a bit).
    pub entropy_posterior_microbits: u64,
    /// The part's true stable state is known to the simulator, and the belief's most probable
    /// state was it.
    pub state_known: bool,
    /// The belief's most probable state was the true one (meaningful only when `state_known`).
    pub state_correct: bool,
}

impl OnlineSample {
    /// The decision of a one-part run's online controller (None: no online controller, or the
    /// part never reached a decision).
    pub fn of(run: &RunResult) -> Option<OnlineSample> {
        let o = run.summary.controller.as_ref()?.online.as_ref()?;
        (o.decisions == 1).then(|| OnlineSample {
            predicted_micro: fixed(o.predicted_mean.clamp(0.0, 1.0)),
            entropy_prior_microbits: fixed(o.entropy_prior_bits),
            entropy_posterior_microbits: fixed(o.entropy_posterior_bits),
            state_known: o.state_known == 1,
            state_correct: o.state_correct == 1,
        })
    }
}

/// One calibration bin's exact counts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BinTally {
    /// Decisions whose prediction fell in this bin.
    pub parts: u64,
    /// Σ predicted, in millionths.
    pub predicted_micro: u64,
    /// Of those, the parts that ended in the goal.
    pub successes: u64,
}

/// The online controller's counts over the samples of one sweep point (also a shard's form).
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OnlineTally {
    /// Samples whose part reached a decision, and those that ended in the goal.
    pub decisions: u64,
    /// Of the decisions, the samples that ended in the goal.
    pub successes: u64,
    /// Σ predicted (millionths) and Σ entropies (millionths of a bit) over the decisions.
    pub predicted_micro: u64,
    /// Σ entropy of the belief before any observation (millionths of a bit).
    pub entropy_prior_microbits: u64,
    /// Σ entropy of the belief at the decision (millionths of a bit).
    pub entropy_posterior_microbits: u64,
    /// Decisions whose part's true stable state is known to the simulator.
    pub state_known: u64,
    /// Of those, the decisions whose most probable state was the true one.
    pub state_correct: u64,
    /// Per bin of the prediction ([`BINS`] of them).
    pub bins: Vec<BinTally>,
}

fn fixed(x: f64) -> u64 {
    (x.max(0.0) * SCALE).round() as u64
}

impl OnlineTally {
    /// Count one decision and whether its part ended in the goal.
    pub fn add(&mut self, s: &OnlineSample, success: bool) {
        if self.bins.len() != BINS {
            self.bins = vec![BinTally::default(); BINS];
        }
        let p = s.predicted_micro.min(SCALE as u64);
        self.decisions += 1;
        self.successes += u64::from(success);
        self.predicted_micro += p;
        self.entropy_prior_microbits += s.entropy_prior_microbits;
        self.entropy_posterior_microbits += s.entropy_posterior_microbits;
        self.state_known += u64::from(s.state_known);
        self.state_correct += u64::from(s.state_known && s.state_correct);
        let b = &mut self.bins[((p * BINS as u64 / SCALE as u64) as usize).min(BINS - 1)];
        b.parts += 1;
        b.predicted_micro += p;
        b.successes += u64::from(success);
    }

    /// Add another tally of the same point.
    pub fn merge(&mut self, o: &OnlineTally) {
        if o.decisions == 0 {
            return;
        }
        if self.bins.len() != BINS {
            self.bins = vec![BinTally::default(); BINS];
        }
        self.decisions += o.decisions;
        self.successes += o.successes;
        self.predicted_micro += o.predicted_micro;
        self.entropy_prior_microbits += o.entropy_prior_microbits;
        self.entropy_posterior_microbits += o.entropy_posterior_microbits;
        self.state_known += o.state_known;
        self.state_correct += o.state_correct;
        for (a, b) in self.bins.iter_mut().zip(&o.bins) {
            a.parts += b.parts;
            a.predicted_micro += b.predicted_micro;
            a.successes += b.successes;
        }
    }

    /// Whether the counts hang together (a shard's check): every part in one bin, no more
    /// successes or correct states than their totals.
    pub fn check(&self) -> Result<(), OnlineTallyError> {
        if self.decisions == 0 {
            return Ok(());
        }
        if self.bins.len() != BINS {
            return Err(OnlineTallyError::Bins(self.bins.len()));
        }
        let parts: u64 = self.bins.iter().map(|b| b.parts).sum();
        let ok: u64 = self.bins.iter().map(|b| b.successes).sum();
        if parts != self.decisions || ok != self.successes {
            return Err(OnlineTallyError::BinTotals {
                parts,
                successes: ok,
                decisions: self.decisions,
                total_successes: self.successes,
            });
        }
        if self.successes > self.decisions
            || self.state_correct > self.state_known
            || self.state_known > self.decisions
            || self.bins.iter().any(|b| b.successes > b.parts)
            || self.predicted_micro > self.decisions * SCALE as u64
        {
            return Err(OnlineTallyError::Exceeds);
        }
        Ok(())
    }

    /// The report of these counts (None without decisions).
    pub fn report(&self) -> Option<OnlineShare> {
        let n = self.decisions;
        (n > 0).then(|| {
            let mean = |micro: u64, k: u64| micro as f64 / SCALE / k as f64;
            OnlineShare {
                decisions: n,
                predicted_mean: mean(self.predicted_micro, n),
                observed: self.successes as f64 / n as f64,
                observed_ci95: wilson_interval(self.successes, n),
                entropy_prior_bits: mean(self.entropy_prior_microbits, n),
                entropy_posterior_bits: mean(self.entropy_posterior_microbits, n),
                state_correct: self.state_correct,
                state_known: self.state_known,
                calibration: self
                    .bins
                    .iter()
                    .enumerate()
                    .filter(|(_, b)| b.parts > 0)
                    .map(|(k, b)| CalibrationBin {
                        lo: k as f64 / BINS as f64,
                        hi: (k + 1) as f64 / BINS as f64,
                        parts: b.parts,
                        predicted_mean: mean(b.predicted_micro, b.parts),
                        observed: b.successes as f64 / b.parts as f64,
                    })
                    .collect(),
            }
        })
    }
}

/// Counts of an online controller that do not hang together ([`OnlineTally::check`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OnlineTallyError {
    /// Not [`BINS`] calibration bins (holds how many there are).
    #[error("online: {0} calibration bins, not {BINS}")]
    Bins(usize),
    /// The bins' decisions or successes are not the tally's.
    #[error(
        "online: the calibration bins hold {parts} decisions and {successes} successes, not {decisions} and {total_successes}"
    )]
    BinTotals {
        /// Decisions, summed over the bins.
        parts: u64,
        /// Successes, summed over the bins.
        successes: u64,
        /// The tally's decisions.
        decisions: u64,
        /// The tally's successes.
        total_successes: u64,
    },
    /// More successes or correct states than their totals, or a mean prediction above 1.
    #[error("online: a count exceeds its total")]
    Exceeds,
}

/// What the online controller did at one sweep point, in the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OnlineShare {
    /// Samples whose part reached a decision.
    pub decisions: u64,
    /// Mean predicted success of the chosen commands, and the share of those parts that ended in
    /// the goal (95% Wilson interval).
    pub predicted_mean: f64,
    /// Share of the decisions whose part ended in the goal, in [0, 1].
    pub observed: f64,
    /// 95% Wilson interval of `observed`, [low, high].
    pub observed_ci95: [f64; 2],
    /// Mean entropy of the belief before any observation and at the decision (bits).
    pub entropy_prior_bits: f64,
    /// Mean entropy of the belief at the decision (bits).
    pub entropy_posterior_bits: f64,
    /// Decisions whose most probable stable state was the true one, of those with a known state.
    pub state_correct: u64,
    /// Decisions whose part's true stable state is known to the simulator.
    pub state_known: u64,
    /// Predicted against observed in bins of the prediction (empty bins left out).
    pub calibration: Vec<CalibrationBin>,
}

/// The report's section on the online controller: one row per sweep point, then the calibration
/// bins (empty when no point has decisions).
pub fn markdown(points: &[(String, &OnlineShare)]) -> String {
    if points.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "\n## Online controller\n\nPer sweep point: the decisions of the online controller (one per \
         part that reached every sensor), the success it predicted for the commands it chose \
         under its belief against the success observed on the perturbed lines, the belief's \
         entropy before any observation and at the decision, and how often its most probable \
         stable state was the part's true one. The belief is built from the nominal line; the \
         samples' physics is drawn from the study's uncertainty, which the belief never sees.\n\n\
         | point | decisions | predicted | observed [95% CI] | entropy before → after (bits) | state found |\n\
         |---|---|---|---|---|---|\n",
    );
    for (name, o) in points {
        s.push_str(&format!(
            "| {name} | {} | {:.3} | {:.3} [{:.3}, {:.3}] | {:.2} → {:.2} | {} of {} |\n",
            o.decisions,
            o.predicted_mean,
            o.observed,
            o.observed_ci95[0],
            o.observed_ci95[1],
            o.entropy_prior_bits,
            o.entropy_posterior_bits,
            o.state_correct,
            o.state_known
        ));
    }
    s.push_str(
        "\nCalibration: parts by the success predicted for their command, the mean prediction and \
         the share observed in the goal.\n\n| point | predicted in | parts | predicted | observed |\n\
         |---|---|---|---|---|\n",
    );
    for (name, o) in points {
        for b in &o.calibration {
            s.push_str(&format!(
                "| {name} | [{:.1}, {:.1}{} | {} | {:.3} | {:.3} |\n",
                b.lo,
                b.hi,
                if b.hi >= 1.0 { "]" } else { ")" },
                b.parts,
                b.predicted_mean,
                b.observed
            ));
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(p: f64, known: bool, correct: bool) -> OnlineSample {
        OnlineSample {
            predicted_micro: fixed(p),
            entropy_prior_microbits: fixed(5.75),
            entropy_posterior_microbits: fixed(2.0 + p),
            state_known: known,
            state_correct: correct,
        }
    }

    /// Tallies split anywhere and merged give the counts of one tally, and the report's means
    /// and bins are those of the samples.
    #[test]
    fn tallies_merge_exactly_and_report_the_samples() {
        let xs: Vec<(OnlineSample, bool)> = (0..97)
            .map(|i| {
                let p = (i as f64 * 0.37).fract();
                (sample(p, i % 3 != 0, i % 2 == 0), i % 4 != 1)
            })
            .collect();
        let mut one = OnlineTally::default();
        for (s, ok) in &xs {
            one.add(s, *ok);
        }
        for cut in [0, 1, 40, 97] {
            let (mut a, mut b) = (OnlineTally::default(), OnlineTally::default());
            for (s, ok) in &xs[..cut] {
                a.add(s, *ok);
            }
            for (s, ok) in &xs[cut..] {
                b.add(s, *ok);
            }
            a.merge(&b);
            if cut == 0 {
                // An empty tally that takes a merge holds the same counts.
                assert_eq!(a.decisions, one.decisions);
            }
            assert_eq!(a, one, "cut at {cut}");
        }
        one.check().unwrap();
        let r = one.report().unwrap();
        let n = xs.len() as f64;
        let mean_p = xs
            .iter()
            .map(|(s, _)| s.predicted_micro as f64 / SCALE)
            .sum::<f64>()
            / n;
        assert!((r.predicted_mean - mean_p).abs() < 1e-6);
        let ok = xs.iter().filter(|(_, ok)| *ok).count() as f64;
        assert_eq!(r.observed, ok / n);
        assert_eq!(r.calibration.iter().map(|b| b.parts).sum::<u64>(), 97);
        for b in &r.calibration {
            assert!(
                b.lo <= b.predicted_mean && b.predicted_mean < b.hi + 1e-12,
                "{b:?}"
            );
        }
        assert_eq!(
            r.state_known,
            xs.iter().filter(|(s, _)| s.state_known).count() as u64
        );
        assert!(r.state_correct <= r.state_known);
    }

    /// A prediction of exactly 1 falls in the last bin, and a tally whose bins disagree with its
    /// totals is refused.
    #[test]
    fn edges_and_inconsistent_counts() {
        let mut t = OnlineTally::default();
        t.add(&sample(1.0, true, true), true);
        t.add(&sample(0.0, true, false), false);
        assert_eq!(t.bins[BINS - 1].parts, 1);
        assert_eq!(t.bins[0].parts, 1);
        t.check().unwrap();
        let mut bad = t.clone();
        bad.successes += 1;
        let e = bad.check().unwrap_err();
        assert_eq!(
            e,
            OnlineTallyError::BinTotals {
                parts: 2,
                successes: 1,
                decisions: 2,
                total_successes: 2
            }
        );
        assert_eq!(
            e.to_string(),
            "online: the calibration bins hold 2 decisions and 1 successes, not 2 and 2"
        );
        let mut bad = t.clone();
        bad.bins.pop();
        let e = bad.check().unwrap_err();
        assert_eq!(e, OnlineTallyError::Bins(BINS - 1));
        assert_eq!(e.to_string(), "online: 9 calibration bins, not 10");
        let mut bad = t.clone();
        bad.state_correct = 3;
        assert_eq!(bad.check(), Err(OnlineTallyError::Exceeds));
        assert!(OnlineTally::default().report().is_none());
    }
}
