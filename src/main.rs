//! The `pinfeed` command: [`cli`] maps its arguments to the library's workflows and prints their
//! results. The library `pinfeed` (crates/pinfeed) holds the physics, the line, the planner and
//! the studies.

use pinfeed_cli as cli;

fn main() {
    // Set but empty means unset, as the map cache's default folder reads it (clap would refuse
    // `--cache-dir` "a value is required" for an option the user never gave).
    if std::env::var_os("PINFEED_CACHE").is_some_and(|v| v.is_empty()) {
        std::env::remove_var("PINFEED_CACHE");
    }
    let cli = cli::Cli::parse();
    if let Err(e) = cli::run(cli) {
        if let Some(cli::Exit(code)) = e.downcast_ref::<cli::Exit>() {
            std::process::exit(*code);
        }
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
