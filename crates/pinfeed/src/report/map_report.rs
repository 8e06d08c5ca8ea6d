//! The report of `pinfeed map` (configuration maps, [`crate::maps`]): the JSON document, the
//! terminal summary, the samples as CSV and the report folder (README.md, map.json, samples.csv
//! and the figures).

use crate::maps::ConfigurationMap;
use crate::report::{map_table, plot_map};
use crate::report::{ReportError, ReportResult};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The JSON document of `pinfeed map --json` (and `map.json`).
#[derive(Debug, Serialize)]
pub struct MapReport<'a> {
    /// The command that regenerates this report.
    pub command: String,
    /// The part spec, as given.
    pub part: &'a str,
    /// The contact model's name (`map` when the map tier ran).
    pub model: &'a str,
    /// Pin–part friction coefficient μc.
    pub mu_c: f64,
    /// Pin radius (part units).
    pub pin_radius: f64,
    /// The support spec (`uniform`, `tripod:SEED`).
    pub support: &'a str,
    /// Spacing of the initial orientations θ0 (degrees; divides 360).
    pub theta_step_deg: f64,
    /// Band threshold T (degrees): neighbouring final angles at least T apart start a new band.
    pub threshold_deg: f64,
    /// Integration tolerance per step.
    pub tol: f64,
    /// The fence of a fence map, placed as `pinfeed contact --fence` places it (part units at θ0 = 0,
    /// the part's centroid at the origin).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fence: Option<crate::mechanics::FenceSpec>,
    /// One configuration map per offset d.
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

impl MapReport<'_> {
    /// The terminal summary: the settings on one line, then the bands of every map.
    pub fn text(&self) -> String {
        let obstacle = match &self.fence {
            Some(f) => format!(
                "fence {}° length {} μf {}",
                fence_angle_deg(self.maps),
                f.length,
                f.mu_f
            ),
            None => format!("μc {}  pin radius {}", self.mu_c, self.pin_radius),
        };
        format!(
            "{}  model {}  {obstacle}  support {}  θ0 step {}°  threshold {}°\n{}",
            self.part,
            self.model,
            self.support,
            self.theta_step_deg,
            self.threshold_deg,
            map_table::bands_text(self.maps)
        )
    }
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

/// One CSV row per sample of every map (`pinfeed map --csv`, `samples.csv`).
pub fn write_csv<W: std::io::Write>(w: W, maps: &[ConfigurationMap]) -> ReportResult<()> {
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
pub fn write_report(
    report: &MapReport,
    out_dir: &Path,
    plot_dir: Option<&Path>,
) -> ReportResult<()> {
    let plot_dir = plot_dir.unwrap_or(out_dir);
    for dir in [out_dir, plot_dir] {
        crate::report::error::create_dir(dir)?;
    }
    let json_path = out_dir.join("map.json");
    // Compact: the document holds every sample (README.md is the readable summary).
    crate::output::write_atomic(&json_path, crate::report::versioned::compact(report)?)
        .map_err(ReportError::writing(&json_path))?;
    let csv_path = out_dir.join("samples.csv");
    crate::output::produce_atomic(&csv_path, |tmp| {
        write_csv(
            std::io::BufWriter::new(std::fs::File::create(tmp)?),
            report.maps,
        )
    })
    .map_err(ReportError::writing(&csv_path))?;

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
            .map_err(ReportError::writing(&path))?;
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
            .map_err(ReportError::writing(&path))?;
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
        "# Configuration maps: {part}\n\nRegenerate with\n\n    {cmd}\n\n",
        part = report.part,
        cmd = report.command,
    );
    let obstacle = match &report.fence {
        Some(f) => format!(
            "a fence at {}° of length {} (part units) with friction μf = {}, its upstream end at \
             ({:.4}, {:.4}) when the part's centroid is at the origin (the placement of \
             `pinfeed contact --fence`, `crates/pinfeed/src/maps/start.rs`)",
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
         Conventions: docs/physics.md#configuration-maps and the module docs of `crates/pinfeed/src/maps/` (bands group neighbours in sorted \
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
    crate::output::write_atomic(&readme, md).map_err(ReportError::writing(&readme))?;
    // The folder holds this run's figures only: a figure of an earlier run for a d not asked
    // for now goes.
    let written: Vec<String> = figures
        .iter()
        .filter_map(|(_, p)| p.file_name().map(|f| f.to_string_lossy().into_owned()))
        .collect();
    crate::report::stale::remove_stale(plot_dir, &written, is_map_figure)
        .map_err(ReportError::removing("figures", plot_dir))?;
    Ok(())
}

/// The names of the figures `pinfeed map` writes.
fn is_map_figure(name: &str) -> bool {
    name.ends_with(".svg")
        && (name.starts_with("map_d")
            || name == "map_fence.svg"
            || name.starts_with("band_intervals"))
}
