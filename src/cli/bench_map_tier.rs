//! `pinfeed bench map-tier`: writes the map-tier sections of results/accuracy-vs-time.md and
//! results/line-speed.md ([`pinfeed::study::map_tier`]).

use anyhow::{bail, Result};
use clap::Args;
use pinfeed::study::map_tier::{
    contact_row, contact_section, line_row, line_section, marked, splice,
};
use std::path::{Path, PathBuf};

#[derive(Debug, Args)]
pub struct MapTierArgs {
    /// Parts, comma-separated (each gets a freshly built map).
    #[arg(long, value_delimiter = ',', default_value = "tripoly1,tripoly2")]
    pub parts: Vec<String>,
    /// Random pushes per part.
    #[arg(long, default_value_t = 2000)]
    pub contacts: usize,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The line scenario run exact and on the map tier.
    #[arg(long, default_value = "scenarios/quickstart.toml")]
    pub scenario: PathBuf,
    /// Parts of the line runs.
    #[arg(long, default_value_t = 10_000)]
    pub line_parts: u64,
    #[arg(long, default_value = "pinfeed-out/accuracy-vs-time.md")]
    pub accuracy_out: PathBuf,
    #[arg(long, default_value = "pinfeed-out/line-speed.md")]
    pub line_out: PathBuf,
}

fn write_section(path: &Path, section: &str) -> Result<()> {
    pinfeed::output::rewrite_file(path, |old| splice(old, &marked(section)))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

pub fn run(a: &MapTierArgs, spin: &indicatif::ProgressBar, cmd: &str) -> Result<()> {
    if a.contacts == 0 || a.contacts > 1_000_000 {
        bail!(
            "--contacts must be between 1 and 1000000, got {}",
            a.contacts
        );
    }
    if a.line_parts == 0 || a.line_parts > 10_000_000 {
        bail!(
            "--line-parts must be between 1 and 10000000, got {}",
            a.line_parts
        );
    }
    let mut rows = Vec::new();
    for part in &a.parts {
        let stage = format!("map tier: building and measuring {part}");
        super::progress::note(spin, &stage);
        spin.set_message(stage);
        rows.push(contact_row(part, a.contacts, a.seed)?);
    }
    let section = contact_section(&rows, cmd);
    crate::out!("{section}");
    write_section(&a.accuracy_out, &section)?;
    let stage = format!("map tier: line runs of {}", a.scenario.display());
    super::progress::note(spin, &stage);
    spin.set_message(stage);
    let line = line_row(&a.scenario, a.line_parts)?;
    let section = line_section(&line, &a.scenario, cmd);
    crate::out!("{section}");
    write_section(&a.line_out, &section)
}
