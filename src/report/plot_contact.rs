//! SVG of one pin pass (like the thesis's Figure 3-1): the part's successive poses in the belt frame,
//! the pin's path, the pin at the start and end of contact, and the centroid's track.

use crate::cli::contact::Case;
use crate::geometry::{Polygon, Pose, Vec2};
use crate::mechanics::{ContactOutcome, TraceSample};
use plotters::prelude::*;
use std::path::Path;

pub fn plot_contact(
    poly: &Polygon,
    pose0: Pose,
    pin_start: Vec2,
    out: &ContactOutcome,
    trace: &[TraceSample],
    case: &Case,
    path: &Path,
) -> anyhow::Result<()> {
    let a = poly.radius();
    // Poses to draw: the start, ~10 evenly spaced trace samples, and the end.
    let mut poses = vec![pose0];
    if !trace.is_empty() {
        let stride = (trace.len() / 10).max(1);
        poses.extend(trace.iter().step_by(stride).map(|t| t.pose));
    }
    poses.push(out.pose_final);
    let mut pts: Vec<Vec2> = Vec::new();
    for p in &poses {
        pts.extend(poly.vertices().iter().map(|&v| p.apply(v)));
    }
    let pin_end_s = out.travel_to_contact + out.contact_length;
    let pin_end = pin_start + Vec2::new(-1.0, case.pin_speed) * (pin_end_s + a * 0.5);
    pts.push(pin_start);
    pts.push(pin_end);
    let (mut lo, mut hi) = (pts[0], pts[0]);
    for p in &pts {
        lo = Vec2::new(lo.x.min(p.x), lo.y.min(p.y));
        hi = Vec2::new(hi.x.max(p.x), hi.y.max(p.y));
    }
    let pad = 0.15 * a;
    let (w, h) = (hi.x - lo.x + 2.0 * pad, hi.y - lo.y + 2.0 * pad);
    let span = w.max(h);
    let cx = 0.5 * (lo.x + hi.x);
    let cy = 0.5 * (lo.y + hi.y);
    let root = SVGBackend::new(path, (800, 800)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut ch = ChartBuilder::on(&root)
        .caption(
            format!(
                "{} θ0={}° d={} μc={} ({}) → θf={:.2}°",
                case.part,
                case.theta0_deg,
                case.d,
                case.mu_c,
                case.model.name(),
                crate::geometry::wrap_deg(out.pose_final.theta.to_degrees())
            ),
            ("sans-serif", 18),
        )
        .margin(15)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(
            (cx - span / 2.0)..(cx + span / 2.0),
            (cy - span / 2.0)..(cy + span / 2.0),
        )?;
    ch.configure_mesh()
        .x_desc("x (belt frame, part units)")
        .y_desc("y")
        .draw()?;
    let n = poses.len();
    for (i, p) in poses.iter().enumerate() {
        let mut ring: Vec<(f64, f64)> = poly
            .vertices()
            .iter()
            .map(|&v| {
                let q = p.apply(v);
                (q.x, q.y)
            })
            .collect();
        ring.push(ring[0]);
        let t = i as f64 / (n - 1).max(1) as f64;
        let col = RGBColor((30.0 + 200.0 * t) as u8, 60, (220.0 - 180.0 * t) as u8);
        let width = if i == 0 || i == n - 1 { 3 } else { 1 };
        ch.draw_series(LineSeries::new(ring, col.stroke_width(width)))?;
    }
    let track: Vec<(f64, f64)> = poses.iter().map(|p| (p.x, p.y)).collect();
    ch.draw_series(LineSeries::new(track, BLACK.mix(0.5)))?;
    ch.draw_series(LineSeries::new(
        vec![(pin_start.x, pin_start.y), (pin_end.x, pin_end.y)],
        RED.mix(0.5),
    ))?;
    let px = |v: f64| ((v / span) * 700.0).max(3.0) as i32;
    for t in [trace.first(), trace.last()].into_iter().flatten() {
        ch.draw_series(std::iter::once(Circle::new(
            (t.pin_centre.x, t.pin_centre.y),
            px(case.pin_radius),
            RED.filled(),
        )))?;
    }
    root.present()?;
    Ok(())
}
