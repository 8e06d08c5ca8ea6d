//! Answering a push from a map: the exact first-touch ray cast, then the certified cell's
//! interpolation, or the exact model where the map cannot vouch for the answer.

use super::build::interpolate;
use super::{Node, Sample, TierInputs, TierMap};
use crate::geometry::{wrap_2pi, Pose, Vec2};
use crate::mechanics::{
    pin_first_touch, push_path, untouched, ContactOutcome, ContactSettings, ContactStatus,
    PartModel, PinPath,
};
use serde::Serialize;

/// Why a push was computed by the exact model instead of the map.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Fallback {
    /// The query lies in a cell the map could not certify (near a jump of θf, a non-ok push, a
    /// second contact, a change of the final feature).
    Uncertified,
    /// The pin starts inside or against the part.
    PinInside,
    /// Something records the push's path (a sensor pin, a neighbouring obstacle, a drawn part).
    Trace,
    /// A moving pin (its path is not a straight line along −x).
    MovingPin,
    /// A fence.
    Fence,
    /// The part has its own support (a random tripod per part).
    PartSupport,
    /// The query lies in a base cell the map has not built (a map built for other queries).
    Unbuilt,
}

impl Fallback {
    /// The reason's name in the summary's counters (`uncertified`, `pin_inside`, `trace`, …).
    pub fn name(self) -> &'static str {
        match self {
            Fallback::Uncertified => "uncertified",
            Fallback::PinInside => "pin_inside",
            Fallback::Trace => "trace",
            Fallback::MovingPin => "moving_pin",
            Fallback::Fence => "fence",
            Fallback::PartSupport => "part_support",
            Fallback::Unbuilt => "unbuilt",
        }
    }
}

impl TierMap {
    /// The push of a part resting at `pose` by a still pin of radius `radius` starting at
    /// `pin_start` (belt frame, caller's units; the model and radius must be the map's), from the
    /// map: a miss is exact (the ray cast), a hit in a certified cell is interpolated. `Err` says
    /// why the exact model must answer instead.
    pub fn answer(
        &self,
        model: &PartModel,
        pose: Pose,
        pin_start: Vec2,
        radius: f64,
    ) -> Result<ContactOutcome, Fallback> {
        answer_from(model, pose, pin_start, radius, |theta, d| {
            let (node, u, v) = self.leaf(theta, d)?;
            Some((node, u, v, self.samples.as_slice()))
        })
    }
}

/// [`TierMap::answer`] with the leaf of (θ0 ∈ [0, 2π), d) looked up by `leaf`: the leaf, its
/// local coordinates and the samples its points index (None outside the map's d range).
pub(super) fn answer_from<'m>(
    model: &PartModel,
    pose: Pose,
    pin_start: Vec2,
    radius: f64,
    leaf: impl FnOnce(f64, f64) -> Option<(Node, f64, f64, &'m [Sample])>,
) -> Result<ContactOutcome, Fallback> {
    let k = model.scale();
    let local = pose.apply_inverse(pin_start) / k;
    let poly = model.polygon();
    if poly.contains(local) || poly.distance_to_boundary(local).0 < radius / k {
        return Err(Fallback::PinInside);
    }
    let path = PinPath::constant(0.0);
    let Some(touch) = pin_first_touch(model, pose, pin_start, radius, &path) else {
        return Ok(untouched(pose, ContactStatus::Ok));
    };
    let d = (pin_start.y - pose.y) / k;
    let Some((node, u, v, samples)) = leaf(wrap_2pi(pose.theta_rad), d) else {
        return Err(Fallback::Uncertified);
    };
    let points = match node {
        Node::Certified { points } => points,
        Node::Unbuilt => return Err(Fallback::Unbuilt),
        Node::Split { .. } | Node::Fallback => return Err(Fallback::Uncertified),
    };
    let c = points.map(|i| &samples[i as usize]);
    let [rotation, dx, dy, span] = interpolate(c, u, v);
    Ok(ContactOutcome {
        contact: true,
        pose_initial: pose,
        pose_final: Pose::new(pose.x + dx * k, pose.y + dy * k, pose.theta_rad + rotation),
        rotation_rad: rotation,
        travel_to_contact: touch,
        contact_length: span * k,
        contacts: 1,
        segments: Vec::new(),
        evaluations: 0,
        steps: 0,
        status: ContactStatus::Ok,
    })
}

/// The base cell a query of [`TierMap::answer`] falls in (None: outside the map's d range), for
/// building only the cells a batch of queries needs ([`super::load_or_build_cells`]).
pub fn cell_of_query(inputs: &TierInputs, pose: Pose, pin_start: Vec2) -> Option<usize> {
    let k = inputs.model.scale();
    let d = (pin_start.y - pose.y) / k;
    super::base_cell(
        &inputs.spec,
        super::build::reach(inputs),
        wrap_2pi(pose.theta_rad),
        d,
    )
    .map(|(root, _, _)| root)
}

/// The push from the map where it can answer, else from the exact model (with the reason).
pub fn push_with_map(
    map: &TierMap,
    model: &PartModel,
    pose: Pose,
    pin_start: Vec2,
    radius: f64,
    settings: &ContactSettings,
) -> (ContactOutcome, Option<Fallback>) {
    match map.answer(model, pose, pin_start, radius) {
        Ok(out) => (out, None),
        Err(why) => {
            let path = PinPath::constant(0.0);
            let out = push_path(model, pose, pin_start, radius, &path, settings, None);
            (out, Some(why))
        }
    }
}
