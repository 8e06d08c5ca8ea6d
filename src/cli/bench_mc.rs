//! `pinfeed bench mc-precision`: the statistical side of accuracy against time. Runs a Monte Carlo
//! study for increasing sample counts (2 threads), and its largest count on 1 thread too, and
//! writes the 95% half-width against samples and wall time, with the parallel efficiency, as a
//! marked section of `results/accuracy-vs-time.md` (the rest of the file is left as it is), with
//! the largest count repeated at the cheaper fidelities (speed against bias).

use anyhow::{bail, Result};
use pinfeed::mechanics::Fidelity;
use pinfeed::study::mc::{self, precision};
use std::path::Path;

/// The machine's 1-minute load average (Linux), for the record.
pub(super) fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|l| l.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "unknown".into())
}

/// Measure and write the section.
pub fn run(
    study_file: &Path,
    counts: &[u64],
    repeats: usize,
    out: &Path,
    spin: &indicatif::ProgressBar,
    cmd: &str,
) -> Result<()> {
    if !(1..=100).contains(&repeats) {
        bail!("--repeats must lie in [1, 100], got {repeats}");
    }
    if counts.is_empty() || counts.iter().any(|&n| !(1..=10_000_000).contains(&n)) {
        bail!("--samples needs one or more counts in [1, 10000000], got {counts:?}");
    }
    let largest = *counts.iter().max().expect("non-empty");
    let study = mc::load(study_file, Some(largest))?;
    if !study.axes.is_empty() {
        bail!(
            "{}: the precision benchmark needs a study without sweeps",
            study_file.display()
        );
    }
    // Warm-up (page in the code, start the pools).
    spin.set_message("mc-precision: warm-up");
    precision::measure(&study, &[largest.min(100)], 2, 1)?;
    let load_before = load_average();
    spin.set_message(format!("mc-precision: {counts:?} samples, 2 threads"));
    let rows = precision::measure(&study, counts, 2, repeats)?;
    spin.set_message("mc-precision: 1 against 2 threads");
    // 1 against 2 threads, alternating so that other work on the machine disturbs both alike;
    // the fastest of each is kept.
    let (mut one, mut two) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..repeats {
        one = one.min(precision::measure(&study, &[largest], 1, 1)?[0].wall_s);
        two = two.min(precision::measure(&study, &[largest], 2, 1)?[0].wall_s);
    }
    let (one, two) = (largest as f64 / one, largest as f64 / two);
    let exact_row = rows
        .iter()
        .find(|r| r.samples == largest)
        .expect("the largest count was measured");
    // The same samples at the cheaper fidelities (the exact model's row is the largest count).
    let mut fidelities = vec![(
        study.scene.contact.fidelity.name().to_string(),
        exact_row.clone(),
    )];
    for fid in [Fidelity::Ellipsoid, Fidelity::Tip] {
        if fid == study.scene.contact.fidelity {
            continue;
        }
        spin.set_message(format!("mc-precision: {} model", fid.name()));
        let mut cheaper = mc::load(study_file, Some(largest))?;
        cheaper.scene.contact.fidelity = fid;
        let row = precision::measure(&cheaper, &[largest], 2, repeats)?;
        fidelities.push((fid.name().to_string(), row[0].clone()));
    }
    let load_after = load_average();
    let section = precision::section(
        cmd,
        &study_file.display().to_string(),
        &rows,
        &fidelities,
        &precision::Conditions {
            one_thread: one,
            two_threads: two,
            repeats,
            load_before,
            load_after,
        },
    );
    pinfeed::output::rewrite_file(out, |doc| precision::splice(doc, &section))?;
    crate::out!("{section}");
    eprintln!(
        "wrote the Monte Carlo precision section of {}",
        out.display()
    );
    Ok(())
}
