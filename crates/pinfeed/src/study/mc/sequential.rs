//! `pinfeed mc --precision E`: run each sweep point's samples until its success rate is known to
//! ± E, or the study's `samples` (the cap) are spent.
//!
//! The samples run in deterministic rounds: in each, every point not yet stopped runs its next
//! [`BLOCK`] samples (sample indices in order, fewer in the last block at the cap), and the point
//! stops when the half-width of the 95% confidence sequence of its success rate
//! ([`crate::statistics::confidence_sequence()`]: Robbins' beta-binomial mixture, Howard et al.
//! 2021) is at most E, checked after each block. Because the sequence holds at every sample count
//! at once, the interval reported at the stop keeps its 95% coverage although the stop was chosen
//! by looking at the data — which a Wilson interval, checked after every block, would not
//! (docs/output-analysis.md). Sample i of a point draws only from (seed, i), and a point's stop
//! depends only on its own samples at block boundaries, so the result does not depend on the
//! thread count; a point that stopped after n samples has exactly the tally of a fixed run of n
//! samples.

use super::run::{run_range, with_threads};
use super::tally::PointTally;
use super::{Study, StudyError};
use crate::statistics::confidence_sequence;
use serde::Serialize;

// The rule's confidence, its stop reasons and the check of E are shared with `run --precision`
// (the engine's sequential stop), so they live in the statistics layer below both.
pub use crate::statistics::confidence_sequence::{check_precision, Stop, ALPHA};

/// Samples per point between two checks of the precision.
pub const BLOCK: u64 = 1000;

/// How a point's sequential run ended (in the report, per point, beside its samples).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sequential {
    /// The half-width asked for (`--precision`).
    pub precision: f64,
    /// Samples run between two checks.
    pub block: u64,
    /// The 95% confidence sequence of the success rate at the stop, [low, high].
    pub confidence_sequence: [f64; 2],
    /// Half its width.
    pub half_width: f64,
    /// Why the point stopped.
    pub stopped: Stop,
}

/// Whether a point with `successes` in `samples`, checked every `block` samples, stops: on
/// `precision` (the confidence sequence's half-width at most it; this wins at the cap too), at the
/// `cap`, or not yet (None).
pub fn status(
    successes: u64,
    samples: u64,
    precision: f64,
    block: u64,
    cap: u64,
) -> Option<Sequential> {
    let cs = confidence_sequence(successes, samples, ALPHA);
    let half_width = 0.5 * (cs[1] - cs[0]);
    let stopped = if half_width <= precision {
        Stop::Precision
    } else if samples >= cap {
        Stop::Cap
    } else {
        return None;
    };
    Some(Sequential {
        precision,
        block,
        confidence_sequence: cs,
        half_width,
        stopped,
    })
}

/// Run `study` point by point in rounds of `block` samples until each point's success rate is
/// known to ± `precision` or the study's samples are spent (the module documentation gives the
/// rule), on `threads` threads (None: all cores); `tick` is called once per sample run. Returns the
/// tally of every point and how it stopped, in point order.
pub fn run_to_precision(
    study: &Study,
    precision: f64,
    block: u64,
    threads: Option<usize>,
    tick: &(dyn Fn() + Sync),
) -> Result<(Vec<PointTally>, Vec<Sequential>), StudyError> {
    let block = block.max(1);
    let points = study.points.len();
    let cap = study.samples;
    with_threads(threads, || {
        let mut tallies = vec![PointTally::default(); points];
        let mut stops: Vec<Option<Sequential>> = vec![None; points];
        while stops.iter().any(Option::is_none) {
            for j in 0..points {
                if stops[j].is_some() {
                    continue;
                }
                let done = tallies[j].samples;
                let first = j as u64 * cap;
                let range = first + done..first + (done + block).min(cap);
                if let Some(t) = run_range(study, range, tick)?.get(&j) {
                    tallies[j]
                        .merge(t)
                        .expect("the tallies of one study share their histograms' bounds");
                }
                let t = &tallies[j];
                stops[j] = status(t.outcomes.success, t.samples, precision, block, cap);
            }
        }
        Ok((tallies, stops.into_iter().flatten().collect()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn precision_lies_in_the_open_half_unit() {
        for e in [1e-9, 0.01, 0.499] {
            assert_eq!(check_precision(e), Ok(e));
        }
        for e in [0.0, 0.5, -0.1, 1.0, f64::NAN, f64::INFINITY] {
            let m = check_precision(e).unwrap_err();
            assert!(m.contains("--precision") && m.contains("(0, 0.5)"), "{m}");
        }
    }

    #[test]
    fn stops_on_precision_before_the_cap() {
        // 500 of 1000: the sequence is about ±0.05 wide.
        let s = status(500, 1000, 0.06, 1000, 5000).unwrap();
        assert_eq!(s.stopped, Stop::Precision);
        assert!(
            s.half_width <= 0.06 && s.half_width > 0.04,
            "{}",
            s.half_width
        );
        assert_eq!(status(500, 1000, 0.04, 1000, 5000), None);
        assert_eq!(
            status(500, 1000, 0.04, 1000, 1000).unwrap().stopped,
            Stop::Cap
        );
        // Precise at the cap: precision wins.
        assert_eq!(
            status(500, 1000, 0.06, 1000, 1000).unwrap().stopped,
            Stop::Precision
        );
    }
}
