//! `pinfeed mc STUDY.toml`: a Monte Carlo robustness study (docs/study-format.md). Without
//! `--shard` it runs every sample and writes `report.md`, `report.json` and `sensitivity.svg` to
//! `<out>` (default `pinfeed-out/mc/<study name>/`), printing the table (or the JSON with `--json`).
//! With `--shard K/N` it runs one contiguous share of the samples and writes only a shard file
//! (`<out>/shard-K-of-N.json`, default `<out>` = `pinfeed-out/mc/<study name>/shards/`) for
//! `pinfeed merge`.

use anyhow::{bail, Context, Result};
use clap::Args;
use pinfeed::study::mc::report::{self, McReport, StudyHeader};
use pinfeed::study::mc::shard::{ShardFile, ShardSpec};
use pinfeed::study::mc::{self, run};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `pinfeed mc`.
#[derive(Debug, Args)]
pub struct McArgs {
    /// Study file (TOML; see docs/study-format.md), or the name of a bundled study.
    pub study: PathBuf,
    /// Samples per sweep point (overrides the study's `samples`).
    #[arg(long)]
    pub samples: Option<u64>,
    /// Print the report as JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Worker threads (default: all cores); the results do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Run shard K of N (K 0-based) and write a shard file; `/N` takes K from
    /// SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Folder for the report (or the shard file).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// No table and no progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Run each sweep point in blocks of 1000 samples until the 95% confidence sequence of its
    /// success rate has a half-width of at most E (in (0, 0.5)), or its samples (the cap) are spent.
    #[arg(long, value_name = "E", value_parser = parse_precision, conflicts_with = "shard")]
    pub precision: Option<f64>,
}

/// `--precision E`: a number in (0, 0.5) (`mc` and `run`).
pub(crate) fn parse_precision(text: &str) -> Result<f64, String> {
    let e: f64 = text
        .parse()
        .map_err(|_| format!("--precision must be a number in (0, 0.5), got '{text}'"))?;
    mc::sequential::check_precision(e)
}

/// The default report folder of a study.
pub fn default_dir(study_name: &str) -> PathBuf {
    pinfeed::default_out(&["mc", study_name])
}

pub fn run(args: &McArgs) -> Result<()> {
    if let Some(n) = args.samples {
        if !(1..=mc::MAX_SAMPLES).contains(&n) {
            bail!("--samples must lie in [1, {}], got {n}", mc::MAX_SAMPLES);
        }
    }
    if let Some(t) = args.threads {
        if !(1..=1024).contains(&t) {
            bail!("--threads must lie in [1, 1024], got {t}");
        }
    }
    let study = pinfeed::study::bundled::load_study(&args.study, args.samples)?;
    for w in study.warnings() {
        eprintln!("warning: {w}");
    }
    let header = StudyHeader::of(&study);
    let total = study.total_samples();
    let shard = match &args.shard {
        Some(text) => Some(ShardSpec::parse(text, &|k| std::env::var(k).ok())?),
        None => None,
    };
    let range = shard.map_or(0..total, |s| s.range(total));
    let bar = super::progress::bar(range.end - range.start, "samples", args.quiet);
    let started = Instant::now();
    let running = || format!("running {}", args.study.display());
    let (tallies, stops) = match args.precision {
        None => {
            let tallies =
                run::run_range_with_threads(&study, range.clone(), args.threads, &|| bar.inc(1))
                    .with_context(running)?;
            (tallies, None)
        }
        Some(e) => {
            let (tallies, stops) = mc::sequential::run_to_precision(
                &study,
                e,
                mc::sequential::BLOCK,
                args.threads,
                &|| bar.inc(1),
            )
            .with_context(running)?;
            (tallies.into_iter().enumerate().collect(), Some(stops))
        }
    };
    let wall = started.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let n: u64 = tallies.values().map(|t| t.samples).sum();
    let speed = format!(
        "{n} samples in {wall:.2} s wall: {:.0} samples/s",
        n as f64 / wall.max(1e-9)
    );

    if let Some(spec) = shard {
        let dir = args
            .out
            .clone()
            .unwrap_or_else(|| default_dir(&study.name).join("shards"));
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        let path = dir.join(spec.file_name());
        let file =
            ShardFile::new(&header, spec, range.clone(), &tallies).with_study_path(&args.study);
        let text = serde_json::to_string_pretty(&file)? + "\n";
        pinfeed::output::write_atomic(&path, text)
            .with_context(|| format!("writing {}", path.display()))?;
        if !args.quiet {
            eprintln!(
                "shard {}/{}: samples [{}, {}) of {total}; {speed}; wrote {}",
                spec.index,
                spec.count,
                range.start,
                range.end,
                path.display()
            );
        }
        return Ok(());
    }
    let tallies: Vec<_> = (0..study.points.len())
        .map(|j| tallies.get(&j).cloned().unwrap_or_default())
        .collect();
    let dir = args.out.clone().unwrap_or_else(|| default_dir(&study.name));
    let r = match (args.precision, stops) {
        (Some(e), Some(stops)) => report::with_sequential(
            report::build(
                &report::with_out(report::with_precision(header, e), &dir),
                &tallies,
            ),
            &stops,
        ),
        _ => report::build(&report::with_out(header, &dir), &tallies),
    };
    publish(&r, &dir, args.json, args.quiet)?;
    if !args.quiet && !args.json {
        eprintln!("{speed}");
    }
    Ok(())
}

/// Write a report's files to `dir` ([`pinfeed::report::study_files::mc_report_files`]) and print the table or the JSON.
/// `mc` and `merge` share it, so their outputs are the same bytes.
pub fn publish(r: &McReport, dir: &Path, json: bool, quiet: bool) -> Result<()> {
    let (json_text, md) = pinfeed::report::study_files::mc_report_files(r, dir)?;
    let text = if json {
        json_text
    } else if quiet {
        String::new()
    } else {
        format!("{}\nreport: {}\n", report::table(r), md.display())
    };
    super::stdout::print_result(&text)
}
