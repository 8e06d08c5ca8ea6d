//! The summary of one contact case's outcome: the JSON of `pinfeed contact --json`, its text form
//! and the per-step trace as CSV.

use super::Case;
use crate::geometry::wrap_deg;
use crate::mechanics::{ContactOutcome, TraceSample};
use serde::Serialize;
use std::fmt::Write as _;

/// The JSON printed by `pinfeed contact --json`.
#[derive(Debug, Serialize)]
pub struct ContactReport {
    /// The part spec, as given.
    pub part: String,
    /// The contact model's name.
    pub model: String,
    /// Initial orientation θ0 (degrees).
    pub theta0_deg: f64,
    /// Lateral offset of the pin's start (units of a).
    pub d: f64,
    /// Pin–part friction coefficient μc.
    pub mu_c: f64,
    /// Part–belt friction coefficient μs.
    pub mu_s: f64,
    /// Pin radius (part units).
    pub pin_radius: f64,
    /// Lateral speed of the pin as a fraction of the belt speed.
    pub pin_speed: f64,
    /// Belt travel (units of a) from the pin's start to where it stops.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pin_stop: Option<f64>,
    /// `--pin-stop-after-touch`: belt travel (units of a) from the first touch to the stop.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pin_stop_after_touch: Option<f64>,
    /// A moving pin's lateral offset (units of a, the frame of `d`) at its first touch.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pin_touch_d: Option<f64>,
    /// A moving pin's lateral offset (units of a) where it stops.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pin_stop_d: Option<f64>,
    /// Did the pin push the part at all?
    pub contact: bool,
    /// Final orientation (degrees, in [0, 360)).
    pub theta_final_deg: f64,
    /// Signed total rotation (degrees, not wrapped).
    pub rotation_deg: f64,
    /// Final centroid position [x, y] (belt frame, part units).
    pub com_final: [f64; 2],
    /// Pin travel relative to the belt before the first touch (part units).
    pub travel_to_contact: f64,
    /// Pin travel while in contact (part units).
    pub contact_length: f64,
    /// Number of separate contacts during the pass.
    pub contacts: u32,
    /// The stretches of contact, each with one feature in one mode.
    pub segments: Vec<crate::mechanics::Segment>,
    /// Limit-surface evaluations (exact model: dissipation evaluations; closed forms: solves).
    pub evaluations: u64,
    /// Accepted integration steps.
    pub steps: u32,
    /// The status's name (`ok` when the pass completed).
    pub status: String,
    /// The status with its details.
    pub status_detail: crate::mechanics::ContactStatus,
}

/// The report of a case and its outcome (a moving pin's positions: [`ContactReport::with_pin_positions`]).
pub fn report(c: &Case, out: &ContactOutcome) -> ContactReport {
    ContactReport {
        part: c.part.clone(),
        model: c.model.name().into(),
        theta0_deg: c.theta0_deg,
        d: c.d,
        mu_c: c.mu_c,
        mu_s: c.mu_s,
        pin_radius: c.pin_radius,
        pin_speed: c.pin_speed,
        pin_stop: c.pin_stop,
        pin_stop_after_touch: c.pin_stop_after_touch,
        pin_touch_d: None,
        pin_stop_d: None,
        contact: out.contact,
        theta_final_deg: wrap_deg(out.pose_final.theta_rad.to_degrees()),
        rotation_deg: out.rotation_rad.to_degrees(),
        com_final: [out.pose_final.x, out.pose_final.y],
        travel_to_contact: out.travel_to_contact,
        contact_length: out.contact_length,
        contacts: out.contacts,
        segments: out.segments.clone(),
        evaluations: out.evaluations,
        steps: out.steps,
        status: out.status.name().into(),
        status_detail: out.status,
    }
}

impl ContactReport {
    /// A moving pin's travel to its stop and its lateral offsets at the first touch and at the
    /// stop (units of a; `a` is the part's size), from the case and its outcome.
    pub fn with_pin_positions(mut self, c: &Case, a: f64, out: &ContactOutcome) -> Self {
        if c.fence.is_some() || c.pin_speed == 0.0 {
            return self;
        }
        let touch = out.contact.then(|| out.travel_to_contact / a);
        let stop = match (c.pin_stop, c.pin_stop_after_touch) {
            (Some(s), _) => Some(s),
            (None, Some(t)) => touch.map(|s| s + t),
            (None, None) => None,
        };
        let at = |s: f64| c.d + c.pin_speed * stop.map_or(s, |e| s.min(e));
        self.pin_stop = stop;
        self.pin_touch_d = touch.map(at);
        self.pin_stop_d = stop.map(at);
        self
    }

    /// The final pose, rotation and contact length of a push that touched (lines of text).
    pub fn motion_text(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "final orientation   {:.4}°", self.theta_final_deg);
        let _ = writeln!(s, "rotation            {:+.4}°", self.rotation_deg);
        let _ = writeln!(
            s,
            "final centroid      ({:.5}, {:.5})",
            self.com_final[0], self.com_final[1]
        );
        let _ = writeln!(s, "contact length      {:.5}", self.contact_length);
        if let Some(y) = self.pin_touch_d {
            let _ = writeln!(s, "pin at first touch  d = {y:.5}");
        }
        if let Some(y) = self.pin_stop_d {
            let _ = writeln!(s, "pin stops at        d = {y:.5}");
        }
        s
    }

    /// The terminal summary of `pinfeed contact`: the case, the motion, the contact segments, the
    /// work done and the status.
    pub fn text(&self) -> String {
        let mut s = format!(
            "part {}  model {}  θ0 {}°  d {}  μc {}\n",
            self.part, self.model, self.theta0_deg, self.d, self.mu_c
        );
        if !self.contact {
            s += "no contact: the pin passes the part\n";
        } else {
            s += &self.motion_text();
            let segs: Vec<String> = self
                .segments
                .iter()
                .map(|g| {
                    format!(
                        "{} {} {}",
                        g.feature.kind(),
                        g.feature.index(),
                        g.mode.name()
                    )
                })
                .collect();
            let _ = writeln!(s, "segments            {}", segs.join(" → "));
            let _ = writeln!(
                s,
                "evaluations         {} ({} steps)",
                self.evaluations, self.steps
            );
        }
        let _ = writeln!(s, "status              {}", self.status);
        s
    }
}

/// The trajectory and contact force per step as CSV (`pinfeed contact --trace`).
pub fn trace_csv(trace: &[TraceSample]) -> String {
    let mut f = String::from(
        "s,x,y,theta_deg,pin_x,pin_y,contact_x,contact_y,force_x,force_y,mode,feature,index,normal_x,normal_y,rotation_rate\n",
    );
    for t in trace {
        let (kind, idx) = (t.feature.kind(), t.feature.index());
        let _ = writeln!(
            f,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            t.s,
            t.pose.x,
            t.pose.y,
            t.pose.theta_rad.to_degrees(),
            t.pin_centre.x,
            t.pin_centre.y,
            t.contact_point.x,
            t.contact_point.y,
            t.force.x,
            t.force.y,
            t.mode.name(),
            kind,
            idx,
            t.normal.x,
            t.normal.y,
            t.rotation_rate
        );
    }
    f
}
