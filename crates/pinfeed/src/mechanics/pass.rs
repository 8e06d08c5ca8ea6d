//! The pass loop: an obstacle (a pin along its path, or a fence) passes the part; each time it
//! touches, the contact is integrated ([`super::integrate`]) until it separates, and the obstacle's
//! path is cast again from there, so that a concave part can be struck more than once.
//!
//! The public entry points live here: [`push`] and [`push_path`] (a pin), [`push_fence`] (a fence),
//! and the queries the line schedules with ([`pin_first_touch`], [`fence_first_touch`],
//! [`first_instant`]). All take and return the caller's units and are pure functions of their
//! inputs.

use super::contact_state::{initial_state, Ctx, Feat};
use super::fence::{first_touch, next_fence_touch, FenceGeom, FenceSpec};
use super::instant::{classify, ContactGeom, Instant};
use super::integrate::{integrate_contact, End, Tally};
use super::outcome::{ContactOutcome, ContactStatus, Recorder, SelfCheck};
use super::part_model::PartModel;
use super::pin_path::{PinPath, PinPathError};
use super::settings::{ContactSettings, Pin};
use crate::geometry::{first_contact, Feature, Pose, Vec2};

/// How the next contact of a pass begins.
enum Touch {
    None,
    At(f64, Feat, [f64; 2]),
    Stop(ContactStatus),
}

/// The next touch between the obstacle and the part resting at `cur`, after travel `s`.
fn next_touch(ctx: &mut Ctx, cur: &Pose, s: f64, after_separation: bool) -> Touch {
    let k = ctx.scale;
    if ctx.fence.is_some() {
        let s_from = if after_separation { s + 1e-9 } else { s };
        return match next_fence_touch(ctx, cur, s_from) {
            None => Touch::None,
            Some((t, feat, y)) => Touch::At(t, feat, y),
        };
    }
    let mut s = s;
    let mut min_travel = if after_separation { 1e-9 } else { 0.0 };
    // Piece by piece along the pin's path: a touch beyond the next turn is not on this piece.
    loop {
        let touch = cast_piece(ctx, cur, s, min_travel);
        let s_turn = ctx.turn_at();
        let beyond_turn = match &touch {
            Touch::At(t, ..) => *t > s_turn,
            Touch::Stop(ContactStatus::MultiContact { s: t }) => *t / k > s_turn,
            Touch::Stop(_) => false,
            Touch::None => s_turn.is_finite(),
        };
        if !beyond_turn {
            return touch;
        }
        s = s_turn;
        ctx.take_turn();
        // At a turn the pin may already overlap the part by the rounding of the integration (it
        // can run along an edge it has just left, then turn into it): a touch up to the
        // self-check's limit behind the turn is a touch at the turn, not a pin passing through.
        min_travel = -ctx.check_limit();
    }
}

/// The first touch of the pin on the current piece of its path (extended as a ray), after travel
/// `s` plus `min_travel` along the path.
fn cast_piece(ctx: &mut Ctx, cur: &Pose, s: f64, mut min_travel: f64) -> Touch {
    let k = ctx.scale;
    let dir_len = ctx.vdir.norm();
    let dir = ctx.vdir / dir_len;
    for _ in 0..8 {
        let Some(hit) = first_contact(ctx.poly, cur, ctx.pin_at(s), dir, ctx.rho, min_travel)
        else {
            return Touch::None;
        };
        if hit.grazing {
            // A touch that pushes nothing: continue along the path past it (a relative step:
            // the travel can be 1e8 a).
            min_travel = hit.travel + 1e-9 * (1.0 + hit.travel.abs());
            continue;
        }
        let s_touch = s + hit.travel / dir_len;
        if let Feature::Vertex { index } = hit.feature {
            if !ctx.poly.vertex_is_convex(index) {
                // The pin strikes a reflex corner: it touches both edges of the notch at once.
                return Touch::Stop(ContactStatus::MultiContact { s: s_touch * k });
            }
        }
        let (feat, y) = initial_state(ctx, cur, hit.feature, hit.normal);
        // The contact state must put the part where it is: a ray that runs along an edge it has
        // just left (the pin separated moving tangentially) can report a touch elsewhere on that
        // edge, which would teleport the part. Such a touch pushes nothing: look past it.
        let at = ctx.pose(s_touch, feat, y);
        if (at.x - cur.x).abs() > 1e-9 || (at.y - cur.y).abs() > 1e-9 {
            min_travel = hit.travel + 1e-9 * (1.0 + hit.travel.abs());
            continue;
        }
        return Touch::At(s_touch, feat, y);
    }
    Touch::None
}

/// The status of a pass stopped by a non-finite travel or pose after travel `s` (normalised).
fn non_finite(s: f64, k: f64) -> ContactStatus {
    ContactStatus::SelfCheck {
        check: SelfCheck::NonFinite,
        s: s * k,
    }
}

/// The outcome of a pass that never touched the part.
pub(crate) fn untouched(pose: Pose, status: ContactStatus) -> ContactOutcome {
    ContactOutcome {
        contact: false,
        pose_initial: pose,
        pose_final: pose,
        rotation_rad: 0.0,
        travel_to_contact: 0.0,
        contact_length: 0.0,
        contacts: 0,
        segments: Vec::new(),
        evaluations: 0,
        steps: 0,
        status,
    }
}

/// Run the passes of one obstacle over the part until it no longer touches it.
fn run_passes(ctx: &mut Ctx, settings: &ContactSettings, pose: Pose) -> ContactOutcome {
    let k = ctx.scale;
    let pose_n = Pose::new(pose.x / k, pose.y / k, pose.theta_rad);
    let mut out = untouched(pose, ContactStatus::Ok);
    let mut s = 0.0;
    let mut cur = pose_n;
    let mut segs = Tally::default();
    let mut after_separation = false;
    for _pass in 0..16 {
        let (s_touch, feat, y) = match next_touch(ctx, &cur, s, after_separation) {
            Touch::None => break,
            Touch::Stop(st) => {
                out.status = st;
                break;
            }
            Touch::At(t, ..) if !t.is_finite() => {
                out.status = non_finite(s, k);
                break;
            }
            Touch::At(t, f, y) => (t, f, y),
        };
        if out.contacts == 0 {
            out.travel_to_contact = s_touch * k;
        }
        out.contacts += 1;
        let (end, s_end, pose_end) = integrate_contact(ctx, settings, s_touch, feat, y, &mut segs);
        if ![s_end, pose_end.x, pose_end.y, pose_end.theta_rad]
            .iter()
            .all(|v| v.is_finite())
        {
            // Keep the last finite state as the result and say why it stopped.
            out.status = non_finite(s_touch, k);
            break;
        }
        segs.close(s_end, pose_end.theta_rad, k);
        out.contact_length += (s_end - s_touch) * k;
        s = s_end;
        cur = pose_end;
        match end {
            End::Separated => after_separation = true,
            End::Stop(st) => {
                out.status = st;
                break;
            }
        }
    }
    out.contact = out.contacts > 0;
    out.segments = segs.list;
    out.pose_final = Pose::new(cur.x * k, cur.y * k, cur.theta_rad);
    out.rotation_rad = cur.theta_rad - pose.theta_rad;
    out.evaluations = ctx.evals;
    out.steps = segs.steps;
    out
}

/// Push a part with one pin: the pin starts at `pin_start` (world, caller's units) and travels along
/// (−1, w) relative to the belt past the part resting at `pose`. Pure function of its inputs.
///
/// ```
/// use pinfeed::geometry::part_from_spec;
/// use pinfeed::maps::pass_start;
/// use pinfeed::mechanics::{push, ContactSettings, ContactStatus, PartModel, Pin, Support};
///
/// // tripoly2 in metres at θ0 = 30°, a point pin at d = −0.2 (units of the part's radius a).
/// let part = part_from_spec("tripoly2").unwrap().scaled(0.02);
/// let model = PartModel::new(&part, &Support::Uniform).unwrap();
/// let (pose, pin_start) = pass_start(&part, 30.0, -0.2, 0.0);
/// let out = push(&model, pose, pin_start, &Pin::point(), &ContactSettings::default(), None);
/// assert_eq!(out.status, ContactStatus::Ok);
/// assert!(out.contact);
/// assert!((out.rotation_rad.to_degrees() - -19.05).abs() < 0.01);
/// ```
pub fn push(
    model: &PartModel,
    pose: Pose,
    pin_start: Vec2,
    pin: &Pin,
    settings: &ContactSettings,
    recorder: Option<&mut dyn Recorder>,
) -> ContactOutcome {
    let path = PinPath::constant(pin.lateral_speed);
    push_path(
        model, pose, pin_start, pin.radius, &path, settings, recorder,
    )
}

/// Push a part with a pin of radius `radius` whose lateral speed follows `path` (docs/physics.md#moving-and-retractable-pins: one push
/// with the pin's true relative velocity (−V, w(s)), each change of w a step boundary). Pure.
pub fn push_path(
    model: &PartModel,
    pose: Pose,
    pin_start: Vec2,
    radius: f64,
    path: &PinPath,
    settings: &ContactSettings,
    recorder: Option<&mut dyn Recorder>,
) -> ContactOutcome {
    let k = model.scale();
    let mut ctx = pin_ctx(model, pin_start, radius, path, settings, recorder);
    // The pin must start clear of the part.
    let pose_n = Pose::new(pose.x / k, pose.y / k, pose.theta_rad);
    let local = pose_n.apply_inverse(ctx.start);
    if ctx.poly.contains(local) || ctx.poly.distance_to_boundary(local).0 < ctx.rho * (1.0 - 1e-12)
    {
        return untouched(pose, ContactStatus::PinInsidePart);
    }
    run_passes(&mut ctx, settings, pose)
}

fn pin_ctx<'a, 'r>(
    model: &'a PartModel,
    pin_start: Vec2,
    radius: f64,
    path: &PinPath,
    settings: &ContactSettings,
    recorder: Option<&'r mut dyn Recorder>,
) -> Ctx<'a, 'r> {
    let k = model.scale();
    Ctx::new(
        model,
        model.polygon(),
        settings,
        settings.mu_c,
        radius / k,
        Vec2::new(-1.0, 0.0),
        pin_start / k,
        None,
        recorder,
    )
    .with_path(path)
}

/// Belt travel (caller's units) until a pin of radius `radius` starting at `pin_start` and
/// following `path` first touches the part resting at `pose` so as to push it (grazes skipped; a
/// strike into a reflex corner counts), or `None`: the same query the contact model starts with,
/// for scheduling pin contacts in the line.
pub fn pin_first_touch(
    model: &PartModel,
    pose: Pose,
    pin_start: Vec2,
    radius: f64,
    path: &PinPath,
) -> Option<f64> {
    let k = model.scale();
    let settings = ContactSettings::default();
    let mut ctx = pin_ctx(model, pin_start, radius, path, &settings, None);
    let pose_n = Pose::new(pose.x / k, pose.y / k, pose.theta_rad);
    match next_touch(&mut ctx, &pose_n, 0.0, false) {
        Touch::At(s, ..) => Some(s * k),
        Touch::Stop(ContactStatus::MultiContact { s }) => Some(s),
        _ => None,
    }
}

/// Why a stopping pin path could not be built ([`stop_after_touch`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StopAfterTouchError {
    /// The travel after the first touch is negative or not finite.
    #[error("the travel after first touch must be a finite number >= 0, got {after}")]
    After {
        /// The travel given.
        after: f64,
    },
    /// The pin path itself is invalid (e.g. the speed); its message is printed as it is.
    #[error("{0}")]
    Path(PinPathError),
}

/// The path of a pin moving at lateral speed `w` from `pin_start` that stops `after` (belt travel,
/// caller's units) after it first touches the part resting at `pose` ([`pin_first_touch`] on the
/// constant path, which the stopping path follows up to the stop), then stands still. A pin that
/// never touches the part keeps moving (the stop never comes). `after` must be finite and ≥ 0.
pub fn stop_after_touch(
    model: &PartModel,
    pose: Pose,
    pin_start: Vec2,
    radius: f64,
    w: f64,
    after: f64,
) -> Result<PinPath, StopAfterTouchError> {
    if !(after.is_finite() && after >= 0.0) {
        return Err(StopAfterTouchError::After { after });
    }
    let moving = PinPath::new(w, Vec::new()).map_err(StopAfterTouchError::Path)?;
    match pin_first_touch(model, pose, pin_start, radius, &moving) {
        Some(s) if s.is_finite() => PinPath::new(
            w,
            vec![super::pin_path::Turn {
                s: s.max(0.0) + after.max(f64::MIN_POSITIVE),
                w: 0.0,
            }],
        )
        .map_err(StopAfterTouchError::Path),
        _ => Ok(moving),
    }
}

/// Push a part resting at `pose` with a fence (docs/physics.md#fences; see [`super::fence`]): the fence travels at
/// (−V, 0) relative to the belt past the part; its friction μf replaces μc in `settings`.
/// Fence-contact features index the part's convex hull.
pub fn push_fence(
    model: &PartModel,
    pose: Pose,
    fence: &FenceSpec,
    settings: &ContactSettings,
    recorder: Option<&mut dyn Recorder>,
) -> ContactOutcome {
    let geom = FenceGeom::new(fence, model.scale());
    push_fence_chain(model, pose, vec![geom], fence.mu_f, settings, recorder)
}

/// [`push_fence`] against a chain of fence pieces (normalised units; see
/// [`super::fence::tangent_chain`]) with friction `mu_f`.
pub(crate) fn push_fence_chain(
    model: &PartModel,
    pose: Pose,
    chain: Vec<FenceGeom>,
    mu_f: f64,
    settings: &ContactSettings,
    recorder: Option<&mut dyn Recorder>,
) -> ContactOutcome {
    let geom = chain[0];
    let mut ctx = Ctx::new(
        model,
        model.hull(),
        settings,
        mu_f,
        0.0,
        Vec2::new(-1.0, 0.0),
        geom.p1(),
        Some(geom),
        recorder,
    );
    // Sliding along a steep fence is slow (it stops altogether at the jam angle): allow the belt
    // travel a fence of this length (and its tail) can take before calling the part held.
    let length: f64 = chain
        .iter()
        .map(|f| f.len + f.tail.map_or(0.0, |t| t.radius * t.sweep.abs()))
        .sum();
    ctx.chain = chain;
    let settings = ContactSettings {
        max_travel: settings.max_travel + 50.0 * length,
        ..*settings
    };
    run_passes(&mut ctx, &settings, pose)
}

/// The mode and twist at the first instant of contact (for Mason's-vote checks and sensors).
/// Returns (contact geometry in the part frame, the instant) or `None` without a pushing contact.
pub fn first_instant(
    model: &PartModel,
    pose: Pose,
    pin_start: Vec2,
    pin: &Pin,
    settings: &ContactSettings,
) -> Option<(ContactGeom, Instant)> {
    let k = model.scale();
    let pose_n = Pose::new(pose.x / k, pose.y / k, pose.theta_rad);
    let path = PinPath::constant(pin.lateral_speed);
    let mut ctx = pin_ctx(model, pin_start, pin.radius, &path, settings, None);
    let dir = ctx.vdir.normalized();
    let hit = first_contact(ctx.poly, &pose_n, ctx.start, dir, ctx.rho, 0.0)?;
    if hit.grazing {
        return None;
    }
    let (feat, y) = initial_state(&ctx, &pose_n, hit.feature, hit.normal);
    let g = ctx.geom(feat, y);
    let inst = classify(model, ctx.fid, &g, ctx.fr, &mut ctx.warm, &mut ctx.evals).ok()??;
    Some((g, inst))
}

/// Belt travel (caller's units) until a fence first touches the part resting at `pose`, or `None`
/// if it never does (for scheduling fence contacts in the line).
pub fn fence_first_touch(model: &PartModel, pose: Pose, fence: &FenceSpec) -> Option<f64> {
    let k = model.scale();
    let geom = FenceGeom::new(fence, k);
    let pose_n = Pose::new(pose.x / k, pose.y / k, pose.theta_rad);
    first_touch(model.hull(), &pose_n, &geom, Vec2::new(-1.0, 0.0), 0.0).map(|(s, _)| s * k)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;
    use crate::mechanics::part_model::Support;

    /// A disc pin (ρ = 0.1 a, as on the quickstart line) rolling round a vertex turns its normal at
    /// about 1/ρ per unit of travel. The first step after each event is sized from the new
    /// segment's rates (`contact_step::first_step`), so the acceptance guard seldom has to refuse
    /// a step: without that, it refused one attempt in nine on the quickstart line (mostly first
    /// steps after events, each refusal 4× smaller and six right-hand sides lost), and here 20
    /// refusals per 100 accepted steps against 4.6 with it (the rest follow a step's growth).
    #[test]
    fn the_guard_seldom_refuses_a_disc_pins_steps() {
        let poly = part_from_spec("tripoly2").unwrap();
        let model = PartModel::new(&poly, &Support::Uniform)
            .unwrap()
            .with_slide_tables(&[0.5]);
        let a = poly.radius();
        let rho = 0.1 * a;
        let settings = ContactSettings::default();
        let (mut refusals, mut steps, mut touched) = (0u64, 0u64, 0u32);
        for k in 0..240 {
            let pose = Pose::new(0.0, 0.0, (k as f64 * 1.5).to_radians());
            let d = -0.8 + 1.6 * ((k * 37 % 240) as f64) / 239.0;
            let start = Vec2::new(1.01 * a + rho, d * a);
            let path = PinPath::constant(0.0);
            let mut ctx = pin_ctx(&model, start, rho, &path, &settings, None);
            let out = run_passes(&mut ctx, &settings, pose);
            assert_eq!(out.status, ContactStatus::Ok, "contact {k}");
            touched += u32::from(out.contact);
            refusals += ctx.guard_refusals;
            steps += u64::from(out.steps);
        }
        assert!(touched > 150, "{touched} contacts touched");
        assert!(
            refusals * 100 <= 8 * steps,
            "{refusals} guard refusals in {steps} accepted steps"
        );
    }
}
