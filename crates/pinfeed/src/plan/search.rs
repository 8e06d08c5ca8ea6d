//! Breadth-first search over particle states, with branch and bound (see the module docs of
//! [`super`] for what the returned plan's "shortest" means).
//!
//! Level k holds the states first reached with k pins; a state seen before (at any level) is not
//! kept again, so every kept state is reached by a shortest action sequence. States of a level are
//! expanded in order (their actions in increasing y), each expansion's pushes in parallel; the goal
//! is tested as states are generated, so the search stops at the first goal state of the shallowest
//! level that has one. Without a goal it ends with "none up to depth k" (every plan of ≤ k pins
//! tried), "exhausted" (no new state worth expanding at some level, and no cut relied on the depth
//! limit: no plan at any depth in this action set), or a limit (`max_states` kept states, `time_limit_s`), reporting the
//! depth it completed.
//!
//! **Bound** ([`super::bound`], on unless `bound` is off, not with `fewest_sets`): a new state that
//! cannot hold more weight in one window than the best state so far within the pins left is not
//! expanded (nor kept, unless it is that best state), and a pin whose passes could not lead to such
//! a state is not taken (its passes are never computed). Neither can hide a goal (which needs more
//! weight than any non-goal state) nor a better best effort (ties go to the shallower plan), so the
//! outcome — plan or best effort — is the one of the full search; only the work changes. The
//! two deepest levels are not stored: each state of the level before the deepest is expanded as
//! soon as it is generated (in the breadth-first order, so the first goal found there is still
//! the breadth-first one, returned once the level is done unless a shallower goal turns up), and a
//! deepest state is kept only as a goal or a new best effort. Memory then holds the levels up to
//! depth − 2; a state repeated in the level before the deepest is expanded again.

use super::actions::{pin_actions, Action, Worth};
use super::bound::{may_exceed, may_exceed_parts, BoundGeometry};
use super::particles::{best_window, initial_state, orientation_sets, Particle, State, Window};
use super::problem::{Compiled, Problem};
use super::transition::{PushCounters, Transition};
use super::{Limit, PlanError};
use serde::Serialize;
use std::collections::HashSet;
use std::sync::Arc;
use std::time::Instant;

/// One pin of a plan and what the particles look like after it.
#[derive(Debug, Clone, Serialize)]
pub struct PlanStep {
    /// The pin (or fence) placed at this step.
    pub action: Action,
    /// The particles after it.
    #[serde(skip)]
    pub state: State,
    /// Best window after this pin.
    pub window: Window,
    /// Orientation sets after this pin (see [`orientation_sets`]; `usize::MAX`, written null,
    /// when the lost particles alone miss the target).
    #[serde(serialize_with = "sets_or_null")]
    pub sets: usize,
}

/// A plan: the pins in belt order and the states they lead through.
#[derive(Debug, Clone, Serialize)]
pub struct Plan {
    /// The feed's particles, before any pin.
    #[serde(skip)]
    pub initial: State,
    /// Best window of the feed.
    pub initial_window: Window,
    /// Orientation sets of the feed (`usize::MAX`, written null, when the lost particles alone miss the target).
    #[serde(serialize_with = "sets_or_null")]
    pub initial_sets: usize,
    /// One step per pin, in belt order.
    pub steps: Vec<PlanStep>,
    /// The goal window (the final best window).
    pub window: Window,
    /// Predicted success: the share of the particles inside the goal window.
    pub predicted_success: f64,
    /// Orientation sets at the end (`usize::MAX`, written null, when none reaches the target).
    #[serde(serialize_with = "sets_or_null")]
    pub sets: usize,
}

/// A count of orientation sets as JSON: null for `usize::MAX` (no count reaches the target).
fn sets_or_null<S: serde::Serializer>(sets: &usize, s: S) -> Result<S::Ok, S::Error> {
    if *sets == usize::MAX {
        s.serialize_none()
    } else {
        s.serialize_u64(*sets as u64)
    }
}

/// How a search ended.
#[derive(Debug, Clone)]
pub enum Outcome {
    /// A shortest plan (with `fewest_sets`: the shortest among those with the fewest sets).
    Found(Plan),
    /// Every plan of at most `depth` pins was tried; none reaches the goal. `best`: the shortest
    /// of the plans that bring the most particles into one window (a best effort, if any pin helps).
    NoneUpTo {
        /// The deepest level tried (pins).
        depth: usize,
        /// The best effort, if any pin helps.
        best: Option<Plan>,
    },
    /// After `depth` pins no new state appeared: no plan exists at any depth in this action set
    /// (`best` as for `NoneUpTo`).
    Exhausted {
        /// The level after which no new state appeared.
        depth: usize,
        /// The best effort, if any pin helps.
        best: Option<Plan>,
    },
    /// A limit ended the search after `depth_completed` full levels (`best`: with `fewest_sets`
    /// the fewest sets so far, otherwise the most particles in one window so far).
    LimitHit {
        /// The limit that ended it.
        limit: Limit,
        /// Levels fully expanded before it.
        depth_completed: usize,
        /// The best plan so far.
        best: Option<Plan>,
    },
}

/// Search statistics.
#[derive(Debug, Clone, Default, Serialize)]
pub struct SearchStats {
    /// Particles of the initial state (before merging).
    pub particles: u32,
    /// Physics samples (μc and support draws) each push is computed for.
    pub physics_samples: usize,
    /// New states per level kept open for expansion (level 0 = the feed); states the bound cut
    /// are counted in `pruned`.
    pub states_per_depth: Vec<usize>,
    /// Levels fully expanded.
    pub depth_completed: usize,
    /// States expanded.
    pub expanded: u64,
    /// Successors generated (before deduplication).
    pub generated: u64,
    /// Successors already seen (dropped).
    pub duplicates: u64,
    /// Actions not taken and new states not expanded because they cannot beat the best effort
    /// within the pins left (branch and bound, [`super::bound`]).
    pub pruned: u64,
    /// Mean actions tried per expansion.
    pub actions_per_expansion: f64,
    /// Contact passes computed, memo hits and the like.
    pub pushes: PushCounters,
    /// Entries of the transition's memo.
    pub memo_entries: usize,
    /// Wall time of the search (s).
    pub elapsed_s: f64,
    /// States' and memo's bytes (estimate).
    pub memory_estimate_bytes: usize,
    /// Peak resident memory of the process (VmHWM, Linux), if readable.
    pub peak_rss_bytes: Option<u64>,
}

/// Peak resident set size of this process (Linux `/proc/self/status` VmHWM).
pub fn peak_rss_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// A planner: the checked problem, the transition with its memo, and the feed's state.
pub struct Planner {
    /// The problem, as given.
    pub problem: Problem,
    /// Its derived data: the part in metres, its stable states and grids.
    pub compiled: Compiled,
    /// The pin transition with its memo of pushes.
    pub transition: Transition,
    /// The feed's particles.
    pub initial: State,
    /// With fences: the fence actions replace the pin actions (or, with `hybrid`, join them).
    pub fences: Option<super::fences::FenceTransition>,
    /// With fences: pins and fences in one action set (a line may mix them).
    pub hybrid: bool,
}

struct Node {
    state: Arc<State>,
    parent: Option<usize>,
    action: Option<Action>,
}

impl Planner {
    /// Check `problem` and build the part, its memo and the feed's particles; Err names the bad field or the part that cannot be built.
    pub fn new(problem: &Problem) -> Result<Planner, PlanError> {
        let compiled = problem.compile()?;
        let n = super::particles::feed_samples(problem, &compiled).len();
        let transition = Transition::new(problem, &compiled, n)?;
        let initial = initial_state(problem, &compiled, |i| transition.sample_of(i));
        Ok(Planner {
            problem: problem.clone(),
            compiled,
            transition,
            initial,
            fences: None,
            hybrid: false,
        })
    }

    /// The actions of a state and their successors.
    pub fn actions(&mut self, state: &State) -> Vec<(Action, State)> {
        self.actions_worth(state, None)
    }

    /// The actions of a state and their successors; pin actions only where `worth` accepts them
    /// (fences: all).
    pub fn actions_worth(&mut self, state: &State, worth: Option<Worth>) -> Vec<(Action, State)> {
        if let Some(f) = self.fences.as_mut() {
            let steps = self.compiled.theta_steps;
            let mut out = f.actions(state, &self.transition, &self.problem, steps);
            if !self.hybrid {
                return out;
            }
            out.extend(pin_actions(
                state,
                &mut self.transition,
                self.problem.min_margin_m,
                worth,
            ));
            return out;
        }
        pin_actions(
            state,
            &mut self.transition,
            self.problem.min_margin_m,
            worth,
        )
    }

    /// The best window of a state.
    pub fn window(&self, state: &State) -> Window {
        let p = &self.problem;
        if let Some(goal) = p.goal_deg {
            return super::particles::window_at(
                state,
                goal,
                p.tolerance_deg,
                p.theta_quantum_deg,
                self.compiled.theta_steps,
            );
        }
        best_window(
            state,
            p.tolerance_deg,
            p.theta_quantum_deg,
            self.compiled.theta_steps,
        )
    }

    /// The number of orientation sets of a state.
    pub fn sets(&self, state: &State) -> usize {
        let p = &self.problem;
        orientation_sets(
            state,
            p.tolerance_deg,
            p.theta_quantum_deg,
            self.compiled.theta_steps,
            p.target,
        )
    }

    /// What the branch-and-bound of [`super::bound`] needs: the pins' reach (none for fences),
    /// the goal window's span and the orientation quanta per period.
    pub fn bound_geometry(&self) -> BoundGeometry {
        let p = &self.problem;
        BoundGeometry {
            reach_q: self.fences.is_none().then_some(self.transition.reach_q),
            width_q: ((2.0 * p.tolerance_deg / p.theta_quantum_deg) + 1e-9).floor() as i32,
            steps: self.compiled.theta_steps,
        }
    }

    /// Does a state reach the goal (one window holding the target share)?
    pub fn is_goal(&self, state: &State) -> bool {
        self.window(state).share >= self.problem.target - 1e-12
    }

    fn plan_to(&self, nodes: &[Node], leaf: usize) -> Plan {
        let mut chain = vec![leaf];
        while let Some(p) = nodes[*chain.last().unwrap()].parent {
            chain.push(p);
        }
        chain.reverse();
        let steps: Vec<PlanStep> = chain[1..]
            .iter()
            .map(|&i| {
                let s = &nodes[i].state;
                PlanStep {
                    action: nodes[i].action.unwrap(),
                    state: (**s).clone(),
                    window: self.window(s),
                    sets: self.sets(s),
                }
            })
            .collect();
        let last = &nodes[leaf].state;
        let window = self.window(last);
        Plan {
            initial: self.initial.clone(),
            initial_window: self.window(&self.initial),
            initial_sets: self.sets(&self.initial),
            steps,
            window,
            predicted_success: window.share,
            sets: self.sets(last),
        }
    }

    /// Run the breadth-first search.
    pub fn search(&mut self) -> (Outcome, SearchStats) {
        let p = self.problem.clone();
        let mut run = Run::new(self);
        if self.fewest_done(&run) || (!p.fewest_sets && self.is_goal(&self.initial)) {
            return (
                Outcome::Found(self.plan_to(&run.nodes, 0)),
                self.finish(run),
            );
        }
        let mut frontier = vec![0usize];
        for depth in 1..=p.max_pins {
            // With the bound, the level before the deepest is expanded as it is generated and
            // neither level is stored (see `Planner::expand_deepest`).
            let eager = p.bound && !p.fewest_sets && depth + 1 == p.max_pins;
            let mut next = Vec::new();
            let mut open = 0usize;
            for &id in &frontier {
                if run.started.elapsed().as_secs_f64() > p.time_limit_s || self.transition.expired()
                {
                    return self.limit(run, Limit::time(p.time_limit_s), depth - 1);
                }
                let state = run.nodes[id].state.clone();
                for (action, s) in self.successors(&mut run, &state, p.max_pins - depth) {
                    match self.admit(&mut run, s, id, action, depth, eager) {
                        Admit::Goal(nid) => {
                            run.stats.states_per_depth.push(open + next.len());
                            return (
                                Outcome::Found(self.plan_to(&run.nodes, nid)),
                                self.finish(run),
                            );
                        }
                        Admit::Open(nid) => next.push(nid),
                        Admit::Eager(s, node) => {
                            open += 1;
                            if run.goal_last.is_none() {
                                self.expand_deepest(&mut run, s, node, (id, action));
                            }
                        }
                        Admit::Closed => {}
                    }
                    if run.nodes.len() >= p.max_states {
                        run.stats.states_per_depth.push(open + next.len());
                        return self.limit(run, Limit::States(p.max_states), depth - 1);
                    }
                }
            }
            run.stats.states_per_depth.push(open + next.len());
            run.stats.depth_completed = depth;
            if eager {
                run.stats.depth_completed = p.max_pins;
                run.stats.states_per_depth.push(0);
                if let Some(goal) = run.goal_last {
                    return (
                        Outcome::Found(self.plan_to(&run.nodes, goal)),
                        self.finish(run),
                    );
                }
            }
            // A level the deadline cut short dropped the successors it could not compute (a goal
            // found before it stands): the search stopped at its limit, it did not exhaust the
            // level.
            if self.transition.expired() {
                return self.limit(run, Limit::time(p.time_limit_s), depth - 1);
            }
            if next.is_empty() {
                return self.no_plan(run, depth, open == 0);
            }
            frontier = next;
        }
        self.no_plan(run, p.max_pins, false)
    }

    /// The successors of `state` worth generating with `left` pins after this one (all of them
    /// without the bound); counts the expansion and the pins the bound refused.
    fn successors(&mut self, run: &mut Run, state: &State, left: usize) -> Vec<(Action, State)> {
        run.stats.expanded += 1;
        if self.problem.fewest_sets || !self.problem.bound {
            return self.actions(state);
        }
        let (bar, geometry) = (run.bar(), self.bound_geometry());
        let refused = std::cell::Cell::new(0u64);
        let worth = |parts: &[Particle], free: u64| {
            let ok = may_exceed_parts(parts, free, left, geometry, bar);
            refused.set(refused.get() + u64::from(!ok));
            ok
        };
        let succ = self.actions_worth(state, Some(&worth));
        run.stats.pruned += refused.get();
        run.depth_bounded |= refused.get() > 0;
        succ
    }

    /// Has `fewest_sets` reached one set?
    fn fewest_done(&self, run: &Run) -> bool {
        self.problem.fewest_sets && run.fewest.0 <= 1
    }

    /// Take a successor generated at `depth` into the search: deduplicate it, test the goal,
    /// update the best so far and decide whether it is expanded (the bound).
    fn admit(
        &self,
        run: &mut Run,
        s: State,
        parent: usize,
        action: Action,
        depth: usize,
        eager: bool,
    ) -> Admit {
        let p = &self.problem;
        run.stats.generated += 1;
        if run.seen.contains(&s) {
            run.stats.duplicates += 1;
            return Admit::Closed;
        }
        if p.fewest_sets {
            let k = self.sets(&s);
            let s = Arc::new(s);
            run.seen.insert(s.clone());
            let nid = run.push(s, parent, action);
            if k < run.fewest.0 {
                run.fewest = (k, nid);
            }
            return if self.fewest_done(run) {
                Admit::Goal(run.fewest.1)
            } else {
                Admit::Open(nid)
            };
        }
        let inside = self.window(&s).inside;
        if self.is_goal(&s) {
            return Admit::Goal(run.push(Arc::new(s), parent, action));
        }
        // Kept as the best effort if it holds the most so far at a stored level (the shallowest
        // wins ties); expanded only if it may beat the best so far within the pins left.
        let improves = inside > run.most.0;
        let bar = run.bar().max(inside);
        let open = !p.bound || may_exceed(&s, p.max_pins - depth, self.bound_geometry(), bar);
        if !open {
            run.stats.pruned += 1;
            // A cut that needed the depth limit (not just the weight already lost).
            run.depth_bounded |= s.live() > bar;
        }
        if !open && !improves {
            return Admit::Closed;
        }
        let s = Arc::new(s);
        if eager && !improves {
            return Admit::Eager(s, None);
        }
        if open && !eager {
            run.seen.insert(s.clone());
        }
        let nid = run.push(s.clone(), parent, action);
        if improves {
            run.most = (inside, nid);
        }
        match (open, eager) {
            (false, _) => Admit::Closed,
            (true, false) => Admit::Open(nid),
            (true, true) => Admit::Eager(s, Some(nid)),
        }
    }

    /// Expand a state of the level before the deepest as soon as it is generated: its successors
    /// (the deepest level) are only tested — the first goal in breadth-first order, or a new most
    /// in one window — and kept only then; so is the state itself (`node`, created on demand
    /// under `via` = (parent, action)). Neither level is stored or deduplicated otherwise: a
    /// repeated state is expanded again, finding nothing new.
    fn expand_deepest(
        &mut self,
        run: &mut Run,
        state: Arc<State>,
        mut node: Option<usize>,
        via: (usize, Action),
    ) {
        for (action, s) in self.successors(run, &state, 0) {
            run.stats.generated += 1;
            let inside = self.window(&s).inside;
            let goal = self.is_goal(&s);
            if !goal && inside <= run.bar() {
                run.stats.pruned += 1;
                continue;
            }
            let pid = *node.get_or_insert_with(|| run.push(state.clone(), via.0, via.1));
            let nid = run.push(Arc::new(s), pid, action);
            if goal {
                run.goal_last = Some(nid);
                return;
            }
            run.most_last = Some((inside, nid));
        }
    }

    /// The search ended without a goal after `depth` levels; `empty`: the last level had no new
    /// state at all.
    fn no_plan(&self, run: Run, depth: usize, empty: bool) -> (Outcome, SearchStats) {
        let p = &self.problem;
        if p.fewest_sets {
            let plan = self.plan_to(&run.nodes, run.fewest.1);
            return (Outcome::Found(plan), self.finish(run));
        }
        let best = self.best_of(&run);
        // The bound refutes plans up to the depth limit only.
        let outcome = if empty && depth < p.max_pins && !run.depth_bounded {
            Outcome::Exhausted {
                depth: depth - 1,
                best,
            }
        } else {
            Outcome::NoneUpTo {
                depth: p.max_pins,
                best,
            }
        };
        (outcome, self.finish(run))
    }

    /// The best plan found so far when none reaches the goal: with `fewest_sets` the one to the
    /// fewest sets, otherwise the shallowest bringing the most particles into one window; none if
    /// no pin improves on the feed.
    fn best_of(&self, run: &Run) -> Option<Plan> {
        let node = if self.problem.fewest_sets {
            run.fewest.1
        } else {
            match run.most_last {
                Some((inside, nid)) if inside > run.most.0 => nid,
                _ => run.most.1,
            }
        };
        (node != 0).then(|| self.plan_to(&run.nodes, node))
    }

    fn limit(&self, mut run: Run, limit: Limit, depth_completed: usize) -> (Outcome, SearchStats) {
        run.stats.depth_completed = depth_completed;
        let best = self.best_of(&run);
        let outcome = Outcome::LimitHit {
            limit,
            depth_completed,
            best,
        };
        (outcome, self.finish(run))
    }

    /// The statistics of a finished run.
    fn finish(&self, run: Run) -> SearchStats {
        let mut stats = run.stats;
        stats.pushes = self.transition.counters;
        stats.memo_entries = self.transition.memo_len();
        if let Some(f) = &self.fences {
            stats.pushes.computed += f.computed;
            stats.memo_entries += f.memo_len();
        }
        stats.elapsed_s = run.started.elapsed().as_secs_f64();
        stats.memory_estimate_bytes = run.bytes + self.transition.memo_bytes();
        stats.peak_rss_bytes = peak_rss_bytes();
        if stats.expanded > 0 {
            stats.actions_per_expansion = stats.generated as f64 / stats.expanded as f64;
        }
        stats
    }
}

/// What [`Planner::admit`] made of a successor.
enum Admit {
    /// A goal (kept as this node).
    Goal(usize),
    /// Kept and to be expanded at the next level.
    Open(usize),
    /// To be expanded now (the level before the deepest); kept as a node only if it is the best
    /// effort so far.
    Eager(Arc<State>, Option<usize>),
    /// A duplicate, or cut by the bound (kept as a node if it is the best effort so far).
    Closed,
}

/// A search in progress: its nodes, the states seen, the best so far and the statistics.
struct Run {
    started: Instant,
    nodes: Vec<Node>,
    seen: HashSet<Arc<State>>,
    stats: SearchStats,
    /// States' bytes (estimate).
    bytes: usize,
    /// With `fewest_sets`: (sets, node) of the fewest so far.
    fewest: (usize, usize),
    /// The most weight in one window so far, (inside, node), among the states of the stored
    /// levels; the first found (the shallowest) wins ties.
    most: (u32, usize),
    /// The same among the deepest level's states when they are evaluated eagerly.
    most_last: Option<(u32, usize)>,
    /// The first goal (breadth-first order) among those.
    goal_last: Option<usize>,
    /// Some cut relied on the depth limit (then an empty level proves "none up to the depth
    /// limit", not "none at any depth").
    depth_bounded: bool,
}

impl Run {
    fn new(planner: &Planner) -> Run {
        let root = Arc::new(planner.initial.clone());
        let mut seen = HashSet::new();
        seen.insert(root.clone());
        let stats = SearchStats {
            particles: planner.initial.total(),
            physics_samples: planner.transition.samples.len(),
            states_per_depth: vec![1],
            ..SearchStats::default()
        };
        Run {
            started: Instant::now(),
            bytes: root.bytes(),
            nodes: vec![Node {
                state: root,
                parent: None,
                action: None,
            }],
            seen,
            stats,
            fewest: (planner.sets(&planner.initial), 0),
            most: (planner.window(&planner.initial).inside, 0),
            most_last: None,
            goal_last: None,
            depth_bounded: false,
        }
    }

    /// The most weight in one window of any state so far: what a state must beat to matter.
    fn bar(&self) -> u32 {
        self.most.0.max(self.most_last.map_or(0, |m| m.0))
    }

    fn push(&mut self, state: Arc<State>, parent: usize, action: Action) -> usize {
        self.bytes += state.bytes() + 64;
        self.nodes.push(Node {
            state,
            parent: Some(parent),
            action: Some(action),
        });
        self.nodes.len() - 1
    }
}

/// Check a problem and run its search.
pub fn search(problem: &Problem) -> Result<(Planner, Outcome, SearchStats), PlanError> {
    let mut planner = Planner::new(problem)?;
    let (outcome, stats) = planner.search();
    Ok((planner, outcome, stats))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plan found for a small problem reaches the target, and no plan one pin shorter does:
    /// the search is breadth first, so what it finds is a shortest plan.
    #[test]
    fn a_found_plan_reaches_the_target_and_is_shortest() {
        let p = Problem::new("square");
        let (_, outcome, _) = search(&p).unwrap();
        let Outcome::Found(plan) = outcome else {
            panic!("no plan for the square: {outcome:?}");
        };
        // The feed alone (jittered stable states) misses the target: the plan needs pins.
        assert!(plan.initial_window.share < p.target);
        assert!(!plan.steps.is_empty());
        let last = plan.steps.last().unwrap();
        assert_eq!(last.window.share, plan.predicted_success);
        assert!(
            plan.predicted_success >= p.target,
            "{}",
            plan.predicted_success
        );
        assert!(plan.steps.len() <= p.max_pins);
        let mut shorter = p.clone();
        shorter.max_pins = plan.steps.len() - 1;
        let (_, again, _) = search(&shorter).unwrap();
        assert!(!matches!(again, Outcome::Found(_)), "{again:?}");
    }

    /// A problem the planner cannot take is refused before any search, naming its field.
    #[test]
    fn a_bad_problem_is_refused_with_its_field() {
        let mut p = Problem::new("square");
        p.target = 1.5;
        let e = search(&p).err().expect("target 1.5 refused");
        assert_eq!(e.field(), Some("target"), "{e}");
    }
}
