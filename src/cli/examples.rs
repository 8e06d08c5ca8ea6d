//! `pinfeed examples [NAME…] [--all] [--to DIR] [--force]`: list the bundled scenarios and studies,
//! or write them into a folder ([`pinfeed::study::bundled`]).

use pinfeed::study::bundled::{self, Kind};
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct ExamplesArgs {
    /// Bundled scenarios or studies to write (their names, as listed); none: list them all
    pub names: Vec<String>,
    /// Write every bundled scenario and study
    #[arg(long)]
    pub all: bool,
    /// Folder to write into (each file at scenarios/NAME.toml or studies/NAME.toml, with the
    /// scenario a study names)
    #[arg(long, value_name = "DIR")]
    pub to: Option<PathBuf>,
    /// Overwrite files that exist (by default nothing is written if any target exists)
    #[arg(long)]
    pub force: bool,
}

pub fn run(args: &ExamplesArgs) -> anyhow::Result<()> {
    let names: Vec<String> = if args.all {
        bundled::all().iter().map(|b| b.path.to_string()).collect()
    } else {
        args.names.clone()
    };
    if names.is_empty() {
        anyhow::ensure!(
            args.to.is_none(),
            "--to needs the names of the examples to write, or --all"
        );
        for (kind, title, verb) in [
            (Kind::Scenario, "scenarios", "pinfeed run NAME"),
            (Kind::Study, "studies", "pinfeed mc NAME"),
        ] {
            crate::outln!("{title} ({verb}):");
            for b in bundled::all().iter().filter(|b| b.kind() == kind) {
                crate::outln!("  {:<28} {}", b.name(), b.description());
            }
        }
        crate::outln!("write them with: pinfeed examples NAME... --to DIR  (or --all --to DIR)");
        return Ok(());
    }
    let dir = args
        .to
        .as_ref()
        .ok_or_else(|| anyhow::anyhow!("--to DIR: the folder to write the examples into"))?;
    let files = bundled::select(&names)?;
    for path in bundled::write(&files, dir, args.force)? {
        crate::outln!("wrote {}", path.display());
    }
    Ok(())
}
