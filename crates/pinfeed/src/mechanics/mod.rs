//! The contact model: what happens to a part carried by the belt into one pin (docs/physics.md#one-instant).
//!
//! * [`limit_surface`]: dissipation D(ξ), its gradient (the support load) and Hessian for uniform
//!   pressure (closed form per edge, with a far-field quadrature) and for weighted support points.
//! * [`limits`]: the ranges in which a contact's numeric settings are accepted.
//! * [`part_model`]: the compiled part (normalised geometry + support) and the two convex
//!   sub-problems, at three fidelity levels (`tip`, `ellipsoid`, `exact`).
//! * [`instant`]: one instant — separation, stick, slide-left/right — in twist form.
//! * [`integrate`]: one contact, integrated in pin travel with error control and event location:
//!   `contact_step` (one step of a contact), `event_locate` (finding and landing on the earliest
//!   event in a step) and `event_apply` (what each event does).
//! * `contact_state`: the state of one contact (feature, reduced coordinates, pose, rates, events).
//! * `ode`: the Dormand–Prince 5(4) step, its dense output and the Illinois root finder.
//! * `settings`: the pin and the [`ContactSettings`].
//! * `pass`: the pass loop — cast the obstacle's path, integrate each contact, cast again — and
//!   the entry points [`push`], [`push_path`], [`push_fence`].
//! * [`outcome`]: [`ContactOutcome`], segments, statuses and the optional trajectory recorder.
//! * [`pin_path`]: a moving pin's lateral speed profile over a pass (docs/physics.md#moving-and-retractable-pins).
//! * [`fence`]: fences (docs/physics.md#fences): vertex on the fence line, flush edge translation or jam, ends.
//! * [`slide_table`]: the exact model's sliding twists on each edge and vertex, tabulated per (μc, place,
//!   side) for models many contacts share.
//! * [`stick_table`]: the exact model's sticking twists on each edge, tabulated per edge over (ℓ,
//!   direction of the pin's velocity), for a map tier's build.
//! * [`support`]: random support models — a tripod or a smooth density per sample — and their draw.
//! * [`vote`]: Mason's voting theorem, the geometric check on the sense of rotation.
//!
//! The entry point is [`push`], a pure function: (part model, pose, pin, settings, optional recorder)
//! → [`ContactOutcome`].

mod contact_state;
mod contact_step;
mod event_apply;
mod event_locate;
pub mod fence;
pub mod instant;
pub mod integrate;
pub mod limit_surface;
pub mod limits;
mod ode;
pub mod outcome;
pub mod part_model;
mod pass;
pub mod pin_path;
mod settings;
pub mod slide_table;
pub mod stick_table;
pub mod support;
pub mod vote;

pub use fence::FenceSpec;
pub use instant::Mode;
pub use outcome::{
    ContactFeature, ContactOutcome, ContactStatus, Recorder, Segment, SelfCheck, TraceSample,
};
pub use part_model::{Fidelity, PartModel, PartModelError, SolveFailure, Support, TripodError};
pub(crate) use pass::untouched;
pub use pass::{
    fence_first_touch, first_instant, pin_first_touch, push, push_fence, push_path,
    stop_after_touch, StopAfterTouchError,
};
pub use pin_path::{PinPath, Turn, MAX_LATERAL_SPEED};
pub use settings::{ContactSettings, Pin};
pub use vote::mason_vote;

/// The version of the contact model's answers: bumped whenever a change moves them beyond
/// rounding of the previous ones (a new table, a changed integrator rule). Whatever is cached from
/// the model's answers keys on it (the map tier, `maps::tier::key`), so that a cache written by an
/// older model is rebuilt, not reused.
///
/// * 1: the exact model with slide tables on edges and vertices (up to `4db9b7c`).
/// * 2: stick tables on edges in a map tier's build.
pub const MODEL_VERSION: u32 = 2;
