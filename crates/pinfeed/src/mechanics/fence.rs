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
//! * **on the tail** (a fence with [`FenceSpec::tail_radius`]): the downstream end is no end but
//!   the start of a circular arc of radius R tangent to the fence that turns it parallel to the
//!   belt (Brokowski, Peshkin & Goldberg). Seen from the part the arc is convex, its centre on the
//!   far side: a hull edge tangent to it, or a hull vertex on it, is exactly the contact of a disc
//!   pin of radius R centred there (the arc is fixed in the world like a pin), so the pin model
//!   integrates it, its contact normal held to the arc's span by an event at the span's start
//!   (the contact goes back onto the straight fence). At the span's end the normal is
//!   perpendicular to the belt: the contact separates there, the edge parallel to the belt.
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
    /// Radius of the fence's curved tail (caller's units), if it has one: a circular arc tangent
    /// to the fence at its downstream end that turns it from α to 0, parallel to the belt
    /// (docs/physics.md#fences). `None` ends the fence abruptly; a fence at 0° has no tail.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tail_radius: Option<f64>,
}

impl FenceSpec {
    /// The straight fence from `start` at `angle_rad` for `length`, friction `mu_f`, no tail.
    pub fn straight(start: Vec2, angle_rad: f64, length: f64, mu_f: f64) -> FenceSpec {
        FenceSpec {
            start,
            angle_rad,
            length,
            mu_f,
            tail_radius: None,
        }
    }

    /// The same fence with a tail of radius `radius` (`None`: without one).
    pub fn with_tail(self, radius: Option<f64>) -> FenceSpec {
        FenceSpec {
            tail_radius: radius,
            ..self
        }
    }

    /// The downstream end of the straight part (where a tail begins).
    pub fn straight_end(&self) -> Vec2 {
        self.start + Vec2::from_angle(self.angle_rad) * self.length
    }

    /// The fence's tail as an arc (caller's units), if it has one: (centre, radius, the normal
    /// into the part's side at its start and at its end). The arc runs from the straight end
    /// `centre + radius·n_start` to the fence's far end `centre + radius·n_end`, turning by −α.
    pub fn tail_arc(&self) -> Option<(Vec2, f64, Vec2, Vec2)> {
        let r = self.tail_radius?;
        if self.angle_rad.abs() <= 1e-12 || r.is_nan() || r <= 0.0 {
            return None;
        }
        let n = part_side_normal(self.angle_rad);
        let centre = self.straight_end() - n * r;
        Some((centre, r, n, Vec2::new(0.0, self.angle_rad.signum())))
    }

    /// The fence's far (downstream) end: the tail's end if it has one, else the straight end.
    pub fn far_end(&self) -> Vec2 {
        match self.tail_arc() {
            Some((c, r, _, n_end)) => c + n_end * r,
            None => self.straight_end(),
        }
    }

    /// Points along the whole fence (caller's units), upstream to downstream: the start, then the
    /// tail's arc in `arc_points` pieces (or the straight end alone), for drawings.
    pub fn polyline(&self, arc_points: usize) -> Vec<Vec2> {
        let mut pts = vec![self.start];
        match self.tail_arc() {
            Some((c, r, n, _)) => {
                let k = arc_points.max(1);
                for i in 0..=k {
                    let t = i as f64 / k as f64;
                    pts.push(c + n.rotate(-self.angle_rad * t) * r);
                }
            }
            None => pts.push(self.straight_end()),
        }
        pts
    }
}

/// The unit normal of a fence at angle `angle_rad` facing upstream (−x), into the side parts
/// arrive from.
fn part_side_normal(angle_rad: f64) -> Vec2 {
    let mut n = Vec2::from_angle(angle_rad).perp();
    if n.x > 0.0 {
        n = -n;
    }
    n
}

/// A fence in normalised units: the segment p0 → p0 + len·e, normal n into the part's side, all
/// moving with the belt-frame velocity of fixed obstacles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FenceGeom {
    pub p0: Vec2,
    pub e: Vec2,
    pub n: Vec2,
    pub len: f64,
    /// The curved tail beyond p1, if any.
    pub tail: Option<TailGeom>,
}

/// A fence's tail in normalised units: the arc of the circle of radius `radius` about `centre`
/// (at travel 0) from normal `n` (the fence's, at p1) turning by `sweep` = −α to the normal
/// perpendicular to the belt; the normals point into the part's side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TailGeom {
    pub centre: Vec2,
    pub radius: f64,
    pub sweep: f64,
}

impl TailGeom {
    /// The arc's far end at travel 0.
    pub fn end(&self, n: Vec2) -> Vec2 {
        self.centre + n.rotate(self.sweep) * self.radius
    }
    /// How far (a sine) the unit normal `u` lies past the arc's start `n`, towards its end:
    /// positive inside the span, zero at its start.
    pub fn past_start(&self, n: Vec2, u: Vec2) -> f64 {
        self.sweep.signum() * n.cross(u)
    }
    /// How far (a sine) the unit normal `u` lies before the arc's end (`n` its start): positive
    /// inside the span, zero at its end.
    pub fn before_end(&self, n: Vec2, u: Vec2) -> f64 {
        -self.sweep.signum() * n.rotate(self.sweep).cross(u)
    }
    /// Does unit normal `u` lie on the arc's span (from its start `n` through `sweep`), to `tol`
    /// radians?
    pub fn spans(&self, n: Vec2, u: Vec2, tol: f64) -> bool {
        let beta = n.cross(u).atan2(n.dot(u)) * self.sweep.signum();
        beta >= -tol && beta <= self.sweep.abs() + tol
    }
}

impl FenceGeom {
    pub fn new(spec: &FenceSpec, scale: f64) -> FenceGeom {
        let e = Vec2::from_angle(spec.angle_rad);
        // The normal facing upstream (−x): parts arrive from there.
        let n = part_side_normal(spec.angle_rad);
        FenceGeom {
            p0: spec.start / scale,
            e,
            n,
            len: spec.length / scale,
            tail: spec.tail_arc().map(|(c, r, _, _)| TailGeom {
                centre: c / scale,
                radius: r / scale,
                sweep: -spec.angle_rad,
            }),
        }
    }
    /// The downstream end of the straight part at travel 0 (where a tail begins).
    pub fn p1(&self) -> Vec2 {
        self.p0 + self.e * self.len
    }
    /// End `end` of the fence at travel 0: 0 upstream, 1 the straight part's downstream end,
    /// 2 the tail's far end.
    pub fn end_point(&self, end: usize) -> Vec2 {
        match (end, self.tail) {
            (0, _) => self.p0,
            (2, Some(t)) => t.end(self.n),
            _ => self.p1(),
        }
    }
}

/// The fence `spec` with its tail replaced by `n` straight pieces (tests: the arc model against
/// straight fences): the tangent polygon of the tail's arc — n + 1 tangent lines at angles
/// α(1 − j/n), the first the fence's own line, the last parallel to the belt — with its corners
/// rounded to radius `corner` (caller's units, well below the tail's radius), the last corner
/// being the chain's own tail. Normalised by `scale`. `None` without a tail.
#[cfg(test)]
pub(crate) fn tangent_chain(
    spec: &FenceSpec,
    n: usize,
    corner: f64,
    scale: f64,
) -> Option<Vec<FenceGeom>> {
    let (c, r, n0, _) = spec.tail_arc()?;
    let alpha = spec.angle_rad;
    let n = n.max(1);
    let step = alpha / n as f64;
    let normal = |j: usize| n0.rotate(-step * j as f64);
    let dir = |j: usize| Vec2::from_angle(alpha - step * j as f64);
    // Corner j (1..=n) joins tangent lines j − 1 and j.
    let knee = |j: usize| c + (normal(j - 1) + normal(j)).normalized() * (r / (step / 2.0).cos());
    let t = corner * (step / 2.0).abs().tan();
    let mut chain = Vec::with_capacity(n);
    let mut start = spec.start;
    for j in 0..n {
        let end = knee(j + 1) - dir(j) * t;
        let len = (end - start).dot(dir(j));
        chain.push(FenceGeom {
            p0: start / scale,
            e: dir(j),
            n: normal(j),
            len: len / scale,
            tail: Some(TailGeom {
                centre: (end - normal(j) * corner) / scale,
                radius: corner / scale,
                sweep: -step,
            }),
        });
        start = knee(j + 1) + dir(j + 1) * t;
    }
    Some(chain)
}

/// How a part first meets a fence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum FenceTouch {
    /// Hull vertex `k` meets the fence line at fence coordinate `sigma`.
    LineVertex { k: usize, sigma: f64 },
    /// Hull edge `k` meets the fence line flush; `sigma` is the fence coordinate of vertex k.
    LineEdge { k: usize, sigma: f64 },
    /// Fence end `end` ([`FenceGeom::end_point`]) strikes the hull like a point pin.
    End { end: usize, feature: Feature },
    /// The tail's arc touches the hull at `feature` with the contact normal `normal` (world,
    /// into the part).
    Arc { feature: Feature, normal: Vec2 },
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
    first_touch_chain(hull, pose, std::slice::from_ref(f), vdir, s_from)
        .map(|(t, touch, _)| (t, touch))
}

/// First touch between the part and a chain of fence pieces (see [`Ctx::chain`]): (travel s,
/// touch, the piece touched). Only the first piece's upstream end and the last piece's far end
/// are ends; the pieces meet at their arcs.
pub(crate) fn first_touch_chain(
    hull: &Polygon,
    pose: &Pose,
    chain: &[FenceGeom],
    vdir: Vec2,
    s_from: f64,
) -> Option<(f64, FenceTouch, usize)> {
    let tol = 1e-12;
    let mut best: Option<(f64, FenceTouch, usize)> = None;
    let mut consider = |t: f64, touch: FenceTouch, piece: usize| {
        if t < s_from - tol {
            return;
        }
        match best {
            Some((bt, _, _)) if bt <= t + tol => {}
            _ => best = Some((t, touch, piece)),
        }
    };
    let world: Vec<Vec2> = hull.vertices().iter().map(|&v| pose.apply(v)).collect();
    let last = chain.len() - 1;
    for (i, f) in chain.iter().enumerate() {
        if let Some((t, touch)) = line_touch(hull, &world, f, vdir, i > 0, s_from) {
            consider(t, touch, i);
        }
        // The piece's arc, where it touches with a normal on its span.
        if let Some(tail) = f.tail {
            if let Some((t, feature, normal)) = arc_touch(&world, f, &tail, vdir) {
                consider(t, FenceTouch::Arc { feature, normal }, i);
            }
        }
    }
    // The fence's ends strike like point pins: the upstream end, and the downstream end of the
    // straight part or of the tail.
    let dir = vdir.normalized();
    let far = if chain[last].tail.is_some() { 2 } else { 1 };
    for (piece, end) in [(0, 0usize), (last, far)] {
        let p = chain[piece].end_point(end);
        let start = p + vdir * s_from;
        if let Some(hit) = first_contact(hull, pose, start, dir, 0.0, 0.0) {
            if !hit.grazing {
                consider(
                    s_from + hit.travel / vdir.norm(),
                    FenceTouch::End {
                        end,
                        feature: hit.feature,
                    },
                    piece,
                );
            }
        }
    }
    best
}

/// How near an end (normalised units: the part's a) a vertex on the line at the current travel
/// counts as at the end: above the landing error of an event at any tolerance the contact model
/// takes (at most 10⁻²·tol, tol ≤ 10⁻³).
const END_LANDING: f64 = 1e-5;

/// The first touch of the hull (vertices `world`) on the straight line of fence piece `f`, strictly
/// between its ends (`joined`: its upstream end is the previous piece's arc). Travel may be
/// negative (the caller filters). A vertex that meets the line now (within [`END_LANDING`] of
/// travel `s_from`) within as much of an end lies at that end: the event that put it there (a
/// pivot about the end letting go as the edge's far vertex reaches it) lands within that of the
/// end, and taking it for a touch of the line would start a contact the part is leaving (the
/// end's own cast decides whether it strikes).
fn line_touch(
    hull: &Polygon,
    world: &[Vec2],
    f: &FenceGeom,
    vdir: Vec2,
    joined: bool,
    s_from: f64,
) -> Option<(f64, FenceTouch)> {
    let speed_n = vdir.dot(f.n);
    if speed_n <= 1e-12 {
        return None; // a fence parallel to the belt pushes nothing
    }
    let m = hull.len();
    // Vertices against the moving line: (v − p0 − s·vdir)·n = 0.
    let mut line_hits: Vec<(f64, usize, f64)> = Vec::new();
    for (k, &v) in world.iter().enumerate() {
        let t = (v - f.p0).dot(f.n) / speed_n;
        let sigma = (v - f.p0 - vdir * t).dot(f.e);
        // Strictly inside: a vertex meeting the line exactly at an end meets that end, which the
        // point-pin cast handles (this keeps the decision at a fence end unambiguous). An end
        // joined to an arc is the arc's, whose cast meets it.
        let now = (t - s_from).abs() <= END_LANDING;
        let end_tol = if now { END_LANDING } else { 0.0 }.max(1e-9 * f.len.max(1.0));
        let lo = if joined { 0.0 } else { end_tol };
        let hi = if f.tail.is_some() {
            f.len
        } else {
            f.len - end_tol
        };
        if sigma > lo && sigma < hi {
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
        return Some(if flush_next {
            (t, FenceTouch::LineEdge { k, sigma })
        } else if flush_prev {
            let sp = (world[prev] - f.p0 - vdir * t).dot(f.e);
            (t, FenceTouch::LineEdge { k: prev, sigma: sp })
        } else {
            (t, FenceTouch::LineVertex { k, sigma })
        });
    }
    None
}

/// The first touch of a tail's arc (the circle about `tail.centre`, moving along `vdir`, at
/// normals on its span) with the convex hull whose vertices are `world`: (travel, feature, contact
/// normal into the part). An arc touches an edge face with the edge's inward normal, or a vertex
/// with the normal from the centre to the vertex inside the vertex's normal cone; only touches
/// that push (the normal against the direction of travel) count. Travel may be negative (the
/// caller filters).
fn arc_touch(
    world: &[Vec2],
    f: &FenceGeom,
    tail: &TailGeom,
    vdir: Vec2,
) -> Option<(f64, Feature, Vec2)> {
    let m = world.len();
    let speed = vdir.norm();
    let dn = vdir / speed;
    let r = tail.radius;
    // A normal within 1e-9 a of the span (as a distance along the arc) is on it.
    let tol = 1e-9 / r + 1e-12;
    let mut best: Option<(f64, Feature, Vec2)> = None;
    let mut keep = |t: f64, feat: Feature, u: Vec2| {
        if t.is_finite() && best.is_none_or(|b: (f64, Feature, Vec2)| t < b.0) {
            best = Some((t, feat, u));
        }
    };
    let inward = |k: usize| {
        let (a, b) = (world[k], world[(k + 1) % m]);
        (b - a).perp().normalized()
    };
    let eps = 1e-12;
    for k in 0..m {
        let (a, b) = (world[k], world[(k + 1) % m]);
        let u = inward(k);
        let push = dn.dot(u);
        if push <= 1e-12 || !tail.spans(f.n, u, tol) {
            continue;
        }
        // The arc's point centre + r·u reaches the edge's line: (c + dn·τ + r·u − a)·u = 0.
        let tau = ((a - tail.centre).dot(u) - r) / push;
        let q = tail.centre + dn * tau + u * r;
        let e = b - a;
        let frac = (q - a).dot(e) / e.norm2();
        if frac > eps && frac < 1.0 - eps {
            keep(tau / speed, Feature::Edge { index: k, t: frac }, u);
        }
    }
    for (k, &v) in world.iter().enumerate() {
        let w = v - tail.centre;
        let perp = w.cross(dn);
        if perp * perp > r * r {
            continue;
        }
        let tau = w.dot(dn) - (r * r - perp * perp).max(0.0).sqrt();
        let u = (v - tail.centre - dn * tau).normalized();
        if dn.dot(u) <= 1e-12 || !tail.spans(f.n, u, tol) {
            continue;
        }
        // −u in the vertex's outward normal cone (the edges' inward normals bound u).
        let (na, nb) = (inward((k + m - 1) % m), inward(k));
        if na.cross(u) < -1e-12 || u.cross(nb) < -1e-12 {
            continue;
        }
        keep(tau / speed, Feature::Vertex { index: k }, u);
    }
    best
}

impl Ctx<'_, '_> {
    /// Make the fence's point `p` (at travel 0) the pin of the contact: a point pin.
    pub(super) fn fence_point_pin(&mut self, p: Vec2) {
        self.start = p;
        self.rho = 0.0;
        self.arc = false;
    }

    /// Make the fence's tail the pin of the contact: a disc of the tail's radius about its centre.
    pub(super) fn fence_arc_pin(&mut self) {
        let t = self.fence_geom().tail.expect("a tail");
        self.start = t.centre;
        self.rho = t.radius;
        self.arc = true;
    }

    /// The contact passes the straight part's downstream end: onto the tail if there is one, else
    /// that end acts as a point pin.
    pub(super) fn past_straight_end(&mut self) {
        let f = *self.fence_geom();
        if f.tail.is_some() {
            self.fence_arc_pin();
        } else {
            self.fence_point_pin(f.p1());
        }
    }

    /// The contact passes the straight part's upstream end: back onto the previous piece's arc if
    /// the fence is a chain and this is not its first piece, else that end acts as a point pin.
    pub(super) fn past_straight_start(&mut self) {
        if self.piece > 0 {
            self.set_piece(self.piece - 1);
            self.fence_arc_pin();
        } else {
            let p0 = self.fence_geom().p0;
            self.fence_point_pin(p0);
        }
    }

    /// Piece `i` of the chain is the fence in contact.
    pub(super) fn set_piece(&mut self, i: usize) {
        self.piece = i;
        self.fence = Some(self.chain[i]);
    }

    /// On a fence's arc, with a pin feature: the arc, its start normal and the contact normal
    /// (world).
    fn arc_contact(&self, feat: Feat, y: [f64; 2]) -> Option<(TailGeom, Vec2, Vec2)> {
        if !self.arc {
            return None;
        }
        let f = self.fence_geom();
        let u_part = match feat {
            Feat::Edge(k) => self.poly.inward_normal(k),
            Feat::Vertex(_) => Vec2::from_angle(y[1]),
            _ => return None,
        };
        Some((f.tail?, f.n, self.to_world(u_part, y[0])))
    }

    /// On a fence's arc: how far the contact normal of `feat` (a pin feature) lies past the
    /// arc's start (a sine; see [`TailGeom::past_start`]); 1 off the arc.
    pub(super) fn arc_start_event(&self, feat: Feat, y: [f64; 2]) -> f64 {
        self.arc_contact(feat, y)
            .map_or(1.0, |(tail, n, u)| tail.past_start(n, u))
    }

    /// On an arc that the fence goes on beyond (a chain's corner): how far (a sine) the contact
    /// normal of `feat` lies before the arc's end; 1 elsewhere (a tail's end is where the contact
    /// separates, its normal perpendicular to the belt).
    pub(super) fn arc_end_event(&self, feat: Feat, y: [f64; 2]) -> f64 {
        if self.piece + 1 >= self.chain.len() {
            return 1.0;
        }
        self.arc_contact(feat, y)
            .map_or(1.0, |(tail, n, u)| tail.before_end(n, u))
    }

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
        // A fence end inside the edge: that end pushes the edge like a point pin, or the edge
        // rolls onto the tail (tangent to it at the tail's start).
        if end <= -y[1] + 1e-12 {
            ctx.past_straight_start();
        } else {
            ctx.past_straight_end();
        }
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
            // The end acts as a point pin on the vertex (its normal the fence's), or the vertex
            // slides onto the tail at the arc's start (the same normal).
            let f = *ctx.fence_geom();
            if i == 5 {
                ctx.past_straight_start();
            } else {
                ctx.past_straight_end();
            }
            (Feat::Vertex(k), [y[0], f.n.rotate(-y[0]).angle()])
        }
        _ => unreachable!("not a fence-vertex event"),
    }
}

/// On the tail, the contact normal of `feat` turned back past the arc's start (event 5 of a pin
/// feature): the contact goes back onto the straight fence at its downstream end — a vertex onto
/// the fence line there, an edge flush on it (its orientation snapped to exactly flush).
pub(super) fn arc_back_to_line(ctx: &mut Ctx, feat: Feat, y: [f64; 2]) -> (Feat, [f64; 2]) {
    let f = *ctx.fence_geom();
    ctx.fence_point_pin(f.p1());
    match feat {
        Feat::Vertex(k) => (Feat::FenceVertex(k), [y[0], f.len]),
        Feat::Edge(k) => {
            let th = ctx.flush_angle(k, y[0]);
            let along = ctx.to_world(ctx.poly.edge_dir(k), th).dot(f.e);
            (Feat::FenceEdge(k), [th, f.len - y[1] * along])
        }
        _ => unreachable!("only a pin feature lies on the tail"),
    }
}

/// A chain's corner arc: the contact normal of `feat` reached the arc's end (event 6 of a pin
/// feature), and the contact goes on onto the next piece's straight line at its upstream end — a
/// vertex onto the line there, an edge flush on it (its orientation snapped to exactly flush).
pub(super) fn arc_on_to_next_line(ctx: &mut Ctx, feat: Feat, y: [f64; 2]) -> (Feat, [f64; 2]) {
    ctx.set_piece(ctx.piece + 1);
    let f = *ctx.fence_geom();
    ctx.fence_point_pin(f.p1());
    match feat {
        Feat::Vertex(k) => (Feat::FenceVertex(k), [y[0], 0.0]),
        Feat::Edge(k) => {
            let th = ctx.flush_angle(k, y[0]);
            let along = ctx.to_world(ctx.poly.edge_dir(k), th).dot(f.e);
            (Feat::FenceEdge(k), [th, -y[1] * along])
        }
        _ => unreachable!("only a pin feature lies on an arc"),
    }
}

/// The contact state at the next touch of the fence (the chain `ctx.chain`) on the part resting
/// at `cur`, from travel `s_from` (normalised units): (travel, feature, state). A fence end that
/// strikes first becomes the pin of the contact (`ctx.start`).
pub(super) fn next_fence_touch(
    ctx: &mut Ctx,
    cur: &Pose,
    s_from: f64,
) -> Option<(f64, Feat, [f64; 2])> {
    let (t, touch, piece) = first_touch_chain(ctx.poly, cur, &ctx.chain, ctx.vdir, s_from)?;
    ctx.set_piece(piece);
    let f = *ctx.fence_geom();
    // The fence line's own features need no pin; reset it.
    ctx.fence_point_pin(f.p1());
    match (t, touch) {
        (t, FenceTouch::LineVertex { k, sigma }) => {
            Some((t, Feat::FenceVertex(k), [cur.theta_rad, sigma]))
        }
        (t, FenceTouch::LineEdge { k, sigma }) => {
            Some((t, Feat::FenceEdge(k), [cur.theta_rad, sigma]))
        }
        (t, FenceTouch::End { end, feature }) => {
            ctx.fence_point_pin(f.end_point(end));
            let n = ctx.vdir.normalized();
            let (feat, y) = initial_state(ctx, cur, feature, n);
            Some((t, feat, y))
        }
        (t, FenceTouch::Arc { feature, normal }) => {
            ctx.fence_arc_pin();
            let (feat, y) = initial_state(ctx, cur, feature, normal);
            Some((t, feat, y))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;
    use crate::maps::fence_pass_start;
    use crate::mechanics::pass::push_fence_chain;
    use crate::mechanics::{push_fence, ContactOutcome, ContactSettings, PartModel, Support};

    /// The final pose's distance between two passes: |Δθ| (radians) and |Δc| / a.
    fn pose_gap(p: &ContactOutcome, q: &ContactOutcome, a: f64) -> f64 {
        let (u, v) = (p.pose_final, q.pose_final);
        let dc = Vec2::new(u.x - v.x, u.y - v.y).norm() / a;
        (u.theta_rad - v.theta_rad).abs().max(dc)
    }

    /// The tail's arc against its tangent polygon of n straight pieces (corners rounded to
    /// 10⁻⁴ a, the last corner the chain's own tail): the final pose (θ in radians, the centroid
    /// in units of a) converges to the arc's as n grows. Observed (tol 1e-9), from n = 2 to 128:
    /// the square at 30° (R = 3a) 9.4e-2 → 1.2e-4, about n^−1.8 (each doubling ×3.5 from n = 16);
    /// tripoly2 at 35° (R = 1.5a) 9.6e-2 → 8.9e-5, n^−1.8; tripoly2 at −40° (R = 4a) 0.31 →
    /// 2.2e-3, n^−1.2 (its worst θ0). Asserted: the gap shrinks with every doubling from n = 4,
    /// by ≥ 16× from n = 8 to 128 (order ≥ 1), below 5e-3 at n = 128.
    #[test]
    fn a_tail_agrees_with_ever_finer_straight_pieces() {
        // A chain of n pieces takes a few events per corner.
        let settings = ContactSettings {
            tol: 1e-9,
            max_events: 4000,
            ..ContactSettings::default()
        };
        let ns = [2usize, 4, 8, 16, 32, 64, 128];
        for (name, alpha, radius_a) in [
            ("square", 30.0, 3.0),
            ("tripoly2", -40.0, 4.0),
            ("tripoly2", 35.0, 1.5),
        ] {
            let poly = part_from_spec(name).unwrap();
            let model = PartModel::new(&poly, &Support::Uniform).unwrap();
            let a = poly.radius();
            let spec = fence_pass_start(&poly, 0.0, alpha, Some(6.0 * a), 0.5)
                .with_tail(Some(radius_a * a));
            for th in [10.0f64, 75.0, 140.0, 200.0, 290.0] {
                let pose = Pose::new(0.0, 0.0, th.to_radians());
                let arc = push_fence(&model, pose, &spec, &settings, None);
                assert!(arc.status.is_ok(), "{name} θ0 {th}: {:?}", arc.status);
                assert!(
                    arc.segments
                        .iter()
                        .any(|s| matches!(s.feature, crate::mechanics::ContactFeature::Edge(_))),
                    "{name} θ0 {th}: no edge rolled on the tail"
                );
                let gaps: Vec<f64> = ns
                    .iter()
                    .map(|&n| {
                        let chain = tangent_chain(&spec, n, 1e-4 * a, model.scale()).unwrap();
                        let out = push_fence_chain(&model, pose, chain, spec.mu_f, &settings, None);
                        assert!(out.status.is_ok(), "{name} θ0 {th} n {n}: {:?}", out.status);
                        pose_gap(&arc, &out, a)
                    })
                    .collect();
                let what = format!(
                    "{name} α {alpha} θ0 {th}: gaps {:?}",
                    gaps.iter().map(|g| format!("{g:.2e}")).collect::<Vec<_>>()
                );
                assert!(gaps[1..].windows(2).all(|w| w[1] < w[0]), "{what}");
                assert!(gaps[2] / gaps[6] >= 16.0, "{what}");
                assert!(gaps[6] < 5e-3, "{what}");
            }
        }
    }

    #[test]
    fn normal_faces_upstream() {
        for a in [-60.0f64, -10.0, 10.0, 45.0, 80.0] {
            let g = FenceGeom::new(
                &FenceSpec {
                    start: Vec2::ZERO,
                    angle_rad: a.to_radians(),
                    length: 1.0,
                    mu_f: 0.3,
                    tail_radius: None,
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
                tail_radius: None,
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
