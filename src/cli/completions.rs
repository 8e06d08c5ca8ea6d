//! `pinfeed completions SHELL`: the shell completion script for `pinfeed`, on stdout.

use clap::CommandFactory;

#[derive(Debug, clap::Args)]
pub struct CompletionsArgs {
    /// The shell: bash, zsh, fish, elvish or powershell
    pub shell: clap_complete::Shell,
}

pub fn run(args: &CompletionsArgs) -> anyhow::Result<()> {
    let mut cmd = super::Cli::command();
    clap_complete::generate(
        args.shell,
        &mut cmd,
        "pinfeed",
        &mut super::stdout::writer(),
    );
    Ok(())
}
