//! The report of `pinfeed validate` ([`crate::validate`]) and the report folder `validate` and
//! `calibrate` share: the JSON document, the row table, the summary, README.md and the figures.

use crate::geometry::named::part_folder;
use crate::maps::arcs::Arc;
use crate::maps::ensemble::PredictedBands;
use crate::report::fixed;
use crate::report::map_table::predicted_bands_text as bands_text;
use crate::report::plot_validate::plot_band_distributions;
use crate::report::{ReportError, ReportResult};
use crate::validate::score::{RowScore, ScoreSettings, Summary};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// The head of a report's README.md: title, regenerating command, a sentence and a bullet list.
pub(crate) struct ReportHead<'a> {
    /// The report's title.
    pub title: String,
    /// The command that regenerates the report.
    pub command: &'a str,
    /// One paragraph after the command.
    pub intro: String,
    /// The bullet list after it.
    pub bullets: &'a [String],
}

/// Create `out_dir`, write `report` there as `json_name`, then README.md: the head followed by
/// what `body` returns (it may write figures into `out_dir`).
pub(crate) fn write_report_files<T: Serialize>(
    out_dir: &Path,
    json_name: &str,
    report: &T,
    head: ReportHead,
    body: impl FnOnce(&Path) -> ReportResult<String>,
) -> ReportResult<()> {
    crate::report::error::create_dir(out_dir)?;
    let json = out_dir.join(json_name);
    crate::output::write_atomic(&json, crate::report::versioned::pretty(report)?)
        .map_err(ReportError::writing(&json))?;
    let mut md = format!(
        "# {}\n\nRegenerate with:\n\n```\n{}\n```\n\n{}\n\n",
        head.title, head.command, head.intro
    );
    for line in head.bullets {
        let _ = writeln!(md, "* {line}");
    }
    md.push('\n');
    md.push_str(&body(out_dir)?);
    let readme = out_dir.join("README.md");
    crate::output::write_atomic(&readme, md).map_err(ReportError::writing(&readme))?;
    Ok(())
}

/// The document `validate.json`.
#[derive(Debug, Serialize)]
pub struct ValidateReport<'a> {
    /// The command that regenerates the report.
    pub command: String,
    /// The measured-band CSV file, as given.
    pub measured: String,
    /// The uncertain parameters, one line each.
    pub uncertain: Vec<String>,
    /// Members of the ensemble.
    pub members: usize,
    /// The settings of the score.
    pub score_settings: ScoreSettings,
    /// What `contained` and the verdicts mean ([`containment_text`]).
    pub containment: String,
    /// The overall score.
    pub summary: &'a Summary,
    /// The score of each measured row.
    pub rows: &'a [RowScore],
}

/// What "contained" means, in one sentence.
pub fn containment_text(threshold: f64) -> String {
    format!(
        "Contained: at least {}% of the predicted mass lies inside the measured band (for input `all`, of the mass within the window of it); the share is given with its 95% bootstrap interval over the members ({} resamples), and the verdict is yes when the whole interval is at or above {}%, no when it is below, undecided when it straddles it.",
        fixed(100.0 * threshold, 0, false),
        crate::validate::score::RESAMPLES,
        fixed(100.0 * threshold, 0, false)
    )
}

/// One line per row, then the summary.
pub fn rows_text(rows: &[RowScore], summary: &Summary) -> String {
    let mut s = String::from("| line | part | d | input | measured | trials | contained | share in band [95%] | overlapping | centre offset | P(measured) | log score | predicted bands (90%) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    let yes = |b: bool| if b { "yes" } else { "no" };
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {:+} | {} | [{}, {}] | {} | {} | {} [{}, {}] | {} | {} | {} | {} | {} |",
            r.line,
            r.part,
            r.d,
            r.input,
            r.min_deg,
            r.max_deg,
            r.trials.map_or("—".into(), |n| n.to_string()),
            r.containment.label(),
            fixed(r.contained_share, 3, false),
            fixed(r.contained_share_ci95[0], 3, false),
            fixed(r.contained_share_ci95[1], 3, false),
            yes(r.overlapping),
            r.centre_offset_deg
                .map_or("—".into(), |o| format!("{}°", fixed(o, 1, true))),
            fixed(r.predicted_probability, 3, false),
            fixed(r.log_score, 2, false),
            bands_text(&r.predicted)
        );
    }
    let _ = writeln!(
        s,
        "\n{}\n\n{}",
        containment_text(summary.contained_share),
        summary_text(summary)
    );
    s
}

/// The summary in one line.
pub fn summary_text(s: &Summary) -> String {
    format!(
        "{} rows: {} contained (95% interval {}–{}; verdicts {} yes, {} no, {} undecided), {} overlapping; predicted bands cover {}% of the circle on average; log score {} ({} per row)",
        s.rows,
        s.contained,
        s.contained_ci95[0],
        s.contained_ci95[1],
        s.verdict_contained,
        s.verdict_not_contained,
        s.verdict_undecided,
        s.overlapping,
        fixed(100.0 * s.coverage, 1, false),
        fixed(s.log_score, 2, false),
        fixed(s.mean_log_score, 3, false)
    )
}

/// Figures of measured bands over predictions, one per (part, input): (file name, title) written.
pub fn write_figures(rows: &[RowScore], dir: &Path) -> ReportResult<Vec<String>> {
    let mut groups: Vec<(String, String)> = Vec::new();
    for r in rows {
        let key = (r.part.clone(), r.input.clone());
        if !groups.contains(&key) {
            groups.push(key);
        }
    }
    let mut names = Vec::new();
    for (part, input) in groups {
        let of: Vec<&RowScore> = rows
            .iter()
            .filter(|r| r.part == part && r.input == input)
            .collect();
        // One prediction per d (rows of a thesis-style table share theirs).
        let mut predicted: Vec<&PredictedBands> = Vec::new();
        for r in &of {
            if !predicted.iter().any(|p| p.d == r.d) {
                predicted.push(&r.predicted);
            }
        }
        let measured: Vec<(f64, Arc)> = of
            .iter()
            .map(|r| (r.d, Arc::from_ends(r.min_deg, r.max_deg)))
            .collect();
        let name = format!("bands_{}_{}.svg", part_folder(&part), part_folder(&input));
        let title = format!("{part}, input {input}: measured bands over predicted θf");
        plot_band_distributions(&predicted, &measured, &title, &dir.join(&name))?;
        names.push(name);
    }
    Ok(names)
}

/// Write `validate.json`, README.md (with `text`) and the figures into `out_dir`.
pub fn write_report(report: &ValidateReport, text: &str, out_dir: &Path) -> ReportResult<()> {
    let head = ReportHead {
        title: format!("Validation: {}", report.measured),
        command: &report.command,
        intro: format!("{} members; ensemble:", report.members),
        bullets: &report.uncertain,
    };
    write_report_files(out_dir, "validate.json", report, head, |dir| {
        let mut md = format!("{text}\n");
        for name in write_figures(report.rows, dir)? {
            let _ = writeln!(md, "![{name}]({name})\n");
        }
        Ok(md)
    })
}
