//! The report of an ensemble map (`pinfeed map --uncertain`, [`crate::maps::ensemble`]): the
//! JSON document, the band table and the report folder with one figure per input state.

use crate::maps::ensemble::{InputState, MemberDraw, PredictedBands};
use crate::report::map_table::predicted_bands_text;
use crate::report::plot_validate::plot_band_distributions;
use crate::report::validate_report::{write_report_files, ReportHead};
use crate::report::ReportResult;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// The document `ensemble.json`.
#[derive(Debug, Serialize)]
pub struct EnsembleReport<'a> {
    /// The command that regenerates the report.
    pub command: String,
    /// The part spec, as given.
    pub part: &'a str,
    /// The uncertain parameters, one line each.
    pub uncertain: Vec<String>,
    /// Members of the ensemble (one drawn set of parameters each).
    pub members: usize,
    /// Seed of the members' draws; the same seed gives the same members.
    pub seed: u64,
    /// Spacing of the initial orientations θ0 (degrees).
    pub theta_step_deg: f64,
    /// The predicted bands per (d, input state).
    pub predicted: &'a [PredictedBands],
    /// What each member drew.
    pub draws: &'a [MemberDraw],
}

/// The band table: one line per (d, input).
pub fn table(predicted: &[PredictedBands]) -> String {
    let mut s = String::from(
        "| d | input | passes | predicted bands (90%) | circle covered |\n|---|---|---|---|---|\n",
    );
    for p in predicted {
        let _ = writeln!(
            s,
            "| {:+} | {} | {} | {} | {:.1}% |",
            p.d,
            p.input,
            p.passes,
            predicted_bands_text(p),
            100.0 * p.coverage
        );
    }
    s
}

/// Write `ensemble.json`, README.md (with the band `table`) and one figure per input state.
pub fn write_report(
    report: &EnsembleReport,
    inputs: &[InputState],
    table: &str,
    out_dir: &Path,
    plot_dir: Option<&Path>,
) -> ReportResult<()> {
    let head = ReportHead {
        title: format!("Ensemble map: {}", report.part),
        command: &report.command,
        intro: format!(
            "{} members, seed {}; uncertain:",
            report.members, report.seed
        ),
        bullets: &report.uncertain,
    };
    write_report_files(out_dir, "ensemble.json", report, head, |out_dir| {
        let plot_dir = plot_dir.unwrap_or(out_dir);
        crate::report::error::create_dir(plot_dir)?;
        let mut md = format!("Predicted bands: the smallest arcs (1° resolution, gaps under 5° closed, ends at the extreme passes they hold) that hold 90% of the passes pooled over the members and the input's θ0 (a stable state: the grid θ0 nearest it).\n\n{table}\n");
        for input in inputs {
            let label = input.label();
            let name = format!("ensemble_{}.svg", label.replace(':', ""));
            let of_input: Vec<&PredictedBands> = report
                .predicted
                .iter()
                .filter(|p| p.input == label)
                .collect();
            let title = format!("{}: predicted θf against d, input {label}", report.part);
            plot_band_distributions(&of_input, &[], &title, &plot_dir.join(&name))?;
            let _ = writeln!(md, "![{label}]({name})\n");
        }
        Ok(md)
    })
}
