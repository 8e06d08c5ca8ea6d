//! A **certificate of impossibility** for lines that touch only a part's convex hull.
//!
//! Fences touch a part only on its convex hull, and a pin of radius r only where a disc of that
//! radius reaches the outline. When the hull has a rotational symmetry of order k_h that the part
//! itself lacks (a hexagon with a small notch: k_h = 6, the part 1), orientations 360°/k_h apart
//! present the same hull to every obstacle: a push turns them alike, and what differs between
//! them is only the part's pressure distribution, whose centre (the centroid under uniform
//! pressure) lies δ from the hull's own centroid. A sensor pin reads the same forces for the same
//! reason. So, with δ negligible, a line's exit orientations are as symmetric as the feed: for a
//! feed invariant under the turn by 360°/k_h (any orientation, or the part's stable states when
//! they come in such sets), no more than k_p/k_h of the parts (k_p the part's own symmetry) can
//! end in one window narrower than 360°/k_h. Random tripods keep this in distribution: they are
//! drawn uniformly inside the outline, whose hull-symmetric turns give them as likely.
//!
//! The argument holds exactly for the hull's mechanics; the centroid offset δ is stated beside it
//! and the certificate is only issued for δ ≤ [`MAX_OFFSET_A`]·a. A pin that can reach a notch can
//! feel the part's asymmetry: then the certificate covers fence lines alone.

use super::problem::{rotational_symmetry, Compiled, FeedKind, Problem, SYMMETRY_TOL_A};
use crate::geometry::{Polygon, Vec2};
use serde::Serialize;

/// Largest centroid offset from the hull's centroid (units of a) for which the certificate is
/// issued: the mechanics see the notch only through this offset, a fiftieth of the part's size.
pub const MAX_OFFSET_A: f64 = 0.02;

/// Why no line of some kinds can orient the part, with the bound it implies.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Certificate {
    /// Order of the convex hull's rotational symmetry.
    pub hull_symmetry: u32,
    /// Order of the part's own rotational symmetry (a divisor of `hull_symmetry`).
    pub part_symmetry: u32,
    /// Distance from the part's centroid to its hull's centroid (units of a).
    pub centroid_offset_a: f64,
    /// Whether a pin of the problem's radius can touch the outline where it leaves the hull.
    pub pins_reach_notches: bool,
    /// The most of a symmetric feed any line the certificate covers brings into one window:
    /// `part_symmetry / hull_symmetry`.
    pub bound: f64,
}

impl Certificate {
    /// Does the certificate cover lines with pins (sensor and moving pins included)?
    pub fn covers_pins(&self) -> bool {
        !self.pins_reach_notches
    }

    /// The certificate in words.
    pub fn describe(&self) -> String {
        let turn = 360.0 / self.hull_symmetry as f64;
        let own = match self.part_symmetry {
            1 => "the part itself has none".to_string(),
            k => format!("the part itself only {k}-fold"),
        };
        let who = if self.covers_pins() {
            "fences and pins touch only the hull (no pin of this radius reaches the outline where it leaves the hull)"
        } else {
            "fences touch only the hull (pins of this radius can reach the outline where it leaves the hull, so pin lines are not covered)"
        };
        format!(
            "the convex hull has {}-fold rotational symmetry and {own}; {who}, so orientations {turn:.0}° apart are pushed and sensed alike (the centroid lies {:.4}a from the hull's centre) and at most {:.1}% of a symmetric feed can end in one window",
            self.hull_symmetry,
            self.centroid_offset_a,
            self.bound * 100.0
        )
    }
}

/// The certificate for `problem`'s part, if its hull is more symmetric than the part, the
/// centroid offset is at most [`MAX_OFFSET_A`]·a, the window is narrower than the hull's
/// symmetry turn and the feed is invariant under that turn.
pub fn of(problem: &Problem, compiled: &Compiled) -> Option<Certificate> {
    let part = &compiled.polygon;
    let hull = Polygon::new(&straightened(part.hull(), SYMMETRY_TOL_A * part.radius())).ok()?;
    let k_h = rotational_symmetry(&hull);
    let k_p = rotational_symmetry(part);
    if k_h <= k_p || k_h % k_p != 0 {
        return None;
    }
    let a = part.radius();
    let offset = area_centroid(part.hull()).norm() / a;
    let turn = 360.0 / k_h as f64;
    if offset > MAX_OFFSET_A || 2.0 * problem.tolerance_deg >= turn {
        return None;
    }
    let symmetric_feed = match problem.feed {
        FeedKind::Uniform => true,
        FeedKind::Stable => invariant(&compiled.stable_deg, turn),
    };
    if !symmetric_feed {
        return None;
    }
    let pin = problem.pin_radius_m;
    Some(Certificate {
        hull_symmetry: k_h,
        part_symmetry: k_p,
        centroid_offset_a: offset,
        pins_reach_notches: pins_reach_notches(part, pin),
        bound: k_p as f64 / k_h as f64,
    })
}

/// The convex ring `v` without the vertices that lie within `eps` of the line through their
/// neighbours: a hull drawn to a few decimals keeps a point of a straight edge that rounding
/// pushed out of it, which would hide the hull's symmetry.
fn straightened(v: &[Vec2], eps: f64) -> Vec<Vec2> {
    let mut v = v.to_vec();
    let mut k = 0;
    while v.len() > 3 && k < v.len() {
        let n = v.len();
        let (p, q, r) = (v[(k + n - 1) % n], v[k], v[(k + 1) % n]);
        let e = r - p;
        let off = (q - p).cross(e).abs() / e.norm();
        if off <= eps {
            v.remove(k);
            k = 0;
        } else {
            k += 1;
        }
    }
    v
}

/// The area centroid of a simple polygon.
fn area_centroid(v: &[Vec2]) -> Vec2 {
    let (mut a2, mut c) = (0.0, Vec2::ZERO);
    for i in 0..v.len() {
        let (p, q) = (v[i], v[(i + 1) % v.len()]);
        let w = p.cross(q);
        a2 += w;
        c += (p + q) * w;
    }
    c * (1.0 / (3.0 * a2))
}

/// Is the set of orientations (degrees) the same after a turn by `turn` degrees (within 1°)?
fn invariant(states: &[f64], turn: f64) -> bool {
    let near = |x: f64, y: f64| {
        let d = (x - y).rem_euclid(360.0);
        d.min(360.0 - d) < 1.0
    };
    !states.is_empty()
        && states
            .iter()
            .all(|&s| states.iter().any(|&t| near(s + turn, t)))
}

/// Can a disc of radius `r` (the polygon's units) touch the outline of `part` somewhere off its convex
/// hull without overlapping the part? Each edge that is not a hull edge is tried at 32 points of
/// its interior, the disc tangent there on the outside (a disc touching a reflex vertex would
/// overlap an edge beside it; a point pin, r = 0, touches any edge).
pub fn pins_reach_notches(part: &Polygon, r: f64) -> bool {
    let v = part.vertices();
    // The hull as a polygon, re-centred on its own centroid (`offset` in the part's frame).
    let hull = Polygon::new(part.hull()).ok();
    let offset = area_centroid(part.hull());
    let a = part.radius();
    // A point on the hull's boundary (to the symmetry tolerance): an edge whose ends and middle
    // all are lies along a hull edge, where any obstacle may touch it.
    let on_hull = |p: Vec2| {
        hull.as_ref()
            .is_some_and(|h| h.distance_to_boundary(p - offset).0 <= SYMMETRY_TOL_A * a)
    };
    let n = v.len();
    // Outward normal side: the vertices are counter-clockwise when the signed area is positive.
    let ccw = area_sign(v) > 0.0;
    for i in 0..n {
        let (p, q) = (v[i], v[(i + 1) % n]);
        if on_hull(p) && on_hull(q) && on_hull((p + q) * 0.5) {
            continue;
        }
        let e = q - p;
        let len = e.norm();
        if len <= 0.0 {
            continue;
        }
        let t = e * (1.0 / len);
        let out = if ccw {
            Vec2::new(t.y, -t.x)
        } else {
            Vec2::new(-t.y, t.x)
        };
        for k in 1..32 {
            let s = p + e * (k as f64 / 32.0);
            if r <= 0.0 {
                return true;
            }
            let c = s + out * r;
            let (d, _) = part.distance_to_boundary(c);
            if !part.contains(c) && d >= r * (1.0 - 1e-9) {
                return true;
            }
        }
    }
    false
}

fn area_sign(v: &[Vec2]) -> f64 {
    (0..v.len()).map(|i| v[i].cross(v[(i + 1) % v.len()])).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A regular hexagon of circumradius 1 with a notch of depth `depth` and half-width `half`
    /// cut into the middle of one edge.
    fn notched_hexagon(depth: f64, half: f64) -> Vec<Vec2> {
        let mut v = Vec::new();
        for k in 0..6 {
            let (s, c) = (k as f64 * 60f64.to_radians()).sin_cos();
            v.push(Vec2::new(c, s));
            if k == 0 {
                // The edge from 0° to 60°: its midpoint, inward normal.
                let (p, q) = (
                    Vec2::new(1.0, 0.0),
                    Vec2::new(0.5, 60f64.to_radians().sin()),
                );
                let m = (p + q) * 0.5;
                let t = (q - p) * (1.0 / (q - p).norm());
                let inward = Vec2::new(-t.y, t.x) * -1.0;
                let inward = if (m + inward).norm() < m.norm() {
                    inward
                } else {
                    inward * -1.0
                };
                v.push(m - t * half);
                v.push(m + inward * depth);
                v.push(m + t * half);
            }
        }
        v
    }

    fn problem_for(v: &[Vec2], pin_radius: f64) -> (Problem, Compiled) {
        let spec = format!(
            "vertices:{}",
            v.iter()
                .map(|p| format!("{},{}", p.x * 20.0, p.y * 20.0))
                .collect::<Vec<_>>()
                .join(" ")
        );
        let mut p = Problem::new(&spec);
        p.scale = 0.001;
        p.pin_radius_m = pin_radius;
        p.feed = FeedKind::Uniform;
        let c = p.compile().unwrap();
        (p, c)
    }

    /// A hexagon with a small notch: six-fold hull, no symmetry of its own, the bound 1/6; a
    /// 2 mm pin does not fit a 0.8 mm-wide notch, a point pin does.
    #[test]
    fn a_notched_hexagon_is_certified_with_the_bound_of_its_hull() {
        let v = notched_hexagon(0.05, 0.02);
        let (p, c) = problem_for(&v, 0.002);
        let cert = of(&p, &c).expect("a certificate");
        assert_eq!((cert.hull_symmetry, cert.part_symmetry), (6, 1));
        assert!((cert.bound - 1.0 / 6.0).abs() < 1e-12);
        assert!(cert.covers_pins(), "{cert:?}");
        assert!(cert.centroid_offset_a < MAX_OFFSET_A);
        assert!(
            cert.describe().contains("at most 16.7%"),
            "{}",
            cert.describe()
        );
        let (p0, c0) = problem_for(&v, 0.0);
        assert!(!of(&p0, &c0).unwrap().covers_pins());
        // A V notch 2 mm wide and 0.5 mm deep: a disc wedged in it touches both sides inside
        // them up to r = L tan α = √1.25 · 2 ≈ 2.236 mm (L the side, α the half opening).
        let vee = notched_hexagon(0.025, 0.05);
        for (r, reach) in [(0.0021, true), (0.0024, false)] {
            let (p, c) = problem_for(&vee, r);
            assert_eq!(of(&p, &c).unwrap().pins_reach_notches, reach, "r {r}");
        }
        // A wide notch a 2 mm pin enters: fences only.
        let wide = notched_hexagon(0.1, 0.3);
        let (pw, cw) = problem_for(&wide, 0.002);
        // (Or its centroid moved too far for a certificate at all.)
        if let Some(c) = of(&pw, &cw) {
            assert!(!c.covers_pins(), "{c:?}");
        }
    }

    /// No certificate where the hull is no more symmetric than the part, where the part's own
    /// centroid sits far from the hull's, or where the window spans the hull's turn.
    #[test]
    fn no_certificate_without_a_hull_symmetry_the_part_lacks() {
        for part in ["square", "rect:2:1", "tripoly1", "lshape", "ngon:6"] {
            let p = Problem::new(part);
            let c = p.compile().unwrap();
            assert_eq!(of(&p, &c), None, "{part}");
        }
        // A deep notch moves the centroid by more than the threshold.
        let (p, c) = problem_for(&notched_hexagon(0.6, 0.4), 0.002);
        assert_eq!(of(&p, &c), None);
        // A window as wide as the hull's turn (±30° of 60°) can hold every part.
        let (mut p, c) = problem_for(&notched_hexagon(0.05, 0.02), 0.002);
        p.tolerance_deg = 30.0;
        assert_eq!(of(&p, &c), None);
        p.tolerance_deg = 29.0;
        assert!(of(&p, &c).is_some());
    }
}
