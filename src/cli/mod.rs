//! The `pinfeed` command's interface (the library `pinfeed_cli` of this workspace's top package):
//! argument definitions and one module per sub-command, each mapping its arguments to the
//! library `pinfeed`'s workflows and printing their results. `src/main.rs` only parses and
//! dispatches; the command is a library so that tests/all can drive it in-process
//! (tests/all/cli_in_process.rs) without compiling it a second time. It offers no API beyond that.
//!
//! The doc comments of the argument structs are the commands' `--help` text (clap prints them as
//! written), so they are plain text rather than rustdoc Markdown: `[feed]`, `<part>` and
//! `random:SEED[:N]` are what the user types, not links or HTML.
#![allow(rustdoc::broken_intra_doc_links, rustdoc::invalid_html_tags)]
// Every print goes through `stdout` (a closed pipe ends the output quietly, never a panic).
#![deny(clippy::print_stdout)]

pub mod bench;
pub mod bench_designs;
pub mod bench_line;
pub mod bench_map_tier;
pub mod bench_mc;
pub mod calibrate;
pub mod compare;
pub mod completions;
pub mod contact;
pub mod contact_map;
pub mod examples;
pub mod fuzz;
pub mod map;
pub mod map_ensemble;
pub mod mc;
pub mod merge;
pub mod part;
pub mod physics;
pub mod plan;
pub mod progress;
pub mod record;
pub mod run;
pub mod sense;
pub mod stdout;
pub mod validate;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

pub use pinfeed::geometry::named::part_folder;

/// pinfeed: orient planar parts on a conveyor with overhead pins and fences.
#[derive(Debug, Parser)]
#[command(name = "pinfeed", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// The command line as outputs record it ([`record::command_line`]); filled by
    /// [`Cli::parse`] and [`Cli::try_parse_from`], which shadow clap's own.
    #[arg(skip)]
    pub recorded: String,
}

impl Cli {
    /// Parse an argument vector (the program name first) and record its command line.
    pub fn try_parse_from<I, T>(argv: I) -> Result<Cli, clap::Error>
    where
        I: IntoIterator<Item = T>,
        T: Into<std::ffi::OsString> + Clone,
    {
        let cmd = <Cli as CommandFactory>::command();
        let matches = cmd.clone().try_get_matches_from(argv)?;
        let mut cli = <Cli as FromArgMatches>::from_arg_matches(&matches)?;
        cli.recorded = record::command_line(&cmd, &matches);
        Ok(cli)
    }

    /// Parse the process's arguments (exiting with clap's message on an error).
    pub fn parse() -> Cli {
        Cli::try_parse_from(std::env::args_os()).unwrap_or_else(|e| e.exit())
    }
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Describe a part: area, centroid, a, convexity, stable states; optionally plot it.
    Part(part::PartArgs),
    /// One pin pass over one part (or a batch from CSV): final pose, rotation, contact segments.
    Contact(contact::ContactArgs),
    /// Configuration maps θ0 → θf for several d: bands, no-contact runs, figures, report files.
    Map(map::MapArgs),
    /// Simulate a feeder line from a scenario file: throughput and orientation success
    /// (`--draw FILE.svg` a still picture, `--animate FILE.svg` an animation of sample parts).
    Run(run::RunArgs),
    /// Run several line designs on the same part stream and print one table.
    Compare(compare::CompareArgs),
    /// Monte Carlo robustness study: success rate and outcome mix per sweep point, with 95% intervals.
    Mc(mc::McArgs),
    /// Merge the shard files of a Monte Carlo study into its report (the same bytes as one run).
    Merge(merge::MergeArgs),
    /// What a sensorised pin can tell: classifiers' confusion, accuracy and information under noise.
    Sense(Box<sense::SenseArgs>),
    /// Design a line for a part (pins, fences, both, or a sensor with moving pins), checked on the
    /// line: the best design the line confirms, written as a scenario and drawn.
    Plan(Box<plan::PlanArgs>),
    /// Measurements behind the reports in results/ (each report names its command; default output pinfeed-out/).
    Bench(bench::BenchArgs),
    /// Fuzz the inputs (scenario and study files, contacts, polygons) and write a robustness report.
    Fuzz(fuzz::FuzzArgs),
    /// Measured bands (CSV) against an ensemble's predicted bands: containment, overlap, log score.
    Validate(validate::ValidateArgs),
    /// Fit μc centre and spread, tripod share and pin radius to measured bands, with intervals.
    Calibrate(calibrate::CalibrateArgs),
    /// List the bundled scenarios and studies, or write them into a folder.
    Examples(examples::ExamplesArgs),
    /// Print the shell completion script (bash, zsh, fish, elvish, powershell).
    Completions(completions::CompletionsArgs),
}

/// The flag that sets a library setting named by its field (`mu_c` → `--mu-c`): how the
/// command line renders the library's errors, which name settings by field.
pub fn flag(field: &str) -> String {
    format!("--{}", field.replace('_', "-"))
}

/// Run a parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    let Cli { command, recorded } = cli;
    let recorded = recorded.as_str();
    let result = command_run(command, recorded);
    // Map-tier cells a command's lines built are kept for the next command (a file that cannot
    // be written costs only the rebuild).
    for w in pinfeed::maps::tier::lazy::persist_all() {
        eprintln!("warning: {w}");
    }
    result
}

fn command_run(command: Command, recorded: &str) -> anyhow::Result<()> {
    match command {
        Command::Part(a) => part::run(&a),
        Command::Contact(a) => contact::run(&a),
        Command::Map(a) => map::run(&a, recorded),
        Command::Run(a) => run::run(&a),
        Command::Compare(a) => compare::run(&a),
        Command::Mc(a) => mc::run(&a),
        Command::Merge(a) => merge::run(&a),
        Command::Sense(a) => sense::run(&a, recorded),
        Command::Plan(a) => plan::run(&a, recorded),
        Command::Bench(a) => bench::run(&a, recorded),
        Command::Fuzz(a) => fuzz::run(&a, recorded),
        Command::Validate(a) => validate::run(&a, recorded),
        Command::Calibrate(a) => calibrate::run(&a, recorded),
        Command::Examples(a) => examples::run(&a),
        Command::Completions(a) => completions::run(&a),
    }
}

/// A command that ends with a non-zero status it has already explained on standard output (e.g.
/// `pinfeed plan`: 3 a design the line does not confirm, 4 no design).
#[derive(Debug)]
pub struct Exit(pub i32);

impl std::fmt::Display for Exit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "exit status {}", self.0)
    }
}

impl std::error::Error for Exit {}

/// Print the warning for a `--pin-radius` (part units) thinner than a real pin at `scale`
/// ([`pinfeed::scenario::limits::thin_pin_warning`]).
pub(crate) fn warn_thin_pin(radius_units: f64, scale: f64) {
    if let Some(w) = pinfeed::scenario::limits::thin_pin_warning(radius_units, scale) {
        eprintln!("warning: --pin-radius {radius_units}: {w}");
    }
}
