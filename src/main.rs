use clap::Parser;

fn main() {
    let cli = pinfeed::cli::Cli::parse();
    if let Err(e) = pinfeed::cli::run(cli) {
        if let Some(pinfeed::cli::Exit(code)) = e.downcast_ref::<pinfeed::cli::Exit>() {
            std::process::exit(*code);
        }
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
