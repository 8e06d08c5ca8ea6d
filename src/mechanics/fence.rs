//! Fences (SPEC §6): a segment fixed over the belt at angle α to the belt direction, with friction μf.
//!
//! In the belt frame the fence translates at v = (−V, 0), like a fixed pin. Only the part's convex
//! hull can touch a straight fence. A contact passes through these states, all integrated by
//! [`super::integrate`] with the same instant solve as pins:
//!
//! * **vertex on the fence line**: a hull vertex slides (or sticks) on the line; the contact normal
//!   is the fence normal, the contact friction μf. The part turns until an adjacent hull edge lies
//!   flush.
//! * **flush edge**: a pure translation. The part slides along the fence with the force on the
//!   friction-cone edge, which for a translation must pass through the centroid: this is consistent
//!   only while the line through the centroid along that force meets the supported part of the edge
//!   (the part of it still on the fence); otherwise the part pivots about the nearer end — a hull
//!   vertex (back to vertex-on-line) or the fence's end (a point pin). If the belt's motion relative
//!   to the fence lies inside the friction cone (α + atan μf ≥ 90°) the part cannot slide: it
//!   **jams**, stopping in the world while the belt slips under it. That is reported
//!   ([`super::ContactStatus::Jam`]), never integrated.
//! * **past an end**: once the contact reaches a fence end, that end acts as a point pin moving
//!   with the fence, handled by the pin model; the part leaves when it separates.
//!
//! Peshkin & Sanderson's COR-locus tip bounds the push distance needed to align an edge: the `tip`
//! fidelity is that bound, and the exact model must rotate at least as fast (tested).

use crate::geometry::{first_contact, Feature, Polygon, Pose, Vec2};
use serde::Serialize;

/// A fence as the caller gives it (caller's units, world frame at the start of the pass).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FenceSpec {
    /// The upstream end of the fence (where parts first meet it).
    pub start: Vec2,
    /// Angle α of the fence from the belt direction, radians in (−π/2, π/2): positive fences run
    /// downstream to the left (+y), deflecting parts to the left.
    pub angle: f64,
    /// Length along the fence.
    pub length: f64,
    /// Fence–part friction coefficient μf ≥ 0.
    pub mu_f: f64,
}

/// A fence in normalised units: the segment p0 → p0 + len·e, normal n into the part's side, all
/// moving with the belt-frame velocity of fixed obstacles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FenceGeom {
    pub p0: Vec2,
    pub e: Vec2,
    pub n: Vec2,
    pub len: f64,
}

impl FenceGeom {
    pub fn new(spec: &FenceSpec, scale: f64) -> FenceGeom {
        let e = Vec2::from_angle(spec.angle);
        // The normal facing upstream (−x): parts arrive from there.
        let mut n = e.perp();
        if n.x > 0.0 {
            n = -n;
        }
        FenceGeom {
            p0: spec.start / scale,
            e,
            n,
            len: spec.length / scale,
        }
    }
    /// The far (downstream) end at travel 0.
    pub fn p1(&self) -> Vec2 {
        self.p0 + self.e * self.len
    }
}

/// How a part first meets a fence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum FenceTouch {
    /// Hull vertex `k` meets the fence line at fence coordinate `sigma`.
    LineVertex { k: usize, sigma: f64 },
    /// Hull edge `k` meets the fence line flush; `sigma` is the fence coordinate of vertex k.
    LineEdge { k: usize, sigma: f64 },
    /// Fence end `end` (0 upstream, 1 downstream) strikes the hull like a point pin.
    End { end: usize, feature: Feature },
}

/// First touch between the part (hull `hull`, at rest at `pose`, normalised units) and the fence
/// moving along `vdir` from travel `s_from`: (travel s, touch).
pub(crate) fn first_touch(
    hull: &Polygon,
    pose: &Pose,
    f: &FenceGeom,
    vdir: Vec2,
    s_from: f64,
) -> Option<(f64, FenceTouch)> {
    let speed_n = vdir.dot(f.n);
    if speed_n <= 1e-12 {
        return None; // a fence parallel to the belt pushes nothing
    }
    let tol = 1e-12;
    let m = hull.len();
    let mut best: Option<(f64, FenceTouch)> = None;
    let mut consider = |t: f64, touch: FenceTouch| {
        if t < s_from - tol {
            return;
        }
        match best {
            Some((bt, _)) if bt <= t + tol => {}
            _ => best = Some((t, touch)),
        }
    };
    // Vertices against the moving line: (v − p0 − s·vdir)·n = 0.
    let world: Vec<Vec2> = hull.vertices().iter().map(|&v| pose.apply(v)).collect();
    let mut line_hits: Vec<(f64, usize, f64)> = Vec::new();
    for (k, &v) in world.iter().enumerate() {
        let t = (v - f.p0).dot(f.n) / speed_n;
        let sigma = (v - f.p0 - vdir * t).dot(f.e);
        // Strictly inside: a vertex meeting the line exactly at an end meets that end, which the
        // point-pin cast below handles (this keeps the decision at a fence end unambiguous).
        let end_tol = 1e-9 * f.len.max(1.0);
        if sigma > end_tol && sigma < f.len - end_tol {
            line_hits.push((t, k, sigma));
        }
    }
    if let Some(&(t, k, sigma)) = line_hits.iter().min_by(|a, b| a.0.total_cmp(&b.0)) {
        // Two adjacent vertices at the same travel: the edge arrives flush.
        let next = (k + 1) % m;
        let prev = (k + m - 1) % m;
        let flush_next = line_hits
            .iter()
            .any(|h| h.1 == next && (h.0 - t).abs() <= 1e-12);
        let flush_prev = line_hits
            .iter()
            .any(|h| h.1 == prev && (h.0 - t).abs() <= 1e-12);
        if flush_next {
            consider(t, FenceTouch::LineEdge { k, sigma });
        } else if flush_prev {
            let sp = (world[prev] - f.p0 - vdir * t).dot(f.e);
            consider(t, FenceTouch::LineEdge { k: prev, sigma: sp });
        } else {
            consider(t, FenceTouch::LineVertex { k, sigma });
        }
    }
    // The fence's ends strike like point pins.
    let dir = vdir.normalized();
    for (end, p) in [(0usize, f.p0), (1usize, f.p1())] {
        let start = p + vdir * s_from;
        if let Some(hit) = first_contact(hull, pose, start, dir, 0.0, 0.0) {
            if !hit.grazing {
                consider(
                    s_from + hit.travel / vdir.norm(),
                    FenceTouch::End {
                        end,
                        feature: hit.feature,
                    },
                );
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;

    #[test]
    fn normal_faces_upstream() {
        for a in [-60.0f64, -10.0, 10.0, 45.0, 80.0] {
            let g = FenceGeom::new(
                &FenceSpec {
                    start: Vec2::ZERO,
                    angle: a.to_radians(),
                    length: 1.0,
                    mu_f: 0.3,
                },
                1.0,
            );
            assert!(g.n.x < 0.0 && (g.n.dot(g.e)).abs() < 1e-15);
        }
    }

    #[test]
    fn square_meets_a_45_degree_fence_at_a_vertex() {
        let sq = part_from_spec("square").unwrap();
        let f = FenceGeom::new(
            &FenceSpec {
                start: Vec2::new(2.0, -3.0),
                angle: 45f64.to_radians(),
                length: 10.0,
                mu_f: 0.3,
            },
            1.0,
        );
        let (t, touch) = first_touch(&sq, &Pose::default(), &f, Vec2::new(-1.0, 0.0), 0.0).unwrap();
        // The line y = x − 5 moving left meets the square's lower-right corner (0.5, −0.5) when
        // shifted to y = x − 1: travel 4.
        assert!((t - 4.0).abs() < 1e-12, "{t}");
        assert!(matches!(touch, FenceTouch::LineVertex { .. }));
        // A square at 45° offers an edge flush to a 45° fence.
        let (_, touch) = first_touch(
            &sq,
            &Pose::new(0.0, 0.0, 45f64.to_radians()),
            &f,
            Vec2::new(-1.0, 0.0),
            0.0,
        )
        .unwrap();
        assert!(matches!(touch, FenceTouch::LineEdge { .. }), "{touch:?}");
    }
}
