//! Fences (docs/physics.md#fences): a segment fixed over the belt at angle α to the belt direction, with friction μf.
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
//! The contact model holds these states as features of its contact state
//! (`mechanics::contact_state`); this module gives their geometry and instants (flush edges in closed
//! form), the transitions between them and the fence's first touch.
//!
//! Peshkin & Sanderson's COR-locus tip bounds the push distance needed to align an edge: the `tip`
//! fidelity is that bound, and the exact model must rotate at least as fast (tested).

use super::contact_state::{initial_state, Ctx, Feat, N_EVENTS};
use super::instant::{Instant, Mode};
use crate::geometry::{first_contact, Feature, Polygon, Pose, Vec2};
use serde::Serialize;

/// A fence as the caller gives it (caller's units, world frame at the start of the pass).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FenceSpec {
    /// The upstream end of the fence (where parts first meet it).
    pub start: Vec2,
    /// Angle α of the fence from the belt direction, radians in (−π/2, π/2): positive fences run
    /// downstream to the left (+y), deflecting parts to the left.
    #[serde(rename = "angle")]
    pub angle_rad: f64,
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
        let e = Vec2::from_angle(spec.angle_rad);
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

impl Ctx<'_, '_> {
    /// The flush edge k's supported interval and the point where the force line through the
    /// centroid meets the fence, all as fence coordinates relative to hull vertex k:
    /// (lo, hi, where the force line meets the fence).
    pub(super) fn flush_interval(&self, k: usize, y: [f64; 2], force_dir: Vec2) -> (f64, f64, f64) {
        let f = self.fence_geom();
        let vk = self.to_world(self.poly.vertex(k), y[0]);
        let other = (self.to_world(self.poly.vertex(k + 1), y[0]) - vk).dot(f.e);
        let lo = other.min(0.0).max(-y[1]);
        let hi = other.max(0.0).min(f.len - y[1]);
        // Centroid relative to vertex k is −vk; the line c + λ·dir meets the fence line (through
        // vertex k, normal n) at λ = vk·n / (dir·n).
        let lambda = vk.dot(f.n) / force_dir.dot(f.n);
        let meet = (-vk + force_dir * lambda).dot(f.e);
        (lo, hi, meet)
    }

    /// A flush edge translates (docs/physics.md#fences): sliding with the force on a friction-cone edge, or, in
    /// `Stick` mode, jammed (moving with the fence). The force passes through the centroid; the
    /// margins say how far inside the supported interval it meets the fence.
    pub(super) fn flush_instant(&self, k: usize, y: [f64; 2], mode: Mode) -> Instant {
        let f = self.fence_geom();
        let (dir, v_world) = match mode {
            Mode::SlideLeft | Mode::SlideRight | Mode::Slide => {
                let dir = match mode {
                    Mode::SlideLeft => self.fr.left_edge(f.n),
                    Mode::SlideRight => self.fr.right_edge(f.n),
                    _ => f.n,
                };
                (dir, dir * (f.n.dot(self.vdir) / f.n.dot(dir)))
            }
            Mode::Stick => (self.vdir.normalized(), self.vdir),
        };
        let (lo, hi, meet) = self.flush_interval(k, y, dir);
        let v = self.to_part(v_world, y[0]);
        Instant {
            mode,
            twist: [v.x, v.y, 0.0],
            force: self.to_part(dir, y[0]),
            margins: [meet - lo, hi - meet],
        }
    }

    /// The hull edge adjacent to vertex k that is flush to rounding (its other end within 1e-9 a of
    /// the fence line), if any.
    pub(super) fn flush_neighbour(&self, k: usize, y: [f64; 2]) -> Option<usize> {
        let f = self.fence_geom();
        let m = self.poly.len();
        let v = self.poly.vertex(k);
        let dist = |j: usize| self.to_world(self.poly.vertex(j) - v, y[0]).dot(f.n);
        if dist(k + m - 1).abs() <= 1e-9 {
            Some((k + m - 1) % m)
        } else if dist(k + 1).abs() <= 1e-9 {
            Some(k)
        } else {
            None
        }
    }

    /// The orientation nearest `theta` at which hull edge k lies exactly flush on the fence (its
    /// outward normal against the fence normal). Flush is a geometric fact at the event that finds
    /// it; snapping removes the event's landing error (≤ 1e-2·tol).
    pub(super) fn flush_angle(&self, k: usize, theta: f64) -> f64 {
        let f = self.fence_geom();
        let out = -self.poly.inward_normal(k);
        let target = (-f.n).angle() - out.angle();
        theta + crate::geometry::wrap_pi(target - theta)
    }

    /// The consistent translation mode of a flush edge: slide towards the side the belt's motion
    /// leaves the friction cone on, or `Stick` (a jam) when it lies inside the cone (inclusive:
    /// α + atan μf ≥ 90° jams).
    pub(super) fn flush_mode(&self) -> Mode {
        let f = self.fence_geom();
        if self.fr.mu_c == 0.0 {
            return Mode::Slide;
        }
        let (fl, fr) = (self.fr.left_edge(f.n), self.fr.right_edge(f.n));
        // The cone boundary itself jams (α + atan μf = 90° exactly); 1e-12 absorbs the rounding
        // of the angles so that the condition holds at exactly the predicted angle.
        let v = self.vdir.normalized();
        if fl.cross(v) > 1e-12 {
            Mode::SlideLeft
        } else if fr.cross(v) < -1e-12 {
            Mode::SlideRight
        } else {
            Mode::Stick
        }
    }
}

/// A flush edge whose force line leaves its supported interval pivots about that end: a hull vertex
/// (vertex on the fence line) or the fence's own end (which then acts as a point pin on the edge).
pub(super) fn flush_pivot(ctx: &mut Ctx, k: usize, y: [f64; 2], hi_end: bool) -> (Feat, [f64; 2]) {
    let f = *ctx.fence_geom();
    let m = ctx.poly.len();
    let vk = ctx.to_world(ctx.poly.vertex(k), y[0]);
    let other = (ctx.to_world(ctx.poly.vertex(k + 1), y[0]) - vk).dot(f.e);
    let (lo, hi, _) = ctx.flush_interval(k, y, f.n);
    let end = if hi_end { hi } else { lo };
    if end == 0.0 {
        (Feat::FenceVertex(k), y)
    } else if end == other {
        (Feat::FenceVertex((k + 1) % m), [y[0], y[1] + other])
    } else {
        // A fence end inside the edge: that end pushes the edge like a point pin.
        ctx.start = if end <= -y[1] + 1e-12 { f.p0 } else { f.p1() };
        (Feat::Edge(k), [y[0], end.abs()])
    }
}

/// How a flush edge goes on.
pub(super) enum Flush {
    /// It translates along the fence in its consistent mode (this instant).
    Translate(Instant),
    /// The force line misses the supported interval: it pivots about the nearer end (new state).
    Pivot(Feat, [f64; 2]),
    /// The belt's motion lies inside the friction cone: the part jams.
    Jam,
}

/// Decide how flush hull edge `k` in state `y` goes on (the event bands are reset on a pivot).
pub(super) fn settle_flush(ctx: &mut Ctx, k: usize, y: [f64; 2]) -> Flush {
    let mode = ctx.flush_mode();
    let inst = ctx.flush_instant(k, y, mode);
    // The supported interval is closed (the force may act at an end vertex): rounding-level
    // negatives count as inside.
    let (m0, m1) = (inst.margins[0] + ctx.band[1], inst.margins[1] + ctx.band[2]);
    if m0 < -1e-12 || m1 < -1e-12 {
        // The force line misses the supported interval: pivot about the nearer end.
        ctx.band = [0.0; N_EVENTS];
        let (f, yy) = flush_pivot(ctx, k, y, m1 < m0);
        return Flush::Pivot(f, yy);
    }
    if mode == Mode::Stick {
        return Flush::Jam;
    }
    Flush::Translate(inst)
}

/// Hull edge `j` (a neighbour of hull vertex `k`, which is on the fence line in state `y`) turns
/// flush: the state on the flush edge, its orientation snapped to exactly flush.
pub(super) fn edge_turns_flush(ctx: &Ctx, j: usize, k: usize, y: [f64; 2]) -> (Feat, [f64; 2]) {
    let f = *ctx.fence_geom();
    let th = ctx.flush_angle(j, y[0]);
    let d = (ctx.poly.vertex(j) - ctx.poly.vertex(k))
        .rotate(th)
        .dot(f.e);
    (Feat::FenceEdge(j), [th, y[1] + d])
}

/// Where a geometric event of hull vertex `k` on the fence line leads (event indices of
/// [`Ctx::feature_events`]): 3 / 4, the edge before / after the vertex turns flush; 5 / 6, the
/// vertex slides off the upstream / downstream end of the fence, which then acts as a point pin on
/// the part.
pub(super) fn fence_vertex_event(
    ctx: &mut Ctx,
    i: usize,
    k: usize,
    y: [f64; 2],
) -> (Feat, [f64; 2]) {
    let m = ctx.poly.len();
    match i {
        // The edge before vertex k turns flush: its start vertex k−1 reached the line.
        3 => edge_turns_flush(ctx, (k + m - 1) % m, k, y),
        4 => (Feat::FenceEdge(k), [ctx.flush_angle(k, y[0]), y[1]]),
        5 | 6 => {
            let f = *ctx.fence_geom();
            ctx.start = if i == 5 { f.p0 } else { f.p1() };
            (Feat::Vertex(k), [y[0], f.n.rotate(-y[0]).angle()])
        }
        _ => unreachable!("not a fence-vertex event"),
    }
}

/// The contact state at the next touch of fence `f` on the part resting at `cur`, from travel
/// `s_from` (normalised units): (travel, feature, state). A fence end that strikes first becomes
/// the pin of the contact (`ctx.start`).
pub(super) fn next_fence_touch(
    ctx: &mut Ctx,
    f: &FenceGeom,
    cur: &Pose,
    s_from: f64,
) -> Option<(f64, Feat, [f64; 2])> {
    match first_touch(ctx.poly, cur, f, ctx.vdir, s_from)? {
        (t, FenceTouch::LineVertex { k, sigma }) => {
            Some((t, Feat::FenceVertex(k), [cur.theta_rad, sigma]))
        }
        (t, FenceTouch::LineEdge { k, sigma }) => {
            Some((t, Feat::FenceEdge(k), [cur.theta_rad, sigma]))
        }
        (t, FenceTouch::End { end, feature }) => {
            ctx.start = if end == 0 { f.p0 } else { f.p1() };
            let n = ctx.vdir.normalized();
            let (feat, y) = initial_state(ctx, cur, feature, n);
            Some((t, feat, y))
        }
    }
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
                    angle_rad: a.to_radians(),
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
                angle_rad: 45f64.to_radians(),
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
