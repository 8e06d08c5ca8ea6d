//! Progress on standard error for the commands that wait: a bar when the work is counted, a
//! spinner with the elapsed time and a stage when it is not. Nothing is drawn with `quiet` (a
//! command's `--quiet` or `--json`) or when standard error is not a terminal, so pipes, files and
//! scripts see only the command's own lines. The library never draws: its long functions take a
//! callback (`done` of `total`, or a tick per unit of work) that the command points at a bar.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pinfeed::progress::{Forecast, Observer};
use std::io::IsTerminal;
use std::time::Duration;

/// Whether progress is drawn: standard error is a terminal and the command is not quiet.
pub fn shown(quiet: bool) -> bool {
    !quiet && std::io::stderr().is_terminal()
}

/// A bar counting `total` units named `unit` ("samples", "passes"), with a message before it (a
/// stage, set with `set_message`) and the time left, as wide as the terminal.
pub fn bar(total: u64, unit: &str, quiet: bool) -> ProgressBar {
    if !shown(quiet) {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
    let template = format!("{{msg}}{{wide_bar}} {{pos}}/{{len}} {unit}  eta {{eta}}");
    b.set_style(ProgressStyle::with_template(&template).expect("valid progress template"));
    b
}

/// A spinner with `label`, the elapsed time and a message (what runs, set with `set_message`),
/// redrawn steadily so a long step without counts still shows it is alive.
pub fn spinner(label: &str, quiet: bool) -> ProgressBar {
    if !shown(quiet) {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    let template = format!("{{spinner}} {label} {{elapsed}}: {{msg}}");
    b.set_style(ProgressStyle::with_template(&template).expect("valid progress template"));
    b.enable_steady_tick(Duration::from_millis(120));
    b
}

/// An observer for the library's reports that moves `bar` (its length follows `total`, so one
/// bar can follow several counted stages in turn) and writes nothing else.
pub fn counter(bar: &ProgressBar) -> Watch<'_> {
    watch(bar, true)
}

/// [`counter`] that also writes a forecast (a map tier's build, after its probe) as a line above
/// the bar, unless `quiet`.
pub fn watch(bar: &ProgressBar, quiet: bool) -> Watch<'_> {
    Watch { bar, quiet }
}

/// See [`watch`].
pub struct Watch<'a> {
    bar: &'a ProgressBar,
    quiet: bool,
}

impl Observer for Watch<'_> {
    fn progress(&self, done: u64, total: u64) {
        if self.bar.length() != Some(total) {
            self.bar.set_length(total);
        }
        self.bar.set_position(done);
    }

    fn forecast(&self, forecast: &Forecast) {
        if !self.quiet {
            note(self.bar, &forecast.said);
        }
    }
}

/// A line on standard error that leaves `bar` drawn below it.
pub fn note(bar: &ProgressBar, line: &str) {
    bar.suspend(|| eprintln!("{line}"));
}
