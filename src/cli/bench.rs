//! `pinfeed bench`: measurements that produce the reports in `results/`.

use crate::mechanics::Fidelity;
use crate::study::contact_cost;
use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    pub what: BenchWhat,
}

#[derive(Debug, Subcommand)]
pub enum BenchWhat {
    /// Time, evaluations and self-accuracy per contact for each fidelity on the reference parts;
    /// writes results/contact-model.md.
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
        #[arg(long, default_value = "results/contact-model.md")]
        out: PathBuf,
    },
}

pub fn run(args: &BenchArgs) -> Result<()> {
    match &args.what {
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
            let rows = contact_cost::measure(&parts, &fids, *contacts, *tol, *seed)?;
            let table = contact_cost::markdown(&rows);
            let cmd = format!(
                "cargo run --release -- bench contact --contacts {contacts} --tol {tol:e} --seed {seed} --out {}",
                out.display()
            );
            let doc = format!(
                "# Contact model: cost and self-accuracy per contact\n\n\
                 Regenerate with:\n\n```\n{cmd}\n```\n\n\
                 Machine: {} cores. Each row: {contacts} random contacts (θ0 uniform, d uniform in \
                 [−0.9, 0.9], point pin, μc = 0.5, uniform pressure). Times are wall-clock per contact \
                 (single thread), including contacts where the pin misses. *Evaluations* are \
                 limit-surface evaluations per touching contact (exact: dissipation evaluations \
                 inside the Newton solves; tip/ellipsoid: closed-form solves). *Self-error* is \
                 |θf(tol) − θf(tol/1000)| with the same model: the integration error at the \
                 default tolerance, not the model error (see the accuracy-vs-time report for that).\n\n\
                 {table}\n",
                std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
            );
            if let Some(dir) = out.parent() {
                std::fs::create_dir_all(dir).ok();
            }
            std::fs::write(out, &doc).with_context(|| format!("writing {}", out.display()))?;
            print!("{table}");
            eprintln!("wrote {}", out.display());
            Ok(())
        }
    }
}
