//! **A check station and a reject gate after the orienting line** (`pinfeed plan --reject`):
//! does a gauge pin, a gate commanded by its touch and a return path raise the oriented parts
//! delivered per minute at a required purity?
//!
//! 1. The chosen passive line runs under the planning uncertainty — at [`FRICTION_POINTS`]
//!    frictions evenly over its range, pins and fences alike, on the support it was planned for
//!    (random tripods with `--robust`) — and every part's exit is grouped into **states** by its
//!    orientation (sorted exits more than [`STATE_GAP_DEG`] apart start a new state); the parts in
//!    the goal window form the goal state. Each part's lateral extent across the belt comes from
//!    its outline at its exit pose.
//! 2. A plain pin placed beside the parts is touched by exactly those that reach across the line
//!    where its disc begins. It **separates** the goal state when, on one side of the belt, the
//!    goal's parts (their 99th percentile) stay short of every other part measured by at least
//!    [`GAUGE_MARGIN_M`]: the goal state is the narrowest on that side. The pin's disc begins
//!    halfway between. When no side has such a gap the result says why (the widths) instead of
//!    inventing a sensor.
//! 3. The loop: the gauge one fence gap ([`super::super::fences::fence_gap_m`]) past the line's
//!    last obstacle, a `reject_gate` with `reject_on = "contact"` at the belt's end, a return
//!    conveyor of uniform 8–12 s, a buffer of 20 (blocking), at most 10 passes, a merge gap equal
//!    to the open line's headway, and a feed headway that keeps the merge at [`MERGE_LOAD`] of
//!    its capacity given the worst measured yield per pass.
//! 4. **Verification** ([`verify`]): the loop's scenario, built in memory from the text the design
//!    writes, runs at every friction with parts the measurement did not see (another seed), at
//!    least [`MIN_PARTS`] new parts each; the purity over all of them (delivered parts in the goal
//!    over delivered parts) with its 95% Wilson interval decides: **confirmed** when the interval's
//!    lower bound reaches the required purity.

use super::line::{fmt_headway, Line, LineError};
use super::{Candidate, DesignError, DesignOptions, Layout};
use crate::engine::{run, PartOutcome, RunOptions};
use crate::geometry::vec2::Pose;
use crate::scenario::{Obstacle, Scene};
use crate::statistics::wilson_interval;
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// The default required purity of the delivered parts.
pub const DEFAULT_PURITY: f64 = 0.995;
/// The least gap between the goal state's far edge and every other state's (m).
pub const GAUGE_MARGIN_M: f64 = 0.002;
/// Frictions measured and verified over the uncertainty's range.
pub const FRICTION_POINTS: usize = 5;
/// Least new parts per friction, in the measurement and in the verification.
pub const MIN_PARTS: u64 = 1000;
/// The merge's load the feed headway aims at (below 1: saturation).
pub const MERGE_LOAD: f64 = 0.8;
/// Sorted exit orientations more than this apart (degrees) start a new state.
pub const STATE_GAP_DEG: f64 = 5.0;
/// The return conveyor's transit time, uniform between these (s).
pub const TRANSIT_S: (f64, f64) = (8.0, 12.0);
/// Most passes a part makes.
pub const MAX_PASSES: u32 = 10;
/// Parts the buffer before the merge holds (a full buffer blocks the conveyor).
pub const BUFFER: u64 = 20;

/// What `--reject` asks for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RejectOptions {
    /// The required purity of the delivered parts, in (0, 1).
    pub purity: f64,
    /// New parts per friction, in the measurement and the verification (at least [`MIN_PARTS`]).
    pub parts: u64,
}

impl RejectOptions {
    /// `purity` with the parts a design's check asks for: `check_parts` over the frictions, at
    /// least [`MIN_PARTS`].
    pub fn new(purity: f64, check_parts: u64) -> RejectOptions {
        RejectOptions {
            purity,
            parts: (check_parts / FRICTION_POINTS as u64).max(MIN_PARTS),
        }
    }

    /// Refuse a purity outside (0, 1) (the field `purity`).
    pub fn check(&self) -> Result<(), DesignError> {
        if !(self.purity.is_finite() && self.purity > 0.0 && self.purity < 1.0) {
            return Err(super::input(
                "purity",
                self.purity,
                "must lie in (0, 1) (the share of delivered parts in the goal)",
            ));
        }
        Ok(())
    }
}

/// The loop's verdict.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RejectVerdict {
    /// The verification's purity lower bound reaches the required purity.
    Confirmed,
    /// A gauge was placed and the loop run, and its purity falls short.
    NotConfirmed,
    /// No gauge pin tells the goal state from the others (the reason gives the widths).
    NoGauge,
    /// Nothing to add a gate to: no passive design, or no other state to reject.
    NotApplicable,
}

impl RejectVerdict {
    /// As printed: `confirmed`, `not confirmed`, `no gauge`, `not applicable`.
    pub fn word(self) -> &'static str {
        match self {
            RejectVerdict::Confirmed => "confirmed",
            RejectVerdict::NotConfirmed => "not confirmed",
            RejectVerdict::NoGauge => "no gauge",
            RejectVerdict::NotApplicable => "not applicable",
        }
    }
}

/// Which side of the parts the gauge stands on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// +y, to the left looking downstream.
    Left,
    /// −y.
    Right,
}

impl Side {
    /// The signed far edge of a part spanning [lo, hi] across the belt on this side (larger is
    /// farther out).
    fn edge(self, lo: f64, hi: f64) -> f64 {
        match self {
            Side::Left => hi,
            Side::Right => -lo,
        }
    }
}

/// One state the orienting line leaves parts in.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExitState {
    /// Is it the goal (the parts in the goal window)?
    pub goal: bool,
    /// Its median exit orientation (degrees).
    pub orientation_deg: f64,
    /// Parts measured in it (every friction).
    pub parts: u64,
    /// Its share of the parts that left the line.
    pub share: f64,
    /// Median extent across the belt (mm).
    pub width_mm: f64,
    /// Its parts' lower edges across the belt (m): least, median, largest.
    pub low_edge_m: [f64; 3],
    /// Its parts' upper edges across the belt (m): least, median, largest.
    pub high_edge_m: [f64; 3],
}

/// The gauge pin, where it stands and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gauge {
    /// The side of the parts it stands on.
    pub side: Side,
    /// Along the belt (m).
    pub x_m: f64,
    /// Across the belt (m).
    pub y_m: f64,
    /// Its radius (m).
    pub radius_m: f64,
    /// Where its disc begins across the belt (m): a part reaching past it touches the pin.
    pub touch_m: f64,
    /// The goal state's far edge on that side (m; its parts' 99th percentile).
    pub goal_edge_m: f64,
    /// The nearest far edge of any other part measured (m).
    pub other_edge_m: f64,
}

/// The loop around the line.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LoopSettings {
    /// The belt's length with the gauge (m).
    pub belt_length_m: f64,
    /// The belt's width with the gauge (m).
    pub belt_width_m: f64,
    /// The gate's band across the belt: centre and half-width (m).
    pub gate_y_m: f64,
    /// Half-width of the gate's band (m).
    pub gate_reach_m: f64,
    /// Return conveyor transit, uniform (s).
    pub transit_s: (f64, f64),
    /// Buffer before the merge (parts; blocking).
    pub buffer: u64,
    /// Most passes a part makes.
    pub max_passes: u32,
    /// Least time between entries at the merge: the open line's headway (s).
    pub merge_gap_s: f64,
    /// Seconds between new parts.
    pub feed_headway_s: f64,
    /// The worst measured share of a pass that leaves untouched and in the goal (the feed
    /// headway is set from it).
    pub planned_yield: f64,
}

/// The loop run at one friction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrictionRun {
    /// Pins' μc and fences' μf.
    pub mu: f64,
    /// New parts fed.
    pub new_parts: u64,
    /// Parts delivered.
    pub delivered: u64,
    /// Delivered parts in the goal.
    pub in_goal: u64,
    /// Their 95% Wilson interval of the purity.
    pub purity_ci95: [f64; 2],
    /// Passes that ended delivered / passes.
    pub yield_per_pass: f64,
    /// Mean passes per delivered part.
    pub passes_per_delivered: f64,
    /// Delivered parts per minute over the steady window.
    pub delivered_per_min: Option<f64>,
    /// Delivered parts in the goal per minute.
    pub oriented_per_min: Option<f64>,
}

/// The loop verified by running it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verification {
    /// One run per friction.
    pub runs: Vec<FrictionRun>,
    /// Parts delivered in all.
    pub delivered: u64,
    /// Delivered parts in the goal.
    pub in_goal: u64,
    /// in_goal / delivered.
    pub purity: f64,
    /// Its 95% Wilson interval.
    pub purity_ci95: [f64; 2],
    /// Passes that ended delivered / passes, over every run.
    pub yield_per_pass: f64,
    /// Passes per delivered part, over every run.
    pub passes_per_delivered: f64,
    /// Delivered parts per minute, the runs' mean.
    pub delivered_per_min: f64,
    /// Delivered parts in the goal per minute, the runs' mean.
    pub oriented_per_min: f64,
    /// Wall time (s).
    pub elapsed_s: f64,
}

/// What `--reject` found: the states, the gauge, the loop and its verification, beside the open
/// line's numbers.
#[derive(Debug, Clone, Serialize)]
pub struct RejectDesign {
    /// The required purity.
    pub purity_target: f64,
    /// The verdict.
    pub verdict: RejectVerdict,
    /// One sentence: what was found, or why not.
    pub reason: String,
    /// The frictions measured and verified at (pins and fences).
    pub frictions: Vec<f64>,
    /// Did every part rest on a random tripod?
    pub tripod: bool,
    /// New parts per friction.
    pub parts_per_friction: u64,
    /// The states the orienting line leaves parts in, widest share first.
    pub states: Vec<ExitState>,
    /// The gauge, when one separates the goal state.
    pub gauge: Option<Gauge>,
    /// The loop, when a gauge was placed.
    pub settings: Option<LoopSettings>,
    /// The loop run under the uncertainty.
    pub verification: Option<Verification>,
    /// The open line's share in the goal (its verdict check).
    pub open_purity: f64,
    /// The open line's oriented parts per minute.
    pub open_oriented_per_min: f64,
    /// Wall time (s).
    pub elapsed_s: f64,
    /// The open line's scenario at its headway (the loop is written around it).
    #[serde(skip)]
    pub open_toml: String,
    /// The seed of the verification (the measurement's + 1).
    pub seed: u64,
}

/// One part's exit: orientation (degrees), lateral extent [lo, hi] (m), in the goal?
#[derive(Debug, Clone, Copy)]
struct Exit {
    theta_deg: f64,
    lo: f64,
    hi: f64,
    goal: bool,
}

/// The frictions of the uncertainty's range ([`FRICTION_POINTS`] evenly, ends included), or
/// the nominal alone.
fn frictions(o: &DesignOptions) -> Vec<f64> {
    let u = o.uncertainty();
    match u.pins_friction().or(u.fences_friction()) {
        Some((lo, hi)) => (0..FRICTION_POINTS)
            .map(|i| lo + (hi - lo) * i as f64 / (FRICTION_POINTS - 1) as f64)
            .map(|m| (m * 1e6).round() / 1e6)
            .collect(),
        None => vec![o.problem.mu_c],
    }
}

/// `scene` with every pin's μc and every fence's μf set to `mu`.
fn at_friction(scene: &Scene, mu: f64) -> Scene {
    let mut s = scene.clone();
    s.part.mu_c = mu;
    s.contact.mu_c = mu;
    for ob in &mut s.obstacles {
        match ob {
            Obstacle::Pin(p) => p.mu_c = mu,
            Obstacle::Fence(f) => f.mu_f = mu,
        }
    }
    s
}

/// The states of `exits`: grouped by orientation, the goal's parts apart.
fn states(exits: &[Exit]) -> Vec<ExitState> {
    let total = exits.len().max(1) as f64;
    let mut groups: Vec<Vec<Exit>> = Vec::new();
    let goal: Vec<Exit> = exits.iter().copied().filter(|e| e.goal).collect();
    if !goal.is_empty() {
        groups.push(goal);
    }
    let mut others: Vec<Exit> = exits.iter().copied().filter(|e| !e.goal).collect();
    others.sort_by(|a, b| a.theta_deg.total_cmp(&b.theta_deg));
    let mut current: Vec<Exit> = Vec::new();
    let mut rest: Vec<Vec<Exit>> = Vec::new();
    for e in others {
        if current
            .last()
            .is_some_and(|l| e.theta_deg - l.theta_deg > STATE_GAP_DEG)
        {
            rest.push(std::mem::take(&mut current));
        }
        current.push(e);
    }
    if !current.is_empty() {
        rest.push(current);
    }
    // The first and last groups are one state across 0°/360°.
    if rest.len() > 1 {
        let (first, last) = (
            rest[0][0].theta_deg,
            rest[rest.len() - 1].last().unwrap().theta_deg,
        );
        if first + 360.0 - last <= STATE_GAP_DEG {
            let last = rest.pop().unwrap();
            rest[0].splice(0..0, last);
        }
    }
    groups.extend(rest);
    let mut out: Vec<ExitState> = groups
        .iter()
        .map(|g| {
            let spread = |f: &dyn Fn(&Exit) -> f64| {
                let mut v: Vec<f64> = g.iter().map(f).collect();
                v.sort_by(f64::total_cmp);
                [v[0], v[v.len() / 2], v[v.len() - 1]]
            };
            ExitState {
                goal: g[0].goal,
                orientation_deg: spread(&|e| e.theta_deg)[1],
                parts: g.len() as u64,
                share: g.len() as f64 / total,
                width_mm: spread(&|e| e.hi - e.lo)[1] * 1e3,
                low_edge_m: spread(&|e| e.lo),
                high_edge_m: spread(&|e| e.hi),
            }
        })
        .collect();
    out.sort_by(|a, b| b.goal.cmp(&a.goal).then(b.parts.cmp(&a.parts)));
    out
}

/// The gauge's touching line on the better side, or why there is none: the goal's parts (99th
/// percentile of their far edge) must stay [`GAUGE_MARGIN_M`] short of every other part.
fn separate(exits: &[Exit], st: &[ExitState]) -> Result<(Side, f64, f64), String> {
    let widths = || {
        st.iter()
            .map(|s| {
                format!(
                    "{} {:.1} mm at {:.1}°",
                    if s.goal { "goal" } else { "other" },
                    s.width_mm,
                    s.orientation_deg
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut best: Option<(Side, f64, f64)> = None;
    for side in [Side::Left, Side::Right] {
        let mut goal: Vec<f64> = exits
            .iter()
            .filter(|e| e.goal)
            .map(|e| side.edge(e.lo, e.hi))
            .collect();
        goal.sort_by(f64::total_cmp);
        let g = goal[((goal.len() - 1) as f64 * 0.99).round() as usize];
        let other = exits
            .iter()
            .filter(|e| !e.goal)
            .map(|e| side.edge(e.lo, e.hi))
            .fold(f64::INFINITY, f64::min);
        if best.is_none_or(|(_, bg, bo)| other - g > bo - bg) {
            best = Some((side, g, other));
        }
    }
    let (side, g, other) = best.expect("two sides");
    let gap = other - g;
    if gap >= GAUGE_MARGIN_M {
        return Ok((side, g, other));
    }
    let goal = &st[0];
    let narrowest = st.iter().all(|s| s.goal || s.width_mm > goal.width_mm);
    Err(if narrowest {
        format!(
            "no gauge separates the goal state: widths {}; the nearest other part reaches {:.1} mm {} the goal's far edge, {:.1} mm of clearance needed",
            widths(),
            gap.abs() * 1e3,
            if gap < 0.0 { "inside" } else { "beyond" },
            GAUGE_MARGIN_M * 1e3
        )
    } else {
        format!(
            "the goal state is not the narrowest across the belt (widths {}): a pin touches the wider parts, and here they are the goal's; telling it from narrower states needs a sensor, which --reject does not add",
            widths()
        )
    })
}

impl RejectDesign {
    /// The loop's scenario (no header): the open line with the belt lengthened and widened for
    /// the gauge, the feed headway and part count of the loop, the gauge pin, the gate and the
    /// `[recirculation]` table. None without a gauge.
    pub fn loop_toml(&self) -> Option<String> {
        let (g, s) = (self.gauge.as_ref()?, self.settings.as_ref()?);
        let mut out = String::new();
        let mut section = String::new();
        for line in self.open_toml.lines() {
            if line.starts_with('[') {
                section = line.trim().to_string();
            }
            if line.starts_with("[goal]") {
                out += &self.loop_obstacles(g, s);
            }
            let replaced = match (section.as_str(), line.split(" = ").next()) {
                ("[belt]", Some("length")) => {
                    Some(format!("length = {:.4}        # m: with the gauge", s.belt_length_m))
                }
                ("[belt]", Some("width")) => Some(format!("width = {:.3}", s.belt_width_m)),
                ("[feed]", Some("parts")) => Some(format!("parts = {}", self.parts_per_friction)),
                ("[feed]", Some("headway")) => Some(format!(
                    "headway = {}        # s: keeps the merge at {:.0}% of its capacity with the returns",
                    fmt_headway(s.feed_headway_s),
                    MERGE_LOAD * 100.0
                )),
                _ => None,
            };
            out += replaced.as_deref().unwrap_or(line);
            out.push('\n');
        }
        Some(out)
    }

    fn loop_obstacles(&self, g: &Gauge, s: &LoopSettings) -> String {
        format!(
            "[[obstacles]]   # the gauge: parts reaching past y = {touch:.4} m touch it (goal's far edge {ge:.4}, others' {oe:.4})\n\
             kind = \"pin\"\nname = \"gauge\"\nx = {x:.4}\ny = {y:.5}\nradius = {r}\nmu_c = {mu}\n\n\
             [[obstacles]]   # an air jet at the belt's end: rejects every part that touched the gauge\n\
             kind = \"reject_gate\"\nname = \"jet\"\ndecided_by = \"gauge\"\nreject_on = \"contact\"\ny = {gy:.4}\nreach = {gr:.4}\n\n\
             [recirculation]\ntransit = {{ distribution = \"uniform\", min = {t0:?}, max = {t1:?} }}  # s back to the merge\n\
             buffer = {buf}\nwhen_full = \"block\"\nmax_passes = {mp}\nmerge_gap = {mg}      # s: the open line's headway\n\n",
            touch = g.touch_m,
            ge = g.goal_edge_m * side_sign(g.side),
            oe = g.other_edge_m * side_sign(g.side),
            x = g.x_m,
            y = g.y_m,
            r = g.radius_m,
            mu = self.frictions[self.frictions.len() / 2],
            gy = s.gate_y_m,
            gr = s.gate_reach_m,
            t0 = s.transit_s.0,
            t1 = s.transit_s.1,
            buf = s.buffer,
            mp = s.max_passes,
            mg = fmt_headway(s.merge_gap_s),
        )
    }

    /// The header lines of the loop's scenario: what the loop is and what its verification
    /// measured.
    pub fn header_lines(&self) -> Vec<String> {
        let mut l = vec![format!(
            "A closed loop (`--reject`, required purity {}): {}",
            self.purity_target, self.reason
        )];
        if let Some(v) = &self.verification {
            l.push(format!(
                "Verified at μ {} ({} new parts each{}): purity {:.4} (95% CI {:.4}–{:.4}), yield per pass {:.3}, {:.2} passes per delivered part, {:.2} delivered / {:.2} in the goal per minute; the open line {:.2} oriented parts per minute at purity {:.4}.",
                self.frictions.iter().map(|m| format!("{m}")).collect::<Vec<_>>().join(", "),
                self.parts_per_friction,
                if self.tripod { ", random tripods" } else { "" },
                v.purity, v.purity_ci95[0], v.purity_ci95[1], v.yield_per_pass, v.passes_per_delivered,
                v.delivered_per_min, v.oriented_per_min, self.open_oriented_per_min, self.open_purity
            ));
        }
        l.push(String::new());
        l
    }
}

fn side_sign(side: Side) -> f64 {
    match side {
        Side::Left => 1.0,
        Side::Right => -1.0,
    }
}

/// Run the loop of `r` (its gauge and settings as they stand: a test may move the gauge) at each
/// friction of `r.frictions`, `r.parts_per_friction` new parts each, with `r.seed`: its scenario
/// is built in memory from [`RejectDesign::loop_toml`], the text the design writes.
pub fn verify(r: &RejectDesign) -> Result<Verification, DesignError> {
    let started = Instant::now();
    let toml = r
        .loop_toml()
        .ok_or_else(|| super::input("reject", "", "the design has no gauge to verify"))?;
    let draft = crate::scenario::SceneDraft::parse_with_policy(
        std::path::Path::new("design.toml"),
        &toml,
        None,
    )
    .map_err(LineError::from)?;
    let mut scene = draft.build().map_err(LineError::from)?;
    scene.seed = r.seed;
    let runs: Vec<FrictionRun> = r
        .frictions
        .par_iter()
        .map(|&mu| {
            let s = at_friction(&scene, mu);
            let res = run(&s, &RunOptions::from_scene(&s), &mut |_| {}).map_err(LineError::from)?;
            let l = res
                .summary
                .closed_loop
                .expect("the loop scenario has a gate");
            Ok(FrictionRun {
                mu,
                new_parts: l.new_parts,
                delivered: l.fates.delivered(),
                in_goal: l.fates.delivered_ok,
                purity_ci95: l.purity_ci95,
                yield_per_pass: l.yield_per_pass,
                passes_per_delivered: l.passes_per_delivered.mean,
                delivered_per_min: l.delivered_per_min,
                oriented_per_min: l.oriented_per_min,
            })
        })
        .collect::<Result<_, DesignError>>()?;
    let delivered: u64 = runs.iter().map(|r| r.delivered).sum();
    let in_goal: u64 = runs.iter().map(|r| r.in_goal).sum();
    let passes: f64 = runs
        .iter()
        .map(|r| r.passes_per_delivered * r.delivered as f64)
        .sum();
    let all_passes: f64 = runs
        .iter()
        .filter(|r| r.yield_per_pass > 0.0)
        .map(|r| r.delivered as f64 / r.yield_per_pass)
        .sum();
    let mean = |f: &dyn Fn(&FrictionRun) -> Option<f64>| {
        runs.iter().map(|r| f(r).unwrap_or(0.0)).sum::<f64>() / runs.len().max(1) as f64
    };
    Ok(Verification {
        delivered,
        in_goal,
        purity: in_goal as f64 / delivered.max(1) as f64,
        purity_ci95: wilson_interval(in_goal, delivered),
        yield_per_pass: if all_passes > 0.0 {
            delivered as f64 / all_passes
        } else {
            0.0
        },
        passes_per_delivered: passes / delivered.max(1) as f64,
        delivered_per_min: mean(&|r| r.delivered_per_min),
        oriented_per_min: mean(&|r| r.oriented_per_min),
        runs,
        elapsed_s: started.elapsed().as_secs_f64(),
    })
}

/// The exits of the open line at each friction: `parts` parts each with `seed`.
fn measure(
    scene: &Scene,
    mus: &[f64],
    parts: u64,
    seed: u64,
) -> Result<Vec<Vec<Exit>>, DesignError> {
    mus.par_iter()
        .map(|&mu| {
            let s = at_friction(scene, mu);
            let opts = RunOptions {
                parts,
                seed,
                sample_paths: 0,
                keep_records: true,
                online: None,
                stop: None,
            };
            let res = run(&s, &opts, &mut |_| {}).map_err(LineError::from)?;
            let mut out = Vec::new();
            let mut verts = Vec::new();
            for rec in &res.records {
                let goal = match rec.outcome {
                    PartOutcome::Success => true,
                    PartOutcome::WrongOrientation => false,
                    _ => continue,
                };
                let pose = Pose {
                    x: 0.0,
                    y: rec.y_out_m,
                    theta_rad: rec.theta_out_deg.to_radians(),
                };
                s.part.polygon.world_vertices_into(&pose, &mut verts);
                let (lo, hi) = verts
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                        (lo.min(v.y), hi.max(v.y))
                    });
                out.push(Exit {
                    theta_deg: rec.theta_out_deg,
                    lo,
                    hi,
                    goal,
                });
            }
            Ok(out)
        })
        .collect()
}

/// Design and verify the loop around the chosen candidate `c` of a design planned with `o`.
pub fn design_reject(
    o: &DesignOptions,
    c: Option<&Candidate>,
    ro: RejectOptions,
) -> Result<RejectDesign, DesignError> {
    ro.check()?;
    let started = Instant::now();
    let mus = frictions(o);
    let mut r = RejectDesign {
        purity_target: ro.purity,
        verdict: RejectVerdict::NotApplicable,
        reason: String::new(),
        frictions: mus.clone(),
        tripod: o.uncertainty().tripod(),
        parts_per_friction: ro.parts,
        states: Vec::new(),
        gauge: None,
        settings: None,
        verification: None,
        open_purity: 0.0,
        open_oriented_per_min: 0.0,
        elapsed_s: 0.0,
        open_toml: String::new(),
        seed: o.problem.seed.wrapping_add(1),
    };
    let done = |mut r: RejectDesign, verdict, reason: String| {
        r.verdict = verdict;
        r.reason = reason;
        r.elapsed_s = started.elapsed().as_secs_f64();
        Ok(r)
    };
    let Some(c) = c else {
        return done(
            r,
            RejectVerdict::NotApplicable,
            "no orienting design to add a gate to".into(),
        );
    };
    if matches!(c.layout, Layout::Contingent(_)) {
        return done(
            r,
            RejectVerdict::NotApplicable,
            "the chosen line has a sensor pin and moving pins: --reject adds a gauge to a passive line (ask for --pins and/or --fences)".into(),
        );
    }
    r.open_purity = c.measured().map_or(0.0, |m| m.success_rate);
    r.open_oriented_per_min = c.oriented_per_min;
    let headway = if c.headway_s > 0.0 { c.headway_s } else { 4.0 };
    r.open_toml = c.runnable.with_headway(headway);
    let mut line = Line::new(&c.runnable);
    let scene = line.scene(headway)?.clone();
    let per_friction = measure(&scene, &mus, ro.parts, o.problem.seed)?;
    let exits: Vec<Exit> = per_friction.iter().flatten().copied().collect();
    r.states = states(&exits);
    let goal_parts = exits.iter().filter(|e| e.goal).count();
    if goal_parts == 0 {
        return done(
            r,
            RejectVerdict::NotApplicable,
            "the orienting line leaves no measured part in the goal".into(),
        );
    }
    if goal_parts == exits.len() {
        return done(
            r,
            RejectVerdict::NotApplicable,
            format!("every measured part ({}) left the orienting line in the goal: there is nothing for a gate to reject", exits.len()),
        );
    }
    let (side, goal_edge, other_edge) = match separate(&exits, &r.states) {
        Ok(s) => s,
        Err(why) => return done(r, RejectVerdict::NoGauge, why),
    };
    let touch_edge = 0.5 * (goal_edge + other_edge);
    let radius = o.problem.pin_radius_m;
    let sign = side_sign(side);
    let touch_m = sign * touch_edge;
    let y_pin = touch_m + sign * radius;
    // Along the belt: one fence gap past the farthest reach of the line's obstacles.
    let a = scene.part.radius;
    let far_x = scene
        .obstacles
        .iter()
        .map(|ob| {
            let (p, q, rad) = ob.capsule();
            p.x.max(q.x) + rad
        })
        .fold(0.0, f64::max);
    let x_pin = far_x + crate::plan::fences::fence_gap_m(a);
    let belt_length_m = scene.belt.length.max(x_pin + o.problem.spacing_m);
    let ys: Vec<f64> = exits.iter().map(|e| 0.5 * (e.lo + e.hi)).collect();
    let reach_out = exits
        .iter()
        .map(|e| e.lo.abs().max(e.hi.abs()))
        .fold(y_pin.abs() + radius, f64::max);
    let belt_width_m = scene
        .belt
        .width
        .max(((2.0 * reach_out + 0.01) * 100.0).ceil() / 100.0);
    let (ylo, yhi) = ys
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &y| {
            (l.min(y), h.max(y))
        });
    let gate_y_m = 0.5 * (ylo + yhi);
    let gate_reach_m = (0.5 * (yhi - ylo) + a).min(belt_width_m);
    // The worst friction's share of a pass that leaves untouched and in the goal.
    let passing = per_friction
        .iter()
        .map(|ex| {
            let n = ex
                .iter()
                .filter(|e| e.goal && side.edge(e.lo, e.hi) < touch_edge)
                .count();
            n as f64 / ex.len().max(1) as f64
        })
        .fold(1.0, f64::min);
    if passing <= 0.0 {
        return done(
            r,
            RejectVerdict::NoGauge,
            "at some friction no measured part of the goal state passes the gauge".into(),
        );
    }
    let merge_gap_s = headway;
    let q = 1.0 - passing;
    let passes_per_new = (1.0 - q.powi(MAX_PASSES as i32)) / passing.max(1e-9);
    let feed_headway_s = ((merge_gap_s * passes_per_new / MERGE_LOAD) * 10.0).ceil() / 10.0;
    r.gauge = Some(Gauge {
        side,
        x_m: x_pin,
        y_m: y_pin,
        radius_m: radius,
        touch_m,
        goal_edge_m: goal_edge,
        other_edge_m: other_edge,
    });
    r.settings = Some(LoopSettings {
        belt_length_m,
        belt_width_m,
        gate_y_m,
        gate_reach_m,
        transit_s: TRANSIT_S,
        buffer: BUFFER,
        max_passes: MAX_PASSES,
        merge_gap_s,
        feed_headway_s,
        planned_yield: passing,
    });
    let v = verify(&r)?;
    let lower = v.purity_ci95[0];
    let (verdict, reason) = if lower >= ro.purity {
        (
            RejectVerdict::Confirmed,
            format!(
                "a gauge pin {:.1} mm from the goal's far edge and {:.1} mm from the others' rejects every part but the goal state's: purity lower bound {:.4} ≥ {}",
                (touch_edge - goal_edge) * 1e3,
                (other_edge - touch_edge) * 1e3,
                lower,
                ro.purity
            ),
        )
    } else {
        (
            RejectVerdict::NotConfirmed,
            format!(
                "the loop delivers {} parts of which {} in the goal: purity lower bound {:.4} < {}",
                v.delivered, v.in_goal, lower, ro.purity
            ),
        )
    };
    r.verification = Some(v);
    done(r, verdict, reason)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Parts flush on a rail at y = 0 (+y side out): the goal `goal_mm` wide, one other state
    /// `other_mm` wide.
    fn flush(goal_mm: f64, other_mm: f64) -> Vec<Exit> {
        let mut v = Vec::new();
        for k in 0..50 {
            let jitter = k as f64 * 1e-6;
            v.push(Exit {
                theta_deg: 180.0,
                lo: 0.0,
                hi: goal_mm * 1e-3 + jitter,
                goal: true,
            });
            v.push(Exit {
                theta_deg: 45.0,
                lo: 0.0,
                hi: other_mm * 1e-3 + jitter,
                goal: false,
            });
        }
        v
    }

    #[test]
    fn a_gauge_goes_halfway_between_the_goal_s_edge_and_the_others() {
        let e = flush(30.0, 42.4);
        let (side, g, o) = separate(&e, &states(&e)).unwrap();
        assert_eq!(side, Side::Left);
        assert!(
            (g - 0.03).abs() < 1e-4 && (o - 0.0424).abs() < 1e-9,
            "{g} {o}"
        );
    }

    #[test]
    fn widths_too_close_or_a_wider_goal_are_no_gauge_with_the_widths() {
        let e = flush(30.0, 30.4);
        let why = separate(&e, &states(&e)).unwrap_err();
        assert!(
            why.starts_with("no gauge separates the goal state: widths goal 30.0 mm")
                && why.contains("other 30.4 mm"),
            "{why}"
        );
        let e = flush(42.4, 30.0);
        let why = separate(&e, &states(&e)).unwrap_err();
        assert!(why.contains("not the narrowest"), "{why}");
    }

    #[test]
    fn states_across_zero_degrees_are_one() {
        let mk = |t: f64| Exit {
            theta_deg: t,
            lo: 0.0,
            hi: 0.04,
            goal: false,
        };
        let st = states(&[mk(358.5), mk(1.0), mk(2.0), mk(90.0)]);
        assert_eq!(st.len(), 2);
        assert_eq!(st[0].parts, 3);
    }
}
