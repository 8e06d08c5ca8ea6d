//! SVG figure of a part: its outline in the part frame (with centroid, hull and the circle of radius
//! `a`) beside its radius function ρ(φ) with the stable states marked.

use crate::geometry::{Polygon, Vec2};
use crate::output::Staged;
use crate::report::ReportResult;
use plotters::prelude::*;
use std::path::Path;

/// Draw the part and its radius function into an SVG file.
pub fn plot_part(poly: &Polygon, title: &str, path: &Path) -> ReportResult<()> {
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (1000, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let (left, right) = root.split_horizontally(460);
    // The legend gets its own strip under the outline, so it never covers the part.
    let (outline, legend) = left.split_vertically(460);
    let a = poly.radius() * 1.15;
    let mut ch = ChartBuilder::on(&outline)
        .caption(format!("{title}: outline (part frame)"), ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(30)
        .y_label_area_size(40)
        .build_cartesian_2d(-a..a, -a..a)?;
    ch.configure_mesh().disable_mesh().draw()?;
    let circle: Vec<(f64, f64)> = (0..=180)
        .map(|k| {
            let p = Vec2::from_angle(k as f64 * std::f64::consts::TAU / 180.0) * poly.radius();
            (p.x, p.y)
        })
        .collect();
    let grey = RGBColor(190, 190, 190);
    ch.draw_series(LineSeries::new(circle, grey))?;
    let mut hull: Vec<(f64, f64)> = poly.hull().iter().map(|p| (p.x, p.y)).collect();
    hull.push(hull[0]);
    ch.draw_series(LineSeries::new(hull, BLUE.mix(0.4)))?;
    let pts: Vec<(f64, f64)> = poly.vertices().iter().map(|p| (p.x, p.y)).collect();
    ch.draw_series(std::iter::once(plotters::element::Polygon::new(
        pts.clone(),
        BLUE.mix(0.15),
    )))?;
    let mut ring = pts;
    ring.push(ring[0]);
    ch.draw_series(LineSeries::new(ring, BLACK.stroke_width(2)))?;
    ch.draw_series(std::iter::once(Circle::new((0.0, 0.0), 4, RED.filled())))?;
    let font = ("sans-serif", 14).into_font();
    let mut x = 52;
    for (label, colour, dot) in [
        ("radius a", grey.to_rgba(), false),
        ("convex hull", BLUE.mix(0.4), false),
        ("part", BLACK.to_rgba(), false),
        ("centroid", RED.to_rgba(), true),
    ] {
        if dot {
            legend.draw(&Circle::new((x + 8, 18), 4, colour.filled()))?;
        } else {
            legend.draw(&PathElement::new(
                vec![(x, 18), (x + 16, 18)],
                colour.stroke_width(2),
            ))?;
        }
        legend.draw(&Text::new(label, (x + 22, 11), font.clone()))?;
        x += 30 + 8 * label.len() as i32;
    }

    let samples: Vec<(f64, f64)> = (0..=720)
        .map(|k| {
            let deg = k as f64 * 0.5;
            (deg, poly.radius_function(deg.to_radians()))
        })
        .collect();
    let rmax = samples.iter().map(|s| s.1).fold(0.0, f64::max) * 1.1;
    let mut ch2 = ChartBuilder::on(&right)
        .caption(
            "radius function ρ(φ) (stable states: minima, marked at φ = −90° − θ)",
            ("sans-serif", 16),
        )
        .margin(12)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(0.0..360.0, 0.0..rmax)?;
    ch2.configure_mesh()
        .x_desc("direction φ (deg)")
        .y_desc("ρ")
        .draw()?;
    ch2.draw_series(LineSeries::new(samples, BLACK))?;
    for s in poly.stable_states() {
        let phi = crate::geometry::wrap_deg(-90.0 - s.theta_rad.to_degrees());
        ch2.draw_series(std::iter::once(Circle::new(
            (phi, s.height),
            5,
            RED.filled(),
        )))?;
        ch2.draw_series(std::iter::once(Text::new(
            format!("θ={:.1}°", s.theta_rad.to_degrees()),
            (phi, s.height - rmax * 0.06),
            ("sans-serif", 13).into_font().color(&RED),
        )))?;
    }
    root.present()?;
    staged.commit()?;
    Ok(())
}
