//! Event location inside one step: finding the earliest event function that crosses zero within an
//! accepted step, and landing on it with a real step.
//!
//! Events are located in two stages. First, for each event function that changed sign, the
//! Illinois method ([`super::ode::illinois`]) finds its root on the step's dense output (geometric
//! events and separation from the state alone; a mode margin by solving the instant in the
//! current mode); the earliest root wins. Then the landing takes one real sub-step onto that
//! estimate and slides from its end along the rates to the root ([`land`]), so that the state
//! handed to the event has its instant, its rates, and the event function within the landing
//! tolerance of zero.
//! Before either, [`interior_dip`] shortens a step across which an event comes and goes.

use super::contact_state::{second_contact, second_contact_possible, Ctx, Feat, N_EVENTS};
use super::contact_step::{dp_step, step_change_ok, Cursor, StepResult};
use super::instant::{push_margin, solve_in_mode, Instant};
use super::ode::{illinois, Bracket};

/// The first fraction of the step `step` of size `h` from `at` (event functions `ev1` at its end)
/// at which an event comes and goes inside it, which the end-point signs miss: a mode that breaks
/// at an interior stage and holds again at the end, or one of the geometric event functions (edge
/// ends, normal cone, fence ends), which depend on the state alone, so that the dense output shows
/// without solving anything whether one positive at both ends dips below −slack at one of eight
/// interior fractions; likewise a disc pin's brief second touch on a concave part.
pub(super) fn interior_dip(
    ctx: &Ctx,
    at: &Cursor,
    step: &StepResult,
    h: f64,
    ev1: &[f64; N_EVENTS],
) -> Option<f64> {
    let mode_dip = step.margin_dip.filter(|_| ev1[1] >= 0.0 && ev1[2] >= 0.0);
    let (feat, s, y0, slack) = (at.feat, at.s, at.y, at.slack);
    // Nothing to miss unless an event not yet crossed ends the step near zero (the guard keeps a
    // step's change of the contact coordinate below 0.5) or a disc could touch a second edge.
    let near = (3..N_EVENTS).any(|j| (0.0..1.0).contains(&ev1[j]));
    let second = second_contact_possible(ctx);
    if !near && !second {
        return mode_dip;
    }
    (1..8)
        .map(|k| k as f64 / 8.0)
        .find(|&t| {
            let yt = step.dp.dense(y0, h, t);
            // The event functions as `ev1` has them: with their bands (an edge's end a bounce
            // let the state run past, see `ctx.band`), else a banded state below zero looks like
            // a dip in every step and the steps shrink without end.
            let dips = near
                && ctx
                    .feature_events(feat, yt)
                    .iter()
                    .zip(&ctx.band[3..])
                    .zip(&ev1[3..])
                    .any(|((&e, &b), &e1)| e1 >= 0.0 && e + b < -slack);
            dips || (second && second_contact(ctx, feat, &ctx.pose(s + t * h, feat, yt), s + t * h))
        })
        .or(mode_dip)
}

/// The events that cross zero within a step from `at` ending with event functions `ev1` (those
/// not already past their boundary at its start).
pub(super) fn crossed_events(at: &Cursor, ev1: &[f64; N_EVENTS]) -> Vec<usize> {
    (0..N_EVENTS)
        .filter(|&i| ev1[i] < 0.0 && at.ev0[i] >= -at.slack)
        .collect()
}

/// The earliest of the `crossed` events on the dense output of `step` (size `h`, from `at`):
/// (fraction of the step, event index). The warm starts of the instant solve are left as they were.
pub(super) fn earliest_crossing(
    ctx: &mut Ctx,
    at: &Cursor,
    step: &StepResult,
    h: f64,
    ev1: &[f64; N_EVENTS],
    crossed: &[usize],
) -> (f64, usize) {
    let (feat, mode, inst) = (at.feat, at.mode, at.inst);
    let mut best = (2.0, 0usize);
    let warm_saved = ctx.warm;
    let root_tol = 1e-3 * ctx.tol;
    let band = ctx.band;
    for &i in crossed {
        let g0 = at.ev0[i].max(0.0);
        let t = illinois(
            |t| {
                let yt = step.dp.dense(at.y, h, t);
                if i == 0 || i >= 3 {
                    ctx.events(feat, yt, &inst)[i]
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
    best
}

/// How far (units of a of travel) a landing slides from its real sub-step along the rates there:
/// an Euler slide of δs errs by about δs²·|dy/ds|' / 2, below 1e-8 for δs ≤ 1e-4.
const ANCHOR_REACH: f64 = 1e-4;

/// A Dormand–Prince sub-step of fraction `t` of the accepted `step` from the cursor, when it is
/// valid (its own error estimate within 10× the tolerance, the step guard, and within 1e3·tol
/// of the dense output): its end state and the rates there. An untrusted sub-step's state means
/// nothing (the −880° case landed on one): the landing then uses the dense output.
fn real_substep(
    ctx: &mut Ctx,
    at: &Cursor,
    step: &StepResult,
    h: f64,
    t: f64,
) -> Option<([f64; 2], [f64; 2])> {
    if t * h <= 1e-15 {
        return None;
    }
    let r = dp_step(ctx, at.feat, at.mode, at.y, at.f0, t * h).ok()?;
    let yd = step.dp.dense(at.y, h, t);
    let near =
        (r.dp.y1[0] - yd[0]).abs() <= 1e3 * ctx.tol && (r.dp.y1[1] - yd[1]).abs() <= 1e3 * ctx.tol;
    (r.dp.err <= 10.0 && step_change_ok(at.feat, at.y, r.dp.y1) && near)
        .then(|| (r.dp.y1, r.dp.f1()))
}

/// Where the landing stopped: the state, the instant solved there in the step's mode, and the
/// rates it gives.
pub(super) struct Landed {
    pub(super) y: [f64; 2],
    pub(super) inst: Instant,
    pub(super) rates: [f64; 2],
}

/// A trial point while landing on an event.
enum Trial {
    /// The start of the step.
    Start,
    /// A landing state and the located event's function there.
    At(Landed, f64),
    /// A state whose instant could not be solved, or past another event.
    Invalid,
}

/// Where the landing on event `i` ended.
pub(super) struct Landing {
    /// The event landed on.
    pub(super) i: usize,
    /// The landing point: its fraction of the step and the state there, or `None` for the start
    /// of the step.
    pub(super) at: Option<(f64, Landed)>,
    /// The event function at the landing.
    pub(super) g: f64,
    /// Some trial could not be trusted (the bracket shrank from above).
    pub(super) any_invalid: bool,
}

/// Land on event `i`, estimated at fraction `t_est` of the accepted `step` of size `h` from `at`:
/// the state at the largest fraction with g ≥ 0 (or g just below 0 within the landing
/// tolerance), with the instant solved there.
///
/// One real sub-step goes to the estimate (located on the dense output, so usually within the
/// integration error of the root); from its end the landing slides along the rates there to the
/// root, each trial one instant solve. Before, every trial was a sub-step of its own (2.8 per
/// landing on average, a quarter of all evaluations); the slide is a first-order step over a
/// travel of the order of the landing tolerance, so the state handed on is as accurate as a
/// sub-step's end. Where the sub-step cannot be trusted (or a trial falls beyond ANCHOR_REACH)
/// the trial state comes from the dense output instead. The event functions are evaluated at the
/// states the contact will continue from, so a landed mode margin or edge end is within the
/// landing tolerance of zero at the state handed to the event.
pub(super) fn land(
    ctx: &mut Ctx,
    at: &Cursor,
    step: &StepResult,
    h: f64,
    ev1: &[f64; N_EVENTS],
    (t_est, i): (f64, usize),
) -> Landing {
    let (feat, mode, y, slack) = (at.feat, at.mode, at.y, at.slack);
    let t_est = t_est.clamp(0.0, 1.0);
    // A real sub-step onto the estimate: the state the contact continues from is then as
    // accurate as any step's end (the dense output is one order less accurate).
    let anchor = real_substep(ctx, at, step, h, t_est);
    // The state at fraction t of the step: a short Euler slide along the anchor's rates when t
    // is within ANCHOR_REACH of it (its error, O(δs²), far below the tolerance), else the dense
    // output; its instant in the step's mode and its event i. A trial past another event
    // (separation or a geometric one) or whose instant cannot be solved cannot be trusted: the
    // bracket shrinks from above.
    let trial = |t: f64, ctx: &mut Ctx| -> Trial {
        if t * h <= 1e-15 {
            return Trial::Start;
        }
        let yt = match &anchor {
            Some((ya, fa)) if ((t - t_est) * h).abs() <= ANCHOR_REACH => {
                let ds = (t - t_est) * h;
                [ya[0] + ds * fa[0], ya[1] + ds * fa[1]]
            }
            _ => step.dp.dense(y, h, t),
        };
        match ctx.rhs(feat, mode, yt) {
            Ok((rates, inst, g)) => {
                let ev = ctx.events_at(feat, yt, &g, &inst);
                if [0, 3, 4, 5, 6].iter().all(|&j| j == i || ev[j] >= -slack) {
                    let g = ev[i];
                    Trial::At(Landed { y: yt, inst, rates }, g)
                } else {
                    Trial::Invalid
                }
            }
            Err(_) => Trial::Invalid,
        }
    };
    let mut bracket = Bracket::new(at.ev0[i].max(0.0), ev1[i]);
    // The landing: the trial at the largest t with g ≥ 0 (or g just below 0 within the
    // landing tolerance), and its g.
    let mut best: (Trial, f64, f64) = (Trial::Start, 0.0, at.ev0[i].max(0.0));
    let mut t = t_est;
    let mut any_invalid = false;
    // Landing tolerance: far below the integration tolerance, far above rounding.
    let g_tol = at.land_tol;
    for _ in 0..40 {
        let tr = trial(t, ctx);
        let gt = match &tr {
            Trial::Start => at.ev0[i].max(0.0),
            Trial::At(_, g) => *g,
            Trial::Invalid => {
                any_invalid = true;
                bracket.cut_above(t);
                if bracket.width() * h <= 1e-13 {
                    break;
                }
                t = bracket.midpoint();
                continue;
            }
        };
        let close = gt.abs() <= g_tol;
        let lower_end = bracket.narrow(t, gt);
        if lower_end || close {
            best = (tr, t, gt);
        }
        if close || bracket.width() * h <= 1e-13 {
            break;
        }
        t = bracket.next();
    }
    let (landing, best_t, best_g) = best;
    Landing {
        i,
        at: match landing {
            Trial::At(l, _) => Some((best_t, l)),
            _ => None,
        },
        g: best_g,
        any_invalid,
    }
}

/// The event to apply at the landing state `y_land` on `feat` (`None`: none can be trusted).
///
/// If a trial was invalid and the landing fell short of the event, the event lies beyond a
/// stretch the integrator cannot resolve (the rates blow up before it). Near a separation that is
/// the triple point where the pin's path turns tangent while the sliding side's contact velocity
/// does too (κ = n·v_pin / n·v_b → 0/0): the part is within asin(push margin) of letting go, so it
/// separates here when that margin is below min(1e3·tol, 1e-3) (an orientation error below 0.06°).
/// Anywhere else the caller says so rather than apply the event at a state short of it.
pub(super) fn landed_event(
    ctx: &Ctx,
    feat: Feat,
    y_land: [f64; 2],
    landing: &Landing,
    slack: f64,
) -> Option<usize> {
    if landing.any_invalid && landing.g > slack {
        let g = ctx.geom(feat, y_land);
        if push_margin(&g).abs() <= (1e3 * ctx.tol).min(1e-3) {
            Some(0)
        } else {
            None
        }
    } else {
        Some(landing.i)
    }
}

#[cfg(test)]
mod tests {
    use crate::geometry::{Polygon, Pose, Vec2};
    use crate::mechanics::outcome::{ContactFeature, ContactStatus, TraceSample};
    use crate::mechanics::part_model::{PartModel, Support};
    use crate::mechanics::{ContactSettings, Pin};

    /// A square pushed near a corner by a point pin: the part turns until the pin reaches the
    /// corner and leaves there. That edge end is an event, landed on: the last sample has the
    /// contact point on the corner to the landing tolerance (far below the steps' lengths), and no
    /// sample on the edge lies beyond it.
    #[test]
    fn an_edge_end_is_landed_on_to_the_landing_tolerance() {
        let poly = Polygon::new(&[
            Vec2::new(-1.0, -1.0),
            Vec2::new(1.0, -1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(-1.0, 1.0),
        ])
        .unwrap();
        let model = PartModel::new(&poly, &Support::Uniform).unwrap();
        let k = model.scale();
        let corners: Vec<Vec2> = model.polygon().vertices().iter().map(|&v| v * k).collect();
        let pin = Pin {
            radius: 0.0,
            lateral_speed: 0.0,
        };
        for (mu, y) in [(0.05, 0.8), (0.3, 0.6), (0.05, -0.7), (0.8, -0.5)] {
            let settings = ContactSettings {
                mu_c: mu,
                ..ContactSettings::default()
            };
            let mut trace: Vec<TraceSample> = Vec::new();
            let out = crate::mechanics::pass::push(
                &model,
                Pose::new(0.0, 0.0, 0.0),
                Vec2::new(3.0, y),
                &pin,
                &settings,
                Some(&mut trace),
            );
            assert_eq!(out.status, ContactStatus::Ok);
            assert!(
                out.rotation_rad.abs() > 0.1,
                "μc {mu}, y {y}: the part turned"
            );
            // The contact point in the part's frame, against the edge's end.
            let local = |t: &TraceSample| t.pose.apply_inverse(t.contact_point);
            let last = trace.last().unwrap();
            assert!(matches!(last.feature, ContactFeature::Edge(_)));
            let miss = corners
                .iter()
                .map(|&c| (local(last) - c).norm())
                .fold(f64::INFINITY, f64::min)
                / k;
            assert!(
                miss < 1e-8,
                "μc {mu}, y {y}: the pin left {miss:e}·a from a corner"
            );
            for t in &trace {
                let p = local(t);
                assert!(
                    p.x.abs().max(p.y.abs()) <= 1.0 + 1e-8,
                    "μc {mu}, y {y}: a contact beyond the edge's end at {p:?}"
                );
            }
        }
    }
}
