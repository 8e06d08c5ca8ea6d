//! A pin's path relative to the belt when its lateral speed changes during a pass (docs/physics.md#moving-and-retractable-pins).
//!
//! A moving pin's lateral velocity is piecewise constant in pin travel: it starts at `w0` and
//! changes to `w` at each [`Turn`]. Relative to the belt the pin moves along (−1, w) (speeds as
//! fractions of the belt speed), so its path is a polyline in the belt frame parametrised by the
//! travel s (= belt speed × time). Each turn is a step boundary of the integrator, like a mode
//! switch: the state is continuous there and the mode is settled again with the new velocity.
//!
//! A continuous acceleration (a trapezoidal actuator move) is approximated by constant-velocity
//! pieces whose positions agree with the true move at the piece ends; `results/online-line.md` measures
//! what that costs against a finely resolved acceleration phase.

use serde::Serialize;

/// From pin travel `s` (caller's units, measured from the start of the pass) on, the pin's lateral
/// speed is `w` (a fraction of the belt speed).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Turn {
    /// Pin travel where the speed changes (caller's units, from the start of the pass).
    pub s: f64,
    /// Lateral speed from `s` on (a fraction of the belt speed, signed: + is +y).
    pub w: f64,
}

/// The largest lateral pin speed accepted, as a multiple of the belt speed.
pub const MAX_LATERAL_SPEED: f64 = 1e3;

/// The lateral speed profile of a pin over one pass: `w0` at the start, then each turn in order.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct PinPath {
    w0: f64,
    turns: Vec<Turn>,
}

/// Why a pin path is refused ([`PinPath::new`], [`PinPath::move_to`], [`PinPath::ramp`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PinPathError {
    /// The initial lateral speed is not finite or exceeds ±[`MAX_LATERAL_SPEED`].
    #[error("lateral pin speed {w0} is not within ±{MAX_LATERAL_SPEED} belt speeds")]
    InitialSpeed {
        /// The initial lateral speed.
        w0: f64,
    },
    /// A turn's travel is not finite or does not exceed the previous turn's.
    #[error("turn {index}: travel {s} must be finite and greater than {previous}")]
    Travel {
        /// Index of the turn.
        index: usize,
        /// Its travel.
        s: f64,
        /// The previous turn's travel (0 for the first).
        previous: f64,
    },
    /// A turn's lateral speed is not finite or exceeds ±[`MAX_LATERAL_SPEED`].
    #[error("turn {index}: lateral pin speed {w} is not within ±{MAX_LATERAL_SPEED} belt speeds")]
    TurnSpeed {
        /// Index of the turn.
        index: usize,
        /// Its lateral speed.
        w: f64,
    },
    /// A pin moving away from its stop position.
    #[error("a pin moving at lateral speed {w} from y = {y0} never reaches y = {y_stop}")]
    NeverReaches {
        /// The lateral speed.
        w: f64,
        /// The starting lateral position.
        y0: f64,
        /// The stop position.
        y_stop: f64,
    },
}

impl PinPath {
    /// A pin moving at constant lateral speed `w` (0: a still pin).
    pub fn constant(w: f64) -> PinPath {
        PinPath {
            w0: w,
            turns: Vec::new(),
        }
    }

    /// A profile starting at `w0` with `turns`; travels must be finite, positive and increasing,
    /// speeds finite and within ±[`MAX_LATERAL_SPEED`].
    pub fn new(w0: f64, turns: Vec<Turn>) -> Result<PinPath, PinPathError> {
        let speed_ok = |w: f64| w.is_finite() && w.abs() <= MAX_LATERAL_SPEED;
        if !speed_ok(w0) {
            return Err(PinPathError::InitialSpeed { w0 });
        }
        let mut last = 0.0;
        for (i, t) in turns.iter().enumerate() {
            if !(t.s.is_finite() && t.s > last) {
                return Err(PinPathError::Travel {
                    index: i,
                    s: t.s,
                    previous: last,
                });
            }
            if !speed_ok(t.w) {
                return Err(PinPathError::TurnSpeed { index: i, w: t.w });
            }
            last = t.s;
        }
        Ok(PinPath { w0, turns })
    }

    /// The thesis's app. E set-up: the pin moves across the belt at lateral speed `w` from lateral
    /// position `y0` until it stands at `y_stop` (then still). Positions in the caller's units.
    pub fn move_to(w: f64, y0: f64, y_stop: f64) -> Result<PinPath, PinPathError> {
        if y_stop == y0 || w == 0.0 {
            return PinPath::new(0.0, Vec::new());
        }
        if (y_stop - y0) * w < 0.0 {
            return Err(PinPathError::NeverReaches { w, y0, y_stop });
        }
        let s = (y_stop - y0) / w;
        PinPath::new(w, vec![Turn { s, w: 0.0 }])
    }

    /// A pin still until travel `s0`, then changing its lateral speed linearly from 0 to `w` over
    /// a travel `len`, resolved into `pieces` constant-speed pieces (each at its mean speed, so
    /// positions agree with the linear ramp at the piece ends), then moving at `w`.
    pub fn ramp(s0: f64, len: f64, w: f64, pieces: usize) -> Result<PinPath, PinPathError> {
        let n = pieces.max(1);
        let turns = (0..n)
            .map(|i| Turn {
                s: s0 + len * i as f64 / n as f64,
                w: w * (i as f64 + 0.5) / n as f64,
            })
            .chain(std::iter::once(Turn { s: s0 + len, w }))
            .collect();
        PinPath::new(0.0, turns)
    }

    /// Lateral speed before the first turn (a fraction of the belt speed).
    pub fn initial_speed(&self) -> f64 {
        self.w0
    }

    /// The turns, in increasing travel.
    pub fn turns(&self) -> &[Turn] {
        &self.turns
    }

    /// Lateral speed at travel `s` (the speed after a turn at exactly `s`).
    pub fn speed_at(&self, s: f64) -> f64 {
        self.turns
            .iter()
            .take_while(|t| t.s <= s)
            .last()
            .map_or(self.w0, |t| t.w)
    }

    /// Lateral displacement of the pin after travel `s` (caller's units).
    pub fn offset_at(&self, s: f64) -> f64 {
        let mut y = 0.0;
        let (mut from, mut w) = (0.0, self.w0);
        for t in &self.turns {
            if t.s >= s {
                break;
            }
            y += w * (t.s - from);
            from = t.s;
            w = t.w;
        }
        y + w * (s - from)
    }

    /// The same profile in normalised units (travels divided by `scale`).
    pub(crate) fn scaled(&self, scale: f64) -> impl Iterator<Item = Turn> + '_ {
        self.turns.iter().map(move |t| Turn {
            s: t.s / scale,
            w: t.w,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_integrate_the_speed_profile() {
        let p = PinPath::new(1.0, vec![Turn { s: 2.0, w: -0.5 }, Turn { s: 4.0, w: 0.0 }]).unwrap();
        assert_eq!(p.offset_at(1.0), 1.0);
        assert_eq!(p.offset_at(2.0), 2.0);
        assert_eq!(p.offset_at(3.0), 1.5);
        assert_eq!(p.offset_at(10.0), 1.0);
        assert_eq!(p.speed_at(1.9), 1.0);
        assert_eq!(p.speed_at(2.0), -0.5);
        assert_eq!(p.speed_at(5.0), 0.0);
    }

    #[test]
    fn bad_profiles_are_refused() {
        assert!(PinPath::new(f64::NAN, vec![]).is_err());
        assert!(PinPath::new(0.0, vec![Turn { s: 0.0, w: 1.0 }]).is_err());
        assert!(PinPath::new(0.0, vec![Turn { s: 2.0, w: 1.0 }, Turn { s: 1.0, w: 0.0 }]).is_err());
        assert!(PinPath::new(0.0, vec![Turn { s: 1.0, w: 1e9 }]).is_err());
        assert!(PinPath::move_to(1.0, 0.0, -1.0).is_err());
        let p = PinPath::move_to(-1.0, 0.3, 0.1).unwrap();
        assert!((p.offset_at(100.0) + 0.2).abs() < 1e-15);
    }
}
