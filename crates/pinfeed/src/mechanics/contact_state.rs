//! The state of one contact: which feature touches (`Feat`), the reduced coordinates held on it,
//! and what follows from them — the pose, the contact geometry, the rates, the event functions,
//! the self-check and the recording (`Ctx`).
//!
//! Work happens in the belt frame, in normalised units (the part's `a` = 1, belt speed 1). The pin
//! moves along v_pin = (−1, w) (w = lateral speed / belt speed) and its travel `s` relative to the belt
//! parametrises the motion (time = s / V). A contact is held in reduced coordinates so the contact
//! constraint never drifts:
//!
//! * on edge k: y = (θ, ℓ), ℓ the distance of the contact point from vertex k along the edge;
//! * on vertex k: y = (θ, φ), φ the part-frame angle of the normal from the pin centre to the vertex
//!   (a disc pin rides round the vertex; for a point pin φ is frozen while the vertex sticks — the
//!   ρ → 0 limit of the disc);
//! * on the fence line (hull vertex k, or hull edge k flush): y = (θ, σ), σ the fence coordinate of
//!   hull vertex k (see [`super::fence`]).
//!
//! The pose follows from (s, θ, contact): c = P(s) + R(θ)(ρ n − p). The rates are
//! dθ/ds = ω, dℓ/ds = ê·(v_pin + ρ ω ẑ×n − v_p) and dφ/ds = (ẑ×n)·(v_p − v_pin)/ρ − ω, with v_p the
//! material velocity of the contact point (all in part axes); the twist comes from [`super::instant`].

use super::fence::FenceGeom;
use super::instant::{push_margin, solve_in_mode, ContactGeom, Friction, Instant, Mode, Warm};
use super::outcome::{ContactFeature, Recorder, SelfCheck, TraceSample};
use super::part_model::{Fidelity, PartModel, SolveFailure};
use super::pin_path::{PinPath, Turn};
use super::settings::{ContactSettings, POINT_PIN_RADIUS};
use super::slide_table::SlideAt;
use crate::geometry::{Feature, Polygon, Pose, Vec2};
use std::cell::Cell;

/// The feature in contact, and what its second coordinate y[1] means.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Feat {
    /// Pin on polygon edge k; y = (θ, ℓ).
    Edge(usize),
    /// Pin on polygon vertex k; y = (θ, φ).
    Vertex(usize),
    /// Hull vertex k on the fence line; y = (θ, σ), σ the vertex's fence coordinate.
    FenceVertex(usize),
    /// Hull edge k flush on the fence line; y = (θ, σ), σ the fence coordinate of hull vertex k.
    FenceEdge(usize),
}

impl Feat {
    /// The feature as the outcome reports it.
    pub(super) fn public(self) -> ContactFeature {
        match self {
            Feat::Edge(k) => ContactFeature::Edge(k),
            Feat::Vertex(k) => ContactFeature::Vertex(k),
            Feat::FenceVertex(k) => ContactFeature::FenceVertex(k),
            Feat::FenceEdge(k) => ContactFeature::FenceEdge(k),
        }
    }
}

/// The state of one obstacle pass over a part: the obstacle, the settings in normalised units,
/// the warm starts and evaluation count of the instant solve, event bands and the recorder.
pub(super) struct Ctx<'a, 'r> {
    pub(super) model: &'a PartModel,
    pub(super) poly: &'a Polygon,
    pub(super) fid: Fidelity,
    pub(super) fr: Friction,
    pub(super) rho: f64,
    pub(super) vdir: Vec2,
    /// Where the pin (or the fence end acting as one) is at travel 0.
    pub(super) start: Vec2,
    /// The fence, when the obstacle is one (`poly` is then the part's hull).
    pub(super) fence: Option<FenceGeom>,
    /// The pin is the fence's tail (a disc of the tail's radius about its centre, `start`): its
    /// contact normal is held to the arc's span ([`Ctx::arc_start_event`]).
    pub(super) arc: bool,
    /// The pieces of the fence (one straight piece and its arc each, see [`super::fence`]) and
    /// the one in contact (`fence` is that piece): a fence with a tail is one piece; a chain of
    /// pieces joined by rounded corners approximates a curved fence by straight ones.
    pub(super) chain: Vec<FenceGeom>,
    pub(super) piece: usize,
    pub(super) tol: f64,
    /// μs: the trace reports forces in units of m g (the model's are in units of μs m g).
    pub(super) mu_s: f64,
    pub(super) scale: f64,
    pub(super) evals: u64,
    /// Right-hand sides evaluated, with the evaluations the pass's work budget (a right-hand
    /// side a slide table serves costs no evaluation, so evaluations alone would not bound a
    /// pass whose steps crawl).
    pub(super) rhs_calls: u64,
    /// Steps refused by the acceptance guard (`contact_step::step_change_ok`).
    pub(super) guard_refusals: u64,
    pub(super) warm: Warm,
    pub(super) recorder: Option<&'r mut dyn Recorder>,
    /// Per-event tolerance band: event i fires when its function drops below −band[i]. Zero except
    /// for a mode margin that just bounced (see the ping-pong rule in `integrate_contact`).
    pub(super) band: [f64; N_EVENTS],
    /// Changes of the pin's lateral speed still ahead (normalised travel), in order; `start` and
    /// `vdir` describe the current piece of the path (see [`super::pin_path`]).
    pub(super) turns: Vec<Turn>,
    pub(super) next_turn: usize,
    /// The part's last orientation θ (bits) with its sine and cosine: the geometry, the pose, the
    /// record and the events all turn vectors by ±θ of the same state, and one `sin_cos` serves
    /// them (sin(−θ) = −sin θ and cos(−θ) = cos θ bit for bit, so the result is that of rotating
    /// by ±θ directly).
    trig: Cell<(u64, f64, f64)>,
}

/// Number of event functions (see [`Ctx::events`]).
pub(super) const N_EVENTS: usize = 7;
/// Pseudo-event index of a turn of the pin's path (a change of its lateral speed).
pub(super) const TURN: usize = N_EVENTS;
impl<'a, 'r> Ctx<'a, 'r> {
    /// A context for one obstacle pass: `poly` is the polygon the obstacle touches (the part, or
    /// its hull for a fence); lengths are already normalised.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(
        model: &'a PartModel,
        poly: &'a Polygon,
        settings: &ContactSettings,
        mu: f64,
        rho: f64,
        vdir: Vec2,
        start: Vec2,
        fence: Option<FenceGeom>,
        recorder: Option<&'r mut dyn Recorder>,
    ) -> Self {
        Ctx {
            model,
            poly,
            fid: settings.fidelity,
            fr: Friction::new(mu),
            rho: if rho < POINT_PIN_RADIUS { 0.0 } else { rho },
            vdir,
            start,
            fence,
            arc: false,
            chain: fence.into_iter().collect(),
            piece: 0,
            tol: settings.tol,
            mu_s: settings.mu_s,
            scale: model.scale(),
            evals: 0,
            rhs_calls: 0,
            guard_refusals: 0,
            warm: Warm::for_tolerance(settings.tol),
            recorder,
            band: [0.0; N_EVENTS],
            turns: Vec::new(),
            next_turn: 0,
            trig: Cell::new((f64::NAN.to_bits(), f64::NAN, f64::NAN)),
        }
    }

    /// Let the pin follow `path` (its lateral speed changes at the path's turns).
    pub(super) fn with_path(mut self, path: &PinPath) -> Self {
        self.vdir = Vec2::new(-1.0, path.initial_speed());
        self.turns = path.scaled(self.scale).collect();
        self
    }
}

impl Ctx<'_, '_> {
    /// The pin centre (or the fence end acting as a pin) at travel `s`.
    pub(super) fn pin_at(&self, s: f64) -> Vec2 {
        self.start + self.vdir * s
    }

    /// Travel of the next change of the pin's lateral speed (∞ if none is left).
    pub(super) fn turn_at(&self) -> f64 {
        self.turns
            .get(self.next_turn)
            .map_or(f64::INFINITY, |t| t.s)
    }

    /// Take the next turn: the pin, where it stands at the turn, goes on along its new direction
    /// (`start` is moved so that `pin_at` stays continuous).
    pub(super) fn take_turn(&mut self) {
        let t = self.turns[self.next_turn];
        let at = self.pin_at(t.s);
        self.vdir = Vec2::new(-1.0, t.w);
        self.start = at - self.vdir * t.s;
        self.next_turn += 1;
    }

    /// Is travel `s` at the next turn (to rounding)?
    pub(super) fn at_turn(&self, s: f64) -> bool {
        self.turn_at() - s <= 1e-12 * (1.0 + s.abs())
    }

    /// (sin θ, cos θ), from the last call's if θ is the same.
    #[inline]
    fn sin_cos(&self, theta: f64) -> (f64, f64) {
        let (bits, s, c) = self.trig.get();
        if bits == theta.to_bits() {
            return (s, c);
        }
        let (s, c) = crate::geometry::sin_cos(theta);
        self.trig.set((theta.to_bits(), s, c));
        (s, c)
    }

    /// `v` (part axes) in world axes for the part at orientation θ: `v.rotate(θ)`.
    #[inline]
    pub(super) fn to_world(&self, v: Vec2, theta: f64) -> Vec2 {
        let (s, c) = self.sin_cos(theta);
        v.rotate_sc(s, c)
    }

    /// `v` (world axes) in part axes for the part at orientation θ: `v.rotate(−θ)`.
    #[inline]
    pub(super) fn to_part(&self, v: Vec2, theta: f64) -> Vec2 {
        let (s, c) = self.sin_cos(theta);
        v.rotate_sc(-s, c)
    }

    /// The contact geometry in part axes: contact point, normal into the part, pin velocity.
    pub(super) fn geom(&self, feat: Feat, y: [f64; 2]) -> ContactGeom {
        let v_pin = self.to_part(self.vdir, y[0]);
        match feat {
            Feat::Edge(k) => {
                let e = self.poly.edge_dir(k);
                ContactGeom {
                    p: self.poly.vertex(k) + e * y[1],
                    n: e.perp(),
                    v_pin,
                    slide_at: self.own_polygon().then_some(SlideAt::Edge(k, y[1])),
                }
            }
            Feat::Vertex(k) => ContactGeom {
                p: self.poly.vertex(k),
                n: Vec2::from_angle(y[1]),
                v_pin,
                slide_at: self.own_polygon().then_some(SlideAt::Vertex(k, y[1])),
            },
            Feat::FenceVertex(k) => {
                let n = self.to_part(self.fence_geom().n, y[0]);
                ContactGeom {
                    p: self.poly.vertex(k),
                    n,
                    v_pin,
                    slide_at: self
                        .hull_vertex_tables(k)
                        .map(|i| SlideAt::Vertex(i, n.angle())),
                }
            }
            Feat::FenceEdge(k) => ContactGeom {
                p: self.poly.vertex(k),
                n: self.to_part(self.fence_geom().n, y[0]),
                v_pin,
                slide_at: None,
            },
        }
    }

    /// Does the obstacle touch the part's own polygon (a pin), not its hull (a fence and its
    /// ends)? The model's slide tables are for the part's own edges and vertices (a fence's hull
    /// vertex is served by its polygon vertex's: [`Self::hull_vertex_tables`]).
    fn own_polygon(&self) -> bool {
        std::ptr::eq(self.poly, self.model.polygon())
    }

    /// The polygon vertex whose slide tables serve a fence on hull vertex k: the hull is the
    /// model's own and the model has tables (else nothing, and no angle is computed).
    fn hull_vertex_tables(&self, k: usize) -> Option<usize> {
        if !(self.model.has_slide_tables() && std::ptr::eq(self.poly, self.model.hull())) {
            return None;
        }
        self.model.hull_vertex_in_polygon(k)
    }

    /// The fence (fence features only arise with one).
    pub(super) fn fence_geom(&self) -> &FenceGeom {
        self.fence
            .as_ref()
            .expect("fence features only arise with a fence")
    }

    /// The part's pose (belt frame, normalised units) at travel `s` in state `y` on `feat`.
    pub(super) fn pose(&self, s: f64, feat: Feat, y: [f64; 2]) -> Pose {
        let g = self.geom(feat, y);
        let c = match feat {
            Feat::FenceVertex(_) | Feat::FenceEdge(_) => {
                let f = self.fence_geom();
                f.p0 + self.vdir * s + f.e * y[1] - self.to_world(g.p, y[0])
            }
            _ => self.pin_at(s) + self.to_world(g.n * self.rho - g.p, y[0]),
        };
        Pose::new(c.x, c.y, y[0])
    }

    /// The rates dy/ds of the reduced coordinates given the instant's twist.
    pub(super) fn rates(
        &self,
        feat: Feat,
        y: [f64; 2],
        g: &ContactGeom,
        inst: &Instant,
    ) -> [f64; 2] {
        let xi = inst.twist;
        let om = xi[2];
        let vp = Vec2::new(xi[0], xi[1]) + g.p.perp() * om;
        let dq = match feat {
            Feat::Edge(k) => {
                let e = self.poly.edge_dir(k);
                e.dot(g.v_pin + g.n.perp() * (self.rho * om) - vp)
            }
            Feat::Vertex(_) => {
                if self.rho > 0.0 {
                    g.n.perp().dot(vp - g.v_pin) / self.rho - om
                } else {
                    0.0
                }
            }
            // dσ/ds: the contact point's velocity relative to the fence, along the fence.
            Feat::FenceVertex(_) | Feat::FenceEdge(_) => {
                self.fence_geom().e.dot(self.to_world(vp, y[0]) - self.vdir)
            }
        };
        [om, dq]
    }

    /// The right-hand side: solve the instant in `mode` at `y` (a flush edge in closed form) and
    /// return the rates with it; non-finite rates are a solver failure. Inlined into its callers
    /// (the step's stages), so that the instant and the geometry are not copied on the way out.
    #[inline(always)]
    pub(super) fn rhs(
        &mut self,
        feat: Feat,
        mode: Mode,
        y: [f64; 2],
    ) -> Result<([f64; 2], Instant, ContactGeom), SolveFailure> {
        self.rhs_calls += 1;
        let g = self.geom(feat, y);
        let inst = match feat {
            Feat::FenceEdge(k) => self.flush_instant(k, y, mode),
            _ => solve_in_mode(
                self.model,
                self.fid,
                &g,
                self.fr,
                mode,
                &mut self.warm,
                &mut self.evals,
            )?,
        };
        let d = self.rates(feat, y, &g, &inst);
        if !(d[0].is_finite() && d[1].is_finite()) {
            return Err(SolveFailure::NonFinite);
        }
        Ok((d, inst, g))
    }

    /// Event functions (positive while nothing happens): separation, the two mode margins, then
    /// the geometric ones of [`Ctx::feature_events`].
    pub(super) fn events(&self, feat: Feat, y: [f64; 2], inst: &Instant) -> [f64; N_EVENTS] {
        self.events_at(feat, y, &self.geom(feat, y), inst)
    }

    /// [`Ctx::events`] with the contact geometry at (feat, y) already at hand.
    pub(super) fn events_at(
        &self,
        feat: Feat,
        y: [f64; 2],
        g: &ContactGeom,
        inst: &Instant,
    ) -> [f64; N_EVENTS] {
        let [e3, e4, e5, e6] = self.feature_events(feat, y);
        let b = &self.band;
        [
            push_margin(g) + b[0],
            inst.margins[0] + b[1],
            inst.margins[1] + b[2],
            e3 + b[3],
            e4 + b[4],
            e5 + b[5],
            e6 + b[6],
        ]
    }

    /// The geometric event functions (positive while the contact stays on its feature): an edge's
    /// two ends (units of a), a disc's normal cone at a vertex (sines), a fence vertex's
    /// neighbours and the fence's two ends (units of a); on a fence's arc, its start and (if the
    /// fence goes on beyond it) its end (sines, events 5 and 6).
    pub(super) fn feature_events(&self, feat: Feat, y: [f64; 2]) -> [f64; 4] {
        // On a fence's tail, the contact normal stays past the arc's start.
        let (mut e5, mut e6) = (self.arc_start_event(feat, y), self.arc_end_event(feat, y));
        let (e3, e4) = match feat {
            Feat::Edge(k) => (y[1], self.poly.edge_len(k) - y[1]),
            Feat::Vertex(k) => {
                if self.rho > 0.0 {
                    let m = self.poly.len();
                    let na = self.poly.inward_normal(k + m - 1);
                    let nb = self.poly.inward_normal(k);
                    // The normal of `geom` on a vertex.
                    let n = Vec2::from_angle(y[1]);
                    (na.cross(n), n.cross(nb))
                } else {
                    (1.0, 1.0)
                }
            }
            Feat::FenceVertex(k) => {
                // Neighbouring hull vertices stay off the line (an edge turns flush at zero), and
                // the vertex stays between the fence's ends.
                let f = self.fence_geom();
                let m = self.poly.len();
                let v = self.poly.vertex(k);
                let dist = |j: usize| self.to_world(self.poly.vertex(j) - v, y[0]).dot(f.n);
                e5 = y[1];
                e6 = f.len - y[1];
                (dist(k + m - 1), dist(k + 1))
            }
            Feat::FenceEdge(_) => (1.0, 1.0),
        };
        [e3, e4, e5, e6]
    }

    /// How far (normalised units) a state may stray from its contact before the self-check fails:
    /// the pin may overlap the part, or a contact point lie off its feature, by this much.
    pub(super) fn check_limit(&self) -> f64 {
        10.0 * self.tol
    }

    /// The self-check at the end of a contact (a few event functions and one distance): the state
    /// must still lie on its feature, and the pin must not overlap the part. Both hold by
    /// construction in exact arithmetic and to the landing tolerance in a correct run; a failure
    /// means an accepted step or landing went wrong.
    pub(super) fn self_check(&self, s: f64, feat: Feat, y: [f64; 2]) -> Option<SelfCheck> {
        let limit = self.check_limit();
        if self.feature_events(feat, y).iter().any(|&e| e < -limit) {
            return Some(SelfCheck::OffFeature);
        }
        if self.fence.is_none() {
            let pose = self.pose(s, feat, y);
            let centre = pose.apply_inverse(self.pin_at(s));
            let (dist, _) = self.poly.distance_to_boundary(centre);
            let depth = if self.poly.contains(centre) {
                dist + self.rho
            } else {
                self.rho - dist
            };
            if depth > limit {
                return Some(SelfCheck::Penetration);
            }
        }
        None
    }

    /// Give the recorder, if any, a sample in the caller's units.
    pub(super) fn record(&mut self, s: f64, feat: Feat, y: [f64; 2], inst: &Instant) {
        if self.recorder.is_none() {
            return;
        }
        let pose = self.pose(s, feat, y);
        let g = self.geom(feat, y);
        let k = self.scale;
        let sample = TraceSample {
            s: s * k,
            pose: Pose::new(pose.x * k, pose.y * k, pose.theta_rad),
            pin_centre: self.pin_at(s) * k,
            contact_point: pose.apply(g.p) * k,
            force: self.to_world(inst.force, y[0]) * self.mu_s,
            normal: self.to_world(g.n, y[0]),
            rotation_rate: inst.twist[2] / k,
            mode: inst.mode,
            feature: feat.public(),
        };
        if let Some(r) = self.recorder.as_deref_mut() {
            r.record(&sample);
        }
    }
}

/// The starting contact state for a first touch.
pub(super) fn initial_state(
    ctx: &Ctx,
    pose: &Pose,
    feature: Feature,
    normal_world: Vec2,
) -> (Feat, [f64; 2]) {
    let theta = pose.theta_rad;
    match feature {
        Feature::Edge { index, t } => {
            let (a, b) = ctx.poly.edge(index);
            (Feat::Edge(index), [theta, t * (b - a).norm()])
        }
        Feature::Vertex { index } => {
            let n_part = if ctx.rho > 0.0 {
                ctx.to_part(normal_world, theta)
            } else {
                // Point pin: the ρ → 0 limit of a disc arriving along its path: the normal is the
                // direction of travel, clamped into the vertex's normal cone.
                let m = ctx.poly.len();
                let na = ctx.poly.inward_normal(index + m - 1);
                let nb = ctx.poly.inward_normal(index);
                let d = ctx.to_part(ctx.vdir, theta).normalized();
                if na.cross(d) >= 0.0 && d.cross(nb) >= 0.0 {
                    d
                } else if d.dot(na) >= d.dot(nb) {
                    na
                } else {
                    nb
                }
            };
            (Feat::Vertex(index), [theta, n_part.angle()])
        }
    }
}

/// Can the pin touch a second edge at all? Only a disc pin on a concave part.
pub(super) fn second_contact_possible(ctx: &Ctx) -> bool {
    !ctx.poly.is_convex() && ctx.rho > 0.0 && ctx.fence.is_none()
}

/// Minimum distance from the pin centre to edges not adjacent to the current feature (disc pins on
/// concave parts): negative margin means a second contact.
pub(super) fn second_contact(ctx: &Ctx, feat: Feat, pose: &Pose, s: f64) -> bool {
    if !second_contact_possible(ctx) {
        return false;
    }
    let m = ctx.poly.len();
    let centre = pose.apply_inverse(ctx.pin_at(s));
    let (skip_a, skip_b) = match feat {
        Feat::Edge(k) | Feat::FenceEdge(k) => (k, k),
        Feat::Vertex(k) | Feat::FenceVertex(k) => ((k + m - 1) % m, k),
    };
    for i in 0..m {
        if i == skip_a || i == skip_b {
            continue;
        }
        let (a, b) = ctx.poly.edge(i);
        let e = b - a;
        let t = ((centre - a).dot(e) / e.norm2()).clamp(0.0, 1.0);
        if (a + e * t - centre).norm() < ctx.rho * (1.0 - 1e-9) {
            return true;
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;
    use crate::mechanics::part_model::Support;

    /// Turning by ±θ through the context's remembered sine and cosine gives the bits of
    /// `Vec2::rotate(±θ)`, whether θ repeats (remembered) or changes (computed), so that the
    /// contact's answers do not depend on the cache.
    #[test]
    fn turns_by_the_remembered_angle_equal_rotate_bit_for_bit() {
        let model =
            PartModel::new(&part_from_spec("tripoly2").unwrap(), &Support::Uniform).unwrap();
        let settings = ContactSettings::default();
        let ctx = Ctx::new(
            &model,
            model.polygon(),
            &settings,
            0.5,
            0.0,
            Vec2::new(-1.0, 0.0),
            Vec2::new(0.0, 0.0),
            None,
            None,
        );
        let v = Vec2::new(0.37, -1.21);
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for k in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let scale = [1e-9, 1e-3, 1.0, 40.0][k % 4];
            let theta = ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2.0 * scale;
            for _ in 0..2 {
                let (w, p) = (ctx.to_world(v, theta), ctx.to_part(v, theta));
                let (rw, rp) = (v.rotate(theta), v.rotate(-theta));
                assert_eq!(
                    (w.x.to_bits(), w.y.to_bits()),
                    (rw.x.to_bits(), rw.y.to_bits())
                );
                assert_eq!(
                    (p.x.to_bits(), p.y.to_bits()),
                    (rp.x.to_bits(), rp.y.to_bits())
                );
            }
        }
    }
}
