//! How a long library function reports its progress without drawing anything: it takes a
//! callback told `done` units of `total` (from any worker thread), and the command line points
//! that at a progress bar (`cli::progress`). [`silent`] is the callback of callers that show none.

use std::sync::atomic::{AtomicU64, Ordering};

/// A progress callback: `done` units of `total` so far.
pub type Report<'a> = &'a (dyn Fn(u64, u64) + Sync);

/// The callback that ignores every report.
pub fn silent(_done: u64, _total: u64) {}

/// A count of finished units shared by worker threads, reporting each addition.
pub struct Tally<'a> {
    done: AtomicU64,
    total: u64,
    report: Report<'a>,
}

impl<'a> Tally<'a> {
    /// A count of `total` units, none done yet (reported at once).
    pub fn new(total: u64, report: Report<'a>) -> Tally<'a> {
        report(0, total);
        Tally {
            done: AtomicU64::new(0),
            total,
            report,
        }
    }

    /// `n` more units are done.
    pub fn add(&self, n: u64) {
        let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
        (self.report)(done.min(self.total), self.total);
    }
}
