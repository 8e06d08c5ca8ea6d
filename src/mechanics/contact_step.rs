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
            last = Some((inst, g));
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
