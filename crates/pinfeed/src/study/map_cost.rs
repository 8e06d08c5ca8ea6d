//! What a set of configuration maps costs: wall time of [`compute_maps`] (sampling, bands, runs; no
//! output) for the thesis's set of 18 contact parameters d = ±0.1 … ±0.9 at 360 θ0 each, per part,
//! fidelity and thread count. Each figure is the median (with min and max) of several repeats after
//! one warm-up run; the pool is built once per thread count, outside the timed region.

use crate::geometry::part_from_spec;
use crate::maps::{compute_maps, MapSettings};
use crate::mechanics::Fidelity;
use crate::study::bench_error::{uniform_model, BenchError};
use std::time::Instant;

/// The thesis's contact parameters: ±0.1 … ±0.9.
pub const THESIS_DS: [f64; 18] = [
    -0.9, -0.8, -0.7, -0.6, -0.5, -0.4, -0.3, -0.2, -0.1, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8,
    0.9,
];

/// One (part, fidelity, threads) row.
#[derive(Debug, Clone)]
pub struct MapCostRow {
    /// The part spec.
    pub part: String,
    /// The contact model.
    pub fidelity: Fidelity,
    /// Threads of the pool.
    pub threads: usize,
    /// Contacts in one computation of the maps (18 d × the θ0 count).
    pub contacts: usize,
    /// Median wall time over the repeats (s).
    pub median_s: f64,
    /// Fastest repeat (s).
    pub min_s: f64,
    /// Slowest repeat (s).
    pub max_s: f64,
}

/// Time `repeats` computations of the maps at `THESIS_DS` for each part, fidelity and thread count
/// (μc = 0.5, point pin, uniform pressure, θ0 step `theta_step_deg`, threshold 5°).
pub fn measure(
    parts: &[&str],
    fidelities: &[Fidelity],
    thread_counts: &[usize],
    theta_step_deg: f64,
    repeats: usize,
) -> Result<Vec<MapCostRow>, BenchError> {
    let mut rows = Vec::new();
    for part in parts {
        let poly = part_from_spec(part)?;
        let model = uniform_model(&poly)?;
        for &fidelity in fidelities {
            let settings = MapSettings::point_pin(fidelity, 0.5, theta_step_deg, 5.0);
            for &threads in thread_counts {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()?;
                let mut times = Vec::with_capacity(repeats);
                let mut contacts = 0;
                for r in 0..=repeats {
                    let t0 = Instant::now();
                    let maps =
                        pool.install(|| compute_maps(&poly, &model, &THESIS_DS, &settings))?;
                    let dt = t0.elapsed().as_secs_f64();
                    contacts = maps.iter().map(|m| m.samples.len()).sum();
                    if r > 0 {
                        times.push(dt);
                    }
                }
                times.sort_by(f64::total_cmp);
                rows.push(MapCostRow {
                    part: part.to_string(),
                    fidelity,
                    threads,
                    contacts,
                    median_s: times[times.len() / 2],
                    min_s: times[0],
                    max_s: times[times.len() - 1],
                });
            }
        }
    }
    Ok(rows)
}

/// Render the rows as a Markdown table.
pub fn markdown(rows: &[MapCostRow]) -> String {
    let mut s = String::from(
        "| part | model | threads | contacts | median s | min s | max s | µs per contact |\n\
         |---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        s += &format!(
            "| {} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.1} |\n",
            r.part,
            r.fidelity,
            r.threads,
            r.contacts,
            r.median_s,
            r.min_s,
            r.max_s,
            r.median_s * 1e6 * r.threads as f64 / r.contacts.max(1) as f64
        );
    }
    s
}

/// The report `bench maps` writes (its Markdown document) and the table it prints: `cores` and the
/// load averages before and after describe the machine; `out` is named in the command.
pub fn report(
    rows: &[MapCostRow],
    repeats: usize,
    cores: usize,
    (load_before, load_after): (&str, &str),
    cmd: &str,
) -> (String, String) {
    let table = markdown(rows);
    let doc = format!(
        "# Configuration maps: wall time\n\n\
         Regenerate with:\n\n```\n{cmd}\n```\n\n\
         Machine: {cores} cores, shared with other work (1-minute load average {load_before} before, \
         {load_after} after this run; with a load near the core count the 2-thread rows cannot \
         show their speed-up). Each row \
         times `maps::compute_maps` for the 18 thesis maps d = ±0.1 … ±0.9 with θ0 every 1° \
         (6480 contacts: sampling, bands and runs; no printing, files or figures), point pin, \
         μc = 0.5, uniform pressure, tolerance 1e-6: median, min and max of {repeats} runs after \
         one warm-up. *µs per contact* is thread-time per contact (median × threads / contacts). \
         Target: under 0.5 s with the exact model on 2 cores.\n\n{table}"
    );
    (table, doc)
}

/// `pinfeed bench maps`: `repeats` timed runs (1 to 1000) per part, model and thread count (1, 2
/// and every core), written to `out` headed by `cmd` with the machine's load before and after
/// (`load` reads it). Returns the table printed.
pub fn bench(
    repeats: usize,
    cmd: &str,
    out: &std::path::Path,
    load: &dyn Fn() -> String,
) -> Result<String, BenchError> {
    if repeats == 0 || repeats > 1000 {
        return Err(BenchError::argument(
            "repeats",
            "between 1 and 1000",
            repeats,
        ));
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut threads = vec![1, 2, cores];
    threads.sort_unstable();
    threads.dedup();
    let fids = [Fidelity::Exact, Fidelity::Ellipsoid, Fidelity::Tip];
    let load_before = load();
    let rows = measure(&["tripoly1", "tripoly2"], &fids, &threads, 1.0, repeats)?;
    let load_after = load();
    let (table, doc) = report(&rows, repeats, cores, (&load_before, &load_after), cmd);
    crate::output::write_file(out, &doc)?;
    Ok(table)
}
