//! `pinfeed compare A.toml B.toml ...`: run line designs on the same part stream and print one
//! table (pin layouts measured against fence designs; [`pinfeed::study::compare`]).
//!
//! Each design runs its own feed (headway, orientation and lateral distributions, seed, number of
//! parts), so its row is the same whichever files it is compared with and in whatever order;
//! designs whose feeds agree see the same parts in the same order. The part (shape, scale,
//! support) must be the same in every file; otherwise the scenario is refused with the reason.
//! `--parts`, `--seed`, `--headway` and `--uniform-orientation` impose one value on every design
//! ([`pinfeed::scenario::FeedOverrides`]), said in the header. Nothing is written to disk.

use anyhow::{Context, Result};
use clap::Args;
use pinfeed::report::compare_table;
use pinfeed::scenario::FeedOverrides;
use pinfeed::study::compare::{compare_observed, designs};
use std::path::PathBuf;

/// Arguments of `pinfeed compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// Scenario files (one part); each runs its own feed unless an option below imposes one.
    #[arg(required = true, num_args = 1..)]
    pub scenarios: Vec<PathBuf>,
    /// Number of parts of every design (default: each file's [feed] parts).
    #[arg(long)]
    pub parts: Option<u64>,
    /// Random seed of every design (default: each file's seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Seconds between arrivals for every design (default: each file's [feed] headway).
    #[arg(long)]
    pub headway: Option<f64>,
    /// Feed orientations uniform on [0°, 360°) instead of each file's distribution.
    #[arg(long)]
    pub uniform_orientation: bool,
    /// Print the rows as a JSON array of objects.
    #[arg(long, conflicts_with = "markdown")]
    pub json: bool,
    /// Print the table as Markdown.
    #[arg(long)]
    pub markdown: bool,
    /// No progress display.
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(args: &CompareArgs) -> Result<()> {
    let d = designs(
        &args.scenarios,
        FeedOverrides {
            seed: args.seed,
            parts: args.parts,
            headway: args.headway,
            uniform_orientation: args.uniform_orientation,
        },
    )?;
    let bar = super::progress::bar(0, "parts", args.quiet || args.json);
    let tell = super::progress::counter(&bar);
    let rows = compare_observed(&d.scenes, &d.files, &d.online, &tell)
        .context("running the comparison")?;
    bar.finish_and_clear();
    let text = if args.json {
        // One document: the version fields and the rows, one per design.
        #[derive(serde::Serialize)]
        struct Designs<'a, T: serde::Serialize> {
            designs: &'a T,
        }
        pinfeed::report::versioned::pretty(&Designs { designs: &rows })?
    } else {
        let feed = compare_table::feed_lines(&d.files, &d.scenes, &d.overrides);
        let loops = compare_table::loop_lines(&rows);
        if args.markdown {
            format!("{feed}\n\n{}{loops}", compare_table::markdown(&rows))
        } else {
            format!("{feed}\n{}{loops}", compare_table::text(&rows))
        }
    };
    super::stdout::print_result(&text)
}
