//! The actions of a state: not a blind grid, but one pin position per interval of the lateral
//! grid over which no particle's pass changes qualitatively (thesis ch. 4's band and
//! no-contact edges).
//!
//! Every pin position on the grid (step = the lateral quantum) within reach of some particle and on
//! the belt is a candidate. Its *signature vector* is each particle's qualitative outcome there (see
//! [`super::transition`]); the positions where some particle's signature changes cut the grid into
//! intervals. Each interval is one action: its representative is its middle (rounded down to the
//! grid), its robustness margin the distance from the representative to the interval's nearer
//! edge (edges lie half a grid step outside the interval's end positions), so a pin placed within
//! ±margin of the representative meets every particle in the same qualitative way. Intervals with
//! margin below `min_margin_m` are dropped (a design there breaks under a small pin error), and so
//! are actions whose successor equals the state (no particle touched, or nothing changed).

use super::particles::{Particle, State};
use super::transition::{PassKey, Transition, NO_CONTACT};
use serde::Serialize;

/// A fixed pin at one lateral position.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PinAction {
    /// Lateral position (grid quanta).
    pub y_q: i32,
    /// Lateral position of the pin's centre (m).
    pub y_m: f64,
    /// Lower end of the interval of positions that act the same way qualitatively (m).
    pub lo_m: f64,
    /// Upper end of that interval (m).
    pub hi_m: f64,
    /// Distance from `y_m` to the nearer edge of the interval (m).
    pub margin_m: f64,
}

/// One step of a plan: a fixed pin, or a fence (the fence planner, [`super::fences`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Action {
    /// A fixed pin.
    Pin(PinAction),
    /// A fence.
    Fence(super::fences::FenceAction),
}

/// Decides, before an action's passes are computed, whether its successor is worth having: called
/// with the particles the pin cannot touch and the weight it may touch (see
/// [`super::bound::may_exceed_parts`]).
pub type Worth<'a> = &'a dyn Fn(&[Particle], u64) -> bool;

/// The pin actions of `state` with their successors, in increasing lateral position; with
/// `worth`, only the actions it accepts (the others' passes are never computed).
pub fn pin_actions(
    state: &State,
    tr: &mut Transition,
    min_margin_m: f64,
    worth: Option<Worth>,
) -> Vec<(Action, State)> {
    if state.particles.is_empty() {
        return Vec::new();
    }
    let reach = tr.reach_q;
    let limit = tr.belt_limit_q();
    let q = tr.y_quantum();
    let ymin = state.particles.iter().map(|p| p.y_q).min().unwrap();
    let ymax = state.particles.iter().map(|p| p.y_q).max().unwrap();
    let lo = (ymin - reach).max(-limit);
    let hi = (ymax + reach).min(limit);
    if lo > hi {
        return Vec::new();
    }
    let cols: Vec<(u32, i32)> = state
        .particles
        .iter()
        .map(|p| (p.sample, p.theta_q))
        .collect();
    tr.ensure_columns(&cols);
    if tr.expired() {
        return Vec::new();
    }
    // Cuts: pin positions c where some particle's signature differs between c − 1 and c.
    let mut cuts: Vec<i32> = Vec::new();
    let columns: Vec<_> = cols.iter().map(|&(s, t)| tr.column_of(s, t)).collect();
    for (p, col) in state.particles.iter().zip(&columns) {
        let at = |i: i64| -> u32 {
            if i < 0 || i >= col.len() as i64 {
                NO_CONTACT
            } else {
                col[i as usize]
            }
        };
        for i in 0..=col.len() as i64 {
            if at(i) != at(i - 1) {
                // Column index i is pin offset i − reach from the particle.
                let c = p.y_q + i as i32 - reach;
                if c > lo && c <= hi {
                    cuts.push(c);
                }
            }
        }
    }
    cuts.sort_unstable();
    cuts.dedup();
    let mut starts = vec![lo];
    starts.extend(&cuts);
    let mut intervals = Vec::new();
    for (k, &s) in starts.iter().enumerate() {
        let e = starts.get(k + 1).map_or(hi, |n| n - 1);
        let rep = s + (e - s) / 2;
        let margin = ((rep - s).min(e - rep) as f64 + 0.5) * q;
        if margin + 1e-12 < min_margin_m {
            continue;
        }
        // Skip intervals where no particle is touched at all.
        let touched = state.particles.iter().zip(&columns).any(|(p, col)| {
            let i = rep - p.y_q + reach;
            i >= 0 && (i as usize) < col.len() && col[i as usize] != NO_CONTACT
        });
        if touched && worth.is_none_or(|w| worth_it(state, &columns, reach, rep, w)) {
            intervals.push((s, e, rep, margin));
        }
    }
    let mut keys: Vec<PassKey> = Vec::new();
    for &(_, _, rep, _) in &intervals {
        for p in &state.particles {
            let dy = rep - p.y_q;
            if dy.abs() <= reach {
                keys.push((p.sample, p.theta_q, dy));
            }
        }
    }
    tr.ensure(&keys);
    if tr.expired() {
        return Vec::new();
    }
    let mut out = Vec::with_capacity(intervals.len());
    for (s, e, rep, margin) in intervals {
        let next = tr.apply(state, rep);
        if &next == state {
            continue;
        }
        let action = Action::Pin(PinAction {
            y_q: rep,
            y_m: rep as f64 * q,
            lo_m: (s as f64 - 0.5) * q,
            hi_m: (e as f64 + 0.5) * q,
            margin_m: margin,
        });
        out.push((action, next));
    }
    out
}

/// Ask `worth` about a pin at `rep`: the particles it cannot touch (out of reach, or no contact in
/// their column) and the weight of those it may touch.
fn worth_it(
    state: &State,
    columns: &[std::sync::Arc<Vec<u32>>],
    reach: i32,
    rep: i32,
    worth: Worth,
) -> bool {
    let mut untouched = Vec::with_capacity(state.particles.len());
    let mut touched = 0u64;
    for (p, col) in state.particles.iter().zip(columns) {
        let i = rep - p.y_q + reach;
        if i >= 0 && (i as usize) < col.len() && col[i as usize] != NO_CONTACT {
            touched += p.weight as u64;
        } else {
            untouched.push(*p);
        }
    }
    worth(&untouched, touched)
}
