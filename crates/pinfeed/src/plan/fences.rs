//! The **fence planner**: the same breadth-first search, each action a fence
//! (SPEC §6) instead of a pin.
//!
//! A fence action is an angle α from a candidate set (±15° … ±60° in 5° steps by default, only
//! |α| + atan μf < 90°, the jam limit) and a lateral placement. For α > 0 the fence runs
//! downstream to the left and slides parts to +y; its upstream end lies `gap` below every
//! particle's reach (y0 = min y − a − gap: no particle can meet the upstream end, each meets the
//! face), its downstream end `gap` above it (y1 = max y + a + gap, plus an optional overhang), so
//! every particle slides along the face and leaves over the downstream end (mirrored for α < 0).
//! Any y0 in [−width/2, min y − a] acts the same way qualitatively (the part meets the face, not
//! the end): that is the action's interval, y0 its representative, `gap` its margin. Both ends
//! must lie over the belt; angles whose fence would not fit are not actions of the state.
//!
//! Each particle's pass is one [`crate::mechanics::push_fence`] from rest, memoised per
//! (physics sample, θ, angle, y0 − y, y1 − y) and computed in parallel. Along the belt the fences
//! follow one another with 2a + 2 cm between one fence's downstream x and the next one's upstream
//! x, so a part touches one obstacle at a time (see [`layout`]).

use super::particles::{theta_quanta, y_quanta, Particle, State};
use super::problem::Problem;
use super::transition::Transition;
use super::Action;
use crate::geometry::{wrap_deg, Pose, Vec2};
use crate::mechanics::{push_fence, ContactSettings, ContactStatus, FenceSpec, Fidelity};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::HashMap;

/// One fence of a plan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FenceAction {
    /// Angle from the belt direction (degrees; > 0 runs downstream to the left).
    pub angle_deg: f64,
    /// Lateral position of the upstream end (m).
    pub y0_m: f64,
    /// Lateral position of the downstream end (m).
    pub y1_m: f64,
    /// Length along the fence (m).
    pub length_m: f64,
    /// Fence–part friction μf.
    pub mu_f: f64,
    /// Lower end of the upstream end's positions that act the same way qualitatively (m).
    pub lo_m: f64,
    /// Upper end of that interval (m).
    pub hi_m: f64,
    /// Distance from `y0_m` to the interval's edge at the parts (m).
    pub margin_m: f64,
    /// Largest lag behind the belt a part takes on this fence (m, belt frame; see [`headway_s`]).
    pub max_lag_m: f64,
}

impl FenceAction {
    /// The fence's extent along the belt (m).
    pub fn x_extent_m(&self) -> f64 {
        self.length_m * self.angle_deg.to_radians().cos()
    }
}

/// Settings of the fence actions.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FenceOptions {
    /// Candidate angles (degrees).
    pub angles_deg: Vec<f64>,
    /// Fence friction μf.
    pub mu_f: f64,
    /// Overhang of the downstream end past the parts' reach, in units of a.
    pub overhang_a: f64,
}

impl FenceOptions {
    /// ±15° … ±60° in 5° steps, kept below the jam limit |α| + atan μf < 90°.
    pub fn default_for(mu_f: f64) -> FenceOptions {
        FenceOptions::grid(mu_f, 5.0, 60.0)
    }

    /// ±15°, ±(15 + step)°, … up to `max_deg`, kept below the jam limit |α| + atan μf < 90°.
    pub fn grid(mu_f: f64, step_deg: f64, max_deg: f64) -> FenceOptions {
        let jam = 90.0 - mu_f.atan().to_degrees();
        let mut angles = Vec::new();
        let mut k = 0;
        loop {
            let a = 15.0 + step_deg * k as f64;
            if a > max_deg + 1e-9 || a >= jam - 1e-9 {
                break;
            }
            angles.push(a);
            angles.push(-a);
            k += 1;
        }
        FenceOptions {
            angles_deg: angles,
            mu_f,
            overhang_a: 0.0,
        }
    }
}

/// Largest integration tolerance of a fence pass (the line's, `[model] tol = 1e-6`).
pub const FENCE_TOL: f64 = 1e-6;

/// Memo key: (sample, θ quanta, angle index, y0 − y quanta, y1 − y quanta).
type FenceKey = (u32, i32, u16, i32, i32);

/// A fence pass as the planner keeps it: `None` = lost (not ok), else (θ final deg, Δy m,
/// touched, lag behind the belt m).
type FenceOutcome = Option<(f64, f64, bool, f64)>;

/// Fence transitions with their memo.
pub struct FenceTransition {
    /// The fence planner's settings.
    pub options: FenceOptions,
    memo: HashMap<FenceKey, FenceOutcome>,
    /// Fence passes computed (memo misses).
    pub computed: u64,
}

impl FenceTransition {
    /// A transition with an empty memo.
    pub fn new(options: FenceOptions) -> FenceTransition {
        FenceTransition {
            options,
            memo: HashMap::new(),
            computed: 0,
        }
    }

    /// Distinct fence passes in the memo.
    pub fn memo_len(&self) -> usize {
        self.memo.len()
    }

    fn pass(&self, tr: &Transition, problem: &Problem, key: FenceKey) -> FenceOutcome {
        let (sample, theta_q, ai, d0, d1) = key;
        let phys = &tr.samples[sample as usize];
        let q = problem.y_quantum_m;
        let a = tr.radius();
        let theta_deg = theta_q as f64 * problem.theta_quantum_deg;
        let angle = self.options.angles_deg[ai as usize].to_radians();
        let e = Vec2::from_angle(angle);
        let mut n = e.perp();
        if n.x > 0.0 {
            n = -n;
        }
        let (y0, y1) = (d0 as f64 * q, d1 as f64 * q);
        // The line 1.01a upstream of the centroid, through the upstream end at lateral y0.
        let x0 = (1.01 * a + y0 * n.y) / (-n.x);
        let length = (y1 - y0).abs() / angle.sin().abs();
        let spec = FenceSpec {
            start: Vec2::new(x0, y0),
            angle_rad: angle,
            length,
            mu_f: phys.mu_f.unwrap_or(self.options.mu_f),
            tail_radius: None,
        };
        let settings = ContactSettings {
            fidelity: Fidelity::Exact,
            mu_c: phys.mu_c,
            // A slide along a fence is a long integration: at the planner's default 1e-5 its
            // end state drifts from the line's (1e-6), so fences use at most the line's tolerance.
            tol: problem.contact_tol.min(FENCE_TOL),
            ..ContactSettings::default()
        };
        let pose = Pose::new(0.0, 0.0, theta_deg.to_radians());
        let out = push_fence(&phys.model, pose, &spec, &settings, None);
        if !out.contact {
            return Some((theta_deg, 0.0, false, 0.0));
        }
        let ok = matches!(
            out.status,
            ContactStatus::Ok | ContactStatus::Metastable { .. }
        );
        if !ok {
            return None;
        }
        Some((
            wrap_deg(theta_deg + out.rotation_rad.to_degrees()),
            out.pose_final.y,
            true,
            (-out.pose_final.x).max(0.0),
        ))
    }

    /// The fence actions of `state` with their successors.
    pub fn actions(
        &mut self,
        state: &State,
        tr: &Transition,
        problem: &Problem,
        theta_steps: i32,
    ) -> Vec<(Action, State)> {
        if state.particles.is_empty() {
            return Vec::new();
        }
        let q = problem.y_quantum_m;
        let a = tr.radius();
        let half = problem.belt_width_m / 2.0;
        let gap = problem.min_margin_m.max(0.001);
        let ymin = state.particles.iter().map(|p| p.y_q).min().unwrap() as f64 * q;
        let ymax = state.particles.iter().map(|p| p.y_q).max().unwrap() as f64 * q;
        let over = self.options.overhang_a * a;
        // (angle index, y0 quanta, y1 quanta, interval lo, hi)
        let mut cands = Vec::new();
        for (ai, &deg) in self.options.angles_deg.iter().enumerate() {
            let (y0, y1, lo, hi) = if deg > 0.0 {
                (
                    (ymin - a - gap) / q,
                    (ymax + a + gap + over) / q,
                    -half,
                    ymin - a,
                )
            } else {
                (
                    (ymax + a + gap) / q,
                    (ymin - a - gap - over) / q,
                    ymax + a,
                    half,
                )
            };
            let (y0q, y1q) = if deg > 0.0 {
                (y0.floor() as i32, y1.ceil() as i32)
            } else {
                (y0.ceil() as i32, y1.floor() as i32)
            };
            let lim = half + 1e-12;
            if (y0q as f64 * q).abs() > lim || (y1q as f64 * q).abs() > lim {
                continue;
            }
            cands.push((ai as u16, y0q, y1q, lo, hi));
        }
        let mut missing: Vec<FenceKey> = Vec::new();
        for &(ai, y0q, y1q, _, _) in &cands {
            for p in &state.particles {
                let k = (p.sample, p.theta_q, ai, y0q - p.y_q, y1q - p.y_q);
                if !self.memo.contains_key(&k) {
                    missing.push(k);
                }
            }
        }
        missing.sort_unstable();
        missing.dedup();
        let this = &*self;
        let out: Vec<FenceOutcome> = missing
            .par_iter()
            .map(|&k| {
                if tr.past_deadline() {
                    None
                } else {
                    this.pass(tr, problem, k)
                }
            })
            .collect();
        if tr.expired() {
            return Vec::new();
        }
        self.computed += out.len() as u64;
        self.memo.extend(missing.into_iter().zip(out));
        let mut res = Vec::new();
        for (ai, y0q, y1q, lo, hi) in cands {
            let mut lost = state.lost;
            let mut parts = Vec::with_capacity(state.particles.len());
            let mut max_lag: f64 = 0.0;
            for p in &state.particles {
                let k = (p.sample, p.theta_q, ai, y0q - p.y_q, y1q - p.y_q);
                match self.memo[&k] {
                    None => lost += p.weight,
                    Some((_, _, false, _)) => parts.push(*p),
                    Some((th, dy, true, lag)) => {
                        max_lag = max_lag.max(lag);
                        let y = p.y_q as f64 * q + dy;
                        if y.abs() > half {
                            lost += p.weight;
                        } else {
                            parts.push(Particle {
                                sample: p.sample,
                                theta_q: theta_quanta(th, problem.theta_quantum_deg, theta_steps),
                                y_q: y_quanta(y, q),
                                weight: p.weight,
                            });
                        }
                    }
                }
            }
            let next = State::canonical(parts, lost);
            if &next == state {
                continue;
            }
            let deg = self.options.angles_deg[ai as usize];
            let (y0, y1) = (y0q as f64 * q, y1q as f64 * q);
            let margin = if deg > 0.0 { hi - y0 } else { y0 - lo };
            res.push((
                Action::Fence(FenceAction {
                    angle_deg: deg,
                    y0_m: y0,
                    y1_m: y1,
                    length_m: (y1 - y0).abs() / deg.to_radians().sin().abs(),
                    mu_f: self.options.mu_f,
                    lo_m: lo,
                    hi_m: hi,
                    margin_m: margin,
                    max_lag_m: max_lag,
                }),
                next,
            ));
        }
        res
    }
}

/// Along-belt gap between one fence's downstream x and the next one's upstream x (m): the part's
/// diameter plus 2 cm, so a part touches one obstacle at a time.
pub fn fence_gap_m(radius_m: f64) -> f64 {
    2.0 * radius_m + 0.02
}

/// The upstream-end x of each fence of a plan (the first one `first_x` along the belt) and the
/// belt length (one gap past the last fence's downstream end).
pub fn layout(fences: &[FenceAction], radius_m: f64, first_x: f64) -> (Vec<f64>, f64) {
    let gap = fence_gap_m(radius_m);
    let mut xs = Vec::new();
    let mut x = first_x;
    for f in fences {
        xs.push(x);
        x += f.x_extent_m() + gap;
    }
    (xs, x)
}

/// Headway (s) of the emitted line at belt speed `speed`: at least 6 s, and long enough that a
/// part lagging the belt by every fence's largest lag stays a diameter plus 2 cm ahead of the next
/// part (a fence near the jam limit holds parts long), rounded up to a whole second.
pub fn headway_s(fences: &[FenceAction], radius_m: f64, speed: f64) -> f64 {
    let lag: f64 = fences.iter().map(|f| f.max_lag_m).sum();
    ((lag + fence_gap_m(radius_m)) / speed).ceil().max(6.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angle_grid_steps_from_15_and_stays_below_the_jam_limit() {
        let g = FenceOptions::grid(0.5, 2.0, 50.0);
        let pos: Vec<f64> = g.angles_deg.iter().copied().filter(|a| *a > 0.0).collect();
        assert_eq!(pos.first(), Some(&15.0));
        assert_eq!(pos.last(), Some(&49.0));
        assert!(pos.windows(2).all(|w| (w[1] - w[0] - 2.0).abs() < 1e-12));
        assert_eq!(g.angles_deg.len(), 2 * pos.len());
        // μf 1: jam limit 45°, so nothing at or above it.
        let j = FenceOptions::grid(1.0, 5.0, 80.0);
        assert!(j.angles_deg.iter().all(|a| a.abs() < 45.0));
        assert_eq!(FenceOptions::default_for(0.5).angles_deg.len(), 20);
    }

    /// A fence pass uses the physics sample's own fence friction when the problem is robust
    /// against it: at 55° a fence jams a part whose μf is at least tan 35° ≈ 0.70, so a sample
    /// drawn from [0.75, 0.8] is lost where the planner's nominal μf 0.5 slides it along.
    #[test]
    fn a_fence_pass_uses_its_samples_fence_friction() {
        let mut p = Problem::new("square");
        p.mu_f_range = Some((0.75, 0.8));
        let compiled = p.compile().unwrap();
        let tr = Transition::new(&p, &compiled, 3).unwrap();
        let mut options = FenceOptions::grid(0.5, 5.0, 60.0);
        options.angles_deg = vec![55.0];
        let ft = FenceTransition::new(options);
        // Upstream end 3a to the right of the part's centroid, downstream end 3a to its left.
        let reach = (3.0 * tr.radius() / p.y_quantum_m).round() as i32;
        let outcome = |sample: u32| ft.pass(&tr, &p, (sample, 0, 0, -reach, reach));
        for k in 0..3 {
            assert!(
                outcome(k).is_none(),
                "sample {k} (μf {:?})",
                tr.samples[k as usize].mu_f
            );
        }
        // The same pass at the nominal μf (a problem without the range) slides the part on.
        let q = Problem::new("square");
        let tq = Transition::new(&q, &compiled, 1).unwrap();
        assert!(ft
            .pass(&tq, &q, (0, 0, 0, -reach, reach))
            .is_some_and(|o| o.2));
    }
}
