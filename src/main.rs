use clap::Parser;

fn main() {
    let cli = pinfeed::cli::Cli::parse();
    if let Err(e) = pinfeed::cli::run(cli) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
