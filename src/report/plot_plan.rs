//! `pinfeed plan` drawing (SVG): the planned line from above (pins at their positions, each with
//! the interval of positions that act the same way, belt edges, the part at its goal orientation at
//! the exit) and, below it, the orientation sets after each pin — one row per stage (feed, pin 1,
//! …), a dot per particle orientation sized by its weight, the goal window shaded — as in the
//! thesis's ch. 4 figures.

use crate::geometry::{Pose, Vec2};
use crate::plan::{Action, Plan, Problem, State};
use crate::report::atomic::Staged;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
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

/// A fixed pin at belt position `x`: its interval of equivalent positions shaded, the pin, a label.
fn draw_pin(
    ch: &mut Chart<'_, '_>,
    x: f64,
    p: &crate::plan::PinAction,
    pin_px: i32,
    label: String,
) -> anyhow::Result<()> {
    ch.draw_series(std::iter::once(Rectangle::new(
        [(x - 0.004, p.lo_m * 1e3), (x + 0.004, p.hi_m * 1e3)],
        BLUE.mix(0.2).filled(),
    )))?;
    ch.draw_series(std::iter::once(Circle::new(
        (x, p.y_m * 1e3),
        pin_px,
        BLACK.filled(),
    )))?;
    ch.draw_series(std::iter::once(Text::new(
        label,
        (x + 0.006, p.y_m * 1e3 + 2.0),
        ("sans-serif", 12),
    )))?;
    Ok(())
}

/// The line from above: x along the belt (m) over `length`, y (mm) over ±`half`.
fn belt_view<'a, 'b>(
    area: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    caption: String,
    length: f64,
    half: f64,
) -> anyhow::Result<Chart<'a, 'b>> {
    let mut ch = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(35)
        .y_label_area_size(55)
        .build_cartesian_2d(0.0..length, -half..half)?;
    ch.configure_mesh()
        .x_desc("x along the belt (m)")
        .y_desc("y (mm)")
        .draw()?;
    Ok(ch)
}

/// The orientation sets: one row per stage (`label(k)` names row k), θ over the part's period,
/// the goal window (centre ± tol, repeated over the period) shaded.
#[allow(clippy::too_many_arguments)]
fn sets_view<'a, 'b>(
    area: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    period: f64,
    symmetry: u32,
    rows: usize,
    y_desc: &str,
    label: &dyn Fn(usize) -> String,
    centre: f64,
    tol: f64,
) -> anyhow::Result<Chart<'a, 'b>> {
    let mut ch = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(35)
        .y_label_area_size(75)
        .build_cartesian_2d(0.0..period, -0.5..(rows as f64 - 0.5))?;
    ch.configure_mesh()
        .x_desc(if symmetry > 1 {
            format!("orientation θ modulo the {period}° symmetry (degrees)")
        } else {
            "orientation θ (degrees)".to_string()
        })
        .y_desc(y_desc)
        .x_labels(13)
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

/// Draw a plan to `path` under `title` (the design's verdict: its line check beside the
/// prediction).
pub fn plot_plan(problem: &Problem, plan: &Plan, title: &str, path: &Path) -> anyhow::Result<()> {
    let compiled = problem.compile()?;
    let period = compiled.period_deg();
    let stages = plan.steps.len() + 1;
    let (xs_layout, length) = crate::plan::emit::layout(problem, plan, compiled.radius);
    let half = problem.belt_width_m / 2.0 * 1e3;
    let height = 330 + 40 * stages as u32 + 80;
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (1000, height)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, bottom) = root.split_vertically(330);
    let mut ch = belt_view(&top, title.to_string(), length, half)?;
    // Pixels per metre along each axis, to draw true shapes on stretched axes.
    let (w_px, h_px) = ch.plotting_area().dim_in_pixel();
    let px_per_m_x = w_px as f64 / length;
    let px_per_m_y = h_px as f64 / (2.0 * half * 1e-3);
    let pin_px = ((problem.pin_radius_m * px_per_m_y).round() as i32).max(2);
    for (k, s) in plan.steps.iter().enumerate() {
        let p = match s.action {
            Action::Pin(p) => p,
            Action::Fence(f) => {
                let x0 = xs_layout[k];
                let x1 = x0 + f.x_extent_m();
                ch.draw_series(std::iter::once(PathElement::new(
                    vec![(x0, f.y0_m * 1e3), (x1, f.y1_m * 1e3)],
                    BLACK.stroke_width(3),
                )))?;
                ch.draw_series(std::iter::once(Text::new(
                    format!(
                        "fence{} {:+}° ±{:.2} mm",
                        k + 1,
                        f.angle_deg,
                        f.margin_m * 1e3
                    ),
                    (x0, f.y0_m * 1e3 + 2.0),
                    ("sans-serif", 12),
                )))?;
                continue;
            }
        };
        let x = xs_layout[k];
        let label = format!(
            "pin{} y={:+.2} mm ±{:.2}",
            k + 1,
            p.y_m * 1e3,
            p.margin_m * 1e3
        );
        draw_pin(&mut ch, x, &p, pin_px, label)?;
    }
    // The part at its goal orientation near the exit (true shape, x stretched like the axes).
    let pose = Pose::new(0.0, 0.0, plan.window.centre_deg.to_radians());
    let verts: Vec<Vec2> = compiled.polygon.world_vertices(&pose);
    let xs = px_per_m_y / px_per_m_x;
    let cx = length - compiled.radius * xs - 0.01;
    let outline: Vec<(f64, f64)> = verts.iter().map(|v| (cx + v.x * xs, v.y * 1e3)).collect();
    ch.draw_series(std::iter::once(Polygon::new(
        outline,
        RGBColor(30, 150, 60).mix(0.5).filled(),
    )))?;
    // Orientation sets after each stage.
    let label = |k: usize| {
        if k == 0 {
            "feed".to_string()
        } else {
            format!("{k}")
        }
    };
    let mut ch = sets_view(
        &bottom,
        period,
        compiled.symmetry,
        stages,
        "after obstacle",
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
) -> anyhow::Result<()> {
    let compiled = problem.compile()?;
    let period = compiled.period_deg();
    let k = plan.k;
    let rows = k + 2;
    let length = problem.spacing_m * (k as f64 + 2.0);
    let half = problem.belt_width_m / 2.0 * 1e3;
    let height = 330 + 40 * rows as u32 + 80;
    let staged = Staged::new(path);
    let tmp = staged.tmp().to_path_buf();
    let root = SVGBackend::new(&tmp, (1000, height)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, bottom) = root.split_vertically(330);
    let mut ch = belt_view(&top, title.to_string(), length, half)?;
    let (_, h_px) = ch.plotting_area().dim_in_pixel();
    let pin_px = ((problem.pin_radius_m * h_px as f64 / (2.0 * half * 1e-3)).round() as i32).max(3);
    let s = plan.sensor;
    let xs = problem.spacing_m;
    let label = format!("sensor y={:+.2} mm ±{:.2}", s.y_m * 1e3, s.margin_m * 1e3);
    draw_pin(&mut ch, xs, &s, pin_px, label)?;
    for j in 0..k {
        let x = problem.spacing_m * (j as f64 + 2.0);
        let ys: Vec<f64> = plan.branches.iter().map(|b| b.targets_m[j] * 1e3).collect();
        let (lo, hi) = ys
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &y| (a.min(y), b.max(y)));
        ch.draw_series(std::iter::once(PathElement::new(
            vec![(x, lo), (x, hi)],
            BLACK.mix(0.4).stroke_width(2),
        )))?;
        ch.draw_series(std::iter::once(Text::new(
            format!("mover{}", j + 1),
            (x + 0.006, hi + 3.0),
            ("sans-serif", 12),
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
    for (b, br) in plan.branches.iter().enumerate() {
        ch.draw_series(std::iter::once(Text::new(
            format!("decides {}: {} of {} inside", br.label, br.inside, br.total),
            (0.005, half - 5.0 - 5.0 * b as f64),
            ("sans-serif", 12).into_font().color(&branch_colour(b)),
        )))?;
    }
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
