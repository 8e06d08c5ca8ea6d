//! What Monte Carlo precision costs in time: the 95% Wilson interval's half-width of a study's
//! success rate against the number of samples and the wall time they take on this machine, and the
//! parallel efficiency of 1 against 2 threads. Written as a section of
//! `results/accuracy-vs-time.md` (between the markers below) by `pinfeed bench mc-precision`.
//!
//! The half-width of a proportion's interval shrinks as z·√(p(1−p)/n) (z = 1.96), so each halving
//! costs four times the samples and four times the time; the projection rows use the measured
//! success rate and the measured samples per second.

use super::{run, Study, StudyError};
use crate::statistics::wilson_interval;
use serde::Serialize;
use std::time::Instant;

/// Marks the start of the generated section in the accuracy-vs-time report.
pub const BEGIN: &str = "<!-- mc-precision:begin -->";
/// Marks its end.
pub const END: &str = "<!-- mc-precision:end -->";

/// One measured sample count.
#[derive(Debug, Clone, Serialize)]
pub struct PrecisionRow {
    /// Samples run (the requested count, capped at the study's samples per point).
    pub samples: u64,
    /// Samples that ended in success.
    pub successes: u64,
    /// Success rate, `successes / samples`.
    pub rate: f64,
    /// 95% Wilson interval of the rate, [low, high].
    pub ci95: [f64; 2],
    /// Half the width of `ci95`.
    pub half_width: f64,
    /// Fastest wall time of the repeats (s).
    pub wall_s: f64,
    /// Samples per second of the fastest repeat.
    pub samples_per_s: f64,
}

/// Run the first `n` samples of the study's first point for each `n` in `counts` on `threads`
/// threads, `repeats` times, and keep the fastest wall time (on a shared machine the fastest run
/// is the one least disturbed by other work).
pub fn measure(
    study: &Study,
    counts: &[u64],
    threads: usize,
    repeats: usize,
) -> Result<Vec<PrecisionRow>, StudyError> {
    let mut rows = Vec::new();
    for &n in counts {
        let n = n.min(study.samples);
        let mut wall = f64::INFINITY;
        let mut tallies = Default::default();
        for _ in 0..repeats.max(1) {
            let t0 = Instant::now();
            tallies = run::run_range_with_threads(study, 0..n, Some(threads), &|| {})?;
            wall = wall.min(t0.elapsed().as_secs_f64());
        }
        let successes = tallies
            .get(&0)
            .map_or(0, |t: &super::tally::PointTally| t.outcomes.success);
        let ci = wilson_interval(successes, n);
        rows.push(PrecisionRow {
            samples: n,
            successes,
            rate: successes as f64 / n as f64,
            ci95: ci,
            half_width: 0.5 * (ci[1] - ci[0]),
            wall_s: wall,
            samples_per_s: n as f64 / wall.max(1e-9),
        });
    }
    Ok(rows)
}

/// Samples needed for a 95% half-width `h` at success rate `p` (normal approximation).
pub fn samples_for(p: f64, h: f64) -> f64 {
    let z = 1.959_963_984_540_054_f64;
    // Never below the rule-of-three floor for p near 0 or 1.
    (z * z * (p * (1.0 - p)).max(1e-4) / (h * h)).ceil()
}

/// How the measurement was taken.
#[derive(Debug, Clone)]
pub struct Conditions {
    /// Samples/s of the largest count on 1 and on 2 threads.
    pub one_thread: f64,
    /// Samples/s of the largest count on 2 threads.
    pub two_threads: f64,
    /// Timed runs per count (the fastest is kept).
    pub repeats: usize,
    /// 1-minute load average before and after.
    pub load_before: String,
    /// 1-minute load average after the measurement.
    pub load_after: String,
}

/// The Markdown section (with its markers): `rows` at the study's fidelity, `fidelities` the
/// largest count at each fidelity.
pub fn section(
    cmd: &str,
    study_file: &str,
    rows: &[PrecisionRow],
    fidelities: &[(String, PrecisionRow)],
    c: &Conditions,
) -> String {
    let (one_thread, two_threads, repeats) = (c.one_thread, c.two_threads, c.repeats);
    let load = (&c.load_before, &c.load_after);
    let mut s = format!(
        "{BEGIN}\n## The statistical side: Monte Carlo precision against samples and time\n\n\
         Regenerate this section (the rest of the file is `bench accuracy`'s):\n\n```\n{cmd}\n```\n\n\
         The bundled study `{study_file}` (the quickstart line under μc uniform in [0.3, 0.7] and a \
         random tripod per part; one sample = one part through a freshly perturbed line), run for \
         increasing sample counts on this machine (2 threads; wall time = the fastest of {repeats} \
         runs; 1-minute load average {} before, {} after — the machine is shared with other builds, \
         so times are upper bounds). The interval is the 95% Wilson \
         score interval of the success rate; its half-width shrinks as 1/√n, so each halving costs \
         four times the samples and the time.\n\n\
         | samples | successes | success rate | 95% interval | half-width | wall time (s) | samples/s |\n\
         |---|---|---|---|---|---|---|\n",
        load.0, load.1
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {:.2}% | [{:.2}%, {:.2}%] | ±{:.2}% | {:.2} | {:.0} |\n",
            r.samples,
            r.successes,
            100.0 * r.rate,
            100.0 * r.ci95[0],
            100.0 * r.ci95[1],
            100.0 * r.half_width,
            r.wall_s,
            r.samples_per_s
        ));
    }
    if let Some(last) = rows.last() {
        s.push_str(&format!(
            "\nWhat a target precision costs at the measured success rate ({:.1}%) and speed ({:.0} samples/s on 2 threads):\n\n\
             | 95% half-width | samples | wall time |\n|---|---|---|\n",
            100.0 * last.rate,
            two_threads
        ));
        for h in [0.05, 0.02, 0.01, 0.005, 0.002, 0.001] {
            let n = samples_for(last.rate, h);
            let t = n / two_threads.max(1e-9);
            let time = if t < 120.0 {
                format!("{t:.1} s")
            } else if t < 7200.0 {
                format!("{:.1} min", t / 60.0)
            } else {
                format!("{:.1} h", t / 3600.0)
            };
            s.push_str(&format!("| ±{}% | {n:.0} | {time} |\n", 100.0 * h));
        }
        s.push_str(&format!(
            "\nParallel efficiency ({} samples): {:.0} samples/s on 1 thread, {:.0} on 2 threads: \
             speed-up {:.2}, efficiency {:.0}% (speed-up / 2).\n",
            last.samples,
            one_thread,
            two_threads,
            two_threads / one_thread.max(1e-9),
            50.0 * two_threads / one_thread.max(1e-9)
        ));
        if two_threads > 2.0 * one_thread {
            s.push_str(
                "(Above 100% is measurement noise: other work on the shared machine slowed the \
                 single-thread runs more than the two-thread ones. Samples share nothing, so the \
                 ideal is 100%.)\n",
            );
        }
    }
    if !fidelities.is_empty() {
        s.push_str(
            "\nFidelity against statistics: the same samples with a cheaper contact model. A faster \
             model buys more samples per second, but its success rate is a different number — a \
             bias no sample count removes (compare each interval with the exact model's):\n\n\
             | fidelity | success rate | 95% interval | samples/s (2 threads) | wall time for ±1% |\n\
             |---|---|---|---|---|\n",
        );
        for (name, r) in fidelities {
            let t = samples_for(r.rate, 0.01) / r.samples_per_s.max(1e-9);
            s.push_str(&format!(
                "| {name} | {:.2}% | [{:.2}%, {:.2}%] | {:.0} | {t:.1} s |\n",
                100.0 * r.rate,
                100.0 * r.ci95[0],
                100.0 * r.ci95[1],
                r.samples_per_s
            ));
        }
    }
    s.push_str(END);
    s.push('\n');
    s
}

/// Put `section` into `doc`: replace the marked section if there is one, else append it.
pub fn splice(doc: &str, section: &str) -> String {
    splice_between(doc, section, (BEGIN, END))
}

/// Put `section` into `doc` in place of the section between the markers `(begin, end)` if there
/// is one, else append it.
pub fn splice_between(doc: &str, section: &str, (begin, end): (&str, &str)) -> String {
    if let (Some(a), Some(b)) = (doc.find(begin), doc.find(end)) {
        if a < b {
            let mut rest = &doc[b + end.len()..];
            rest = rest.strip_prefix('\n').unwrap_or(rest);
            return format!("{}{}{}", &doc[..a], section, rest);
        }
    }
    let mut out = doc.to_string();
    if !out.ends_with('\n') {
        out.push('\n');
    }
    out.push('\n');
    out.push_str(section);
    out
}

/// The marked section of `doc`, if any (so `bench accuracy` can keep it when it rewrites the file).
pub fn existing(doc: &str) -> Option<String> {
    existing_between(doc, (BEGIN, END))
}

/// The section of `doc` between the markers `(begin, end)`, markers included, if any.
pub fn existing_between(doc: &str, (begin, end): (&str, &str)) -> Option<String> {
    let a = doc.find(begin)?;
    let b = doc.find(end)?;
    (a < b).then(|| format!("{}\n", &doc[a..b + end.len()]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splice_replaces_or_appends() {
        let sec = format!("{BEGIN}\nnew\n{END}\n");
        let doc = "# Title\n\ntext\n";
        let once = splice(doc, &sec);
        assert!(once.starts_with(doc) && once.ends_with(&sec));
        let old = format!("# Title\n\n{BEGIN}\nold\n{END}\n\ntail\n");
        let twice = splice(&old, &sec);
        assert_eq!(twice, format!("# Title\n\n{sec}\ntail\n"));
        assert_eq!(existing(&twice).unwrap(), sec);
        assert_eq!(splice(&twice, &sec), twice);
    }

    #[test]
    fn halving_the_half_width_costs_four_times_the_samples() {
        let a = samples_for(0.8, 0.02);
        let b = samples_for(0.8, 0.01);
        assert!((b / a - 4.0).abs() < 0.01, "{a} {b}");
        // 0.8 ± 1%: 1.96² · 0.16 / 1e-4 ≈ 6147.
        assert_eq!(b, 6147.0);
    }
}
