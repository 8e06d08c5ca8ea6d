//! `pinfeed compare A.toml B.toml ...`: run line designs on the same part stream and print one
//! table (pin layouts measured against fence designs; [`pinfeed::study::compare`]).
//!
//! The same part stream: the first scenario's feed (number of parts, arrivals, orientation and
//! lateral distributions) and seed are imposed on every scenario ([`pinfeed::scenario::FeedSource`]),
//! so part i arrives at the same time with the same orientation and offset in every design. The
//! part (shape, scale, support) must be the same in every file, and the first file's lateral
//! offsets must fit on every belt; otherwise the scenario is refused with the reason. Each
//! scenario keeps its own belt, obstacles, goal and model. `--parts` and `--seed` override the
//! first file's; `--uniform-orientation` feeds every design parts at orientations uniform on
//! [0°, 360°) instead of the first file's distribution. Nothing is written to disk.

use anyhow::{Context, Result};
use clap::Args;
use pinfeed::report::compare_table;
use pinfeed::study::compare::{compare_observed, designs};
use std::path::PathBuf;

/// Arguments of `pinfeed compare`.
#[derive(Debug, Args)]
pub struct CompareArgs {
    /// Scenario files; the first one's feed and seed are used for all.
    #[arg(required = true, num_args = 1..)]
    pub scenarios: Vec<PathBuf>,
    /// Number of parts (overrides the first file's [feed] parts).
    #[arg(long)]
    pub parts: Option<u64>,
    /// Random seed (overrides the first file's seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Feed orientations uniform on [0°, 360°) instead of the first file's distribution.
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
        args.seed,
        args.parts,
        args.uniform_orientation,
    )?;
    let (files, source, parts) = (&d.files, &d.source, d.source.feed.parts);
    let bar = super::progress::bar(0, "parts", args.quiet || args.json);
    let tell = super::progress::counter(&bar);
    let rows = compare_observed(&d.scenes, files, &d.online, parts, &tell)
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
        let feed = compare_table::feed_line(&files[0], source, parts);
        if args.markdown {
            format!("{feed}\n\n{}", compare_table::markdown(&rows))
        } else {
            format!("{feed}\n{}", compare_table::text(&rows))
        }
    };
    super::stdout::print_result(&text)
}
