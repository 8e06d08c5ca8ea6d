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
    /// Radius of the curved tail past the downstream end `y1_m` (m; None: a straight fence).
    pub tail_radius_m: Option<f64>,
}

impl FenceAction {
    /// The fence's extent along the belt (m), its tail included.
    pub fn x_extent_m(&self) -> f64 {
        let alpha = self.angle_deg.to_radians();
        self.length_m * alpha.cos() + self.tail_radius_m.map_or(0.0, |r| r * alpha.sin().abs())
    }

    /// Lateral position of the fence's far end (m): the tail's end, or `y1_m` without a tail.
    pub fn far_y_m(&self) -> f64 {
        self.y1_m + tail_rise(self.angle_deg, self.tail_radius_m.unwrap_or(0.0))
    }
}

/// How far across the belt a tail of radius `radius` turns a fence at `angle_deg` on from its
/// straight end: R (1 − cos α), towards the side the fence slides parts to (docs/physics.md,
/// "Curved tails").
pub fn tail_rise(angle_deg: f64, radius: f64) -> f64 {
    let alpha = angle_deg.to_radians();
    alpha.signum() * radius * (1.0 - alpha.cos())
}

/// The smallest tail the planner tries, in units of a: a smaller one hardly narrows the spread
/// of exit orientations on uneven supports (docs/physics.md, "Curved tails": 2.6° at 4a against
/// 9.6° without a tail for the square on tripods).
pub const TAIL_MIN_A: f64 = 4.0;

/// The largest tail the planner tries by default, in units of a: exits on tripods within 0.5° of
/// parallel (docs/physics.md, "Curved tails": 0.34° at 40a for the square).
pub const TAIL_MAX_A: f64 = 40.0;

/// Settings of the fence actions.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FenceOptions {
    /// Candidate angles (degrees).
    pub angles_deg: Vec<f64>,
    /// Fence friction μf.
    pub mu_f: f64,
    /// Overhang of the downstream end past the parts' reach, in units of a.
    pub overhang_a: f64,
    /// Largest tail radius tried, in units of a (None: straight fences only). Each angle is then
    /// tried straight and with the largest tail up to this radius, and at least [`TAIL_MIN_A`],
    /// that keeps the fence's far end over the belt.
    pub tail_max_a: Option<f64>,
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
            tail_max_a: None,
        }
    }
}

/// Largest integration tolerance of a fence pass (the line's, `[model] tol = 1e-6`).
pub const FENCE_TOL: f64 = 1e-6;

/// Memo key: (sample, θ quanta, angle index, y0 − y quanta, y1 − y quanta, tail radius quanta
/// (0: no tail)).
type FenceKey = (u32, i32, u16, i32, i32, i32);

/// A fence pass as the planner keeps it: `None` = lost (not ok), else (θ final deg, Δy m,
/// touched, lag behind the belt m).
type FenceOutcome = Option<(f64, f64, bool, f64)>;

/// The memo key of particle `p`'s pass by fence `ai` from `y0q` to `y1q` (quanta) with tail
/// `rq`: its sample's fence twin ([`Transition::fence_sample`]), ends relative to the particle.
fn fence_key(tr: &Transition, p: &Particle, ai: u16, y0q: i32, y1q: i32, rq: i32) -> FenceKey {
    (
        tr.fence_sample(p.sample),
        p.theta_q,
        ai,
        y0q - p.y_q,
        y1q - p.y_q,
        rq,
    )
}

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
        let (sample, theta_q, ai, d0, d1, rq) = key;
        let phys = &tr.samples[sample as usize];
        let q = problem.y_quantum_m;
        let a = tr.radius();
        let theta_deg = theta_q as f64 * problem.theta_quantum_deg;
        let nominal = self.options.angles_deg[ai as usize].to_radians();
        let (y0, y1) = (d0 as f64 * q, d1 as f64 * q);
        let length = (y1 - y0).abs() / nominal.sin().abs();
        // The sample's error in the fence's angle turns the fence, its length kept, about its
        // upstream end (as a study's `fence_angle` does): its far end moves across the belt.
        let angle = nominal + phys.fence_angle_deg.to_radians();
        let e = Vec2::from_angle(angle);
        let mut n = e.perp();
        if n.x > 0.0 {
            n = -n;
        }
        // The line 1.01a upstream of the centroid, through the upstream end at lateral y0.
        let x0 = (1.01 * a + y0 * n.y) / (-n.x);
        let spec = FenceSpec {
            start: Vec2::new(x0, y0),
            angle_rad: angle,
            length,
            mu_f: phys.mu_f.unwrap_or(self.options.mu_f),
            tail_radius: (rq > 0).then_some(rq as f64 * q),
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

    /// The tail (radius in quanta of `q`) a fence at `deg` whose straight part ends at the
    /// parts' reach gets: the largest radius up to `tail_max_a`·a whose far end stays over the
    /// belt (|y| ≤ `half`), if that is at least [`TAIL_MIN_A`]·a; None without tails. `y1q` is
    /// the straight fence's downstream end, which lies at least as far out as the tailed one's.
    fn tail_quanta(&self, deg: f64, y1q: i32, a: f64, q: f64, half: f64) -> Option<i32> {
        let most = self.options.tail_max_a? * a;
        // Room from the straight fence's downstream end (overhang included: it is no nearer the
        // parts than the tailed fence's straight end) to the belt's edge, a conservative bound.
        let room = half - (y1q as f64 * q).abs();
        let rise = tail_rise(deg.abs(), 1.0);
        let r = if rise > 0.0 {
            most.min(room / rise)
        } else {
            most
        };
        let rq = (r / q).floor() as i32;
        (rq as f64 * q >= TAIL_MIN_A * a - 1e-12).then_some(rq)
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
        // Planned against an error in the fences' angles, a fence reaches past the parts by as
        // much more as the largest error turns its far end back: L·cos α·δ, with L at least the
        // parts' spread plus their reach both sides.
        let turn = problem
            .fence_angle_range
            .map_or(0.0, |(lo, hi)| lo.abs().max(hi.abs()).to_radians());
        // (angle index, y0 quanta, y1 quanta, tail radius quanta, interval lo, hi)
        let span = ymax - ymin + 2.0 * (a + gap) + over;
        let mut cands = Vec::new();
        for (ai, &deg) in self.options.angles_deg.iter().enumerate() {
            let alpha = deg.to_radians().abs();
            let back = span / alpha.sin() * alpha.cos() * turn;
            let (y0, y1, lo, hi) = if deg > 0.0 {
                (
                    (ymin - a - gap) / q,
                    (ymax + a + gap + over + back) / q,
                    -half,
                    ymin - a,
                )
            } else {
                (
                    (ymax + a + gap) / q,
                    (ymin - a - gap - over - back) / q,
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
            cands.push((ai as u16, y0q, y1q, 0, lo, hi));
            if let Some(rq) = self.tail_quanta(deg, y1q, a, q, half) {
                // The straight part ends where the parts' reach does (no overhang: the tail
                // carries them on), and the tail turns it parallel to the belt.
                let end = if deg > 0.0 {
                    ((ymax + a + gap) / q).ceil() as i32
                } else {
                    ((ymin - a - gap) / q).floor() as i32
                };
                cands.push((ai as u16, y0q, end, rq, lo, hi));
            }
        }
        let mut missing: Vec<FenceKey> = Vec::new();
        for &(ai, y0q, y1q, rq, _, _) in &cands {
            for p in &state.particles {
                let k = fence_key(tr, p, ai, y0q, y1q, rq);
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
        for (ai, y0q, y1q, rq, lo, hi) in cands {
            let mut lost = state.lost;
            let mut parts = Vec::with_capacity(state.particles.len());
            let mut max_lag: f64 = 0.0;
            for p in &state.particles {
                let k = fence_key(tr, p, ai, y0q, y1q, rq);
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
                    tail_radius_m: (rq > 0).then_some(rq as f64 * q),
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
        let outcome = |sample: u32| ft.pass(&tr, &p, (sample, 0, 0, -reach, reach, 0));
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
            .pass(&tq, &q, (0, 0, 0, -reach, reach, 0))
            .is_some_and(|o| o.2));
    }

    /// Every angle gets, besides its straight fence, the largest tail up to the most allowed
    /// whose far end stays over the belt, and none below 4a; the tailed fence's far end is
    /// R (1 − cos α) beyond its straight end, towards the side it slides parts to.
    #[test]
    fn tails_are_the_largest_that_fit_the_belt() {
        let p = Problem::new("square");
        let compiled = p.compile().unwrap();
        let tr = Transition::new(&p, &compiled, 1).unwrap();
        let a = tr.radius();
        let q = p.y_quantum_m;
        let mut options = FenceOptions::grid(0.5, 5.0, 55.0);
        options.tail_max_a = Some(40.0);
        let ft = FenceTransition::new(options.clone());
        for &deg in &options.angles_deg {
            for half in [0.05, 0.1, 0.3, 1.0] {
                // A straight fence whose downstream end lies 1.5a inside the belt's edge.
                let y1q = (deg.signum() * (half - 1.5 * a) / q).round() as i32;
                let rise = 1.0 - deg.to_radians().cos();
                match ft.tail_quanta(deg, y1q, a, q, half) {
                    Some(rq) => {
                        let r = rq as f64 * q;
                        assert!(r >= TAIL_MIN_A * a - 1e-12 && r <= 40.0 * a + 1e-12);
                        let far = y1q as f64 * q + tail_rise(deg, r);
                        assert!(far.abs() <= half + 1e-12, "{deg}° {half}: far end {far}");
                        // The largest: one quantum more would leave the belt or pass 40a.
                        let more = (rq + 1) as f64 * q;
                        assert!(
                            more > 40.0 * a || (y1q as f64 * q + tail_rise(deg, more)).abs() > half
                        );
                    }
                    None => assert!(1.5 * a / rise < TAIL_MIN_A * a, "{deg}° {half}"),
                }
            }
        }
        assert!((tail_rise(-30.0, 2.0) + 2.0 * (1.0 - 30f64.to_radians().cos())).abs() < 1e-15);
        // Without tails, none.
        let straight = FenceTransition::new(FenceOptions::grid(0.5, 5.0, 55.0));
        assert_eq!(straight.tail_quanta(30.0, 0, a, q, 1.0), None);
        // A tailed action's extent along the belt takes in the tail's R sin α.
        let f = FenceAction {
            angle_deg: -30.0,
            y0_m: 0.02,
            y1_m: -0.02,
            length_m: 0.08,
            mu_f: 0.5,
            lo_m: 0.0,
            hi_m: 0.05,
            margin_m: 0.0,
            max_lag_m: 0.0,
            tail_radius_m: Some(0.1),
        };
        let c = 30f64.to_radians().cos();
        assert!((f.x_extent_m() - (0.08 * c + 0.05)).abs() < 1e-12);
        assert!((f.far_y_m() - (-0.02 - 0.1 * (1.0 - c))).abs() < 1e-12);
    }

    /// A tailed fence pass carries the part onto the tail: it leaves further across the belt, and
    /// on a tripod nearer parallel to the belt than off a straight fence's end.
    #[test]
    fn a_tailed_pass_leaves_its_part_parallel_to_the_tail() {
        let mut p = Problem::new("square");
        p.tripod = true;
        let compiled = p.compile().unwrap();
        let tr = Transition::new(&p, &compiled, 8).unwrap();
        let a = tr.radius();
        let mut options = FenceOptions::grid(0.5, 5.0, 60.0);
        options.angles_deg = vec![30.0];
        let ft = FenceTransition::new(options);
        let (r0, r1) = (
            (-1.5 * a / p.y_quantum_m).round() as i32,
            (1.5 * a / p.y_quantum_m).round() as i32,
        );
        let rq = (40.0 * a / p.y_quantum_m).round() as i32;
        // Exit orientations modulo the square's 90°, in [−45°, 45°): the tail's end is parallel
        // to the belt (0°), the straight fence's end at 30°.
        let m = |th: f64| (th + 45.0).rem_euclid(90.0) - 45.0;
        let (mut straight, mut tailed) = (Vec::new(), Vec::new());
        for sample in 0..8 {
            for theta_q in [0, 40, 100, 170, 260, 330] {
                let s = ft.pass(&tr, &p, (sample, theta_q, 0, r0, r1, 0)).unwrap();
                let t = ft.pass(&tr, &p, (sample, theta_q, 0, r0, r1, rq)).unwrap();
                assert!(s.2 && t.2);
                assert!(t.1 > s.1 + 0.5 * 40.0 * a * (1.0 - 30f64.to_radians().cos()));
                straight.push(m(s.0));
                tailed.push(m(t.0));
            }
        }
        let spread = |v: &[f64]| {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (lo, hi)
        };
        let (s_lo, s_hi) = spread(&straight);
        let (t_lo, t_hi) = spread(&tailed);
        assert!(
            t_lo.abs() < 0.5 && t_hi.abs() < 0.5,
            "tailed exits {t_lo}°…{t_hi}° off parallel"
        );
        assert!(
            s_hi - s_lo > 4.0 * (t_hi - t_lo),
            "straight {s_lo}°…{s_hi}°"
        );
    }

    /// Planned against an error δ in the fences' angles, a fence reaches past the parts by
    /// L·cos α·δ more (the error turns its far end back by that much), and a sample's pass is
    /// the fence turned by the sample's error about its upstream end, its length kept, as a
    /// study's `fence_angle` turns it.
    #[test]
    fn an_angle_error_turns_the_fence_about_its_upstream_end() {
        let mut p = Problem::new("tripoly2");
        let compiled = p.compile().unwrap();
        let fence_at = |p: &Problem, deg: f64| {
            let tr = Transition::new(p, &compiled, 150).unwrap();
            let state = crate::plan::particles::initial_state(p, &compiled, |i| tr.sample_of(i));
            let mut ft = FenceTransition::new(FenceOptions::grid(0.5, 5.0, 60.0));
            let acts = ft.actions(&state, &tr, p, compiled.theta_steps);
            acts.into_iter()
                .find_map(|(a, _)| match a {
                    Action::Fence(f) if f.angle_deg == deg && f.tail_radius_m.is_none() => Some(f),
                    _ => None,
                })
                .unwrap()
        };
        let plain = fence_at(&p, 15.0);
        p.fence_angle_range = Some((-0.5, 0.5));
        let turned = fence_at(&p, 15.0);
        assert_eq!(plain.y0_m, turned.y0_m);
        let alpha = 15f64.to_radians();
        let back = (plain.y1_m - plain.y0_m) / alpha.sin() * alpha.cos() * 0.5f64.to_radians();
        let more = turned.y1_m - plain.y1_m;
        assert!(
            (more - back).abs() <= p.y_quantum_m,
            "{more} against {back}"
        );

        // The pass of a sample with an error of +0.5° is the fence at 15.5° from the same
        // upstream end with the 15° fence's length.
        let tr = Transition::new(&p, &compiled, 150).unwrap();
        let k = (0..150u32)
            .find(|&k| tr.samples[k as usize].fence_angle_deg == 0.5)
            .unwrap();
        let mut options = FenceOptions::grid(0.5, 5.0, 60.0);
        options.angles_deg = vec![15.0];
        let ft = FenceTransition::new(options);
        let a = tr.radius();
        let q = p.y_quantum_m;
        let (d0, d1) = ((-1.5 * a / q).round() as i32, (1.5 * a / q).round() as i32);
        let got = ft.pass(&tr, &p, (k, 40, 0, d0, d1, 0)).unwrap();
        let length = (d1 - d0) as f64 * q / alpha.sin();
        let turned = alpha + 0.5f64.to_radians();
        let n = {
            let n = Vec2::from_angle(turned).perp();
            if n.x > 0.0 {
                -n
            } else {
                n
            }
        };
        let y0 = d0 as f64 * q;
        let spec = FenceSpec {
            start: Vec2::new((1.01 * a + y0 * n.y) / (-n.x), y0),
            angle_rad: turned,
            length,
            mu_f: tr.samples[k as usize].mu_f.unwrap_or(0.5),
            tail_radius: None,
        };
        let settings = ContactSettings {
            fidelity: Fidelity::Exact,
            mu_c: tr.samples[k as usize].mu_c,
            tol: p.contact_tol.min(FENCE_TOL),
            ..ContactSettings::default()
        };
        let pose = Pose::new(0.0, 0.0, (40.0 * p.theta_quantum_deg).to_radians());
        let out = push_fence(&tr.samples[k as usize].model, pose, &spec, &settings, None);
        assert!(out.contact);
        assert_eq!(got.1, out.pose_final.y);
        assert_eq!(
            got.0,
            wrap_deg(40.0 * p.theta_quantum_deg + out.rotation_rad.to_degrees())
        );
    }
}
