//! The actuators of dynamic pins (docs/physics.md#moving-and-retractable-pins): where a moving pin stands and whether a retractable
//! pin is raised, at any time, as a timeline of commanded moves with their real motion times.
//!
//! * A **moving pin** travels along y in trapezoidal moves: acceleration `accel` up to `speed`,
//!   cruise, deceleration to rest (a triangle when the move is too short to reach `speed`), then
//!   `settle` seconds before it counts as ready. [`Track::path_from`] turns the timeline into the
//!   lateral speed profile the contact model follows ([`PinPath`]): each acceleration phase is
//!   resolved into `pieces` constant-speed pieces whose positions agree with the true move at the
//!   piece ends (second-order convergence; `tests/moving_pin.rs` measures it).
//! * A **retractable pin** is raised or withdrawn; a switch takes `raise_time` or `lower_time`,
//!   during which the pin is not an obstacle (a part never meets a pin in transit: commands that
//!   cannot finish before the part arrives are refused as late, see [`super::controller`]).
//!
//! Moves never overlap: a new one starts after the last has settled. Moves that ended before
//! every part on the belt was last planned are forgotten ([`Track::forget_before`]), so memory is
//! flat in the number of parts.

use crate::mechanics::{PinPath, Turn, MAX_LATERAL_SPEED};
use crate::scenario::{MovingSpec, RetractSpec, Target};
use std::collections::VecDeque;

/// One trapezoidal move of a moving pin, from rest at `y0` (time `t0`) to rest at `y1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Move {
    /// Start time (s).
    pub t0: f64,
    /// Start position (m).
    pub y0: f64,
    /// End position (m).
    pub y1: f64,
    /// Duration of the acceleration phase, and of the equal deceleration phase (s).
    pub ta: f64,
    /// Cruise time at full speed (s, 0 for a triangular profile).
    pub tc: f64,
}

impl Move {
    /// The fastest move from `y0` to `y1` under the speed and acceleration limits, starting at `t0`.
    pub fn plan(t0: f64, y0: f64, y1: f64, speed: f64, accel: f64) -> Move {
        let dist = (y1 - y0).abs();
        let (ta, tc) = if dist >= speed * speed / accel {
            (speed / accel, (dist - speed * speed / accel) / speed)
        } else {
            ((dist / accel).sqrt(), 0.0)
        };
        Move { t0, y0, y1, ta, tc }
    }

    /// The move's length in time (s; 0 for a null move).
    pub fn duration(&self) -> f64 {
        2.0 * self.ta + self.tc
    }

    /// When the move ends (s).
    pub fn t_end(&self) -> f64 {
        self.t0 + self.duration()
    }

    /// Peak speed (signed).
    fn peak(&self) -> f64 {
        let d = self.y1 - self.y0;
        if d == 0.0 {
            0.0
        } else {
            d / (self.ta + self.tc)
        }
    }

    /// Position at time `t` (exact: piecewise quadratic).
    pub fn y_at(&self, t: f64) -> f64 {
        let tau = t - self.t0;
        let vp = self.peak();
        let acc = if self.ta > 0.0 { vp / self.ta } else { 0.0 };
        if tau <= 0.0 {
            self.y0
        } else if tau < self.ta {
            self.y0 + 0.5 * acc * tau * tau
        } else if tau < self.ta + self.tc {
            self.y0 + 0.5 * vp * self.ta + vp * (tau - self.ta)
        } else if tau < self.duration() {
            let r = self.duration() - tau;
            self.y1 - 0.5 * acc * r * r
        } else {
            self.y1
        }
    }

    /// The instants that bound constant-speed pieces: each acceleration phase cut into `pieces`,
    /// the cruise whole.
    fn knots(&self, pieces: usize) -> Vec<f64> {
        let n = pieces.max(1);
        let mut k = Vec::with_capacity(2 * n + 2);
        for i in 0..=n {
            k.push(self.t0 + self.ta * i as f64 / n as f64);
        }
        let decel = self.t0 + self.ta + self.tc;
        if self.tc > 0.0 {
            k.push(decel);
        }
        for i in 1..=n {
            k.push(decel + self.ta * i as f64 / n as f64);
        }
        k
    }
}

/// A retractable pin's switch: from `t0` to `t1` it is in transit, then raised (`up`) or withdrawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Switch {
    /// Start time (s).
    pub t0: f64,
    /// End time (s).
    pub t1: f64,
    /// The state it switches to (true: raised).
    pub up: bool,
}

/// The timeline of one dynamic pin.
#[derive(Debug, Clone)]
pub enum Track {
    /// A moving pin's planned moves.
    Moving {
        /// The pin's limits.
        spec: MovingSpec,
        /// Where the pin rests before the first remembered move.
        base: f64,
        /// Its moves, in time order.
        moves: VecDeque<Move>,
    },
    /// A retractable pin's planned switches.
    Retractable {
        /// The pin's switching times.
        spec: RetractSpec,
        /// Its state before the first switch.
        base: bool,
        /// Its switches, in time order.
        switches: VecDeque<Switch>,
    },
}

impl Track {
    /// A moving pin with no move planned.
    pub fn moving(spec: MovingSpec) -> Track {
        Track::Moving {
            base: spec.home,
            spec,
            moves: VecDeque::new(),
        }
    }

    /// A retractable pin with no switch planned.
    pub fn retractable(spec: RetractSpec) -> Track {
        Track::Retractable {
            base: spec.raised,
            spec,
            switches: VecDeque::new(),
        }
    }

    /// Lateral position of the pin's centre at time `t` (a retractable pin stands still).
    pub fn y_at(&self, t: f64, home: f64) -> f64 {
        match self {
            Track::Moving { base, moves, .. } => moves
                .iter()
                .rev()
                .find(|m| m.t0 <= t)
                .map_or(*base, |m| m.y_at(t)),
            Track::Retractable { .. } => home,
        }
    }

    /// Is the pin an obstacle at time `t` (a moving pin always is; a retractable one when fully
    /// raised)?
    pub fn present_at(&self, t: f64) -> bool {
        match self {
            Track::Moving { .. } => true,
            Track::Retractable { base, switches, .. } => {
                match switches.iter().rev().find(|s| s.t0 <= t) {
                    None => *base,
                    Some(s) if t < s.t1 => false,
                    Some(s) => s.up,
                }
            }
        }
    }

    /// When the last commanded motion is over and the pin ready again (settle included).
    pub fn ready_at(&self) -> f64 {
        match self {
            Track::Moving { spec, moves, .. } => moves
                .back()
                .map_or(f64::NEG_INFINITY, |m| m.t_end() + spec.settle),
            Track::Retractable { switches, .. } => {
                switches.back().map_or(f64::NEG_INFINITY, |s| s.t1)
            }
        }
    }

    /// The state the pin is in once its commanded motions are over.
    pub fn final_target(&self) -> Target {
        match self {
            Track::Moving { base, moves, .. } => Target::Y(moves.back().map_or(*base, |m| m.y1)),
            Track::Retractable { base, switches, .. } => {
                Target::Raised(switches.back().map_or(*base, |s| s.up))
            }
        }
    }

    /// The motion that brings the pin to `target` starting at `t0`: (duration until ready, travel
    /// in metres). A target equal to the current one needs nothing (0, 0).
    pub fn cost(&self, target: Target) -> (f64, f64) {
        match (self, target, self.final_target()) {
            (Track::Moving { spec, .. }, Target::Y(y1), Target::Y(y0)) => {
                if y1 == y0 {
                    return (0.0, 0.0);
                }
                let m = Move::plan(0.0, y0, y1, spec.speed, spec.accel);
                (m.duration() + spec.settle, (y1 - y0).abs())
            }
            (Track::Retractable { spec, .. }, Target::Raised(up), Target::Raised(now)) => {
                if up == now {
                    (0.0, 0.0)
                } else if up {
                    (spec.raise_time, 0.0)
                } else {
                    (spec.lower_time, 0.0)
                }
            }
            _ => (0.0, 0.0),
        }
    }

    /// Start the motion to `target` at `t0` (after the last one is over).
    pub fn command(&mut self, t0: f64, target: Target) {
        debug_assert!(t0 >= self.ready_at());
        let dur = self.cost(target).0;
        if dur == 0.0 {
            return;
        }
        match (self, target) {
            (Track::Moving { spec, moves, base }, Target::Y(y1)) => {
                let y0 = moves.back().map_or(*base, |m| m.y1);
                moves.push_back(Move::plan(t0, y0, y1, spec.speed, spec.accel));
            }
            (Track::Retractable { switches, .. }, Target::Raised(up)) => {
                switches.push_back(Switch {
                    t0,
                    t1: t0 + dur,
                    up,
                });
            }
            _ => {}
        }
    }

    /// Forget motions that were over before `t` (no part on the belt was planned before `t`).
    pub fn forget_before(&mut self, t: f64) {
        match self {
            Track::Moving { base, moves, .. } => {
                while moves.len() > 1 && moves[1].t0 <= t && moves[0].t_end() <= t {
                    *base = moves.pop_front().expect("checked").y1;
                }
            }
            Track::Retractable { base, switches, .. } => {
                while switches.len() > 1 && switches[1].t0 <= t && switches[0].t1 <= t {
                    *base = switches.pop_front().expect("checked").up;
                }
            }
        }
    }

    /// The pin's lateral speed profile from time `t0` on, as the contact model takes it: travel
    /// s = V·(t − t0), speed w = ẏ / V, each acceleration phase in `pieces` pieces.
    pub fn path_from(&self, t0: f64, belt_speed: f64, pieces: usize) -> PinPath {
        let Track::Moving { moves, spec, .. } = self else {
            return PinPath::constant(0.0);
        };
        let mut knots: Vec<f64> = Vec::new();
        for m in moves.iter().filter(|m| m.t_end() > t0) {
            knots.extend(m.knots(pieces));
        }
        // Pieces between successive knots (and from t0 to the first), at their mean speed.
        // A piece's mean speed never exceeds the actuator's limit; rounding of the difference
        // quotient over a short piece may, so it is clamped to the limit (which the scenario
        // checker keeps within the path's invariant, `limits::max_pin_speed`).
        let w_max = (spec.speed / belt_speed).min(MAX_LATERAL_SPEED);
        let mut w0 = 0.0;
        let mut turns = Vec::new();
        let mut prev = t0;
        let home = 0.0;
        for &k in knots.iter().filter(|&&k| k > t0) {
            if k - prev <= 1e-12 * (1.0 + k.abs()) {
                continue;
            }
            let w = ((self.y_at(k, home) - self.y_at(prev, home)) / (k - prev) / belt_speed)
                .clamp(-w_max, w_max);
            if prev == t0 {
                w0 = w;
            } else {
                turns.push(Turn {
                    s: belt_speed * (prev - t0),
                    w,
                });
            }
            prev = k;
        }
        if prev > t0 {
            turns.push(Turn {
                s: belt_speed * (prev - t0),
                w: 0.0,
            });
        }
        // Successive turns to the same speed are one piece.
        turns.dedup_by(|b, a| a.w == b.w);
        if turns.first().is_some_and(|t| t.w == w0) {
            turns.remove(0);
        }
        PinPath::new(w0, turns).expect("an actuator's profile is a valid pin path")
    }

    /// The lateral span [lo, hi] the pin's centre covers during [ta, tb] (a move is monotone, so
    /// its extremes are at the ends of the interval or of the moves inside it).
    pub fn y_span(&self, ta: f64, tb: f64, home: f64) -> (f64, f64) {
        let mut ys = vec![self.y_at(ta, home), self.y_at(tb, home)];
        if let Track::Moving { moves, .. } = self {
            for m in moves.iter().filter(|m| m.t0 < tb && m.t_end() > ta) {
                ys.push(m.y_at(m.t0.max(ta)));
                ys.push(m.y_at(m.t_end().min(tb)));
            }
        }
        let lo = ys.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = ys.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (lo, hi)
    }

    /// Is the pin present at any time during [ta, tb]?
    pub fn present_during(&self, ta: f64, tb: f64) -> bool {
        match self {
            Track::Moving { .. } => true,
            Track::Retractable { switches, .. } => {
                self.present_at(ta)
                    || self.present_at(tb)
                    || switches.iter().any(|s| s.up && s.t1 > ta && s.t1 < tb)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> MovingSpec {
        MovingSpec {
            home: 0.0,
            travel: [-0.05, 0.05],
            speed: 0.1,
            accel: 1.0,
            settle: 0.05,
            pieces: 8,
        }
    }

    #[test]
    fn trapezoid_respects_its_limits() {
        // Long move: cruises at the speed limit.
        let m = Move::plan(1.0, 0.0, 0.05, 0.1, 1.0);
        assert!((m.ta - 0.1).abs() < 1e-15 && (m.tc - 0.4).abs() < 1e-12);
        assert!((m.y_at(m.t_end()) - 0.05).abs() < 1e-15);
        assert!((m.y_at(1.0 + 0.05) - 0.5 * 1.0 * 0.05f64.powi(2)).abs() < 1e-15);
        // Speeds never exceed the limit; positions are continuous and monotone.
        let mut last = 0.0;
        for i in 1..=1000 {
            let t = 1.0 + m.duration() * i as f64 / 1000.0;
            let y = m.y_at(t);
            assert!(y >= last - 1e-15);
            assert!((y - last) / (m.duration() / 1000.0) <= 0.1 + 1e-9);
            last = y;
        }
        // Short move: a triangle below the speed limit.
        let s = Move::plan(0.0, 0.01, 0.0, 0.1, 1.0);
        assert_eq!(s.tc, 0.0);
        assert!((s.duration() - 2.0 * 0.1f64.sqrt() * 0.1f64.sqrt()).abs() < 1e-12);
        assert!((s.y_at(s.duration() / 2.0) - 0.005).abs() < 1e-12);
    }

    #[test]
    fn path_agrees_with_the_move_at_piece_ends() {
        let mut t = Track::moving(spec());
        t.command(2.0, Target::Y(0.03));
        let v = 0.05;
        for t0 in [0.0, 2.05, 2.2] {
            let p = t.path_from(t0, v, 8);
            for tt in [2.0, 2.1, 2.3, 2.4, 3.0] {
                if tt < t0 {
                    continue;
                }
                let s = v * (tt - t0);
                let y = t.y_at(t0, 0.0) + p.offset_at(s);
                assert!((y - t.y_at(tt, 0.0)).abs() < 1e-12, "t0={t0} t={tt}: {y}");
            }
        }
        // At rest: a still pin.
        assert_eq!(t.path_from(10.0, v, 8), PinPath::constant(0.0));
    }

    #[test]
    fn retractable_is_absent_in_transit() {
        let mut t = Track::retractable(RetractSpec {
            raised: true,
            raise_time: 0.2,
            lower_time: 0.1,
        });
        assert!(t.present_at(0.0));
        t.command(1.0, Target::Raised(false));
        assert!(t.present_at(0.99) && !t.present_at(1.05) && !t.present_at(5.0));
        t.command(5.0, Target::Raised(true));
        assert!(!t.present_at(5.1) && t.present_at(5.2));
        assert_eq!(t.cost(Target::Raised(true)), (0.0, 0.0));
        t.forget_before(6.0);
        assert!(t.present_at(6.0));
    }
}
