//! The files of a study's report: a Monte Carlo study's report folder ([`mc_report_files`], as
//! `pinfeed mc` and `pinfeed merge` write it) and the accuracy benchmark's report
//! ([`accuracy_bench`]).

use crate::output::{write_file, Batch};
use crate::study::accuracy;
use crate::study::mc::report::{self, McReport};

/// Write a report's files into `dir`: `report.md`, `report.json` and `sensitivity.svg`, whole
/// and together or not at all. Returns the JSON text and the Markdown file's path; `mc` and
/// `merge` both write through it, so their files are the same bytes.
pub fn mc_report_files(
    r: &McReport,
    dir: &std::path::Path,
) -> anyhow::Result<(String, std::path::PathBuf)> {
    use anyhow::Context;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
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
        .with_context(|| format!("writing {}", md.display()))?;
    batch
        .write(&js, &json_text)
        .with_context(|| format!("writing {}", js.display()))?;
    batch
        .produce(&svg, |tmp| {
            super::plot_sensitivity::plot_sensitivity(r, tmp)
        })
        .with_context(|| format!("writing {}", svg.display()))?;
    batch
        .commit()
        .with_context(|| format!("writing the report into {}", dir.display()))?;
    Ok((json_text, md))
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
) -> anyhow::Result<(String, [std::path::PathBuf; 3])> {
    if !(4..=1_000_000).contains(&contacts) {
        anyhow::bail!("--contacts must be between 4 and 1000000, got {contacts}");
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
    crate::report::plot_accuracy::plot_accuracy(&st, &svg)
        .map_err(|e| anyhow::anyhow!("writing {}: {e:#}", svg.display()))?;
    Ok((accuracy::markdown_table(&st), [md, csv_path, svg]))
}
