//! One integration step of a contact: the Dormand–Prince step ([`super::ode`]) with the contact's
//! right-hand side in a fixed feature and mode, the mode margins watched at the interior stages,
//! and the guards on what one step may do; plus where the integrator stands between steps
//! ([`Cursor`]).

use super::contact_state::{Ctx, Feat, N_EVENTS};
use super::instant::{ContactGeom, Instant, Mode};
use super::ode::{self, NonFinite, Step};
use super::part_model::SolveFailure;

/// Where the integration of one contact stands: at travel `s` on `feat` in `mode` with state `y`,
/// the instant, rates and event functions there, and the size of the next step.
#[derive(Debug, Clone, Copy)]
pub(super) struct Cursor {
    pub(super) s: f64,
    pub(super) feat: Feat,
    pub(super) mode: Mode,
    pub(super) y: [f64; 2],
    pub(super) inst: Instant,
    /// The rates at (s, y): the next step's first stage.
    pub(super) f0: [f64; 2],
    /// The event functions at (s, y).
    pub(super) ev0: [f64; N_EVENTS],
    /// The next step's size (units of a of travel).
    pub(super) h: f64,
    /// Events are landed to |g| ≤ `land_tol`; a fresh segment treats |g| ≤ `slack` as "at the
    /// boundary" (the new mode's margin starts at zero up to the landing error), and only
    /// g < −slack at a segment start means the state is already past an event.
    pub(super) land_tol: f64,
    pub(super) slack: f64,
}

/// Step acceptance guard: the most one accepted step may change θ (radians) or the contact
/// coordinate ℓ (units of a) / φ (radians). The embedded error estimate is only asymptotic for
/// small changes: near a singular instant (a sliding twist whose contact velocity turns tangential,
/// so κ = n·v_pin / n·v_b blows up) all seven stages can agree on a huge rate and a step of 1e-4 a
/// of travel passes the error test while turning the part by 900°. No real contact needs more
/// than this per step at any tolerance: the guard shrinks the step instead. A flush fence edge
/// translates at constant rates, so its fence coordinate is not limited.
const MAX_STEP_CHANGE: f64 = 0.5;
/// Does a step from `y0` to `y1` on `feat` pass the acceptance guard?
pub(super) fn step_change_ok(feat: Feat, y0: [f64; 2], y1: [f64; 2]) -> bool {
    let d_theta = (y1[0] - y0[0]).abs();
    let d_contact = match feat {
        Feat::FenceEdge(_) => 0.0,
        _ => (y1[1] - y0[1]).abs(),
    };
    d_theta <= MAX_STEP_CHANGE && d_contact <= MAX_STEP_CHANGE
}

/// The first step after an event is at most the travel over which the rates at its start would
/// change θ or the contact coordinate by half the guard's allowance.
const FIRST_STEP_CHANGE: f64 = 0.5 * MAX_STEP_CHANGE;
/// The first step (units of a) after an event: the step the integrator had reached, `h`, unless
/// the new segment's rates `f0` at its start would carry it past [`FIRST_STEP_CHANGE`] (never
/// below `h_floor`). A segment's rates can be far faster than the last one's (a disc rolling
/// round a vertex turns its normal at about 1/ρ per unit of travel): without this cap the first
/// step was refused by the guard, 4× smaller, often twice (45% of the first steps after events
/// on the quickstart line).
pub(super) fn first_step(feat: Feat, f0: [f64; 2], h: f64, h_floor: f64) -> f64 {
    let rate = match feat {
        Feat::FenceEdge(_) => f0[0].abs(),
        _ => f0[0].abs().max(f0[1].abs()),
    };
    if rate * h > FIRST_STEP_CHANGE {
        (FIRST_STEP_CHANGE / rate).max(h_floor)
    } else {
        h
    }
}

/// The largest step (units of a) on `feat`: a flush fence edge translates at constant rates, so a
/// single step may take it along any length of fence (its events are monotone in the travel);
/// elsewhere two units of a, so that no event can come and go within one step.
pub(super) fn max_step(feat: Feat) -> f64 {
    match feat {
        Feat::FenceEdge(_) => f64::INFINITY,
        _ => 2.0,
    }
}

/// A Dormand–Prince step of a contact: the scheme's step and what the contact adds to it.
pub(super) struct StepResult {
    pub(super) dp: Step<2>,
    /// The instant at the end of the step.
    pub(super) inst1: Instant,
    /// The contact geometry at the end of the step (the last stage is evaluated at `dp.y1`).
    pub(super) g1: ContactGeom,
    /// The first interior stage (as a fraction of the step) at which the mode's own margins were
    /// clearly violated: a mode switch that comes and goes inside the step.
    pub(super) margin_dip: Option<f64>,
}

/// A stage's mode margin below −MARGIN_DIP (a sine) means the mode broke inside the step even if
/// it holds again at both ends (stage states are approximations: a clear violation only).
const MARGIN_DIP: f64 = 1e-3;

/// One Dormand–Prince step of size h from (y0, f0) on `feat` in `mode`, watching the mode's
/// margins at the interior stages.
#[inline(always)]
pub(super) fn dp_step(
    ctx: &mut Ctx,
    feat: Feat,
    mode: Mode,
    y0: [f64; 2],
    f0: [f64; 2],
    h: f64,
) -> Result<StepResult, SolveFailure> {
    let mut last = None;
    let mut margin_dip = None;
    let tol = ctx.tol;
    let dp = ode::dp_step(
        |c, yi| {
            let (d, inst, g) = ctx.rhs(feat, mode, yi)?;
            let broken = inst.margins[0] + ctx.band[1] < -MARGIN_DIP
                || inst.margins[1] + ctx.band[2] < -MARGIN_DIP;
            // Interior stages only (C < 1; stages 5 and 6 sit at the step's end).
            if c < 1.0 && broken && margin_dip.is_none() {
                margin_dip = Some(c);
            }
            // Only the last stage's (at the step's end) is kept: stages 6 and 7 sit at c = 1,
            // and the copy is skipped for the interior ones.
            if c == 1.0 {
                last = Some((inst, g));
            }
            Ok::<_, SolveFailure>(d)
        },
        y0,
        f0,
        h,
        tol,
    )?;
    let (inst1, g1) = last.expect("six stages ran");
    Ok(StepResult {
        dp,
        inst1,
        g1,
        margin_dip,
    })
}

impl From<NonFinite> for SolveFailure {
    fn from(_: NonFinite) -> SolveFailure {
        SolveFailure::NonFinite
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_step_after_an_event_keeps_within_half_the_guard() {
        // Slow rates: the step the integrator had reached stands.
        assert_eq!(first_step(Feat::Edge(0), [0.1, -0.2], 1.0, 1e-6), 1.0);
        // Fast ones: the linear change over the step is half the guard's allowance.
        let h = first_step(Feat::Vertex(1), [0.3, -8.0], 1.0, 1e-6);
        assert!((h * 8.0 - FIRST_STEP_CHANGE).abs() < 1e-15, "{h}");
        let h = first_step(Feat::Edge(2), [-5.0, 1.0], 2.0, 1e-6);
        assert!((h * 5.0 - FIRST_STEP_CHANGE).abs() < 1e-15, "{h}");
        // Never below the floor, whatever the rates.
        assert_eq!(first_step(Feat::Edge(0), [1e12, 0.0], 1.0, 1e-6), 1e-6);
        // A flush fence edge's fence coordinate is not guarded, so it does not cap the step.
        assert_eq!(first_step(Feat::FenceEdge(0), [0.0, 50.0], 2.0, 1e-6), 2.0);
        // The capped step passes the guard if the rates hold over it.
        let (y0, f0) = ([0.2, 0.4], [0.5, 12.0]);
        let h = first_step(Feat::Vertex(0), f0, 1.0, 1e-6);
        let y1 = [y0[0] + h * f0[0], y0[1] + h * f0[1]];
        assert!(step_change_ok(Feat::Vertex(0), y0, y1));
    }
}
