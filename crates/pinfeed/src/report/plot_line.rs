//! `pinfeed run --draw FILE.svg`: the line seen from above, to scale (equal metres on both axes).
//! One panel per sample part: belt edges, entry and exit, every obstacle, and the part's outline
//! at successive instants along its path — every few part sizes while it rides the belt, and along
//! each push — coloured by the class it ended in. Obstacles are drawn in their own colour (never an
//! outcome's) and named beyond the belt edge on their side.

use crate::engine::{PartOutcome, SamplePath};
use crate::geometry::{wrap_deg, Pose};
use crate::output::Staged;
use crate::report::plot_labels::{text_width, LabelRows};
use crate::report::ReportResult;
use crate::scenario::{Obstacle, Scene};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Pins and fences: a dark slate, apart from every outcome colour; sensor pins blue.
pub const OBSTACLE_COLOUR: RGBColor = RGBColor(40, 50, 70);
/// Sensor pins' colour.
pub const SENSOR_COLOUR: RGBColor = RGBColor(31, 111, 208);
const LABEL_FONT: f64 = 12.0;
const LABEL_ROW_PX: f64 = 15.0;

/// The colour of an outcome class.
pub fn outcome_colour(o: PartOutcome) -> RGBColor {
    match o {
        PartOutcome::Success => RGBColor(30, 150, 60),
        PartOutcome::WrongOrientation => RGBColor(230, 120, 20),
        PartOutcome::Collision => RGBColor(210, 30, 30),
        PartOutcome::MultiContact => RGBColor(140, 50, 170),
        PartOutcome::OffBelt => RGBColor(120, 80, 40),
        PartOutcome::Jam => RGBColor(0, 0, 0),
        PartOutcome::Solver => RGBColor(120, 120, 120),
        PartOutcome::Rejected => RGBColor(60, 110, 200),
    }
}

/// Pick up to `n` sample paths: the first part of each outcome class, then the earliest others.
pub fn choose_samples(paths: &[SamplePath], n: usize) -> Vec<&SamplePath> {
    let mut chosen: Vec<&SamplePath> = Vec::new();
    for o in PartOutcome::ALL {
        if chosen.len() >= n {
            break;
        }
        if let Some(p) = paths
            .iter()
            .filter(|p| p.outcome == o)
            .min_by_key(|p| p.part)
        {
            chosen.push(p);
        }
    }
    let mut rest: Vec<&SamplePath> = paths.iter().collect();
    rest.sort_by_key(|p| p.part);
    for p in rest {
        if chosen.len() >= n {
            break;
        }
        if !chosen.iter().any(|c| c.part == p.part) {
            chosen.push(p);
        }
    }
    chosen.sort_by_key(|p| p.part);
    chosen
}

/// Poses to draw along a path: recorded poses at least `gap` apart (centroid) or 20° apart, with
/// free rides filled in every `gap`.
fn display_poses(path: &SamplePath, gap: f64) -> Vec<Pose> {
    let mut out: Vec<Pose> = Vec::new();
    let push = |p: Pose, out: &mut Vec<Pose>| {
        if let Some(l) = out.last() {
            let moved = ((p.x - l.x).powi(2) + (p.y - l.y).powi(2)).sqrt();
            if moved < gap && (p.theta_rad - l.theta_rad).abs() < 20f64.to_radians() {
                return;
            }
        }
        out.push(p);
    };
    for w in path.poses.windows(2) {
        let (p, q) = (w[0].1, w[1].1);
        let d = ((q.x - p.x).powi(2) + (q.y - p.y).powi(2)).sqrt();
        let steps = (d / gap).floor() as usize;
        push(p, &mut out);
        for k in 1..=steps {
            let u = k as f64 / (steps + 1) as f64;
            push(
                Pose::new(
                    p.x + u * (q.x - p.x),
                    p.y + u * (q.y - p.y),
                    p.theta_rad + u * (q.theta_rad - p.theta_rad),
                ),
                &mut out,
            );
        }
    }
    if let Some(&(_, last)) = path.poses.last() {
        out.push(last);
    }
    out
}

/// The chart of one panel: metres on both axes.
type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// An obstacle's label: text, x (m), beyond the upper belt edge or the lower, row, colour.
type Label = (String, f64, bool, usize, RGBColor);

/// Every obstacle named in a row beyond the belt edge on its side, no two overlapping; with the
/// rows they take (x0: the plot's left edge in metres).
fn obstacle_labels(scene: &Scene, x0: f64, px_per_m: f64) -> (Vec<Label>, LabelRows) {
    let mut rows = LabelRows::new();
    let labels: Vec<Label> = scene
        .obstacles
        .iter()
        .map(|ob| {
            let (text, x, y, colour) = match ob {
                Obstacle::Pin(p) if p.sensor.is_some() => (
                    format!("{} (sensor)", p.name),
                    p.centre.x,
                    p.centre.y,
                    SENSOR_COLOUR,
                ),
                Obstacle::Pin(p) => (p.name.clone(), p.centre.x, p.centre.y, OBSTACLE_COLOUR),
                Obstacle::Fence(f) => {
                    let m = (f.start + f.end()) * 0.5;
                    (f.name.clone(), m.x, m.y, OBSTACLE_COLOUR)
                }
            };
            let cx = (x - x0) * px_per_m;
            let w = text_width(&text, LABEL_FONT, false);
            let above = y >= 0.0;
            let row = rows.place(above, cx - w / 2.0, cx + w / 2.0, (0.0, 1.0), 0);
            (text, x, above, row, colour)
        })
        .collect();
    (labels, rows)
}

/// A panel's caption: the sample part, its outcome and its first and last orientation.
fn caption(scene: &Scene, sample: Option<&&SamplePath>) -> String {
    match sample {
        Some(s) => {
            let first = s.poses.first().map(|p| p.1.theta_rad).unwrap_or(0.0);
            let last = s.poses.last().map(|p| p.1.theta_rad).unwrap_or(0.0);
            format!(
                "{} — part {}: {} (θ {:.1}° → {:.1}°)",
                scene.name,
                s.part,
                s.outcome.name(),
                wrap_deg(first.to_degrees()),
                wrap_deg(last.to_degrees())
            )
        }
        None => format!("{} — no sample part", scene.name),
    }
}

/// Draw the line itself into a panel: belt edges, entry and exit, the obstacles and their labels.
fn draw_line(ch: &mut Chart, scene: &Scene, labels: &[Label], px_per_m: f64) -> ReportResult<()> {
    let belt = scene.belt;
    // Belt edges, entry and exit.
    for y in [-belt.width / 2.0, belt.width / 2.0] {
        ch.draw_series(LineSeries::new(
            vec![(0.0, y), (belt.length, y)],
            BLACK.stroke_width(2),
        ))?;
    }
    for x in [0.0, belt.length] {
        ch.draw_series(DashedLineSeries::new(
            vec![(x, -belt.width / 2.0), (x, belt.width / 2.0)],
            5,
            4,
            BLACK.mix(0.5).stroke_width(1),
        ))?;
    }
    for ob in &scene.obstacles {
        match ob {
            Obstacle::Pin(pin) => {
                let r = ((pin.radius * px_per_m).round() as i32).max(2);
                let fill = if pin.sensor.is_some() {
                    SENSOR_COLOUR
                } else {
                    OBSTACLE_COLOUR
                };
                ch.draw_series(std::iter::once(Circle::new(
                    (pin.centre.x, pin.centre.y),
                    r,
                    fill.filled(),
                )))?;
            }
            Obstacle::Fence(fence) => {
                // The straight part and its tail (if any) as a polyline of 48 arc pieces.
                let pts = fence.spec().polyline(48);
                ch.draw_series(LineSeries::new(
                    pts.iter().map(|p| (p.x, p.y)),
                    OBSTACLE_COLOUR.stroke_width(3),
                ))?;
            }
        }
    }
    for (text, x, above, row, colour) in labels {
        let gap = (6.0 + LABEL_ROW_PX * *row as f64) / px_per_m;
        let (y, v) = if *above {
            (belt.width / 2.0 + gap, VPos::Bottom)
        } else {
            (-belt.width / 2.0 - gap + 2.0 / px_per_m, VPos::Top)
        };
        ch.draw_series(std::iter::once(Text::new(
            text.clone(),
            (*x, y),
            ("sans-serif", LABEL_FONT)
                .into_font()
                .color(colour)
                .pos(Pos::new(HPos::Center, v)),
        )))?;
    }
    Ok(())
}

/// Draw a sample part into a panel: its outline at the display poses and its centroid's track,
/// in its outcome's colour.
fn draw_sample(ch: &mut Chart, scene: &Scene, sample: &SamplePath) -> ReportResult<()> {
    let a = scene.part.radius;
    let colour = outcome_colour(sample.outcome);
    let poses = display_poses(sample, 2.5 * a);
    let m = poses.len();
    for (i, p) in poses.iter().enumerate() {
        let mut ring: Vec<(f64, f64)> = scene
            .part
            .polygon
            .world_vertices(p)
            .iter()
            .map(|v| (v.x, v.y))
            .collect();
        ring.push(ring[0]);
        let strength = if i == 0 || i + 1 == m { 1.0 } else { 0.55 };
        ch.draw_series(LineSeries::new(ring, colour.mix(strength).stroke_width(1)))?;
    }
    let track: Vec<(f64, f64)> = sample.poses.iter().map(|(_, p)| (p.x, p.y)).collect();
    ch.draw_series(LineSeries::new(track, colour.mix(0.35)))?;
    Ok(())
}

/// Draw the sample paths over the line.
pub fn plot_line(scene: &Scene, samples: &[&SamplePath], path: &Path) -> ReportResult<()> {
    let belt = scene.belt;
    let a = scene.part.radius;
    let margin = 2.0 * a;
    let (x0, x1) = (-margin, belt.length + margin);
    let plot_w = 1500.0;
    let px_per_m = plot_w / (x1 - x0);
    // Every obstacle named in a row beyond the belt edge on its side, no two overlapping.
    let (labels, rows) = obstacle_labels(scene, x0, px_per_m);
    let room = |above: bool| (10.0 + LABEL_ROW_PX * rows.rows(above) as f64) / px_per_m;
    let (y0, y1) = (
        -belt.width / 2.0 - margin.max(room(false)),
        belt.width / 2.0 + margin.max(room(true)),
    );
    let plot_h = ((y1 - y0) * px_per_m).max(40.0);
    let (left, bottom, top) = (60u32, 35u32, 30u32);
    let panel_h = plot_h as u32 + bottom + top + 10;
    let n = samples.len().max(1);
    let width = plot_w as u32 + left + 20;
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (width, panel_h * n as u32)).into_drawing_area();
    root.fill(&WHITE)?;
    let panels = root.split_evenly((n, 1));
    for (k, panel) in panels.iter().enumerate() {
        let sample = samples.get(k);
        let mut ch = ChartBuilder::on(panel)
            .caption(caption(scene, sample), ("sans-serif", 16))
            .margin(5)
            .x_label_area_size(bottom)
            .y_label_area_size(left)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        ch.configure_mesh()
            .disable_mesh()
            .x_desc("x along the belt (m)")
            .y_desc("y (m)")
            .y_label_formatter(&|v| crate::report::fixed(*v, 2, false))
            .draw()?;
        draw_line(&mut ch, scene, &labels, px_per_m)?;
        let Some(sample) = sample else { continue };
        draw_sample(&mut ch, scene, sample)?;
    }
    root.present()?;
    staged.commit()?;
    Ok(())
}
