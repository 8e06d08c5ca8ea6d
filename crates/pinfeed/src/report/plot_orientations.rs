//! SVG histogram of the final orientations of the parts that reached the end of the belt, zoomed
//! on the data (`plot_zoom`): the part's stable states marked (dashed, labelled; those
//! outside the view named in the caption below the axis) and the goal's tolerance bands shaded and
//! labelled. Counts are whole numbers.

use super::plot_zoom::{degree_axis, degree_view, DegreeView};
use crate::engine::Summary;
use crate::geometry::wrap_deg;
use crate::output::Staged;
use crate::report::ReportResult;
use crate::scenario::{Goal, Scene};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// A degree in a label: whole when it is, else one decimal.
fn deg(x: f64) -> String {
    let w = wrap_deg(x);
    if (w - w.round()).abs() < 0.05 {
        format!("{:.0}°", w.round())
    } else {
        format!("{w:.1}°")
    }
}

/// Draw the histogram of a line run's final part orientations, the scenario's goal windows
/// marked, to the SVG file `path` (written whole or not at all).
pub fn plot_orientation_histogram(scene: &Scene, s: &Summary, path: &Path) -> ReportResult<()> {
    let h = &s.orientation_histogram;
    let top = h.counts.iter().copied().max().unwrap_or(0).max(1);
    let ymax = (top as f64 * 1.18).max(top as f64 + 1.0);
    // Goal windows (centre, tolerance, name) in degrees.
    let mut goals: Vec<(f64, f64, String)> = Vec::new();
    if let Goal::Sets(sets) = &scene.goal {
        for set in sets {
            for &o in &set.orientations_rad {
                goals.push((
                    wrap_deg(o.to_degrees()),
                    set.tolerance_rad.to_degrees(),
                    set.name.clone(),
                ));
            }
        }
    }
    // Zoom on the occupied bins and the goal windows.
    let mut arcs: Vec<(f64, f64)> = h
        .counts
        .iter()
        .enumerate()
        .filter(|(_, &c)| c > 0)
        .map(|(i, _)| (i as f64 * h.bin_deg, h.bin_deg))
        .collect();
    arcs.extend(goals.iter().map(|(c, t, _)| (c - t, 2.0 * t)));
    let view = degree_view(&arcs, 4.0, 20.0, 40.0);
    let stable: Vec<f64> = scene
        .part
        .stable_states
        .iter()
        .map(|st| wrap_deg(st.theta_rad.to_degrees()))
        .collect();
    let hidden: Vec<String> = stable
        .iter()
        .filter(|&&x| !view.shows(x))
        .map(|&x| deg(x))
        .collect();
    let x_desc = if hidden.is_empty() {
        "final orientation θ (degrees)".to_string()
    } else {
        format!(
            "final orientation θ (degrees); stable state(s) outside this view: {}",
            hidden.join(", ")
        )
    };
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
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(degree_axis(view.lo..view.hi, 12), 0.0..ymax)?;
    ch.configure_mesh()
        .x_desc(x_desc)
        .y_desc("parts")
        .x_label_formatter(&|v| DegreeView::label(*v))
        .y_label_formatter(&|v| {
            if (v - v.round()).abs() < 1e-6 {
                format!("{:.0}", v.round())
            } else {
                String::new()
            }
        })
        .draw()?;
    let font = ("sans-serif", 12).into_font();
    for (c, tol, name) in &goals {
        for (a, b) in view.pieces(c - tol, 2.0 * tol) {
            ch.draw_series(std::iter::once(Rectangle::new(
                [(a, 0.0), (b, ymax)],
                GREEN.mix(0.15).filled(),
            )))?;
        }
        if view.shows(*c) {
            let x = view.place(*c);
            ch.draw_series(std::iter::once(Text::new(
                format!("goal {name}: {} ± {}", deg(*c), deg(*tol)),
                (x, ymax * 0.97),
                font.color(&RGBColor(20, 110, 40))
                    .pos(Pos::new(HPos::Center, VPos::Top)),
            )))?;
        }
    }
    ch.draw_series(
        h.counts
            .iter()
            .enumerate()
            .filter(|(_, &c)| c > 0)
            .map(|(i, &c)| {
                let x0 = view.place(i as f64 * h.bin_deg);
                Rectangle::new(
                    [(x0, 0.0), (x0 + h.bin_deg, c as f64)],
                    BLUE.mix(0.7).filled(),
                )
            }),
    )?;
    for (k, &x) in stable.iter().enumerate() {
        if !view.shows(x) {
            continue;
        }
        let xp = view.place(x);
        ch.draw_series(DashedLineSeries::new(
            vec![(xp, 0.0), (xp, ymax)],
            6,
            4,
            BLACK.mix(0.6).stroke_width(1),
        ))?;
        ch.draw_series(std::iter::once(Text::new(
            format!("stable state {k}: {}", deg(x)),
            (xp, ymax * (0.88 - 0.07 * (k % 3) as f64)),
            font.color(&BLACK.mix(0.75))
                .pos(Pos::new(HPos::Left, VPos::Top)),
        )))?;
    }
    root.present()?;
    staged.commit()?;
    Ok(())
}
