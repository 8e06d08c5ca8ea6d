//! `pinfeed bench line`: a scenario's line against its own pushes run as a bare batch; writes the
//! marked section of results/line-speed.md ([`pinfeed::study::line_cost`]).

use anyhow::{bail, Context, Result};
use clap::Args;
use pinfeed::study::line_cost::{measure, section, MARKERS};
use pinfeed::study::mc::precision::splice_between;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct LineArgs {
    /// Scenario files, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "scenarios/quickstart.toml,scenarios/crowded_belt.toml"
    )]
    pub scenarios: Vec<PathBuf>,
    /// Parts per run.
    #[arg(long, default_value_t = 20_000)]
    pub parts: u64,
    /// Alternating repeats of the line and the batches (the minimum of each is reported).
    #[arg(long, default_value_t = 3)]
    pub reps: usize,
    #[arg(long, default_value = "pinfeed-out/line-speed.md")]
    pub out: PathBuf,
}

pub fn run(a: &LineArgs, spin: &indicatif::ProgressBar, cmd: &str) -> Result<()> {
    if a.parts == 0 || a.parts > 10_000_000 {
        bail!("--parts must be between 1 and 10000000, got {}", a.parts);
    }
    if a.reps == 0 || a.reps > 100 {
        bail!("--reps must be between 1 and 100, got {}", a.reps);
    }
    let mut rows = Vec::new();
    for path in &a.scenarios {
        let scene = pinfeed::scenario::load(path)?;
        spin.set_message(format!("line: {}", path.display()));
        let row = measure(&scene, a.parts, a.reps)
            .with_context(|| format!("measuring {}", path.display()))?;
        let line = format!(
            "{}: line {:.2} s, batch {:.2} s (recording {:.2} s), ratio {:.3} ({:.3}–{:.3} in the repeats)",
            path.display(),
            row.line_s,
            row.bare_s,
            row.bare_recorded_s,
            row.ratio(),
            row.repeat_ratios.0,
            row.repeat_ratios.1
        );
        super::progress::note(spin, &line);
        rows.push(row);
    }
    let marked = format!("{}\n{}{}\n", MARKERS.0, section(&rows, cmd), MARKERS.1);
    pinfeed::output::rewrite_file(&a.out, |old| splice_between(old, &marked, MARKERS))?;
    eprintln!("wrote {}", a.out.display());
    Ok(())
}
