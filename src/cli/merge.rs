//! `pinfeed merge SHARD.json...`: check that shard files of one Monte Carlo study fit together
//! (same study, seed and pinfeed version; sample ranges covering every sample exactly once) and
//! write the report an unsharded `pinfeed mc` run writes, byte for byte.

use super::mc::{default_dir, publish};
use anyhow::Result;
use clap::Args;
use pinfeed::study::mc::{report, shard};
use std::path::PathBuf;

/// Arguments of `pinfeed merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// Shard files written by `pinfeed mc --shard K/N`.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Print the report as JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Folder for the report (default: pinfeed-out/mc/<study name>/).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// No table.
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(args: &MergeArgs) -> Result<()> {
    let mut files = Vec::new();
    for p in &args.files {
        files.push((p.clone(), shard::read(p)?));
    }
    let (header, tallies) = shard::merge(&files)?;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| default_dir(&header.study));
    let r = report::build(
        &pinfeed::study::mc::report::with_out(header, &dir),
        &tallies,
    );
    publish(&r, &dir, args.json, args.quiet)
}
