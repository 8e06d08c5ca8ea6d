//! `pinfeed map`: configuration maps θ0 → θf for a list of contact parameters d (docs/physics.md#configuration-maps, thesis
//! chapter 3), their bands, and the figures and report files under `pinfeed-out/maps/<part>/`.
//!
//! Each map samples θ0 over [0°, 360°) with the start convention of `pinfeed contact`
//! ([`crate::maps::pass_start`]). With `--fence ANGLE[:LENGTH]` the one map is of a fence instead
//! (docs/physics.md#fences), placed as `pinfeed contact --fence` places it ([`crate::contact_case::case_fence`]);
//! a fence map has no contact parameter, so `--d` is not taken, and its report goes to
//! `pinfeed-out/maps/<part>/fence_<angle>[_<length>]/` by default. Standard output gets a band table (default), the JSON document
//! (`--json`) or the samples as CSV (`--csv`); unless `--no-write`, the report directory receives
//! `README.md` (headed by the command that regenerates it), `map.json`, `samples.csv` and the SVG
//! figures (or the figures go to `--plot-dir`). The time spent computing goes to standard error.

use crate::contact_case::{
    case_fence, check_geometry, check_inputs, compile_part, num, parse_fence, parse_model,
    settings_and_pin, Case,
};
use crate::maps::{compute_maps_with, ConfigurationMap, MapFence, MapSettings};
use crate::report::shell_word;
use crate::report::{map_table, plot_map};
use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use serde::Serialize;
use std::path::{Path, PathBuf};

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
    #[arg(long, value_name = "ANGLE_DEG[:LENGTH]", allow_hyphen_values = true)]
    pub fence: Option<String>,
    /// Spacing of the initial orientations θ0 (degrees; must divide 360).
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    pub theta_step: f64,
    /// Fidelity: exact, ellipsoid or tip; or map (the certified map tier over exact, pins only).
    #[arg(long, default_value = "exact")]
    pub model: String,
    /// With --model map: the folder of the map cache files (default $XDG_CACHE_HOME/pinfeed/maps
    /// or ~/.cache/pinfeed/maps).
    #[arg(long, value_name = "DIR", env = "PINFEED_CACHE")]
    pub cache_dir: Option<PathBuf>,
    /// With --model map: the map's grid, θ0 base cells, d base cells, refinement depth
    /// (default 36,12,4).
    #[arg(long, value_name = "T,D,DEPTH")]
    pub map_grid: Option<String>,
    /// Pin–part friction coefficient μc (≥ 0).
    #[arg(long, default_value_t = 0.5, allow_hyphen_values = true)]
    pub mu_c: f64,
    /// Pin radius in part units: the coordinates the part is given in,
    /// not metres (`plan` and `sense`, which take `--scale`, use metres); 0: point pin.
    #[arg(
        long,
        default_value_t = 0.0,
        allow_hyphen_values = true,
        conflicts_with = "fence"
    )]
    pub pin_radius: f64,
    /// Support: uniform or tripod:SEED.
    #[arg(long, default_value = "uniform")]
    pub support: String,
    /// Band threshold T (degrees): neighbouring final angles at least T apart start a new band.
    #[arg(long, default_value_t = 5.0, allow_hyphen_values = true)]
    pub threshold: f64,
    /// Integration tolerance (absolute, radians / units of a, per step).
    #[arg(long, default_value_t = 1e-6, allow_hyphen_values = true)]
    pub tol: f64,
    /// Print the maps as one JSON document.
    #[arg(long, conflicts_with = "csv")]
    pub json: bool,
    /// Print the samples as CSV.
    #[arg(long)]
    pub csv: bool,
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

/// The JSON document of `pinfeed map --json` (and `map.json`).
#[derive(Debug, Serialize)]
pub struct MapReport<'a> {
    /// The command that regenerates this report.
    pub command: String,
    pub part: &'a str,
    pub model: &'a str,
    pub mu_c: f64,
    pub pin_radius: f64,
    pub support: &'a str,
    pub theta_step_deg: f64,
    pub threshold_deg: f64,
    pub tol: f64,
    /// The fence of a fence map, placed as `pinfeed contact --fence` places it (part units at θ0 = 0,
    /// the part's centroid at the origin).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fence: Option<crate::mechanics::FenceSpec>,
    pub maps: &'a [ConfigurationMap],
}

/// One CSV row: a sample of one map.
#[derive(Debug, Serialize)]
struct SampleRow {
    d: f64,
    theta0_deg: f64,
    theta_final_deg: f64,
    rotation_deg: f64,
    contact: bool,
    com_final_y: f64,
    contact_length: f64,
    band: Option<usize>,
    status: &'static str,
}

/// The command line that regenerates a report, every setting explicit.
pub fn command_line(args: &MapArgs) -> String {
    let ds: Vec<String> = args.d.iter().map(|d| d.to_string()).collect();
    let mut words = vec![
        "pinfeed".to_string(),
        "map".into(),
        "--part".into(),
        shell_word(&args.part),
    ];
    match &args.fence {
        Some(f) => words.extend(["--fence".to_string(), shell_word(f)]),
        None => words.push(format!("--d={}", ds.join(","))),
    }
    words.extend([
        "--theta-step".into(),
        args.theta_step.to_string(),
        "--model".into(),
        shell_word(&args.model),
        "--mu-c".into(),
        args.mu_c.to_string(),
    ]);
    if args.fence.is_none() {
        words.extend(["--pin-radius".into(), args.pin_radius.to_string()]);
    }
    words.extend([
        "--support".into(),
        shell_word(&args.support),
        "--threshold".into(),
        args.threshold.to_string(),
        "--tol".into(),
        args.tol.to_string(),
    ]);
    for (flag, dir) in [("--out-dir", &args.out_dir), ("--plot-dir", &args.plot_dir)] {
        if let Some(dir) = dir {
            words.push(flag.into());
            words.push(shell_word(&dir.display().to_string()));
        }
    }
    words.join(" ")
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
    crate::default_out(&["maps", &super::part_folder(part)])
}

/// The angle of a fence map as the user gave it (degrees; 0 for pin maps).
fn fence_angle_deg(maps: &[ConfigurationMap]) -> f64 {
    maps.first()
        .and_then(|m| m.fence)
        .map_or(0.0, |f| f.angle_deg)
}

fn figure_name(m: &ConfigurationMap) -> String {
    match m.fence {
        None => format!("map_d{:+}.svg", m.d),
        Some(_) => "map_fence.svg".into(),
    }
}

/// Most contact parameters in one map command.
pub const MAX_DS: usize = 1000;
/// Most contacts (maps × θ0 samples) in one map command: bounds the memory (about 100 bytes each)
/// and the time.
pub const MAX_CONTACTS: usize = 3_600_000;
/// Most worker threads.
pub const MAX_THREADS: usize = 1024;

/// Refuse out-of-range map settings with the flag, the range and the value.
fn check_map_args(args: &MapArgs) -> Result<()> {
    if args.threads > MAX_THREADS {
        bail!(
            "--threads must lie in [0, {MAX_THREADS}] (0: one per core), got {}",
            args.threads
        );
    }
    if args.d.len() > MAX_DS {
        bail!(
            "--d takes at most {MAX_DS} contact parameters, got {}",
            args.d.len()
        );
    }
    if !(args.theta_step.is_finite() && args.theta_step > 0.0 && args.theta_step <= 360.0) {
        bail!(
            "--theta-step: theta step must be a finite number of degrees in (0, 360] dividing 360, got {}",
            num(args.theta_step)
        );
    }
    let grid =
        crate::maps::theta_grid(args.theta_step).map_err(|e| anyhow!("--theta-step: {e}"))?;
    let maps = if args.fence.is_some() {
        1
    } else {
        args.d.len()
    };
    if maps * grid.len() > MAX_CONTACTS {
        bail!(
            "{maps} maps × {} θ0 samples = {} contacts; at most {MAX_CONTACTS} are allowed in one command (raise --theta-step or give fewer --d)",
            grid.len(),
            maps * grid.len()
        );
    }
    if !(args.threshold.is_finite() && args.threshold > 0.0 && args.threshold <= 360.0) {
        bail!(
            "--threshold must be a finite number of degrees in (0, 360], got {}",
            num(args.threshold)
        );
    }
    Ok(())
}

pub fn run(args: &MapArgs) -> Result<()> {
    // The map tier answers over the exact model, which computes what it cannot vouch for.
    let use_tier = args.model.trim() == "map";
    if use_tier && (args.fence.is_some() || args.uncertain.is_some()) {
        bail!("--model map: the map tier tabulates still pins with one support; use --model exact with --fence or --uncertain");
    }
    let model = parse_model(if use_tier { "exact" } else { &args.model })?;
    let fence = args.fence.as_deref().map(parse_fence).transpose()?;
    let template = Case {
        part: args.part.clone(),
        theta0_deg: 0.0,
        d: 0.0,
        mu_c: args.mu_c,
        mu_s: crate::mechanics::ContactSettings::default().mu_s,
        model,
        pin_radius: args.pin_radius,
        pin_speed: 0.0,
        pin_stop: None,
        pin_stop_after_touch: None,
        support: args.support.clone(),
        tol: args.tol,
        fence,
    };
    check_inputs(&template)?;
    check_map_args(args)?;
    let (poly, part_model) = compile_part(&args.part, &args.support)?;
    if fence.is_some() {
        check_geometry(&template, &poly)?;
    } else {
        for &d in &args.d {
            check_geometry(
                &Case {
                    d,
                    ..template.clone()
                },
                &poly,
            )?;
        }
    }
    if let Some(uncertain) = &args.uncertain {
        return super::map_ensemble::run(args, uncertain, model, &poly);
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
        let support =
            crate::mechanics::Support::parse(&args.support, &poly).map_err(anyhow::Error::msg)?;
        let loaded = pool.install(|| {
            super::contact_map::load_tier(
                &part_model,
                &support,
                args.pin_radius,
                contact,
                args.map_grid.as_deref(),
                args.cache_dir.as_deref(),
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
            super::contact_map::served_line(&l.map, &poly, &part_model, &ds, &settings)
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
        command: command_line(args),
        part: &args.part,
        model: if use_tier { "map" } else { model.name() },
        mu_c: args.mu_c,
        pin_radius: args.pin_radius,
        support: &args.support,
        theta_step_deg: args.theta_step,
        threshold_deg: args.threshold,
        tol: args.tol,
        fence: fence.map(|(angle, length)| case_fence(&poly, &template, angle, length)),
        maps: &maps,
    };
    if args.json {
        print!("{}", crate::report::versioned::pretty(&report)?);
    } else if args.csv {
        write_csv(std::io::stdout().lock(), &maps)?;
    } else {
        let obstacle = match &report.fence {
            Some(f) => format!(
                "fence {}° length {} μf {}",
                fence_angle_deg(report.maps),
                f.length,
                f.mu_f
            ),
            None => format!("μc {}  pin radius {}", args.mu_c, args.pin_radius),
        };
        println!(
            "{}  model {}  {obstacle}  support {}  θ0 step {}°  threshold {}°",
            args.part, report.model, args.support, args.theta_step, args.threshold
        );
        print!("{}", map_table::bands_text(&maps));
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

fn write_csv<W: std::io::Write>(w: W, maps: &[ConfigurationMap]) -> Result<()> {
    let mut wtr = csv::Writer::from_writer(w);
    for m in maps {
        for s in &m.samples {
            wtr.serialize(SampleRow {
                d: m.d,
                theta0_deg: s.theta0_deg,
                theta_final_deg: s.theta_final_deg,
                rotation_deg: s.rotation_deg,
                contact: s.contact,
                com_final_y: s.com_final_y,
                contact_length: s.contact_length,
                band: s.band,
                status: s.status.name(),
            })?;
        }
    }
    wtr.flush()?;
    Ok(())
}

/// Write README.md, map.json, samples.csv and the figures.
fn write_report(report: &MapReport, out_dir: &Path, plot_dir: Option<&Path>) -> Result<()> {
    let plot_dir = plot_dir.unwrap_or(out_dir);
    for dir in [out_dir, plot_dir] {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let json_path = out_dir.join("map.json");
    // Compact: the document holds every sample (README.md is the readable summary).
    crate::report::atomic::write_atomic(&json_path, crate::report::versioned::compact(report)?)
        .with_context(|| format!("writing {}", json_path.display()))?;
    let csv_path = out_dir.join("samples.csv");
    crate::report::atomic::produce_atomic(&csv_path, |tmp| {
        write_csv(
            std::io::BufWriter::new(std::fs::File::create(tmp)?),
            report.maps,
        )
    })
    .with_context(|| format!("writing {}", csv_path.display()))?;

    let describe = match &report.fence {
        Some(f) => format!(
            "{} ({}, fence {}° length {}, μf {})",
            report.part,
            report.model,
            fence_angle_deg(report.maps),
            f.length,
            report.mu_c
        ),
        None => format!("{} ({}, μc {})", report.part, report.model, report.mu_c),
    };
    let mut figures: Vec<(String, PathBuf)> = Vec::new();
    // Band intervals against d: only pin maps have a d to plot against.
    let against_d: &[(bool, &str, &str)] = if report.fence.is_some() {
        &[]
    } else {
        &[
            (false, "band_intervals.svg", "Band intervals against d"),
            (
                true,
                "band_intervals_adjusted.svg",
                "Adjusted band intervals (mean ± sd) against d",
            ),
        ]
    };
    for &(adjusted, file, what) in against_d {
        let path = plot_dir.join(file);
        plot_map::plot_band_intervals(report.maps, adjusted, &format!("{what}: {describe}"), &path)
            .with_context(|| format!("writing {}", path.display()))?;
        figures.push((what.to_string(), path));
    }
    for m in report.maps {
        let path = plot_dir.join(figure_name(m));
        let (title, what) = match m.fence {
            Some(_) => (format!("{describe}: θ0 → θf"), "θ0 → θf".to_string()),
            None => (
                format!("{describe}, d = {:+}: θ0 → θf", m.d),
                format!("d = {:+}", m.d),
            ),
        };
        plot_map::plot_map(m, &title, report.theta_step_deg, &path)
            .with_context(|| format!("writing {}", path.display()))?;
        figures.push((what, path));
    }

    let link = |p: &Path| -> String {
        if plot_dir == out_dir {
            p.file_name()
                .map_or_else(String::new, |f| f.to_string_lossy().into_owned())
        } else {
            p.display().to_string()
        }
    };
    let samples = report.maps.first().map_or(0, |m| m.samples.len());
    let non_ok: usize = report.maps.iter().map(|m| m.non_ok_samples()).sum();
    let mut md = format!(
        "# Configuration maps: {part}\n\nRegenerate from the repository root with\n\n    cargo run --release -- {cmd}\n\n",
        part = report.part,
        cmd = report.command.trim_start_matches("pinfeed "),
    );
    let obstacle = match &report.fence {
        Some(f) => format!(
            "a fence at {}° of length {} (part units) with friction μf = {}, its upstream end at \
             ({:.4}, {:.4}) when the part's centroid is at the origin (the placement of \
             `pinfeed contact --fence`, `src/maps/start.rs`)",
            fence_angle_deg(report.maps),
            f.length,
            f.mu_f,
            f.start.x,
            f.start.y
        ),
        None => format!(
            "contact friction μc = {}, pin radius {} (part units)",
            report.mu_c, report.pin_radius
        ),
    };
    md += &format!(
        "Part `{}`, model `{}`, {obstacle}, support `{}`, \
         θ0 every {}° ({samples} samples per map), band threshold T = {}°, integration tolerance {}. \
         Conventions: docs/physics.md#configuration-maps and the module docs of `src/maps/` (bands group neighbours in sorted \
         final angle, circularly; an interval [a, b] with b < a straddles 0°/360°; sd uses n − 1; \
         adjusted band = mean ± sd, thesis eq. 3-2). Contacts that did not end `ok`: {non_ok}.\n\n",
        report.part,
        report.model,
        report.support,
        report.theta_step_deg,
        report.threshold_deg,
        report.tol
    );
    md += "Files: `map.json` (every sample, band and no-contact interval), `samples.csv` \
           (one row per sample), and the figures below.\n\n";
    md += if report.fence.is_some() {
        "## Bands\n\n"
    } else {
        "## Bands per d\n\n"
    };
    md += &map_table::bands_markdown(report.maps);
    md += "\n## Figures\n\n";
    for (what, path) in &figures {
        md += &format!("### {what}\n\n![{what}]({})\n\n", link(path));
    }
    let readme = out_dir.join("README.md");
    crate::report::atomic::write_atomic(&readme, md)
        .with_context(|| format!("writing {}", readme.display()))?;
    // The folder holds this run's figures only: a figure of an earlier run for a d not asked
    // for now goes.
    let written: Vec<String> = figures
        .iter()
        .filter_map(|(_, p)| p.file_name().map(|f| f.to_string_lossy().into_owned()))
        .collect();
    crate::report::stale::remove_stale(plot_dir, &written, is_map_figure)
        .with_context(|| format!("removing earlier figures from {}", plot_dir.display()))?;
    Ok(())
}

/// The names of the figures `pinfeed map` writes.
fn is_map_figure(name: &str) -> bool {
    name.ends_with(".svg")
        && (name.starts_with("map_d")
            || name == "map_fence.svg"
            || name.starts_with("band_intervals"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    fn parse(args: &[&str]) -> MapArgs {
        let cli =
            crate::cli::Cli::parse_from(std::iter::once("pinfeed").chain(args.iter().copied()));
        match cli.command {
            crate::cli::Command::Map(a) => a,
            other => panic!("not a map command: {other:?}"),
        }
    }

    #[test]
    fn the_recorded_command_parses_back_to_the_same_settings() {
        let a = parse(&[
            "map",
            "--part",
            "vertices:0,0 2,0 0,1",
            "--d",
            "-0.5,0.25",
            "--mu-c",
            "0.7",
            "--theta-step",
            "2",
            "--out-dir",
            "out dir",
        ]);
        let cmd = command_line(&a);
        assert!(cmd.contains("--part 'vertices:0,0 2,0 0,1'"), "{cmd}");
        assert!(cmd.contains("--out-dir 'out dir'"), "{cmd}");
        // Split the shell words back (single quotes only) and parse them again.
        let mut words: Vec<String> = Vec::new();
        let mut quoted = false;
        let mut cur = String::new();
        for c in cmd.chars() {
            match c {
                '\'' => quoted = !quoted,
                ' ' if !quoted => words.push(std::mem::take(&mut cur)),
                _ => cur.push(c),
            }
        }
        words.push(cur);
        let refs: Vec<&str> = words.iter().skip(1).map(String::as_str).collect();
        let b = parse(&refs);
        assert_eq!(
            (b.part, b.d, b.mu_c, b.theta_step),
            (a.part, a.d, a.mu_c, a.theta_step)
        );
        assert_eq!(b.out_dir, a.out_dir);
        assert_eq!(command_line(&parse(&refs)), cmd);
    }

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
