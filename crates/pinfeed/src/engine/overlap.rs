//! Overlap tests for the line (docs/physics.md#the-line: "simultaneous contact with two obstacles and part–part
//! overlap are detected and reported, never silently mis-simulated").
//!
//! * [`polygon_clearance`]: the distance between two simple polygons (world vertices), 0 when they
//!   intersect;
//! * [`disc_clearance`]: the distance from a disc (a pin) to a polygon, ≤ 0 when they touch;
//! * [`capsule_clearance`]: the same for a segment thickened by a radius (a fence, or a pin);
//! * [`first_touch`]: the earliest time in a window at which a clearance that varies with time
//!   reaches 0, given the clearance at any instant and a bound on how fast it can fall.
//!
//! Motion between recorded integration steps is taken as linear in (centroid, θ); over such a piece a
//! rigid part's points move at most |Δc| + a·|Δθ|, so the clearance at any instant of an interval is
//! at least (c₀ + c₁ − Δ)/2 where Δ is the summed motion of both bodies. Intervals whose bound is not
//! positive are bisected until Δ falls below `resolution`; an interval that small with positive
//! clearance at both ends is a near miss, not a touch (resolved to `resolution`).

use crate::geometry::Vec2;

pub use crate::geometry::segment::{point_segment_distance, segment_distance, segments_intersect};

/// Is `p` strictly inside the polygon with vertices `v` (crossing-number test)?
pub fn point_in_polygon(p: Vec2, v: &[Vec2]) -> bool {
    crate::geometry::polygon::ring_contains(v, p)
}

/// Distance between two simple polygons given by their vertices; 0 if they intersect or one
/// contains the other.
pub fn polygon_clearance(a: &[Vec2], b: &[Vec2]) -> f64 {
    let (na, nb) = (a.len(), b.len());
    let mut best = f64::INFINITY;
    for i in 0..na {
        let (a0, a1) = (a[i], a[(i + 1) % na]);
        for j in 0..nb {
            let (b0, b1) = (b[j], b[(j + 1) % nb]);
            if segments_intersect(a0, a1, b0, b1) {
                return 0.0;
            }
            best = best
                .min(point_segment_distance(a0, b0, b1))
                .min(point_segment_distance(b0, a0, a1));
        }
    }
    if point_in_polygon(a[0], b) || point_in_polygon(b[0], a) {
        return 0.0;
    }
    best
}

/// Distance from the disc (centre, radius) to the polygon `v`, negative or 0 when they touch.
pub fn disc_clearance(centre: Vec2, radius: f64, v: &[Vec2]) -> f64 {
    if point_in_polygon(centre, v) {
        return -radius;
    }
    let m = v.len();
    let d = (0..m)
        .map(|i| point_segment_distance(centre, v[i], v[(i + 1) % m]))
        .fold(f64::INFINITY, f64::min);
    d - radius
}

/// Distance from the capsule (the points within `radius` of the segment [p, q]: a pin's disc when
/// p = q, a fence when radius = 0) to the polygon `v`, negative or 0 when they touch.
pub fn capsule_clearance(p: Vec2, q: Vec2, radius: f64, v: &[Vec2]) -> f64 {
    if point_in_polygon(p, v) {
        return -radius;
    }
    let m = v.len();
    let d = (0..m)
        .map(|i| segment_distance(p, q, v[i], v[(i + 1) % m]))
        .fold(f64::INFINITY, f64::min);
    d - radius
}

/// The earliest time in [t0, t1] at which `clearance(t) ≤ 0`, or `None`.
///
/// `breaks` are the times inside (t0, t1) at which the motion's linear pieces join (recorded
/// steps), sorted; `motion(ta, tb)` bounds how much the clearance can fall between two instants of
/// one piece. A piece is skipped without evaluating the clearance at its end while a lower bound
/// of the clearance at its start (the last value less the motion since) exceeds its motion.
/// Counts clearance evaluations in `evaluations`.
pub fn first_touch(
    t0: f64,
    t1: f64,
    breaks: &[f64],
    clearance: &mut dyn FnMut(f64) -> f64,
    motion: &dyn Fn(f64, f64) -> f64,
    resolution: f64,
    evaluations: &mut u64,
) -> Option<f64> {
    let mut eval = |t: f64, n: &mut u64| {
        *n += 1;
        clearance(t)
    };
    let mut ta = t0;
    let mut ca = eval(t0, evaluations);
    if ca <= 0.0 {
        return Some(t0);
    }
    if t1 <= t0 {
        return None;
    }
    let grid = breaks
        .iter()
        .copied()
        .filter(|&t| t > t0 && t < t1)
        .chain(std::iter::once(t1));
    for tb in grid {
        // Conservative advancement: while the clearance at the start of the piece (a value, or a
        // lower bound carried from pieces before) exceeds how far the bodies can move within it,
        // nothing touches in the piece and its end needs no evaluation; the bound carries on.
        let d = motion(ta, tb);
        if ca - d > resolution {
            ca -= d;
            ta = tb;
            continue;
        }
        let cb = eval(tb, evaluations);
        if let Some(t) = bisect(
            (ta, ca),
            (tb, cb),
            d,
            &mut |t| eval(t, evaluations),
            motion,
            resolution,
            0,
        ) {
            return Some(t);
        }
        ta = tb;
        ca = cb;
    }
    None
}

/// The first touch in [ta, tb] given the clearance at both ends and the motion bound `d` over
/// the piece (the caller has it already).
fn bisect(
    (ta, ca): (f64, f64),
    (tb, cb): (f64, f64),
    d: f64,
    clearance: &mut dyn FnMut(f64) -> f64,
    motion: &dyn Fn(f64, f64) -> f64,
    resolution: f64,
    depth: u32,
) -> Option<f64> {
    if cb > 0.0 && 0.5 * (ca + cb - d) > 0.0 {
        return None;
    }
    if d <= resolution || depth >= 48 {
        return if cb <= 0.0 { Some(tb) } else { None };
    }
    let tm = 0.5 * (ta + tb);
    let cm = clearance(tm);
    let d1 = motion(ta, tm);
    if let Some(t) = bisect(
        (ta, ca),
        (tm, cm),
        d1,
        clearance,
        motion,
        resolution,
        depth + 1,
    ) {
        return Some(t);
    }
    if cm <= 0.0 {
        return Some(tm);
    }
    let d2 = motion(tm, tb);
    bisect(
        (tm, cm),
        (tb, cb),
        d2,
        clearance,
        motion,
        resolution,
        depth + 1,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(cx: f64, cy: f64) -> Vec<Vec2> {
        vec![
            Vec2::new(cx - 0.5, cy - 0.5),
            Vec2::new(cx + 0.5, cy - 0.5),
            Vec2::new(cx + 0.5, cy + 0.5),
            Vec2::new(cx - 0.5, cy + 0.5),
        ]
    }

    #[test]
    fn clearance_of_polygons() {
        assert!((polygon_clearance(&square(0.0, 0.0), &square(2.0, 0.0)) - 1.0).abs() < 1e-12);
        assert_eq!(polygon_clearance(&square(0.0, 0.0), &square(0.9, 0.3)), 0.0);
        // Containment without edge crossings.
        let big: Vec<Vec2> = square(0.0, 0.0).iter().map(|&p| p * 4.0).collect();
        assert_eq!(polygon_clearance(&big, &square(0.0, 0.0)), 0.0);
        assert!(
            (disc_clearance(Vec2::new(1.5, 0.0), 0.25, &square(0.0, 0.0)) - 0.75).abs() < 1e-12
        );
        assert!(disc_clearance(Vec2::new(0.0, 0.0), 0.25, &square(0.0, 0.0)) < 0.0);
    }

    #[test]
    fn clearance_of_capsules() {
        let sq = square(0.0, 0.0);
        // A segment (fence) 1 above the square, crossing it, or inside it.
        let d = capsule_clearance(Vec2::new(-3.0, 1.5), Vec2::new(3.0, 1.5), 0.0, &sq);
        assert!((d - 1.0).abs() < 1e-12, "{d}");
        let cross = capsule_clearance(Vec2::new(-3.0, 0.2), Vec2::new(3.0, 0.1), 0.0, &sq);
        assert_eq!(cross, 0.0);
        assert!(capsule_clearance(Vec2::new(-0.1, 0.0), Vec2::new(0.1, 0.0), 0.0, &sq) <= 0.0);
        // A degenerate capsule is the disc.
        let c = Vec2::new(1.5, 0.0);
        assert!((capsule_clearance(c, c, 0.25, &sq) - disc_clearance(c, 0.25, &sq)).abs() < 1e-12);
    }

    #[test]
    fn first_touch_finds_the_earliest_contact() {
        // A unit square moving at speed 1 toward a fixed one 1 unit away touches at t = 1.
        let mut n = 0;
        let t = first_touch(
            0.0,
            3.0,
            &[],
            &mut |t| polygon_clearance(&square(t, 0.0), &square(2.0, 0.0)),
            &|a, b| (b - a).abs(),
            1e-9,
            &mut n,
        )
        .unwrap();
        assert!((t - 1.0).abs() < 1e-8, "{t}");
        // A near miss passes.
        let miss = first_touch(
            0.0,
            3.0,
            &[1.0, 2.0],
            &mut |t| polygon_clearance(&square(t, 1.0 + 1e-3), &square(2.0, 0.0)),
            &|a, b| (b - a).abs(),
            1e-9,
            &mut n,
        );
        assert_eq!(miss, None);
    }

    /// Pieces the bodies cannot cross are skipped: a square 10 units away, approaching over 1 000
    /// recorded steps, is found at the same time with a handful of evaluations rather than one
    /// per step; and a piece whose motion could close the gap is still looked into.
    #[test]
    fn first_touch_skips_pieces_it_cannot_touch_in() {
        let breaks: Vec<f64> = (1..1000).map(|k| k as f64 * 0.01).collect();
        let mut n = 0;
        let t = first_touch(
            0.0,
            10.0,
            &breaks,
            &mut |t| polygon_clearance(&square(t, 0.0), &square(10.0, 0.0)),
            &|a, b| (b - a).abs(),
            1e-9,
            &mut n,
        )
        .unwrap();
        assert!((t - 9.0).abs() < 1e-8, "{t}");
        assert!(n < 120, "{n} evaluations for 1000 pieces");
        // With a bound 50 times too loose, every piece starting closer than 0.5 is looked at.
        let mut m = 0;
        let t = first_touch(
            0.0,
            10.0,
            &breaks,
            &mut |t| polygon_clearance(&square(t, 0.0), &square(10.0, 0.0)),
            &|a, b| 50.0 * (b - a).abs(),
            1e-9,
            &mut m,
        )
        .unwrap();
        assert!((t - 9.0).abs() < 1e-8, "{t}");
        assert!(m > 2 * n, "{m} against {n}");
    }
}
