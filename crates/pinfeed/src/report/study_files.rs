//! The files of a study's report: a Monte Carlo study's report folder ([`mc_report_files`], as
//! `pinfeed mc` and `pinfeed merge` write it) and the accuracy benchmark's report
//! ([`accuracy_bench`]).

use crate::output::{write_file, Batch, WriteError};
use crate::report::{ReportError, ReportResult};
use crate::study::accuracy;
use crate::study::bench_error::BenchError;
use crate::study::mc::report::{self, McReport};

/// Write a report's files into `dir`: `report.md`, `report.json` and `sensitivity.svg`, whole
/// and together or not at all. Returns the JSON text and the Markdown file's path; `mc` and
/// `merge` both write through it, so their files are the same bytes.
pub fn mc_report_files(
    r: &McReport,
    dir: &std::path::Path,
) -> ReportResult<(String, std::path::PathBuf)> {
    crate::report::error::create_dir(dir)?;
    let figure = "sensitivity.svg";
    let (md, js, svg) = (
        dir.join("report.md"),
        dir.join("report.json"),
        dir.join(figure),
    );
    let json_text = report::json(r);
    let mut batch = Batch::new();
    batch
        .write(&md, report::markdown(r, figure))
        .map_err(ReportError::writing(&md))?;
    batch
        .write(&js, &json_text)
        .map_err(ReportError::writing(&js))?;
    batch
        .produce(&svg, |tmp| {
            super::plot_sensitivity::plot_sensitivity(r, tmp)
        })
        .map_err(ReportError::writing(&svg))?;
    batch
        .commit()
        .map_err(ReportError::writing_into("report", dir))?;
    Ok((json_text, md))
}

/// Why `pinfeed bench accuracy` failed.
#[derive(Debug, thiserror::Error)]
pub enum AccuracyBenchError {
    /// The study could not run (or its number of contacts is out of range).
    #[error(transparent)]
    Bench(#[from] BenchError),
    /// The report or its table could not be written.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// The figure could not be written (the cause in full in the message, not as a source).
    #[error("writing {}: {}", path.display(), chain(error))]
    Figure {
        /// The figure's file.
        path: std::path::PathBuf,
        /// Why it could not be written.
        error: ReportError,
    },
}

/// `e` and its sources, joined by ": " (as the command line prints a chain with `{:#}`).
fn chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text.push_str(&format!(": {s}"));
        source = s.source();
    }
    text
}

/// `pinfeed bench accuracy`: the study over tripoly1, tripoly2, square and lshape with
/// `contacts` contacts (4 to 10⁶), written to `out` with the extensions md (keeping the
/// hand-written sections of an existing report; `cmd` heads it), csv and svg. Returns the
/// Markdown table and the three files.
pub fn accuracy_bench(
    contacts: usize,
    seed: u64,
    cmd: &str,
    out: &std::path::Path,
) -> Result<(String, [std::path::PathBuf; 3]), AccuracyBenchError> {
    if !(4..=1_000_000).contains(&contacts) {
        return Err(BenchError::argument("contacts", "between 4 and 1000000", contacts).into());
    }
    let st = accuracy::run(
        &["tripoly1", "tripoly2", "square", "lshape"],
        contacts,
        seed,
    )?;
    let [md, csv_path, svg] = ["md", "csv", "svg"].map(|e| out.with_extension(e));
    let old = std::fs::read_to_string(&md).unwrap_or_default();
    write_file(&md, accuracy::report_keeping(&st, cmd, &old))?;
    write_file(&csv_path, accuracy::csv(&st))?;
    crate::report::plot_accuracy::plot_accuracy(&st, &svg).map_err(|error| {
        AccuracyBenchError::Figure {
            path: svg.clone(),
            error,
        }
    })?;
    Ok((accuracy::markdown_table(&st), [md, csv_path, svg]))
}
