//! The report of `pinfeed calibrate` ([`crate::validate::calibrate`]): the JSON document, the
//! parameter table with the scores, and the report folder.

use crate::report::validate_report::{summary_text, write_report_files, ReportHead};
use crate::report::ReportResult;
use crate::validate::calibrate::Calibration;
use crate::validate::score::Summary;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// The document `calibration.json`.
#[derive(Debug, Serialize)]
pub struct CalibrateReport<'a> {
    /// The command that regenerates the report.
    pub command: String,
    /// The measured-band CSV file, as given.
    pub measured: String,
    /// The fit: the parameters found and how.
    pub calibration: &'a Calibration,
    /// The nominal (starting) parameters, one line each.
    pub nominal: Vec<String>,
    /// The score of the nominal parameters against the measured bands.
    pub nominal_score: &'a Summary,
    /// The fitted parameters, one line each.
    pub fitted: Vec<String>,
    /// The score of the fitted parameters against the measured bands.
    pub fitted_score: &'a Summary,
    /// With --synthesize: the hidden values, in the order of the parameters.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hidden: Option<[f64; 4]>,
}

/// The fitted parameters with their intervals (and the hidden values of a synthetic data set).
pub fn parameter_table(c: &Calibration, hidden: Option<[f64; 4]>) -> String {
    let mut s = String::from("| parameter | estimate | 95% interval | searched | hidden value |\n|---|---|---|---|---|\n");
    for (k, p) in c.parameters.iter().enumerate() {
        let open = |o: bool| if o { " (open: grid end)" } else { "" };
        let truth = match hidden {
            Some(h) => format!(
                "{} ({})",
                h[k],
                if p.covers(h[k]) { "inside" } else { "OUTSIDE" }
            ),
            None => "—".into(),
        };
        let _ = writeln!(
            s,
            "| {} | {:.3} | [{:.3}{}, {:.3}{}] | [{}, {}] | {truth} |",
            p.name,
            p.estimate,
            p.lo,
            open(p.open_low),
            p.hi,
            open(p.open_high),
            p.grid_min,
            p.grid_max
        );
    }
    let _ = writeln!(
        s,
        "\nlog-likelihood at the estimate {:.2} ({} grid points); effective members {:.0} of {}",
        c.log_likelihood, c.grid_points, c.effective_members, c.members
    );
    s
}

/// The printed result: the parameter table, then the nominal model's and the fit's scores
/// (`nominal` describes the nominal ensemble).
pub fn calibration_text(
    cal: &Calibration,
    hidden: Option<[f64; 4]>,
    nominal: &[String],
    nominal_score: &Summary,
    fitted_score: &Summary,
) -> String {
    let mut text = parameter_table(cal, hidden);
    let _ = writeln!(
        text,
        "\nnominal model ({}): {}",
        nominal[..3].join("; "),
        summary_text(nominal_score)
    );
    let _ = writeln!(text, "fitted ensemble: {}", summary_text(fitted_score));
    text
}

/// Write `calibration.json` and README.md (with `text`) into `out_dir`.
pub fn write_report(report: &CalibrateReport, text: &str, out_dir: &Path) -> ReportResult<()> {
    let head = ReportHead {
        title: format!("Calibration: {}", report.measured),
        command: &report.command,
        intro: "Fitted ensemble:".into(),
        bullets: &report.fitted,
    };
    write_report_files(out_dir, "calibration.json", report, head, |_| {
        Ok(text.to_string())
    })
}
