//! One pin pass over every particle of a state, through the pure contact model.
//!
//! A particle at (θ, y) met by a fixed pin at lateral position y_pin is pushed from the standard
//! start of [`crate::maps::pass_start`] with d = (y_pin − y)/a (SPEC §1, belt frame: the part rests,
//! the pin travels in −x); its orientation becomes θ + rotation and its offset y + Δy, Δy the
//! centroid's lateral displacement (`pose_final.y`). The outcome depends only on (physics sample,
//! θ, y_pin − y), all on the quantum grid, so outcomes are memoised under that key and reused by
//! every state that meets the same sub-problem.
//!
//! A **column** is the outcome at one (physics sample, θ) over every pin offset of the grid within
//! reach (|y_pin − y| ≤ a + ρ): a slice of the configuration map along d. The planner needs only
//! its *qualitative signature* per offset (no contact; failed; or the sequence of part features the
//! pin touched and the sense of rotation — what changes at the thesis's band and no-contact edges).
//! It is sampled every `coarse` offsets and bisected wherever two neighbouring samples differ, down
//! to single grid steps; offsets between two equal samples are taken to share their signature (a
//! qualitative band narrower than `coarse` grid steps that starts and ends between two samples can
//! be missed; `coarse = 1` samples every offset). Columns are computed in parallel (rayon, results
//! collected in order, so the memo and the search do not depend on the thread count).

use super::particles::{theta_quanta, y_quanta, Particle, State};
use super::problem::{Compiled, Problem};
use super::PlanError;
use crate::geometry::{wrap_deg, Polygon};
use crate::maps::pass_start;
use crate::mechanics::{push, ContactSettings, ContactStatus, Fidelity, PartModel, Pin, Support};
use rand::RngExt;
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Signature of a pass without contact.
pub const NO_CONTACT: u32 = 0;
/// Signature of a failed pass (non-ok contact status): the particle is lost.
pub const FAILED: u32 = 1;

/// The physics one particle carries.
#[derive(Debug, Clone)]
pub struct PhysicsSample {
    /// The part's contact model under this sample's support.
    pub model: Arc<PartModel>,
    /// Pin–part friction coefficient of this sample.
    pub mu_c: f64,
    /// The tripod's points (m, part frame) and weights, if any (for reports).
    pub support: Support,
    /// Fence–part friction of this sample, when the problem is robust against it
    /// ([`Problem::mu_f_range`]; None: the fence planner's own μf).
    pub mu_f: Option<f64>,
    /// Error added to every fence's angle in this sample (degrees;
    /// [`Problem::fence_angle_range`]).
    pub fence_angle_deg: f64,
}

/// The outcome of one pass, as the planner keeps it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PassOutcome {
    /// Qualitative signature: `NO_CONTACT`, `FAILED`, or (≥ 2) a hash of the features touched and the sense of rotation.
    pub signature: u32,
    /// Final orientation (degrees, [0, 360)).
    pub theta_deg: f64,
    /// Lateral displacement of the centroid (m).
    pub dy_m: f64,
}

/// Memo key: (physics sample, θ quanta, (y_pin − y) quanta).
pub type PassKey = (u32, i32, i32);

/// Work counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct PushCounters {
    /// Contact-model passes computed.
    pub computed: u64,
    /// Look-ups answered by the memo.
    pub memo_hits: u64,
    /// Columns (θ slices) computed.
    pub columns: u64,
}

/// The transition function with its memo.
pub struct Transition {
    polygon: Polygon,
    radius: f64,
    pin_radius: f64,
    contact_tol: f64,
    theta_quantum: f64,
    theta_steps: i32,
    y_quantum: f64,
    half_width: f64,
    coarse: usize,
    /// Largest |y_pin − y| (quanta) at which the pin can touch.
    pub reach_q: i32,
    /// The physics samples the particles draw from (one without robustness options).
    pub samples: Vec<PhysicsSample>,
    /// Per sample, the first sample with the same fence passes ([`Transition::fence_sample`]).
    fence_twins: Vec<u32>,
    /// Per sample, the first sample with the same pin passes (model and μc): the memo's and
    /// the columns' keys are theirs.
    pin_twins: Vec<u32>,
    memo: HashMap<PassKey, PassOutcome>,
    columns: HashMap<(u32, i32), Arc<Vec<u32>>>,
    /// Work done so far.
    pub counters: PushCounters,
    /// Past this instant no pass is computed: [`Transition::expired`] turns true and the batch
    /// in progress is dropped (a search then stops with its time limit).
    deadline: Option<Instant>,
    expired: AtomicBool,
}

/// Stream of the physics samples (each particle's own μc and tripod).
const PHYSICS_STREAM: u64 = 0x7068_7973;

/// How many frictions of a range a robust search on one support plans against.
pub const FRICTION_LEVELS: usize = 9;

/// `k` values evenly spaced over a range from end to end, which a robust search on one support
/// plans against (`nominal` alone without a range).
fn levels(range: Option<(f64, f64)>, nominal: f64, k: usize) -> Vec<f64> {
    match range {
        Some((lo, hi)) if hi > lo => (0..k)
            .map(|j| lo + (hi - lo) * j as f64 / (k - 1) as f64)
            .collect(),
        Some((lo, _)) => vec![lo],
        None => vec![nominal],
    }
}

impl Transition {
    /// The physics samples: one (nominal) for all particles, or one per feed sample (`n`) when
    /// the problem asks for robustness — on one support a point of the grid over its ranges
    /// ([`FRICTION_LEVELS`] frictions per range, three angle errors; μc and the angle error
    /// advance together, so not every (μc, μf) pair occurs), on random tripods a draw from the
    /// seed.
    pub fn new(problem: &Problem, compiled: &Compiled, n: usize) -> Result<Transition, PlanError> {
        let part_err = |reason: crate::mechanics::PartModelError| PlanError::Part {
            part: problem.part.clone(),
            reason: reason.to_string(),
        };
        // Every physics sample's passes come from one model whose exact slides are served from
        // tables at the sample's μc, built per edge on first use: the nominal model (uniform
        // pressure) with a table set per μc its samples draw, and each tripod sample's own model.
        // A search pushes every sample thousands of times, so a table (~10⁴ limit-surface
        // evaluations) pays for itself many times over; a part with many vertices is left to
        // the solver (`MAX_TABLED_VERTICES`).
        let tabulate =
            compiled.polygon.vertices().len() <= crate::mechanics::slide_table::MAX_TABLED_VERTICES;
        // A robust search's samples each stand for one draw of uncertain physics: their tables
        // are certified to a sample's tolerance (`sampled_table_tol`: 10⁻⁸ at the default
        // integration tolerance, a third of the nodes of the 10⁻¹⁰ a nominal search keeps).
        let robust = problem.is_robust();
        let table_tol = if robust {
            crate::mechanics::slide_table::sampled_table_tol(problem.contact_tol)
        } else {
            crate::mechanics::slide_table::TABLE_TOL
        };
        let tabled = |model: PartModel, mus: &[f64]| {
            if tabulate {
                model.with_slide_tables_to(mus, table_tol)
            } else {
                model
            }
        };
        let mut draws = Vec::new();
        if robust && !problem.tripod {
            // On one support only the frictions and the fences' angle error vary: each feed
            // sample takes its values from a grid over each range (FRICTION_LEVELS values from
            // end to end, the angle error's ends and middle), the grids' values in turn. The
            // passes depend on the grid point, not on the particle, so particles in the same
            // state share them (the pins' and the fences' memos key the grid point), and the
            // grid's ends are each range's worst cases.
            let cs = levels(problem.mu_c_range, problem.mu_c, FRICTION_LEVELS);
            let fs = levels(problem.mu_f_range, f64::NAN, FRICTION_LEVELS);
            let angles = levels(problem.fence_angle_range, 0.0, 3);
            for i in 0..n {
                let (a, rest) = (i % angles.len(), i / angles.len());
                let mu_f = fs[rest % fs.len()];
                draws.push((
                    cs[i % cs.len()],
                    None,
                    (!mu_f.is_nan()).then_some(mu_f),
                    angles[a],
                ));
            }
        } else if robust {
            for i in 0..n {
                let mut rng = crate::random::stream(problem.seed ^ PHYSICS_STREAM, i as u64);
                let mu_c = match problem.mu_c_range {
                    Some((lo, hi)) => lo + (hi - lo) * rng.random::<f64>(),
                    None => problem.mu_c,
                };
                let tripod = if problem.tripod {
                    Some(
                        Support::random_tripod(&compiled.polygon, &mut rng)
                            .map_err(|e| part_err(e.into()))?,
                    )
                } else {
                    None
                };
                // Drawn after the others, so that a problem without a fence range draws as it did.
                let mu_f = problem
                    .mu_f_range
                    .map(|(lo, hi)| lo + (hi - lo) * rng.random::<f64>());
                let angle = problem
                    .fence_angle_range
                    .map_or(0.0, |(lo, hi)| lo + (hi - lo) * rng.random::<f64>());
                draws.push((mu_c, tripod, mu_f, angle));
            }
        }
        // The uniform model's μc values: the nominal one, and every draw on uniform pressure.
        let mut uniform_mus = vec![problem.mu_c];
        uniform_mus.extend(draws.iter().filter(|d| d.1.is_none()).map(|d| d.0));
        let uniform = Arc::new(tabled(
            PartModel::new(&compiled.polygon, &Support::Uniform).map_err(part_err)?,
            &uniform_mus,
        ));
        let mut samples = Vec::new();
        if !robust {
            samples.push(PhysicsSample {
                model: uniform,
                mu_c: problem.mu_c,
                support: Support::Uniform,
                mu_f: None,
                fence_angle_deg: 0.0,
            });
        } else {
            for (mu_c, tripod, mu_f, fence_angle_deg) in draws {
                let (model, support) = match tripod {
                    Some(s) => (
                        Arc::new(tabled(
                            PartModel::new(&compiled.polygon, &s).map_err(part_err)?,
                            &[mu_c],
                        )),
                        s,
                    ),
                    None => (uniform.clone(), Support::Uniform),
                };
                samples.push(PhysicsSample {
                    model,
                    mu_c,
                    support,
                    mu_f,
                    fence_angle_deg,
                });
            }
        }
        let twins = |same: &dyn Fn(&PhysicsSample, &PhysicsSample) -> bool| -> Vec<u32> {
            samples
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    samples[..i]
                        .iter()
                        .position(|t| Arc::ptr_eq(&t.model, &s.model) && same(t, s))
                        .unwrap_or(i) as u32
                })
                .collect()
        };
        let fence_twins = twins(&|t, s| t.mu_f == s.mu_f && t.fence_angle_deg == s.fence_angle_deg);
        let pin_twins = twins(&|t, s| t.mu_c == s.mu_c);
        let reach_q =
            ((compiled.radius + problem.pin_radius_m) / problem.y_quantum_m).floor() as i32;
        Ok(Transition {
            polygon: compiled.polygon.clone(),
            radius: compiled.radius,
            pin_radius: problem.pin_radius_m,
            contact_tol: problem.contact_tol,
            theta_quantum: problem.theta_quantum_deg,
            theta_steps: compiled.theta_steps,
            y_quantum: problem.y_quantum_m,
            half_width: problem.belt_width_m / 2.0,
            coarse: problem.coarse,
            reach_q,
            samples,
            fence_twins,
            pin_twins,
            memo: HashMap::new(),
            columns: HashMap::new(),
            counters: PushCounters::default(),
            deadline: problem.deadline,
            expired: AtomicBool::new(false),
        })
    }

    /// The first physics sample whose fence passes are those of `sample`: the same contact
    /// model, fence friction and angle error (a fence pass does not read the pins' μc).
    pub fn fence_sample(&self, sample: u32) -> u32 {
        self.fence_twins[sample as usize]
    }

    /// `key` with its sample replaced by the first one with the same pin passes.
    fn pin_key(&self, key: PassKey) -> PassKey {
        (self.pin_twins[key.0 as usize], key.1, key.2)
    }

    /// The physics sample feed sample `i` carries: the samples in turn.
    pub fn sample_of(&self, i: usize) -> u32 {
        (i % self.samples.len().max(1)) as u32
    }

    /// The part's radius a (m).
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Lateral quantum (m).
    pub fn y_quantum(&self) -> f64 {
        self.y_quantum
    }

    /// Bytes held by the memo and the columns (estimate).
    pub fn memo_bytes(&self) -> usize {
        let entry = std::mem::size_of::<(PassKey, PassOutcome)>() + 8;
        let col: usize = self.columns.values().map(|c| c.len() * 4 + 64).sum();
        self.memo.capacity() * entry + col
    }

    /// Distinct passes in the memo.
    pub fn memo_len(&self) -> usize {
        self.memo.len()
    }

    /// Has the deadline passed during a computation? Then the batch that saw it was dropped.
    pub fn expired(&self) -> bool {
        self.expired.load(Ordering::Relaxed)
    }

    /// Is the deadline past? (Records it: see [`Transition::expired`].)
    pub(crate) fn past_deadline(&self) -> bool {
        if self.expired() {
            return true;
        }
        let past = self.deadline.is_some_and(|d| Instant::now() >= d);
        if past {
            self.expired.store(true, Ordering::Relaxed);
        }
        past
    }

    /// One pass, computed (pure); past the deadline a placeholder that the caller drops.
    fn pass(&self, key: PassKey) -> PassOutcome {
        let (sample, theta_q, dy_q) = key;
        if self.past_deadline() {
            return PassOutcome {
                signature: FAILED,
                theta_deg: 0.0,
                dy_m: 0.0,
            };
        }
        let phys = &self.samples[sample as usize];
        let theta_deg = theta_q as f64 * self.theta_quantum;
        let d = dy_q as f64 * self.y_quantum / self.radius;
        let (pose, start) = pass_start(&self.polygon, theta_deg, d, self.pin_radius);
        let settings = ContactSettings {
            fidelity: Fidelity::Exact,
            mu_c: phys.mu_c,
            tol: self.contact_tol,
            ..ContactSettings::default()
        };
        let pin = Pin {
            radius: self.pin_radius,
            lateral_speed: 0.0,
        };
        let out = push(&phys.model, pose, start, &pin, &settings, None);
        if !out.contact {
            return PassOutcome {
                signature: NO_CONTACT,
                theta_deg,
                dy_m: 0.0,
            };
        }
        let ok = matches!(
            out.status,
            ContactStatus::Ok | ContactStatus::Metastable { .. }
        );
        let theta_final = wrap_deg(theta_deg + out.rotation_rad.to_degrees());
        if !ok {
            return PassOutcome {
                signature: FAILED,
                theta_deg: theta_final,
                dy_m: out.pose_final.y,
            };
        }
        // FNV-1a over the touched features (consecutive repeats dropped), the sense of rotation
        // and whether the push rode an unstable equilibrium.
        let mut h: u32 = 0x811c_9dc5;
        let mut mix = |v: u32| {
            for b in v.to_le_bytes() {
                h ^= b as u32;
                h = h.wrapping_mul(0x0100_0193);
            }
        };
        let mut last = None;
        for seg in &out.segments {
            let f = (seg.feature.kind(), seg.feature.index());
            if last != Some(f) {
                mix(match f.0 {
                    "edge" => 1,
                    "vertex" => 2,
                    _ => 3,
                });
                mix(f.1 as u32);
                last = Some(f);
            }
        }
        mix(if out.rotation_rad >= 0.0 { 7 } else { 9 });
        mix(matches!(out.status, ContactStatus::Metastable { .. }) as u32);
        PassOutcome {
            signature: h.max(2),
            theta_deg: theta_final,
            dy_m: out.pose_final.y,
        }
    }

    /// Make sure every key has an outcome in the memo (missing ones computed in parallel).
    pub fn ensure(&mut self, keys: &[PassKey]) {
        let mut missing: Vec<PassKey> = Vec::new();
        for &k in keys {
            let k = self.pin_key(k);
            if self.memo.contains_key(&k) {
                self.counters.memo_hits += 1;
            } else {
                missing.push(k);
            }
        }
        missing.sort_unstable();
        missing.dedup();
        let this = &*self;
        let out: Vec<PassOutcome> = missing.par_iter().map(|&k| this.pass(k)).collect();
        if self.expired() {
            return;
        }
        self.counters.computed += out.len() as u64;
        self.memo.extend(missing.into_iter().zip(out));
    }

    /// The memoised outcome (call [`Transition::ensure`] first).
    pub fn outcome(&self, key: PassKey) -> Option<&PassOutcome> {
        self.memo.get(&self.pin_key(key))
    }

    /// Signature of column (sample, θ) at offset index i (offset i − reach), computing it (and
    /// recording it in `local`) when it is in neither memo.
    fn column_sig(
        &self,
        sample: u32,
        theta_q: i32,
        i: usize,
        local: &mut Vec<(PassKey, PassOutcome)>,
        sig: &mut [u32],
        hits: &mut u64,
    ) -> u32 {
        const UNKNOWN: u32 = u32::MAX;
        if sig[i] != UNKNOWN {
            return sig[i];
        }
        let key = (sample, theta_q, i as i32 - self.reach_q);
        let s = match self.memo.get(&key) {
            Some(o) => {
                *hits += 1;
                o.signature
            }
            None => {
                let o = self.pass(key);
                local.push((key, o));
                o.signature
            }
        };
        sig[i] = s;
        s
    }

    /// Compute one column: coarse samples, bisected where neighbours differ.
    fn column(&self, sample: u32, theta_q: i32) -> (Vec<u32>, Vec<(PassKey, PassOutcome)>, u64) {
        const UNKNOWN: u32 = u32::MAX;
        let len = (2 * self.reach_q + 1) as usize;
        let mut sig = vec![UNKNOWN; len];
        let mut local = Vec::new();
        let mut hits = 0u64;
        let mut coarse: Vec<usize> = (0..len).step_by(self.coarse).collect();
        if *coarse.last().unwrap() != len - 1 {
            coarse.push(len - 1);
        }
        for &i in &coarse {
            self.column_sig(sample, theta_q, i, &mut local, &mut sig, &mut hits);
        }
        let mut stack: Vec<(usize, usize)> =
            coarse.windows(2).map(|w| (w[0], w[1])).rev().collect();
        while let Some((lo, hi)) = stack.pop() {
            if hi - lo <= 1 {
                continue;
            }
            if sig[lo] == sig[hi] {
                let s = sig[lo];
                for v in &mut sig[lo + 1..hi] {
                    if *v == UNKNOWN {
                        *v = s;
                    }
                }
                continue;
            }
            let mid = (lo + hi) / 2;
            self.column_sig(sample, theta_q, mid, &mut local, &mut sig, &mut hits);
            stack.push((mid, hi));
            stack.push((lo, mid));
        }
        (sig, local, hits)
    }

    /// Make sure every (sample, θ) column exists (missing ones computed in parallel).
    pub fn ensure_columns(&mut self, cols: &[(u32, i32)]) {
        let mut missing: Vec<(u32, i32)> = cols
            .iter()
            .map(|&(s, t)| (self.pin_twins[s as usize], t))
            .filter(|c| !self.columns.contains_key(c))
            .collect();
        missing.sort_unstable();
        missing.dedup();
        let this = &*self;
        let out: Vec<_> = missing
            .par_iter()
            .map(|&(s, t)| this.column(s, t))
            .collect();
        if self.expired() {
            return;
        }
        for ((s, t), (sig, local, hits)) in missing.into_iter().zip(out) {
            self.counters.columns += 1;
            self.counters.memo_hits += hits;
            self.counters.computed += local.len() as u64;
            self.memo.extend(local);
            self.columns.insert((s, t), Arc::new(sig));
        }
    }

    /// The signature column of (sample, θ) (call [`Transition::ensure_columns`] first).
    pub fn column_of(&self, sample: u32, theta_q: i32) -> Arc<Vec<u32>> {
        self.columns[&(self.pin_twins[sample as usize], theta_q)].clone()
    }

    /// The state after a pin at `pin_q` (quanta); every touched particle's pass must be in the
    /// memo (see [`Transition::ensure`]); one that is not (the deadline dropped its batch) counts
    /// as lost.
    pub fn apply(&self, state: &State, pin_q: i32) -> State {
        let mut lost = state.lost;
        let mut parts = Vec::with_capacity(state.particles.len());
        for p in &state.particles {
            let dy = pin_q - p.y_q;
            if dy.abs() > self.reach_q {
                parts.push(*p);
                continue;
            }
            let Some(&o) = self.outcome((p.sample, p.theta_q, dy)) else {
                lost += p.weight;
                continue;
            };
            match o.signature {
                NO_CONTACT => parts.push(*p),
                FAILED => lost += p.weight,
                _ => {
                    let y = p.y_q as f64 * self.y_quantum + o.dy_m;
                    if y.abs() > self.half_width {
                        lost += p.weight;
                    } else {
                        parts.push(Particle {
                            sample: p.sample,
                            theta_q: theta_quanta(
                                o.theta_deg,
                                self.theta_quantum,
                                self.theta_steps,
                            ),
                            y_q: y_quanta(y, self.y_quantum),
                            weight: p.weight,
                        });
                    }
                }
            }
        }
        State::canonical(parts, lost)
    }

    /// Largest pin position on the belt (quanta): pins stay within ±width/2.
    pub fn belt_limit_q(&self) -> i32 {
        (self.half_width / self.y_quantum + 1e-9).floor() as i32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::slide_table::{Place, Side};

    /// Every physics sample of a robust problem serves its slides from tables at its own μc, on
    /// its own support; a part with more than 64 vertices is left to the solver.
    #[test]
    fn every_physics_sample_has_slide_tables_at_its_friction() {
        for tripod in [false, true] {
            let mut p = Problem::new("tripoly2");
            p.tripod = tripod;
            p.mu_c_range = Some((0.3, 0.7));
            let compiled = p.compile().unwrap();
            let t = Transition::new(&p, &compiled, 12).unwrap();
            assert_eq!(t.samples.len(), 12);
            for s in &t.samples {
                assert_eq!(matches!(s.support, Support::Uniform), !tripod);
                let table = s.model.slide_table(s.mu_c, Place::Edge(0), Side::Left);
                assert!(table.is_some_and(|t| t.range().is_some()), "μc {}", s.mu_c);
                // Not at a μc no sample drew.
                assert!(s
                    .model
                    .slide_table(0.71, Place::Edge(0), Side::Left)
                    .is_none());
            }
        }
        let mut p = Problem::new("ngon:80");
        p.tripod = true;
        let compiled = p.compile().unwrap();
        let t = Transition::new(&p, &compiled, 2).unwrap();
        assert!(t.samples.iter().all(|s| !s.model.has_slide_tables()));
    }

    /// A problem robust against the fences' friction draws each sample's fence μf from its
    /// range, after the other draws: the pins' μc and tripods are what they were without it.
    #[test]
    fn a_fence_friction_range_gives_every_sample_its_own_fence_friction() {
        let mut p = Problem::new("tripoly2");
        p.tripod = true;
        p.mu_c_range = Some((0.3, 0.7));
        let compiled = p.compile().unwrap();
        let before = Transition::new(&p, &compiled, 10).unwrap();
        assert!(before.samples.iter().all(|s| s.mu_f.is_none()));
        p.mu_f_range = Some((0.45, 0.55));
        let after = Transition::new(&p, &compiled, 10).unwrap();
        let mut seen = Vec::new();
        for (a, b) in before.samples.iter().zip(&after.samples) {
            assert_eq!(a.mu_c, b.mu_c);
            assert_eq!(format!("{:?}", a.support), format!("{:?}", b.support));
            let f = b.mu_f.expect("a fence friction per sample");
            assert!((0.45..=0.55).contains(&f), "{f}");
            seen.push(f);
        }
        seen.sort_by(f64::total_cmp);
        seen.dedup();
        assert_eq!(seen.len(), 10, "each sample draws its own: {seen:?}");
        // A fence range alone makes the problem robust.
        let mut q = Problem::new("tripoly2");
        q.mu_f_range = Some((0.4, 0.6));
        assert!(q.is_robust());
        assert_eq!(Transition::new(&q, &compiled, 4).unwrap().samples.len(), 4);
    }

    /// On one support a robust search plans against a grid over each range — nine frictions
    /// from end to end, the angle error's ends and middle — the grid's points in turn, and
    /// particles at the same grid point share their passes: a pin pass per pin friction, a
    /// fence pass per fence friction and angle error.
    #[test]
    fn on_one_support_the_samples_are_a_grid_whose_points_share_their_passes() {
        let mut p = Problem::new("tripoly2");
        p.mu_c_range = Some((0.4, 0.6));
        p.mu_f_range = Some((0.35, 0.65));
        p.fence_angle_range = Some((-0.5, 0.5));
        let compiled = p.compile().unwrap();
        let mut t = Transition::new(&p, &compiled, 150).unwrap();
        assert_eq!(t.samples.len(), 150);
        let distinct = |f: &dyn Fn(&PhysicsSample) -> f64| {
            let mut v: Vec<f64> = t.samples.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            v.dedup();
            v
        };
        let mu_c = distinct(&|s| s.mu_c);
        assert_eq!(mu_c.len(), FRICTION_LEVELS);
        assert_eq!((mu_c[0], mu_c[8]), (0.4, 0.6));
        assert!((mu_c[4] - 0.5).abs() < 1e-12);
        let mu_f = distinct(&|s| s.mu_f.unwrap());
        assert_eq!(
            (mu_f.len(), mu_f[0], mu_f[8]),
            (FRICTION_LEVELS, 0.35, 0.65)
        );
        assert_eq!(distinct(&|s| s.fence_angle_deg), vec![-0.5, 0.0, 0.5]);
        // Every (fence friction, angle) pair is planned against.
        let mut pairs: Vec<(u64, u64)> = t
            .samples
            .iter()
            .map(|s| (s.mu_f.unwrap().to_bits(), s.fence_angle_deg.to_bits()))
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        assert_eq!(pairs.len(), 27);
        let fence_twins: std::collections::BTreeSet<u32> =
            (0..150).map(|i| t.fence_sample(i)).collect();
        assert_eq!(fence_twins.len(), 27);
        for i in 0..150u32 {
            let (s, f) = (
                &t.samples[i as usize],
                &t.samples[t.fence_sample(i) as usize],
            );
            assert!(t.fence_sample(i) <= i);
            assert_eq!((s.mu_f, s.fence_angle_deg), (f.mu_f, f.fence_angle_deg));
        }
        // One pin pass per pin friction for 150 particles at one orientation and offset.
        let keys: Vec<PassKey> = (0..150).map(|i| (i, 0, 0)).collect();
        t.ensure(&keys);
        assert_eq!(t.counters.computed, FRICTION_LEVELS as u64);
        for i in 0..150 {
            let o = t.outcome((i, 0, 0)).expect("served");
            let mut q = p.clone();
            q.mu_c_range = None;
            q.mu_c = t.samples[i as usize].mu_c;
            let alone = Transition::new(&q, &compiled, 1).unwrap().pass((0, 0, 0));
            assert_eq!(o.signature, alone.signature, "sample {i}");
            assert!((o.theta_deg - alone.theta_deg).abs() < 1e-6, "sample {i}");
        }
        // On random tripods every sample stays its own.
        p.tripod = true;
        let r = Transition::new(&p, &compiled, 20).unwrap();
        assert!((0..20).all(|i| r.fence_sample(i) == i && r.pin_twins[i as usize] == i));
    }
}
