//! The Monte Carlo study's figure (SVG). With one swept parameter: the success rate against it,
//! with its 95% interval as a band and whiskers; with two: one line per value of the second
//! parameter; without a sweep: the share of every outcome class that occurred, with whiskers.

use crate::engine::PartOutcome;
use crate::mechanics::limits::short;
use crate::output::Staged;
use crate::report::ReportResult;
use crate::study::mc::report::McReport;
use plotters::prelude::*;
use std::path::Path;

/// Draw the figure for `r` into `path`.
pub fn plot_sensitivity(r: &McReport, path: &Path) -> ReportResult<()> {
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let title = format!(
        "{}: {} samples per point",
        r.header.study, r.header.samples_per_point
    );
    if r.header.sweep.is_empty() {
        outcome_bars(r, &root, &title)?;
    } else {
        success_lines(r, &root, &title)?;
    }
    root.present()?;
    staged.commit()?;
    Ok(())
}

fn y_floor(lows: impl Iterator<Item = f64>) -> f64 {
    let lo = lows.fold(1.0, f64::min) * 100.0;
    ((lo - 5.0) / 10.0).floor().max(0.0) * 10.0
}

fn success_lines(
    r: &McReport,
    root: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    title: &str,
) -> ReportResult<()> {
    let axis0 = &r.header.sweep[0];
    let (mut x0, mut x1) = axis0
        .values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if x1 <= x0 {
        let pad = if x0 == 0.0 { 1.0 } else { 0.1 * x0.abs() };
        (x0, x1) = (x0 - pad, x1 + pad);
    }
    let pad = 0.04 * (x1 - x0);
    let ymin = y_floor(r.results.iter().map(|p| p.success_ci95[0]));
    let mut ch = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d((x0 - pad)..(x1 + pad), ymin..100.5)?;
    ch.configure_mesh()
        .x_desc(axis0.parameter.as_str())
        .y_desc("success rate (%), 95% interval")
        .x_label_formatter(&|v| {
            if *v == 0.0 || (0.01..1000.0).contains(&v.abs()) {
                short((v * 1e4).round() / 1e4)
            } else {
                format!("{v:.2e}")
            }
        })
        .draw()?;
    // One series per value of the second axis (or a single one).
    let groups: Vec<(String, Vec<usize>)> = match r.header.sweep.get(1) {
        None => vec![("success rate".to_string(), (0..r.results.len()).collect())],
        Some(a1) => (0..a1.values.len())
            .map(|k| {
                (
                    format!("{} = {}", a1.parameter, short(a1.values[k])),
                    (0..axis0.values.len())
                        .map(|i| i * a1.values.len() + k)
                        .collect(),
                )
            })
            .collect(),
    };
    for (gi, (label, idx)) in groups.iter().enumerate() {
        let color = Palette99::pick(gi).to_rgba();
        let pts: Vec<(f64, f64, f64, f64)> = idx
            .iter()
            .map(|&j| {
                let p = &r.results[j];
                (
                    r.header.points[j][0],
                    100.0 * p.success_rate,
                    100.0 * p.success_ci95[0],
                    100.0 * p.success_ci95[1],
                )
            })
            .collect();
        let mut band: Vec<(f64, f64)> = pts.iter().map(|p| (p.0, p.3)).collect();
        band.extend(pts.iter().rev().map(|p| (p.0, p.2)));
        ch.draw_series(std::iter::once(Polygon::new(
            band,
            color.mix(0.15).filled(),
        )))?;
        for p in &pts {
            ch.draw_series(std::iter::once(PathElement::new(
                vec![(p.0, p.2), (p.0, p.3)],
                color.stroke_width(1),
            )))?;
        }
        ch.draw_series(LineSeries::new(
            pts.iter().map(|p| (p.0, p.1)),
            color.stroke_width(2),
        ))?
        .label(label.clone())
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
        ch.draw_series(
            pts.iter()
                .map(|p| Circle::new((p.0, p.1), 4, color.filled())),
        )?;
    }
    ch.configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.8))
        .draw()?;
    Ok(())
}

/// The axis of the outcome bars: each sample's outcome, under what the study perturbs (a study
/// without a sweep names no parameter anywhere else in its figure).
fn outcome_axis(uncertain: &[String]) -> String {
    if uncertain.is_empty() {
        "outcome of each sample (nothing uncertain: the nominal line)".to_string()
    } else {
        format!("outcome of each sample under {}", uncertain.join("; "))
    }
}

fn outcome_bars(
    r: &McReport,
    root: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    title: &str,
) -> ReportResult<()> {
    let p = &r.results[0];
    let classes: Vec<&str> = PartOutcome::ALL
        .iter()
        .map(|c| c.name())
        .filter(|&c| c == "success" || p.shares[c].count > 0)
        .collect();
    let n = classes.len();
    let mut ch = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(-0.5f64..(n as f64 - 0.5), 0.0f64..100.5)?;
    let names = classes.clone();
    ch.configure_mesh()
        .disable_x_mesh()
        .x_labels(n.max(2))
        .x_label_formatter(&move |v| {
            let i = v.round();
            if (v - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < names.len() {
                names[i as usize].to_string()
            } else {
                String::new()
            }
        })
        .x_desc(outcome_axis(&r.header.uncertain))
        .y_desc("share of samples (%), 95% interval")
        .draw()?;
    for (i, c) in classes.iter().enumerate() {
        let s = p.shares[*c];
        let x = i as f64;
        let color = if *c == "success" { GREEN } else { RED };
        ch.draw_series(std::iter::once(Rectangle::new(
            [(x - 0.3, 0.0), (x + 0.3, 100.0 * s.rate)],
            color.mix(0.6).filled(),
        )))?;
        ch.draw_series(std::iter::once(PathElement::new(
            vec![(x, 100.0 * s.ci95[0]), (x, 100.0 * s.ci95[1])],
            BLACK.stroke_width(2),
        )))?;
    }
    Ok(())
}
