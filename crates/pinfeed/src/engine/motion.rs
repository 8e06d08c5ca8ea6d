//! How a part moves on the line between events (docs/physics.md#the-line).
//!
//! * Free: the part rides the belt: its world pose at time t is its pose at the anchor time t₀
//!   translated by V·(t − t₀) along x.
//! * Held: a pin or a fence is pushing it. The contact model works in the belt frame that coincides
//!   with the world at the anchor time t_ref (docs/physics.md#frames, #fences): the obstacle, fixed in the world, starts
//!   where it stands and travels along −x relative to the belt, its travel s = V·(t − t_ref). The
//!   push outcome gives the belt-frame pose after the obstacle has passed; the world pose at time t
//!   is the belt-frame pose translated by s along x. The part therefore lags the belt while it is
//!   held (a part sliding along a fence also moves across the belt).
//!
//! Intermediate poses of a push are only needed when something may touch the part during it (a
//! neighbouring obstacle or another part) or when it is drawn. Then the push is run again with a
//! recorder (it is a pure function, so the outcome is the same) and the trace is kept; between
//! recorded steps the pose is interpolated linearly in (centroid, θ).

use super::outcome::Cause;
use crate::geometry::{Pose, Vec2};
use crate::mechanics::{
    push_fence, push_path, ContactOutcome, ContactSettings, FenceSpec, PartModel, PinPath,
    Recorder, TraceSample,
};
use std::cell::Cell;

/// The obstacle pushing a held part, as the contact model takes it (world frame at t_ref, m).
#[derive(Debug, Clone, PartialEq)]
pub enum Pusher {
    /// A pin of radius `radius` whose centre stands at `centre` at the anchor time and then
    /// follows `path` (a still pin: `PinPath::constant(0.0)`).
    Pin {
        /// Pin centre at the anchor time (world, m).
        centre: Vec2,
        /// Pin radius (m, ≥ 0).
        radius: f64,
        /// The pin's lateral motion during the push, as a function of its travel.
        path: PinPath,
    },
    /// A fence.
    Fence(FenceSpec),
}

impl Pusher {
    /// The push of a part resting at `pose` (belt frame = world at the anchor time): a pure
    /// function, so calling it again with a recorder gives the same outcome.
    pub fn push(
        &self,
        model: &PartModel,
        pose: Pose,
        settings: &ContactSettings,
        recorder: Option<&mut dyn Recorder>,
    ) -> ContactOutcome {
        match self {
            Pusher::Pin {
                centre,
                radius,
                path,
            } => push_path(model, pose, *centre, *radius, path, settings, recorder),
            Pusher::Fence(fence) => push_fence(model, pose, fence, settings, recorder),
        }
    }
}

/// Why a part leaves the line at the end of a push instead of riding on.
#[derive(Debug, Clone, PartialEq)]
pub enum Stop {
    /// Two obstacles at once; `cause` names how ([`Cause::Notch`], [`Cause::SecondObstacle`]).
    MultiContact {
        /// How.
        cause: Cause,
    },
    /// The obstacle holds the part for good; `cause` is [`Cause::TravelLimit`] (still pushed
    /// after `model.max_travel`) or [`Cause::FenceAngle`] (stopped against a fence at
    /// α + atan μf ≥ 90°).
    Jam {
        /// Why.
        cause: Cause,
    },
    /// The part's centroid crossed the belt's edge while it was pushed along a fence.
    OffBelt,
    /// The contact model failed; `cause` is the contact status ([`Cause::EvaluationLimit`],
    /// [`Cause::EventLimit`], [`Cause::StepTooSmall`], …), or for a failed sub-problem
    /// [`Cause::NoConvergence`] / [`Cause::NonFinite`].
    Solver {
        /// The contact status or sub-problem failure.
        cause: Cause,
    },
}

/// A push in progress: its inputs (to re-run it with a recorder) and its outcome.
#[derive(Debug, Clone)]
pub struct ContactPlan {
    /// Index of the pushing obstacle in `Scene::obstacles`.
    pub obstacle: usize,
    /// Anchor: the world and belt frames coincide at this time.
    pub t_ref: f64,
    /// World pose of the part at `t_ref` (= its belt-frame pose throughout the push, before touch).
    pub pose_ref: Pose,
    /// The pushing obstacle.
    pub pusher: Pusher,
    /// Contact-model settings of the push (the obstacle's friction, tolerance, fidelity).
    pub settings: ContactSettings,
    /// What the contact model computed.
    pub outcome: ContactOutcome,
    /// Pin travel at first touch (m, belt frame).
    pub s_touch: f64,
    /// Pin travel at the end of the last contact of the pass (m, belt frame).
    pub s_end: f64,
    /// World time of first touch (s).
    pub t_begin: f64,
    /// World time of the end of the push, or of an earlier stop (s).
    pub t_end: f64,
    /// Why the part leaves the line at the end of the push, if it does.
    pub stop: Option<Stop>,
    /// Recorded poses (pin travel, belt-frame pose), sorted by travel, once recorded.
    pub trace: Option<Vec<(f64, Pose)>>,
}

impl ContactPlan {
    /// Belt speed implied by the plan's times (travel / time).
    fn travel_at(&self, t: f64, speed: f64) -> f64 {
        speed * (t - self.t_ref)
    }

    /// Record the push's trace (if not yet recorded). Returns true if work was done.
    pub fn ensure_trace(&mut self, model: &PartModel) -> bool {
        if self.trace.is_some() {
            return false;
        }
        let mut samples: Vec<TraceSample> = Vec::new();
        let again = self
            .pusher
            .push(model, self.pose_ref, &self.settings, Some(&mut samples));
        debug_assert_eq!(
            again.pose_final, self.outcome.pose_final,
            "push is not pure"
        );
        self.set_trace(&samples);
        true
    }

    /// Keep the trace of a push that was recorded when it was computed (a sensor pin's knots), so
    /// that nothing pushes it again.
    pub fn set_trace(&mut self, samples: &[TraceSample]) {
        let mut trace = Vec::with_capacity(samples.len() + 2);
        trace.push((self.s_touch, self.pose_ref));
        for s in samples {
            if s.s
                > trace
                    .last()
                    .map(|l: &(f64, Pose)| l.0)
                    .unwrap_or(f64::NEG_INFINITY)
                && s.s < self.s_end
            {
                trace.push((s.s, s.pose));
            }
        }
        if self.s_end > self.s_touch {
            trace.push((self.s_end, self.outcome.pose_final));
        }
        self.trace = Some(trace);
    }

    /// World pose at time `t` of the part this plan holds, its trace searched from `hint`
    /// ([`Self::belt_pose_from`]).
    fn world_pose_from(&self, t: f64, speed: f64, hint: Option<&Cell<usize>>) -> Pose {
        let s = self.travel_at(t, speed);
        let b = self.belt_pose_from(s, hint);
        Pose::new(b.x + s, b.y, b.theta_rad)
    }

    /// Belt-frame pose at pin travel `s` (inside the contact: from the trace, if recorded),
    /// trying first the trace interval `hint` holds (the one found last) before searching the
    /// trace; `hint` is set to the interval found. The pose is the same either way: the interval
    /// is the one the search finds.
    fn belt_pose_from(&self, s: f64, hint: Option<&Cell<usize>>) -> Pose {
        if s <= self.s_touch {
            return self.pose_ref;
        }
        if s >= self.s_end {
            return self.outcome.pose_final;
        }
        let Some(tr) = self.trace.as_ref() else {
            // Without a trace only the ends are known: interpolate between them (callers that
            // need the real path record the trace first).
            let u = (s - self.s_touch) / (self.s_end - self.s_touch);
            let (p0, p1) = (self.pose_ref, self.outcome.pose_final);
            return Pose::new(
                p0.x + u * (p1.x - p0.x),
                p0.y + u * (p1.y - p0.y),
                p0.theta_rad + u * (p1.theta_rad - p0.theta_rad),
            );
        };
        // The number of knots at or before s (the trace is strictly increasing in travel).
        let i = match hint.map(Cell::get) {
            Some(h) if h >= 1 && h < tr.len() && tr[h - 1].0 <= s && tr[h].0 > s => h,
            _ => tr.partition_point(|(si, _)| *si <= s),
        };
        if let Some(h) = hint {
            h.set(i);
        }
        if i == 0 {
            return tr[0].1;
        }
        if i >= tr.len() {
            return tr[tr.len() - 1].1;
        }
        let (s0, p0) = tr[i - 1];
        let (s1, p1) = tr[i];
        let u = if s1 > s0 { (s - s0) / (s1 - s0) } else { 1.0 };
        Pose::new(
            p0.x + u * (p1.x - p0.x),
            p0.y + u * (p1.y - p0.y),
            p0.theta_rad + u * (p1.theta_rad - p0.theta_rad),
        )
    }

    /// World times at which the recorded path is known: first touch, the recorded steps inside
    /// (t_begin, t_end), and the end.
    pub fn path_times(&self, speed: f64) -> Vec<f64> {
        let mut times = vec![self.t_begin];
        times.extend(self.step_times(speed));
        times.push(self.t_end);
        times
    }

    /// World times of the recorded steps inside (t_begin, t_end).
    pub fn step_times(&self, speed: f64) -> Vec<f64> {
        match &self.trace {
            Some(tr) => tr
                .iter()
                .map(|(s, _)| self.t_ref + s / speed)
                .filter(|&t| t > self.t_begin && t < self.t_end)
                .collect(),
            None => Vec::new(),
        }
    }
}

/// The motion of a part between two of its events.
#[derive(Debug, Clone)]
pub enum Motion {
    /// Riding the belt from world pose `pose` at time `t0`, until its next event at `until`.
    Free {
        /// Start time (s).
        t0: f64,
        /// World pose at `t0`.
        pose: Pose,
        /// Time of the part's next event (s).
        until: f64,
    },
    /// Being pushed by a pin.
    Held(Box<ContactPlan>),
}

impl Motion {
    /// The time this motion ends (the part's next event).
    pub fn until(&self) -> f64 {
        match self {
            Motion::Free { until, .. } => *until,
            Motion::Held(p) => p.t_end,
        }
    }

    /// World pose at time `t` within the motion.
    pub fn world_pose(&self, t: f64, speed: f64) -> Pose {
        match self {
            Motion::Free { t0, pose, .. } => {
                Pose::new(pose.x + speed * (t - t0), pose.y, pose.theta_rad)
            }
            Motion::Held(p) => p.world_pose_from(t, speed, None),
        }
    }

    /// Belt-frame pose at time `t` (the belt frame anchored at world time 0 is not used: only
    /// differences matter). Free parts are still in it; held parts move.
    pub fn belt_pose(&self, t: f64, speed: f64) -> Pose {
        let w = self.world_pose(t, speed);
        Pose::new(w.x - speed * t, w.y, w.theta_rad)
    }
}

/// World poses of one motion asked for at times that mostly advance, as the overlap walk asks
/// for them: each the pose [`Motion::world_pose`] gives, bit for bit, from the trace interval
/// found last when the time is still in it, and the last two instants kept.
pub struct PoseCursor<'a> {
    motion: &'a Motion,
    speed: f64,
    hint: Cell<usize>,
    /// The last two instants asked for (time bits, pose), newest first.
    kept: Cell<[(u64, Pose); 2]>,
}

impl<'a> PoseCursor<'a> {
    /// A cursor on `motion` on a belt running at `speed`.
    pub fn new(motion: &'a Motion, speed: f64) -> Self {
        let none = (f64::NAN.to_bits(), Pose::default());
        PoseCursor {
            motion,
            speed,
            hint: Cell::new(0),
            kept: Cell::new([none, none]),
        }
    }

    /// The world pose at `t` (= `motion.world_pose(t, speed)`).
    pub fn at(&self, t: f64) -> Pose {
        let kept = self.kept.get();
        let bits = t.to_bits();
        if let Some(&(_, pose)) = kept.iter().find(|k| k.0 == bits) {
            return pose;
        }
        let pose = match self.motion {
            Motion::Free { .. } => self.motion.world_pose(t, self.speed),
            Motion::Held(p) => p.world_pose_from(t, self.speed, Some(&self.hint)),
        };
        self.kept.set([(bits, pose), kept[0]]);
        pose
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::part_from_spec;
    use crate::mechanics::pin_path::PinPath;
    use crate::mechanics::{ContactSettings, PartModel, Support};

    /// The overlap walk's cursor gives, bit for bit, the poses `world_pose` gives: at the recorded
    /// steps, between them, before the touch and after the end, forwards, backwards and twice.
    #[test]
    fn a_pose_cursor_gives_the_poses_world_pose_gives() {
        let poly = part_from_spec("tripoly2").unwrap();
        let model = PartModel::new(&poly, &Support::Uniform).unwrap();
        let pusher = Pusher::Pin {
            centre: Vec2::new(0.0, 0.25),
            radius: 0.1,
            path: PinPath::constant(0.0),
        };
        let pose = Pose::new(-3.0, 0.0, 0.7);
        let settings = ContactSettings::default();
        let outcome = pusher.push(&model, pose, &settings, None);
        assert!(outcome.contact);
        let speed = 0.5;
        let (s_touch, s_end) = (
            outcome.travel_to_contact,
            outcome.segments.last().unwrap().s_end,
        );
        let mut plan = ContactPlan {
            obstacle: 0,
            t_ref: 0.0,
            pose_ref: pose,
            pusher,
            settings,
            outcome,
            s_touch,
            s_end,
            t_begin: s_touch / speed,
            t_end: s_end / speed,
            stop: None,
            trace: None,
        };
        plan.ensure_trace(&model);
        assert!(plan.trace.as_ref().unwrap().len() > 5);
        let knots = plan.path_times(speed);
        let held = Motion::Held(Box::new(plan));
        let mut times: Vec<f64> = vec![0.0, knots[0] - 1.0];
        for w in knots.windows(2) {
            times.extend([w[0], 0.3 * w[0] + 0.7 * w[1], w[1], w[1]]);
        }
        times.extend([
            knots[knots.len() - 1] + 1.0,
            knots[2],
            knots[1],
            0.5 * knots[3],
        ]);
        let cursor = PoseCursor::new(&held, speed);
        for &t in &times {
            let (a, b) = (cursor.at(t), held.world_pose(t, speed));
            assert_eq!(
                [a.x.to_bits(), a.y.to_bits(), a.theta_rad.to_bits()],
                [b.x.to_bits(), b.y.to_bits(), b.theta_rad.to_bits()],
                "t = {t}"
            );
        }
    }
}
