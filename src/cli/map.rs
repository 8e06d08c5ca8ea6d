//! `pinfeed map`: configuration maps θ0 → θf for a list of contact parameters d (docs/physics.md#configuration-maps, thesis
//! chapter 3), their bands, and the figures and report files under `pinfeed-out/maps/<part>/`.
//!
//! Each map samples θ0 over [0°, 360°) with the start convention of `pinfeed contact`
//! ([`pinfeed::maps::pass_start`]). With `--fence ANGLE[:LENGTH]` the one map is of a fence instead
//! (docs/physics.md#fences), placed as `pinfeed contact --fence` places it ([`pinfeed::contact_case::case_fence`]);
//! a fence map has no contact parameter, so `--d` is not taken, and its report goes to
//! `pinfeed-out/maps/<part>/fence_<angle>[_<length>]/` by default. Standard output gets a band table (default), the JSON document
//! (`--json`) or the samples as CSV (`--csv`); unless `--no-write`, the report directory receives
//! `README.md` (headed by the command that regenerates it), `map.json`, `samples.csv` and the SVG
//! figures (or the figures go to `--plot-dir`). The time spent computing goes to standard error.

use anyhow::{bail, Context, Result};
use clap::Args;
use pinfeed::contact_case::{
    case_fence, check_geometry, check_inputs, compile_part, parse_fence, settings_and_pin, Case,
};
use pinfeed::maps::{compute_maps_with, MapFence, MapSettings};
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
/// `custom`), and below it `fence_<angle>[_<length>]` for a fence map.
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
            dir.join(format!("fence_{name}"))
        }
    }
}

/// The default report directory of a part: `pinfeed-out/maps/<part>` (a vertex list is `custom`).
pub fn default_out_dir(part: &str) -> PathBuf {
    pinfeed::default_out(&["maps", &super::part_folder(part)])
}

/// Run `pinfeed map`; `recorded` is the command line its report records.
pub fn run(args: &MapArgs, recorded: &str) -> Result<()> {
    // The map tier answers over the exact model, which computes what it cannot vouch for.
    let use_tier = args.push.map_tier();
    if use_tier && (args.fence.is_some() || args.uncertain.is_some()) {
        bail!("--model map: the map tier tabulates still pins with one support; use --model exact with --fence or --uncertain");
    }
    let model = match args.push.model {
        pinfeed::contact_case::ModelChoice::Model(f) => f,
        pinfeed::contact_case::ModelChoice::Map => pinfeed::mechanics::Fidelity::Exact,
    };
    let fence = (args.fence.as_deref())
        .map(|f| parse_fence(f, "--fence"))
        .transpose()?;
    let template = Case {
        fence,
        ..args.push.case(args.part.clone(), model)
    };
    check_inputs(&template, &super::flag)?;
    let fenced = args.fence.is_some();
    let (step, threshold) = (args.theta_step, args.threshold);
    pinfeed::maps::limits::check(args.threads, args.d.len(), fenced, step, threshold)
        .map_err(|e| anyhow::anyhow!(e.describe(|s| super::flag(s.field()))))?;
    let (poly, part_model) = compile_part(&args.part, &args.push.support)?;
    if fence.is_some() {
        check_geometry(&template, &poly, &super::flag)?;
    } else {
        for &d in &args.d {
            check_geometry(
                &Case {
                    d,
                    ..template.clone()
                },
                &poly,
                &super::flag,
            )?;
        }
    }
    if let Some(uncertain) = &args.uncertain {
        return super::map_ensemble::run(args, recorded, uncertain, model, &poly);
    }
    let (contact, pin) = settings_and_pin(&template);
    // Every pass of the maps shares the model: its exact slides come from tables.
    let part_model = part_model.with_slide_tables(&[contact.mu_c]);
    let settings = MapSettings {
        theta_step_deg: args.theta_step,
        threshold_deg: args.threshold,
        contact,
        pin,
        fence: fence.map(|(angle_deg, length)| MapFence { angle_deg, length }),
    };
    // A fence map has one map and no contact parameter (the fence's placement ignores d).
    let ds: Vec<f64> = if fence.is_some() {
        vec![0.0]
    } else {
        args.d.clone()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .context("starting the worker threads")?;
    let tier = if use_tier {
        // Only the base cells the maps' passes fall in are built.
        let grid = pinfeed::maps::theta_grid(args.theta_step).unwrap_or_default();
        let passes: Vec<_> = ds
            .iter()
            .flat_map(|&d| grid.iter().map(move |&t| (t, d)))
            .map(|(t, d)| pinfeed::maps::pass_start(&poly, t, d, pin.radius))
            .collect();
        let support = pinfeed::mechanics::Support::parse(&args.push.support, &poly)
            .map_err(anyhow::Error::msg)?;
        let loaded = pool.install(|| {
            super::contact_map::load_tier(
                (&part_model, &support, args.push.pin_radius, contact),
                args.push.map_grid.as_deref(),
                args.push.cache_dir.as_deref(),
                Some(&passes),
                args.json || args.csv || args.quiet,
            )
        })?;
        Some(loaded)
    } else {
        None
    };
    let started = std::time::Instant::now();
    let maps = pool.install(|| {
        compute_maps_with(
            &poly,
            &part_model,
            &ds,
            &settings,
            tier.as_ref().map(|l| &*l.map),
        )
    })?;
    let elapsed = started.elapsed().as_secs_f64();
    if let Some(l) = &tier {
        eprintln!(
            "{}",
            pinfeed::maps::tier::report::served_line(&l.map, &poly, &part_model, &ds, &settings)
        );
    }
    let contacts: usize = maps.iter().map(|m| m.samples.len()).sum();
    eprintln!(
        "computed {} maps × {} θ0 = {contacts} contacts ({}) in {elapsed:.3} s on {} threads",
        maps.len(),
        maps.first().map_or(0, |m| m.samples.len()),
        if use_tier { "map" } else { model.name() },
        pool.current_num_threads()
    );
    let non_ok: usize = maps.iter().map(|m| m.non_ok_samples()).sum();
    if non_ok > 0 {
        eprintln!("warning: {non_ok} contacts ended with a status other than ok (see the samples' status)");
    }

    let report = MapReport {
        command: recorded.to_string(),
        part: &args.part,
        model: if use_tier { "map" } else { model.name() },
        mu_c: args.push.mu_c,
        pin_radius: args.push.pin_radius,
        support: &args.push.support,
        theta_step_deg: args.theta_step,
        threshold_deg: args.threshold,
        tol: args.push.tol,
        fence: fence.map(|(angle, length)| case_fence(&poly, &template, angle, length)),
        maps: &maps,
    };
    if args.json {
        print!("{}", pinfeed::report::versioned::pretty(&report)?);
    } else if args.csv {
        write_csv(std::io::stdout().lock(), &maps)?;
    } else {
        print!("{}", report.text());
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn default_report_directory_is_per_part() {
        assert_eq!(
            default_out_dir("tripoly1"),
            Path::new("pinfeed-out/maps/tripoly1")
        );
        assert_eq!(
            default_out_dir("rect:2:1"),
            Path::new("pinfeed-out/maps/rect_2_1")
        );
        assert_eq!(
            default_out_dir("vertices:0,0 1,0 0,1"),
            Path::new("pinfeed-out/maps/custom")
        );
    }
}
