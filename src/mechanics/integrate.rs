//! Integration of one pin pass over a part: from first touch to separation, with error control and
//! precise event location (SPEC §2, "Integration over a contact").
//!
//! The contact is held in reduced coordinates on its feature (see [`super::contact_state`]).
//!
//! Steps: Dormand–Prince 5(4) with absolute tolerance `tol` on θ (radians) and on ℓ, φ (units of a).
//! Events, located with a cubic Hermite interpolant and the Illinois method and then landed on with a
//! real step: separation (n·v_pin = 0), mode margins (stick ↔ slide), edge ends and, for a disc on a
//! vertex, the edges of the vertex's normal cone. At a convex vertex a point pin passes onto the next
//! edge in its direction of sliding (or separates if that edge faces away); a reflex vertex means a
//! second contact in a notch, which is reported as [`ContactStatus::MultiContact`], not simulated.
//! After separation the pin's path is cast again, so a concave part can be struck more than once.

use super::contact_state::{second_contact, Ctx, Feat, N_EVENTS, TURN};
use super::fence::{edge_turns_flush, fence_vertex_event, flush_pivot, settle_flush, Flush};
use super::instant::{classify, push_margin, solve_in_mode, Instant, Mode};
use super::ode::{self, dense, illinois, NonFinite, Step};
use super::outcome::{ContactStatus, Segment};
use super::part_model::SolveFailure;
use crate::geometry::Pose;

// The entry points, where they were before the pass loop had a module of its own.
pub use super::pass::{
    fence_first_touch, first_instant, pin_first_touch, push, push_fence, push_path,
};
pub use super::settings::{ContactSettings, Pin, POINT_PIN_RADIUS};

/// How a contact ended.
pub(super) enum End {
    Separated,
    Stop(ContactStatus),
}

/// Tolerance band of a mode margin after a ping-pong (a sine: about 0.006°).
const BOUNCE_BAND: f64 = 1e-4;
/// Step acceptance guard: the most one accepted step may change θ (radians) or the contact
/// coordinate ℓ (units of a) / φ (radians). The embedded error estimate is only asymptotic for
/// small changes: near a singular instant (a sliding twist whose contact velocity turns tangential,
/// so κ = n·v_pin / n·v_b blows up) all seven stages can agree on a huge rate and a step of 1e-4 a
/// of travel passes the error test while turning the part by 900°. No real contact needs more
/// than this per step at any tolerance: the guard shrinks the step instead. A flush fence edge
/// translates at constant rates, so its fence coordinate is not limited.
const MAX_STEP_CHANGE: f64 = 0.5;
/// Does a step from `y0` to `y1` on `feat` pass the acceptance guard?
fn step_change_ok(feat: Feat, y0: [f64; 2], y1: [f64; 2]) -> bool {
    let d_theta = (y1[0] - y0[0]).abs();
    let d_contact = match feat {
        Feat::FenceEdge(_) => 0.0,
        _ => (y1[1] - y0[1]).abs(),
    };
    d_theta <= MAX_STEP_CHANGE && d_contact <= MAX_STEP_CHANGE
}

/// The largest step (units of a) on `feat`: a flush fence edge translates at constant rates, so a
/// single step may take it along any length of fence (its events are monotone in the travel);
/// elsewhere two units of a, so that no event can come and go within one step.
fn max_step(feat: Feat) -> f64 {
    match feat {
        Feat::FenceEdge(_) => f64::INFINITY,
        _ => 2.0,
    }
}

/// A Dormand–Prince step of a contact: the scheme's step and what the contact adds to it.
struct StepResult {
    dp: Step<2>,
    /// The instant at the end of the step.
    inst1: Instant,
    /// The first interior stage (as a fraction of the step) at which the mode's own margins were
    /// clearly violated: a mode switch that comes and goes inside the step.
    margin_dip: Option<f64>,
}

/// A stage's mode margin below −MARGIN_DIP (a sine) means the mode broke inside the step even if
/// it holds again at both ends (stage states are approximations: a clear violation only).
const MARGIN_DIP: f64 = 1e-3;

/// The geometric event functions (edge ends, normal cone, fence ends) depend on the state alone,
/// so the dense output shows, without solving anything, an event that comes and goes inside one
/// step — which the end-point signs miss; likewise a disc pin's brief second touch on a concave
/// part. Returns the first of eight interior fractions of the step at which an event positive at
/// both ends dips below −slack, or the pin overlaps another edge.
#[allow(clippy::too_many_arguments)]
fn geometric_dip(
    ctx: &Ctx,
    feat: Feat,
    s: f64,
    y0: [f64; 2],
    step: &StepResult,
    h: f64,
    ev1: &[f64; N_EVENTS],
    slack: f64,
) -> Option<f64> {
    // Nothing to miss unless an event not yet crossed ends the step near zero (the guard keeps a
    // step's change of the contact coordinate below 0.5) or a disc could touch a second edge.
    let near = (3..N_EVENTS).any(|j| (0.0..1.0).contains(&ev1[j]));
    let second = !ctx.poly.is_convex() && ctx.rho > 0.0 && ctx.fence.is_none();
    if !near && !second {
        return None;
    }
    (1..8).map(|k| k as f64 / 8.0).find(|&t| {
        let yt = step.dp.dense(y0, h, t);
        let g = ctx.geom(feat, yt);
        let dips = near
            && ctx
                .feature_events(feat, yt, &g)
                .iter()
                .zip(&ev1[3..])
                .any(|(&e, &e1)| e1 >= 0.0 && e < -slack);
        dips || (second && second_contact(ctx, feat, &ctx.pose(s + t * h, feat, yt), s + t * h))
    })
}

/// A trial step while landing on an event.
enum Trial {
    /// No step: the state at the start of the step.
    Start,
    /// A valid step and the located event's function after it.
    Step(Box<StepResult>, f64),
    /// A step that failed, or whose result cannot be trusted.
    Invalid,
}

/// One Dormand–Prince step of size h from (y0, f0) on `feat` in `mode`, watching the mode's
/// margins at the interior stages.
fn dp_step(
    ctx: &mut Ctx,
    feat: Feat,
    mode: Mode,
    y0: [f64; 2],
    f0: [f64; 2],
    h: f64,
) -> Result<StepResult, SolveFailure> {
    let mut inst_last = None;
    let mut margin_dip = None;
    let tol = ctx.tol;
    let dp = ode::dp_step(
        |c, yi| {
            let (d, inst) = ctx.rhs(feat, mode, yi)?;
            let broken = inst.margins[0] + ctx.band[1] < -MARGIN_DIP
                || inst.margins[1] + ctx.band[2] < -MARGIN_DIP;
            // Interior stages only (C < 1; stages 5 and 6 sit at the step's end).
            if c < 1.0 && broken && margin_dip.is_none() {
                margin_dip = Some(c);
            }
            inst_last = Some(inst);
            Ok::<_, SolveFailure>(d)
        },
        y0,
        f0,
        h,
        tol,
    )?;
    Ok(StepResult {
        dp,
        inst1: inst_last.expect("six stages ran"),
        margin_dip,
    })
}

impl From<NonFinite> for SolveFailure {
    fn from(_: NonFinite) -> SolveFailure {
        SolveFailure::NonFinite
    }
}

/// The state after a point pin's instantaneous sweep round convex vertex `k`: onto the incoming edge
/// (direction left) or the outgoing edge (right), or separation if that edge faces away from the pin.
fn sweep(ctx: &Ctx, k: usize, left: bool, theta: f64) -> Option<(Feat, [f64; 2])> {
    let m = ctx.poly.len();
    let (edge, ell) = if left {
        let e = (k + m - 1) % m;
        let (a, b) = ctx.poly.edge(e);
        (e, (b - a).norm())
    } else {
        (k % m, 0.0)
    };
    let n = ctx.poly.inward_normal(edge);
    let v_pin = ctx.vdir.rotate(-theta);
    if n.dot(v_pin) / v_pin.norm() <= 1e-12 {
        None
    } else {
        Some((Feat::Edge(edge), [theta, ell]))
    }
}

/// Outcome of settling the mode at a new contact state: continue, or the contact ends.
enum Settle {
    Go(Feat, [f64; 2], Instant),
    Separate,
    Stop(ContactStatus),
}

/// Decide the mode at a (possibly new) contact state, resolving point-pin vertex sweeps.
fn settle(ctx: &mut Ctx, s: f64, mut feat: Feat, mut y: [f64; 2]) -> Settle {
    for _ in 0..6 {
        if let Feat::FenceEdge(k) = feat {
            match settle_flush(ctx, k, y) {
                Flush::Translate(inst) => return Settle::Go(feat, y, inst),
                Flush::Pivot(f, yy) => {
                    feat = f;
                    y = yy;
                    continue;
                }
                Flush::Jam => return Settle::Stop(ContactStatus::Jam { s: s * ctx.scale }),
            }
        }
        let g = ctx.geom(feat, y);
        let inst = match classify(
            ctx.model,
            ctx.fid,
            &g,
            ctx.fr,
            &mut ctx.warm,
            &mut ctx.evals,
        ) {
            Ok(Some(i)) => i,
            Ok(None) => return Settle::Separate,
            Err(failure) => {
                return Settle::Stop(ContactStatus::Solver {
                    failure,
                    s: s * ctx.scale,
                })
            }
        };
        match (feat, ctx.rho > 0.0, inst.mode) {
            (Feat::Vertex(k), false, Mode::SlideLeft | Mode::SlideRight | Mode::Slide) => {
                // A point pin cannot slide on a vertex: it passes onto the edge it slides towards.
                let left = match inst.mode {
                    Mode::SlideLeft => true,
                    Mode::SlideRight => false,
                    _ => g.v_pin.dot(g.n.perp()) > 0.0,
                };
                match sweep(ctx, k, left, y[0]) {
                    Some((f, yy)) => {
                        feat = f;
                        y = yy;
                        continue;
                    }
                    None => return Settle::Separate,
                }
            }
            _ => return Settle::Go(feat, y, inst),
        }
    }
    Settle::Stop(ContactStatus::EventLimit { events: 6 })
}

/// Book-keeping of one pass: segments, events and steps so far.
#[derive(Default)]
pub(super) struct Tally {
    /// The closed segments (caller's units).
    pub(super) list: Vec<Segment>,
    open: Option<(Feat, Mode, f64, f64)>,
    events: u32,
    /// Accepted steps (including landing steps).
    pub(super) steps: u32,
    /// Pin travel (units of a) in the current contact during which a pin turned the part slower
    /// than [`NOISE_RATE`]·tol per unit of travel (see [`ContactStatus::Metastable`]).
    still: f64,
}

/// A pin pushing with |ω| below NOISE_RATE·tol (radians per unit a of travel) turns the part less
/// over one a than a single step's error: its sense of rotation is noise.
const NOISE_RATE: f64 = 10.0;
/// How long (units of a of pin travel) a pin may push within the noise rate before the side the part
/// finally falls to is taken as decided by noise rather than by the inputs.
const METASTABLE_TRAVEL: f64 = 1.0;

impl Tally {
    /// Count `travel` of pushing at rate `omega` on `feat` towards the metastable ride (a pin, or
    /// a fence's end acting as one; a part dragged along a fence by a sticking vertex or a flush
    /// edge is held stably, not balanced).
    fn ride(&mut self, ctx: &Ctx, feat: Feat, omega: f64, travel: f64) {
        let pin_like = matches!(feat, Feat::Edge(_) | Feat::Vertex(_));
        if pin_like && omega.abs() < NOISE_RATE * ctx.tol {
            self.still += travel;
        }
    }
}

impl Tally {
    /// Reopen the segment just closed if it had this feature and mode (no zero-length split).
    /// Closed segments are in the caller's units, open ones in normalised units: `scale` converts.
    fn reopen(&mut self, feat: Feat, mode: Mode, s: f64, theta: f64, scale: f64) {
        match self.list.last() {
            Some(last) if last.feature == feat.public() && last.mode == mode => {
                let last = self.list.pop().expect("checked above");
                self.open = Some((feat, mode, last.s_begin / scale, last.theta_begin));
            }
            _ => self.open(feat, mode, s, theta),
        }
    }
    fn open(&mut self, feat: Feat, mode: Mode, s: f64, theta: f64) {
        self.open = Some((feat, mode, s, theta));
    }
    /// Close the open segment at (s, θ) (normalised travel; `scale` converts).
    pub(super) fn close(&mut self, s: f64, theta: f64, scale: f64) {
        if let Some((f, m, s0, t0)) = self.open.take() {
            self.list.push(Segment {
                feature: f.public(),
                mode: m,
                s_begin: s0 * scale,
                s_end: s * scale,
                theta_begin: t0,
                theta_end: theta,
            });
        }
    }
}

/// After a pin separates from edge k (its path tangent to the edge at orientation `theta`), is the
/// vertex it runs towards along the edge reflex?
fn reflex_ahead(ctx: &Ctx, k: usize, theta: f64) -> bool {
    let (a, b) = ctx.poly.edge(k);
    let towards_b = (b - a).dot(ctx.vdir.rotate(-theta)) > 0.0;
    let m = ctx.poly.len();
    let v = if towards_b { (k + 1) % m } else { k };
    !ctx.poly.vertex_is_convex(v)
}

/// The end of a contact that separated at (s, feat, y), after the self-check.
fn separated(ctx: &Ctx, s: f64, feat: Feat, y: [f64; 2], segs: &Tally) -> (End, f64, Pose) {
    let p = ctx.pose(s, feat, y);
    if segs.still > METASTABLE_TRAVEL {
        let travel = segs.still * ctx.scale;
        return (End::Stop(ContactStatus::Metastable { travel }), s, p);
    }
    match ctx.self_check(s, feat, y) {
        None => (End::Separated, s, p),
        Some(check) => (
            End::Stop(ContactStatus::SelfCheck {
                check,
                s: s * ctx.scale,
            }),
            s,
            p,
        ),
    }
}

/// Integrate one contact from its first touch until separation. Returns the end and the final state.
pub(super) fn integrate_contact(
    ctx: &mut Ctx,
    settings: &ContactSettings,
    s_start: f64,
    feat0: Feat,
    y_start: [f64; 2],
    segs: &mut Tally,
) -> (End, f64, Pose) {
    let mut s = s_start;
    segs.still = 0.0;
    let (mut feat, mut y, mut inst) = match settle(ctx, s, feat0, y_start) {
        Settle::Go(f, yy, i) => (f, yy, i),
        Settle::Separate => {
            let p = ctx.pose(s, feat0, y_start);
            return (End::Separated, s, p);
        }
        Settle::Stop(st) => {
            let p = ctx.pose(s, feat0, y_start);
            return (End::Stop(st), s, p);
        }
    };
    let mut mode = inst.mode;
    segs.open(feat, mode, s, y[0]);
    ctx.record(s, feat, y, &inst);
    let mut f0 = ctx.rates(feat, y, &ctx.geom(feat, y), &inst);
    let mut ev0 = ctx.events(feat, y, &inst);
    let h_min = 1e-13;
    // First step: a tenth of a, shrunk by the error control if the motion is fast.
    let mut h = 0.1;
    // Events are landed to |g| ≤ land_tol; a fresh segment treats |g| ≤ slack as "at the boundary"
    // (the new mode's margin starts at zero up to the landing error), and only g < −slack at a
    // segment start means the state is already past an event.
    let land_tol = 1e-2 * ctx.tol;
    let slack = 100.0 * land_tol;
    let mut last_switch: Option<(f64, Mode)> = None;
    // (travel, feature left, event index) of the last change of contact feature.
    let mut last_feature_change: Option<(f64, Feat, usize)> = None;
    ctx.band = [0.0; N_EVENTS];
    loop {
        if ctx.evals > settings.max_evaluations {
            let p = ctx.pose(s, feat, y);
            return (
                End::Stop(ContactStatus::EvaluationLimit {
                    evaluations: ctx.evals,
                }),
                s,
                p,
            );
        }
        if s - s_start > settings.max_travel {
            let p = ctx.pose(s, feat, y);
            return (
                End::Stop(ContactStatus::TravelLimit {
                    travel: (s - s_start) * ctx.scale,
                }),
                s,
                p,
            );
        }
        // An event function already negative at the start of a step: the state is at an event.
        let pending = (0..N_EVENTS).find(|&i| ev0[i] < -slack);
        let (event, s_ev, y_ev, inst_ev) = if let Some(i) = pending {
            (Some(i), s, y, inst)
        } else if ctx.at_turn(s) {
            (Some(TURN), s, y, inst)
        } else {
            // A step never crosses a turn of the pin's path: it ends there.
            let to_turn = ctx.turn_at() - s;
            let clipped = h >= to_turn;
            if clipped {
                h = to_turn;
            }
            let step = match dp_step(ctx, feat, mode, y, f0, h) {
                Ok(r) => r,
                Err(failure) => {
                    h *= 0.25;
                    if h < h_min {
                        let p = ctx.pose(s, feat, y);
                        return (
                            End::Stop(ContactStatus::Solver {
                                failure,
                                s: s * ctx.scale,
                            }),
                            s,
                            p,
                        );
                    }
                    continue;
                }
            };
            let guarded = !step_change_ok(feat, y, step.dp.y1);
            if step.dp.err > 1.0 || guarded {
                h *= if guarded {
                    0.25
                } else {
                    (0.9 * step.dp.err.powf(-0.2)).max(0.2)
                };
                if h < h_min {
                    let p = ctx.pose(s, feat, y);
                    return (
                        End::Stop(ContactStatus::StepTooSmall { s: s * ctx.scale }),
                        s,
                        p,
                    );
                }
                continue;
            }
            let ev1 = ctx.events(feat, step.dp.y1, &step.inst1);
            let mode_dip = step.margin_dip.filter(|_| ev1[1] >= 0.0 && ev1[2] >= 0.0);
            if let Some(t_dip) = geometric_dip(ctx, feat, s, y, &step, h, &ev1, slack).or(mode_dip)
            {
                // The contact runs off its feature and back (e.g. past an edge's end), or its mode
                // breaks and recovers, within the step: shorten the step so that it ends beyond
                // the first crossing, where the event is located as usual. (Below 1e-10 a a dip
                // is the start state itself sitting on the boundary: the endpoint rule decides.)
                if h * t_dip >= 1e-10 {
                    h *= t_dip;
                    continue;
                }
            }
            let crossed: Vec<usize> = (0..N_EVENTS)
                .filter(|&i| ev1[i] < 0.0 && ev0[i] >= -slack)
                .collect();
            let factor = (0.9 * step.dp.err.max(1e-10).powf(-0.2)).clamp(0.2, 5.0);
            if crossed.is_empty() {
                // A bounced margin that has recovered gets its ordinary zero threshold back.
                for (b, e) in ctx.band.iter_mut().zip(ev1) {
                    if *b > 0.0 && e - *b > slack {
                        *b = 0.0;
                    }
                }
                segs.ride(ctx, feat, step.dp.f1()[0].abs().max(f0[0].abs()), h);
                s = if clipped { ctx.turn_at() } else { s + h };
                y = step.dp.y1;
                inst = step.inst1;
                f0 = step.dp.f1();
                ev0 = ev1;
                segs.steps += 1;
                ctx.record(s, feat, y, &inst);
                let pose = ctx.pose(s, feat, y);
                if second_contact(ctx, feat, &pose, s) {
                    return (
                        End::Stop(ContactStatus::MultiContact { s: s * ctx.scale }),
                        s,
                        pose,
                    );
                }
                h = (h * factor).min(max_step(feat));
                continue;
            }
            // Locate the earliest crossing on the interpolant.
            let (y0c, y1c, kc, hc) = (y, step.dp.y1, step.dp.k, h);
            let mut best = (2.0, 0usize);
            let warm_saved = ctx.warm;
            let root_tol = 1e-3 * ctx.tol;
            let ctx_tol = ctx.tol;
            let band = ctx.band;
            for &i in &crossed {
                let g0 = ev0[i].max(0.0);
                let t = illinois(
                    |t| {
                        let yt = dense(y0c, y1c, &kc, hc, t);
                        if i == 0 || i >= 3 {
                            let dummy = inst;
                            ctx.events(feat, yt, &dummy)[i]
                        } else {
                            let g = ctx.geom(feat, yt);
                            match solve_in_mode(
                                ctx.model,
                                ctx.fid,
                                &g,
                                ctx.fr,
                                mode,
                                &mut ctx.warm,
                                &mut ctx.evals,
                            ) {
                                Ok(it) => it.margins[i - 1] + band[i],
                                Err(_) => -1.0,
                            }
                        }
                    },
                    g0,
                    ev1[i],
                    root_tol,
                );
                if t < best.0 {
                    best = (t, i);
                }
            }
            ctx.warm = warm_saved;
            let (t_est, i) = best;
            // A sub-step of the accepted step must agree with its dense output (both are
            // accurate to about tol; 1e3·tol leaves room for a mode boundary inside the step).
            let near_dense = |r: &StepResult, t: f64| {
                let yd = dense(y0c, y1c, &kc, hc, t);
                (r.dp.y1[0] - yd[0]).abs() <= 1e3 * ctx_tol
                    && (r.dp.y1[1] - yd[1]).abs() <= 1e3 * ctx_tol
            };
            // Refine on real steps: g(t) = event i after a Dormand–Prince step of t·h from (s, y).
            // A trial step counts only if it is itself accurate (its own error estimate within 10×
            // the tolerance: sub-steps of an accepted step may sit just above it), passes the step
            // guard and crosses neither the separation nor another geometric event; otherwise its event
            // value means nothing (the −880° case of issue 11 landed on such a step) and the
            // bracket shrinks from above.
            let real = |t: f64, ctx: &mut Ctx| -> Trial {
                if t * h <= 1e-15 {
                    return Trial::Start;
                }
                match dp_step(ctx, feat, mode, y, f0, t * h) {
                    Ok(r) if step_change_ok(feat, y, r.dp.y1) && near_dense(&r, t) => {
                        let ev = ctx.events(feat, r.dp.y1, &r.inst1);
                        if [0, 3, 4, 5, 6].iter().all(|&j| j == i || ev[j] >= -slack) {
                            Trial::Step(Box::new(r), ev[i])
                        } else {
                            Trial::Invalid
                        }
                    }
                    _ => Trial::Invalid,
                }
            };
            let (mut a, mut b) = (0.0f64, 1.0f64);
            let (mut ga, mut gb) = (ev0[i].max(0.0), ev1[i]);
            // The landing: the trial at the largest t with g ≥ 0 (or g just below 0 within the
            // landing tolerance), and its g.
            let mut best: (Trial, f64, f64) = (Trial::Start, 0.0, ev0[i].max(0.0));
            let mut t = t_est.clamp(0.0, 1.0);
            let mut side = 0;
            let mut any_invalid = false;
            // Landing tolerance: far below the integration tolerance, far above rounding.
            let g_tol = land_tol;
            for _ in 0..40 {
                let trial = real(t, ctx);
                let gt = match &trial {
                    Trial::Start => ev0[i].max(0.0),
                    Trial::Step(_, g) => *g,
                    Trial::Invalid => {
                        any_invalid = true;
                        b = t;
                        side = 0;
                        if (b - a) * h <= 1e-13 {
                            break;
                        }
                        t = 0.5 * (a + b);
                        continue;
                    }
                };
                let close = gt.abs() <= g_tol;
                if gt < 0.0 {
                    b = t;
                    gb = gt;
                    if side == -1 {
                        ga *= 0.5;
                    }
                    side = -1;
                    if close {
                        best = (trial, t, gt);
                    }
                } else {
                    a = t;
                    ga = gt;
                    best = (trial, t, gt);
                    if side == 1 {
                        gb *= 0.5;
                    }
                    side = 1;
                }
                if close || (b - a) * h <= 1e-13 {
                    break;
                }
                t = (a * gb - b * ga) / (gb - ga);
                if !t.is_finite() || t <= a || t >= b {
                    t = 0.5 * (a + b);
                }
            }
            let (landing, best_t, best_g) = best;
            let (s_land, y_land, inst_land) = match landing {
                Trial::Step(r, _) => {
                    segs.steps += 1;
                    segs.ride(ctx, feat, r.dp.f1()[0].abs().max(f0[0].abs()), best_t * h);
                    (s + best_t * h, r.dp.y1, r.inst1)
                }
                _ => (s, y, inst),
            };
            if any_invalid && best_g > slack {
                // The event lies beyond a stretch the integrator cannot resolve (the rates blow up
                // before it). Near a separation that is the triple point where the pin's path turns
                // tangent while the sliding side's contact velocity does too (κ = n·v_pin / n·v_b →
                // 0/0): the part is within asin(push margin) of letting go, so it separates here
                // when that margin is below min(1e3·tol, 1e-3) (an orientation error below 0.06°).
                // Anywhere else, say so rather than apply the event at a state short of it.
                let g = ctx.geom(feat, y_land);
                if push_margin(&g).abs() <= (1e3 * ctx.tol).min(1e-3) {
                    (Some(0), s_land, y_land, inst_land)
                } else {
                    let p = ctx.pose(s, feat, y);
                    return (
                        End::Stop(ContactStatus::StepTooSmall { s: s * ctx.scale }),
                        s,
                        p,
                    );
                }
            } else {
                (Some(i), s_land, y_land, inst_land)
            }
        };
        let i = event.expect("an event was found");

        // Turns of the pin's path are bounded by the path itself; only contact events count.
        segs.events += u32::from(i != TURN);
        if segs.events > settings.max_events {
            let p = ctx.pose(s_ev, feat, y_ev);
            return (
                End::Stop(ContactStatus::EventLimit {
                    events: segs.events,
                }),
                s_ev,
                p,
            );
        }
        s = s_ev;
        y = y_ev;
        ctx.record(s, feat, y, &inst_ev);
        segs.close(s, y[0], ctx.scale);
        // Apply the event.
        let m = ctx.poly.len();
        let next: Option<(Feat, [f64; 2], Option<Mode>)> = match (i, feat) {
            (TURN, _) => {
                // The pin's lateral speed changes: same contact, mode settled again.
                ctx.take_turn();
                Some((feat, y, None))
            }
            (0, Feat::Edge(k)) if ctx.fence.is_none() && reflex_ahead(ctx, k, y[0]) => {
                // The edge let go by turning parallel to the pin's path, so the pin runs on along
                // the edge's line into the reflex corner ahead, where the next edge blocks it: the
                // pin touches two edges at once (as when it slides into the corner in contact).
                // Casting the path again would decide that by rounding.
                let p = ctx.pose(s, feat, y);
                return (
                    End::Stop(ContactStatus::MultiContact { s: s * ctx.scale }),
                    s,
                    p,
                );
            }
            (0, _) => None,
            (1 | 2, Feat::FenceEdge(k)) => {
                let (f, yy) = flush_pivot(ctx, k, y, i == 2);
                Some((f, yy, None))
            }
            (1 | 2, Feat::FenceVertex(k)) if ctx.flush_neighbour(k, y).is_some() => {
                // The mode changes just as an adjacent edge turns flush (the two events coincide,
                // e.g. at exactly the jam angle): the edge's arrival decides.
                let j = ctx.flush_neighbour(k, y).expect("checked by the guard");
                let (f, yy) = edge_turns_flush(ctx, j, k, y);
                Some((f, yy, None))
            }
            (1 | 2, _) => {
                let new_mode = match (mode, i) {
                    (Mode::Stick, 1) => Mode::SlideLeft,
                    (Mode::Stick, _) => Mode::SlideRight,
                    _ => Mode::Stick,
                };
                // Ping-pong: switching straight back to the mode we left at this very point means the
                // state sits on the stick/slide boundary, where both modes give the same motion and
                // their margins differ only by solver rounding. Stay, and let this margin run down to
                // −BOUNCE_BAND before it counts (a real, sustained violation still switches).
                if let Some((s_prev, from)) = last_switch {
                    if (s - s_prev).abs() <= 1e-12 && from == new_mode && ctx.band[i] == 0.0 {
                        ctx.band[i] = BOUNCE_BAND;
                        segs.reopen(feat, mode, s, y[0], ctx.scale);
                        ev0 = ctx.events(feat, y, &inst_ev);
                        inst = inst_ev;
                        f0 = ctx.rates(feat, y, &ctx.geom(feat, y), &inst);
                        continue;
                    }
                }
                last_switch = Some((s, mode));
                if let (Feat::Vertex(k), false) = (feat, ctx.rho > 0.0) {
                    // Hooked point pin lets go: it sweeps onto the edge it now slides towards.
                    sweep(ctx, k, new_mode == Mode::SlideLeft, y[0]).map(|(f, yy)| (f, yy, None))
                } else {
                    Some((feat, y, Some(new_mode)))
                }
            }
            (3, Feat::Edge(k)) | (4, Feat::Edge(k)) => {
                let v = if i == 3 { k } else { (k + 1) % m };
                if !ctx.poly.vertex_is_convex(v) {
                    let p = ctx.pose(s, feat, y);
                    return (
                        End::Stop(ContactStatus::MultiContact { s: s * ctx.scale }),
                        s,
                        p,
                    );
                }
                if ctx.rho > 0.0 {
                    let n = ctx.poly.inward_normal(k);
                    Some((Feat::Vertex(v), [y[0], n.angle()], None))
                } else {
                    sweep(ctx, v, i == 3, y[0]).map(|(f, yy)| (f, yy, None))
                }
            }
            (3, Feat::Vertex(k)) => {
                let e = (k + m - 1) % m;
                let (a, b) = ctx.poly.edge(e);
                Some((Feat::Edge(e), [y[0], (b - a).norm()], None))
            }
            (4, Feat::Vertex(k)) => Some((Feat::Edge(k), [y[0], 0.0], None)),
            (3..=6, Feat::FenceVertex(k)) => {
                let (f, yy) = fence_vertex_event(ctx, i, k, y);
                Some((f, yy, None))
            }
            _ => unreachable!("event index out of range"),
        };
        let Some((nf, ny, forced)) = next else {
            return separated(ctx, s, feat, y, segs);
        };
        if nf != feat {
            // Event indices mean different things on the new feature: start with no bands, except
            // when this transition merely returns, at the same point, to the feature just left (a
            // marginal geometry, e.g. a force line through an edge's end): then stay there and let
            // the event that ejected it run down to −BOUNCE_BAND before it counts.
            let cycle = matches!(last_feature_change, Some((s0, f0, _)) if (s - s0).abs() <= 1e-12 && f0 == nf);
            let ejected_by = last_feature_change.map(|(_, _, i)| i);
            ctx.band = [0.0; N_EVENTS];
            if cycle {
                if let Some(j) = ejected_by {
                    ctx.band[j] = BOUNCE_BAND;
                }
            }
            last_feature_change = Some((s, feat, i));
        }
        let settled = match forced {
            Some(md) => {
                let g = ctx.geom(nf, ny);
                match solve_in_mode(
                    ctx.model,
                    ctx.fid,
                    &g,
                    ctx.fr,
                    md,
                    &mut ctx.warm,
                    &mut ctx.evals,
                ) {
                    Ok(it) => Settle::Go(nf, ny, it),
                    Err(failure) => Settle::Stop(ContactStatus::Solver {
                        failure,
                        s: s * ctx.scale,
                    }),
                }
            }
            None => settle(ctx, s, nf, ny),
        };
        match settled {
            Settle::Go(f, yy, it) => {
                feat = f;
                y = yy;
                inst = it;
                mode = it.mode;
            }
            Settle::Separate => return separated(ctx, s, nf, ny, segs),
            Settle::Stop(st) => {
                let p = ctx.pose(s, nf, ny);
                return (End::Stop(st), s, p);
            }
        }
        segs.open(feat, mode, s, y[0]);
        // The state just after the event (the force may jump here): a recorder sees both sides.
        ctx.record(s, feat, y, &inst);
        f0 = ctx.rates(feat, y, &ctx.geom(feat, y), &inst);
        ev0 = ctx.events(feat, y, &inst);
        // Freshly started segments begin at their boundary: do not re-trigger on rounding.
        for e in ev0.iter_mut() {
            if e.abs() <= slack {
                *e = 0.0;
            }
        }
        h = h.clamp(1e-6, max_step(feat).max(1e-6));
    }
}
