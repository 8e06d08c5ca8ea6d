//! `pinfeed run --animate FILE.svg`: the line seen from above as an animated SVG (SMIL
//! `<animate>`, `<animateTransform>`; browsers such as Chromium play it), to scale with equal
//! metres on both axes (world frame of docs/physics.md#frames: x along travel, y to the left, drawn upwards).
//!
//! The renderer works over plain data, [`Animation`]: the belt, the part's outline in its own
//! frame, the obstacles (a pin's lateral position and raised/withdrawn state as knots in time, so
//! moving and retractable pins need nothing new here), the sample parts' world poses in time, and
//! timed marks (sensor readings, controller decisions, actuations, late commands). [`from_run`]
//! fills it from what a run records today; a controller can fill `track` and `marks` later.
//!
//! Time: simulated time [t_start, t_end] plays in `dur = (t_end − t_start) / speedup` seconds and
//! loops. Every animation runs over the whole loop (`dur`, `repeatCount="indefinite"`) with
//! `keyTimes` u = (t − t_start)/(t_end − t_start) ∈ [0, 1], so all of them restart together.
//! Between recorded poses a part moves linearly (exact for a free ride; a push is recorded at the
//! contact model's steps) and rotates about its centroid: the outer group translates to the
//! centroid, an inner group rotates by −θ (the SVG y axis points down, so a counter-clockwise
//! world turn is a clockwise SVG one). Poses are thinned (Douglas–Peucker in time, keeping the
//! drawing within [`POSE_TOLERANCE_PX`] of the recorded motion) to at most [`MAX_KEYS`] keyframes
//! per part, and numbers are written with limited precision, so a dozen parts stay well under
//! 1 MB. A part is drawn neutral while it rides, takes its outcome colour
//! ([`super::plot_line::outcome_colour`]) when it ends, and stays there [`END_HOLD_S`] before it
//! goes.

use super::plot_line::outcome_colour;
use crate::engine::controller::ControlRecord;
use crate::engine::{PartOutcome, RunResult};
use crate::geometry::{wrap_pi, Pose, Vec2};
use crate::scenario::{Actuator, Obstacle, PinObstacle, Scene};
use std::fmt::Write;

/// Everything the animation shows (plain data; world frame, metres, seconds, radians).
#[derive(Debug, Clone, PartialEq)]
pub struct Animation {
    pub title: String,
    /// m.
    pub belt_length: f64,
    /// m.
    pub belt_width: f64,
    /// m/s.
    pub belt_speed: f64,
    /// The part's outline in its own frame (metres, centroid at the origin).
    pub outline: Vec<Vec2>,
    pub obstacles: Vec<AnimObstacle>,
    pub parts: Vec<AnimPart>,
    pub marks: Vec<AnimMark>,
    /// Simulated time shown: [t_start, t_end] seconds.
    pub t_start: f64,
    pub t_end: f64,
}

/// The shape of an obstacle (world frame, m).
#[derive(Debug, Clone, PartialEq)]
pub enum AnimShape {
    /// A pin at `x` along the belt; its lateral position is the obstacle's `track`.
    Pin { x: f64, radius: f64 },
    /// A fence from `p0` to `p1`.
    Fence { p0: Vec2, p1: Vec2 },
}

/// An obstacle and, for a pin, its lateral motion and raised state in time.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimObstacle {
    pub name: String,
    pub shape: AnimShape,
    /// Does it carry a sensor?
    pub sensor: bool,
    /// Knots (time s, pin centre y in metres, raised?) — linear in y between knots; a still pin
    /// has one knot; ignored for fences. The raised state holds from its knot to the next.
    pub track: Vec<(f64, f64, bool)>,
}

/// A sample part: its outcome and its world poses (time s, pose), in time order.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimPart {
    pub part: u64,
    pub outcome: PartOutcome,
    pub poses: Vec<(f64, Pose)>,
}

/// What a mark reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MarkKind {
    /// A sensor reads a part.
    Reading,
    /// A classifier or controller decides.
    Decision,
    /// An actuator moves (a pin starts to move, rises or withdraws).
    Actuation,
    /// A command that could not finish before the part arrived.
    Late,
}

impl MarkKind {
    pub const ALL: [MarkKind; 4] = [
        MarkKind::Reading,
        MarkKind::Decision,
        MarkKind::Actuation,
        MarkKind::Late,
    ];
    /// Lower-case name (the legend's and the SVG class's).
    pub fn name(self) -> &'static str {
        match self {
            MarkKind::Reading => "reading",
            MarkKind::Decision => "decision",
            MarkKind::Actuation => "actuation",
            MarkKind::Late => "late",
        }
    }
    /// The colour its label and flash are drawn in.
    pub fn colour(self) -> &'static str {
        match self {
            MarkKind::Reading => "#1f6fd0",
            MarkKind::Decision => "#7b2cbf",
            MarkKind::Actuation => "#d07000",
            MarkKind::Late => "#d01010",
        }
    }
    /// Which text line (away from the point) its label takes, so that kinds at one place at one
    /// time do not overprint.
    fn line(self) -> usize {
        match self {
            MarkKind::Reading => 0,
            MarkKind::Decision => 1,
            MarkKind::Actuation => 2,
            MarkKind::Late => 3,
        }
    }
}

/// A short timed label (with a flash) at a place: a reading, a decision, an actuation.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimMark {
    /// Simulated time (s).
    pub t: f64,
    /// Where (world, m), usually the pin.
    pub at: Vec2,
    pub kind: MarkKind,
    pub text: String,
}

/// How to play the animation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AnimateOptions {
    /// Simulated seconds per animation second; default: [`default_speedup`].
    pub speedup: Option<f64>,
}

/// At most this many parts are drawn (the first ones); a larger `parts` list is cut.
pub const MAX_PARTS: usize = 50;
/// At most this many keyframes per part (and per pin track).
pub const MAX_KEYS: usize = 300;
/// At most this many marks are drawn (the earliest).
pub const MAX_MARKS: usize = 1000;
/// At most this many outline vertices are drawn (a longer outline is sampled evenly).
pub const MAX_OUTLINE: usize = 400;
/// Thinned keyframes keep the drawn part within this distance (px) of the recorded motion.
pub const POSE_TOLERANCE_PX: f64 = 0.3;
/// A part stays, in its outcome colour, this long (animation seconds) after it ends.
pub const END_HOLD_S: f64 = 1.5;
/// A mark's label shows this long (animation seconds), then fades over [`MARK_FADE_S`].
pub const MARK_SHOW_S: f64 = 1.8;
pub const MARK_FADE_S: f64 = 0.5;
/// The loop lasts at least / at most this long (animation seconds), whatever the speed-up.
pub const MIN_DURATION_S: f64 = 0.5;
pub const MAX_DURATION_S: f64 = 3600.0;

/// Fill of a part still riding the line.
const RIDING_FILL: &str = "#a9c1db";
const PART_STROKE: &str = "#223344";
const PIN_FILL: &str = "#b01818";
const SENSOR_FILL: &str = "#1f6fd0";

/// Simulated seconds shown, at least a millisecond.
fn span(anim: &Animation) -> f64 {
    let s = anim.t_end - anim.t_start;
    if s.is_finite() && s > 1e-3 {
        s
    } else {
        1e-3
    }
}

/// The default speed-up: real time when the simulated span lasts 20–40 s, else whatever brings
/// the loop to 20 s (short spans, slowed down) or 40 s (long spans, sped up).
pub fn default_speedup(anim: &Animation) -> f64 {
    let s = span(anim);
    s / s.clamp(20.0, 40.0)
}

/// Length of one loop (animation seconds) with these options, within
/// [[`MIN_DURATION_S`], [`MAX_DURATION_S`]].
pub fn duration(anim: &Animation, opts: &AnimateOptions) -> f64 {
    let speedup = opts
        .speedup
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or_else(|| default_speedup(anim));
    (span(anim) / speedup).clamp(MIN_DURATION_S, MAX_DURATION_S)
}

/// A number with at most `decimals` decimals, trailing zeros (and "-0") dropped.
fn num(x: f64, decimals: usize) -> String {
    if !x.is_finite() {
        return "0".into();
    }
    let mut s = format!("{x:.decimals$}");
    if s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if s.ends_with('.') {
            s.pop();
        }
    }
    if s == "-0" {
        s = "0".into();
    }
    s
}

/// A pixel coordinate (2 decimals).
fn px(x: f64) -> String {
    num(x, 2)
}

/// A key time (5 decimals: 0.3 ms of a 30 s loop).
fn key(u: f64) -> String {
    num(u.clamp(0.0, 1.0), 5)
}

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

/// A "nice" step (1, 2 or 5 × 10ⁿ) near `x`.
fn nice_step(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return 1.0;
    }
    let e = 10f64.powf(x.log10().floor());
    let f = x / e;
    let m = if f < 1.5 {
        1.0
    } else if f < 3.5 {
        2.0
    } else if f < 7.5 {
        5.0
    } else {
        10.0
    };
    m * e
}

/// Decimals needed to print multiples of `step`.
fn decimals_for(step: f64) -> usize {
    (-(step.log10().floor())).clamp(0.0, 6.0) as usize
}

/// The world → SVG mapping and the page layout.
struct Layout {
    /// px per metre (both axes).
    k: f64,
    /// SVG x of world x = 0.
    ox: f64,
    /// SVG y of world y = 0.
    oy: f64,
    width: f64,
    height: f64,
    /// SVG y just below the drawing (axis, progress bar, legend follow).
    below: f64,
    /// Largest centroid-to-vertex distance of the outline, px.
    a_px: f64,
    /// Loop length, s.
    dur: f64,
    t_start: f64,
    span: f64,
}

impl Layout {
    fn new(anim: &Animation, dur: f64) -> Layout {
        let length = finite_or(anim.belt_length, 1.0).max(1e-6);
        let width = finite_or(anim.belt_width, 0.1).max(1e-6);
        let a = anim
            .outline
            .iter()
            .map(|v| v.x.hypot(v.y))
            .filter(|r| r.is_finite())
            .fold(0.0, f64::max)
            .min(length);
        // Room for a part at the entry and exit and beside the belt (marks' labels, parts
        // falling off).
        let margin = (1.2 * a).max(0.02 * length);
        let (mut y_lo, mut y_hi) = (-width / 2.0 - margin, width / 2.0 + margin);
        for ob in &anim.obstacles {
            if let AnimShape::Fence { p0, p1 } = ob.shape {
                for y in [p0.y, p1.y] {
                    if y.is_finite() {
                        y_lo = y_lo.min(y - margin);
                        y_hi = y_hi.max(y + margin);
                    }
                }
            }
            for &(_, y, _) in &ob.track {
                if y.is_finite() {
                    y_lo = y_lo.min(y - margin);
                    y_hi = y_hi.max(y + margin);
                }
            }
        }
        y_lo = y_lo.max(-width * 5.0 - margin);
        y_hi = y_hi.min(width * 5.0 + margin);
        let x_range = length + 2.0 * margin;
        let k = (1230.0 / x_range).min(560.0 / (y_hi - y_lo));
        let left = 30.0;
        let top = 64.0;
        let draw_w = x_range * k;
        // Room on the right for the axes' names.
        let page_w = (draw_w + 2.0 * left + 110.0).max(1000.0);
        let ox = left + margin * k;
        let oy = top + y_hi * k;
        let below = top + (y_hi - y_lo) * k;
        Layout {
            k,
            ox,
            oy,
            width: page_w,
            height: below + 112.0,
            below,
            a_px: a * k,
            dur,
            t_start: anim.t_start,
            span: span(anim),
        }
    }
    fn x(&self, x: f64) -> f64 {
        self.ox + x * self.k
    }
    fn y(&self, y: f64) -> f64 {
        self.oy - y * self.k
    }
    /// Key time of simulated time `t`, in [0, 1].
    fn u(&self, t: f64) -> f64 {
        ((t - self.t_start) / self.span).clamp(0.0, 1.0)
    }
    /// The attributes every animation shares.
    fn timing(&self) -> String {
        format!(r#"dur="{}s" repeatCount="indefinite""#, num(self.dur, 3))
    }
}

fn finite_or(x: f64, d: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        d
    }
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

/// One keyframe of a part: key time and the SVG pose (px, px, degrees).
#[derive(Debug, Clone, Copy)]
struct Key {
    t: f64,
    x: f64,
    y: f64,
    deg: f64,
}

fn lerp_key(a: &Key, b: &Key, t: f64) -> Key {
    let w = if b.t > a.t {
        ((t - a.t) / (b.t - a.t)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    Key {
        t,
        x: a.x + w * (b.x - a.x),
        y: a.y + w * (b.y - a.y),
        deg: a.deg + w * (b.deg - a.deg),
    }
}

/// The part's keyframes in SVG terms: θ unwrapped (consecutive turns within ±180°), clipped to
/// [t0, t1]; non-finite poses are skipped.
fn part_keys(lay: &Layout, poses: &[(f64, Pose)], t0: f64, t1: f64) -> Vec<Key> {
    let mut keys: Vec<Key> = Vec::new();
    let mut prev_theta: Option<(f64, f64)> = None; // (raw, unwrapped)
    for &(t, p) in poses {
        if !(t.is_finite() && p.x.is_finite() && p.y.is_finite() && p.theta.is_finite()) {
            continue;
        }
        let theta = match prev_theta {
            Some((raw, unwrapped)) => unwrapped + wrap_pi(p.theta - raw),
            None => p.theta,
        };
        prev_theta = Some((p.theta, theta));
        // Keep times in order (a recorded path is; guard against a bad one).
        let t = keys.last().map_or(t, |k| t.max(k.t));
        keys.push(Key {
            t,
            x: lay.x(p.x),
            y: lay.y(p.y),
            deg: -theta.to_degrees(),
        });
    }
    clip_keys(keys, t0, t1)
}

/// Keep the keys within [t0, t1], interpolating new ends where the path crosses them.
fn clip_keys(keys: Vec<Key>, t0: f64, t1: f64) -> Vec<Key> {
    if keys.is_empty() || keys[keys.len() - 1].t < t0 || keys[0].t > t1 {
        return Vec::new();
    }
    let mut out = Vec::with_capacity(keys.len());
    for i in 0..keys.len() {
        let k = keys[i];
        if k.t < t0 {
            if let Some(n) = keys.get(i + 1) {
                if n.t > t0 {
                    out.push(lerp_key(&k, n, t0));
                }
            }
            continue;
        }
        if k.t > t1 {
            if i > 0 && keys[i - 1].t < t1 {
                out.push(lerp_key(&keys[i - 1], &k, t1));
            }
            break;
        }
        out.push(k);
    }
    out
}

/// Greatest drawing error (px) of replacing keys a..=b by the straight interpolation a → b.
fn worst(keys: &[Key], a: usize, b: usize, arm_px: f64) -> (f64, usize) {
    let mut worst = (0.0, a);
    for (i, k) in keys.iter().enumerate().take(b).skip(a + 1) {
        let m = lerp_key(&keys[a], &keys[b], k.t);
        let e = (m.x - k.x)
            .abs()
            .max((m.y - k.y).abs())
            .max((m.deg - k.deg).abs().to_radians() * arm_px);
        if e > worst.0 {
            worst = (e, i);
        }
    }
    worst
}

/// Douglas–Peucker in time: the fewest keys whose linear interpolation stays within `tol` px
/// (position, and rotation measured at the outline's radius `arm_px`) of every recorded key.
fn simplify(keys: &[Key], tol: f64, arm_px: f64) -> Vec<Key> {
    if keys.len() <= 2 {
        return keys.to_vec();
    }
    let mut keep = vec![false; keys.len()];
    keep[0] = true;
    keep[keys.len() - 1] = true;
    let mut stack = vec![(0, keys.len() - 1)];
    while let Some((a, b)) = stack.pop() {
        if b <= a + 1 {
            continue;
        }
        let (e, i) = worst(keys, a, b, arm_px);
        if e > tol {
            keep[i] = true;
            stack.push((a, i));
            stack.push((i, b));
        }
    }
    keys.iter()
        .zip(keep)
        .filter(|(_, k)| *k)
        .map(|(k, _)| *k)
        .collect()
}

/// Thin keys to at most [`MAX_KEYS`], loosening the tolerance as needed.
fn thin(keys: &[Key], arm_px: f64) -> Vec<Key> {
    let mut tol = POSE_TOLERANCE_PX;
    loop {
        let out = simplify(keys, tol, arm_px);
        if out.len() <= MAX_KEYS || tol > 1e6 {
            if out.len() <= MAX_KEYS {
                return out;
            }
            // Degenerate input: sample evenly.
            let n = out.len();
            return (0..MAX_KEYS)
                .map(|i| out[i * (n - 1) / (MAX_KEYS - 1)])
                .collect();
        }
        tol *= 2.0;
    }
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

/// Render the animation as an SVG document.
pub fn render(anim: &Animation, opts: &AnimateOptions) -> String {
    let dur = duration(anim, opts);
    let lay = Layout::new(anim, dur);
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
    for ob in &anim.obstacles {
        obstacle(&mut s, ob, &lay, anim);
    }
    let mut marks: Vec<&AnimMark> = anim
        .marks
        .iter()
        .filter(|m| m.t.is_finite() && m.at.x.is_finite() && m.at.y.is_finite())
        .collect();
    marks.sort_by(|a, b| a.t.total_cmp(&b.t));
    for m in marks.iter().take(MAX_MARKS) {
        mark(&mut s, m, &lay);
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
            px(y_top - 4.0)
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

/// A pin's (y, raised) at simulated time `t` from its knots: y linear between knots, the raised
/// state of the latest knot at or before `t` (the first knot's before it).
pub fn pin_state(track: &[(f64, f64, bool)], t: f64) -> Option<(f64, bool)> {
    let first = track.first()?;
    if t <= first.0 {
        return Some((first.1, first.2));
    }
    for w in track.windows(2) {
        let (a, b) = (w[0], w[1]);
        if t < b.0 {
            let f = if b.0 > a.0 {
                (t - a.0) / (b.0 - a.0)
            } else {
                1.0
            };
            return Some((a.1 + f * (b.1 - a.1), a.2));
        }
    }
    let last = track[track.len() - 1];
    Some((last.1, last.2))
}

/// One obstacle: a group holding its drawing (and label); a pin that moves animates `cy`, one
/// that withdraws animates its opacity.
fn obstacle(s: &mut String, ob: &AnimObstacle, lay: &Layout, anim: &Animation) {
    let name = esc(&ob.name);
    let width = finite_or(anim.belt_width, 0.1);
    match ob.shape {
        AnimShape::Fence { p0, p1 } => {
            let _ = writeln!(
                s,
                r#"<g class="obstacle" data-name="{name}" data-kind="fence"><line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{PIN_FILL}" stroke-width="3" stroke-linecap="round"/><text x="{}" y="{}" font-size="11" fill="{PIN_FILL}">{name}</text></g>"#,
                px(lay.x(p0.x)),
                px(lay.y(p0.y)),
                px(lay.x(p1.x)),
                px(lay.y(p1.y)),
                px(lay.x(p0.x)),
                px(lay.y(p0.y.max(p1.y)) - 6.0),
            );
        }
        AnimShape::Pin { x, radius } => {
            let track: Vec<(f64, f64, bool)> = ob
                .track
                .iter()
                .copied()
                .filter(|k| k.0.is_finite() && k.1.is_finite())
                .collect();
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
            // The name just outside the belt's nearer edge.
            let (ly, anchor_y) = if y0 >= 0.0 {
                (lay.y(width / 2.0) - 6.0, "auto")
            } else {
                (lay.y(-width / 2.0) + 14.0, "auto")
            };
            let _ = writeln!(
                s,
                r#"<text x="{}" y="{}" font-size="11" fill="{fill}" text-anchor="middle" dominant-baseline="{anchor_y}">{name}{}</text></g>"#,
                px(cx),
                px(ly),
                if ob.sensor { " (sensor)" } else { "" }
            );
        }
    }
}

/// Thin a pin's (t, y) knots to at most [`MAX_KEYS`] (Douglas–Peucker, as for parts).
fn thin_track(pts: &[(f64, f64)], lay: &Layout) -> Vec<(f64, f64)> {
    let keys: Vec<Key> = pts
        .iter()
        .map(|&(t, y)| Key {
            t,
            x: 0.0,
            y: y * lay.k,
            deg: 0.0,
        })
        .collect();
    thin(&keys, 0.0)
        .iter()
        .map(|k| (k.t, k.y / lay.k))
        .collect()
}

/// A mark: a label (and a ring flashing at the place) shown for [`MARK_SHOW_S`] from its time.
fn mark(s: &mut String, m: &AnimMark, lay: &Layout) {
    let u0 = lay.u(m.t);
    let u1 = (u0 + MARK_SHOW_S / lay.dur).min(1.0);
    let u2 = (u1 + MARK_FADE_S / lay.dur).min(1.0);
    let (x, y) = (lay.x(m.at.x), lay.y(m.at.y));
    let colour = m.kind.colour();
    // Labels go away from the belt's centre line, beyond the part's reach.
    let line = m.kind.line() as f64;
    let ty = if m.at.y > 0.0 {
        y - lay.a_px - 8.0 - line * 13.0
    } else {
        y + lay.a_px + 16.0 + line * 13.0
    };
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

/// How many parts `pinfeed run --animate` shows by default: enough that several share the belt.
pub const DEFAULT_PARTS: usize = 10;

/// Fill an [`Animation`] from a run: the first `n_parts` sample paths (by part index; record at
/// least that many with `RunOptions::sample_paths`), every obstacle (pins still and raised: one
/// knot), and, when the run kept per-part records, each sensor pin's reading (at contact begin)
/// and decision (at contact end) of the parts shown. The shown span runs from the first arrival
/// to the last end plus a tenth, so the last part's outcome colour shows.
pub fn from_run(scene: &Scene, result: &RunResult, n_parts: usize) -> Animation {
    let mut paths: Vec<_> = result.paths.iter().collect();
    paths.sort_by_key(|p| p.part);
    paths.truncate(n_parts.min(MAX_PARTS));
    let parts: Vec<AnimPart> = paths
        .iter()
        .map(|p| AnimPart {
            part: p.part,
            outcome: p.outcome,
            poses: p.poses.clone(),
        })
        .collect();
    let times = parts.iter().flat_map(|p| p.poses.iter().map(|q| q.0));
    let t_first = times.clone().fold(f64::INFINITY, f64::min);
    let t_last = times.fold(f64::NEG_INFINITY, f64::max);
    let (t_start, t_end) = if t_first.is_finite() && t_last.is_finite() {
        let span = (t_last - t_first).max(1e-3);
        (t_first, t_last + 0.1 * span)
    } else {
        (0.0, scene.belt.length / scene.belt.speed)
    };
    let obstacles = scene
        .obstacles
        .iter()
        .map(|o| match o {
            Obstacle::Pin(p) => AnimObstacle {
                name: p.name.clone(),
                shape: AnimShape::Pin {
                    x: p.centre.x,
                    radius: p.radius,
                },
                sensor: p.sensor.is_some(),
                track: pin_track(p, &result.control, t_start),
            },
            Obstacle::Fence(f) => AnimObstacle {
                name: f.name.clone(),
                shape: AnimShape::Fence {
                    p0: f.start,
                    p1: f.end(),
                },
                sensor: false,
                track: Vec::new(),
            },
        })
        .collect();
    let mut marks = Vec::new();
    for rec in &result.records {
        let Some(part) = parts.iter().find(|p| p.part == rec.part) else {
            continue;
        };
        for (name, decision) in parse_sensed(&rec.sensed) {
            let Some(Obstacle::Pin(pin)) = scene.obstacles.iter().find(|o| o.name() == name) else {
                continue;
            };
            let reach = scene.part.radius + pin.radius;
            if let Some((tb, te)) = contact_interval(&part.poses, pin.centre, reach) {
                marks.push(AnimMark {
                    t: tb,
                    at: pin.centre,
                    kind: MarkKind::Reading,
                    text: format!("{name}: reading"),
                });
                // With a controller its own decision records say when decisions were taken.
                if result.control.is_empty() {
                    marks.push(AnimMark {
                        t: te,
                        at: pin.centre,
                        kind: MarkKind::Decision,
                        text: format!("part {} → {decision}", part.part),
                    });
                }
            }
        }
    }
    marks.extend(control_marks(scene, &result.control, &parts));
    Animation {
        title: format!("{} — {} on the line", scene.name, scene.part.label),
        belt_length: scene.belt.length,
        belt_width: scene.belt.width,
        belt_speed: scene.belt.speed,
        outline: scene.part.polygon.vertices().to_vec(),
        obstacles,
        parts,
        marks,
        t_start,
        t_end,
    }
}

/// A pin's knots (time, centre y, raised?): where it starts and, for a dynamic pin, each motion the
/// controller carried out (a retractable pin is withdrawn while in transit).
fn pin_track(pin: &PinObstacle, control: &[ControlRecord], t_start: f64) -> Vec<(f64, f64, bool)> {
    let home = pin.centre.y;
    let mut track = vec![(
        t_start,
        home,
        !matches!(pin.actuator, Some(Actuator::Retractable(r)) if !r.raised),
    )];
    for rec in control.iter().filter(|r| r.obstacle == pin.name) {
        let Some(m) = rec.motion else { continue };
        match pin.actuator {
            Some(Actuator::Moving(_)) => {
                track.push((m.t_start, m.from, true));
                track.push((m.t_ready, m.to, true));
            }
            Some(Actuator::Retractable(_)) => {
                track.push((m.t_start, home, false));
                track.push((m.t_ready, home, m.to > 0.5));
            }
            None => {}
        }
    }
    track.sort_by(|a, b| a.0.total_cmp(&b.0));
    track
}

/// The controller's decisions, actuations and late commands for the animated parts, as marks at
/// the sensor or the pin concerned.
fn control_marks(scene: &Scene, control: &[ControlRecord], parts: &[AnimPart]) -> Vec<AnimMark> {
    control
        .iter()
        .filter(|r| parts.iter().any(|p| p.part == r.part))
        .filter_map(|r| {
            let Some(Obstacle::Pin(pin)) = scene.obstacles.iter().find(|o| o.name() == r.obstacle)
            else {
                return None;
            };
            let (kind, text) = match r.kind {
                "decision" => (MarkKind::Decision, format!("part {} → {}", r.part, r.what)),
                "actuation" => (
                    MarkKind::Actuation,
                    format!("{} {} for part {}", r.obstacle, r.what, r.part),
                ),
                "late" => (
                    MarkKind::Late,
                    format!("late: {} {} for part {}", r.obstacle, r.what, r.part),
                ),
                _ => return None,
            };
            let at = match r.motion {
                Some(m) if matches!(pin.actuator, Some(Actuator::Moving(_))) => {
                    Vec2::new(pin.centre.x, m.from)
                }
                _ => pin.centre,
            };
            Some(AnimMark {
                t: r.t,
                at,
                kind,
                text,
            })
        })
        .collect()
}

/// `pin=decision; pin2=decision` (a part record's `sensed`) as (pin, decision) pairs.
fn parse_sensed(sensed: &str) -> Vec<(&str, &str)> {
    sensed
        .split("; ")
        .filter_map(|item| item.split_once('='))
        .map(|(a, b)| (a.trim(), b.trim()))
        .collect()
}

/// The first run of recorded poses whose centroid lies within `reach` (part radius + pin
/// radius) of a pin: its first and last times — contact begin and end, since a path records the
/// pose at both and the pins stand beyond reach of the entry.
fn contact_interval(poses: &[(f64, Pose)], pin: Vec2, reach: f64) -> Option<(f64, f64)> {
    let near = |p: &Pose| (p.position() - pin).norm() <= reach * (1.0 + 1e-9) + 1e-12;
    let i = poses.iter().position(|(_, p)| near(p))?;
    let mut j = i;
    while j + 1 < poses.len() && near(&poses[j + 1].1) {
        j += 1;
    }
    Some((poses[i].0, poses[j].0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short() {
        assert_eq!(num(1.230_000_1, 2), "1.23");
        assert_eq!(num(-0.000_1, 2), "0");
        assert_eq!(num(3.0, 2), "3");
        assert_eq!(num(f64::NAN, 2), "0");
        assert_eq!(key(1.2), "1");
    }

    #[test]
    fn nice_steps() {
        assert_eq!(nice_step(0.07), 0.05);
        assert_eq!(nice_step(2.6), 2.0);
        assert_eq!(nice_step(9.0), 10.0);
    }

    #[test]
    fn simplify_keeps_corners_and_drops_straight_runs() {
        let mut keys = Vec::new();
        for i in 0..=100 {
            let t = i as f64;
            // Straight to t = 50, then a turn in place.
            let (x, deg) = if i <= 50 { (t, 0.0) } else { (50.0, t - 50.0) };
            keys.push(Key { t, x, y: 0.0, deg });
        }
        let out = simplify(&keys, 0.3, 10.0);
        assert_eq!(out.len(), 3, "{out:?}");
        assert_eq!(out[1].t, 50.0);
    }

    #[test]
    fn thin_caps_the_number_of_keys() {
        let keys: Vec<Key> = (0..5000)
            .map(|i| Key {
                t: i as f64,
                x: (i as f64 * 0.7).sin() * 50.0,
                y: 0.0,
                deg: 0.0,
            })
            .collect();
        assert!(thin(&keys, 1.0).len() <= MAX_KEYS);
    }

    #[test]
    fn clipping_interpolates_the_ends() {
        let keys = vec![
            Key {
                t: 0.0,
                x: 0.0,
                y: 0.0,
                deg: 0.0,
            },
            Key {
                t: 10.0,
                x: 10.0,
                y: 0.0,
                deg: 0.0,
            },
        ];
        let out = clip_keys(keys, 2.0, 5.0);
        assert_eq!(out.len(), 2);
        assert_eq!((out[0].t, out[0].x), (2.0, 2.0));
        assert_eq!((out[1].t, out[1].x), (5.0, 5.0));
    }

    #[test]
    fn pin_state_is_linear_in_y_and_stepwise_in_raised() {
        let track = [(0.0, 0.0, true), (2.0, 0.02, false), (4.0, 0.02, true)];
        assert_eq!(pin_state(&track, -1.0), Some((0.0, true)));
        let (y, up) = pin_state(&track, 1.0).unwrap();
        assert!((y - 0.01).abs() < 1e-12 && up);
        assert_eq!(pin_state(&track, 3.0), Some((0.02, false)));
        assert_eq!(pin_state(&track, 5.0), Some((0.02, true)));
        assert_eq!(pin_state(&[], 5.0), None);
    }

    #[test]
    fn sensed_text_parses() {
        assert_eq!(
            parse_sensed("probe=0° (0.998); b=unknown"),
            vec![("probe", "0° (0.998)"), ("b", "unknown")]
        );
        assert!(parse_sensed("").is_empty());
    }

    #[test]
    fn theta_is_unwrapped() {
        let anim = Animation {
            title: String::new(),
            belt_length: 1.0,
            belt_width: 0.1,
            belt_speed: 0.1,
            outline: vec![],
            obstacles: vec![],
            parts: vec![],
            marks: vec![],
            t_start: 0.0,
            t_end: 10.0,
        };
        let lay = Layout::new(&anim, 10.0);
        let poses = [
            (0.0, Pose::new(0.0, 0.0, 6.2)),
            (1.0, Pose::new(0.0, 0.0, 0.1)),
        ];
        let keys = part_keys(&lay, &poses, 0.0, 10.0);
        let turn = keys[1].deg - keys[0].deg;
        assert!(turn.abs() < 20.0, "turned {turn}°");
    }

    /// The drawing's transform — translate to the key's centre, rotate by its angle, outline at
    /// (k x, −k y) — puts every vertex where the world pose puts it (so parts turn about their
    /// centroid, to scale, and the right way round).
    #[test]
    fn keys_place_the_outline_like_the_world_pose() {
        let outline = vec![
            Vec2::new(-0.01, -0.005),
            Vec2::new(0.02, -0.005),
            Vec2::new(-0.01, 0.01),
        ];
        let anim = Animation {
            title: String::new(),
            belt_length: 0.6,
            belt_width: 0.1,
            belt_speed: 0.05,
            outline: outline.clone(),
            obstacles: vec![],
            parts: vec![],
            marks: vec![],
            t_start: 0.0,
            t_end: 10.0,
        };
        let lay = Layout::new(&anim, 10.0);
        let pose = Pose::new(0.2, -0.01, 0.7);
        let keys = part_keys(&lay, &[(1.0, pose)], 0.0, 10.0);
        let k = keys[0];
        let (s, c) = k.deg.to_radians().sin_cos();
        for v in &outline {
            let (lx, ly) = (v.x * lay.k, -v.y * lay.k);
            // SVG rotate(a): (x cos a − y sin a, x sin a + y cos a).
            let (sx, sy) = (k.x + lx * c - ly * s, k.y + lx * s + ly * c);
            let w = pose.apply(*v);
            assert!((sx - lay.x(w.x)).abs() < 1e-9 && (sy - lay.y(w.y)).abs() < 1e-9);
        }
    }
}
