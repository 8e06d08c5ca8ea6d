//! SVG figures of ensemble predictions and measured bands:
//! [`plot_band_distributions`] draws, at each d, the predicted distribution of θf as a violin
//! (width ∝ share per 1° bin, scaled to the largest bin of the figure), its 90% predicted bands as
//! bars beside it, and optionally the measured bands as red bars with end ticks on the other side.
//! Arcs straddling 0°/360° are drawn as two pieces (as in [`super::plot_map`]).

use super::plot_map::{arc_pieces, d_axis_mesh, degree_chart, draw_legend, Chart, PALETTE};
use crate::maps::arcs::Arc;
use crate::maps::ensemble::PredictedBands;
use crate::report::atomic::Staged;
use plotters::prelude::*;
use std::path::Path;

/// Smallest spacing between distinct d (0.2 for a single d).
fn spacing(ds: &[f64]) -> f64 {
    let mut v = ds.to_vec();
    v.sort_by(f64::total_cmp);
    v.dedup();
    if v.len() < 2 {
        return 0.2;
    }
    v.windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min)
        .clamp(0.05, 0.4)
}

/// A legend entry: a thick line of `colour` (the series itself draws nothing).
fn legend_line(ch: &mut Chart, label: &str, colour: RGBColor) -> anyhow::Result<()> {
    ch.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 14, y)], colour.stroke_width(3)));
    Ok(())
}

/// Predicted θf distributions and bands against d; `measured` are (d, band) pairs to draw over them.
pub fn plot_band_distributions(
    predicted: &[&PredictedBands],
    measured: &[(f64, Arc)],
    title: &str,
    path: &Path,
) -> anyhow::Result<()> {
    let ds: Vec<f64> = predicted
        .iter()
        .map(|p| p.d)
        .chain(measured.iter().map(|m| m.0))
        .collect();
    let step = spacing(&ds);
    let lo = ds.iter().copied().fold(f64::INFINITY, f64::min) - step;
    let hi = ds.iter().copied().fold(f64::NEG_INFINITY, f64::max) + step;
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (900, 640)).into_drawing_area();
    let mut ch = degree_chart(&root, title, lo..hi, 420.0)?;
    d_axis_mesh(&mut ch, "final orientation θf (deg)")?;
    ch.draw_series(LineSeries::new(
        vec![(lo, 360.0), (hi, 360.0)],
        BLACK.mix(0.6),
    ))?;
    let top = predicted
        .iter()
        .flat_map(|p| p.histogram.iter().copied())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let half = 0.32 * step;
    let blue = PALETTE[0];
    let violins = predicted.iter().flat_map(|p| {
        p.histogram
            .iter()
            .enumerate()
            .filter(|(_, &s)| s > 0.0)
            .map(move |(b, &s)| {
                let w = half * (s / top).sqrt().max(0.04);
                Rectangle::new(
                    [(p.d - w, b as f64), (p.d + w, b as f64 + 1.0)],
                    blue.mix(0.55).filled(),
                )
            })
    });
    ch.draw_series(violins)?
        .label("predicted θf distribution (width ∝ √share per 1°)")
        .legend(move |(x, y)| {
            Rectangle::new([(x, y - 4), (x + 14, y + 4)], blue.mix(0.55).filled())
        });
    let dark = RGBColor(20, 40, 110);
    for p in predicted {
        for b in &p.bands {
            for (y0, y1) in arc_pieces(b.arc.lo, b.arc.width.max(0.5)) {
                let x = p.d - half - 0.08 * step;
                ch.draw_series(LineSeries::new(
                    vec![(x, y0), (x, y1)],
                    dark.stroke_width(3),
                ))?;
            }
        }
    }
    legend_line(&mut ch, "90% predicted bands", dark)?;
    if !measured.is_empty() {
        let red = RGBColor(200, 30, 30);
        for &(d, arc) in measured {
            let x = d + half + 0.08 * step;
            for (y0, y1) in arc_pieces(arc.lo, arc.width.max(0.5)) {
                ch.draw_series(LineSeries::new(vec![(x, y0), (x, y1)], red.stroke_width(3)))?;
            }
            for y in [arc.lo, arc.hi()] {
                let t = 0.04 * step;
                ch.draw_series(LineSeries::new(
                    vec![(x - t, y), (x + t, y)],
                    red.stroke_width(2),
                ))?;
            }
        }
        legend_line(&mut ch, "measured bands [min, max]", red)?;
    }
    draw_legend(&mut ch, SeriesLabelPosition::UpperMiddle)?;
    root.present()?;
    staged.commit()?;
    Ok(())
}
