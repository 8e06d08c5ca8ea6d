//! Event handling: what each event does to a contact once it has been located and landed on
//! ([`super::event_locate`]) — the next feature, state and mode, a separation, or an end — and
//! settling the mode at a new contact state.
//!
//! Event indices are those of [`Ctx::events`]: 0 separation (the pin's path turns tangent), 1 / 2
//! the mode's margins (stick ↔ slide), 3–6 the feature's geometric events (an edge's two ends; the
//! edges of a disc's normal cone at a vertex; on the fence line the neighbouring hull edges turning
//! flush and the fence's two ends; on a fence's tail, 5 is the arc's start, see [`super::fence`]),
//! and [`TURN`], a turn of the pin's path.
//! At a convex vertex a point pin passes onto the next edge in its direction of sliding (or
//! separates if that edge faces away); a reflex vertex means a second contact in a notch, which is
//! reported as [`ContactStatus::MultiContact`], not simulated.

use super::contact_state::{Ctx, Feat, TURN};
use super::fence::{
    arc_back_to_line, arc_on_to_next_line, edge_turns_flush, fence_vertex_event, flush_pivot,
    settle_flush, Flush,
};
use super::instant::{classify, solve_in_mode, Instant, Mode};
use super::outcome::ContactStatus;

/// Tolerance band of a mode margin after a ping-pong (a sine: about 0.006°).
pub(super) const BOUNCE_BAND: f64 = 1e-4;

/// What an event leads to.
pub(super) enum Transition {
    /// The contact goes on from this feature and state: in the given mode, or with the mode
    /// settled afresh ([`settle`]).
    To(Feat, [f64; 2], Option<Mode>),
    /// The pin lets go.
    Separate,
    /// The contact cannot go on (a second contact).
    Stop(ContactStatus),
    /// A mode switch straight back to the mode just left, at the same point: stay in the current
    /// mode; the margin that fired now has a tolerance band ([`BOUNCE_BAND`]).
    Bounce,
}

/// Apply event `i` at travel `s` to the contact on `feat` in `mode` with state `y`.
/// `last_switch` is the (travel, mode left) of the last mode switch (updated here).
pub(super) fn apply_event(
    ctx: &mut Ctx,
    i: usize,
    s: f64,
    feat: Feat,
    mode: Mode,
    y: [f64; 2],
    last_switch: &mut Option<(f64, Mode)>,
) -> Transition {
    let m = ctx.poly.len();
    let scale = ctx.scale;
    let multi = move || Transition::Stop(ContactStatus::MultiContact { s: s * scale });
    let to = |next: Option<(Feat, [f64; 2])>| match next {
        Some((f, yy)) => Transition::To(f, yy, None),
        None => Transition::Separate,
    };
    match (i, feat) {
        (TURN, _) => {
            // The pin's lateral speed changes: same contact, mode settled again.
            ctx.take_turn();
            Transition::To(feat, y, None)
        }
        (0, Feat::Edge(k)) if ctx.fence.is_none() && reflex_ahead(ctx, k, y[0]) => {
            // The edge let go by turning parallel to the pin's path, so the pin runs on along
            // the edge's line into the reflex corner ahead, where the next edge blocks it: the
            // pin touches two edges at once (as when it slides into the corner in contact).
            // Casting the path again would decide that by rounding.
            multi()
        }
        (0, _) => Transition::Separate,
        (1 | 2, Feat::FenceEdge(k)) => to(Some(flush_pivot(ctx, k, y, i == 2))),
        (1 | 2, Feat::FenceVertex(k)) if ctx.flush_neighbour(k, y).is_some() => {
            // The mode changes just as an adjacent edge turns flush (the two events coincide,
            // e.g. at exactly the jam angle): the edge's arrival decides.
            let j = ctx.flush_neighbour(k, y).expect("checked by the guard");
            to(Some(edge_turns_flush(ctx, j, k, y)))
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
            if let Some((s_prev, from)) = *last_switch {
                if (s - s_prev).abs() <= 1e-12 && from == new_mode && ctx.band[i] == 0.0 {
                    ctx.band[i] = BOUNCE_BAND;
                    return Transition::Bounce;
                }
            }
            *last_switch = Some((s, mode));
            if let (Feat::Vertex(k), false) = (feat, ctx.rho > 0.0) {
                // Hooked point pin lets go: it sweeps onto the edge it now slides towards.
                to(sweep(ctx, k, new_mode == Mode::SlideLeft, y[0]))
            } else {
                Transition::To(feat, y, Some(new_mode))
            }
        }
        (3, Feat::Edge(k)) | (4, Feat::Edge(k)) => {
            let v = if i == 3 { k } else { (k + 1) % m };
            if !ctx.poly.vertex_is_convex(v) {
                return multi();
            }
            if ctx.rho > 0.0 {
                let n = ctx.poly.inward_normal(k);
                to(Some((Feat::Vertex(v), [y[0], n.angle()])))
            } else {
                to(sweep(ctx, v, i == 3, y[0]))
            }
        }
        (3, Feat::Vertex(k)) => {
            let e = (k + m - 1) % m;
            let (a, b) = ctx.poly.edge(e);
            to(Some((Feat::Edge(e), [y[0], (b - a).norm()])))
        }
        (4, Feat::Vertex(k)) => to(Some((Feat::Edge(k), [y[0], 0.0]))),
        (3..=6, Feat::FenceVertex(k)) => to(Some(fence_vertex_event(ctx, i, k, y))),
        (5, Feat::Edge(_) | Feat::Vertex(_)) => to(Some(arc_back_to_line(ctx, feat, y))),
        (6, Feat::Edge(_) | Feat::Vertex(_)) => to(Some(arc_on_to_next_line(ctx, feat, y))),
        _ => unreachable!("event index out of range"),
    }
}

/// Settle the contact at a new state (`feat`, `y`) at travel `s`: in `forced` mode if given (a mode
/// switch), else deciding the mode afresh ([`settle`]).
pub(super) fn enter(
    ctx: &mut Ctx,
    s: f64,
    feat: Feat,
    y: [f64; 2],
    forced: Option<Mode>,
) -> Settle {
    match forced {
        Some(md) => {
            let g = ctx.geom(feat, y);
            match solve_in_mode(
                ctx.model,
                ctx.fid,
                &g,
                ctx.fr,
                md,
                &mut ctx.warm,
                &mut ctx.evals,
            ) {
                Ok(it) => Settle::Go(feat, y, it),
                Err(failure) => Settle::Stop(ContactStatus::Solver {
                    failure,
                    s: s * ctx.scale,
                }),
            }
        }
        None => settle(ctx, s, feat, y),
    }
}

/// The state after a point pin's instantaneous sweep round convex vertex `k`: onto the incoming edge
/// (direction left) or the outgoing edge (right), or separation if that edge faces away from the pin.
pub(super) fn sweep(ctx: &Ctx, k: usize, left: bool, theta: f64) -> Option<(Feat, [f64; 2])> {
    let m = ctx.poly.len();
    let (edge, ell) = if left {
        let e = (k + m - 1) % m;
        let (a, b) = ctx.poly.edge(e);
        (e, (b - a).norm())
    } else {
        (k % m, 0.0)
    };
    let n = ctx.poly.inward_normal(edge);
    let v_pin = ctx.to_part(ctx.vdir, theta);
    if n.dot(v_pin) / v_pin.norm() <= 1e-12 {
        None
    } else {
        Some((Feat::Edge(edge), [theta, ell]))
    }
}

/// Outcome of settling the mode at a new contact state: continue, or the contact ends.
pub(super) enum Settle {
    Go(Feat, [f64; 2], Instant),
    Separate,
    Stop(ContactStatus),
}

/// Decide the mode at a (possibly new) contact state, resolving point-pin vertex sweeps.
pub(super) fn settle(ctx: &mut Ctx, s: f64, mut feat: Feat, mut y: [f64; 2]) -> Settle {
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

/// After a pin separates from edge k (its path tangent to the edge at orientation `theta`), is the
/// vertex it runs towards along the edge reflex?
fn reflex_ahead(ctx: &Ctx, k: usize, theta: f64) -> bool {
    let (a, b) = ctx.poly.edge(k);
    let towards_b = (b - a).dot(ctx.to_part(ctx.vdir, theta)) > 0.0;
    let m = ctx.poly.len();
    let v = if towards_b { (k + 1) % m } else { k };
    !ctx.poly.vertex_is_convex(v)
}
