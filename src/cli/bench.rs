//! `pinfeed bench`: measurements that produce the reports in `results/`.

use anyhow::Result;
use clap::{Args, Subcommand};
use pinfeed::report::study_files::AccuracyBenchError;
use pinfeed::study::bench_error::BenchError;
use pinfeed::study::{contact_cost, map_cost};
use std::path::PathBuf;

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

/// A study's error with its settings named by their flags.
fn flagged(e: BenchError) -> anyhow::Error {
    match e {
        BenchError::Argument { .. } => anyhow::anyhow!(e.describe(&super::flag)),
        other => other.into(),
    }
}

/// Run `pinfeed bench`; `recorded` is the command line its report records.
pub fn run(args: &BenchArgs, recorded: &str) -> Result<()> {
    // The measurements run for seconds to hours: a spinner with the elapsed time and the stage.
    let spin = super::progress::spinner("bench", false);
    let result = measure(&args.what, &spin, recorded);
    spin.finish_and_clear();
    result
}

fn measure(what: &BenchWhat, spin: &indicatif::ProgressBar, cmd: &str) -> Result<()> {
    match what {
        BenchWhat::Accuracy {
            contacts,
            seed,
            out,
        } => {
            spin.set_message(format!(
                "accuracy: {contacts} contacts against the reference"
            ));
            let (table, files) = pinfeed::report::study_files::accuracy_bench(
                *contacts, *seed, cmd, out,
            )
            .map_err(|e| match e {
                AccuracyBenchError::Bench(b) => flagged(b),
                other => other.into(),
            })?;
            crate::out!("{table}");
            let files: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
            eprintln!("wrote {}", files.join(", "));
            Ok(())
        }
        BenchWhat::Contact {
            contacts,
            tol,
            seed,
            out,
        } => {
            let stage = |s: &str| spin.set_message(s.to_string());
            crate::out!(
                "{}",
                contact_cost::bench(*contacts, *tol, *seed, cmd, out, &stage).map_err(flagged)?
            );
            eprintln!("wrote {}", out.display());
            Ok(())
        }
        BenchWhat::Maps { repeats, out } => {
            spin.set_message(format!("maps: {repeats} timed runs per row"));
            // Other work on the machine slows every row: say how busy it was (Linux only).
            crate::out!(
                "{}",
                map_cost::bench(*repeats, cmd, out, &super::bench_mc::load_average)
                    .map_err(flagged)?
            );
            eprintln!("wrote {}", out.display());
            Ok(())
        }
        BenchWhat::Designs(a) => super::bench_designs::run(a, spin, cmd),
        BenchWhat::McPrecision {
            study,
            samples,
            repeats,
            out,
        } => super::bench_mc::run(study, samples, *repeats, out, spin, cmd),
        BenchWhat::MapTier(a) => super::bench_map_tier::run(a, spin, cmd),
        BenchWhat::Line(a) => super::bench_line::run(a, spin, cmd),
    }
}
