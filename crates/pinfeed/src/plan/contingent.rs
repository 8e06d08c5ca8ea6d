//! The **contingent planner with sensing**: a sensor pin reads which stable
//! state a part arrived in, and each decision gets its own continuation on `k` moving pins.
//!
//! The line: a sensor pin (it pushes like any pin) at `spacing`, then `k` moving pins at
//! `spacing·(j + 2)`; the controller sends every moving pin, per part, to the lateral position its
//! policy gives for the sensor's decision. A branch may use fewer pins: its remaining pins are
//! *parked* at a belt edge, where none of its particles is touched.
//!
//! ## The search (AND-OR over branches)
//!
//! * OR over the sensor's position: the candidates are the pin actions of the feed's state
//!   ([`super::actions`]) at which every particle is touched without failing (a part the sensor
//!   misses gives no reading), most robust (largest margin) first, at most `sensor_candidates`;
//! * AND over the branches: after the sensor, the particles split by their TRUE stable state
//!   (the hypotheses of the sensor's classifier); every branch must reach the SAME goal window;
//! * OR over each branch's continuation: a breadth-first search per (sensor, branch) over the
//!   same quantised particle states and interval actions as the sensorless planner, level by
//!   level. After level k every branch knows, for each window start c, the most particles any of
//!   its plans of ≤ k pins brings into [c, c + 2·tol]; a window is common when the sum over the
//!   branches reaches `target` of all particles.
//!
//! The first k (0, 1, 2, …) at which some sensor position has a common window is the answer: no
//! contingent plan with fewer moving pins exists in this action set for these particles (the
//! same sense of "shortest" as [`super`]). Among the sensor positions that reach it the plan keeps
//! the one with the most particles inside, then the larger sensor margin.
//!
//! The prediction assumes a perfect classifier; the line check runs the real one (F/T sensor,
//! likelihood classifier) and [`ContingentPlan::with_confusion`] folds the measured confusion in:
//! a part decided as d follows d's pins, measured on its own particles ([`ContingentPlan::cross`]).

use super::actions::{Action, PinAction};
use super::particles::{feed_samples, theta_quanta, y_quanta, Particle, State};
use super::problem::FeedKind;
use super::search::Planner;
use super::transition::{FAILED, NO_CONTACT};
use super::{Limit, PlanError};
use serde::Serialize;
use std::collections::HashSet;
use std::sync::Arc;
use std::time::Instant;

/// One branch of a contingent plan: what the moving pins do when the sensor decides `label`.
#[derive(Debug, Clone, Serialize)]
pub struct BranchPlan {
    /// The hypothesis label (`orientation_label` of the stable state).
    pub label: String,
    /// The stable state's orientation (degrees).
    pub stable_deg: f64,
    /// The branch's pin actions, one per moving pin it uses (the rest are parked).
    pub pins: Vec<PinAction>,
    /// Lateral position (m) of every moving pin for this branch (parked ones included).
    pub targets_m: Vec<f64>,
    /// Particles of the branch inside the goal window at the end.
    pub inside: u32,
    /// Particles of the branch.
    pub total: u32,
}

/// A contingent plan.
#[derive(Debug, Clone, Serialize)]
pub struct ContingentPlan {
    /// The sensor pin that reads the stable state.
    pub sensor: PinAction,
    /// Moving pins.
    pub k: usize,
    /// One branch per hypothesis of the sensor, in hypothesis order.
    pub branches: Vec<BranchPlan>,
    /// The goal window's centre (degrees).
    pub centre_deg: f64,
    /// Predicted success with a perfect classifier.
    pub predicted_success: f64,
    /// `cross[b][d]`: share of branch b's particles inside the window when it follows branch d's
    /// pins (a misclassification), d = b on the diagonal.
    pub cross: Vec<Vec<f64>>,
}

impl ContingentPlan {
    /// The prediction with a confusion matrix `counts[true][decided]` (k columns plus a last one
    /// for "unknown", counted as failures), rows in branch order.
    pub fn with_confusion(&self, counts: &[Vec<u64>]) -> f64 {
        let n = self.branches.len();
        let mut total_w = 0.0;
        let mut acc = 0.0;
        for (b, row) in counts.iter().enumerate().take(n) {
            let rt: u64 = row.iter().sum();
            if rt == 0 {
                continue;
            }
            let w = self.branches[b].total as f64;
            total_w += w;
            for (d, &c) in row.iter().enumerate().take(n) {
                acc += w * (c as f64 / rt as f64) * self.cross[b][d];
            }
        }
        if total_w > 0.0 {
            acc / total_w
        } else {
            0.0
        }
    }
}

/// How the contingent search ended.
#[derive(Debug, Clone)]
pub enum ContingentOutcome {
    /// A plan reaching the goal.
    Found(ContingentPlan),
    /// No sensor position and continuations of at most `depth` moving pins reach the goal.
    NoneUpTo {
        /// Most moving pins tried.
        depth: usize,
    },
    /// A limit ended the search after `depth_completed` levels.
    LimitHit {
        /// The limit that ended it.
        limit: Limit,
        /// Levels (moving pins) completed before it.
        depth_completed: usize,
    },
}

/// Statistics of the contingent search.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ContingentStats {
    /// Sensor positions tried.
    pub sensor_candidates: usize,
    /// States kept over every (sensor, branch) search, per level.
    pub states_per_depth: Vec<usize>,
    /// Levels (moving pins) completed.
    pub depth_completed: usize,
    /// Wall time of the search (s).
    pub elapsed_s: f64,
    /// Peak resident memory of the process (bytes; None where it cannot be read).
    pub peak_rss_bytes: Option<u64>,
}

struct Node {
    state: Arc<State>,
    parent: Option<usize>,
    action: Option<PinAction>,
}

/// One branch's breadth-first search after one sensor position.
struct BranchSearch {
    nodes: Vec<Node>,
    seen: HashSet<Arc<State>>,
    frontier: Vec<usize>,
    /// Per window start (θ quanta): the most weight inside over the states so far, and its node.
    best: Vec<(u32, usize)>,
}

/// Weight inside [c, c + width] for every window start c (circular).
fn window_weights(state: &State, width_q: i32, steps: i32) -> Vec<u32> {
    let n = steps as usize;
    let mut h = vec![0u32; n];
    for p in &state.particles {
        h[p.theta_q.rem_euclid(steps) as usize] += p.weight;
    }
    let w = (width_q.max(0) as usize).min(n - 1);
    let mut sum: u32 = (0..=w).map(|i| h[i]).sum();
    let mut out = vec![0u32; n];
    for (c, o) in out.iter_mut().enumerate() {
        *o = sum;
        sum -= h[c];
        sum += h[(c + w + 1) % n];
    }
    out
}

impl BranchSearch {
    fn new(state: State, width_q: i32, steps: i32) -> BranchSearch {
        let ww = window_weights(&state, width_q, steps);
        let root = Arc::new(state);
        let mut seen = HashSet::new();
        seen.insert(root.clone());
        BranchSearch {
            nodes: vec![Node {
                state: root,
                parent: None,
                action: None,
            }],
            seen,
            frontier: vec![0],
            best: ww.into_iter().map(|w| (w, 0)).collect(),
        }
    }

    /// Expand one level; returns the new states.
    fn level(&mut self, planner: &mut Planner, width_q: i32, steps: i32) -> usize {
        let mut next = Vec::new();
        for &id in &self.frontier.clone() {
            let state = self.nodes[id].state.clone();
            for (action, s) in planner.actions(&state) {
                let Action::Pin(a) = action else {
                    unreachable!("the contingent planner uses pins")
                };
                let s = Arc::new(s);
                if !self.seen.insert(s.clone()) {
                    continue;
                }
                let ww = window_weights(&s, width_q, steps);
                self.nodes.push(Node {
                    state: s,
                    parent: Some(id),
                    action: Some(a),
                });
                let nid = self.nodes.len() - 1;
                for (b, w) in self.best.iter_mut().zip(ww) {
                    if w > b.0 {
                        *b = (w, nid);
                    }
                }
                next.push(nid);
            }
        }
        let n = next.len();
        self.frontier = next;
        n
    }

    fn path(&self, leaf: usize) -> Vec<PinAction> {
        let mut out = Vec::new();
        let mut i = leaf;
        while let Some(p) = self.nodes[i].parent {
            out.push(self.nodes[i].action.unwrap());
            i = p;
        }
        out.reverse();
        out
    }
}

/// The feed's particles split by stable state (branch b = stable state b).
pub fn branch_states(planner: &Planner) -> Result<Vec<State>, PlanError> {
    let p = &planner.problem;
    if p.feed != FeedKind::Stable {
        return Err(PlanError::input(
            "feed",
            "uniform",
            "the contingent planner senses the stable state: use a stable feed",
        ));
    }
    let c = &planner.compiled;
    if c.stable_deg.len() < 2 {
        return Err(PlanError::input(
            "sensor",
            c.stable_deg.len(),
            "the part has fewer than two stable states: there is nothing to sense",
        ));
    }
    let per = p.jitter_samples * p.offset_samples;
    let mut out = vec![Vec::new(); c.stable_deg.len()];
    for (i, (t, y)) in feed_samples(p, c)
        .into_iter()
        .take(c.stable_deg.len() * per)
        .enumerate()
    {
        out[i / per].push(Particle {
            sample: planner.transition.sample_of(i),
            theta_q: theta_quanta(t, p.theta_quantum_deg, c.theta_steps),
            y_q: y_quanta(y, p.y_quantum_m),
            weight: 1,
        });
    }
    Ok(out.into_iter().map(|v| State::canonical(v, 0)).collect())
}

/// The sensor pin positions that touch every particle of `root` and fail none, at the problem's
/// `min_margin_m` from the edges of their intervals.
fn touching_sensors(planner: &mut Planner, root: &State) -> Vec<PinAction> {
    let reach = planner.transition.reach_q;
    planner
        .actions(root)
        .into_iter()
        .map(|(a, _)| {
            let Action::Pin(a) = a else {
                unreachable!("the contingent planner uses pins")
            };
            a
        })
        .filter(|a| {
            root.particles.iter().all(|q| {
                let dy = a.y_q - q.y_q;
                dy.abs() <= reach
                    && planner
                        .transition
                        .outcome((q.sample, q.theta_q, dy))
                        .is_some_and(|o| o.signature != NO_CONTACT && o.signature != FAILED)
            })
        })
        .collect()
}

/// Why no sensor pin position serves, with advice only where it helps: a smaller `min_margin`
/// when positions exist at a smaller margin (the largest such margin is named), otherwise the
/// reason, which no margin changes.
fn no_sensor_position(planner: &mut Planner, root: &State) -> PlanError {
    let margin_m = planner.problem.min_margin_m;
    if margin_m > 0.0 {
        planner.problem.min_margin_m = 0.0;
        let at_zero = touching_sensors(planner, root);
        planner.problem.min_margin_m = margin_m;
        if let Some(best) = at_zero.iter().map(|a| a.margin_m).max_by(f64::total_cmp) {
            return PlanError::input(
                "min_margin",
                format!("{} mm", margin_m * 1e3),
                format!(
                    "no sensor pin position touches every part with this margin from a band edge; the widest margin any such position has is {:.3} mm: a min_margin at most that would let the sensor mode search (a design there is that sensitive to the pin's placement)",
                    best * 1e3
                ),
            );
        }
    }
    PlanError::input(
        "sensor",
        "mode",
        "no sensor pin position touches every part in every stable state and lateral offset of the feed, at any margin: one pin cannot read them all (a narrower lateral spread of the feed, or another mode, may serve)",
    )
}

/// Run the contingent search with at most `max_moving` moving pins and at most
/// `sensor_candidates` sensor positions.
pub fn search(
    planner: &mut Planner,
    max_moving: usize,
    sensor_candidates: usize,
) -> Result<(ContingentOutcome, ContingentStats), PlanError> {
    let started = Instant::now();
    let p = planner.problem.clone();
    let steps = planner.compiled.theta_steps;
    let width_q = ((2.0 * p.tolerance_deg / p.theta_quantum_deg) + 1e-9).floor() as i32;
    let branches = branch_states(planner)?;
    let root = planner.initial.clone();
    // Sensor candidates: every particle touched, none failed.
    let mut sensors = touching_sensors(planner, &root);
    sensors.sort_by(|a, b| b.margin_m.total_cmp(&a.margin_m).then(a.y_q.cmp(&b.y_q)));
    sensors.truncate(sensor_candidates.max(1));
    let mut stats = ContingentStats {
        sensor_candidates: sensors.len(),
        ..ContingentStats::default()
    };
    if planner.transition.expired() {
        stats.elapsed_s = started.elapsed().as_secs_f64();
        return Ok((
            ContingentOutcome::LimitHit {
                limit: Limit::time(p.time_limit_s),
                depth_completed: 0,
            },
            stats,
        ));
    }
    if sensors.is_empty() {
        return Err(no_sensor_position(planner, &root));
    }
    let total: u32 = branches.iter().map(|b| b.total()).sum();
    let mut searches: Vec<Vec<BranchSearch>> = sensors
        .iter()
        .map(|s| {
            branches
                .iter()
                .map(|b| BranchSearch::new(planner.transition.apply(b, s.y_q), width_q, steps))
                .collect()
        })
        .collect();
    stats.states_per_depth.push(searches.len() * branches.len());
    let mut kept = 0usize;
    for k in 0..=max_moving {
        if k > 0 {
            let mut new = 0;
            for row in searches.iter_mut() {
                for bs in row.iter_mut() {
                    new += bs.level(planner, width_q, steps);
                    kept += bs.nodes.len();
                    if started.elapsed().as_secs_f64() > p.time_limit_s
                        || planner.transition.expired()
                        || kept >= p.max_states
                    {
                        let limit = if kept >= p.max_states {
                            Limit::States(p.max_states)
                        } else {
                            Limit::time(p.time_limit_s)
                        };
                        stats.elapsed_s = started.elapsed().as_secs_f64();
                        stats.peak_rss_bytes = super::search::peak_rss_bytes();
                        return Ok((
                            ContingentOutcome::LimitHit {
                                limit,
                                depth_completed: k - 1,
                            },
                            stats,
                        ));
                    }
                }
            }
            stats.states_per_depth.push(new);
            stats.depth_completed = k;
        }
        // The best (sensor, window) at this level.
        let mut best: Option<(u32, f64, usize, usize)> = None; // (inside, margin, sensor, c)
                                                               // A goal orientation fixes the window; otherwise any window start.
        let starts: Vec<usize> = match p.goal_deg {
            Some(g) => {
                vec![
                    super::particles::goal_start(g, p.tolerance_deg, p.theta_quantum_deg, steps)
                        as usize,
                ]
            }
            None => (0..steps as usize).collect(),
        };
        for (si, row) in searches.iter().enumerate() {
            for &c in &starts {
                let inside: u32 = row.iter().map(|bs| bs.best[c].0).sum();
                let better = match best {
                    None => true,
                    Some((bi, bm, _, _)) => {
                        inside > bi || (inside == bi && sensors[si].margin_m > bm + 1e-12)
                    }
                };
                if better {
                    best = Some((inside, sensors[si].margin_m, si, c));
                }
            }
        }
        let (inside, _, si, c) = best.expect("at least one sensor");
        if inside as f64 >= p.target * total as f64 - 1e-9 {
            let plan = build(
                planner,
                &branches,
                sensors[si],
                &searches[si],
                c,
                k,
                width_q,
            );
            stats.elapsed_s = started.elapsed().as_secs_f64();
            stats.peak_rss_bytes = super::search::peak_rss_bytes();
            return Ok((ContingentOutcome::Found(plan), stats));
        }
    }
    stats.elapsed_s = started.elapsed().as_secs_f64();
    stats.peak_rss_bytes = super::search::peak_rss_bytes();
    Ok((ContingentOutcome::NoneUpTo { depth: max_moving }, stats))
}

/// Weight of `state` inside the window starting at `c`.
fn inside_at(state: &State, c: usize, width_q: i32, steps: i32) -> u32 {
    state
        .particles
        .iter()
        .filter(|q| ((q.theta_q - c as i32).rem_euclid(steps)) <= width_q)
        .map(|q| q.weight)
        .sum()
}

/// Apply pins at `ys` (quanta) in order, computing missing pushes.
fn run_pins(planner: &mut Planner, state: &State, ys: &[i32]) -> State {
    let reach = planner.transition.reach_q;
    let mut s = state.clone();
    for &y in ys {
        let keys: Vec<_> = s
            .particles
            .iter()
            .filter(|q| (y - q.y_q).abs() <= reach)
            .map(|q| (q.sample, q.theta_q, y - q.y_q))
            .collect();
        planner.transition.ensure(&keys);
        s = planner.transition.apply(&s, y);
    }
    s
}

/// The plan for sensor `sensor`, window start `c` and `k` moving pins: every branch's
/// continuation, parked pins and the cross-branch shares.
fn build(
    planner: &mut Planner,
    branches: &[State],
    sensor: PinAction,
    row: &[BranchSearch],
    c: usize,
    k: usize,
    width_q: i32,
) -> ContingentPlan {
    let p = planner.problem.clone();
    let steps = planner.compiled.theta_steps;
    let q = p.y_quantum_m;
    // Parking: the belt edge (pin inside by its radius) on the side away from the branch's parts.
    let edge = ((p.belt_width_m / 2.0 - p.pin_radius_m) / q).floor() as i32;
    let mut ys_q: Vec<Vec<i32>> = Vec::new();
    let mut pins_of: Vec<Vec<PinAction>> = Vec::new();
    for (b, bs) in row.iter().enumerate() {
        let pins = bs.path(bs.best[c].1);
        let mut ys: Vec<i32> = pins.iter().map(|a| a.y_q).collect();
        if ys.len() < k {
            let after_sensor = run_pins(planner, &branches[b], &[sensor.y_q]);
            let after = run_pins(planner, &after_sensor, &ys);
            let ymax = after.particles.iter().map(|x| x.y_q).max().unwrap_or(0);
            let ymin = after.particles.iter().map(|x| x.y_q).min().unwrap_or(0);
            let park = if edge - ymax >= ymin + edge {
                edge
            } else {
                -edge
            };
            ys.resize(k, park);
        }
        ys_q.push(ys);
        pins_of.push(pins);
    }
    let n = branches.len();
    let mut cross = vec![vec![0.0; n]; n];
    let mut out = Vec::new();
    for b in 0..n {
        let after_sensor = run_pins(planner, &branches[b], &[sensor.y_q]);
        for d in 0..n {
            let end = run_pins(planner, &after_sensor, &ys_q[d]);
            cross[b][d] =
                inside_at(&end, c, width_q, steps) as f64 / branches[b].total().max(1) as f64;
            if d == b {
                out.push(BranchPlan {
                    label: crate::sensing::templates::orientation_label(
                        planner.compiled.stable_deg[b],
                    ),
                    stable_deg: planner.compiled.stable_deg[b],
                    pins: pins_of[b].clone(),
                    targets_m: ys_q[b].iter().map(|&y| y as f64 * q).collect(),
                    inside: inside_at(&end, c, width_q, steps),
                    total: branches[b].total(),
                });
            }
        }
    }
    let inside: u32 = out.iter().map(|b| b.inside).sum();
    let total: u32 = out.iter().map(|b| b.total).sum();
    let centre = (c as f64 + width_q as f64 / 2.0) * p.theta_quantum_deg;
    ContingentPlan {
        sensor,
        k,
        branches: out,
        centre_deg: centre.rem_euclid(steps as f64 * p.theta_quantum_deg),
        predicted_success: inside as f64 / total.max(1) as f64,
        cross,
    }
}

/// The states a contingent plan leads each branch through (for the drawing): per branch, its
/// particles at the feed, after the sensor pin, and after each moving pin at the branch's target
/// (a parked pin touches none of them).
pub fn stage_states(
    planner: &mut Planner,
    plan: &ContingentPlan,
) -> Result<Vec<Vec<State>>, PlanError> {
    let branches = branch_states(planner)?;
    let q = planner.problem.y_quantum_m;
    let mut out = Vec::with_capacity(branches.len());
    for (state, b) in branches.iter().zip(&plan.branches) {
        let mut stages = vec![state.clone(), run_pins(planner, state, &[plan.sensor.y_q])];
        for &y in &b.targets_m {
            let y_q = (y / q).round() as i32;
            let next = run_pins(planner, stages.last().unwrap(), &[y_q]);
            stages.push(next);
        }
        out.push(stages);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(particles: &[(i32, u32)]) -> State {
        State::canonical(
            particles
                .iter()
                .enumerate()
                .map(|(i, &(theta_q, weight))| Particle {
                    sample: 0,
                    theta_q,
                    y_q: i as i32,
                    weight,
                })
                .collect(),
            0,
        )
    }

    #[test]
    fn window_weights_are_the_weights_inside_every_window() {
        // 72 steps around the circle; particles near both ends of it, so windows wrap.
        let s = state(&[(0, 3), (1, 1), (5, 2), (35, 4), (70, 5), (71, 1), (71, 2)]);
        for width in [0, 1, 3, 10, 71, 80] {
            let w = window_weights(&s, width, 72);
            assert_eq!(w.len(), 72);
            for (c, &got) in w.iter().enumerate() {
                let width = width.min(71);
                assert_eq!(got, inside_at(&s, c, width, 72), "width {width}, start {c}");
            }
        }
        // The whole circle holds every particle, a single step only its own.
        assert!(window_weights(&s, 71, 72).iter().all(|&x| x == 18));
        assert_eq!(window_weights(&s, 0, 72)[71], 3);
    }

    fn pin() -> PinAction {
        PinAction {
            y_q: 0,
            y_m: 0.0,
            lo_m: -0.001,
            hi_m: 0.001,
            margin_m: 0.001,
        }
    }

    fn branch(total: u32, inside: u32) -> BranchPlan {
        BranchPlan {
            label: String::new(),
            stable_deg: 0.0,
            pins: vec![pin()],
            targets_m: vec![0.0],
            inside,
            total,
        }
    }

    #[test]
    fn a_confusion_weighs_each_branchs_particles_by_what_they_were_decided() {
        // Branch 0 (30 particles) all inside with its own pins, 40% with branch 1's; branch 1 (10)
        // 90% with its own, none with branch 0's.
        let plan = ContingentPlan {
            sensor: pin(),
            k: 1,
            branches: vec![branch(30, 30), branch(10, 9)],
            centre_deg: 0.0,
            predicted_success: 39.0 / 40.0,
            cross: vec![vec![1.0, 0.4], vec![0.0, 0.9]],
        };
        // A perfect classifier gives the prediction.
        let perfect = plan.with_confusion(&[vec![50, 0, 0], vec![0, 20, 0]]);
        assert!((perfect - plan.predicted_success).abs() < 1e-15);
        // Branch 0 decided as 1 half the time, branch 1 always right.
        let half = plan.with_confusion(&[vec![5, 5, 0], vec![0, 8, 0]]);
        let expect = (30.0 * (0.5 * 1.0 + 0.5 * 0.4) + 10.0 * 0.9) / 40.0;
        assert!((half - expect).abs() < 1e-15, "{half} vs {expect}");
        // "Unknown" (the last column) counts as a failure; a branch never read is left out.
        let unknown = plan.with_confusion(&[vec![1, 0, 1], vec![0, 0, 0]]);
        assert!((unknown - 0.5).abs() < 1e-15, "{unknown}");
        assert_eq!(plan.with_confusion(&[vec![0, 0, 0], vec![0, 0, 0]]), 0.0);
    }
}
