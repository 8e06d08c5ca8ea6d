//! Running a range of samples in parallel. Global sample index g ∈ [0, points × N) maps to sweep
//! point g / N and sample g mod N (so a shard's contiguous range covers whole points in order).
//! Samples run on rayon in chunks with an order-preserving collect and are counted in index order,
//! so the tallies do not depend on the thread count; neither does the error of a failing study
//! (the failure with the lowest index is reported).

use super::sample::{run_sample, SampleResult};
use super::tally::PointTally;
use super::{Study, StudyError};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::ops::Range;

/// Samples run between two reductions (bounds memory for huge studies).
const CHUNK: u64 = 1 << 16;

/// The sweep point and the sample index within it of global sample `g`.
pub fn locate(study: &Study, g: u64) -> (usize, u64) {
    ((g / study.samples) as usize, g % study.samples)
}

/// Run one sample by its global index.
pub fn run_global(study: &Study, g: u64) -> Result<SampleResult, StudyError> {
    let (point, i) = locate(study, g);
    run_sample(
        &study.scene,
        study.online.as_ref(),
        &study.points[point],
        point,
        study.seed,
        i,
    )
}

/// Run the samples in `range` (global indices) on the current rayon pool; `tick` is called once
/// per finished sample (from any thread). Returns the tallies of the points the range touches.
pub fn run_range(
    study: &Study,
    range: Range<u64>,
    tick: &(dyn Fn() + Sync),
) -> Result<BTreeMap<usize, PointTally>, StudyError> {
    let mut tallies: BTreeMap<usize, PointTally> = BTreeMap::new();
    let mut start = range.start;
    while start < range.end {
        let end = (start + CHUNK).min(range.end);
        let results: Vec<Result<SampleResult, StudyError>> = (start..end)
            .into_par_iter()
            .map(|g| {
                let r = run_global(study, g);
                tick();
                r
            })
            .collect();
        // The first failure in index order, whichever thread met it first.
        let results: Vec<SampleResult> = results.into_iter().collect::<Result<_, _>>()?;
        for (g, r) in (start..end).zip(&results) {
            let (point, _) = locate(study, g);
            tallies.entry(point).or_default().add(r);
        }
        start = end;
    }
    Ok(tallies)
}

/// Run `range` on a pool of `threads` threads (None: rayon's global pool, all cores).
pub fn run_range_with_threads(
    study: &Study,
    range: Range<u64>,
    threads: Option<usize>,
    tick: &(dyn Fn() + Sync),
) -> Result<BTreeMap<usize, PointTally>, StudyError> {
    with_threads(threads, || run_range(study, range, tick))
}

/// Run `work` on a pool of `threads` threads, so that every [`run_range`] inside it runs there
/// (None: on rayon's global pool, all cores).
pub fn with_threads<R: Send>(
    threads: Option<usize>,
    work: impl FnOnce() -> Result<R, StudyError> + Send,
) -> Result<R, StudyError> {
    match threads {
        None => work(),
        Some(n) => {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| StudyError::Threads {
                    threads: n,
                    reason: e.to_string(),
                })?;
            pool.install(work)
        }
    }
}
