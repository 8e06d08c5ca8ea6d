//! How a long library function reports its progress without drawing anything: it takes an
//! [`Observer`] told `done` units of `total` (from any worker thread), and, where the function can
//! tell, a [`Forecast`] of the time the rest will take; the command line points that at a progress
//! bar (`cli::progress`). Any `Fn(done, total)` closure is an observer that ignores forecasts;
//! [`silent`] is the callback of callers that show nothing.

use std::sync::atomic::{AtomicU64, Ordering};

/// What a long function tells its caller as it goes.
pub trait Observer: Sync {
    /// `done` units of `total` so far.
    fn progress(&self, done: u64, total: u64);
    /// How long the rest of the work should take, said once, early (ignored unless overridden).
    fn forecast(&self, _forecast: &Forecast) {}
}

impl<F: Fn(u64, u64) + Sync> Observer for F {
    fn progress(&self, done: u64, total: u64) {
        self(done, total)
    }
}

/// A progress observer: `done` units of `total` so far, and perhaps a forecast.
pub type Report<'a> = &'a dyn Observer;

/// A forecast of the time a piece of work still needs, with what it rests on.
#[derive(Debug, Clone, PartialEq)]
pub struct Forecast {
    /// Seconds of wall time the rest should take.
    pub seconds_left: f64,
    /// The forecast in words: the figure and how it was made.
    pub said: String,
}

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
        report.progress(0, total);
        Tally {
            done: AtomicU64::new(0),
            total,
            report,
        }
    }

    /// `n` more units are done.
    pub fn add(&self, n: u64) {
        let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
        self.report.progress(done.min(self.total), self.total);
    }
}
