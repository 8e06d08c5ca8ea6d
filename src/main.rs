fn main() {
    // Set but empty means unset, as the map cache's default folder reads it (clap would refuse
    // `--cache-dir` "a value is required" for an option the user never gave).
    if std::env::var_os("PINFEED_CACHE").is_some_and(|v| v.is_empty()) {
        std::env::remove_var("PINFEED_CACHE");
    }
    let cli = pinfeed::cli::Cli::parse();
    if let Err(e) = pinfeed::cli::run(cli) {
        if let Some(pinfeed::cli::Exit(code)) = e.downcast_ref::<pinfeed::cli::Exit>() {
            std::process::exit(*code);
        }
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
