//! Axis ranges of orientation figures that zoom on the data: the shortest arc of the circle that
//! holds every occupied interval (the complement of the largest empty gap), widened by a margin,
//! as an unwrapped range `lo..hi` (`lo` may be negative, `hi` above 360) so an arc across 0° is
//! drawn in one piece. Tick labels print the angle wrapped into [0, 360).

use crate::geometry::wrap_deg;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;

/// A plotters axis of degrees whose ticks are [`degree_ticks`] (on multiples of a step dividing
/// 360); no light mesh lines.
pub(crate) struct DegreeAxis {
    range: RangedCoordf64,
    ticks: Vec<f64>,
}

impl Ranged for DegreeAxis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;
    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.range.map(value, limit)
    }
    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }
    fn range(&self) -> std::ops::Range<f64> {
        self.range.range()
    }
}

/// The degree axis over `range` with at most `max` ticks ([`degree_ticks`]).
pub(crate) fn degree_axis(range: std::ops::Range<f64>, max: usize) -> DegreeAxis {
    DegreeAxis {
        ticks: degree_ticks(range.start, range.end, max),
        range: range.into(),
    }
}

/// An unwrapped degree range of an axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DegreeView {
    /// Lower end (degrees, may be negative).
    pub lo: f64,
    /// Upper end (degrees, may exceed 360).
    pub hi: f64,
}

impl DegreeView {
    /// The whole circle.
    pub const FULL: DegreeView = DegreeView { lo: 0.0, hi: 360.0 };

    /// `deg` (any wrapping) as a coordinate on this axis: the copy in [lo, lo + 360).
    pub fn place(&self, deg: f64) -> f64 {
        self.lo + (deg - self.lo).rem_euclid(360.0)
    }

    /// Is `deg` (any wrapping) on the axis?
    pub fn shows(&self, deg: f64) -> bool {
        self.place(deg) <= self.hi
    }

    /// The pieces of the arc from `start` running `width` degrees that fall on the axis.
    pub fn pieces(&self, start: f64, width: f64) -> Vec<(f64, f64)> {
        if width >= 360.0 {
            return vec![(self.lo, self.hi)];
        }
        let mut out = Vec::new();
        let a = self.place(start);
        for shift in [-360.0, 0.0] {
            let (p, q) = ((a + shift).max(self.lo), (a + shift + width).min(self.hi));
            if p < q {
                out.push((p, q));
            }
        }
        out
    }

    /// A tick label: the angle wrapped into [0, 360), without decimals.
    pub fn label(v: f64) -> String {
        let w = wrap_deg(v);
        let w = if (w - 360.0).abs() < 1e-6 { 0.0 } else { w };
        format!("{w:.0}")
    }
}

/// Tick steps of an orientation axis (degrees): each divides 360, so ticks at its multiples put
/// one on 0°/360° and keep the same spacing across it (a step of 50° would label an axis crossing
/// 360° "…, 300, 350, 40, 90": 400 wrapped).
const DEGREE_STEPS: [f64; 12] = [
    1.0, 2.0, 5.0, 10.0, 15.0, 20.0, 30.0, 45.0, 60.0, 90.0, 120.0, 180.0,
];

/// Tick positions over [lo, hi] (degrees, unwrapped): the multiples of the smallest step in
/// [`DEGREE_STEPS`] that gives at most `max` ticks (at least 2 asked for). Labelled wrapped into
/// [0, 360) ([`DegreeView::label`]) they read evenly spaced, with 0 where the axis crosses
/// 0°/360°.
pub fn degree_ticks(lo: f64, hi: f64, max: usize) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Vec::new();
    }
    let max = max.max(2);
    let step = DEGREE_STEPS
        .iter()
        .copied()
        .find(|s| (hi / s).floor() - (lo / s).ceil() < max as f64)
        .unwrap_or(180.0);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// The view holding every arc `(start, width)` (degrees), widened each side by `margin` (at least
/// `min_span` wide in all); the whole circle when the arcs leave less than `min_gap` uncovered or
/// there are none.
pub fn degree_view(arcs: &[(f64, f64)], margin: f64, min_span: f64, min_gap: f64) -> DegreeView {
    // Cover the circle with the arcs, merged, as intervals in [0, 720) starting in [0, 360).
    let mut iv: Vec<(f64, f64)> = arcs
        .iter()
        .filter(|(s, w)| s.is_finite() && w.is_finite() && *w >= 0.0)
        .map(|&(s, w)| {
            let a = wrap_deg(s);
            (a, a + w.min(360.0))
        })
        .collect();
    if iv.is_empty() {
        return DegreeView::FULL;
    }
    if iv.iter().any(|(a, b)| b - a >= 360.0) {
        return DegreeView::FULL;
    }
    // What runs past 360° covers the start of the circle too.
    let wrapped: Vec<(f64, f64)> = iv
        .iter()
        .filter(|(_, b)| *b > 360.0)
        .map(|(_, b)| (0.0, b - 360.0))
        .collect();
    iv.extend(wrapped);
    iv.sort_by(|x, y| x.0.total_cmp(&y.0));
    // The largest gap between the end of an interval and the start of the next (cyclically).
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for (a, b) in iv {
        match merged.last_mut() {
            Some(l) if a <= l.1 => l.1 = l.1.max(b),
            _ => merged.push((a, b)),
        }
    }
    // The last interval may wrap over the first ones.
    let first_start = merged[0].0;
    let last_end = merged[merged.len() - 1].1;
    let mut best = (first_start + 360.0 - last_end, merged[0].0); // (gap, data starts at)
    for w in merged.windows(2) {
        let gap = w[1].0 - w[0].1;
        if gap > best.0 {
            best = (gap, w[1].0);
        }
    }
    let (gap, start) = best;
    if gap < min_gap {
        return DegreeView::FULL;
    }
    let span = 360.0 - gap;
    let extra = ((min_span - span) / 2.0).max(0.0);
    let pad = margin.max(extra);
    if span + 2.0 * pad >= 360.0 - 1e-9 {
        return DegreeView::FULL;
    }
    DegreeView {
        lo: start - pad,
        hi: start + span + pad,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_narrow_cluster_is_zoomed_with_its_margin() {
        let v = degree_view(&[(14.0, 1.0), (16.0, 2.0)], 5.0, 0.0, 30.0);
        assert_eq!(v, DegreeView { lo: 9.0, hi: 23.0 });
        assert!(v.shows(20.0) && !v.shows(90.0));
    }

    #[test]
    fn a_cluster_across_zero_is_one_piece() {
        let v = degree_view(&[(355.0, 3.0), (2.0, 3.0)], 2.0, 0.0, 30.0);
        assert_eq!(
            v,
            DegreeView {
                lo: 353.0,
                hi: 367.0
            }
        );
        assert_eq!(v.place(1.0), 361.0);
        assert_eq!(v.pieces(358.0, 4.0), vec![(358.0, 362.0)]);
        assert_eq!(DegreeView::label(361.0), "1");
    }

    #[test]
    fn spread_data_keeps_the_whole_circle() {
        let arcs: Vec<(f64, f64)> = (0..12).map(|k| (k as f64 * 30.0, 5.0)).collect();
        assert_eq!(degree_view(&arcs, 5.0, 0.0, 30.0), DegreeView::FULL);
        assert_eq!(degree_view(&[], 5.0, 0.0, 30.0), DegreeView::FULL);
    }

    /// Issue 57 item 16: an axis across 0°/360° was labelled "…, 350, 40" (plotters' 50° step
    /// put a tick at 400°). Ticks are multiples of a step dividing 360: evenly spaced once
    /// wrapped, with a 0 where the axis crosses 360°.
    #[test]
    fn ticks_across_360_read_evenly_with_a_zero() {
        for (lo, hi, max) in [
            (60.0, 420.0, 15),
            (-40.0, 300.0, 15),
            (250.0, 430.0, 8),
            (353.0, 367.0, 15),
            (0.0, 360.0, 13),
            (-200.0, 200.0, 7),
        ] {
            let ticks = degree_ticks(lo, hi, max);
            assert!(
                ticks.len() >= 2 && ticks.len() <= max,
                "{lo}..{hi}: {ticks:?}"
            );
            assert!(ticks.iter().all(|t| (lo..=hi).contains(t)));
            let step = ticks[1] - ticks[0];
            assert_eq!(360.0 % step, 0.0, "{lo}..{hi}: step {step}");
            let labels: Vec<f64> = ticks
                .iter()
                .map(|&t| DegreeView::label(t).parse().unwrap())
                .collect();
            for w in labels.windows(2) {
                // Each label is the one before plus the step, around the circle.
                assert_eq!((w[0] + step) % 360.0, w[1], "{lo}..{hi}: {labels:?}");
            }
            if lo < 360.0 && hi > 360.0 || lo < 0.0 && hi > 0.0 {
                assert!(labels.contains(&0.0), "{lo}..{hi}: {labels:?}");
            }
        }
        let labels: Vec<String> = degree_ticks(60.0, 420.0, 15)
            .into_iter()
            .map(DegreeView::label)
            .collect();
        assert_eq!(
            labels.join(", "),
            "60, 90, 120, 150, 180, 210, 240, 270, 300, 330, 0, 30, 60"
        );
        assert_eq!(degree_ticks(0.0, 360.0, 13).len(), 13);
    }

    #[test]
    fn the_minimum_span_widens_a_point() {
        let v = degree_view(&[(100.0, 0.0)], 1.0, 20.0, 30.0);
        assert_eq!(
            v,
            DegreeView {
                lo: 90.0,
                hi: 110.0
            }
        );
    }
}
