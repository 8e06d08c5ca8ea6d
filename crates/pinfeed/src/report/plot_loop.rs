//! `closed_loop.svg` of a run with a reject gate: the loop over time, in two panels on one time
//! axis. Above, the parts delivered per minute and those delivered in the goal, per bin of the
//! summary's series, with the warm-up MSER-5 found (shaded) and the steady delivered rate with its
//! batch-means interval; below, the parts on the return path and waiting at the merge (time
//! averages per bin). The time axis ends with the last delivery; both value axes start at zero.

use crate::engine::closed_loop::LoopSummary;
use crate::output::Staged;
use crate::report::ReportResult;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::path::Path;

const DELIVERED: RGBColor = RGBColor(31, 111, 208);
const ORIENTED: RGBColor = RGBColor(30, 150, 60);
const LOAD: RGBColor = RGBColor(200, 110, 20);
const BUFFER: RGBColor = RGBColor(140, 50, 170);

type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The series' legend, upper right, over a pale background.
fn legend<'a, 'b: 'a>(ch: &mut Chart<'a, 'b>) -> ReportResult<()> {
    ch.configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.3))
        .label_font(("sans-serif", 12))
        .draw()?;
    Ok(())
}

/// Draw the loop of run `scenario` (its summary block `l`) to the SVG file `path`, written whole
/// or not at all.
pub fn plot_loop(scenario: &str, l: &LoopSummary, path: &Path) -> ReportResult<()> {
    let s = &l.series;
    // About 200 bins drawn: the series' bins summed (counts) or averaged (levels) in groups.
    let group = s.delivered.len().div_ceil(200).max(1);
    let width = s.bin_s * group as f64;
    let per_min = 60.0 / width;
    let bins = s
        .delivered
        .len()
        .max(s.return_load.len())
        .max(s.buffer.len())
        .max(1);
    let t_end = bins as f64 * s.bin_s;
    let rate = |v: &[u64]| -> Vec<(f64, f64)> {
        (v.chunks(group).enumerate())
            .map(|(k, c)| {
                (
                    (k as f64 + 0.5) * width,
                    c.iter().sum::<u64>() as f64 * per_min,
                )
            })
            .collect()
    };
    let level = |v: &[f64]| -> Vec<(f64, f64)> {
        (v.chunks(group).enumerate())
            .map(|(k, c)| {
                (
                    (k as f64 + 0.5) * width,
                    c.iter().sum::<f64>() / group as f64,
                )
            })
            .collect()
    };
    let delivered = rate(&s.delivered);
    let oriented = rate(&s.oriented);
    // Headroom above the data for the legend.
    let top = delivered.iter().map(|p| p.1).fold(0.0, f64::max).max(1e-9) * 1.7;
    let load = level(&s.return_load);
    let buffer = level(&s.buffer);
    let load_top = load
        .iter()
        .chain(&buffer)
        .map(|p| p.1)
        .fold(0.0, f64::max)
        .max(1.0)
        * 1.7;
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (900, 620)).into_drawing_area();
    root.fill(&WHITE)?;
    let (upper, lower) = root.split_vertically(360);
    let oa = &l.output_analysis;
    let mut ch = ChartBuilder::on(&upper)
        .caption(
            format!(
                "{scenario}: closed loop, {} new parts, purity {:.4} ({:.4}–{:.4}), {:.2} passes per delivered part",
                l.new_parts,
                l.purity,
                l.purity_ci95[0],
                l.purity_ci95[1],
                l.passes_per_delivered.mean
            ),
            ("sans-serif", 16),
        )
        .margin(12)
        .x_label_area_size(30)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t_end, 0.0..top)?;
    ch.configure_mesh()
        .y_desc("parts per minute")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.1}"))
        .draw()?;
    if oa.warm_up_s > 0.0 {
        ch.draw_series(std::iter::once(Rectangle::new(
            [(0.0, 0.0), (oa.warm_up_s.min(t_end), top)],
            BLACK.mix(0.07).filled(),
        )))?
        .label(format!("warm-up (MSER-5): {:.0} s", oa.warm_up_s))
        .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], BLACK.mix(0.1).filled()));
    }
    if let Some(m) = oa.delivered_per_min {
        let lo = oa.warm_up_s.min(t_end);
        ch.draw_series(std::iter::once(Rectangle::new(
            [(lo, m.ci95[0]), (t_end, m.ci95[1])],
            DELIVERED.mix(0.15).filled(),
        )))?;
        ch.draw_series(LineSeries::new(
            vec![(lo, m.mean), (t_end, m.mean)],
            DELIVERED.stroke_width(2),
        ))?
        .label(format!(
            "steady delivered {:.2} ({:.2}–{:.2}) per min, 95% batch means",
            m.mean, m.ci95[0], m.ci95[1]
        ))
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], DELIVERED.stroke_width(2)));
    }
    ch.draw_series(LineSeries::new(delivered, DELIVERED.mix(0.6)))?
        .label("delivered, per bin (under the green where all are in the goal)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], DELIVERED.mix(0.6)));
    ch.draw_series(LineSeries::new(oriented, ORIENTED.mix(0.8)))?
        .label("delivered in the goal, per bin")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], ORIENTED.mix(0.8)));
    legend(&mut ch)?;
    let mut ch = ChartBuilder::on(&lower)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t_end, 0.0..load_top)?;
    ch.configure_mesh()
        .x_desc(format!(
            "time since the first arrival (s); bins of {:.0} s",
            width
        ))
        .y_desc("parts")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.1}"))
        .draw()?;
    ch.draw_series(LineSeries::new(load, LOAD.stroke_width(2)))?
        .label(format!(
            "on the return path (mean {:.2}, max {})",
            l.return_load.mean, l.return_load.max
        ))
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], LOAD.stroke_width(2)));
    ch.draw_series(LineSeries::new(buffer, BUFFER.stroke_width(2)))?
        .label(format!(
            "waiting at the merge (mean {:.2}, max {})",
            l.buffer.mean, l.buffer.max
        ))
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BUFFER.stroke_width(2)));
    legend(&mut ch)?;
    root.present()?;
    staged.commit()?;
    Ok(())
}
