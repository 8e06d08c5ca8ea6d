//! What one pass of a pin past a part produces: [`ContactOutcome`], its segments and status, and the
//! optional [`Recorder`] that receives the trajectory and contact force per step.

use super::instant::Mode;
use super::part_model::SolveFailure;
use crate::geometry::{Pose, Vec2};
use serde::Serialize;

/// The feature of the part in contact during a segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", content = "index", rename_all = "snake_case")]
pub enum ContactFeature {
    /// Edge `k` of the polygon (from vertex k to k + 1).
    Edge(usize),
    /// Vertex `k` of the polygon.
    Vertex(usize),
    /// A vertex of the part's convex hull sliding or sticking on a fence line (hull index).
    FenceVertex(usize),
    /// An edge of the part's convex hull flush against a fence line (hull index).
    FenceEdge(usize),
}

impl ContactFeature {
    /// Machine-readable kind: `edge`, `vertex`, `fence_vertex` or `fence_edge`.
    pub fn kind(&self) -> &'static str {
        match self {
            ContactFeature::Edge(_) => "edge",
            ContactFeature::Vertex(_) => "vertex",
            ContactFeature::FenceVertex(_) => "fence_vertex",
            ContactFeature::FenceEdge(_) => "fence_edge",
        }
    }
    /// Index of the vertex or edge (of the polygon, or of its hull for fence features).
    pub fn index(&self) -> usize {
        match *self {
            ContactFeature::Edge(k)
            | ContactFeature::Vertex(k)
            | ContactFeature::FenceVertex(k)
            | ContactFeature::FenceEdge(k) => k,
        }
    }
}

/// A stretch of contact with one feature in one mode.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Segment {
    /// The feature in contact.
    pub feature: ContactFeature,
    /// Sticking or sliding (and to which side).
    pub mode: Mode,
    /// Pin travel (belt frame, caller's units) at the start of the segment.
    pub s_begin: f64,
    /// Pin travel at the end of the segment (belt frame, caller's units).
    pub s_end: f64,
    /// Part orientation (radians, unwrapped) at the start.
    #[serde(rename = "theta_begin")]
    pub theta_begin_rad: f64,
    /// Part orientation at the end (radians, unwrapped).
    #[serde(rename = "theta_end")]
    pub theta_end_rad: f64,
}

/// How a contact computation ended.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ContactStatus {
    /// The pin passed the part; the result is trustworthy to the requested tolerance.
    Ok,
    /// The pin touches the part at two places at once (a concave notch): the single-contact model
    /// stops here rather than mis-simulate; `pose_final` is the pose at that moment.
    MultiContact {
        /// Pin travel where it stopped (caller's units).
        s: f64,
    },
    /// The pin started inside the part.
    PinInsidePart,
    /// The part was still being pushed after the travel limit (e.g. a metastable push through the
    /// centroid that never turns): the part rides on the pin.
    TravelLimit {
        /// The travel limit reached (caller's units).
        travel: f64,
    },
    /// Too much work in one pass: limit-surface evaluations plus right-hand sides (the budget is
    /// a setting; a right-hand side served by a slide table costs no evaluation but counts here).
    EvaluationLimit {
        /// Work done when the budget ran out.
        evaluations: u64,
    },
    /// Too many contact events (mode chattering).
    EventLimit {
        /// Events handled when the limit was hit.
        events: u32,
    },
    /// The integrator's step fell below its floor (a non-smooth spot it cannot resolve).
    StepTooSmall {
        /// Pin travel where it stopped (caller's units).
        s: f64,
    },
    /// A limit-surface sub-problem failed.
    Solver {
        /// What failed.
        failure: SolveFailure,
        /// Pin travel where it failed (caller's units).
        s: f64,
    },
    /// The part jammed against a fence (α + atan μf ≥ 90°): it stops in the world while the belt
    /// slips under it, and would stay there for ever. `pose_final` is where it stopped.
    Jam {
        /// Pin travel where the part stopped (caller's units).
        s: f64,
    },
    /// The contact model's own consistency check failed: the computed state contradicts the
    /// contact it was computed for (see [`SelfCheck`]). The result is not trustworthy; `pose_final`
    /// is the last state that passed the check.
    SelfCheck {
        /// Which check failed.
        check: SelfCheck,
        /// Pin travel where it failed (caller's units).
        s: f64,
    },
    /// The push rode an unstable equilibrium (its force line through the centroid: a tie in
    /// Mason's vote) for `travel` of pin travel, turning slower than the tolerance resolves, and
    /// then the part fell off to one side. Which side is decided by rounding and the tolerance, not
    /// by the inputs, so `pose_final` is one of two possible outcomes. (Still riding at the travel
    /// limit is [`ContactStatus::TravelLimit`].)
    Metastable {
        /// Pin travel spent on the equilibrium (caller's units).
        travel: f64,
    },
}

/// Which consistency check a contact failed (each is cheap and runs on every contact).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SelfCheck {
    /// At the end of a contact the tracked contact point lies off its feature (beyond an edge's
    /// end, outside a vertex's normal cone, off a fence), by more than the event-landing tolerance.
    OffFeature,
    /// At the end of a contact the pin overlaps the part.
    Penetration,
    /// A computed travel or pose is not a finite number (a degenerate geometric query).
    NonFinite,
}

impl SelfCheck {
    /// Short machine-readable name: `off_feature`, `penetration` or `non_finite`.
    pub fn name(self) -> &'static str {
        match self {
            SelfCheck::OffFeature => "off_feature",
            SelfCheck::Penetration => "penetration",
            SelfCheck::NonFinite => "non_finite",
        }
    }
}

impl ContactStatus {
    /// Did the pass end as it should (`ContactStatus::Ok`)?
    pub fn is_ok(&self) -> bool {
        matches!(self, ContactStatus::Ok)
    }
    /// Short machine-readable name.
    pub fn name(&self) -> &'static str {
        match self {
            ContactStatus::Ok => "ok",
            ContactStatus::MultiContact { .. } => "multi_contact",
            ContactStatus::PinInsidePart => "pin_inside_part",
            ContactStatus::TravelLimit { .. } => "travel_limit",
            ContactStatus::EvaluationLimit { .. } => "evaluation_limit",
            ContactStatus::EventLimit { .. } => "event_limit",
            ContactStatus::StepTooSmall { .. } => "step_too_small",
            ContactStatus::Solver { .. } => "solver",
            ContactStatus::Jam { .. } => "jam",
            ContactStatus::SelfCheck { .. } => "self_check",
            ContactStatus::Metastable { .. } => "metastable",
        }
    }
}

/// The result of pushing one part with one pin (docs/physics.md#one-instant): a pure function of its inputs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ContactOutcome {
    /// Did the pin push the part at all?
    pub contact: bool,
    /// Pose before (belt frame, caller's units, radians).
    pub pose_initial: Pose,
    /// Pose after the pin has passed (or at the moment a non-ok status stopped the computation).
    pub pose_final: Pose,
    /// Signed total rotation θ_final − θ_initial (radians, not wrapped).
    #[serde(rename = "rotation")]
    pub rotation_rad: f64,
    /// Pin travel relative to the belt before the first touch (caller's units).
    pub travel_to_contact: f64,
    /// Pin travel while in contact (caller's units); time in contact = contact_length / V.
    pub contact_length: f64,
    /// Number of separate contacts during the pass (a concave part may be struck twice).
    pub contacts: u32,
    /// The contact's segments, in order of travel.
    pub segments: Vec<Segment>,
    /// Limit-surface evaluations (exact model: dissipation evaluations; closed forms: solves).
    pub evaluations: u64,
    /// Accepted integration steps.
    pub steps: u32,
    /// How the computation ended.
    pub status: ContactStatus,
}

/// One recorded instant of a contact (belt frame, caller's units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TraceSample {
    /// Pin travel relative to the belt.
    pub s: f64,
    /// The part's pose (belt frame).
    pub pose: Pose,
    /// The pin's centre (belt frame).
    pub pin_centre: Vec2,
    /// The contact point (belt frame).
    pub contact_point: Vec2,
    /// Force the pin applies to the part (world axes), in units of the part's weight m g: the
    /// contact model's force (units of μs m g) times μs, so it scales with μs while the motion
    /// does not (multiply by m g for newtons).
    pub force: Vec2,
    /// Unit contact normal into the part (world axes): the force's normal direction.
    pub normal: Vec2,
    /// Rotation rate dθ/ds (radians per unit of pin travel, caller's units).
    pub rotation_rate: f64,
    /// Sticking or sliding (and to which side).
    pub mode: Mode,
    /// The feature in contact.
    pub feature: ContactFeature,
}

/// Receives the trajectory of a contact. With no recorder attached nothing is collected.
pub trait Recorder {
    /// Receive one sample (called at every accepted step and at both sides of every event).
    fn record(&mut self, sample: &TraceSample);
}

impl Recorder for Vec<TraceSample> {
    fn record(&mut self, sample: &TraceSample) {
        self.push(*sample);
    }
}
