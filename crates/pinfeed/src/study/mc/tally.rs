//! Exact accumulators of one sweep point: integer counts per outcome class, contacts and redraws,
//! and an HDR histogram of latencies (µs, 3 significant digits, as the line's metrics). Adding two
//! tallies is exact and commutative, so shards merge to the same numbers as one run.

use super::online::OnlineTally;
use super::sample::SampleResult;
use crate::engine::{OutcomeCounts, PartOutcome};
use hdrhistogram::errors::AdditionError;
use hdrhistogram::Histogram;

/// Counts of one sweep point.
#[derive(Debug, Clone, PartialEq)]
pub struct PointTally {
    /// Samples counted.
    pub samples: u64,
    /// Count per outcome class.
    pub outcomes: OutcomeCounts,
    /// Pin encounters, summed over the samples.
    pub contacts: u64,
    /// Perturbed polygons redrawn because they were invalid.
    pub shape_redraws: u64,
    /// Other values redrawn because they left their domain.
    pub other_redraws: u64,
    /// Entry → exit of the parts that reached the end of the belt (µs).
    pub latency_us: Histogram<u64>,
    /// Sensor readings (passes against sensor pins) and those decided correctly, summed over
    /// the samples and the line's sensor pins (0 without sensors).
    pub sensor_readings: u64,
    /// Of those readings, the ones decided correctly.
    pub sensor_correct: u64,
    /// What an online controller decided and predicted (empty without one).
    pub online: OnlineTally,
    /// A closed loop: the passes its parts made, summed (0 on an open line).
    pub passes: u64,
}

/// An empty latency histogram: 1 µs to 10⁶ s, 3 significant digits.
pub fn latency_histogram() -> Histogram<u64> {
    Histogram::new_with_bounds(1, 1_000_000_000_000, 3)
        .expect("valid histogram bounds: 1 µs to 10⁶ s, 3 significant digits")
}

impl Default for PointTally {
    fn default() -> Self {
        PointTally {
            samples: 0,
            outcomes: OutcomeCounts::default(),
            contacts: 0,
            shape_redraws: 0,
            other_redraws: 0,
            latency_us: latency_histogram(),
            sensor_readings: 0,
            sensor_correct: 0,
            online: OnlineTally::default(),
            passes: 0,
        }
    }
}

impl PointTally {
    /// Count one sample.
    pub fn add(&mut self, r: &SampleResult) {
        self.samples += 1;
        self.outcomes.add(r.outcome);
        self.contacts += r.contacts as u64;
        self.shape_redraws += r.shape_redraws as u64;
        self.other_redraws += r.other_redraws as u64;
        self.sensor_readings += r.sensor_readings as u64;
        self.sensor_correct += r.sensor_correct as u64;
        self.passes += u64::from(r.passes.unwrap_or(0));
        if let Some(o) = &r.online {
            self.online.add(o, r.outcome == PartOutcome::Success);
        }
        if let Some(us) = r.latency_us {
            self.latency_us.saturating_record(us);
        }
    }

    /// Add another tally of the same point.
    pub fn merge(&mut self, o: &PointTally) -> Result<(), TallyMergeError> {
        self.samples += o.samples;
        for c in PartOutcome::EVERY {
            add_count(&mut self.outcomes, c, o.outcomes.get(c));
        }
        self.contacts += o.contacts;
        self.shape_redraws += o.shape_redraws;
        self.other_redraws += o.other_redraws;
        self.sensor_readings += o.sensor_readings;
        self.sensor_correct += o.sensor_correct;
        self.online.merge(&o.online);
        self.passes += o.passes;
        self.latency_us.add(&o.latency_us).map_err(TallyMergeError)
    }
}

/// Two tallies whose latency histograms cannot be added ([`PointTally::merge`]): the other's
/// values exceed this one's range (holds the histogram's error).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("latency histograms do not add up: {0:?}")]
pub struct TallyMergeError(pub AdditionError);

/// Add `n` to the count of class `c`.
pub fn add_count(counts: &mut OutcomeCounts, c: PartOutcome, n: u64) {
    counts.add_n(c, n);
}
