//! SVG figures of ensemble predictions and measured bands:
//! [`plot_band_distributions`] draws, at each d, the predicted distribution of θf as a violin
//! (width ∝ share per 1° bin, scaled to the largest bin of the figure) centred on d, its 90%
//! predicted bands as bars just left of it, and optionally the measured bands as red bars with end
//! ticks just right of it — offsets for legibility only, said in the legend and on the axis; a
//! dotted guide marks each d. The θf axis zooms on the data (`plot_zoom`), so an arc
//! across 0°/360° is drawn in one piece.

use super::plot_map::{d_chart, header_with_legend, Swatch, PALETTE};
use super::plot_zoom::{degree_view, DegreeView};
use crate::maps::arcs::Arc;
use crate::maps::ensemble::PredictedBands;
use crate::output::Staged;
use crate::report::ReportResult;
use plotters::prelude::*;
use std::path::Path;

/// Smallest spacing between distinct d (0.2 for a single d).
fn spacing(ds: &[f64]) -> f64 {
    let v = distinct(ds);
    if v.len() < 2 {
        return 0.2;
    }
    v.windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min)
        .clamp(0.05, 0.4)
}

/// The distinct values of `ds`, ascending.
fn distinct(ds: &[f64]) -> Vec<f64> {
    let mut v = ds.to_vec();
    v.sort_by(f64::total_cmp);
    v.dedup();
    v
}

/// The θf axis: every occupied 1° bin of the predictions, every predicted and measured band.
fn view_of(predicted: &[&PredictedBands], measured: &[(f64, Arc)]) -> DegreeView {
    let mut arcs: Vec<(f64, f64)> = Vec::new();
    for p in predicted {
        arcs.extend(
            p.histogram
                .iter()
                .enumerate()
                .filter(|(_, &s)| s > 0.0)
                .map(|(b, _)| (b as f64, 1.0)),
        );
        arcs.extend(p.bands.iter().map(|b| (b.arc.lo, b.arc.width.max(0.5))));
    }
    arcs.extend(measured.iter().map(|(_, a)| (a.lo, a.width.max(0.5))));
    degree_view(&arcs, 5.0, 30.0, 40.0)
}

/// Predicted θf distributions and bands against d; `measured` are (d, band) pairs to draw over them.
pub fn plot_band_distributions(
    predicted: &[&PredictedBands],
    measured: &[(f64, Arc)],
    title: &str,
    path: &Path,
) -> ReportResult<()> {
    let ds: Vec<f64> = predicted
        .iter()
        .map(|p| p.d)
        .chain(measured.iter().map(|m| m.0))
        .collect();
    let step = spacing(&ds);
    let lo = ds.iter().copied().fold(f64::INFINITY, f64::min) - step;
    let hi = ds.iter().copied().fold(f64::NEG_INFINITY, f64::max) + step;
    let view = view_of(predicted, measured);
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (900, 640)).into_drawing_area();
    let blue = PALETTE[0];
    let dark = RGBColor(20, 40, 110);
    let red = RGBColor(200, 30, 30);
    // The legend, in one row above the chart.
    let mut entries = vec![
        (
            "predicted θf distribution at d (width ∝ √share per 1°)",
            Swatch::Filled(blue),
        ),
        ("90% predicted bands (left of d)", Swatch::Line(dark)),
    ];
    if !measured.is_empty() {
        entries.push(("measured bands [min, max] (right of d)", Swatch::Line(red)));
    }
    let body = header_with_legend(&root, title, &entries, 62)?;
    let mut ch = d_chart(
        &body,
        lo..hi,
        view,
        "contact parameter d (dotted guides; bands beside each d are offset only to be seen)",
        "final orientation θf (deg)",
    )?;
    for d in distinct(&ds) {
        ch.draw_series(DashedLineSeries::new(
            vec![(d, view.lo), (d, view.hi)],
            2,
            4,
            BLACK.mix(0.35).stroke_width(1),
        ))?;
    }
    let top = predicted
        .iter()
        .flat_map(|p| p.histogram.iter().copied())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let half = 0.32 * step;
    let violins = predicted.iter().flat_map(|p| {
        p.histogram
            .iter()
            .enumerate()
            .filter(|(_, &s)| s > 0.0)
            .map(move |(b, &s)| {
                let w = half * (s / top).sqrt().max(0.04);
                let y = view.place(b as f64);
                Rectangle::new([(p.d - w, y), (p.d + w, y + 1.0)], blue.mix(0.55).filled())
            })
    });
    ch.draw_series(violins)?;
    for p in predicted {
        for b in &p.bands {
            for (y0, y1) in view.pieces(b.arc.lo, b.arc.width.max(0.5)) {
                let x = p.d - half - 0.08 * step;
                ch.draw_series(LineSeries::new(
                    vec![(x, y0), (x, y1)],
                    dark.stroke_width(3),
                ))?;
            }
        }
    }
    for &(d, arc) in measured {
        let x = d + half + 0.08 * step;
        for (y0, y1) in view.pieces(arc.lo, arc.width.max(0.5)) {
            ch.draw_series(LineSeries::new(vec![(x, y0), (x, y1)], red.stroke_width(3)))?;
        }
        for y in [arc.lo, arc.hi()] {
            if !view.shows(y) {
                continue;
            }
            let y = view.place(y);
            let t = 0.04 * step;
            ch.draw_series(LineSeries::new(
                vec![(x - t, y), (x + t, y)],
                red.stroke_width(2),
            ))?;
        }
    }
    root.present()?;
    staged.commit()?;
    Ok(())
}
