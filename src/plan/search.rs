//! Breadth-first search over particle states (see the module docs of [`super`] for what the
//! returned plan's "shortest" means).
//!
//! Level k holds the states first reached with k pins; a state seen before (at any level) is not
//! kept again, so every kept state is reached by a shortest action sequence. States of a level are
//! expanded in order (their actions in increasing y), each expansion's pushes in parallel; the goal
//! is tested as states are generated, so the search stops at the first goal state of the shallowest
//! level that has one. Without a goal it ends with "none up to depth k" (every plan of ≤ k pins
//! tried), "exhausted" (no new state at some level: no plan at any depth in this action set), or a
//! limit (`max_states` kept states, `time_limit_s`), reporting the depth it completed.

use super::actions::{pin_actions, Action};
use super::particles::{best_window, initial_state, orientation_sets, State, Window};
use super::problem::{Compiled, Problem};
use super::transition::{PushCounters, Transition};
use super::PlanError;
use serde::Serialize;
use std::collections::HashSet;
use std::sync::Arc;
use std::time::Instant;

/// One pin of a plan and what the particles look like after it.
#[derive(Debug, Clone, Serialize)]
pub struct PlanStep {
    pub action: Action,
    #[serde(skip)]
    pub state: State,
    /// Best window after this pin.
    pub window: Window,
    /// Orientation sets after this pin (see [`orientation_sets`]).
    pub sets: usize,
}

/// A plan: the pins in belt order and the states they lead through.
#[derive(Debug, Clone, Serialize)]
pub struct Plan {
    #[serde(skip)]
    pub initial: State,
    pub initial_window: Window,
    pub initial_sets: usize,
    pub steps: Vec<PlanStep>,
    /// The goal window (the final best window).
    pub window: Window,
    /// Predicted success: the share of the particles inside the goal window.
    pub predicted_success: f64,
    pub sets: usize,
}

/// How a search ended.
#[derive(Debug, Clone)]
pub enum Outcome {
    /// A shortest plan (with `fewest_sets`: the shortest among those with the fewest sets).
    Found(Plan),
    /// Every plan of at most `depth` pins was tried; none reaches the goal. `best`: the shortest
    /// of the plans that bring the most particles into one window (a best effort, if any pin helps).
    NoneUpTo { depth: usize, best: Option<Plan> },
    /// After `depth` pins no new state appeared: no plan exists at any depth in this action set
    /// (`best` as for `NoneUpTo`).
    Exhausted { depth: usize, best: Option<Plan> },
    /// A limit ended the search after `depth_completed` full levels (`best`: with `fewest_sets`
    /// the fewest sets so far, otherwise the most particles in one window so far).
    LimitHit {
        limit: String,
        depth_completed: usize,
        best: Option<Plan>,
    },
}

/// Search statistics.
#[derive(Debug, Clone, Default, Serialize)]
pub struct SearchStats {
    /// Particles of the initial state (before merging) and physics samples.
    pub particles: u32,
    pub physics_samples: usize,
    /// New states per level (level 0 = the feed).
    pub states_per_depth: Vec<usize>,
    /// Levels fully expanded.
    pub depth_completed: usize,
    pub expanded: u64,
    /// Successors generated (before deduplication) and those already seen.
    pub generated: u64,
    pub duplicates: u64,
    pub actions_per_expansion: f64,
    pub pushes: PushCounters,
    pub memo_entries: usize,
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
    pub problem: Problem,
    pub compiled: Compiled,
    pub transition: Transition,
    pub initial: State,
    /// With fences: the fence actions replace the pin actions.
    pub fences: Option<super::fences::FenceTransition>,
}

struct Node {
    state: Arc<State>,
    parent: Option<usize>,
    action: Option<Action>,
}

impl Planner {
    pub fn new(problem: &Problem) -> Result<Planner, PlanError> {
        let compiled = problem.compile()?;
        let n = super::particles::feed_samples(problem, &compiled).len();
        let robust = problem.tripod || problem.mu_c_range.is_some();
        let transition = Transition::new(problem, &compiled, n)?;
        let initial = initial_state(problem, &compiled, robust);
        Ok(Planner {
            problem: problem.clone(),
            compiled,
            transition,
            initial,
            fences: None,
        })
    }

    /// The actions of a state and their successors.
    pub fn actions(&mut self, state: &State) -> Vec<(Action, State)> {
        if let Some(f) = self.fences.as_mut() {
            let steps = self.compiled.theta_steps;
            return f.actions(state, &self.transition, &self.problem, steps);
        }
        pin_actions(state, &mut self.transition, self.problem.min_margin_m)
    }

    /// The best window of a state.
    pub fn window(&self, state: &State) -> Window {
        let p = &self.problem;
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
        let started = Instant::now();
        let p = self.problem.clone();
        let mut stats = SearchStats {
            particles: self.initial.total(),
            physics_samples: self.transition.samples.len(),
            ..SearchStats::default()
        };
        let root = Arc::new(self.initial.clone());
        let mut nodes = vec![Node {
            state: root.clone(),
            parent: None,
            action: None,
        }];
        let mut seen: HashSet<Arc<State>> = HashSet::new();
        seen.insert(root);
        stats.states_per_depth.push(1);
        let mut state_bytes = self.initial.bytes();
        // Best so far: for `fewest_sets` (sets, node), otherwise the most particles in one window
        // (inside, node); the first found (the shallowest) wins ties.
        let mut best: (usize, usize) = (self.sets(&self.initial), 0);
        let mut most: (u32, usize) = (self.window(&self.initial).inside, 0);
        let done = |s: &Self, st: &State, best_sets: usize| -> bool {
            if p.fewest_sets {
                best_sets <= 1
            } else {
                s.is_goal(st)
            }
        };
        let finish = |s: &Self, mut stats: SearchStats, bytes: usize| {
            stats.pushes = s.transition.counters;
            stats.memo_entries = s.transition.memo_len();
            if let Some(f) = &s.fences {
                stats.pushes.computed += f.computed;
                stats.memo_entries += f.memo_len();
            }
            stats.elapsed_s = started.elapsed().as_secs_f64();
            stats.memory_estimate_bytes = bytes + s.transition.memo_bytes();
            stats.peak_rss_bytes = peak_rss_bytes();
            if stats.expanded > 0 {
                stats.actions_per_expansion = stats.generated as f64 / stats.expanded as f64;
            }
            stats
        };
        if done(self, &self.initial, best.0) {
            let plan = self.plan_to(&nodes, 0);
            return (Outcome::Found(plan), finish(self, stats, state_bytes));
        }
        let mut frontier = vec![0usize];
        for depth in 1..=p.max_pins {
            let mut next = Vec::new();
            for &id in &frontier {
                if started.elapsed().as_secs_f64() > p.time_limit_s {
                    let limit = format!("time limit {} s", p.time_limit_s);
                    let best = self.best_of(&nodes, best, most);
                    return self.limit(limit, depth - 1, best, stats, finish, state_bytes);
                }
                let state = nodes[id].state.clone();
                let succ = self.actions(&state);
                stats.expanded += 1;
                for (action, s) in succ {
                    stats.generated += 1;
                    let s = Arc::new(s);
                    if !seen.insert(s.clone()) {
                        stats.duplicates += 1;
                        continue;
                    }
                    state_bytes += s.bytes() + 64;
                    nodes.push(Node {
                        state: s.clone(),
                        parent: Some(id),
                        action: Some(action),
                    });
                    let nid = nodes.len() - 1;
                    next.push(nid);
                    if p.fewest_sets {
                        let k = self.sets(&s);
                        if k < best.0 {
                            best = (k, nid);
                        }
                    } else {
                        let inside = self.window(&s).inside;
                        if inside > most.0 {
                            most = (inside, nid);
                        }
                    }
                    if done(self, &s, best.0) {
                        stats.states_per_depth.push(next.len());
                        let plan = self.plan_to(&nodes, if p.fewest_sets { best.1 } else { nid });
                        return (Outcome::Found(plan), finish(self, stats, state_bytes));
                    }
                    if nodes.len() >= p.max_states {
                        stats.states_per_depth.push(next.len());
                        let limit = format!("state limit {} (--max-states)", p.max_states);
                        let best = self.best_of(&nodes, best, most);
                        return self.limit(limit, depth - 1, best, stats, finish, state_bytes);
                    }
                }
            }
            stats.states_per_depth.push(next.len());
            stats.depth_completed = depth;
            if next.is_empty() {
                let stats = finish(self, stats, state_bytes);
                if p.fewest_sets {
                    return (Outcome::Found(self.plan_to(&nodes, best.1)), stats);
                }
                let best = self.best_of(&nodes, best, most);
                return (
                    Outcome::Exhausted {
                        depth: depth - 1,
                        best,
                    },
                    stats,
                );
            }
            frontier = next;
        }
        let stats = finish(self, stats, state_bytes);
        if p.fewest_sets {
            return (Outcome::Found(self.plan_to(&nodes, best.1)), stats);
        }
        let best = self.best_of(&nodes, best, most);
        (
            Outcome::NoneUpTo {
                depth: p.max_pins,
                best,
            },
            stats,
        )
    }

    /// The best plan found so far when none reaches the goal: with `fewest_sets` the one to the
    /// fewest sets, otherwise the one bringing the most particles into one window; none if no pin
    /// improves on the feed.
    fn best_of(&self, nodes: &[Node], sets: (usize, usize), most: (u32, usize)) -> Option<Plan> {
        let node = if self.problem.fewest_sets {
            sets.1
        } else {
            most.1
        };
        (node != 0).then(|| self.plan_to(nodes, node))
    }

    fn limit(
        &self,
        limit: String,
        depth_completed: usize,
        best: Option<Plan>,
        mut stats: SearchStats,
        finish: impl Fn(&Self, SearchStats, usize) -> SearchStats,
        bytes: usize,
    ) -> (Outcome, SearchStats) {
        stats.depth_completed = depth_completed;
        (
            Outcome::LimitHit {
                limit,
                depth_completed,
                best,
            },
            finish(self, stats, bytes),
        )
    }
}

/// Check a problem and run its search.
pub fn search(problem: &Problem) -> Result<(Planner, Outcome, SearchStats), PlanError> {
    let mut planner = Planner::new(problem)?;
    let (outcome, stats) = planner.search();
    Ok((planner, outcome, stats))
}
