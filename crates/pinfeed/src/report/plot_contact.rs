//! SVG of one pass (like the thesis's Figure 3-1): the part's successive poses in the belt frame,
//! the centroid's track, and the obstacle: for a pin its path and the pin at the start and end of
//! contact; for a fence the fence segment at the start and end of contact (it travels along −x in
//! the belt frame, as every fixed obstacle does).

use crate::contact_case::{case_fence, case_geometry, Case};
use crate::geometry::{Polygon, Pose, Vec2};
use crate::mechanics::{ContactOutcome, TraceSample};
use crate::output::Staged;
use crate::report::ReportResult;
use plotters::prelude::*;
use std::path::Path;

/// The obstacle of a pass as drawn (belt frame at the start of the pass, part units).
#[derive(Debug, Clone, PartialEq)]
pub enum PassObstacle {
    /// A pin of radius `radius` whose centre starts at `start` and moves (−1, `lateral_speed`) per
    /// unit travel.
    Pin {
        /// The centre's start (part units).
        start: Vec2,
        /// The pin's radius (part units).
        radius: f64,
        /// Lateral motion per unit of travel (fraction of the belt speed).
        lateral_speed: f64,
    },
    /// A fence segment from `start` to `end`, and on through `tail` (points along its curved
    /// tail, if it has one).
    Fence {
        /// The segment's start (part units).
        start: Vec2,
        /// The segment's end (part units).
        end: Vec2,
        /// Points along the fence's tail after `end` (part units; empty without a tail).
        tail: Vec<Vec2>,
    },
}

/// Stroke colour of the fence segments (the pin is red).
pub const FENCE_COLOUR: RGBColor = RGBColor(20, 130, 60);

/// Draw the pass of `poly` from `pose0` against `obstacle` (its outcome `out` and recorded `trace`)
/// into the SVG file `path`; `title` heads the plot (the final orientation is appended).
pub fn plot_contact(
    poly: &Polygon,
    pose0: Pose,
    obstacle: &PassObstacle,
    out: &ContactOutcome,
    trace: &[TraceSample],
    title: &str,
    path: &Path,
) -> ReportResult<()> {
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
    if let PassObstacle::Pin {
        start,
        lateral_speed,
        ..
    } = *obstacle
    {
        pts.push(start);
        pts.push(start + Vec2::new(-1.0, lateral_speed) * (pin_end_s + a * 0.5));
    }
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
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (800, 800)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut ch = ChartBuilder::on(&root)
        .caption(
            format!(
                "{title} → θf={:.2}°",
                crate::geometry::wrap_deg(out.pose_final.theta_rad.to_degrees())
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
    match *obstacle {
        PassObstacle::Pin {
            start,
            radius,
            lateral_speed,
        } => {
            let end = start + Vec2::new(-1.0, lateral_speed) * (pin_end_s + a * 0.5);
            ch.draw_series(LineSeries::new(
                vec![(start.x, start.y), (end.x, end.y)],
                RED.mix(0.5),
            ))?;
            let px = |v: f64| ((v / span) * 700.0).max(3.0) as i32;
            for t in [trace.first(), trace.last()].into_iter().flatten() {
                ch.draw_series(std::iter::once(Circle::new(
                    (t.pin_centre.x, t.pin_centre.y),
                    px(radius),
                    RED.filled(),
                )))?;
            }
        }
        PassObstacle::Fence {
            start,
            end,
            ref tail,
        } => {
            // The fence where the contact begins (thick) and where it ends, inside the view.
            let view = (
                Vec2::new(cx - span / 2.0, cy - span / 2.0),
                Vec2::new(cx + span / 2.0, cy + span / 2.0),
            );
            let pts: Vec<Vec2> = [start, end]
                .into_iter()
                .chain(tail.iter().copied())
                .collect();
            for (s, width) in [(out.travel_to_contact, 3), (pin_end_s, 1)] {
                let shift = Vec2::new(-s, 0.0);
                for w in pts.windows(2) {
                    if let Some((p, q)) = clip_segment(w[0] + shift, w[1] + shift, view) {
                        ch.draw_series(LineSeries::new(
                            vec![(p.x, p.y), (q.x, q.y)],
                            FENCE_COLOUR.stroke_width(width),
                        ))?;
                    }
                }
            }
        }
    }
    root.present()?;
    staged.commit()?;
    Ok(())
}

/// The part of segment p → q inside the axis-aligned box (lo, hi), if any (Liang–Barsky).
fn clip_segment(p: Vec2, q: Vec2, (lo, hi): (Vec2, Vec2)) -> Option<(Vec2, Vec2)> {
    let d = q - p;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (dp, num) in [
        (-d.x, p.x - lo.x),
        (d.x, hi.x - p.x),
        (-d.y, p.y - lo.y),
        (d.y, hi.y - p.y),
    ] {
        if dp == 0.0 {
            if num < 0.0 {
                return None;
            }
        } else {
            let t = num / dp;
            if dp < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    // An end inside the box stays exactly where it was.
    let at = |t: f64| {
        if t <= 0.0 {
            p
        } else if t >= 1.0 {
            q
        } else {
            p + d * t
        }
    };
    (t0 <= t1).then(|| (at(t0), at(t1)))
}

/// Draw the pass of contact case `c` (`pinfeed contact --plot`) over `poly` (its outcome `out` and `trace`) into the SVG file `path`.
pub fn plot_case(
    c: &Case,
    poly: &Polygon,
    out: &ContactOutcome,
    trace: &[TraceSample],
    path: &Path,
) -> ReportResult<()> {
    let (pose, obstacle) = pass_obstacle(poly, c);
    plot_contact(poly, pose, &obstacle, out, trace, &plot_title(c), path)
}

/// The initial pose of a case and its obstacle as the plot draws it: the pin (start, radius,
/// lateral speed) or the fence segment.
fn pass_obstacle(poly: &Polygon, c: &Case) -> (Pose, PassObstacle) {
    let (pose, start) = case_geometry(poly, c);
    let obstacle = match c.fence {
        Some((angle, length)) => {
            let fence = case_fence(poly, c, angle, length);
            let mut pts = fence.polyline(48);
            let tail = if fence.tail_arc().is_some() {
                pts.drain(..2);
                pts
            } else {
                Vec::new()
            };
            PassObstacle::Fence {
                start: fence.start,
                end: fence.straight_end(),
                tail,
            }
        }
        None => PassObstacle::Pin {
            start,
            radius: c.pin_radius,
            lateral_speed: c.pin_speed,
        },
    };
    (pose, obstacle)
}

/// The plot's title: the part, θ0, d, the friction and the model (and the fence's angle).
fn plot_title(c: &Case) -> String {
    match c.fence {
        Some((angle, _)) => format!(
            "{} θ0={}° d={} fence α={}° μf={} ({})",
            c.part,
            c.theta0_deg,
            c.d,
            angle,
            c.mu_c,
            c.model.name()
        ),
        None => format!(
            "{} θ0={}° d={} μc={} ({})",
            c.part,
            c.theta0_deg,
            c.d,
            c.mu_c,
            c.model.name()
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clip_keeps_the_inside_and_drops_the_outside() {
        let view = (Vec2::new(0.0, 0.0), Vec2::new(1.0, 1.0));
        let (p, q) = clip_segment(Vec2::new(-1.0, 0.5), Vec2::new(2.0, 0.5), view).unwrap();
        assert!((p.x - 0.0).abs() < 1e-12 && (q.x - 1.0).abs() < 1e-12);
        assert_eq!(p.y, 0.5);
        assert!(clip_segment(Vec2::new(-1.0, 2.0), Vec2::new(2.0, 2.0), view).is_none());
        let inside = (Vec2::new(0.2, 0.3), Vec2::new(0.7, 0.9));
        assert_eq!(clip_segment(inside.0, inside.1, view), Some(inside));
    }
}
