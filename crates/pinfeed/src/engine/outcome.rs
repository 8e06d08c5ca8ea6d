//! How a part leaves the line. Every part that enters ends in exactly one class (docs/physics.md#the-line):
//!
//! | class | meaning |
//! |---|---|
//! | `success` | reached x = belt length with its orientation in the goal |
//! | `wrong_orientation` | reached x = belt length, orientation not in the goal |
//! | `collision` | overlapped another part (both parts are taken off the line at that instant) |
//! | `multi_contact` | touched two obstacles at once (another obstacle during a push), or the pin met a concave notch (two contact points) |
//! | `off_belt` | its centroid left the belt's width after a push, or while a fence carried it across (it falls off) |
//! | `jam` | an obstacle holds it for good: it rides on a pin beyond `model.max_travel` (cause `travel_limit`), or it stops against a fence at α + atan μf ≥ 90° while the belt slips under it (cause `fence_angle`, docs/physics.md#fences). A real line would stop here; the part is counted and removed at that instant |
//! | `solver` | the contact model could not finish the push (evaluation/event limits, step too small, a sub-problem failed); the cause is counted |

use serde::Serialize;

/// The class of a finished part.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PartOutcome {
    /// Reached the end of the belt with its orientation in the goal.
    Success,
    /// Reached the end of the belt with an orientation outside the goal.
    WrongOrientation,
    /// Overlapped another part (both are taken off the line).
    Collision,
    /// Touched two obstacles at once, or the pin met a concave notch.
    MultiContact,
    /// Its centroid left the belt's width (it falls off).
    OffBelt,
    /// Held for good by a pin (beyond `model.max_travel`) or a fence (α + atan μf ≥ 90°).
    Jam,
    /// The contact model could not finish the push.
    Solver,
    /// Taken off by a closed loop's gate and never delivered: scrapped on its last pass or at a
    /// full buffer, or rejected by a gate with no return path. Only a Monte Carlo sample of a
    /// closed loop ends so; on the line the loop's `fates` count these parts.
    Rejected,
}

impl PartOutcome {
    /// Every class, in the order of the summary.
    /// (The classes a pass on the line can end in: [`PartOutcome::EVERY`] but `rejected`.)
    pub const ALL: [PartOutcome; 7] = {
        let mut all = [PartOutcome::Success; 7];
        let mut i = 0;
        while i < 7 {
            all[i] = PartOutcome::EVERY[i];
            i += 1;
        }
        all
    };

    /// Every class, [`PartOutcome::ALL`] and then `rejected` (a Monte Carlo sample of a closed
    /// loop).
    pub const EVERY: [PartOutcome; 8] = [
        PartOutcome::Success,
        PartOutcome::WrongOrientation,
        PartOutcome::Collision,
        PartOutcome::MultiContact,
        PartOutcome::OffBelt,
        PartOutcome::Jam,
        PartOutcome::Solver,
        PartOutcome::Rejected,
    ];

    /// The class's name in outputs (`success`, `wrong_orientation`, `collision`, `multi_contact`, `off_belt`, `jam`, `solver`).
    pub fn name(self) -> &'static str {
        match self {
            PartOutcome::Success => "success",
            PartOutcome::WrongOrientation => "wrong_orientation",
            PartOutcome::Collision => "collision",
            PartOutcome::MultiContact => "multi_contact",
            PartOutcome::OffBelt => "off_belt",
            PartOutcome::Jam => "jam",
            PartOutcome::Solver => "solver",
            PartOutcome::Rejected => "rejected",
        }
    }

    /// Did the part reach the end of the belt?
    pub fn exited(self) -> bool {
        matches!(self, PartOutcome::Success | PartOutcome::WrongOrientation)
    }
}

/// Counts per class, serialised as an object with the classes in a fixed order.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct OutcomeCounts {
    /// Parts that exited in the goal.
    pub success: u64,
    /// Parts that exited outside the goal.
    pub wrong_orientation: u64,
    /// Parts taken off by a part–part overlap.
    pub collision: u64,
    /// Parts that touched two obstacles at once.
    pub multi_contact: u64,
    /// Parts that fell off the belt's side.
    pub off_belt: u64,
    /// Parts held for good by an obstacle.
    pub jam: u64,
    /// Parts whose push the contact model could not finish.
    pub solver: u64,
    /// Monte Carlo samples of a closed loop that the gate took off for good (absent when 0).
    #[serde(skip_serializing_if = "is_zero")]
    pub rejected: u64,
}

fn is_zero(k: &u64) -> bool {
    *k == 0
}

impl OutcomeCounts {
    /// Count one part of class `o`.
    pub fn add(&mut self, o: PartOutcome) {
        *self.get_mut(o) += 1;
    }
    /// Count `n` parts of class `o`.
    pub fn add_n(&mut self, o: PartOutcome, n: u64) {
        *self.get_mut(o) += n;
    }
    /// The count of class `o`.
    pub fn get(&self, o: PartOutcome) -> u64 {
        match o {
            PartOutcome::Success => self.success,
            PartOutcome::WrongOrientation => self.wrong_orientation,
            PartOutcome::Collision => self.collision,
            PartOutcome::MultiContact => self.multi_contact,
            PartOutcome::OffBelt => self.off_belt,
            PartOutcome::Jam => self.jam,
            PartOutcome::Solver => self.solver,
            PartOutcome::Rejected => self.rejected,
        }
    }
    fn get_mut(&mut self, o: PartOutcome) -> &mut u64 {
        match o {
            PartOutcome::Success => &mut self.success,
            PartOutcome::WrongOrientation => &mut self.wrong_orientation,
            PartOutcome::Collision => &mut self.collision,
            PartOutcome::MultiContact => &mut self.multi_contact,
            PartOutcome::OffBelt => &mut self.off_belt,
            PartOutcome::Jam => &mut self.jam,
            PartOutcome::Solver => &mut self.solver,
            PartOutcome::Rejected => &mut self.rejected,
        }
    }
    /// Add every count of `o` to this one's.
    pub fn absorb(&mut self, o: &OutcomeCounts) {
        for k in PartOutcome::EVERY {
            self.add_n(k, o.get(k));
        }
    }
    /// All parts counted, over every class.
    pub fn total(&self) -> u64 {
        PartOutcome::EVERY.iter().map(|&o| self.get(o)).sum()
    }
}

/// Why a part ended as `multi_contact`, `jam` or `solver`: the cause counted in the summary
/// (`causes`) and written in its record. Written as its name (`second_obstacle`, …; the empty
/// string for [`Cause::None`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Cause {
    /// No cause: the part exited, collided or fell off the belt.
    None,
    /// `multi_contact`: the pin met a concave notch (two contact points at once).
    Notch,
    /// `multi_contact`: a neighbouring obstacle touched the part during a push.
    SecondObstacle,
    /// The pin started inside the part: `multi_contact` at a contact's begin (a solver cause if
    /// a push reports it otherwise).
    PinInsidePart,
    /// `jam`: a pin still pushed the part after `model.max_travel`.
    TravelLimit,
    /// `jam`: the part stopped against a fence at α + atan μf ≥ 90°.
    FenceAngle,
    /// `solver`: touches in a row that pushed nothing, beyond the bound on grazes.
    GrazingLoop,
    /// `solver`: a limit-surface sub-problem did not converge.
    NoConvergence,
    /// `solver`: a sub-problem produced a non-finite number.
    NonFinite,
    /// `solver`: the push exceeded its budget of limit-surface evaluations.
    EvaluationLimit,
    /// `solver`: the push exceeded its budget of events.
    EventLimit,
    /// `solver`: the integration step fell below its floor.
    StepTooSmall,
    /// `solver`: the contact model's consistency check failed.
    SelfCheck,
    /// `solver`: the push rode an unstable equilibrium and fell off to a side rounding decided.
    Metastable,
}

impl Cause {
    /// The cause's name in outputs (the empty string for [`Cause::None`]).
    pub fn name(self) -> &'static str {
        match self {
            Cause::None => "",
            Cause::Notch => "notch",
            Cause::SecondObstacle => "second_obstacle",
            Cause::PinInsidePart => "pin_inside_part",
            Cause::TravelLimit => "travel_limit",
            Cause::FenceAngle => "fence_angle",
            Cause::GrazingLoop => "grazing_loop",
            Cause::NoConvergence => "no_convergence",
            Cause::NonFinite => "non_finite",
            Cause::EvaluationLimit => "evaluation_limit",
            Cause::EventLimit => "event_limit",
            Cause::StepTooSmall => "step_too_small",
            Cause::SelfCheck => "self_check",
            Cause::Metastable => "metastable",
        }
    }
}

impl std::fmt::Display for Cause {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for Cause {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::Cause;

    const ALL: [Cause; 14] = [
        Cause::None,
        Cause::Notch,
        Cause::SecondObstacle,
        Cause::PinInsidePart,
        Cause::TravelLimit,
        Cause::FenceAngle,
        Cause::GrazingLoop,
        Cause::NoConvergence,
        Cause::NonFinite,
        Cause::EvaluationLimit,
        Cause::EventLimit,
        Cause::StepTooSmall,
        Cause::SelfCheck,
        Cause::Metastable,
    ];

    /// A cause is written as its name, the empty string for none, and no two share a name.
    #[test]
    fn causes_are_written_by_distinct_names() {
        let names: std::collections::BTreeSet<&str> = ALL.iter().map(|c| c.name()).collect();
        assert_eq!(names.len(), ALL.len());
        assert_eq!(serde_json::to_string(&Cause::None).unwrap(), "\"\"");
        for c in ALL {
            assert_eq!(
                serde_json::to_string(&c).unwrap(),
                format!("\"{}\"", c.name())
            );
            assert_eq!(c.to_string(), c.name());
            assert!(c
                .name()
                .chars()
                .all(|ch| ch.is_ascii_lowercase() || ch == '_'));
        }
    }
}
