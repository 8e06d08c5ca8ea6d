//! `pinfeed map`: configuration maps θ0 → θf for a list of contact parameters d (docs/physics.md#configuration-maps, thesis
//! chapter 3), their bands, and the figures and report files under `pinfeed-out/maps/<part>/`.
//!
//! Each map samples θ0 over [0°, 360°) with the start convention of `pinfeed contact`
//! ([`pinfeed::maps::pass_start`]). With `--fence ANGLE[:LENGTH]` the one map is of a fence instead
//! (docs/physics.md#fences), placed as `pinfeed contact --fence` places it ([`pinfeed::contact_case::case_fence`]);
//! a fence map has no contact parameter, so `--d` is not taken, and its report goes to
//! `pinfeed-out/maps/<part>/fence_<angle>[_<length>][_tail<radius>]/` by default (`--tail R` ends the fence in a
//! curved tail of radius R). Standard output gets a band table (default), the JSON document
//! (`--json`) or the samples as CSV (`--csv`); unless `--no-write`, the report directory receives
//! `README.md` (headed by the command that regenerates it), `map.json`, `samples.csv` and the SVG
//! figures (or the figures go to `--plot-dir`). The time spent computing goes to standard error.

use anyhow::Result;
use clap::Args;
use pinfeed::contact_case::maps::{self, MapRequest, TierSource};
use pinfeed::contact_case::{parse_fence, Case, ModelChoice};
use pinfeed::report::map_report::{write_csv, write_report, MapReport};
use std::path::PathBuf;

/// Arguments of `pinfeed map`.
#[derive(Debug, Args)]
pub struct MapArgs {
    /// Part: tripoly1, tripoly2, square, rect:W:H, ngon:N, lshape, random:SEED[:N], or vertices:"x,y x,y ...".
    #[arg(long)]
    pub part: String,
    /// Contact parameters, comma-separated (e.g. -0.9,-0.5,0.3): d = (y_pin − y_com)/a: the pin's lateral offset from the part's centroid in units of a (its
    /// largest centroid–vertex distance), a ratio without a length unit.
    #[arg(
        long,
        required_unless_present = "fence",
        conflicts_with = "fence",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    pub d: Vec<f64>,
    /// Map a fence instead of a pin: angle from the belt direction in degrees (−90 < α < 90;
    /// positive fences deflect parts to the left) and optional length in part units (default 20a),
    /// placed as `pinfeed contact --fence` places it; `--mu-c` is the fence friction μf.
    #[arg(
        long,
        value_name = "ANGLE_DEG[:LENGTH]",
        allow_hyphen_values = true,
        conflicts_with = "pin_radius"
    )]
    pub fence: Option<String>,
    #[command(flatten)]
    pub tail: super::physics::TailArgs,
    /// Spacing of the initial orientations θ0 (degrees; must divide 360).
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    pub theta_step: f64,
    #[command(flatten)]
    pub push: super::physics::PushArgs,
    /// Band threshold T (degrees): neighbouring final angles at least T apart start a new band.
    #[arg(long, default_value_t = 5.0, allow_hyphen_values = true)]
    pub threshold: f64,
    /// Print the maps as one JSON document.
    #[arg(long, conflicts_with = "csv")]
    pub json: bool,
    /// Print the samples as CSV.
    #[arg(long)]
    pub csv: bool,
    /// No progress bar (as with --json or --csv, or when standard error is not a terminal).
    #[arg(long, short)]
    pub quiet: bool,
    /// Report directory (README.md, map.json, samples.csv, figures) [default: pinfeed-out/maps/<part>].
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
    /// Directory for the SVG figures [default: the report directory].
    #[arg(long, value_name = "DIR")]
    pub plot_dir: Option<PathBuf>,
    /// Print only; write no files.
    #[arg(long, conflicts_with_all = ["out_dir", "plot_dir"])]
    pub no_write: bool,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Ensemble map under uncertain physics (docs/commands.md#validating-against-measurements-pinfeed-validate-pinfeed-calibrate), e.g.
    /// `mu_c=normal:0.5:0.1,support=tripod:0.5,pin_radius=uniform:0:0.1,jitter=2`.
    #[arg(long, value_name = "KEY=VALUE,...", conflicts_with_all = ["fence", "json", "csv"])]
    pub uncertain: Option<String>,
    /// Members of the ensemble (with --uncertain).
    #[arg(long, default_value_t = 200)]
    pub members: usize,
    /// Seed of the ensemble (with --uncertain).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// The default report directory of a map command: `pinfeed-out/maps/<part>` (a vertex list is
/// `custom-HASH`, as `plan` names its designs), and below it `fence_<angle>[_<length>]` for a fence map.
pub fn default_out_dir_for(args: &MapArgs) -> PathBuf {
    let dir = default_out_dir(&args.part);
    match &args.fence {
        None => dir,
        Some(f) => {
            let name: String = f
                .trim()
                .chars()
                .map(|c| if c == ':' { '_' } else { c })
                .filter(|c| c.is_ascii_alphanumeric() || "-_.".contains(*c))
                .collect();
            match args.tail.tail {
                Some(r) => dir.join(format!("fence_{name}_tail{r}")),
                None => dir.join(format!("fence_{name}")),
            }
        }
    }
}

/// The default report directory of a part: `pinfeed-out/maps/<part>` (a vertex list is `custom-HASH`).
pub fn default_out_dir(part: &str) -> PathBuf {
    pinfeed::default_out(&["maps", &super::part_folder(part)])
}

/// The library's request for these arguments.
pub fn request(args: &MapArgs) -> Result<MapRequest> {
    let fence = (args.fence.as_deref())
        .map(|f| parse_fence(f, "--fence"))
        .transpose()?;
    Ok(MapRequest {
        case: Case {
            fence,
            fence_tail: args.tail.tail,
            ..args
                .push
                .case(args.part.clone(), args.push.model.computed_with())
        },
        model: args.push.model,
        ds: args.d.clone(),
        theta_step_deg: args.theta_step,
        threshold_deg: args.threshold,
        threads: args.threads,
        tier: TierSource {
            grid: args.push.map_grid.clone(),
            cache_dir: args.push.cache_dir.clone(),
        },
    })
}

/// Run `pinfeed map`; `recorded` is the command line its report records.
pub fn run(args: &MapArgs, recorded: &str) -> Result<()> {
    let req = request(args)?;
    if let Some(uncertain) = &args.uncertain {
        return super::map_ensemble::run(args, recorded, uncertain, &req);
    }
    // A bar only while the map tier's cells are built (exact maps have none).
    let quiet = args.json || args.csv || args.quiet || req.model != ModelChoice::Map;
    let bar = super::progress::bar(0, "base cells of the map built", quiet);
    bar.set_message("map tier ");
    let run = maps::run(
        &req,
        &super::flag,
        &super::progress::watch(&bar, args.quiet),
    );
    bar.finish_and_clear();
    let run = run?;
    if let Some(l) = &run.tier {
        for w in &l.warnings {
            eprintln!("warning: {w}");
        }
        if !args.quiet {
            eprintln!("map tier: {}", l.describe());
        }
    }
    if let Some(line) = &run.served {
        eprintln!("{line}");
    }
    eprintln!(
        "computed {} maps × {} θ0 = {} contacts ({}) in {:.3} s on {} threads",
        run.maps.len(),
        run.maps.first().map_or(0, |m| m.samples.len()),
        run.contacts(),
        run.answered_by(),
        run.elapsed_s,
        run.threads
    );
    let non_ok = run.non_ok();
    if non_ok > 0 {
        eprintln!("warning: {non_ok} contacts ended with a status other than ok (see the samples' status)");
    }
    let report = MapReport {
        command: recorded.to_string(),
        part: &args.part,
        model: run.answered_by(),
        mu_c: args.push.mu_c,
        pin_radius: args.push.pin_radius,
        support: &args.push.support,
        theta_step_deg: args.theta_step,
        threshold_deg: args.threshold,
        tol: args.push.tol,
        fence: run.fence,
        maps: &run.maps,
    };
    if args.json {
        crate::out!("{}", pinfeed::report::versioned::pretty(&report)?);
    } else if args.csv {
        write_csv(super::stdout::writer(), &run.maps)?;
    } else {
        crate::out!("{}", report.text());
    }
    if !args.no_write {
        let out_dir = args
            .out_dir
            .clone()
            .unwrap_or_else(|| default_out_dir_for(args));
        write_report(&report, &out_dir, args.plot_dir.as_deref())?;
        eprintln!("report written to {}", out_dir.display());
    }
    Ok(())
}
