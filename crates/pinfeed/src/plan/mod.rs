//! Planning pin layouts (thesis ch. 4 "Fixed Pins"): the **sensorless pin planner**.
//!
//! Given a part, a feed (its stable states with jitter and a lateral offset range, or any
//! orientation), the physics (μc, pin radius, optionally a μc range and tripod supports to be
//! robust against) and constraints (belt width, pin spacing, most pins), find a SHORTEST sequence of
//! fixed pins that brings at least a target share of the parts into one orientation window of
//! width 2·tol (or, with `fewest_sets`, into the fewest such windows).
//!
//! * [`problem`]: the inputs, their defaults and checks ([`Problem`]);
//! * [`particles`]: the search state, a weighted set of quantised particles (θ, y, physics
//!   sample), the feed it starts from and the goal measures (best window, number of sets);
//! * [`transition`]: one pin pass over every particle, through the pure contact model
//!   ([`crate::mechanics::push`] from [`crate::maps::pass_start`]), memoised per (physics sample,
//!   θ, y_pin − y) and computed in parallel;
//! * [`actions`]: the actions of a state — pin positions on a fine lateral grid merged into
//!   intervals over which no particle's outcome changes qualitatively, one representative (the
//!   middle) per interval with its robustness margin ([`Action`] is an enum a fence or a sensing
//!   branch can join later);
//! * [`fences`]: the fence planner's actions (`pinfeed plan --fences`): fences at candidate angles
//!   below the jam limit, placed clear of every particle's reach, passes through
//!   [`crate::mechanics::push_fence`]; the same search runs over them;
//! * [`mod@search`]: breadth-first search with deduplication, limits and statistics;
//! * [`certificate`]: a certificate that no line touching only the convex hull can orient a
//!   part whose hull is more symmetric than the part (a hexagon with a small notch), with the
//!   bound it implies;
//! * [`bound`]: its branch and bound — what r more pins can at most bring into one window, from
//!   the pins' lateral reach alone;
//! * [`contingent`]: the contingent planner with sensing (a sensor pin, then per-decision moving
//!   pins; AND-OR over the branches, which must share one goal window);
//! * [`emit`]: the plan as a runnable scenario TOML (and a contingent plan's policy file);
//! * [`check`]: the plan run through the line ([`crate::engine::run`]).
//!
//! ## What "shortest" means here
//!
//! The search is exact over an abstraction, and the claim is exactly that strong:
//! * particles: a finite, seeded set of feed samples (see [`particles::initial_state`]); a plan
//!   reaches the goal for these particles, the line check measures what it does for the real feed;
//! * quantisation: after every pin each particle's orientation is rounded to `theta_quantum_deg`
//!   (default 0.25°) and its lateral offset to `y_quantum_m` (default 0.25 mm); the pin grid has the
//!   same lateral step, so d = (y_pin − y)/a is exact on the grid and pushes recur exactly (memo);
//!   two states are the same state iff their rounded particles coincide;
//! * actions: one representative per interval of the fine pin grid (see [`actions`]), only
//!   intervals with margin ≥ `min_margin_m`.
//!
//! Breadth-first search over these states with deduplication visits every state reachable in k
//! pins before any reachable in k + 1, so the first goal state generated is reached by a plan of the
//! fewest pins among all plans in this action set for this particle set and quantum; "no plan up
//! to depth k" means none of those plans of ≤ k pins reaches the goal (the branch and bound skips
//! only states and pins that provably cannot lead to the goal within k, [`bound`]). A finer quantum or another
//! action set may find a shorter plan; rounding can also make a reported plan slightly optimistic,
//! which the line check measures.

pub mod actions;
pub mod bound;
pub mod certificate;
pub mod check;
pub mod contingent;
pub mod design;
pub mod emit;
pub mod fences;
pub mod margins;
pub mod particles;
pub mod problem;
pub mod search;
pub mod transition;

pub use actions::{Action, PinAction};
pub use fences::{FenceAction, FenceOptions};
pub use particles::{Particle, State};
pub use problem::{FeedKind, Problem};
pub use search::{search, Outcome, Plan, PlanStep, SearchStats};

/// What cut a search or a design short: a limit the problem or the design options set.
#[derive(Debug, Clone, PartialEq)]
pub enum Limit {
    /// The search held [`Problem::max_states`] states.
    States(usize),
    /// The time limit, in seconds ([`Problem::time_limit_s`] or the design's), with what it left
    /// undone when that is known (e.g. `pins not tried`).
    Time {
        /// The limit, in seconds.
        seconds: f64,
        /// What it left undone, in words.
        left_undone: Option<String>,
    },
}

impl Limit {
    /// The setting that sets this limit (`max_states` or `time_limit`), as [`PlanError::field`]
    /// names settings: a command line maps it to its option.
    pub fn field(&self) -> &'static str {
        match self {
            Limit::States(_) => "max_states",
            Limit::Time { .. } => "time_limit",
        }
    }

    /// The time limit of `seconds`, with nothing said of what it left undone.
    pub fn time(seconds: f64) -> Limit {
        Limit::Time {
            seconds,
            left_undone: None,
        }
    }
}

/// A limit is written as its words (`"state limit 1000"`).
impl serde::Serialize for Limit {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl std::fmt::Display for Limit {
    /// `state limit 1000`, `time limit 110 s`, `time limit 110 s: pins not tried`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Limit::States(n) => write!(f, "state limit {n}"),
            Limit::Time {
                seconds,
                left_undone: None,
            } => write!(f, "time limit {seconds} s"),
            Limit::Time {
                seconds,
                left_undone: Some(what),
            } => write!(f, "time limit {seconds} s: {what}"),
        }
    }
}

/// Bad planner input, or a planner that cannot start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// A value out of range; `field` names the quantity (the [`Problem`] or design option it came
    /// from, without its unit suffix: `tolerance`, `pin_radius`, `modes`, …).
    #[error("{field} {value}: {reason}")]
    Input {
        /// The quantity at fault (without its unit suffix).
        field: &'static str,
        /// The value given.
        value: String,
        /// Why it is refused.
        reason: String,
    },
    /// The part could not be built or compiled.
    #[error("part '{part}': {reason}")]
    Part {
        /// The part specification as given.
        part: String,
        /// Why it could not be built.
        reason: String,
    },
}

impl PlanError {
    /// The field an [`PlanError::Input`] names (its message starts with it).
    pub fn field(&self) -> Option<&'static str> {
        match self {
            PlanError::Input { field, .. } => Some(field),
            PlanError::Part { .. } => None,
        }
    }

    pub(crate) fn input(field: &'static str, value: impl ToString, reason: impl ToString) -> Self {
        PlanError::Input {
            field,
            value: value.to_string(),
            reason: reason.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_limit_says_what_it_is_and_names_its_setting() {
        let states = Limit::States(1000);
        assert_eq!(states.to_string(), "state limit 1000");
        assert_eq!(states.field(), "max_states");
        let time = Limit::time(110.0);
        assert_eq!(time.to_string(), "time limit 110 s");
        assert_eq!(time.field(), "time_limit");
        let cut = Limit::Time {
            seconds: 0.5,
            left_undone: Some("fences, sensor not tried".into()),
        };
        assert_eq!(
            cut.to_string(),
            "time limit 0.5 s: fences, sensor not tried"
        );
        // Written as its words.
        assert_eq!(
            serde_json::to_string(&cut).unwrap(),
            "\"time limit 0.5 s: fences, sensor not tried\""
        );
    }
}
