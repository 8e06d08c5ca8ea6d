//! `pinfeed run --precision E` (docs/output-analysis.md#run---precision): the feed keeps sending
//! new parts until the 95% confidence sequence of the line's rate has a half-width of at most E,
//! or until the run's parts (the cap) have been fed.
//!
//! The rate is the success rate (successes / parts finished) on an open line and the purity
//! (delivered in the goal / delivered) on a closed loop. It is checked after every event that
//! finishes a part (on a closed loop, that delivers one): the confidence sequence
//! ([`crate::statistics::confidence_sequence()`], Robbins' beta-binomial mixture) holds at every
//! count at once, so checking it that often costs no coverage. When the rule holds the feed
//! schedules no new arrival (an arrival already scheduled is dropped unprocessed); the parts on
//! the belt and in the loop finish, and the interval reported is the sequence over every part
//! finished by the end of the run — a stopping time too, so it keeps its 95% coverage. The parts
//! fed are then exactly those of a run of that many parts: the same draws, the same events.

use crate::statistics::confidence_sequence::{check_precision, Stop, ALPHA};
use crate::statistics::{confidence_sequence, precise_enough};
use serde::Serialize;

/// A precision to run to: the half-width of the rate's 95% confidence sequence, in (0, 0.5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Precision(f64);

impl Precision {
    /// The precision `half_width`, refused (with a message naming `--precision` and the range)
    /// outside (0, 0.5).
    pub fn new(half_width: f64) -> Result<Precision, String> {
        check_precision(half_width).map(Precision)
    }

    /// The half-width asked for.
    pub fn half_width(self) -> f64 {
        self.0
    }
}

/// The stopping rule's state in a run.
#[derive(Debug, Clone)]
pub(super) struct SequentialStop {
    precision: Precision,
    /// Trials counted at the last check (the rule is checked again only when they change).
    last_trials: u64,
    /// The trials at which the rule held, once it has.
    stopped_at: Option<u64>,
}

impl SequentialStop {
    /// The rule for `precision`, not yet met.
    pub(super) fn new(precision: Precision) -> SequentialStop {
        SequentialStop {
            precision,
            last_trials: 0,
            stopped_at: None,
        }
    }

    /// Has the rule held (the feed stopped)?
    pub(super) fn stopped(&self) -> bool {
        self.stopped_at.is_some()
    }

    /// Check the rule after `successes` in `trials`; true when it holds for the first time now.
    pub(super) fn check(&mut self, successes: u64, trials: u64) -> bool {
        if self.stopped() || trials == self.last_trials {
            return false;
        }
        self.last_trials = trials;
        if precise_enough(successes, trials, ALPHA, self.precision.0) {
            self.stopped_at = Some(trials);
            return true;
        }
        false
    }

    /// The summary's block at the end of a run that fed `parts` new parts and counted
    /// `successes` in `trials` by its end.
    pub(super) fn summary(
        &self,
        rate: &'static str,
        parts: u64,
        successes: u64,
        trials: u64,
    ) -> SequentialSummary {
        let cs = confidence_sequence(successes, trials, ALPHA);
        SequentialSummary {
            precision: self.precision.0,
            rate,
            stopped: if self.stopped() {
                Stop::Precision
            } else {
                Stop::Cap
            },
            parts,
            trials_at_stop: self.stopped_at,
            successes,
            trials,
            confidence_sequence: cs,
            half_width: 0.5 * (cs[1] - cs[0]),
        }
    }
}

/// The `sequential` block of a run's summary (present only with `--precision`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SequentialSummary {
    /// The half-width asked for.
    pub precision: f64,
    /// The rate watched: `success_rate` (successes / parts finished) or, on a closed loop,
    /// `purity` (delivered in the goal / delivered).
    pub rate: &'static str,
    /// Why the feed stopped: `precision` (the rule held) or `cap` (the run's parts were fed first).
    pub stopped: Stop,
    /// New parts fed.
    pub parts: u64,
    /// The trials (parts finished, or delivered) at which the rule held; None at the cap.
    pub trials_at_stop: Option<u64>,
    /// Successes (or deliveries in the goal) at the end of the run.
    pub successes: u64,
    /// Trials (parts finished, or delivered) at the end of the run.
    pub trials: u64,
    /// The 95% confidence sequence of the rate at the end of the run, [low, high].
    pub confidence_sequence: [f64; 2],
    /// Half its width.
    pub half_width: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_holds_once_and_only_when_the_trials_change() {
        let mut s = SequentialStop::new(Precision::new(0.06).unwrap());
        assert!(!s.check(0, 0));
        assert!(!s.check(250, 500), "±0.07 is not yet ±0.06");
        assert!(s.check(500, 1000));
        assert!(s.stopped() && !s.check(600, 1200));
        let b = s.summary("success_rate", 1010, 505, 1010);
        assert_eq!((b.stopped, b.trials_at_stop), (Stop::Precision, Some(1000)));
        assert_eq!(b.confidence_sequence, confidence_sequence(505, 1010, ALPHA));
        let cap = SequentialStop::new(Precision::new(0.01).unwrap());
        assert_eq!(cap.summary("purity", 10, 5, 10).stopped, Stop::Cap);
        assert!(Precision::new(0.5).unwrap_err().contains("--precision"));
    }
}
