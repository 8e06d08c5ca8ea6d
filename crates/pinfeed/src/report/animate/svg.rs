//! The SVG document: title, belt to scale, parts, obstacles, marks, clock and legend, animated
//! with SMIL over one shared loop.

use super::keyframes::{part_keys, thin, thin_track};
use super::layout::{decimals_for, finite_or, key, nice_step, num, px, Layout};
use super::model::*;
use crate::engine::PartOutcome;
use crate::report::plot_labels::{text_width, LabelRows};
use crate::report::plot_line::outcome_colour;
use std::fmt::Write;

/// Fill of a part still riding the line.
const RIDING_FILL: &str = "#a9c1db";
const PART_STROKE: &str = "#223344";
/// Pins and fences: a dark slate, apart from every outcome colour (as in `--draw`).
const PIN_FILL: &str = "#283246";
const SENSOR_FILL: &str = "#1f6fd0";

/// Escape text for XML content and attributes.
fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if (c as u32) < 0x20 && c != '\t' && c != '\n' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

fn rgb(c: plotters::style::RGBColor) -> String {
    format!("#{:02x}{:02x}{:02x}", c.0, c.1, c.2)
}

/// A discrete animation of `attr` through `steps` (key time, value), starting at key time 0:
/// value i holds from its key time to the next. Steps that change nothing are dropped; `None`
/// when the value never changes.
fn discrete(lay: &Layout, attr: &str, steps: &[(f64, String)]) -> Option<String> {
    let mut kept: Vec<(f64, &str)> = Vec::new();
    for (u, v) in steps {
        let u = (u * 1e5).round() / 1e5;
        if let Some(last) = kept.last_mut() {
            if last.1 == v.as_str() {
                continue;
            }
            if last.0 >= u {
                // Same instant: the later value wins (unless that undoes the one before).
                last.1 = v.as_str();
                if kept.len() >= 2 && kept[kept.len() - 2].1 == v.as_str() {
                    kept.pop();
                }
                continue;
            }
        }
        kept.push((u.max(0.0), v.as_str()));
    }
    if kept.len() < 2 {
        return None;
    }
    kept[0].0 = 0.0;
    let values: Vec<&str> = kept.iter().map(|k| k.1).collect();
    let times: Vec<String> = kept.iter().map(|k| key(k.0)).collect();
    Some(format!(
        r#"<animate attributeName="{attr}" calcMode="discrete" values="{}" keyTimes="{}" {}/>"#,
        values.join(";"),
        times.join(";"),
        lay.timing()
    ))
}

/// `values` and `keyTimes` of a linear animation over keys `(u, value)` in [0, 1], extended to
/// key times 0 and 1 by holding the end values.
fn linear_lists(points: &[(f64, String)]) -> (String, String) {
    let mut vals: Vec<&str> = Vec::new();
    let mut times: Vec<String> = Vec::new();
    if let Some((u0, v0)) = points.first() {
        if *u0 > 0.0 {
            vals.push(v0);
            times.push("0".into());
        }
    }
    for (u, v) in points {
        vals.push(v);
        times.push(key(*u));
    }
    if let Some((u1, v1)) = points.last() {
        if key(*u1) != "1" {
            vals.push(v1);
            times.push("1".into());
        }
    }
    if let Some(t) = times.first_mut() {
        *t = "0".into();
    }
    (vals.join(";"), times.join(";"))
}

/// Label rows beyond the belt's edges: a row's height (px).
const ROW_PX: f64 = 15.0;
/// Font sizes of obstacle names and of marks (bold).
const NAME_FONT: f64 = 11.0;
const MARK_FONT: f64 = 12.0;

/// Half the belt's width (m), as drawn.
fn half_width(anim: &Animation) -> f64 {
    finite_or(anim.belt_width, 0.1).max(1e-6) / 2.0
}

/// Where each label goes: (above the belt?, row beyond its edge).
struct Rows {
    obstacles: Vec<(bool, usize)>,
    marks: Vec<(bool, usize)>,
    used_above: usize,
    used_below: usize,
}

/// The text of an obstacle's name label.
fn obstacle_label(ob: &AnimObstacle) -> String {
    format!("{}{}", ob.name, if ob.sensor { " (sensor)" } else { "" })
}

/// The keyframes of an obstacle's track with a finite time and position.
fn finite_track(ob: &AnimObstacle) -> Vec<(f64, f64, bool)> {
    ob.track
        .iter()
        .copied()
        .filter(|k| k.0.is_finite() && k.1.is_finite())
        .collect()
}

/// An obstacle's (x of its label, m; above the belt?).
fn obstacle_anchor(ob: &AnimObstacle, lay: &Layout) -> (f64, bool) {
    match ob.shape {
        AnimShape::Fence { p0, p1, .. } => ((p0.x + p1.x) / 2.0, p0.y + p1.y >= 0.0),
        AnimShape::Pin { x, .. } => {
            let track = finite_track(ob);
            let y0 = pin_state(&track, lay.t_start).map_or(0.0, |p| p.0);
            (x, y0 >= 0.0)
        }
    }
}

/// Place every label in a row where nothing shown at the same time overlaps it: entry and exit,
/// the obstacles' names (shown throughout), then the marks in time order (each shown from its
/// time until it has faded), on the side of the belt where its place is.
fn place_labels(anim: &Animation, lay: &Layout, marks: &[&AnimMark]) -> Rows {
    let mut rows = LabelRows::new();
    let always = (0.0, 1.0);
    // A label centred on x (m), `size` px, in the first free row on its side.
    let centred = |rows: &mut LabelRows, x_m: f64, text: &str, size: f64, bold, above, t| {
        let (cx, w) = (lay.x(x_m), text_width(text, size, bold));
        rows.place(above, cx - w / 2.0, cx + w / 2.0, t, 0)
    };
    let length = finite_or(anim.belt_length, 1.0).max(1e-6);
    centred(&mut rows, 0.0, "entry", NAME_FONT, false, true, always);
    centred(&mut rows, length, "exit", NAME_FONT, false, true, always);
    let obstacles = anim
        .obstacles
        .iter()
        .map(|ob| {
            let (x, above) = obstacle_anchor(ob, lay);
            let x = finite_or(x, 0.0);
            (
                above,
                centred(
                    &mut rows,
                    x,
                    &obstacle_label(ob),
                    NAME_FONT,
                    false,
                    above,
                    always,
                ),
            )
        })
        .collect();
    let marks = marks
        .iter()
        .map(|m| {
            let (u0, u2) = mark_span(m, lay);
            let above = m.at.y >= 0.0;
            (
                above,
                centred(&mut rows, m.at.x, &m.text, MARK_FONT, true, above, (u0, u2)),
            )
        })
        .collect();
    Rows {
        obstacles,
        marks,
        used_above: rows.rows(true),
        used_below: rows.rows(false),
    }
}

/// SVG y of the baseline of a label in `row` beyond the belt's upper (`above`) or lower edge.
fn label_y(lay: &Layout, half: f64, (above, row): (bool, usize)) -> f64 {
    if above {
        lay.y(half) - 6.0 - ROW_PX * row as f64
    } else {
        lay.y(-half) + 14.0 + ROW_PX * row as f64
    }
}

/// Key times a mark's label is shown over: from its time until it has faded.
fn mark_span(m: &AnimMark, lay: &Layout) -> (f64, f64) {
    let u0 = lay.u(m.t);
    let u1 = (u0 + MARK_SHOW_S / lay.dur).min(1.0);
    let u2 = (u1 + MARK_FADE_S / lay.dur).min(1.0);
    (u0, u2)
}

/// Render the animation as an SVG document.
pub fn render(anim: &Animation, opts: &AnimateOptions) -> String {
    let dur = duration(anim, opts);
    let mut lay = Layout::new(anim, dur);
    let mut marks: Vec<&AnimMark> = anim
        .marks
        .iter()
        .filter(|m| m.t.is_finite() && m.at.x.is_finite() && m.at.y.is_finite())
        .collect();
    marks.sort_by(|a, b| a.t.total_cmp(&b.t));
    marks.truncate(MAX_MARKS);
    let rows = place_labels(anim, &lay, &marks);
    lay.reserve(
        half_width(anim),
        8.0 + ROW_PX * rows.used_above as f64,
        8.0 + ROW_PX * rows.used_below as f64,
    );
    let speedup = span(anim) / dur;
    let mut s = String::with_capacity(64 * 1024);
    let (w, h) = (lay.width, lay.height);
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{}" viewBox="0 0 {} {}" font-family="sans-serif">"#,
        px(w),
        px(h),
        px(w),
        px(h)
    );
    let _ = writeln!(s, "<title>{}</title>", esc(&anim.title));
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let parts: Vec<&AnimPart> = anim.parts.iter().take(MAX_PARTS).collect();
    let _ = writeln!(
        s,
        r#"<text x="{}" y="26" font-size="18" font-weight="bold">{}</text>"#,
        px(20.0),
        esc(&anim.title)
    );
    let mut sub = format!(
        "{} part{}, simulated {}–{} s shown in {} s (×{} speed), looping; belt {} m/s, to scale",
        parts.len(),
        if parts.len() == 1 { "" } else { "s" },
        num(anim.t_start, 1),
        num(anim.t_end, 1),
        num(dur, 1),
        num(speedup, if speedup < 1.0 { 3 } else { 2 }),
        num(anim.belt_speed, 4)
    );
    if anim.parts.len() > parts.len() {
        let _ = write!(sub, " (first {MAX_PARTS} of {} parts)", anim.parts.len());
    }
    let _ = writeln!(
        s,
        r##"<text x="20" y="46" font-size="13" fill="#444">{}</text>"##,
        esc(&sub)
    );
    belt(&mut s, anim, &lay);
    // Parts under the obstacles (pins sit above the belt), marks on top.
    let outline = outline_points(anim, &lay);
    for p in &parts {
        part(&mut s, p, &outline, &lay, anim.t_end);
    }
    for (ob, &row) in anim.obstacles.iter().zip(&rows.obstacles) {
        obstacle(&mut s, ob, &lay, anim, row);
    }
    for (m, &row) in marks.iter().zip(&rows.marks) {
        mark(&mut s, m, &lay, half_width(anim), row);
    }
    clock(&mut s, anim, &lay);
    legend(&mut s, anim, &parts, &lay);
    s.push_str("</svg>\n");
    s
}

/// The outline as SVG polygon points about the centroid (px, y down).
fn outline_points(anim: &Animation, lay: &Layout) -> String {
    let n = anim.outline.len();
    let step = n.div_ceil(MAX_OUTLINE).max(1);
    anim.outline
        .iter()
        .step_by(step)
        .filter(|v| v.x.is_finite() && v.y.is_finite())
        .map(|v| format!("{},{}", px(v.x * lay.k), px(-v.y * lay.k)))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The belt to scale: surface, edges, entry and exit, moving stripes, and a metre axis.
fn belt(s: &mut String, anim: &Animation, lay: &Layout) {
    let length = finite_or(anim.belt_length, 1.0).max(1e-6);
    let width = finite_or(anim.belt_width, 0.1).max(1e-6);
    let (x0, x1) = (lay.x(0.0), lay.x(length));
    let (y_top, y_bot) = (lay.y(width / 2.0), lay.y(-width / 2.0));
    let _ = writeln!(
        s,
        r#"<defs><clipPath id="belt-clip"><rect x="{}" y="{}" width="{}" height="{}"/></clipPath></defs>"#,
        px(x0),
        px(y_top),
        px(x1 - x0),
        px(y_bot - y_top)
    );
    let _ = writeln!(
        s,
        r##"<g class="belt"><rect x="{}" y="{}" width="{}" height="{}" fill="#ececec"/>"##,
        px(x0),
        px(y_top),
        px(x1 - x0),
        px(y_bot - y_top)
    );
    // Stripes across the belt that ride with it (their own short loop).
    let gap_m = nice_step(width / 2.0);
    let gap_px = gap_m * lay.k;
    let n = ((length / gap_m).ceil() as usize + 2).min(400);
    let speed = finite_or(anim.belt_speed, 0.0);
    let _ = write!(s, r#"<g clip-path="url(#belt-clip)"><g>"#);
    if speed > 0.0 {
        let speedup = lay.span / lay.dur;
        let _ = write!(
            s,
            r#"<animateTransform attributeName="transform" type="translate" from="0,0" to="{},0" dur="{}s" repeatCount="indefinite"/>"#,
            px(gap_px),
            num((gap_m / speed / speedup).clamp(0.01, 3600.0), 4)
        );
    }
    for i in 0..n {
        let x = x0 + (i as f64 - 1.0) * gap_px;
        let _ = write!(
            s,
            r##"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="#d8d8d8" stroke-width="1"/>"##,
            px(x),
            px(y_top),
            px(x),
            px(y_bot)
        );
    }
    s.push_str("</g></g>\n");
    for y in [y_top, y_bot] {
        let _ = writeln!(
            s,
            r##"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="#333" stroke-width="2"/>"##,
            px(x0),
            px(y),
            px(x1),
            px(y)
        );
    }
    for (x, label) in [(x0, "entry"), (x1, "exit")] {
        let _ = writeln!(
            s,
            r##"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="#666" stroke-dasharray="5 4"/><text x="{}" y="{}" font-size="11" fill="#666" text-anchor="middle">{label}</text>"##,
            px(x),
            px(y_top),
            px(x),
            px(y_bot),
            px(x),
            px(label_y(lay, width / 2.0, (true, 0)))
        );
    }
    let _ = writeln!(
        s,
        r##"<text x="{}" y="{}" font-size="11" fill="#666" text-anchor="end">travel →</text>"##,
        px(x1 - 4.0),
        px(y_bot - 4.0)
    );
    s.push_str("</g>\n");
    // Axis along the belt: metres.
    let step = nice_step(length / 8.0);
    let dec = decimals_for(step);
    let ya = lay.below + 4.0;
    let _ = write!(s, r##"<g class="axis" font-size="11" fill="#444">"##);
    let ticks = ((length / step).floor() as usize).min(100);
    for i in 0..=ticks {
        let xm = i as f64 * step;
        let x = lay.x(xm);
        let _ = write!(
            s,
            r##"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="#444"/><text x="{}" y="{}" text-anchor="middle">{}</text>"##,
            px(x),
            px(ya),
            px(x),
            px(ya + 5.0),
            px(x),
            px(ya + 17.0),
            num(xm, dec)
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}">x (m)</text></g>"#,
        px(x1 + 12.0),
        px(ya + 17.0)
    );
}

/// One part: a group that appears at its first pose, translates to its centroid, and an inner
/// group that rotates the outline; the fill turns to the outcome colour when it ends.
fn part(s: &mut String, p: &AnimPart, outline: &str, lay: &Layout, t_end: f64) {
    let keys = part_keys(lay, &p.poses, lay.t_start, t_end);
    if keys.is_empty() {
        let _ = writeln!(
            s,
            r#"<g class="part" data-part="{}" visibility="hidden"></g>"#,
            p.part
        );
        return;
    }
    let keys = thin(&keys, lay.a_px.max(1.0));
    let first = keys[0];
    let last = keys[keys.len() - 1];
    let u_in = lay.u(first.t);
    let u_end = lay.u(last.t);
    let u_gone = u_end + END_HOLD_S / lay.dur;
    let colour = rgb(outcome_colour(p.outcome));
    let _ = writeln!(
        s,
        r#"<g class="part" data-part="{}" data-outcome="{}" visibility="hidden">"#,
        p.part,
        p.outcome.name()
    );
    let mut vis = vec![(0.0, "hidden".to_string()), (u_in, "visible".to_string())];
    if u_gone < 1.0 {
        vis.push((u_gone, "hidden".to_string()));
    }
    match discrete(lay, "visibility", &vis) {
        Some(a) => {
            let _ = writeln!(s, "{a}");
        }
        None => {
            // Visible for the whole loop.
            let _ = writeln!(s, r#"<set attributeName="visibility" to="visible"/>"#);
        }
    }
    let translate: Vec<(f64, String)> = keys
        .iter()
        .map(|k| (lay.u(k.t), format!("{},{}", px(k.x), px(k.y))))
        .collect();
    let rotate: Vec<(f64, String)> = keys.iter().map(|k| (lay.u(k.t), num(k.deg, 2))).collect();
    let (tv, tk) = linear_lists(&translate);
    let (rv, rk) = linear_lists(&rotate);
    let _ = writeln!(
        s,
        r#"<g transform="translate({},{})"><animateTransform attributeName="transform" type="translate" values="{tv}" keyTimes="{tk}" {}/>"#,
        px(first.x),
        px(first.y),
        lay.timing()
    );
    let _ = writeln!(
        s,
        r#"<g transform="rotate({})"><animateTransform attributeName="transform" type="rotate" values="{rv}" keyTimes="{rk}" {}/>"#,
        num(first.deg, 2),
        lay.timing()
    );
    let fill = discrete(
        lay,
        "fill",
        &[(0.0, RIDING_FILL.to_string()), (u_end, colour.clone())],
    )
    .unwrap_or_default();
    let initial = if u_end <= 0.0 { &colour } else { RIDING_FILL };
    let _ = writeln!(
        s,
        r#"<polygon points="{outline}" fill="{initial}" fill-opacity="0.85" stroke="{PART_STROKE}" stroke-width="1" stroke-linejoin="round">{fill}</polygon>"#
    );
    let _ = writeln!(
        s,
        r#"<circle r="1.5" fill="{PART_STROKE}"/></g><text x="{}" y="{}" font-size="10" fill="{PART_STROKE}">{}</text></g></g>"#,
        px(lay.a_px * 0.75 + 2.0),
        px(-lay.a_px * 0.75 - 2.0),
        p.part
    );
}

/// One obstacle: a group holding its drawing (and label); a pin that moves animates `cy`, one
/// that withdraws animates its opacity.
fn obstacle(s: &mut String, ob: &AnimObstacle, lay: &Layout, anim: &Animation, row: (bool, usize)) {
    let name = esc(&ob.name);
    let half = half_width(anim);
    match ob.shape {
        AnimShape::Fence { p0, p1, tail: None } => {
            let _ = writeln!(
                s,
                r#"<g class="obstacle" data-name="{name}" data-kind="fence"><line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{PIN_FILL}" stroke-width="3" stroke-linecap="round"/><text x="{}" y="{}" font-size="11" fill="{PIN_FILL}" text-anchor="middle">{name}</text></g>"#,
                px(lay.x(p0.x)),
                px(lay.y(p0.y)),
                px(lay.x(p1.x)),
                px(lay.y(p1.y)),
                px(lay.x((p0.x + p1.x) / 2.0)),
                px(label_y(lay, half, row)),
            );
        }
        AnimShape::Fence {
            p0,
            p1,
            tail: Some((r, p2, clockwise)),
        } => {
            // The straight part, then the tail's arc (SVG's sweep flag 1 draws the arc the way
            // a clockwise turn in the world runs once the screen's y points down).
            let _ = writeln!(
                s,
                r#"<g class="obstacle" data-name="{name}" data-kind="fence"><path d="M {} {} L {} {} A {} {} 0 0 {} {} {}" fill="none" stroke="{PIN_FILL}" stroke-width="3" stroke-linecap="round"/><text x="{}" y="{}" font-size="11" fill="{PIN_FILL}" text-anchor="middle">{name}</text></g>"#,
                px(lay.x(p0.x)),
                px(lay.y(p0.y)),
                px(lay.x(p1.x)),
                px(lay.y(p1.y)),
                px(r * lay.k),
                px(r * lay.k),
                u8::from(clockwise),
                px(lay.x(p2.x)),
                px(lay.y(p2.y)),
                px(lay.x((p0.x + p1.x) / 2.0)),
                px(label_y(lay, half, row)),
            );
        }
        AnimShape::Pin { x, radius } => {
            let track = finite_track(ob);
            let (t0, t1) = (lay.t_start, lay.t_start + lay.span);
            let (y0, raised0) = pin_state(&track, t0).unwrap_or((0.0, true));
            let moving = track.iter().any(|k| (k.1 - y0).abs() * lay.k > 0.05);
            let fill = if ob.sensor { SENSOR_FILL } else { PIN_FILL };
            let r = (radius.max(0.0) * lay.k).max(3.0);
            let cx = lay.x(x);
            let kind = match (ob.sensor, moving) {
                (true, true) => "moving sensor_pin",
                (true, false) => "sensor_pin",
                (false, true) => "moving_pin",
                (false, false) => "pin",
            };
            let _ = write!(
                s,
                r#"<g class="obstacle" data-name="{name}" data-kind="{kind}">"#
            );
            if moving {
                // The pin's lateral range of travel, faintly.
                let lo = track.iter().map(|k| k.1).fold(f64::INFINITY, f64::min);
                let hi = track.iter().map(|k| k.1).fold(f64::NEG_INFINITY, f64::max);
                let _ = write!(
                    s,
                    r#"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{fill}" stroke-opacity="0.35" stroke-width="{}" stroke-linecap="round"/>"#,
                    px(cx),
                    px(lay.y(hi)),
                    px(cx),
                    px(lay.y(lo)),
                    px(2.0 * r)
                );
            }
            let _ = write!(
                s,
                r#"<circle cx="{}" cy="{}" r="{}" fill="{fill}" stroke="white" stroke-width="1"{}>"#,
                px(cx),
                px(lay.y(y0)),
                px(r),
                if raised0 { "" } else { r#" opacity="0.2""# }
            );
            if moving {
                // Knots inside the shown span, plus the state at both ends.
                let mut pts: Vec<(f64, f64)> = vec![(t0, y0)];
                pts.extend(
                    track
                        .iter()
                        .filter(|k| k.0 > t0 && k.0 < t1)
                        .map(|k| (k.0, k.1)),
                );
                let (y1, _) = pin_state(&track, t1).unwrap_or((y0, true));
                pts.push((t1, y1));
                let pts = thin_track(&pts, lay);
                let points: Vec<(f64, String)> =
                    pts.iter().map(|&(t, y)| (lay.u(t), px(lay.y(y)))).collect();
                let (v, k) = linear_lists(&points);
                let _ = write!(
                    s,
                    r#"<animate attributeName="cy" values="{v}" keyTimes="{k}" {}/>"#,
                    lay.timing()
                );
            }
            let mut steps = vec![(0.0, if raised0 { "1" } else { "0.2" }.to_string())];
            for k in track.iter().filter(|k| k.0 > t0 && k.0 < t1) {
                steps.push((lay.u(k.0), if k.2 { "1" } else { "0.2" }.to_string()));
            }
            if let Some(a) = discrete(lay, "opacity", &steps) {
                s.push_str(&a);
            }
            s.push_str("</circle>");
            // The name beyond the belt's nearer edge, in its row.
            let _ = writeln!(
                s,
                r#"<text x="{}" y="{}" font-size="11" fill="{fill}" text-anchor="middle">{}</text></g>"#,
                px(cx),
                px(label_y(lay, half, row)),
                esc(&obstacle_label(ob))
            );
        }
    }
}

/// A mark: a label (and a ring flashing at the place) shown for [`MARK_SHOW_S`] from its time,
/// the label in its row beyond the belt's edge ([`place_labels`]).
fn mark(s: &mut String, m: &AnimMark, lay: &Layout, half: f64, row: (bool, usize)) {
    let (u0, u2) = mark_span(m, lay);
    let u1 = (u0 + MARK_SHOW_S / lay.dur).min(1.0);
    let (x, y) = (lay.x(m.at.x), lay.y(m.at.y));
    let colour = m.kind.colour();
    let ty = label_y(lay, half, row);
    let opacity = format!(
        r#"<animate attributeName="opacity" values="0;0;1;1;0;0" keyTimes="0;{};{};{};{};1" {}/>"#,
        key(u0),
        key(u0),
        key(u1),
        key(u2),
        lay.timing()
    );
    let ring = format!(
        r#"<animate attributeName="r" values="3;3;{};{}" keyTimes="0;{};{};1" {}/>"#,
        px(lay.a_px.max(6.0)),
        px(lay.a_px.max(6.0)),
        key(u0),
        key(u1),
        lay.timing()
    );
    let _ = writeln!(
        s,
        r#"<g class="mark" data-kind="{}" opacity="0">{opacity}<circle cx="{}" cy="{}" r="3" fill="none" stroke="{colour}" stroke-width="2">{ring}</circle><text x="{}" y="{}" font-size="12" font-weight="bold" fill="{colour}" stroke="white" stroke-width="3" paint-order="stroke" text-anchor="middle">{}</text></g>"#,
        m.kind.name(),
        px(x),
        px(y),
        px(x),
        px(ty),
        esc(&m.text)
    );
}

/// The clock: a progress bar with simulated-time ticks and a readout of simulated time.
fn clock(s: &mut String, anim: &Animation, lay: &Layout) {
    let y = lay.below + 34.0;
    let (x0, x1) = (lay.x(0.0), lay.x(finite_or(anim.belt_length, 1.0)));
    let w = (x1 - x0).max(100.0);
    let _ = writeln!(
        s,
        r##"<g class="clock" font-size="11" fill="#444"><rect x="{}" y="{}" width="{}" height="8" fill="none" stroke="#888"/><rect class="progress" x="{}" y="{}" width="0" height="8" fill="#5a7fa8"><animate attributeName="width" values="0;{}" keyTimes="0;1" {}/></rect>"##,
        px(x0),
        px(y),
        px(w),
        px(x0),
        px(y),
        px(w),
        lay.timing()
    );
    let step = nice_step(lay.span / 8.0);
    let dec = decimals_for(step);
    let first = (anim.t_start / step).ceil() as i64;
    let last = ((anim.t_start + lay.span) / step).floor() as i64;
    for i in first..=last.min(first + 100) {
        let t = i as f64 * step;
        let x = x0 + w * lay.u(t);
        let _ = write!(
            s,
            r##"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="#888"/><text x="{}" y="{}" text-anchor="middle">{}</text>"##,
            px(x),
            px(y + 8.0),
            px(x),
            px(y + 12.0),
            px(x),
            px(y + 23.0),
            num(t, dec)
        );
    }
    // The readout: one label per step of simulated time, each shown during its step.
    let step = nice_step(lay.span / 60.0);
    let dec = decimals_for(step);
    let n = ((lay.span / step).ceil() as usize).clamp(1, 150);
    let _ = write!(
        s,
        r#"<g class="readout" font-size="20" font-weight="bold" font-family="monospace">"#
    );
    for i in 0..n {
        let t = anim.t_start + i as f64 * step;
        let (ua, ub) = (lay.u(t), lay.u(t + step));
        let mut steps = vec![(0.0, "hidden".to_string()), (ua, "visible".to_string())];
        if ub < 1.0 {
            steps.push((ub, "hidden".to_string()));
        }
        let anim_el = discrete(lay, "visibility", &steps).unwrap_or_default();
        let _ = write!(
            s,
            r#"<text x="{}" y="28" text-anchor="end" visibility="{}">t = {} s{anim_el}</text>"#,
            px(lay.width - 24.0),
            if ua <= 0.0 { "visible" } else { "hidden" },
            num(t, dec.max(1)),
        );
    }
    s.push_str("</g>");
    let _ = writeln!(
        s,
        r#"<text x="{}" y="{}" text-anchor="start">simulated time (s)</text></g>"#,
        px(x1 + 8.0),
        px(y + 8.0)
    );
}

/// The legend: outcome colours of the parts shown, obstacle kinds, mark kinds, a scale bar.
fn legend(s: &mut String, anim: &Animation, parts: &[&AnimPart], lay: &Layout) {
    let y = lay.below + 92.0;
    let mut x = 20.0;
    let _ = write!(s, r##"<g class="legend" font-size="12" fill="#222">"##);
    // A swatch drawn at (x, y) and its label after it.
    let item = |s: &mut String, x: &mut f64, swatch: &dyn Fn(f64) -> String, label: &str| {
        s.push_str(&swatch(*x));
        let _ = write!(
            s,
            r#"<text x="{}" y="{}">{}</text>"#,
            px(*x + 18.0),
            px(y + 4.0),
            esc(label)
        );
        *x += 18.0 + 6.8 * label.chars().count() as f64 + 16.0;
    };
    let square = |x: f64, fill: &str| {
        format!(
            r#"<rect x="{}" y="{}" width="12" height="12" fill="{fill}" stroke="{PART_STROKE}"/>"#,
            px(x),
            px(y - 7.0)
        )
    };
    let dot = |x: f64, fill: &str, opacity: f64| {
        format!(
            r#"<circle cx="{}" cy="{}" r="5" fill="{fill}" opacity="{}"/>"#,
            px(x + 6.0),
            px(y - 1.0),
            num(opacity, 2)
        )
    };
    item(s, &mut x, &|x| square(x, RIDING_FILL), "riding");
    for o in PartOutcome::ALL {
        if parts.iter().any(|p| p.outcome == o) {
            item(s, &mut x, &|x| square(x, &rgb(outcome_colour(o))), o.name());
        }
    }
    let pins: Vec<&AnimObstacle> = anim
        .obstacles
        .iter()
        .filter(|o| matches!(o.shape, AnimShape::Pin { .. }))
        .collect();
    if pins.iter().any(|o| !o.sensor) {
        item(s, &mut x, &|x| dot(x, PIN_FILL, 1.0), "pin");
    }
    if pins.iter().any(|o| o.sensor) {
        item(s, &mut x, &|x| dot(x, SENSOR_FILL, 1.0), "sensor pin");
    }
    if pins.iter().any(|o| o.track.iter().any(|k| !k.2)) {
        item(s, &mut x, &|x| dot(x, PIN_FILL, 0.2), "withdrawn");
    }
    if anim
        .obstacles
        .iter()
        .any(|o| matches!(o.shape, AnimShape::Fence { .. }))
    {
        let line = |x: f64| {
            format!(
                r#"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{PIN_FILL}" stroke-width="3"/>"#,
                px(x),
                px(y - 1.0),
                px(x + 12.0),
                px(y - 1.0)
            )
        };
        item(s, &mut x, &line, "fence");
    }
    for k in MarkKind::ALL {
        if anim.marks.iter().any(|m| m.kind == k) {
            let ring = |x: f64| {
                format!(
                    r#"<circle cx="{}" cy="{}" r="5" fill="none" stroke="{}" stroke-width="2"/>"#,
                    px(x + 6.0),
                    px(y - 1.0),
                    k.colour()
                )
            };
            item(s, &mut x, &ring, k.name());
        }
    }
    // Scale bar: a nice length near 1/10 of the belt.
    let bar_m = nice_step(finite_or(anim.belt_length, 1.0) / 10.0);
    let bar_px = bar_m * lay.k;
    let label = if bar_m < 1.0 {
        format!("{} cm", num(bar_m * 100.0, 1))
    } else {
        format!("{} m", num(bar_m, 2))
    };
    let _ = writeln!(
        s,
        r##"<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="#222" stroke-width="3"/><text x="{}" y="{}">{label}</text></g>"##,
        px(x + 10.0),
        px(y - 1.0),
        px(x + 10.0 + bar_px),
        px(y - 1.0),
        px(x + 16.0 + bar_px),
        px(y + 4.0)
    );
}
