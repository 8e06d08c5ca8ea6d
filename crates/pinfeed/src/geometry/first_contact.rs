//! First contact between a part and a pin moving along a straight line relative to it.
//!
//! On the belt the part travels in +x toward a pin; in the belt frame the pin travels in −x (or, for
//! a moving pin, along (−V, w)) toward a part at rest. Either way the question is a ray cast: a disc of
//! radius ρ ≥ 0 (ρ = 0 is the thesis's point pin) swept from `start` along the unit direction `dir`
//! against the polygon. The answer is the travel until first touch, the touching feature (an edge with
//! its fraction, or a vertex), the contact point and the unit normal pointing *into* the part
//! (docs/physics.md#pin-radius: an edge's inward normal, or for a disc touching a vertex the direction from the pin
//! centre to the vertex).
//!
//! A touch is *grazing* when the pin's direction of travel does not enter the part there (the pin
//! slides past an extreme vertex or along an edge): such a touch pushes nothing, and the caller
//! decides whether to continue past it (`min_travel`). Tolerances are relative to the part's size:
//! a hit within 1e-12·a of an edge end is reported as that vertex, and a disc whose swept edge
//! passes within 1e-12·a of a vertex it touches is grazing it.

use super::polygon::Polygon;
use super::vec2::{Pose, Vec2};
use serde::Serialize;

/// The feature of the part that a pin touches.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Feature {
    /// Edge `index` (from vertex `index` to `index + 1`) at fraction `t` ∈ (0, 1) of its length.
    Edge {
        /// Index of the edge.
        index: usize,
        /// Fraction of the edge's length from its first vertex, in (0, 1).
        t: f64,
    },
    /// Vertex `index`.
    Vertex {
        /// Index of the vertex.
        index: usize,
    },
}

/// Result of a first-contact query. Points and normals are in world coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FirstContact {
    /// Travel of the pin along `dir` (same unit as the part) until it first touches the part.
    pub travel: f64,
    /// Contact point on the part's boundary.
    pub point: Vec2,
    /// Pin centre at contact.
    pub pin_centre: Vec2,
    /// The touched feature.
    pub feature: Feature,
    /// Unit contact normal pointing into the part.
    pub normal: Vec2,
    /// True when the pin's travel does not enter the part at this touch (it pushes nothing).
    pub grazing: bool,
}

/// Does a ray with (part-frame) direction `d` arriving at vertex `i` enter the polygon there?
/// Exactly tangent directions (|d·n| ≤ 1e-12) do not enter.
pub fn enters_at_vertex(poly: &Polygon, i: usize, d: Vec2) -> bool {
    let m = poly.len();
    let na = poly.inward_normal(i + m - 1);
    let nb = poly.inward_normal(i);
    let (da, db) = (d.dot(na), d.dot(nb));
    let tol = 1e-12;
    if poly.vertex_is_convex(i) {
        da > tol && db > tol
    } else {
        da > tol || db > tol
    }
}

/// Sweep a pin of radius `radius` from world point `start` along the world unit vector `dir` against
/// the part at `pose`; return the first touch with travel ≥ `min_travel`, or `None`.
pub fn first_contact(
    poly: &Polygon,
    pose: &Pose,
    start: Vec2,
    dir: Vec2,
    radius: f64,
    min_travel: f64,
) -> Option<FirstContact> {
    let p = pose.apply_inverse(start);
    let d = dir.rotate(-pose.theta_rad).normalized();
    let scale = poly.radius();
    let tol_t = 1e-12 * scale;
    let m = poly.len();
    // (travel, feature, part-frame contact point, part-frame normal, priority: edge 0 / vertex 1)
    let mut best: Option<(f64, Feature, Vec2, Vec2, u8)> = None;
    let mut consider = |cand: (f64, Feature, Vec2, Vec2, u8)| {
        if cand.0 < min_travel - tol_t {
            return;
        }
        match best {
            None => best = Some(cand),
            Some(b) => {
                if cand.0 < b.0 - tol_t || (cand.0 <= b.0 + tol_t && cand.4 < b.4) {
                    best = Some(cand)
                }
            }
        }
    };
    for i in 0..m {
        let (a, b) = poly.edge(i);
        let e = b - a;
        let len = e.norm();
        let n_in = e.perp() / len;
        if d.dot(n_in) <= 0.0 {
            continue; // back-facing or parallel: the pin cannot strike this edge's face
        }
        let a_off = a - n_in * radius;
        let den = d.cross(e);
        let w = a_off - p;
        let t = w.cross(e) / den;
        let s = w.cross(d) / den;
        let eps = 1e-12 * scale / len;
        // `!(..)` also skips NaN: an edge parallel to the ray to rounding (den = 0 while d·n
        // rounds above 0) has no face touch; its ends are the neighbours' or the vertex loop's.
        if !(t.is_finite() && s >= -eps && s <= 1.0 + eps) {
            continue;
        }
        // A touch within the tolerance of an edge end is that vertex, for point and disc pins alike
        // (for a disc the edge's inward normal is then the centre-to-vertex direction).
        if s <= eps {
            consider((t, Feature::Vertex { index: i }, a, n_in, 1));
        } else if s >= 1.0 - eps {
            consider((t, Feature::Vertex { index: (i + 1) % m }, b, n_in, 1));
        } else {
            consider((t, Feature::Edge { index: i, t: s }, a + e * s, n_in, 0));
        }
    }
    if radius > 0.0 {
        for i in 0..m {
            if !poly.vertex_is_convex(i) {
                continue; // a disc reaches a reflex vertex only through its edges
            }
            let v = poly.vertex(i);
            let w = v - p;
            let tc = w.dot(d);
            // Squared distance from the vertex to the centre's path. From the cross product, not as
            // |w|² − tc², which cancels catastrophically when the pin starts far away.
            let perp2 = w.cross(d).powi(2);
            if perp2 > radius * radius {
                continue;
            }
            let t = tc - (radius * radius - perp2).max(0.0).sqrt();
            let centre = p + d * t;
            let n = (v - centre).normalized();
            // −n must lie in the outward normal cone of the vertex.
            let out_a = -poly.inward_normal(i + m - 1);
            let out_b = -poly.inward_normal(i);
            let o = -n;
            if out_a.cross(o) < -1e-12 || o.cross(out_b) < -1e-12 {
                continue;
            }
            consider((t, Feature::Vertex { index: i }, v, n, 1));
        }
    }
    let (t, feature, point, mut normal, _) = best?;
    let grazing = match feature {
        Feature::Edge { .. } => false,
        Feature::Vertex { index } => {
            if radius > 0.0 {
                // Tangent within tolerance: the vertex lies within 1e-12·a of the disc's swept
                // edge. (Near tangency d·n ~ √(2δ/ρ) for an offset δ, so an angle test alone would
                // call an f64-rounded tangent touch an entering push.)
                let miss = radius - (point - p).cross(d).abs();
                d.dot(normal) <= 1e-12 || miss <= tol_t
            } else {
                !enters_at_vertex(poly, index, d)
            }
        }
    };
    if radius == 0.0 {
        if let Feature::Vertex { index } = feature {
            // A point pin on a vertex: report the bisector of the two inward normals as the normal.
            let na = poly.inward_normal(index + m - 1);
            let nb = poly.inward_normal(index);
            let bis = (na + nb).normalized();
            normal = if bis.norm() > 0.5 { bis } else { na };
        }
    }
    let centre = p + d * t;
    Some(FirstContact {
        travel: t,
        point: pose.apply(point),
        pin_centre: pose.apply(centre),
        feature,
        normal: normal.rotate(pose.theta_rad),
        grazing,
    })
}

/// The belt-frame question (docs/physics.md#frames): a part at `pose` travels in +x toward a pin centred at world
/// `pin` (radius `radius`). Returns how far the part travels before first touch (the same as the
/// pin's travel in −x relative to the part). Points in the answer are for the part held at `pose`
/// and the pin moved back by the travel (the belt-frame picture).
pub fn first_contact_travelling_x(
    poly: &Polygon,
    pose: &Pose,
    pin: Vec2,
    radius: f64,
) -> Option<FirstContact> {
    first_contact(poly, pose, pin, Vec2::new(-1.0, 0.0), radius, 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::named::part_from_spec;

    #[test]
    fn point_pin_hits_edge() {
        let sq = part_from_spec("square").unwrap();
        let c =
            first_contact_travelling_x(&sq, &Pose::default(), Vec2::new(5.0, 0.1), 0.0).unwrap();
        assert!((c.travel - 4.5).abs() < 1e-12);
        assert!(matches!(c.feature, Feature::Edge { index: 1, .. }));
        assert!((c.normal - Vec2::new(-1.0, 0.0)).norm() < 1e-12);
        assert!(!c.grazing);
    }

    #[test]
    fn misses() {
        let sq = part_from_spec("square").unwrap();
        assert!(
            first_contact_travelling_x(&sq, &Pose::default(), Vec2::new(5.0, 0.6), 0.0).is_none()
        );
        assert!(
            first_contact_travelling_x(&sq, &Pose::default(), Vec2::new(-5.0, 0.0), 0.0).is_none()
        );
    }
}
