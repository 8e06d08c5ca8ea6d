//! SVG histogram of the final orientations of the parts that reached the end of the belt, with the
//! part's stable states marked (dashed) and the goal's tolerance bands shaded.

use crate::engine::Summary;
use crate::report::atomic::Staged;
use crate::scenario::{Goal, Scene};
use plotters::prelude::*;
use std::path::Path;

pub fn plot_orientation_histogram(scene: &Scene, s: &Summary, path: &Path) -> anyhow::Result<()> {
    let h = &s.orientation_histogram;
    let ymax = h.counts.iter().copied().max().unwrap_or(0).max(1) as f64 * 1.1;
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (900, 420)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut ch = ChartBuilder::on(&root)
        .caption(
            format!(
                "{}: final orientation of {} exiting parts (seed {})",
                s.scenario,
                s.outcomes.success + s.outcomes.wrong_orientation,
                s.seed
            ),
            ("sans-serif", 18),
        )
        .margin(15)
        .x_label_area_size(35)
        .y_label_area_size(55)
        .build_cartesian_2d(0.0..360.0, 0.0..ymax)?;
    ch.configure_mesh()
        .x_desc("final orientation θ (degrees)")
        .y_desc("parts")
        .x_labels(13)
        .draw()?;
    if let Goal::Sets(sets) = &scene.goal {
        for set in sets {
            for &o in &set.orientations {
                let c = crate::geometry::wrap_deg(o.to_degrees());
                let tol = set.tolerance.to_degrees();
                for shift in [-360.0, 0.0, 360.0] {
                    let (a, b) = ((c - tol + shift).max(0.0), (c + tol + shift).min(360.0));
                    if a < b {
                        ch.draw_series(std::iter::once(Rectangle::new(
                            [(a, 0.0), (b, ymax)],
                            GREEN.mix(0.15).filled(),
                        )))?;
                    }
                }
            }
        }
    }
    ch.draw_series(
        h.counts
            .iter()
            .enumerate()
            .filter(|(_, &c)| c > 0)
            .map(|(i, &c)| {
                let x0 = i as f64 * h.bin_deg;
                Rectangle::new(
                    [(x0, 0.0), (x0 + h.bin_deg, c as f64)],
                    BLUE.mix(0.7).filled(),
                )
            }),
    )?;
    for st in &scene.part.stable_states {
        let x = st.theta.to_degrees();
        ch.draw_series(DashedLineSeries::new(
            vec![(x, 0.0), (x, ymax)],
            6,
            4,
            BLACK.mix(0.6).stroke_width(1),
        ))?;
    }
    root.present()?;
    staged.commit()?;
    Ok(())
}
