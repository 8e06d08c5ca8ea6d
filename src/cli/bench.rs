//! `pinfeed bench`: measurements that produce the reports in `results/`.

use crate::mechanics::Fidelity;
use crate::study::{contact_cost, map_cost};
use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use std::path::{Path, PathBuf};

#[derive(Debug, Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    pub what: BenchWhat,
}

#[derive(Debug, Subcommand)]
pub enum BenchWhat {
    /// What accuracy costs in time: every fidelity tier against a tight exact reference; writes
    /// OUT.{md,csv,svg} (the committed report: --out results/accuracy-vs-time).
    Accuracy {
        /// Random contacts (split evenly over tripoly1, tripoly2, square, lshape).
        #[arg(long, default_value_t = 1200)]
        contacts: usize,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output path without extension.
        #[arg(long, default_value = "pinfeed-out/accuracy-vs-time")]
        out: PathBuf,
    },
    /// Monte Carlo precision against samples and wall time (and 1- vs 2-thread efficiency) for a
    /// study; writes a marked section of --out (the committed report: results/accuracy-vs-time.md).
    McPrecision {
        /// A study without sweeps.
        #[arg(long, default_value = "studies/quickstart_mu_tripod.toml")]
        study: PathBuf,
        /// Sample counts, comma-separated.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "100,200,500,1000,2000,5000"
        )]
        samples: Vec<u64>,
        /// Timed runs per count; the fastest is kept.
        #[arg(long, default_value_t = 3)]
        repeats: usize,
        /// The Markdown file that receives the section.
        #[arg(long, default_value = "pinfeed-out/accuracy-vs-time.md")]
        out: PathBuf,
    },
    /// Time, evaluations and self-accuracy per contact for each fidelity on the reference parts;
    /// writes --out (the committed report: results/contact-model.md).
    Contact {
        /// Random contacts per (part, fidelity).
        #[arg(long, default_value_t = 400)]
        contacts: usize,
        /// Integration tolerance under test.
        #[arg(long, default_value_t = 1e-6)]
        tol: f64,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output Markdown file.
        #[arg(long, default_value = "pinfeed-out/contact-model.md")]
        out: PathBuf,
    },
    /// Designs for many parts: each mode alone and all modes together, every verdict from the
    /// line; writes results/designs.md (or --out).
    Designs(super::bench_designs::DesignsArgs),
    /// Wall time of the 18 thesis configuration maps (d = ±0.1 … ±0.9, 360 θ0 each) per part,
    /// model and thread count; writes --out (the committed report: results/maps/timing.md).
    Maps {
        /// Timed repeats per row (after one warm-up).
        #[arg(long, default_value_t = 5)]
        repeats: usize,
        /// Output Markdown file.
        #[arg(long, default_value = "pinfeed-out/maps-timing.md")]
        out: PathBuf,
    },
    /// The certified map tier against the exact model: per contact (a section of
    /// results/accuracy-vs-time.md) and on the line (a section of results/line-speed.md).
    MapTier(super::bench_map_tier::MapTierArgs),
    /// What the line adds to its contacts: each scenario's run against the same pushes as a bare
    /// batch; writes a section of --out (the committed report: results/line-speed.md).
    Line(super::bench_line::LineArgs),
}

pub fn run(args: &BenchArgs) -> Result<()> {
    // The measurements run for seconds to hours: a spinner with the elapsed time and the stage.
    let spin = super::progress::spinner("bench", false);
    let result = measure(&args.what, &spin);
    spin.finish_and_clear();
    result
}

fn measure(what: &BenchWhat, spin: &indicatif::ProgressBar) -> Result<()> {
    match what {
        BenchWhat::Accuracy {
            contacts,
            seed,
            out,
        } => {
            if *contacts < 4 || *contacts > 1_000_000 {
                anyhow::bail!("--contacts must be between 4 and 1000000, got {contacts}");
            }
            let parts = ["tripoly1", "tripoly2", "square", "lshape"];
            spin.set_message(format!(
                "accuracy: {contacts} contacts against the reference"
            ));
            let st = crate::study::accuracy::run(&parts, *contacts, *seed)?;
            let cmd = format!(
                "cargo run --release -- bench accuracy --contacts {contacts} --seed {seed} --out {}",
                out.display()
            );
            let p_md = out.with_extension("md");
            let old = std::fs::read_to_string(&p_md).unwrap_or_default();
            let md = crate::study::accuracy::report_keeping(&st, &cmd, &old);
            let p_csv = out.with_extension("csv");
            let p_svg = out.with_extension("svg");
            write_file(&p_md, md)?;
            write_file(&p_csv, crate::study::accuracy::csv(&st))?;
            crate::report::plot_accuracy::plot_accuracy(&st, &p_svg)
                .with_context(|| format!("writing {}", p_svg.display()))?;
            print!("{}", crate::study::accuracy::markdown_table(&st));
            eprintln!(
                "wrote {}, {}, {}",
                p_md.display(),
                p_csv.display(),
                p_svg.display()
            );
            Ok(())
        }
        BenchWhat::Contact {
            contacts,
            tol,
            seed,
            out,
        } => {
            if *contacts == 0 || *contacts > 1_000_000 {
                anyhow::bail!("--contacts must be between 1 and 1000000, got {contacts}");
            }
            if !(*tol > 0.0 && *tol <= 1e-2) {
                anyhow::bail!("--tol must be in (0, 0.01], got {tol}");
            }
            let parts = ["tripoly1", "tripoly2", "square", "lshape"];
            let fids = [Fidelity::Tip, Fidelity::Ellipsoid, Fidelity::Exact];
            spin.set_message(format!("contact: {contacts} contacts per part and model"));
            let rows = contact_cost::measure(&parts, &fids, *contacts, *tol, *seed, true)?;
            spin.set_message("contact: cost against the vertex count");
            let scaling = contact_cost::vertex_scaling(
                &[3, 6, 12, 24, 48],
                (*contacts / 4).max(1),
                *tol,
                *seed,
            )?;
            let (table, doc) = contact_cost::report(&rows, &scaling, *contacts, *tol, *seed, out);
            write_file(out, &doc)?;
            print!("{table}");
            eprintln!("wrote {}", out.display());
            Ok(())
        }
        BenchWhat::Maps { repeats, out } => {
            spin.set_message(format!("maps: {repeats} timed runs per row"));
            bench_maps(*repeats, out)
        }
        BenchWhat::Designs(a) => super::bench_designs::run(a, spin),
        BenchWhat::McPrecision {
            study,
            samples,
            repeats,
            out,
        } => super::bench_mc::run(study, samples, *repeats, out, spin),
        BenchWhat::MapTier(a) => super::bench_map_tier::run(a, spin),
        BenchWhat::Line(a) => super::bench_line::run(a, spin),
    }
}

/// Write a report file (creating its folder), naming it on failure.
pub(super) fn write_file(path: &Path, bytes: impl AsRef<[u8]>) -> Result<()> {
    crate::report::create_parent(path)?;
    crate::report::atomic::write_atomic(path, bytes)
        .with_context(|| format!("writing {}", path.display()))
}

/// Rewrite a report file from its current text (empty when it does not exist yet): for the
/// commands that replace their own marked section of a shared report.
pub(super) fn rewrite_file(path: &Path, edit: impl FnOnce(&str) -> String) -> Result<()> {
    let old = std::fs::read_to_string(path).unwrap_or_default();
    write_file(path, edit(&old))
}

fn bench_maps(repeats: usize, out: &Path) -> Result<()> {
    if repeats == 0 || repeats > 1000 {
        anyhow::bail!("--repeats must be between 1 and 1000, got {repeats}");
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut threads = vec![1, 2, cores];
    threads.sort_unstable();
    threads.dedup();
    let fids = [Fidelity::Exact, Fidelity::Ellipsoid, Fidelity::Tip];
    // Other work on the machine slows every row: say how busy it was (Linux only).
    let load = super::bench_mc::load_average;
    let load_before = load();
    let rows = map_cost::measure(&["tripoly1", "tripoly2"], &fids, &threads, 1.0, repeats)?;
    let load_after = load();
    let (table, doc) = map_cost::report(&rows, repeats, cores, (&load_before, &load_after), out);
    write_file(out, &doc)?;
    print!("{table}");
    eprintln!("wrote {}", out.display());
    Ok(())
}
