//! `pinfeed plan` drawing (SVG): the planned line from above, to scale in millimetres on both
//! axes (a fence is drawn at its true angle; pins at their true radius), each pin with the
//! interval of positions that act the same way, belt edges, entry and exit, and the part at its
//! goal orientation past the exit; every label in a row above or below the belt where no other
//! label overlaps it (`plot_labels`). Below it, the orientation sets after each obstacle —
//! one row per stage (feed, pin1, fence2, …), a dot per particle orientation sized by its weight,
//! the goal window shaded — as in the thesis's ch. 4 figures.

use super::plot_labels::{text_width, LabelRows};
use crate::geometry::{Pose, Vec2};
use crate::output::Staged;
use crate::plan::{Action, Plan, Problem, State};
use crate::report::ReportResult;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

fn stage_dots(state: &State, q_deg: f64) -> Vec<(f64, u32)> {
    let mut h: Vec<(i32, u32)> = state
        .particles
        .iter()
        .map(|p| (p.theta_q, p.weight))
        .collect();
    h.sort_unstable();
    let mut out: Vec<(f64, u32)> = Vec::new();
    for (t, w) in h {
        let x = t as f64 * q_deg;
        match out.last_mut() {
            Some(l) if l.0 == x => l.1 += w,
            _ => out.push((x, w)),
        }
    }
    out
}

type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Page width (px); the belt view's margins and label areas (px).
const PAGE_W: u32 = 1000;
const MARGIN: u32 = 15;
const Y_LABELS: u32 = 60;
const X_LABELS: u32 = 35;
/// Label rows: height (px) and font size.
const ROW_PX: f64 = 15.0;
const FONT: f64 = 12.0;

/// A label of the belt view: its text and colour, the x (mm) it is centred on, above the belt or
/// below.
struct Label {
    text: String,
    colour: RGBColor,
    x_mm: f64,
    above: bool,
}

/// The belt view to scale: x over `x_range` mm, the belt ±`half` mm, the obstacles in view, and
/// the labels in rows beyond the belt's edges.
struct BeltView {
    x_range: (f64, f64),
    y_range: (f64, f64),
    /// px per mm on both axes.
    k: f64,
    half: f64,
    length: f64,
    /// (label, row) after placement.
    placed: Vec<(Label, usize)>,
}

impl BeltView {
    fn new(length: f64, half: f64, exit_room: f64, ys: &[f64], labels: Vec<Label>) -> BeltView {
        let x_range = (-0.04 * length, length + exit_room);
        let plot_w = (PAGE_W - 2 * MARGIN - Y_LABELS) as f64;
        let k = plot_w / (x_range.1 - x_range.0);
        let mut rows = LabelRows::new();
        let mut placed = Vec::new();
        for mut l in labels {
            // Centred on its x, kept inside the plot.
            let w = text_width(&l.text, FONT, false);
            let cx = ((l.x_mm - x_range.0) * k).clamp(w / 2.0, (plot_w - w / 2.0).max(w / 2.0));
            l.x_mm = x_range.0 + cx / k;
            let row = rows.place(l.above, cx - w / 2.0, cx + w / 2.0, (0.0, 1.0), 0);
            placed.push((l, row));
        }
        // Room (mm) beyond each belt edge: the label rows, the obstacles, a little air.
        let air = 6.0 / k;
        let need_above = (8.0 + ROW_PX * rows.rows(true) as f64) / k;
        let need_below = (8.0 + ROW_PX * rows.rows(false) as f64) / k;
        let top = ys.iter().copied().fold(half, f64::max) + air;
        let bottom = ys.iter().copied().fold(-half, f64::min) - air;
        let y_range = (bottom.min(-half - need_below), top.max(half + need_above));
        BeltView {
            x_range,
            y_range,
            k,
            half,
            length,
            placed,
        }
    }

    /// Height (px) of the view with its axes.
    fn height(&self) -> u32 {
        ((self.y_range.1 - self.y_range.0) * self.k).round() as u32 + 2 * MARGIN + X_LABELS
    }

    /// The chart: belt, entry, exit, axes; then the labels (after the caller drew the obstacles).
    fn chart<'a, 'b>(
        &self,
        area: &'a DrawingArea<SVGBackend<'b>, Shift>,
    ) -> ReportResult<Chart<'a, 'b>> {
        let mut ch = ChartBuilder::on(area)
            .margin(MARGIN)
            .x_label_area_size(X_LABELS)
            .y_label_area_size(Y_LABELS)
            .build_cartesian_2d(
                self.x_range.0..self.x_range.1,
                self.y_range.0..self.y_range.1,
            )?;
        ch.configure_mesh()
            .disable_mesh()
            .x_desc("x along the belt (mm; both axes to one scale)")
            .y_desc("y (mm)")
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.0}"))
            .draw()?;
        let (h, l) = (self.half, self.length);
        ch.draw_series(std::iter::once(Rectangle::new(
            [(0.0, -h), (l, h)],
            RGBColor(236, 236, 236).filled(),
        )))?;
        for y in [-h, h] {
            ch.draw_series(LineSeries::new(
                vec![(0.0, y), (l, y)],
                BLACK.stroke_width(2),
            ))?;
        }
        for x in [0.0, l] {
            ch.draw_series(DashedLineSeries::new(
                vec![(x, -h), (x, h)],
                5,
                4,
                BLACK.mix(0.5).stroke_width(1),
            ))?;
        }
        Ok(ch)
    }

    /// Draw the labels in their rows.
    fn labels(&self, ch: &mut Chart<'_, '_>) -> ReportResult<()> {
        for (l, row) in &self.placed {
            let (y, v) = if l.above {
                (
                    self.half + (6.0 + ROW_PX * *row as f64) / self.k,
                    VPos::Bottom,
                )
            } else {
                (
                    -self.half - (4.0 + ROW_PX * *row as f64) / self.k,
                    VPos::Top,
                )
            };
            ch.draw_series(std::iter::once(Text::new(
                l.text.clone(),
                (l.x_mm, y),
                ("sans-serif", FONT)
                    .into_font()
                    .color(&l.colour)
                    .pos(Pos::new(HPos::Center, v)),
            )))?;
        }
        Ok(())
    }

    /// A pin's radius in px (at least 2).
    fn pin_px(&self, radius_mm: f64) -> i32 {
        ((radius_mm * self.k).round() as i32).max(2)
    }
}

/// The label of the goal silhouette past the exit, centred on `cx` (mm).
fn exit_label(centre_deg: f64, tol_deg: f64, cx: f64) -> Label {
    Label {
        text: format!("exit: goal {centre_deg:.2}° ± {tol_deg}°"),
        colour: RGBColor(20, 110, 40),
        x_mm: cx,
        above: false,
    }
}

/// Pins, fences, labels: one dark colour, not the outcome colours of a run.
const OBSTACLE: RGBColor = RGBColor(40, 50, 70);

/// A fixed pin at belt position `x` (mm): its interval of equivalent positions shaded, the pin.
fn draw_pin(
    ch: &mut Chart<'_, '_>,
    view: &BeltView,
    x: f64,
    p: &crate::plan::PinAction,
    pin_px: i32,
) -> ReportResult<()> {
    let w = 3.0 / view.k;
    ch.draw_series(std::iter::once(Rectangle::new(
        [(x - w, p.lo_m * 1e3), (x + w, p.hi_m * 1e3)],
        BLUE.mix(0.2).filled(),
    )))?;
    ch.draw_series(std::iter::once(Circle::new(
        (x, p.y_m * 1e3),
        pin_px,
        OBSTACLE.filled(),
    )))?;
    Ok(())
}

/// A title strip: the title and, below it, optional coloured notes side by side.
fn head(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    notes: &[(String, RGBColor)],
) -> ReportResult<()> {
    area.draw(&Text::new(
        title.to_string(),
        ((PAGE_W / 2) as i32, 8),
        ("sans-serif", 16)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Top)),
    ))?;
    let mut x = (MARGIN + Y_LABELS) as f64;
    for (text, colour) in notes {
        area.draw(&Text::new(
            text.clone(),
            (x as i32, 32),
            ("sans-serif", FONT).into_font().color(colour),
        ))?;
        x += text_width(text, FONT, false) + 18.0;
    }
    Ok(())
}

/// The orientation sets: one row per stage (`label(k)` names row k), θ over the part's period,
/// the goal window (centre ± tol, repeated over the period) shaded.
#[allow(clippy::too_many_arguments)]
fn sets_view<'a, 'b>(
    area: &'a DrawingArea<SVGBackend<'b>, Shift>,
    period: f64,
    symmetry: u32,
    rows: usize,
    y_desc: &str,
    label: &dyn Fn(usize) -> String,
    centre: f64,
    tol: f64,
) -> ReportResult<Chart<'a, 'b>> {
    let mut ch = ChartBuilder::on(area)
        .margin(MARGIN)
        .x_label_area_size(X_LABELS)
        .y_label_area_size(Y_LABELS + 15)
        .build_cartesian_2d(0.0..period, -0.5..(rows as f64 - 0.5))?;
    ch.configure_mesh()
        .x_desc(if symmetry > 1 {
            format!("orientation θ modulo the {period}° symmetry (degrees)")
        } else {
            "orientation θ (degrees)".to_string()
        })
        .y_desc(y_desc)
        .x_labels(13)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_labels(rows.min(20))
        .y_label_formatter(&|v| label(v.round().max(0.0) as usize))
        .draw()?;
    for shift in [-period, 0.0, period] {
        let (a, b) = (
            (centre - tol + shift).max(0.0),
            (centre + tol + shift).min(period),
        );
        if a < b {
            ch.draw_series(std::iter::once(Rectangle::new(
                [(a, -0.5), (b, rows as f64 - 0.5)],
                GREEN.mix(0.15).filled(),
            )))?;
        }
    }
    Ok(ch)
}

/// The part at orientation `theta_deg` centred at (`cx`, 0) mm, true shape.
fn draw_part(
    ch: &mut Chart<'_, '_>,
    polygon: &crate::geometry::Polygon,
    theta_deg: f64,
    cx: f64,
) -> ReportResult<()> {
    let pose = Pose::new(0.0, 0.0, theta_deg.to_radians());
    let verts: Vec<Vec2> = polygon.world_vertices(&pose);
    let outline: Vec<(f64, f64)> = verts.iter().map(|v| (cx + v.x * 1e3, v.y * 1e3)).collect();
    ch.draw_series(std::iter::once(Polygon::new(
        outline,
        RGBColor(30, 150, 60).mix(0.5).filled(),
    )))?;
    Ok(())
}

/// Draw a plan to `path` under `title` (the design's verdict: its line check beside the
/// prediction).
pub fn plot_plan(problem: &Problem, plan: &Plan, title: &str, path: &Path) -> ReportResult<()> {
    let compiled = problem.compile()?;
    let period = compiled.period_deg();
    let stages = plan.steps.len() + 1;
    let (xs_layout, length) = crate::plan::emit::layout(problem, plan, compiled.radius);
    let (length, half) = (length * 1e3, problem.belt_width_m / 2.0 * 1e3);
    let radius = compiled.radius * 1e3;
    let exit_room = 3.0 * radius + 10.0;
    let cx = length + 1.5 * radius + 5.0;
    let (mut pins, mut fences) = (0, 0);
    let mut labels = Vec::new();
    let mut names = vec!["feed".to_string()];
    let mut ys = Vec::new();
    for (k, s) in plan.steps.iter().enumerate() {
        let x = xs_layout[k] * 1e3;
        match s.action {
            Action::Pin(p) => {
                pins += 1;
                names.push(format!("pin{pins}"));
                ys.extend([p.lo_m * 1e3, p.hi_m * 1e3]);
                labels.push(Label {
                    text: format!(
                        "pin{pins} y={:+.2} mm ±{:.2}",
                        p.y_m * 1e3,
                        p.margin_m * 1e3
                    ),
                    colour: OBSTACLE,
                    x_mm: x,
                    above: p.y_m >= 0.0,
                });
            }
            Action::Fence(f) => {
                fences += 1;
                names.push(format!("fence{fences}"));
                ys.extend([f.y0_m * 1e3, f.y1_m * 1e3, f.far_y_m() * 1e3]);
                labels.push(Label {
                    text: format!(
                        "fence{fences} {:+}° ±{:.2} mm",
                        f.angle_deg,
                        f.margin_m * 1e3
                    ),
                    colour: OBSTACLE,
                    x_mm: x + f.x_extent_m() * 1e3 / 2.0,
                    above: f.y0_m + f.y1_m >= 0.0,
                });
            }
        }
    }
    labels.push(exit_label(
        plan.window.centre_deg,
        problem.tolerance_deg,
        cx,
    ));
    let view = BeltView::new(length, half, exit_room, &ys, labels);
    let head_h = 34;
    let top_h = view.height();
    let height = head_h + top_h + 40 * stages as u32 + 80;
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (PAGE_W, height)).into_drawing_area();
    root.fill(&WHITE)?;
    let (strip, rest) = root.split_vertically(head_h);
    let (top, bottom) = rest.split_vertically(top_h);
    head(&strip, title, &[])?;
    let mut ch = view.chart(&top)?;
    let pin_px = view.pin_px(problem.pin_radius_m * 1e3);
    for (k, s) in plan.steps.iter().enumerate() {
        let x = xs_layout[k] * 1e3;
        match s.action {
            Action::Pin(p) => draw_pin(&mut ch, &view, x, &p, pin_px)?,
            Action::Fence(f) => {
                let spec = crate::mechanics::FenceSpec {
                    start: crate::geometry::Vec2::new(x * 1e-3, f.y0_m),
                    angle_rad: f.angle_deg.to_radians(),
                    length: f.length_m,
                    mu_f: f.mu_f,
                    tail_radius: f.tail_radius_m,
                };
                let path: Vec<(f64, f64)> = spec
                    .polyline(24)
                    .iter()
                    .map(|p| (p.x * 1e3, p.y * 1e3))
                    .collect();
                ch.draw_series(std::iter::once(PathElement::new(
                    path,
                    OBSTACLE.stroke_width(3),
                )))?;
            }
        }
    }
    // The part at its goal orientation past the exit (true shape, to scale).
    draw_part(&mut ch, &compiled.polygon, plan.window.centre_deg, cx)?;
    view.labels(&mut ch)?;
    // Orientation sets after each stage.
    let label = |k: usize| names.get(k).cloned().unwrap_or_default();
    let mut ch = sets_view(
        &bottom,
        period,
        compiled.symmetry,
        stages,
        "after",
        &label,
        plan.window.centre_deg,
        problem.tolerance_deg,
    )?;
    let states: Vec<&State> = std::iter::once(&plan.initial)
        .chain(plan.steps.iter().map(|s| &s.state))
        .collect();
    let total = plan.initial.total().max(1) as f64;
    for (k, s) in states.iter().enumerate() {
        let dots = stage_dots(s, problem.theta_quantum_deg);
        ch.draw_series(dots.into_iter().map(|(x, w)| {
            let r = (2.0 + 10.0 * (w as f64 / total).sqrt()) as i32;
            Circle::new((x, k as f64), r, BLUE.mix(0.6).filled())
        }))?;
    }
    root.present()?;
    staged.commit()?;
    Ok(())
}

/// Colours of the decision branches (dark enough for text on white).
fn branch_colour(b: usize) -> RGBColor {
    const C: [RGBColor; 6] = [
        RGBColor(200, 30, 60),
        RGBColor(30, 140, 60),
        RGBColor(30, 90, 200),
        RGBColor(200, 110, 0),
        RGBColor(130, 50, 170),
        RGBColor(0, 140, 150),
    ];
    C[b % C.len()]
}

/// Draw a contingent plan (`pinfeed plan --sensor`) to `path`: the line from above (the sensor
/// pin, then each moving pin's target per decision in the branch's colour, joined by the pin's
/// travel) and, below, the orientation sets of every branch at the feed, after the sensor and
/// after each moving pin, in the same colours, the goal window shaded. `stages[b]` are branch b's
/// states ([`crate::plan::contingent::stage_states`]).
pub fn plot_contingent(
    problem: &Problem,
    plan: &crate::plan::contingent::ContingentPlan,
    stages: &[Vec<State>],
    title: &str,
    path: &Path,
) -> ReportResult<()> {
    let compiled = problem.compile()?;
    let period = compiled.period_deg();
    let k = plan.k;
    let rows = k + 2;
    let sp = problem.spacing_m * 1e3;
    let length = sp * (k as f64 + 2.0);
    let half = problem.belt_width_m / 2.0 * 1e3;
    let radius = compiled.radius * 1e3;
    let exit_room = 3.0 * radius + 10.0;
    let cx = length + 1.5 * radius + 5.0;
    let s = plan.sensor;
    let mut labels = vec![Label {
        text: format!("sensor y={:+.2} mm ±{:.2}", s.y_m * 1e3, s.margin_m * 1e3),
        colour: OBSTACLE,
        x_mm: sp,
        above: s.y_m >= 0.0,
    }];
    let mut ys = vec![s.lo_m * 1e3, s.hi_m * 1e3];
    let targets: Vec<Vec<f64>> = (0..k)
        .map(|j| plan.branches.iter().map(|b| b.targets_m[j] * 1e3).collect())
        .collect();
    for (j, t) in targets.iter().enumerate() {
        ys.extend(t.iter().copied());
        let top = t.iter().copied().fold(f64::MIN, f64::max);
        labels.push(Label {
            text: format!("mover{}", j + 1),
            colour: OBSTACLE,
            x_mm: sp * (j as f64 + 2.0),
            above: top >= 0.0,
        });
    }
    labels.push(exit_label(plan.centre_deg, problem.tolerance_deg, cx));
    let view = BeltView::new(length, half, exit_room, &ys, labels);
    let head_h = 50;
    let top_h = view.height();
    let height = head_h + top_h + 40 * rows as u32 + 80;
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (PAGE_W, height)).into_drawing_area();
    root.fill(&WHITE)?;
    let (strip, rest) = root.split_vertically(head_h);
    let (top, bottom) = rest.split_vertically(top_h);
    let notes: Vec<(String, RGBColor)> = plan
        .branches
        .iter()
        .enumerate()
        .map(|(b, br)| {
            (
                format!("decides {}: {} of {} inside", br.label, br.inside, br.total),
                branch_colour(b),
            )
        })
        .collect();
    head(&strip, title, &notes)?;
    let mut ch = view.chart(&top)?;
    let pin_px = view.pin_px(problem.pin_radius_m * 1e3).max(3);
    draw_pin(&mut ch, &view, sp, &s, pin_px)?;
    for (j, ys) in targets.iter().enumerate() {
        let x = sp * (j as f64 + 2.0);
        let (lo, hi) = ys
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &y| (a.min(y), b.max(y)));
        ch.draw_series(std::iter::once(PathElement::new(
            vec![(x, lo), (x, hi)],
            BLACK.mix(0.4).stroke_width(2),
        )))?;
        for (b, y) in ys.iter().enumerate() {
            // A parked pin (the branch needs fewer moving pins) is drawn hollow.
            let parked = j >= plan.branches[b].pins.len();
            let style = if parked {
                branch_colour(b).stroke_width(2)
            } else {
                branch_colour(b).filled()
            };
            ch.draw_series(std::iter::once(Circle::new((x, *y), pin_px, style)))?;
        }
    }
    draw_part(&mut ch, &compiled.polygon, plan.centre_deg, cx)?;
    view.labels(&mut ch)?;
    let label = |j: usize| match j {
        0 => "feed".to_string(),
        1 => "sensor".to_string(),
        j => format!("mover{}", j - 1),
    };
    let mut ch = sets_view(
        &bottom,
        period,
        compiled.symmetry,
        rows,
        "after",
        &label,
        plan.centre_deg,
        problem.tolerance_deg,
    )?;
    let total: u32 = plan.branches.iter().map(|b| b.total).sum();
    let nb = stages.len().max(1) as f64;
    for (b, branch) in stages.iter().enumerate() {
        let dy = 0.3 * (b as f64 - (nb - 1.0) / 2.0) / nb;
        for (r, st) in branch.iter().enumerate() {
            let dots = stage_dots(st, problem.theta_quantum_deg);
            ch.draw_series(dots.into_iter().map(|(x, w)| {
                let rad = (2.0 + 10.0 * (w as f64 / total.max(1) as f64).sqrt()) as i32;
                Circle::new(
                    (x.rem_euclid(period), r as f64 + dy),
                    rad,
                    branch_colour(b).mix(0.7).filled(),
                )
            }))?;
        }
    }
    root.present()?;
    staged.commit()?;
    Ok(())
}
