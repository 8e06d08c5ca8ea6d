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
}

impl PartOutcome {
    /// Every class, in the order of the summary.
    pub const ALL: [PartOutcome; 7] = [
        PartOutcome::Success,
        PartOutcome::WrongOrientation,
        PartOutcome::Collision,
        PartOutcome::MultiContact,
        PartOutcome::OffBelt,
        PartOutcome::Jam,
        PartOutcome::Solver,
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
}

impl OutcomeCounts {
    /// Count one part of class `o`.
    pub fn add(&mut self, o: PartOutcome) {
        *self.get_mut(o) += 1;
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
        }
    }
    /// All parts counted, over every class.
    pub fn total(&self) -> u64 {
        PartOutcome::ALL.iter().map(|&o| self.get(o)).sum()
    }
}
