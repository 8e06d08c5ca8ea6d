//! The animation as plain data: the belt, the part's outline, the obstacles with their knots in
//! time, the sample parts' poses and the timed marks; the limits the renderer keeps to, and the
//! loop's length.

use crate::engine::PartOutcome;
use crate::geometry::{Pose, Vec2};

/// Everything the animation shows (plain data; world frame, metres, seconds, radians).
#[derive(Debug, Clone, PartialEq)]
pub struct Animation {
    /// Title shown above the belt.
    pub title: String,
    /// m.
    pub belt_length: f64,
    /// m.
    pub belt_width: f64,
    /// m/s.
    pub belt_speed: f64,
    /// The part's outline in its own frame (metres, centroid at the origin).
    pub outline: Vec<Vec2>,
    /// The pins and fences.
    pub obstacles: Vec<AnimObstacle>,
    /// The sample parts drawn (at most [`MAX_PARTS`]).
    pub parts: Vec<AnimPart>,
    /// The timed labels (at most [`MAX_MARKS`]).
    pub marks: Vec<AnimMark>,
    /// Simulated time shown: [t_start, t_end] seconds.
    pub t_start: f64,
    /// End of the simulated time shown (s).
    pub t_end: f64,
}

/// The shape of an obstacle (world frame, m).
#[derive(Debug, Clone, PartialEq)]
pub enum AnimShape {
    /// A pin at `x` along the belt; its lateral position is the obstacle's `track`.
    Pin {
        /// Position along the belt (m).
        x: f64,
        /// Radius (m).
        radius: f64,
    },
    /// A fence from `p0` to `p1`, and on along its curved tail if it has one.
    Fence {
        /// One end (m).
        p0: Vec2,
        /// The other end of the straight part (m).
        p1: Vec2,
        /// The tail: its radius and far end (m), turning clockwise when `clockwise` (a fence at a
        /// positive angle).
        tail: Option<(f64, Vec2, bool)>,
    },
}

/// An obstacle and, for a pin, its lateral motion and raised state in time.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimObstacle {
    /// The obstacle's name in the scenario.
    pub name: String,
    /// Its shape and place.
    pub shape: AnimShape,
    /// Does it carry a sensor?
    pub sensor: bool,
    /// Knots (time s, pin centre y in metres, raised?) — linear in y between knots; a still pin
    /// has one knot; ignored for fences. The raised state holds from its knot to the next.
    pub track: Vec<(f64, f64, bool)>,
}

/// A sample part: its outcome and its world poses (time s, pose), in time order.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimPart {
    /// Index of the part in the feed.
    pub part: u64,
    /// How the part ended (its colour at the end).
    pub outcome: PartOutcome,
    /// (time s, world pose: metres and radians), in time order.
    pub poses: Vec<(f64, Pose)>,
}

/// What a mark reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MarkKind {
    /// A sensor reads a part.
    Reading,
    /// A classifier or controller decides.
    Decision,
    /// An actuator moves (a pin starts to move, rises or withdraws).
    Actuation,
    /// A command that could not finish before the part arrived.
    Late,
}

impl MarkKind {
    /// Every kind, in legend order.
    pub const ALL: [MarkKind; 4] = [
        MarkKind::Reading,
        MarkKind::Decision,
        MarkKind::Actuation,
        MarkKind::Late,
    ];
    /// Lower-case name (the legend's and the SVG class's).
    pub fn name(self) -> &'static str {
        match self {
            MarkKind::Reading => "reading",
            MarkKind::Decision => "decision",
            MarkKind::Actuation => "actuation",
            MarkKind::Late => "late",
        }
    }
    /// The colour its label and flash are drawn in.
    pub fn colour(self) -> &'static str {
        match self {
            MarkKind::Reading => "#1f6fd0",
            MarkKind::Decision => "#7b2cbf",
            MarkKind::Actuation => "#d07000",
            MarkKind::Late => "#d01010",
        }
    }
}

/// A short timed label (with a flash) at a place: a reading, a decision, an actuation.
#[derive(Debug, Clone, PartialEq)]
pub struct AnimMark {
    /// Simulated time (s).
    pub t: f64,
    /// Where (world, m), usually the pin.
    pub at: Vec2,
    /// What the mark reports (its colour).
    pub kind: MarkKind,
    /// The label's text.
    pub text: String,
}

/// How to play the animation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AnimateOptions {
    /// Simulated seconds per animation second; default: [`default_speedup`].
    pub speedup: Option<f64>,
}

/// At most this many parts are drawn (the first ones); a larger `parts` list is cut.
pub const MAX_PARTS: usize = 50;
/// At most this many keyframes per part (and per pin track).
pub const MAX_KEYS: usize = 300;
/// At most this many marks are drawn (the earliest).
pub const MAX_MARKS: usize = 1000;
/// At most this many outline vertices are drawn (a longer outline is sampled evenly).
pub const MAX_OUTLINE: usize = 400;
/// Thinned keyframes keep the drawn part within this distance (px) of the recorded motion.
pub const POSE_TOLERANCE_PX: f64 = 0.3;
/// A part stays, in its outcome colour, this long (animation seconds) after it ends.
pub const END_HOLD_S: f64 = 1.5;
/// A mark's label shows this long (animation seconds), then fades over [`MARK_FADE_S`].
pub const MARK_SHOW_S: f64 = 1.8;
/// How long a mark's label fades out (animation seconds).
pub const MARK_FADE_S: f64 = 0.5;
/// The loop lasts at least / at most this long (animation seconds), whatever the speed-up.
pub const MIN_DURATION_S: f64 = 0.5;
/// The loop's longest duration (animation seconds).
pub const MAX_DURATION_S: f64 = 3600.0;

/// Simulated seconds shown, at least a millisecond.
pub(super) fn span(anim: &Animation) -> f64 {
    let s = anim.t_end - anim.t_start;
    if s.is_finite() && s > 1e-3 {
        s
    } else {
        1e-3
    }
}

/// The default speed-up: real time when the simulated span lasts 20–40 s, else whatever brings
/// the loop to 20 s (short spans, slowed down) or 40 s (long spans, sped up).
pub fn default_speedup(anim: &Animation) -> f64 {
    let s = span(anim);
    s / s.clamp(20.0, 40.0)
}

/// Length of one loop (animation seconds) with these options, within
/// [[`MIN_DURATION_S`], [`MAX_DURATION_S`]].
pub fn duration(anim: &Animation, opts: &AnimateOptions) -> f64 {
    let speedup = opts
        .speedup
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or_else(|| default_speedup(anim));
    (span(anim) / speedup).clamp(MIN_DURATION_S, MAX_DURATION_S)
}

/// A pin's (y, raised) at simulated time `t` from its knots: y linear between knots, the raised
/// state of the latest knot at or before `t` (the first knot's before it).
pub fn pin_state(track: &[(f64, f64, bool)], t: f64) -> Option<(f64, bool)> {
    let first = track.first()?;
    if t <= first.0 {
        return Some((first.1, first.2));
    }
    for w in track.windows(2) {
        let (a, b) = (w[0], w[1]);
        if t < b.0 {
            let f = if b.0 > a.0 {
                (t - a.0) / (b.0 - a.0)
            } else {
                1.0
            };
            return Some((a.1 + f * (b.1 - a.1), a.2));
        }
    }
    let last = track[track.len() - 1];
    Some((last.1, last.2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pin_state_is_linear_in_y_and_stepwise_in_raised() {
        let track = [(0.0, 0.0, true), (2.0, 0.02, false), (4.0, 0.02, true)];
        assert_eq!(pin_state(&track, -1.0), Some((0.0, true)));
        let (y, up) = pin_state(&track, 1.0).unwrap();
        assert!((y - 0.01).abs() < 1e-12 && up);
        assert_eq!(pin_state(&track, 3.0), Some((0.02, false)));
        assert_eq!(pin_state(&track, 5.0), Some((0.02, true)));
        assert_eq!(pin_state(&[], 5.0), None);
    }
}
