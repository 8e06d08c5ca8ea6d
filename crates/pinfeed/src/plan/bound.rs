//! Branch and bound for the pin search: can r more pins still bring more weight into one window
//! than the best state found so far?
//!
//! A pin at lateral position c can only touch a particle with |c − y| ≤ reach (the part's radius
//! plus the pin's, in grid quanta; see [`super::transition::Transition::apply`]); an untouched
//! particle keeps its orientation and offset. So after r more pins, the particles inside a final
//! window W are (i) particles already inside W that no pin moved out, or (ii) particles touched at
//! least once — and a particle's first touch happens at its *current* offset, so every touched
//! particle lies in one of r intervals [c_k − reach, c_k + reach] of today's offsets. Hence
//!
//! ```text
//! inside_W(any descendant within r pins) ≤ w(inside W now) + max over r intervals of span
//!                                          2·reach of w(outside W now, within the intervals)
//! ```
//!
//! and the best window of a descendant holds at most the maximum of that over W. Lost weight
//! never returns. A state whose bound does not exceed the most weight one window already holds in
//! some state found so far can neither reach the goal (which needs more) nor improve the best
//! effort (ties go to the shallowest plan), so the search need not expand it. The bound ignores
//! the belt's edges, the actions' margins and the physics, each of which only removes plans, so
//! it is sound for every action set the search uses. Fences sweep the whole belt: for them only
//! the lost weight bounds (`reach = None`).

use super::particles::{Particle, State};

/// The geometry the bound needs.
#[derive(Debug, Clone, Copy)]
pub struct BoundGeometry {
    /// Largest |y_pin − y| (quanta) at which a pin can touch; `None`: an action can touch any
    /// particle (fences).
    pub reach_q: Option<i32>,
    /// Window span in quanta (inclusive), as in [`super::particles::best_window`].
    pub width_q: i32,
    /// Orientation quanta per symmetry period.
    pub steps: i32,
}

/// Can some state reached from `state` with at most `r` more actions hold more than `most` weight
/// in one window? `false` is a proof that it cannot; `true` may be optimistic.
pub fn may_exceed(state: &State, r: usize, g: BoundGeometry, most: u32) -> bool {
    may_exceed_parts(&state.particles, 0, r, g, most)
}

/// [`may_exceed`] for `parts` plus `free` weight that may end up anywhere: the particles one
/// action is about to touch, before their passes are computed (see
/// [`super::actions::pin_actions`]).
pub fn may_exceed_parts(
    parts: &[Particle],
    free: u64,
    r: usize,
    g: BoundGeometry,
    most: u32,
) -> bool {
    let live: u64 = free + parts.iter().map(|p| p.weight as u64).sum::<u64>();
    if live <= most as u64 {
        return false;
    }
    let Some(reach) = g.reach_q else {
        return true;
    };
    if parts.is_empty() {
        return true;
    }
    let mut by_y: Vec<Particle> = parts.to_vec();
    by_y.sort_unstable_by_key(|p| p.y_q);
    let span = 2 * reach as i64;
    let ylo = by_y.first().map_or(0, |p| p.y_q) as i64;
    let yhi = by_y.last().map_or(0, |p| p.y_q) as i64;
    // r intervals of span 2·reach (reach·2 + 1 grid points) cover any offsets within this range.
    if (r as i64) * (span + 1) > yhi - ylo {
        return true;
    }
    // Windows: one starting at each distinct orientation (a best window can start at a particle).
    let mut starts: Vec<i32> = by_y.iter().map(|p| p.theta_q).collect();
    starts.sort_unstable();
    starts.dedup();
    let inside = |a: i32, p: &Particle| (p.theta_q - a).rem_euclid(g.steps) <= g.width_q;
    let bound = most as u64;
    let weights: Vec<(i32, u64)> = starts
        .iter()
        .map(|&a| {
            let w = by_y
                .iter()
                .filter(|p| inside(a, p))
                .map(|p| p.weight as u64);
            (a, free + w.sum::<u64>())
        })
        .collect();
    // A cheap over-estimate first: the r intervals' best cover of all particles.
    let all = cover(&by_y, r, span);
    let candidates: Vec<(i32, u64)> = weights
        .into_iter()
        .filter(|&(_, w_in)| w_in + all.min(live - w_in) > bound)
        .collect();
    candidates.into_iter().any(|(a, w_in)| {
        let outside: Vec<Particle> = by_y.iter().filter(|p| !inside(a, p)).copied().collect();
        w_in + cover(&outside, r, span) > bound
    })
}

/// The most weight `r` intervals of span `span` (y_max − y_min ≤ span) can cover, particles
/// sorted by y: dynamic programming over the leftmost uncovered particle.
fn cover(sorted: &[Particle], r: usize, span: i64) -> u64 {
    let n = sorted.len();
    if n == 0 || r == 0 {
        return 0;
    }
    let mut prefix = vec![0u64; n + 1];
    for (i, p) in sorted.iter().enumerate() {
        prefix[i + 1] = prefix[i] + p.weight as u64;
    }
    // next[i]: the first particle beyond an interval starting at particle i.
    let mut next = vec![n; n];
    let mut j = 0;
    for i in 0..n {
        j = j.max(i);
        while j < n && (sorted[j].y_q as i64 - sorted[i].y_q as i64) <= span {
            j += 1;
        }
        next[i] = j;
    }
    // best[i]: most weight among particles i.. with k intervals (k = 1..=r, rolled).
    let mut prev = vec![0u64; n + 1];
    let mut cur = vec![0u64; n + 1];
    for _ in 0..r {
        cur[n] = 0;
        for i in (0..n).rev() {
            let take = prefix[next[i]] - prefix[i] + prev[next[i]];
            cur[i] = cur[i + 1].max(take);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(theta_q: i32, y_q: i32, weight: u32) -> Particle {
        Particle {
            sample: 0,
            theta_q,
            y_q,
            weight,
        }
    }

    const G: BoundGeometry = BoundGeometry {
        reach_q: Some(10),
        width_q: 4,
        steps: 100,
    };

    /// The brute-force bound: every window start, every choice of r interval starts on the grid.
    fn brute(state: &State, r: usize, g: BoundGeometry) -> u64 {
        let reach = g.reach_q.unwrap();
        let ys: Vec<i32> = state.particles.iter().map(|p| p.y_q).collect();
        let (lo, hi) = (
            ys.iter().min().unwrap() - reach,
            ys.iter().max().unwrap() + reach,
        );
        let mut best = 0;
        for a in 0..g.steps {
            let mut pins = vec![lo; r];
            loop {
                let w: u64 = state
                    .particles
                    .iter()
                    .filter(|q| {
                        (q.theta_q - a).rem_euclid(g.steps) <= g.width_q
                            || pins.iter().any(|c| (c - q.y_q).abs() <= reach)
                    })
                    .map(|q| q.weight as u64)
                    .sum();
                best = best.max(w);
                // Next combination (non-decreasing pin positions).
                let mut k = r;
                while k > 0 && pins[k - 1] == hi {
                    k -= 1;
                }
                if k == 0 {
                    break;
                }
                pins[k - 1] += 1;
                let v = pins[k - 1];
                for q in pins.iter_mut().skip(k) {
                    *q = v;
                }
            }
        }
        best
    }

    #[test]
    fn the_bound_is_the_brute_force_maximum() {
        use rand::RngExt;
        let mut rng = crate::random::stream(7, 0);
        for case in 0..60 {
            let n = 2 + case % 7;
            let parts: Vec<Particle> = (0..n)
                .map(|_| {
                    p(
                        rng.random_range(0..100),
                        rng.random_range(-60..60),
                        rng.random_range(1..5),
                    )
                })
                .collect();
            let s = State::canonical(parts, rng.random_range(0..3));
            for r in 0..3 {
                let ub = brute(&s, r, G);
                assert!(may_exceed(&s, r, G, ub as u32 - 1), "case {case} r {r}");
                assert!(!may_exceed(&s, r, G, ub as u32), "case {case} r {r}: {ub}");
            }
        }
    }

    #[test]
    fn far_apart_particles_need_one_pin_each() {
        // Three orientations, 100 quanta apart laterally (reach 10): one pin can fix one of the
        // two stray particles, not both.
        let s = State::canonical(vec![p(0, 0, 5), p(50, 100, 1), p(70, 200, 1)], 0);
        assert!(!may_exceed(&s, 1, G, 6));
        assert!(may_exceed(&s, 2, G, 6));
        assert!(may_exceed(&s, 1, G, 5));
        // Lost weight never returns; fences reach everything.
        let lost = State::canonical(vec![p(0, 0, 5)], 3);
        assert!(!may_exceed(&lost, 8, G, 5));
        let fences = BoundGeometry { reach_q: None, ..G };
        assert!(may_exceed(&s, 1, fences, 6));
    }

    #[test]
    fn free_weight_counts_in_every_window() {
        // Before a pin's passes are computed, the weight it touches may land anywhere.
        let untouched = [p(0, 0, 5), p(50, 100, 1)];
        assert!(!may_exceed_parts(&untouched, 2, 0, G, 7));
        assert!(may_exceed_parts(&untouched, 2, 0, G, 6));
        assert!(may_exceed_parts(&untouched, 2, 1, G, 7));
        assert!(may_exceed_parts(&[], 2, 0, G, 1));
        assert!(!may_exceed_parts(&[], 2, 0, G, 2));
    }
}
