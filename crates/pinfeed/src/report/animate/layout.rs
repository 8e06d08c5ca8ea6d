//! The world → SVG mapping and page layout, and the short numbers the document is written with.

use super::model::{span, AnimShape, Animation};

/// A number with at most `decimals` decimals, trailing zeros (and "-0") dropped.
pub(super) fn num(x: f64, decimals: usize) -> String {
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
pub(super) fn px(x: f64) -> String {
    num(x, 2)
}

/// A key time (5 decimals: 0.3 ms of a 30 s loop).
pub(super) fn key(u: f64) -> String {
    num(u.clamp(0.0, 1.0), 5)
}

/// A "nice" step (1, 2 or 5 × 10ⁿ) near `x`.
pub(super) fn nice_step(x: f64) -> f64 {
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
pub(super) fn decimals_for(step: f64) -> usize {
    (-(step.log10().floor())).clamp(0.0, 6.0) as usize
}

/// SVG y of the drawing's top (the title and subtitle are above).
const TOP: f64 = 64.0;

/// The world → SVG mapping and the page layout.
pub(super) struct Layout {
    /// px per metre (both axes).
    pub(super) k: f64,
    /// SVG x of world x = 0.
    pub(super) ox: f64,
    /// SVG y of world y = 0.
    pub(super) oy: f64,
    pub(super) width: f64,
    pub(super) height: f64,
    /// SVG y just below the drawing (axis, progress bar, legend follow).
    pub(super) below: f64,
    /// Largest centroid-to-vertex distance of the outline, px.
    pub(super) a_px: f64,
    /// Loop length, s.
    pub(super) dur: f64,
    pub(super) t_start: f64,
    pub(super) span: f64,
}

impl Layout {
    pub(super) fn new(anim: &Animation, dur: f64) -> Layout {
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
            if let AnimShape::Fence { p0, p1, tail } = ob.shape {
                let p2 = tail.map_or(p1, |(_, p2, _)| p2);
                for y in [p0.y, p1.y, p2.y] {
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
        let top = TOP;
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
    /// Make room for `above` px of labels beyond the belt's upper edge and `below` px beyond its
    /// lower edge (`half`: half the belt's width, m), moving the drawing down and the axes below
    /// it as needed.
    pub(super) fn reserve(&mut self, half: f64, above: f64, below: f64) {
        let room_above = self.oy - half * self.k - TOP;
        let extra_top = (above - room_above).max(0.0);
        self.oy += extra_top;
        self.below += extra_top;
        self.height += extra_top;
        let room_below = self.below - (self.oy + half * self.k);
        let extra_bottom = (below - room_below).max(0.0);
        self.below += extra_bottom;
        self.height += extra_bottom;
    }
    pub(super) fn x(&self, x: f64) -> f64 {
        self.ox + x * self.k
    }
    pub(super) fn y(&self, y: f64) -> f64 {
        self.oy - y * self.k
    }
    /// Key time of simulated time `t`, in [0, 1].
    pub(super) fn u(&self, t: f64) -> f64 {
        ((t - self.t_start) / self.span).clamp(0.0, 1.0)
    }
    /// The attributes every animation shares.
    pub(super) fn timing(&self) -> String {
        format!(r#"dur="{}s" repeatCount="indefinite""#, num(self.dur, 3))
    }
}

pub(super) fn finite_or(x: f64, d: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        d
    }
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
}
