//! `pinfeed fuzz TARGET`: the long-running fuzzing driver (docs/commands.md#fuzzing-and-robustness-pinfeed-fuzz;
//! [`crate::study::robustness`]). It generates and mutates scenario and study files, random
//! contacts and random polygons, runs each case in-process under `catch_unwind` with a per-case
//! time budget, and writes the counts to a Markdown report (default pinfeed-out/robustness.md; the committed report: --report results/robustness.md) headed
//! by the command that regenerates it. `--case N` re-runs one case and prints its input.

use crate::study::robustness::{self, Class, Corpus, Options, Target};
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

/// What to fuzz.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FuzzTarget {
    Scenarios,
    Studies,
    Contacts,
    Polygons,
    All,
}

/// Arguments of `pinfeed fuzz`.
#[derive(Debug, Args)]
pub struct FuzzArgs {
    /// scenarios, studies, contacts, polygons or all.
    #[arg(value_enum)]
    pub target: FuzzTarget,
    /// Cases per target.
    #[arg(long, default_value_t = 1000)]
    pub count: u64,
    /// Cases of the contacts target (default: --count).
    #[arg(long)]
    pub contacts: Option<u64>,
    /// Seed; case i of a target draws from its own stream (seed, i).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Worker threads (default: all cores); the counts do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Seconds a case may run before it counts as a hang.
    #[arg(long, default_value_t = 60.0)]
    pub budget: f64,
    /// The report file.
    #[arg(long, default_value = "pinfeed-out/robustness.md")]
    pub report: PathBuf,
    /// The project root, where scenarios/, studies/ and tests/fixtures/ are read.
    #[arg(long, default_value = ".")]
    pub root: PathBuf,
    /// Re-run only case N of the target: print its input and how it ended (no report).
    #[arg(long, value_name = "N")]
    pub case: Option<u64>,
}

fn targets(t: FuzzTarget) -> Vec<Target> {
    match t {
        FuzzTarget::Scenarios => vec![Target::Scenarios],
        FuzzTarget::Studies => vec![Target::Studies],
        FuzzTarget::Contacts => vec![Target::Contacts],
        FuzzTarget::Polygons => vec![Target::Polygons],
        FuzzTarget::All => Target::ALL.to_vec(),
    }
}

/// The command line that regenerates the report.
fn command_line(args: &FuzzArgs) -> String {
    let target = format!("{:?}", args.target).to_lowercase();
    let mut c = format!(
        "pinfeed fuzz {target} --count {} --seed {} --budget {}",
        args.count, args.seed, args.budget
    );
    if let Some(n) = args.contacts {
        c.push_str(&format!(" --contacts {n}"));
    }
    c.push_str(&format!(" --report {}", args.report.display()));
    c
}

pub fn run(args: &FuzzArgs) -> Result<()> {
    if !(args.budget.is_finite() && args.budget > 0.0 && args.budget <= 86_400.0) {
        bail!(
            "--budget must lie in (0, 86400] seconds, got {}",
            args.budget
        );
    }
    if args.count > 100_000_000 || args.contacts.is_some_and(|n| n > 100_000_000) {
        bail!("--count and --contacts must be at most 100000000");
    }
    let corpus = Arc::new(Corpus::load(&args.root).map_err(anyhow::Error::msg)?);
    let threads = match args.threads {
        Some(0) => bail!("--threads must be at least 1"),
        Some(n) => n,
        None => std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1),
    };
    let opts = Options {
        seed: args.seed,
        threads,
        budget: Duration::from_secs_f64(args.budget),
        root: args.root.clone(),
    };
    if let Some(i) = args.case {
        for t in targets(args.target) {
            println!("== {} case {i}", t.name());
            println!("{}", robustness::case_input(t, &corpus, args.seed, i));
            let r = robustness::run_case(t, &corpus, args.seed, i);
            println!(
                "-> {:?}{}{}",
                r.class,
                r.status
                    .as_ref()
                    .map(|s| format!(" (status {s})"))
                    .unwrap_or_default(),
                if r.detail.is_empty() {
                    String::new()
                } else {
                    format!(": {}", r.detail)
                }
            );
        }
        return Ok(());
    }
    let mut tallies = Vec::new();
    for t in targets(args.target) {
        let count = match t {
            Target::Contacts => args.contacts.unwrap_or(args.count),
            _ => args.count,
        };
        eprintln!("fuzz {}: {count} cases on {threads} threads", t.name());
        let name = t.name();
        let tally = robustness::run_target(t, count, &corpus, &opts, &move |d| {
            eprintln!("  {name}: {d}/{count}")
        });
        eprintln!(
            "  {name}: {} generated, {} panics, {} hangs, {} non-finite, {} disagreements, {:.0} s",
            tally.generated,
            tally.count(Class::Panic),
            tally.count(Class::Hang),
            tally.count(Class::NonFinite),
            tally.count(Class::Disagreement),
            tally.seconds
        );
        tallies.push((t, tally));
    }
    let text = robustness::report(&command_line(args), &opts, &tallies);
    if let Some(dir) = args.report.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    crate::report::atomic::write_atomic(&args.report, &text)
        .with_context(|| format!("writing {}", args.report.display()))?;
    print!("{text}");
    Ok(())
}
