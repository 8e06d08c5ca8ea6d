//! The search state: a weighted set of quantised particles, the feed it starts from, and the goal
//! measures (best orientation window, number of orientation sets).
//!
//! A particle is a feed sample: orientation θ (in quanta of `theta_quantum_deg`, wrapped to the
//! part's symmetry period — 360° / its rotational symmetry order, so 90° for a square), lateral offset y of the centroid (in quanta of `y_quantum_m`, belt frame, SPEC §1) and the
//! index of its physics sample (0 for all particles unless the problem asks for robustness against
//! a μc range or tripod supports, when every feed sample carries its own). Particles that coincide
//! after rounding are merged and their weights added; the state is sorted, so equal sets of
//! particles are equal states (the deduplication key). A particle whose push failed (a non-ok
//! contact status) or whose centroid left the belt is *lost*: it only adds to `lost`.
//!
//! ## The feed's particles ([`initial_state`])
//!
//! * stable feed: for each stable state, `jitter_samples` orientations at stratified normal
//!   quantiles θs + σ·Φ⁻¹((k + u_k)/n) times `offset_samples` offsets at stratified uniform
//!   quantiles −L + 2L·(m + v_m)/n, with u, v drawn from the seed (default 5 × 5 = 25 per state:
//!   75 particles for a triangle, 100 for a square);
//! * uniform feed: `orientation_samples` orientations 360°·(k + u_k)/n times the offsets.
//!
//! Every stable state gets the same number of particles (equal weights).

use super::problem::{Compiled, FeedKind, Problem};
use rand::RngExt;

/// One (merged) particle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Particle {
    /// Physics sample (index into the transition's samples).
    pub sample: u32,
    /// Orientation in quanta, in [0, period/quantum) (period = 360° / the part's symmetry order).
    pub theta_q: i32,
    /// Centroid's lateral offset in quanta (belt frame).
    pub y_q: i32,
    /// How many feed samples this particle stands for.
    pub weight: u32,
}

/// A search state: sorted, merged particles and the weight lost so far.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct State {
    /// The particles, sorted and merged (equal ones add their weights).
    pub particles: Vec<Particle>,
    /// Weight of the particles lost so far (a failed pass, or pushed off the belt).
    pub lost: u32,
}

impl State {
    /// Sort and merge coinciding particles.
    pub fn canonical(mut particles: Vec<Particle>, lost: u32) -> State {
        particles.sort_unstable();
        let mut out: Vec<Particle> = Vec::with_capacity(particles.len());
        for p in particles {
            match out.last_mut() {
                Some(q) if (q.sample, q.theta_q, q.y_q) == (p.sample, p.theta_q, p.y_q) => {
                    q.weight += p.weight
                }
                _ => out.push(p),
            }
        }
        State {
            particles: out,
            lost,
        }
    }

    /// Total weight (particles and lost).
    pub fn total(&self) -> u32 {
        self.lost + self.particles.iter().map(|p| p.weight).sum::<u32>()
    }

    /// Weight not lost.
    pub fn live(&self) -> u32 {
        self.particles.iter().map(|p| p.weight).sum()
    }

    /// Bytes held by this state (for the memory estimate).
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<State>() + self.particles.capacity() * std::mem::size_of::<Particle>()
    }
}

/// The best orientation window of a state.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Window {
    /// Centre (degrees, [0, period)): the middle of the particles inside.
    pub centre_deg: f64,
    /// Weight inside.
    pub inside: u32,
    /// inside / total (lost parts count against it).
    pub share: f64,
}

/// Inverse of the standard normal CDF (now [`crate::statistics::normal_quantile`], re-exported
/// here where the planner's particles first needed it).
pub use crate::statistics::normal_quantile;

/// Stream index of the feed's stratification draws (the physics samples use their own).
const FEED_STREAM: u64 = 0x706c_616e;

/// The feed's particles as (θ degrees, y metres), before rounding, in feed order.
pub fn feed_samples(problem: &Problem, compiled: &Compiled) -> Vec<(f64, f64)> {
    let mut rng = crate::random::stream(problem.seed, FEED_STREAM);
    let no = problem.offset_samples;
    let l = problem.lateral_m;
    let offsets: Vec<f64> = (0..no)
        .map(|m| -l + 2.0 * l * (m as f64 + rng.random::<f64>()) / no as f64)
        .collect();
    let mut thetas = Vec::new();
    match problem.feed {
        FeedKind::Stable => {
            let nj = problem.jitter_samples;
            for &s in &compiled.stable_deg {
                for k in 0..nj {
                    let p = (k as f64 + rng.random::<f64>()) / nj as f64;
                    thetas.push(s + problem.jitter_deg * normal_quantile(p));
                }
            }
        }
        FeedKind::Uniform => {
            let n = problem.orientation_samples;
            for k in 0..n {
                thetas.push(360.0 * (k as f64 + rng.random::<f64>()) / n as f64);
            }
        }
    }
    let mut out = Vec::with_capacity(thetas.len() * no + problem.extra_samples.len());
    for &t in &thetas {
        for &y in &offsets {
            out.push((t, y));
        }
    }
    out.extend(problem.extra_samples.iter().copied());
    out
}

/// Round an orientation (degrees) to quanta in [0, steps).
pub fn theta_quanta(theta_deg: f64, quantum_deg: f64, steps: i32) -> i32 {
    ((theta_deg / quantum_deg).round() as i64).rem_euclid(steps as i64) as i32
}

/// Round a lateral offset (m) to quanta.
pub fn y_quanta(y: f64, quantum: f64) -> i32 {
    (y / quantum).round() as i32
}

/// The initial state: the feed's particles, rounded; feed sample i carries physics sample
/// `sample_of(i)` ([`super::transition::Transition::sample_of`]).
pub fn initial_state(
    problem: &Problem,
    compiled: &Compiled,
    sample_of: impl Fn(usize) -> u32,
) -> State {
    let parts = feed_samples(problem, compiled)
        .into_iter()
        .enumerate()
        .map(|(i, (t, y))| Particle {
            sample: sample_of(i),
            theta_q: theta_quanta(t, problem.theta_quantum_deg, compiled.theta_steps),
            y_q: y_quanta(y, problem.y_quantum_m),
            weight: 1,
        })
        .collect();
    State::canonical(parts, 0)
}

/// Weight per orientation quantum, sorted by quantum.
fn histogram(particles: &[Particle]) -> Vec<(i32, u32)> {
    let mut h: Vec<(i32, u32)> = particles.iter().map(|p| (p.theta_q, p.weight)).collect();
    h.sort_unstable();
    let mut out: Vec<(i32, u32)> = Vec::with_capacity(h.len());
    for (t, w) in h {
        match out.last_mut() {
            Some(last) if last.0 == t => last.1 += w,
            _ => out.push((t, w)),
        }
    }
    out
}

/// The window of at most `width_q` quanta (inclusive span) holding the most weight of `hist`
/// (circular); ties go to the smallest start. Returns (start, end, weight) in quanta.
fn best_span(hist: &[(i32, u32)], width_q: i32, steps: i32) -> Option<(i32, i32, u32)> {
    let n = hist.len();
    if n == 0 {
        return None;
    }
    let mut best: Option<(i32, i32, u32)> = None;
    let mut j = 0usize; // number of entries after i (circularly) inside the window
    let mut sum: u64 = 0;
    for i in 0..n {
        if i > 0 {
            sum -= hist[i - 1].1 as u64;
            j = j.saturating_sub(1);
        }
        if j == 0 {
            sum = hist[i].1 as u64;
            j = 1;
        }
        while j < n {
            let k = (i + j) % n;
            let gap = (hist[k].0 - hist[i].0).rem_euclid(steps);
            if gap > width_q {
                break;
            }
            sum += hist[k].1 as u64;
            j += 1;
        }
        let end = hist[(i + j - 1) % n].0;
        if best.is_none_or(|b| sum as u32 > b.2) {
            best = Some((hist[i].0, end, sum as u32));
        }
    }
    best
}

/// The best window of half-width `tol_deg` (quantum `q_deg`, `steps` quanta per turn).
pub fn best_window(state: &State, tol_deg: f64, q_deg: f64, steps: i32) -> Window {
    let total = state.total().max(1);
    let width_q = ((2.0 * tol_deg / q_deg) + 1e-9).floor() as i32;
    match best_span(&histogram(&state.particles), width_q, steps) {
        None => Window {
            centre_deg: 0.0,
            inside: 0,
            share: 0.0,
        },
        Some((a, b, w)) => {
            let span = (b - a).rem_euclid(steps);
            let centre = (a as f64 + span as f64 / 2.0) * q_deg;
            Window {
                centre_deg: centre.rem_euclid(steps as f64 * q_deg),
                inside: w,
                share: w as f64 / total as f64,
            }
        }
    }
}

/// The window of half-width `tol_deg` centred at `centre_deg` (taken modulo the period of `steps`
/// quanta of `q_deg`): a goal orientation the user chose. Its start is the quantum nearest to
/// `centre − tol`, so it holds the same quanta a window [`best_window`] finds there would.
pub fn window_at(state: &State, centre_deg: f64, tol_deg: f64, q_deg: f64, steps: i32) -> Window {
    let total = state.total().max(1);
    let width_q = ((2.0 * tol_deg / q_deg) + 1e-9).floor() as i32;
    let start = goal_start(centre_deg, tol_deg, q_deg, steps);
    let inside: u32 = state
        .particles
        .iter()
        .filter(|p| (p.theta_q - start).rem_euclid(steps) <= width_q)
        .map(|p| p.weight)
        .sum();
    Window {
        centre_deg: ((start as f64 + width_q as f64 / 2.0) * q_deg)
            .rem_euclid(steps as f64 * q_deg),
        inside,
        share: inside as f64 / total as f64,
    }
}

/// The first quantum of the window of half-width `tol_deg` centred at `centre_deg`, in
/// `0..steps`.
pub fn goal_start(centre_deg: f64, tol_deg: f64, q_deg: f64, steps: i32) -> i32 {
    let width_q = ((2.0 * tol_deg / q_deg) + 1e-9).floor() as i32;
    let c = (centre_deg / q_deg - width_q as f64 / 2.0).round() as i64;
    c.rem_euclid(steps as i64) as i32
}

/// The number of orientation sets: windows of half-width `tol_deg` taken greedily (most weight
/// first) until they hold `target` of the weight (lost weight counts against it). Greedy covering
/// can overcount by a little; it is the measure `fewest_sets` minimises. `usize::MAX` if the lost
/// weight alone makes the target unreachable.
pub fn orientation_sets(state: &State, tol_deg: f64, q_deg: f64, steps: i32, target: f64) -> usize {
    let total = state.total().max(1) as f64;
    let width_q = ((2.0 * tol_deg / q_deg) + 1e-9).floor() as i32;
    let mut hist = histogram(&state.particles);
    let mut covered = 0u64;
    let mut sets = 0;
    while (covered as f64) < target * total - 1e-9 {
        let Some((a, _, w)) = best_span(&hist, width_q, steps) else {
            return usize::MAX;
        };
        covered += w as u64;
        sets += 1;
        hist.retain(|&(t, _)| (t - a).rem_euclid(steps) > width_q);
    }
    sets
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(t: i32, w: u32) -> Particle {
        Particle {
            sample: 0,
            theta_q: t,
            y_q: 0,
            weight: w,
        }
    }

    #[test]
    fn quantile_is_inverse_of_the_normal_cdf() {
        assert!(normal_quantile(0.5).abs() < 1e-9);
        assert!((normal_quantile(0.975) - 1.959964).abs() < 1e-5);
        assert!((normal_quantile(0.01) + 2.326348).abs() < 1e-5);
    }

    #[test]
    fn canonical_merges_and_sorts() {
        let s = State::canonical(vec![p(5, 1), p(3, 2), p(5, 4)], 1);
        assert_eq!(s.particles, vec![p(3, 2), p(5, 5)]);
        assert_eq!(s.total(), 8);
    }

    #[test]
    fn window_wraps_around_the_circle_and_counts_lost_weight() {
        // 1440 quanta of 0.25°; particles at 359.5° and 1°: one window of ±1°.
        let s = State::canonical(vec![p(1438, 3), p(4, 3), p(720, 2)], 2);
        let w = best_window(&s, 1.0, 0.25, 1440);
        assert_eq!(w.inside, 6);
        assert!((w.share - 0.6).abs() < 1e-12);
        assert!((w.centre_deg - 0.25).abs() < 1e-12, "{w:?}");
        assert_eq!(orientation_sets(&s, 1.0, 0.25, 1440, 0.8), 2);
        assert_eq!(orientation_sets(&s, 1.0, 0.25, 1440, 0.6), 1);
        assert_eq!(orientation_sets(&s, 1.0, 0.25, 1440, 0.9), usize::MAX);
    }

    #[test]
    fn feed_has_equal_weights_per_stable_state() {
        let prob = Problem::new("tripoly2");
        let c = prob.compile().unwrap();
        let f = feed_samples(&prob, &c);
        assert_eq!(f.len(), 75);
        for (i, s) in c.stable_deg.iter().enumerate() {
            let mean: f64 = f[i * 25..(i + 1) * 25].iter().map(|x| x.0).sum::<f64>() / 25.0;
            assert!((mean - s).abs() < 1.0, "{mean} {s}");
        }
        assert!(f.iter().all(|x| x.1.abs() <= 0.002));
    }
}
