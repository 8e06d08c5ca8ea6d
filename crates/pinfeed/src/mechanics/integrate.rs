//! Integration of one contact: from the first touch until separation, in pin travel, with error
//! control and precise event location (docs/physics.md#integration-and-events).
//!
//! The contact is held in reduced coordinates on its feature (`mechanics::contact_state`). Each turn
//! of the loop in `integrate_contact` is one of these named steps:
//!
//! 1. **take a step** (`take_step`): Dormand–Prince 5(4) (`mechanics::contact_step`) with absolute
//!    tolerance `tol` on θ (radians) and on ℓ, φ, σ (units of a), rejected and shrunk on a failed
//!    solve, the error test or the step guard, shortened when an event comes and goes inside it,
//!    and accepted when no event function crosses zero;
//! 2. **locate the event** and **land on it** (`land_on_event`, with `mechanics::event_locate`):
//!    the earliest crossing on the dense output by the Illinois method, then a real sub-step onto it;
//! 3. **apply it** (`mechanics::event_apply`): separation (n·v_pin = 0), mode margins
//!    (stick ↔ slide), edge ends, a disc's normal cone at a vertex, a fence's events
//!    ([`super::fence`]), turns of the pin's path;
//! 4. **open the next segment** (`open_next`): settle the mode on the new feature, reset the
//!    event bands, record the state just after the event, and size the first step from the new
//!    segment's rates (`contact_step::first_step`).
//!
//! The pass loop around it (casting the obstacle's path again after a separation) is
//! `mechanics::pass`.

use super::contact_state::{second_contact, second_contact_possible, Ctx, Feat, N_EVENTS, TURN};
use super::contact_step::{dp_step, first_step, max_step, step_change_ok, Cursor, StepResult};
use super::event_apply::{apply_event, enter, settle, Settle, Transition, BOUNCE_BAND};
use super::event_locate::{crossed_events, earliest_crossing, interior_dip, land, landed_event};
use super::instant::{Instant, Mode};
use super::outcome::{ContactStatus, Segment};
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

/// Where a contact ends: how, at which (normalised) travel, and the part's pose there.
pub(super) type Finish = (End, f64, Pose);

/// The smallest step (units of a) before the integrator gives up.
const H_MIN: f64 = 1e-13;

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
        // A fence's tail holds the part as the fence does: not a pin balancing it.
        let pin_like = matches!(feat, Feat::Edge(_) | Feat::Vertex(_)) && !ctx.arc;
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
                self.open = Some((feat, mode, last.s_begin / scale, last.theta_begin_rad));
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
                theta_begin_rad: t0,
                theta_end_rad: theta,
            });
        }
    }
}

/// The contact stops with `status` at (s, feat, y).
fn stop(ctx: &Ctx, status: ContactStatus, s: f64, feat: Feat, y: [f64; 2]) -> Finish {
    let p = ctx.pose(s, feat, y);
    (End::Stop(status), s, p)
}

/// The end of a contact that separated at (s, feat, y), after the self-check.
fn separated(ctx: &Ctx, s: f64, feat: Feat, y: [f64; 2], segs: &Tally) -> Finish {
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
) -> Finish {
    segs.still = 0.0;
    let (feat, y, inst) = match settle(ctx, s_start, feat0, y_start) {
        Settle::Go(f, yy, i) => (f, yy, i),
        Settle::Separate => {
            let p = ctx.pose(s_start, feat0, y_start);
            return (End::Separated, s_start, p);
        }
        Settle::Stop(st) => return stop(ctx, st, s_start, feat0, y_start),
    };
    let mut at = begin(ctx, s_start, feat, y, inst, segs);
    let mut last_switch: Option<(f64, Mode)> = None;
    // (travel, feature left, event index) of the last change of contact feature.
    let mut last_feature_change: Option<(f64, Feat, usize)> = None;
    loop {
        if let Some(finish) = over_budget(ctx, settings, &at, s_start) {
            return finish;
        }
        // An event function already negative at the start of a step: the state is at an event.
        let pending = (0..N_EVENTS).find(|&i| at.ev0[i] < -at.slack);
        let (i, s_ev, y_ev, inst_ev) = if let Some(i) = pending {
            (i, at.s, at.y, at.inst)
        } else if ctx.at_turn(at.s) {
            (TURN, at.s, at.y, at.inst)
        } else {
            match take_step(ctx, &mut at, segs) {
                Stepped::Again => continue,
                Stepped::Done(finish) => return finish,
                Stepped::Crossed(step, ev1, crossed) => {
                    match land_on_event(ctx, &at, &step, &ev1, &crossed, segs) {
                        Ok(event) => event,
                        Err(finish) => return finish,
                    }
                }
            }
        };

        // Turns of the pin's path are bounded by the path itself; only contact events count.
        segs.events += u32::from(i != TURN);
        if segs.events > settings.max_events {
            let events = segs.events;
            return stop(
                ctx,
                ContactStatus::EventLimit { events },
                s_ev,
                at.feat,
                y_ev,
            );
        }
        at.s = s_ev;
        at.y = y_ev;
        ctx.record(at.s, at.feat, at.y, &inst_ev);
        segs.close(at.s, at.y[0], ctx.scale);
        let (s, feat, y) = (at.s, at.feat, at.y);
        let next = match apply_event(ctx, i, s, feat, at.mode, y, &mut last_switch) {
            Transition::To(nf, ny, forced) => (nf, ny, forced),
            Transition::Separate => return separated(ctx, s, feat, y, segs),
            Transition::Stop(st) => return stop(ctx, st, s, feat, y),
            Transition::Bounce => {
                // Stay in the mode: the segment just closed goes on.
                segs.reopen(feat, at.mode, s, y[0], ctx.scale);
                at.ev0 = ctx.events(feat, y, &inst_ev);
                at.inst = inst_ev;
                at.f0 = ctx.rates(feat, y, &ctx.geom(feat, y), &at.inst);
                continue;
            }
        };
        if let Some(finish) = open_next(ctx, &mut at, i, next, &mut last_feature_change, segs) {
            return finish;
        }
    }
}

/// Open the segment at the cursor's state: record it, and compute its rates and event functions.
fn open_segment(ctx: &mut Ctx, at: &mut Cursor, segs: &mut Tally) {
    segs.open(at.feat, at.mode, at.s, at.y[0]);
    ctx.record(at.s, at.feat, at.y, &at.inst);
    at.f0 = ctx.rates(at.feat, at.y, &ctx.geom(at.feat, at.y), &at.inst);
    at.ev0 = ctx.events(at.feat, at.y, &at.inst);
}

/// The cursor at the first touch (state settled), its segment open and the event bands cleared.
fn begin(
    ctx: &mut Ctx,
    s: f64,
    feat: Feat,
    y: [f64; 2],
    inst: Instant,
    segs: &mut Tally,
) -> Cursor {
    let land_tol = 1e-2 * ctx.tol;
    let mut at = Cursor {
        s,
        feat,
        mode: inst.mode,
        y,
        inst,
        f0: [0.0; 2],
        ev0: [0.0; N_EVENTS],
        // First step: a tenth of a, shrunk by the error control if the motion is fast.
        h: 0.1,
        land_tol,
        slack: 100.0 * land_tol,
    };
    open_segment(ctx, &mut at, segs);
    ctx.band = [0.0; N_EVENTS];
    at
}

/// The contact's evaluation or travel budget is spent: it stops where it stands.
fn over_budget(ctx: &Ctx, settings: &ContactSettings, at: &Cursor, s_start: f64) -> Option<Finish> {
    let work = ctx.evals + ctx.rhs_calls;
    let status = if work > settings.max_evaluations {
        ContactStatus::EvaluationLimit { evaluations: work }
    } else if at.s - s_start > settings.max_travel {
        ContactStatus::TravelLimit {
            travel: (at.s - s_start) * ctx.scale,
        }
    } else {
        return None;
    };
    Some(stop(ctx, status, at.s, at.feat, at.y))
}

/// What one attempted step did.
enum Stepped {
    /// The step was rejected or shortened, or accepted with no event in it: go on from the cursor.
    Again,
    /// The step (event functions at its end, the events that crossed zero) passed every test but
    /// crosses events: locate the earliest.
    Crossed(Box<StepResult>, [f64; N_EVENTS], Vec<usize>),
    /// The contact ends.
    Done(Finish),
}

/// Take one step of size `at.h` from the cursor (ending at the next turn of the pin's path if it
/// comes first): retry smaller on a failed solve, the error test or the step guard; shorten it
/// when an event comes and goes inside it; accept it (advancing the cursor and growing the next
/// step) when no event function crosses zero.
fn take_step(ctx: &mut Ctx, at: &mut Cursor, segs: &mut Tally) -> Stepped {
    // A step never crosses a turn of the pin's path: it ends there.
    let to_turn = ctx.turn_at() - at.s;
    let clipped = at.h >= to_turn;
    if clipped {
        at.h = to_turn;
    }
    let h = at.h;
    let step = match dp_step(ctx, at.feat, at.mode, at.y, at.f0, h) {
        Ok(r) => r,
        Err(failure) => {
            at.h *= 0.25;
            if at.h < H_MIN {
                let status = ContactStatus::Solver {
                    failure,
                    s: at.s * ctx.scale,
                };
                return Stepped::Done(stop(ctx, status, at.s, at.feat, at.y));
            }
            return Stepped::Again;
        }
    };
    let guarded = !step_change_ok(at.feat, at.y, step.dp.y1);
    ctx.guard_refusals += u64::from(guarded);
    if step.dp.err > 1.0 || guarded {
        at.h *= if guarded {
            0.25
        } else {
            (0.9 * step.dp.err.powf(-0.2)).max(0.2)
        };
        if at.h < H_MIN {
            let status = ContactStatus::StepTooSmall {
                s: at.s * ctx.scale,
            };
            return Stepped::Done(stop(ctx, status, at.s, at.feat, at.y));
        }
        return Stepped::Again;
    }
    let ev1 = ctx.events_at(at.feat, step.dp.y1, &step.g1, &step.inst1);
    if let Some(t_dip) = interior_dip(ctx, at, &step, h, &ev1) {
        // The contact runs off its feature and back (e.g. past an edge's end), or its mode
        // breaks and recovers, within the step: shorten the step so that it ends beyond
        // the first crossing, where the event is located as usual. (Below 1e-10 a a dip
        // is the start state itself sitting on the boundary: the endpoint rule decides.)
        if h * t_dip >= 1e-10 {
            at.h *= t_dip;
            return Stepped::Again;
        }
    }
    let crossed = crossed_events(at, &ev1);
    if !crossed.is_empty() {
        return Stepped::Crossed(Box::new(step), ev1, crossed);
    }
    let factor = (0.9 * step.dp.err.max(1e-10).powf(-0.2)).clamp(0.2, 5.0);
    // A bounced margin that has recovered gets its ordinary zero threshold back.
    for (b, e) in ctx.band.iter_mut().zip(ev1) {
        if *b > 0.0 && e - *b > at.slack {
            *b = 0.0;
        }
    }
    segs.ride(ctx, at.feat, step.dp.f1()[0].abs().max(at.f0[0].abs()), h);
    at.s = if clipped { ctx.turn_at() } else { at.s + h };
    at.y = step.dp.y1;
    at.inst = step.inst1;
    at.f0 = step.dp.f1();
    at.ev0 = ev1;
    segs.steps += 1;
    ctx.record(at.s, at.feat, at.y, &at.inst);
    if second_contact_possible(ctx) {
        let pose = ctx.pose(at.s, at.feat, at.y);
        if second_contact(ctx, at.feat, &pose, at.s) {
            let status = ContactStatus::MultiContact {
                s: at.s * ctx.scale,
            };
            return Stepped::Done((End::Stop(status), at.s, pose));
        }
    }
    at.h = (h * factor).min(max_step(at.feat));
    Stepped::Again
}

/// Locate the earliest of the `crossed` events in the accepted `step` (size `at.h`) and land on
/// it: (event, travel, state, instant) there, counting the landing step; or the contact stops
/// when the event cannot be reached.
fn land_on_event(
    ctx: &mut Ctx,
    at: &Cursor,
    step: &StepResult,
    ev1: &[f64; N_EVENTS],
    crossed: &[usize],
    segs: &mut Tally,
) -> Result<(usize, f64, [f64; 2], Instant), Finish> {
    let h = at.h;
    let estimate = earliest_crossing(ctx, at, step, h, ev1, crossed);
    let landing = land(ctx, at, step, h, ev1, estimate);
    let (s_land, y_land, inst_land) = match &landing.at {
        Some((t, l)) => {
            // The landing's sub-step (see `land`) counts as a step.
            segs.steps += 1;
            segs.ride(ctx, at.feat, l.rates[0].abs().max(at.f0[0].abs()), t * h);
            (at.s + t * h, l.y, l.inst)
        }
        None => (at.s, at.y, at.inst),
    };
    match landed_event(ctx, at.feat, y_land, &landing, at.slack) {
        Some(i) => Ok((i, s_land, y_land, inst_land)),
        None => {
            let status = ContactStatus::StepTooSmall {
                s: at.s * ctx.scale,
            };
            Err(stop(ctx, status, at.s, at.feat, at.y))
        }
    }
}

/// Open the next segment after event `i` at the cursor: settle the mode at the new state (`next`:
/// feature, state, forced mode), set the event bands for the new feature, and record the state
/// just after the event. The contact may end here instead.
fn open_next(
    ctx: &mut Ctx,
    at: &mut Cursor,
    i: usize,
    (nf, ny, forced): (Feat, [f64; 2], Option<Mode>),
    last_feature_change: &mut Option<(f64, Feat, usize)>,
    segs: &mut Tally,
) -> Option<Finish> {
    let s = at.s;
    if nf != at.feat {
        // Event indices mean different things on the new feature: start with no bands, except
        // when this transition merely returns, at the same point, to the feature just left (a
        // marginal geometry, e.g. a force line through an edge's end): then stay there and let
        // the event that ejected it run down to −BOUNCE_BAND before it counts.
        let cycle = matches!(*last_feature_change, Some((s0, f0, _)) if (s - s0).abs() <= 1e-12 && f0 == nf);
        let ejected_by = last_feature_change.map(|(_, _, i)| i);
        ctx.band = [0.0; N_EVENTS];
        if cycle {
            if let Some(j) = ejected_by {
                ctx.band[j] = BOUNCE_BAND;
            }
        }
        *last_feature_change = Some((s, at.feat, i));
    }
    match enter(ctx, s, nf, ny, forced) {
        Settle::Go(f, yy, it) => {
            at.feat = f;
            at.y = yy;
            at.inst = it;
            at.mode = it.mode;
        }
        Settle::Separate => return Some(separated(ctx, s, nf, ny, segs)),
        Settle::Stop(st) => return Some(stop(ctx, st, s, nf, ny)),
    }
    // The state just after the event (the force may jump here): a recorder sees both sides.
    open_segment(ctx, at, segs);
    // Freshly started segments begin at their boundary: do not re-trigger on rounding.
    for e in at.ev0.iter_mut() {
        if e.abs() <= at.slack {
            *e = 0.0;
        }
    }
    at.h = first_step(
        at.feat,
        at.f0,
        at.h.clamp(1e-6, max_step(at.feat).max(1e-6)),
        1e-6,
    );
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Polygon, Vec2};
    use crate::mechanics::part_model::{PartModel, Support};
    use crate::mechanics::{mason_vote, ContactSettings};

    /// A 2 × 1 rectangle (uniform pressure) and its normalised right edge: the edge's index, its
    /// start and its length.
    fn rectangle() -> (PartModel, usize, Vec2, f64) {
        let poly = Polygon::new(&[
            Vec2::new(-1.0, -0.5),
            Vec2::new(1.0, -0.5),
            Vec2::new(1.0, 0.5),
            Vec2::new(-1.0, 0.5),
        ])
        .unwrap();
        let model = PartModel::new(&poly, &Support::Uniform).unwrap();
        let v = model.polygon().vertices().to_vec();
        let k = (0..v.len())
            .find(|&k| v[k].x > 0.0 && v[(k + 1) % v.len()].x > 0.0)
            .expect("a right edge");
        let (a, b) = (v[k], v[(k + 1) % v.len()]);
        (model, k, a, (b - a).norm())
    }

    /// A point pin moving in −x from x = 2 (normalised) at height `y`, touching the right edge at
    /// travel `s`; the contact integrated from there until it ends.
    fn push(
        model: &PartModel,
        edge: usize,
        start: Vec2,
        y: f64,
        settings: &ContactSettings,
    ) -> Finish {
        let mut ctx = Ctx::new(
            model,
            model.polygon(),
            settings,
            settings.mu_c,
            0.0,
            Vec2::new(-1.0, 0.0),
            Vec2::new(2.0, y),
            None,
            None,
        );
        let s = 2.0 - start.x;
        let ell = y - start.y;
        integrate_contact(
            &mut ctx,
            settings,
            s,
            Feat::Edge(edge),
            [0.0, ell],
            &mut Tally::default(),
        )
    }

    #[test]
    fn a_push_through_the_centroid_translates_until_the_travel_limit() {
        let (model, edge, start, _) = rectangle();
        let settings = ContactSettings {
            max_travel: 1.5,
            ..ContactSettings::default()
        };
        let (end, s, pose) = push(&model, edge, start, 0.0, &settings);
        assert!(
            matches!(end, End::Stop(ContactStatus::TravelLimit { .. })),
            "{:?}",
            match end {
                End::Separated => "separated".to_string(),
                End::Stop(st) => format!("{st:?}"),
            }
        );
        // By symmetry the part neither turns nor leaves the line of the push.
        assert!(pose.theta_rad.abs() < 1e-9, "θ {}", pose.theta_rad);
        assert!(pose.y.abs() < 1e-9, "y {}", pose.y);
        // It moved with the pin from the touch on, past the travel limit (counted from the touch;
        // the step that crosses it is the last).
        let touch = 2.0 - start.x;
        assert!(s - touch >= 1.5 && s - touch < 50.0, "ended at {s}");
        assert!(
            (pose.x + (s - touch)).abs() < 1e-6,
            "x {} after {}",
            pose.x,
            s - touch
        );
    }

    #[test]
    fn an_off_centre_push_turns_the_part_the_way_masons_vote_says() {
        let (model, edge, start, len) = rectangle();
        for mu in [0.1, 0.5, 1.5] {
            for frac in [0.15, 0.3, 0.7, 0.85] {
                let y = start.y + frac * len;
                let settings = ContactSettings {
                    mu_c: mu,
                    max_travel: 0.05,
                    ..ContactSettings::default()
                };
                let (_, _, pose) = push(&model, edge, start, y, &settings);
                let p = Vec2::new(start.x, y);
                let vote = mason_vote(-p, Vec2::new(-1.0, 0.0), Vec2::new(-1.0, 0.0), mu);
                assert_ne!(vote, 0);
                assert_eq!(
                    pose.theta_rad.signum() as i32,
                    vote,
                    "μc {mu}, contact at {frac} of the edge: θ {}",
                    pose.theta_rad
                );
            }
        }
    }
}
