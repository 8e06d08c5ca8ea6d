//! SVG of the accuracy-vs-time study: error against time per contact, one point per tier
//! (log–log), mean error and 95th percentile.

use crate::output::Staged;
use crate::report::ReportResult;
use crate::study::accuracy::AccuracyStudy;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Draw the accuracy-vs-time study to the SVG file `path` (written whole or not at all).
pub fn plot_accuracy(st: &AccuracyStudy, path: &Path) -> ReportResult<()> {
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (900, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let floor = 1e-9;
    let pts: Vec<(f64, f64, f64, &str)> = st
        .rows
        .iter()
        .map(|r| {
            (
                r.median_us.max(1e-3),
                r.error_mean_deg.max(floor),
                r.error_p95_deg.max(floor),
                r.tier.as_str(),
            )
        })
        .collect();
    let (tmin, tmax) = pts.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| {
        (a.min(p.0), b.max(p.0))
    });
    let emax = pts.iter().map(|p| p.2).fold(floor, f64::max);
    let mut ch = ChartBuilder::on(&root)
        .caption(
            format!(
                "What accuracy costs: {} contacts over {}",
                st.contacts,
                st.parts.join(", ")
            ),
            ("sans-serif", 18),
        )
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(
            ((tmin * 0.5)..(tmax * 3.0)).log_scale(),
            (floor..(emax * 5.0)).log_scale(),
        )?;
    ch.configure_mesh()
        .x_desc("median time per contact (µs, one thread)")
        .y_desc("final-angle error vs exact reference (deg)")
        .x_label_formatter(&|v| format!("{v:.2}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()?;
    ch.draw_series(
        pts.iter()
            .map(|p| Circle::new((p.0, p.1), 5, BLUE.filled())),
    )?
    .label("mean error")
    .legend(|(x, y)| Circle::new((x + 8, y), 5, BLUE.filled()));
    ch.draw_series(
        pts.iter()
            .map(|p| TriangleMarker::new((p.0, p.2), 6, RED.filled())),
    )?
    .label("95th percentile")
    .legend(|(x, y)| TriangleMarker::new((x + 8, y), 6, RED.filled()));
    for p in &pts {
        // The tables' tiers sit left of the solves' at the same errors: label them on their left
        // (right-aligned, level with the 95th-percentile marker), the others on their right.
        let (label, at, h) = match p.3.strip_prefix("exact+tables ") {
            Some(tol) => (format!("+tables {tol}"), (p.0 / 1.12, p.2), HPos::Right),
            None => (p.3.to_string(), (p.0 * 1.08, p.2 * 1.4), HPos::Left),
        };
        let style = TextStyle::from(("sans-serif", 12).into_font()).pos(Pos::new(h, VPos::Center));
        ch.draw_series(std::iter::once(Text::new(label, at, style)))?;
    }
    ch.configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.8))
        .draw()?;
    root.present()?;
    staged.commit()?;
    Ok(())
}
