//! `pinfeed fuzz TARGET`: the long-running fuzzing driver (docs/commands.md#fuzzing-and-robustness-pinfeed-fuzz;
//! [`pinfeed::study::robustness`]). It generates and mutates scenario and study files, random
//! contacts and random polygons, runs each case in-process under `catch_unwind` with a per-case
//! time budget, and writes the counts to a Markdown report (default pinfeed-out/robustness.md; the committed report: --report results/robustness.md) headed
//! by the command that regenerates it. `--case N` re-runs one case and prints its input.
//!
//! The targets whose inputs are `pinfeed` command lines run them through the commands' own
//! argument parsers, so they live here: [`plans`] (`pinfeed plan` argument sets) and [`csvs`]
//! (measured-band files with `validate` and `calibrate` arguments), given to the driver in the
//! corpus ([`corpus`]).

pub mod csvs;
pub mod plans;

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use pinfeed::study::robustness::counts::MAX_CASES;
use pinfeed::study::robustness::files::SeedsError;
use pinfeed::study::robustness::{self, Class, Corpus, Options, Target};
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
    /// Sensing, actuator, controller and policy scenarios with pairs of keys set together.
    Pairs,
    /// `pinfeed plan` argument sets.
    Plans,
    /// Measured-band CSV files with `validate` and `calibrate` arguments.
    Csvs,
    /// Shard files edited before `merge`.
    Merges,
    /// `compare` of bundled designs in both orders and each alone.
    Compares,
    All,
}

/// Arguments of `pinfeed fuzz`.
#[derive(Debug, Args)]
pub struct FuzzArgs {
    /// scenarios, studies, contacts, polygons, pairs, plans, csvs, merges, compares or all.
    #[arg(value_enum)]
    pub target: FuzzTarget,
    /// Cases per target.
    #[arg(long, default_value_t = 1000)]
    pub count: u64,
    /// Cases of the contacts target (default: --count).
    #[arg(long)]
    pub contacts: Option<u64>,
    /// Cases of other targets, overriding --count: TARGET=N,... (e.g. plans=500,pairs=20000).
    #[arg(long, value_name = "TARGET=N,...")]
    pub counts: Option<String>,
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

/// The fuzzing corpus of the project at `root`, with the command-line targets' cases.
pub fn corpus(root: &std::path::Path) -> Result<Corpus, SeedsError> {
    Ok(Corpus::load(root)?
        .with_commands(Target::Plans, plans::CASES)
        .with_commands(Target::Csvs, csvs::CASES))
}

fn targets(t: FuzzTarget) -> Vec<Target> {
    match t {
        FuzzTarget::Scenarios => vec![Target::Scenarios],
        FuzzTarget::Studies => vec![Target::Studies],
        FuzzTarget::Contacts => vec![Target::Contacts],
        FuzzTarget::Polygons => vec![Target::Polygons],
        FuzzTarget::Pairs => vec![Target::Pairs],
        FuzzTarget::Plans => vec![Target::Plans],
        FuzzTarget::Csvs => vec![Target::Csvs],
        FuzzTarget::Merges => vec![Target::Merges],
        FuzzTarget::Compares => vec![Target::Compares],
        FuzzTarget::All => Target::ALL.to_vec(),
    }
}

/// Run `pinfeed fuzz`; `recorded` is the command line its report records.
pub fn run(args: &FuzzArgs, recorded: &str) -> Result<()> {
    if !(args.budget.is_finite() && args.budget > 0.0 && args.budget <= 86_400.0) {
        bail!(
            "--budget must lie in (0, 86400] seconds, got {}",
            args.budget
        );
    }
    if args.count > MAX_CASES || args.contacts.is_some_and(|n| n > MAX_CASES) {
        bail!("--count and --contacts must be at most {MAX_CASES}");
    }
    let overrides = args
        .counts
        .as_deref()
        .map(robustness::counts::parse_counts)
        .transpose()
        .map_err(anyhow::Error::msg)?
        .unwrap_or_default();
    let corpus = Arc::new(corpus(&args.root).map_err(anyhow::Error::msg)?);
    let threads = match args.threads {
        Some(0) => bail!("--threads must be at least 1"),
        Some(n) => n,
        None => std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1),
    };
    // Work a case hands to rayon (plan searches, ensembles) runs on at most as many threads.
    let _ = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global();
    let opts = Options {
        seed: args.seed,
        threads,
        budget: Duration::from_secs_f64(args.budget),
        root: args.root.clone(),
    };
    if let Some(i) = args.case {
        for t in targets(args.target) {
            crate::out!("{}", robustness::counts::replay(t, &corpus, args.seed, i));
        }
        return Ok(());
    }
    let mut tallies = Vec::new();
    for t in targets(args.target) {
        let count = match overrides.iter().find(|(o, _)| *o == t) {
            Some(&(_, n)) => n,
            None => match t {
                Target::Contacts => args.contacts.unwrap_or(args.count),
                _ => args.count,
            },
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
    let text = robustness::report(recorded, &opts, &tallies);
    if let Some(dir) = args.report.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    pinfeed::output::write_atomic(&args.report, &text)
        .with_context(|| format!("writing {}", args.report.display()))?;
    crate::out!("{text}");
    Ok(())
}
