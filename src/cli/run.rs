//! `pinfeed run SCENARIO.toml`: simulate a feeder line (docs/physics.md#the-line) and report throughput and
//! orientation success. Writes `summary.json` (and, as the scenario's `[output]` asks, the
//! per-part CSV, the orientation histogram SVG and the event log) under
//! `<out>/<scenario name>/`; prints a table, or the summary as JSON with `--json`. `--draw` and
//! `--animate` picture sample parts on the line ([`pinfeed::report::plot_line`],
//! [`pinfeed::report::animate`]).

use anyhow::{bail, Context, Result};
use clap::Args;
use pinfeed::engine::sequential::Precision;
use pinfeed::engine::{self, trace, RunOptions};
use pinfeed::report::line_table;
use pinfeed::report::run_folder::{write_run, RunFiles};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `pinfeed run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Scenario file (TOML; see docs/scenario-format.md), or the name of a bundled scenario.
    pub scenario: PathBuf,
    /// Number of parts (overrides [feed] parts).
    #[arg(long)]
    pub parts: Option<u64>,
    /// Random seed (overrides the scenario's seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Print the summary as JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Folder under which <scenario name>/ is written (default: the scenario's [output] dir, else
    /// pinfeed-out/runs).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// No table and no progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Draw the line from above, to scale, with a few sample parts, into this SVG file.
    #[arg(long, value_name = "FILE.svg")]
    pub draw: Option<PathBuf>,
    /// Write the line as a fabrication drawing into this DXF file (millimetres; belt, pins,
    /// sensors, moving pins, fences and names on named layers; docs/outputs.md).
    #[arg(long, value_name = "FILE.dxf")]
    pub dxf: Option<PathBuf>,
    /// Animate the line into this SVG file (plays in a browser, looping): the first sample parts
    /// travelling the belt to scale, the obstacles, sensor readings and decisions as they happen,
    /// and each part's outcome colour when it ends.
    #[arg(long, value_name = "FILE.svg")]
    pub animate: Option<PathBuf>,
    /// Simulated seconds per second of animation (default: the loop lasts 20–40 s).
    #[arg(long, value_name = "X", requires = "animate")]
    pub animate_speed: Option<f64>,
    /// Folder of the map tier's cache files (`[model] fidelity = "map"`; default
    /// $XDG_CACHE_HOME/pinfeed/maps or ~/.cache/pinfeed/maps).
    #[arg(long, value_name = "DIR", env = "PINFEED_CACHE")]
    pub cache_dir: Option<PathBuf>,
    /// Feed parts until the 95% confidence sequence of the success rate (on a closed loop, the
    /// purity) is at most ±E wide, checked after every finished part; [feed] parts (or --parts)
    /// is the cap. E in (0, 0.5). The summary gets a `sequential` block (docs/output-analysis.md).
    #[arg(long, value_name = "E", value_parser = super::mc::parse_precision)]
    pub precision: Option<f64>,
    /// Write every event of the run (arrivals, contacts, readings, decisions, the gate's rejects,
    /// returns, exits and losses) to this file as JSON lines (docs/outputs.md#event-trace).
    #[arg(long, value_name = "FILE.jsonl")]
    pub trace: Option<PathBuf>,
}

pub fn run(args: &RunArgs) -> Result<()> {
    let scene = pinfeed::study::bundled::load_scenario(&args.scenario)?;
    let mut opts = RunOptions::from_scene(&scene);
    opts.online = pinfeed::engine::prepare::online_model(&scene)?;
    if let Some(n) = args.parts {
        if !(1..=1_000_000_000).contains(&n) {
            bail!("--parts must lie in [1, 1000000000], got {n}");
        }
        opts.parts = n;
    }
    if let Some(s) = args.seed {
        opts.seed = s;
    }
    if let Some(e) = args.precision {
        opts.stop = Some(Precision::new(e).map_err(anyhow::Error::msg)?);
    }
    if let Some(x) = args.animate_speed.filter(|_| args.animate.is_some()) {
        if !(x.is_finite() && x > 0.0 && x <= 1e6) {
            bail!("--animate-speed must lie in (0, 1000000], got {x}");
        }
    }
    let files = RunFiles {
        draw: args.draw.as_deref(),
        animate: args.animate.as_deref(),
        animate_speed: args.animate_speed,
    };
    files.record_into(&scene, &mut opts);
    if let Some(path) = &args.dxf {
        pinfeed::report::layout_dxf::write_layout_dxf(&scene, &[], path)?;
    }
    let bar = super::progress::bar(opts.parts, "parts", args.quiet);
    let maps = super::contact_map::prepare_maps(&scene, args.cache_dir.as_deref(), args.quiet);
    let started = Instant::now();
    let progress = &mut |done| bar.set_position(done);
    let result = match &args.trace {
        Some(path) => trace::run_to_file(&scene, &opts, progress, path).map_err(anyhow::Error::new),
        None => engine::run(&scene, &opts, progress).map_err(anyhow::Error::new),
    }
    .with_context(|| format!("running {}", args.scenario.display()))?;
    let wall = started.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let maps = maps + &super::contact_map::persist_maps(&scene);
    let summary = &result.summary;

    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(&scene.output.dir))
        .join(&scene.name);
    let json = write_run(&scene, &result, &dir, &files).map_err(|e| {
        match e.describe_setting(&super::flag) {
            Some(message) => anyhow::anyhow!(message),
            None => e.into(),
        }
    })?;
    let mut text = String::new();
    if args.json {
        text = json;
    } else if !args.quiet {
        text.push_str(&line_table::table(summary));
        if let Some(s) = &summary.sequential {
            let [lo, hi] = s.confidence_sequence;
            text.push_str(&format!(
                "sequential                {} in [{:.4}, {:.4}] (95% CS, ±{:.4} asked): stopped on {} after {} parts\n",
                s.rate, lo, hi, s.precision, s.stopped.name(), s.parts
            ));
        }
        let parts_per_s = summary.parts_in as f64 / wall.max(1e-9);
        let contacts_per_s = summary.work.contact_solves as f64 / wall.max(1e-9);
        text.push_str(&format!(
            "simulator speed           {parts_per_s:.0} parts/s, {contacts_per_s:.0} contacts/s ({wall:.2} s wall)\n"
        ));
        text.push_str(&line_table::tables_line(&scene.part.model));
        text.push_str(&maps);
        text.push_str(&format!("results                   {}\n", dir.display()));
    }
    super::stdout::print_result(&text)
}
