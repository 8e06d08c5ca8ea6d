//! `likelihood`: a matched filter over the template ensembles with the sensor's noise model.
//!
//! The thesis compares profiles by eye and by sign patterns (ch. 5.5); this is the statistically
//! principled alternative the issue asks for. For a reading y and hypothesis h with template
//! ensemble {s_m}:
//!
//! * **Alignment.** Contact begin is detected in the reading by the shared |F| threshold detector
//!   ([`super::common`]) at sample k_b. Every template is placed with its true contact begin at
//!   t(k_b) − u, the lag u searched over a grid of step dt/[`PHASES`]: the detector's own delay on
//!   that member's noise-free samples over every sampling phase, widened by ±[`LAG_SAMPLES`]
//!   samples for noise. The lag is a nuisance parameter, maximised over per member (a profile
//!   likelihood; marginalising would cost an exponential per lag).
//! * **Noise model.** Per channel c, white Gaussian noise of variance σ_c² + q_c²/12 (white noise and
//!   quantisation step from the sensor settings), floored at (10⁻³ × the channel's largest template
//!   magnitude)² so that σ = 0 still gives a finite likelihood. Known bias and drift are removed
//!   from the reading; a low-pass, if set, is applied to the templates (its correlation of the
//!   noise is ignored). Only the informative channels Fx, Fy, Tx, Ty, Tz are used (Fz ≡ 0).
//! * **Sufficient statistics.** To classify 3 × 64 templates in tens of microseconds, the frame
//!   (the contact window of the longest template plus margins, anchored at k_b) is cut into at most
//!   [`MAX_BLOCKS`] blocks of B consecutive samples, and the likelihood is that of the block sums
//!   (exact for the block sums; it ignores the within-block shape: at 1 kHz and a 2 s window a
//!   block is ~50 ms, short beside these profiles' features but a real loss for fast transients;
//!   [`MAX_BLOCKS`] trades it against time). Block sums outside the reading are the quiet baseline
//!   (0). log p(Y | m, u) = Σ_{c,b} w_c/B · (Y·S − S²/2) + const, with S the template's block sums
//!   at lag u and w_c = 1/σ_c²: a dot product with a precomputed vector at a base lag plus, for the
//!   few (block, channel) entries that change with the lag (the contact's jumps), per-lag
//!   corrections — at most [`MAX_VARYING`] of them per member, the ones that matter most.
//! * **Mixture and posterior.** log p(y | h) = log-sum-exp over members − ln n_h (the ensemble
//!   stands for the declared uncertainty). A member whose score is certainly more than 800 below
//!   the best of its hypothesis adds exactly +0 to the sum (e^−800 underflows), so it is not
//!   scored: cheap upper bounds of the scores (the whitened base vectors' first principal
//!   components plus the rest's norm, and the lag corrections' extremes) order and prune each
//!   hypothesis's members, and the result is that of scoring every member, bit for bit. The
//!   posterior normalises over hypotheses with equal
//!   priors; the reject option answers Unknown when the largest posterior is below
//!   `reject_below`. No contact detected, empty or non-finite reading → Unknown; when the detector
//!   cannot see even the noise-free templates' contacts (noise far above the signal) every
//!   reading is Unknown.
//!
//! Works for any hypotheses with templates, including `vertex`/`edge` (the likelihood alternative
//! to the thesis's zero-crossing rule).

use super::common::{self, decide, log_sum_exp};
use super::{Classification, Classifier, ClassifierOptions};
use crate::sensing::reading::{self, Reading};
use crate::sensing::settings::{SensorSettings, CHANNELS};
use crate::sensing::templates::TemplateSet;

/// Channels used: Fx, Fy, Tx, Ty, Tz.
pub const USED: [usize; 5] = [0, 1, 3, 4, 5];
/// Sub-sample lag steps per sample period.
pub const PHASES: usize = 2;
/// Extra lag (samples) searched on each side of the detector's noise-free delay.
pub const LAG_SAMPLES: i64 = 2;
/// Largest number of blocks per channel in the frame.
pub const MAX_BLOCKS: usize = 48;
/// Largest number of lag-dependent (block, channel) entries kept per member.
pub const MAX_VARYING: usize = 8;
/// Largest number of lags searched.
pub const MAX_LAGS: usize = 24;

/// One member of an ensemble as training leaves it (packed into [`Likelihood::data`] after).
struct Member {
    /// The base vector w/B · S_base (used channels × blocks).
    base: Vec<f64>,
    /// Σ −½ w/B S_base² plus, per lag, the lag's correction of that term.
    cst: Vec<f64>,
    /// Flat indices (channel·blocks + block) of the lag-dependent entries.
    vidx: Vec<u32>,
    /// Per entry and lag: w/B · (S_lag − S_base).
    dlin: Vec<f64>,
}

/// Principal directions of the members' (whitened) base vectors kept for their bounds.
pub const BASIS: usize = 16;
/// A member whose score is certainly more than this below the best score of its hypothesis is
/// not scored: its term of the hypothesis's log-sum-exp, exp(score − best), is exactly +0 (see
/// [`common::EXP_UNDERFLOW`]), so leaving it out changes no bit of the result.
const SKIP_GAP: f64 = 800.0;
/// Relative allowance for rounding in a member's bound (rounding errors of these sums are below
/// 10⁻¹³ of the magnitudes involved).
const ROUNDING: f64 = 1e-9;
/// Numbers per member in [`Bounds::rec`] besides its basis coefficients: ρ, κ, ‖b̂‖, max cst,
/// max |cst|, Σ |dlin|, then per lag-dependent entry (padded to [`MAX_VARYING`]) the largest and the
/// smallest correction over the lags.
const REC_FIXED: usize = 6 + 2 * MAX_VARYING;

/// Where one member sits in [`Packed::data`].
#[derive(Debug, Clone, Copy)]
struct Slot {
    /// Offset of its constants per lag (its rows of corrections, then its base vector follow).
    at: u32,
    /// Its lag-dependent entries: a range into `vidx`.
    vars: [u32; 2],
    /// The runs of chunks of eight where its base vector is non-zero: a range into `runs`.
    runs: [u32; 2],
}

/// Upper bounds of the members' scores, far cheaper than the scores. In whitened coordinates
/// (entry d scaled by s_d = √(w/B)), a member's base product is b·y = b̂·ŷ with b̂ = b/s and
/// ŷ = s·y; with V the first [`BASIS`] principal directions of the members' b̂, α = V b̂ and
/// r = b̂ − Vᵀα, b̂·ŷ = α·z + (V r)·z + r·(ŷ − Vᵀz) for z = V ŷ, so
/// b̂·ŷ ≤ α·z + κ‖z‖ + ρ‖ŷ − Vᵀz‖ (κ = ‖V r‖, ρ = ‖r‖). The best lag's correction is at most
/// max cst + Σ_e max(y_e · max_o dlin[e][o], y_e · min_o dlin[e][o]). A reading resembles some
/// templates, so ŷ − Vᵀz is small, and the bound separates a hypothesis's members whose scores
/// lie thousands apart.
struct Bounds {
    /// s_d per entry.
    scale: Vec<f64>,
    /// The directions, `k` rows of `dims`.
    basis: Vec<f64>,
    k: usize,
    /// Per member, `k` + [`REC_FIXED`] numbers: α, then as [`REC_FIXED`] lists.
    rec: Vec<f64>,
    /// Per member, the flat indices of its lag-dependent entries, padded to [`MAX_VARYING`] with
    /// index 0 (a padded entry's largest and smallest correction are 0, so it adds ±0).
    vars: Vec<[u32; MAX_VARYING]>,
}

/// A reading's numbers for the bounds: z = V ŷ, ‖z‖, ‖ŷ − Vᵀz‖, ‖ŷ‖, max |y|.
struct Projected {
    z: Vec<f64>,
    z_norm: f64,
    perp: f64,
    y_norm: f64,
    /// max_d |y_d| (not whitened).
    y_max: f64,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

impl Bounds {
    /// The basis and each member's record; `scale` is s_d per entry.
    fn new(members: &[Member], dims: usize, lags: usize, scale: &[f64]) -> Bounds {
        let whitened: Vec<Vec<f64>> = members
            .iter()
            .map(|m| m.base.iter().zip(scale).map(|(b, s)| b / s).collect())
            .collect();
        let mut basis = Vec::new();
        if !members.is_empty() && dims > 0 {
            let a = nalgebra::DMatrix::from_fn(members.len(), dims, |i, d| whitened[i][d]);
            let svd = a.svd(false, true);
            if let Some(v_t) = svd.v_t {
                let sv = &svd.singular_values;
                let mut order: Vec<usize> = (0..sv.len()).filter(|&i| sv[i] > 0.0).collect();
                order.sort_by(|&i, &j| sv[j].total_cmp(&sv[i]));
                for &i in order.iter().take(BASIS) {
                    basis.extend(v_t.row(i).iter().copied());
                }
            }
        }
        let k = basis.len().checked_div(dims).unwrap_or(0);
        let mut rec = Vec::with_capacity(members.len() * (k + REC_FIXED));
        let vars = members
            .iter()
            .map(|m| std::array::from_fn(|e| m.vidx.get(e).copied().unwrap_or(0)))
            .collect();
        for (m, bh) in members.iter().zip(&whitened) {
            let alpha: Vec<f64> = basis
                .chunks_exact(dims)
                .map(|v| v.iter().zip(bh).map(|(a, b)| a * b).sum())
                .collect();
            let mut r = bh.clone();
            for (v, a) in basis.chunks_exact(dims).zip(&alpha) {
                for (x, b) in r.iter_mut().zip(v) {
                    *x -= a * b;
                }
            }
            let vr: Vec<f64> = basis
                .chunks_exact(dims)
                .map(|v| v.iter().zip(&r).map(|(a, b)| a * b).sum())
                .collect();
            rec.extend_from_slice(&alpha);
            rec.push(norm(&r));
            rec.push(norm(&vr));
            rec.push(norm(bh));
            rec.push(m.cst.iter().copied().fold(f64::NEG_INFINITY, f64::max));
            rec.push(m.cst.iter().fold(0.0, |a: f64, c| a.max(c.abs())));
            rec.push(m.dlin.iter().map(|x| x.abs()).sum());
            let rows: Vec<&[f64]> = m.dlin.chunks_exact(lags.max(1)).collect();
            for e in 0..MAX_VARYING {
                rec.push(
                    rows.get(e)
                        .map_or(0.0, |r| r.iter().copied().fold(f64::NEG_INFINITY, f64::max)),
                );
            }
            for e in 0..MAX_VARYING {
                rec.push(
                    rows.get(e)
                        .map_or(0.0, |r| r.iter().copied().fold(f64::INFINITY, f64::min)),
                );
            }
        }
        Bounds {
            scale: scale.to_vec(),
            basis,
            k,
            rec,
            vars,
        }
    }

    #[inline(always)]
    fn project(&self, y: &[f64]) -> Projected {
        let dims = y.len();
        let yh: Vec<f64> = y.iter().zip(&self.scale).map(|(a, s)| a * s).collect();
        let mut z = vec![0.0; self.k];
        let mut perp = yh.clone();
        for (v, zj) in self.basis.chunks_exact(dims.max(1)).zip(z.iter_mut()) {
            let mut acc = [0.0; 4];
            let (whole, rest) = v.split_at(dims / 4 * 4);
            for (a, b) in whole.chunks_exact(4).zip(yh.chunks_exact(4)) {
                for i in 0..4 {
                    acc[i] += a[i] * b[i];
                }
            }
            let t: f64 = rest
                .iter()
                .zip(&yh[dims / 4 * 4..])
                .map(|(a, b)| a * b)
                .sum();
            *zj = acc[0] + acc[1] + acc[2] + acc[3] + t;
            for (p, b) in perp.iter_mut().zip(v) {
                *p -= *zj * b;
            }
        }
        Projected {
            z_norm: norm(&z),
            perp: norm(&perp),
            y_norm: norm(&yh),
            y_max: y.iter().fold(0.0, |a: f64, x| a.max(x.abs())),
            z,
        }
    }

    /// Member `m`'s bound without its lag term, plus its allowance for rounding; and the bound of
    /// its lag term, for the block sums `y` (`p`: their projection).
    #[inline(always)]
    fn of(&self, m: usize, p: &Projected, y: &[f64]) -> (f64, f64) {
        let k = self.k;
        let r = &self.rec[m * (k + REC_FIXED)..(m + 1) * (k + REC_FIXED)];
        let (alpha, r) = r.split_at(k);
        let mut acc = [0.0; 4];
        let whole = k / 4 * 4;
        for (a, z) in alpha[..whole].chunks_exact(4).zip(p.z.chunks_exact(4)) {
            for i in 0..4 {
                acc[i] += a[i] * z[i];
            }
        }
        let mut az = (acc[0] + acc[1]) + (acc[2] + acc[3]);
        for (a, z) in alpha[whole..].iter().zip(&p.z[whole..]) {
            az += a * z;
        }
        let (rho, kappa, bnorm, cmax, cabs, dsum) = (r[0], r[1], r[2], r[3], r[4], r[5]);
        let (hi, lo) = r[6..].split_at(MAX_VARYING);
        let mut lag = [cmax, 0.0];
        for (e, ((&d, &h), &l)) in self.vars[m].iter().zip(hi).zip(lo).enumerate() {
            let y = y[d as usize];
            let (a, b) = (y * h, y * l);
            lag[e % 2] += if a > b { a } else { b };
        }
        // |y_e| ≤ max |y|, so Σ_e |y_e| Σ_o |dlin[e][o]| bounds the corrections' magnitudes.
        let mag = cabs + p.y_max * dsum;
        let base = az + kappa * p.z_norm + rho * p.perp + ROUNDING * (bnorm * p.y_norm + mag);
        (base, lag[0] + lag[1])
    }
}

/// The trained members laid out for scoring: per member one sequential run of numbers.
struct Packed {
    /// Per member: its constant per lag, per lag-dependent entry its row of corrections over the
    /// lags, then its base vector's chunks of eight that hold a non-zero value and its entries
    /// after the last whole chunk.
    data: Vec<f64>,
    /// The members, in order.
    slots: Vec<Slot>,
    /// The runs of chunks of every member (chunk indices).
    runs: Vec<std::ops::Range<u32>>,
    /// The flat indices (channel·blocks + block) of every member's lag-dependent entries.
    vidx: Vec<u32>,
    /// Lags per member.
    lags: usize,
    bounds: Bounds,
}

impl Packed {
    /// Lay out `members` (base vectors of `dims` entries, `lags` lags; `scale`: s_d per entry,
    /// see [`Bounds`]).
    fn new(members: &[Member], dims: usize, lags: usize, scale: &[f64]) -> Packed {
        let whole = dims / 8 * 8;
        let mut p = Packed {
            data: Vec::new(),
            slots: Vec::with_capacity(members.len()),
            runs: Vec::new(),
            vidx: Vec::new(),
            lags,
            bounds: Bounds::new(members, dims, lags, scale),
        };
        for m in members {
            let at = p.data.len() as u32;
            let vars0 = p.vidx.len() as u32;
            p.vidx.extend_from_slice(&m.vidx);
            p.data.extend_from_slice(&m.cst);
            p.data.extend_from_slice(&m.dlin);
            let runs0 = p.runs.len() as u32;
            for r in nonzero_chunks(&m.base) {
                p.data
                    .extend_from_slice(&m.base[r.start as usize * 8..r.end as usize * 8]);
                p.runs.push(r);
            }
            p.data.extend_from_slice(&m.base[whole..]);
            p.slots.push(Slot {
                at,
                vars: [vars0, p.vidx.len() as u32],
                runs: [runs0, p.runs.len() as u32],
            });
        }
        p
    }

    /// Member `m`'s lag-dependent entries and where its numbers start.
    #[inline(always)]
    fn parts(&self, m: usize) -> (&[u32], &[f64], &[f64], &[f64]) {
        let s = self.slots[m];
        let vidx = &self.vidx[s.vars[0] as usize..s.vars[1] as usize];
        let at = s.at as usize;
        let n = self.lags * (1 + vidx.len());
        let (cst, dlin) = self.data[at..at + n].split_at(self.lags);
        (vidx, cst, dlin, &self.data[at + n..])
    }

    /// Member `m`'s profile log-likelihood of the block sums `y` from its best lag's correction
    /// `lag`: the base dot product plus `lag`.
    #[inline(always)]
    fn score_with(&self, m: usize, y: &[f64], lag: f64) -> f64 {
        let s = self.slots[m];
        let runs = &self.runs[s.runs[0] as usize..s.runs[1] as usize];
        let [lin] = dot_group::<1>(self.parts(m).3, y, runs);
        lin + lag
    }

    /// Member `m`'s best lag's correction.
    #[inline(always)]
    fn lag_of(&self, m: usize, y: &[f64]) -> f64 {
        let (vidx, cst, dlin, _) = self.parts(m);
        best_lag(cst, dlin, vidx, y)
    }

    /// Every member's score (what [`Packed::log_likelihoods`] computes for the members it does
    /// not leave out).
    #[cfg(test)]
    fn scores(&self, y: &[f64]) -> Vec<f64> {
        (0..self.slots.len())
            .map(|m| self.score_with(m, y, self.lag_of(m, y)))
            .collect()
    }

    /// Per range of members (a hypothesis), the log-sum-exp of their scores minus ln n (−∞ for an
    /// empty range), and the number of members scored. Within a range the member with the largest
    /// bound ([`Bounds`]) is scored first, then the others in order; one whose bound (first
    /// without, then with its exact lag correction) lies more than [`SKIP_GAP`] below the best
    /// score so far is left out, since its term of the log-sum-exp would be +0 (which members
    /// are left out depends on the order, the result does not). The result is that of every
    /// member scored, bit for bit. The same arithmetic in the same order on every CPU; where the CPU has
    /// AVX2 the loops are compiled for its wider registers.
    fn log_likelihoods(&self, y: &[f64], ranges: &[std::ops::Range<usize>]) -> (Vec<f64>, usize) {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, checked just above.
            return unsafe { self.log_likelihoods_avx2(y, ranges) };
        }
        self.log_likelihoods_plain(y, ranges)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn log_likelihoods_avx2(
        &self,
        y: &[f64],
        ranges: &[std::ops::Range<usize>],
    ) -> (Vec<f64>, usize) {
        self.log_likelihoods_plain(y, ranges)
    }

    /// The loop of [`Packed::log_likelihoods`], as plain loops so that all of it is compiled
    /// into the caller.
    #[inline(always)]
    fn log_likelihoods_plain(
        &self,
        y: &[f64],
        ranges: &[std::ops::Range<usize>],
    ) -> (Vec<f64>, usize) {
        let p = self.bounds.project(y);
        let mut out = Vec::with_capacity(ranges.len());
        let mut scored = 0;
        // Per member of the range: its bound and its bound without the lag term.
        let mut bounds: Vec<(f64, f64)> = Vec::new();
        let mut scores: Vec<f64> = Vec::new();
        for r in ranges {
            if r.is_empty() {
                out.push(f64::NEG_INFINITY);
                continue;
            }
            bounds.clear();
            let (mut first, mut top) = (r.start, f64::NEG_INFINITY);
            for m in r.clone() {
                let (base, lag) = self.bounds.of(m, &p, y);
                // A bound that is not a number (a reading beyond any scale) leaves out nothing.
                let bound = base + lag;
                let bound = if bound.is_nan() { f64::INFINITY } else { bound };
                if bound > top {
                    (first, top) = (m, bound);
                }
                bounds.push((bound, base));
            }
            scores.clear();
            scores.resize(r.len(), f64::NEG_INFINITY);
            let (mut best, mut here) = (f64::NEG_INFINITY, 0);
            for m in std::iter::once(first).chain(r.clone().filter(|&m| m != first)) {
                let (bound, base) = bounds[m - r.start];
                if bound < best - SKIP_GAP {
                    continue;
                }
                let lag = self.lag_of(m, y);
                if base + lag < best - SKIP_GAP {
                    continue;
                }
                let s = self.score_with(m, y, lag);
                here += 1;
                scores[m - r.start] = s;
                best = best.max(s);
            }
            scored += here;
            // One finite score s alone: its log-sum-exp is s + ln(e⁰) = s + 0.
            let lse = if here == 1 && best.is_finite() {
                best + 0.0
            } else {
                log_sum_exp(&scores)
            };
            out.push(lse - (r.len() as f64).ln());
        }
        (out, scored)
    }
}

/// The dot products of `G` base vectors packed side by side (`a`: per chunk of eight listed by
/// `runs`, each vector's chunk in turn, then each vector's entries after the last whole chunk)
/// with the full vector `y`; [`Packed`] keeps one vector per member (`G` = 1). Per vector: eight independent accumulators over the
/// chunks, summed, plus the tail's sequential sum — [`dot`] bit for bit (a product with an
/// all-zero chunk is ±0, which leaves an accumulator as it was).
#[inline(always)]
fn dot_group<const G: usize>(a: &[f64], y: &[f64], runs: &[std::ops::Range<u32>]) -> [f64; G] {
    let mut acc = [[0.0; 8]; G];
    let whole = y.len() / 8 * 8;
    let mut k = 0;
    for r in runs {
        for c in r.start as usize..r.end as usize {
            let yc: &[f64; 8] = y[c * 8..c * 8 + 8].try_into().expect("a chunk");
            for (j, acc) in acc.iter_mut().enumerate() {
                let xc: &[f64; 8] = a[k + j * 8..k + j * 8 + 8].try_into().expect("a chunk");
                for i in 0..8 {
                    acc[i] += xc[i] * yc[i];
                }
            }
            k += 8 * G;
        }
    }
    let tail = y.len() - whole;
    let mut out = [0.0; G];
    for (j, o) in out.iter_mut().enumerate() {
        let mut t = -0.0;
        for i in 0..tail {
            t += a[k + j * tail + i] * y[whole + i];
        }
        let mut sum = -0.0;
        for v in acc[j] {
            sum += v;
        }
        *o = sum + t;
    }
    out
}

/// The best lag's correction: max over the lags o of `cst[o]` + Σ_e y[vidx[e]] · dlin[e][o]
/// (each lag's sum in the order of the entries), four lags at a time.
#[inline(always)]
fn best_lag(cst: &[f64], dlin: &[f64], vidx: &[u32], y: &[f64]) -> f64 {
    let lags = cst.len();
    let mut ys = [0.0; MAX_VARYING];
    for (v, &d) in ys.iter_mut().zip(vidx) {
        *v = y[d as usize];
    }
    let ys = &ys[..vidx.len()];
    let mut best = [f64::NEG_INFINITY; 4];
    let four = lags / 4 * 4;
    for o in (0..four).step_by(4) {
        let mut v: [f64; 4] = cst[o..o + 4].try_into().expect("four lags");
        for (e, &yd) in ys.iter().enumerate() {
            let row: &[f64; 4] = dlin[e * lags + o..e * lags + o + 4]
                .try_into()
                .expect("four lags");
            for i in 0..4 {
                v[i] += yd * row[i];
            }
        }
        for i in 0..4 {
            best[i] = best[i].max(v[i]);
        }
    }
    let mut rest = f64::NEG_INFINITY;
    for o in four..lags {
        let mut v = cst[o];
        for (e, &yd) in ys.iter().enumerate() {
            v += yd * dlin[e * lags + o];
        }
        rest = rest.max(v);
    }
    best[0].max(best[1]).max(best[2].max(best[3])).max(rest)
}

/// The `likelihood` classifier: a matched filter of the reading against the hypotheses' template
/// ensembles under the sensor's noise model.
pub struct Likelihood {
    /// The members' numbers, packed for the scoring of a reading.
    packed: Packed,
    /// Members of each hypothesis: a range into the packed members.
    ranges: Vec<std::ops::Range<usize>>,
    /// Samples before k_b in the frame, frame length, block length, blocks per channel.
    pre: usize,
    block: usize,
    blocks: usize,
    detector: common::Detector,
    sensor: SensorSettings,
    options: ClassifierOptions,
}

/// Pass 1 of training: what the templates span and how the detector sees them.
struct Survey {
    /// The detector's delays (samples) from each member's true contact begin, over the phases.
    delays: Vec<f64>,
    /// The longest member's contact span (s).
    longest: f64,
    /// Per channel, the largest magnitude of the clean samples.
    scale: [f64; CHANNELS],
}

impl Survey {
    /// Sample every member cleanly at every phase: spans, the detector's delays, channel scales.
    fn new(
        templates: &TemplateSet,
        sensor: &SensorSettings,
        detector: &common::Detector,
        dt: f64,
    ) -> Survey {
        let p = PHASES as f64;
        let mut delays: Vec<f64> = Vec::new();
        let mut longest: f64 = 0.0;
        let mut scale = [0.0f64; CHANNELS];
        for members in &templates.members {
            for s in members {
                let Some((b, e)) = s.span() else { continue };
                longest = longest.max(e - b);
                for ph in 0..PHASES {
                    let phase = (ph as f64 + 0.5) / p;
                    let Some((t0, v)) = reading::sample_clean(s, sensor, phase) else {
                        continue;
                    };
                    if let Some((kb, _)) = detector.detect(&v) {
                        delays.push((t0 + kb as f64 * dt - b) / dt);
                    }
                    for x in &v {
                        for c in 0..CHANNELS {
                            scale[c] = scale[c].max(x[c].abs());
                        }
                    }
                }
            }
        }
        Survey {
            delays,
            longest,
            scale,
        }
    }
}

/// The frame, its blocks, the lag grid and the channel weights that pass 2 of training fills.
struct Frame {
    /// Lag grid (in steps of dt/[`PHASES`]): first, last and base lag.
    o_lo: i64,
    o_hi: i64,
    o_base: i64,
    /// Whole-sample lags of the first and last lag.
    l_lo: i64,
    l_hi: i64,
    /// Number of lags.
    lags: usize,
    /// Samples before k_b in the frame, frame length, block length, blocks per channel.
    pre: usize,
    frame: usize,
    block: usize,
    blocks: usize,
    /// Entries per member vector (used channels × blocks).
    dims: usize,
    /// Per used channel, the weight 1/σ² of the noise model.
    w: Vec<f64>,
}

impl Frame {
    /// Lay out the lag grid from the detector's delays, the frame and its blocks from the longest
    /// span, and the channel weights from the sensor's noise floored by the channel scales.
    fn new(survey: &Survey, sensor: &SensorSettings, dt: f64) -> Frame {
        let p = PHASES as f64;
        let delays = &survey.delays;
        let dmin = delays.iter().copied().fold(f64::INFINITY, f64::min);
        let dmax = delays.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mut o_lo = ((dmin - LAG_SAMPLES as f64) * p).floor() as i64;
        let mut o_hi = ((dmax + LAG_SAMPLES as f64) * p).ceil() as i64;
        while (o_hi - o_lo + 1) as usize > MAX_LAGS {
            o_lo += 1;
            if (o_hi - o_lo + 1) as usize > MAX_LAGS {
                o_hi -= 1;
            }
        }
        let lags = (o_hi - o_lo + 1) as usize;
        let o_base = ((0.5 * (dmin + dmax)) * p).round() as i64;
        let o_base = o_base.clamp(o_lo, o_hi);
        let l_lo = o_lo.div_euclid(PHASES as i64);
        let l_hi = o_hi.div_euclid(PHASES as i64);
        // Frame: from k_b − pre; the template at lag o sits at (i − pre)·dt + o·dt/P from its begin.
        let pre = (l_hi.max(0) + 2) as usize;
        let frame = pre + (survey.longest / dt).ceil() as usize + (-l_lo).max(0) as usize + 4;
        let block = frame.div_ceil(MAX_BLOCKS).max(1);
        let blocks = frame.div_ceil(block);
        let frame = blocks * block;
        let dims = USED.len() * blocks;
        let w: Vec<f64> = USED
            .iter()
            .map(|&c| {
                let floor = (1e-3 * survey.scale[c]).max(1e-12);
                1.0 / common::noise_var(sensor, c).max(floor * floor)
            })
            .collect();
        Frame {
            o_lo,
            o_hi,
            o_base,
            l_lo,
            l_hi,
            lags,
            pre,
            frame,
            block,
            blocks,
            dims,
            w,
        }
    }

    /// Block sums of member `s` (contact begin `b`) per lag, with the sensor's low-pass.
    fn lag_sums(
        &self,
        s: &crate::sensing::ContactSignal,
        b: f64,
        sensor: &SensorSettings,
        dt: f64,
    ) -> Vec<Vec<f64>> {
        let p = PHASES as f64;
        let (pre, frame, l_lo) = (self.pre, self.frame, self.l_lo);
        let (blocks, block, dims) = (self.blocks, self.block, self.dims);
        let span_l = (self.l_hi - l_lo) as usize;
        // fine[φ][j] = s(b + (j − pre + l_lo + φ/P)·dt)
        let fine: Vec<Vec<[f64; CHANNELS]>> = (0..PHASES)
            .map(|ph| {
                s.at_each((0..frame + span_l + 1).map(|j| {
                    let tau = (j as f64 - pre as f64 + l_lo as f64 + ph as f64 / p) * dt;
                    b + tau
                }))
            })
            .collect();
        (self.o_lo..=self.o_hi)
            .map(|o| {
                let l = o.div_euclid(PHASES as i64);
                let ph = o.rem_euclid(PHASES as i64) as usize;
                let off = (l - l_lo) as usize;
                let mut v: Vec<[f64; CHANNELS]> = fine[ph][off..off + frame].to_vec();
                reading::lowpass(&mut v, sensor);
                // Entry ci·blocks + k: channel USED[ci] summed over block k, in sample order
                // (the frame is whole blocks).
                debug_assert_eq!(v.len(), blocks * block);
                let mut out = vec![0.0; dims];
                for (k, chunk) in v.chunks(block).enumerate() {
                    let mut acc = [0.0; USED.len()];
                    for x in chunk {
                        for (a, &c) in acc.iter_mut().zip(&USED) {
                            *a += x[c];
                        }
                    }
                    for (ci, a) in acc.into_iter().enumerate() {
                        out[ci * blocks + k] = a;
                    }
                }
                out
            })
            .collect()
    }

    /// Train one member `s` (contact begin `b`): its base vector, constant terms and
    /// lag-dependent entries.
    fn member(
        &self,
        s: &crate::sensing::ContactSignal,
        b: f64,
        sensor: &SensorSettings,
        dt: f64,
    ) -> Member {
        let (dims, blocks, block, lags) = (self.dims, self.blocks, self.block, self.lags);
        let w = &self.w;
        let sums = self.lag_sums(s, b, sensor, dt);
        let sb = &sums[(self.o_base - self.o_lo) as usize];
        let wb = |d: usize| w[d / blocks] / block as f64;
        let cst0: f64 = (0..dims).map(|d| -0.5 * wb(d) * sb[d] * sb[d]).sum();
        let base: Vec<f64> = (0..dims).map(|d| wb(d) * sb[d]).collect();
        // Lag-dependent entries, most important first.
        let mut imp: Vec<(f64, usize)> = (0..dims)
            .map(|d| {
                let m = sums
                    .iter()
                    .map(|so| (so[d] - sb[d]).abs())
                    .fold(0.0, f64::max);
                (m * wb(d).sqrt(), d)
            })
            .filter(|&(m, _)| m > 1e-6)
            .collect();
        imp.sort_by(|a, b| b.0.total_cmp(&a.0));
        imp.truncate(MAX_VARYING);
        let vidx: Vec<u32> = imp.iter().map(|&(_, d)| d as u32).collect();
        let mut dlin = Vec::with_capacity(vidx.len() * lags);
        let mut cst = vec![cst0; lags];
        for &d in &vidx {
            let d = d as usize;
            for (o, so) in sums.iter().enumerate() {
                dlin.push(wb(d) * (so[d] - sb[d]));
                cst[o] -= 0.5 * wb(d) * (so[d] * so[d] - sb[d] * sb[d]);
            }
        }
        Member {
            base,
            cst,
            vidx,
            dlin,
        }
    }
}

impl Likelihood {
    /// Train on `templates` for `sensor`. Templates whose contacts the detector never sees give a
    /// classifier that answers Unknown to every reading.
    pub fn new(
        templates: &TemplateSet,
        sensor: &SensorSettings,
        options: &ClassifierOptions,
    ) -> Likelihood {
        let dt = 1.0 / sensor.rate;
        let detector = common::Detector::new(sensor);
        // Pass 1: spans, the detector's delays, channel scales.
        let survey = Survey::new(templates, sensor, &detector, dt);
        if survey.delays.is_empty() {
            // The detector sees none of the templates' contacts at this noise level: no reading
            // of these pushes will be detected either, so every answer is Unknown.
            return Likelihood {
                packed: Packed::new(&[], 0, 0, &[]),
                ranges: Vec::new(),
                pre: 0,
                block: 1,
                blocks: 0,
                detector,
                sensor: *sensor,
                options: *options,
            };
        }
        let f = Frame::new(&survey, sensor, dt);

        // Pass 2: block sums per member and lag.
        let mut members = Vec::new();
        let mut ranges = Vec::new();
        for ms in &templates.members {
            let start = members.len();
            for s in ms {
                let Some((b, _)) = s.span() else { continue };
                members.push(f.member(s, b, sensor, dt));
            }
            ranges.push(start..members.len());
        }
        let scale: Vec<f64> = (0..f.dims)
            .map(|d| (f.w[d / f.blocks] / f.block as f64).sqrt())
            .collect();
        Likelihood {
            packed: Packed::new(&members, f.dims, f.lags, &scale),
            ranges,
            pre: f.pre,
            block: f.block,
            blocks: f.blocks,
            detector,
            sensor: *sensor,
            options: *options,
        }
    }

    /// The reading's block sums on the frame anchored at its detected begin; `None` without a
    /// detected contact or with bad values.
    fn block_sums(&self, r: &Reading) -> Option<Vec<f64>> {
        let Reading::Ft(s) = r else { return None };
        let v = common::clean_values(s, &self.sensor)?;
        let kb = self.detector.first(&v)?;
        let mut y = vec![0.0; USED.len() * self.blocks];
        let first = kb as i64 - self.pre as i64;
        let lo = (-first).max(0) as usize;
        let hi = ((v.len() as i64 - first).max(0) as usize).min(self.blocks * self.block);
        for b in 0..self.blocks {
            let (s0, s1) = ((b * self.block).max(lo), ((b + 1) * self.block).min(hi));
            if s0 >= s1 {
                continue;
            }
            let k0 = (first + s0 as i64) as usize;
            let mut acc = [0.0; 5];
            for x in &v[k0..k0 + (s1 - s0)] {
                for (a, &c) in acc.iter_mut().zip(&USED) {
                    *a += x[c];
                }
            }
            for (ci, a) in acc.iter().enumerate() {
                y[ci * self.blocks + b] = *a;
            }
        }
        Some(y)
    }

    /// log p(reading | h) per hypothesis (up to a common constant); `None` when no contact is
    /// detected.
    pub fn log_likelihoods(&self, r: &Reading) -> Option<Vec<f64>> {
        if self.packed.slots.is_empty() {
            return None;
        }
        let y = self.block_sums(r)?;
        // A hypothesis without a template that makes a detectable contact gets −∞: a reading with
        // a contact cannot come from it.
        Some(self.packed.log_likelihoods(&y, &self.ranges).0)
    }
}

/// The runs of whole chunks of eight entries of `a` that hold a non-zero value, as chunk index
/// ranges; the entries after the last whole chunk are always summed (see [`dot_group`]).
fn nonzero_chunks(a: &[f64]) -> Vec<std::ops::Range<u32>> {
    let mut out: Vec<std::ops::Range<u32>> = Vec::new();
    for (k, c) in a.chunks_exact(8).enumerate() {
        if c.iter().all(|&x| x == 0.0) {
            continue;
        }
        let k = k as u32;
        match out.last_mut() {
            Some(r) if r.end == k => r.end = k + 1,
            _ => out.push(k..k + 1),
        }
    }
    out
}

/// A dot product with eight independent accumulators (a plain sequential sum cannot vectorise).
#[cfg(test)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 8];
    let ca = a.chunks_exact(8);
    let cb = b.chunks_exact(8);
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ca.zip(cb) {
        for i in 0..8 {
            acc[i] += x[i] * y[i];
        }
    }
    acc.iter().sum::<f64>() + tail
}

impl Classifier for Likelihood {
    fn name(&self) -> &'static str {
        "likelihood"
    }

    fn classify(&self, r: &Reading) -> Classification {
        match self.log_likelihoods(r) {
            Some(ll) if ll.iter().all(|x| !x.is_nan()) => {
                decide(common::posterior(&ll), self.options.reject_below)
            }
            _ => Classification::unknown(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    /// `n` values in (−`scale`, `scale`) broken by quiet runs (zeros) of random length about
    /// `run`, as a template's base vector outside its contact.
    fn quiet_runs(
        rng: &mut crate::random::ChaCha8Rng,
        n: usize,
        run: usize,
        scale: f64,
    ) -> Vec<f64> {
        (0..n)
            .map(|i| {
                if (i / run + rng.random_range(0..3)) % 3 == 0 {
                    rng.random_range(-scale..scale)
                } else {
                    0.0
                }
            })
            .collect()
    }

    /// Skipping the all-zero chunks of a template's base vector gives the full dot product bit
    /// for bit, for every pattern of quiet runs and lengths that are not a multiple of eight.
    #[test]
    fn dot_over_nonzero_chunks_is_the_full_dot_bit_for_bit() {
        let mut rng = crate::random::stream(7, 0);
        for n in [1usize, 7, 8, 9, 40, 235, 240] {
            for _ in 0..200 {
                let a = quiet_runs(&mut rng, n, 5, 1e6);
                let b: Vec<f64> = (0..n).map(|_| rng.random_range(-1e3..1e3)).collect();
                let chunks = nonzero_chunks(&a);
                assert!(chunks.iter().all(|r| r.start < r.end));
                let whole = n / 8 * 8;
                let packed: Vec<f64> = chunks
                    .iter()
                    .flat_map(|r| a[r.start as usize * 8..r.end as usize * 8].iter().copied())
                    .collect();
                let packed = [packed, a[whole..].to_vec()].concat();
                let [fast] = dot_group::<1>(&packed, &b, &chunks);
                assert_eq!(fast.to_bits(), dot(&a, &b).to_bits());
            }
            let zero = vec![0.0; n];
            assert!(nonzero_chunks(&zero).is_empty());
        }
    }

    /// A member's score as the plain formula gives it: the full dot product of its base vector,
    /// then each lag's corrections in entry order, then the largest over the lags.
    fn naive_score(m: &Member, y: &[f64], lags: usize) -> f64 {
        let mut acc = m.cst.clone();
        for (e, &d) in m.vidx.iter().enumerate() {
            for (o, a) in acc.iter_mut().enumerate() {
                *a += y[d as usize] * m.dlin[e * lags + o];
            }
        }
        dot(&m.base, y) + acc.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }

    /// The packed layout (base vectors without their all-zero chunks, constants and lag rows in
    /// one stream, four lags at a time) scores hand-made members exactly as the plain formula.
    #[test]
    fn packed_scores_are_the_plain_formula_bit_for_bit() {
        let mut rng = crate::random::stream(11, 0);
        for (dims, lags) in [(5usize, 1usize), (21, 5), (40, 8), (240, 24), (235, 23)] {
            let members: Vec<Member> = (0..6)
                .map(|_| {
                    let base = quiet_runs(&mut rng, dims, 7, 1e3);
                    let n_var = rng.random_range(0..=MAX_VARYING.min(dims));
                    let vidx: Vec<u32> = (0..n_var)
                        .map(|_| rng.random_range(0..dims) as u32)
                        .collect();
                    Member {
                        base,
                        cst: (0..lags).map(|_| rng.random_range(-1e4..0.0)).collect(),
                        dlin: (0..n_var * lags)
                            .map(|_| rng.random_range(-1e2..1e2))
                            .collect(),
                        vidx,
                    }
                })
                .collect();
            let scale = vec![1.0; dims];
            let packed = Packed::new(&members, dims, lags, &scale);
            for _ in 0..20 {
                let y: Vec<f64> = (0..dims).map(|_| rng.random_range(-10.0..10.0)).collect();
                let fast = packed.scores(&y);
                for (m, f) in members.iter().zip(&fast) {
                    assert_eq!(f.to_bits(), naive_score(m, &y, lags).to_bits());
                }
            }
        }
    }

    /// log-sum-exp over every member's score, without leaving any term out.
    fn full_log_likelihoods(
        packed: &Packed,
        y: &[f64],
        ranges: &[std::ops::Range<usize>],
    ) -> Vec<f64> {
        let s = packed.scores(y);
        ranges
            .iter()
            .map(|r| {
                let v = &s[r.clone()];
                let m = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                if !m.is_finite() {
                    return m;
                }
                m + v.iter().map(|x| (x - m).exp()).sum::<f64>().ln() - (r.len() as f64).ln()
            })
            .collect()
    }

    /// The members' bounds are upper bounds of their scores (without and with the exact lag
    /// correction), and the hypotheses' log-likelihoods with the members the bounds leave out
    /// are those of every member scored, bit for bit — on hand-made members whose scores lie
    /// far apart, so that members are left out, and on members alike, so that few are.
    #[test]
    fn leaving_out_members_by_their_bounds_changes_no_bit() {
        let mut rng = crate::random::stream(13, 0);
        let (mut scored, mut total) = (0, 0);
        let (mut scored_far, mut total_far) = (0, 0);
        for (dims, lags, spread, near) in [
            (40usize, 5usize, 1e3, true),
            (240, 17, 1e3, true),
            (235, 24, 3e2, true),
            (240, 17, 1e3, false),
        ] {
            // Six hypotheses of six members: a hypothesis's members vary about a common shape.
            let mut members = Vec::new();
            for _ in 0..6 {
                let shape = quiet_runs(&mut rng, dims, 7, spread);
                for _ in 0..6 {
                    let base: Vec<f64> = shape
                        .iter()
                        .map(|&x| x * rng.random_range(0.7..1.3) + rng.random_range(-1.0..1.0))
                        .collect();
                    let n_var = rng.random_range(0..=MAX_VARYING.min(dims));
                    let vidx: Vec<u32> = (0..n_var)
                        .map(|_| rng.random_range(0..dims) as u32)
                        .collect();
                    members.push(Member {
                        cst: (0..lags).map(|_| rng.random_range(-1e4..0.0)).collect(),
                        dlin: (0..n_var * lags)
                            .map(|_| rng.random_range(-1e2..1e2))
                            .collect(),
                        vidx,
                        base,
                    });
                }
            }
            let ranges: Vec<std::ops::Range<usize>> = (0..6).map(|h| h * 6..h * 6 + 6).collect();
            let scale: Vec<f64> = (0..dims).map(|_| rng.random_range(0.5..2.0)).collect();
            let packed = Packed::new(&members, dims, lags, &scale);
            for _ in 0..20 {
                // A reading near a member (its block sums base/s², plus noise), or anywhere.
                let like = rng.random_range(0..members.len());
                let y: Vec<f64> = (0..dims)
                    .map(|d| {
                        let noise = rng.random_range(-1.0..1.0);
                        if near {
                            members[like].base[d] / (scale[d] * scale[d]) + noise
                        } else {
                            10.0 * noise
                        }
                    })
                    .collect();
                let p = packed.bounds.project(&y);
                for (m, s) in packed.scores(&y).iter().enumerate() {
                    let (base, lag) = packed.bounds.of(m, &p, &y);
                    assert!(base + lag >= *s, "member {m}: {} < {s}", base + lag);
                    assert!(base + packed.lag_of(m, &y) >= *s, "member {m}");
                }
                let (fast, n) = packed.log_likelihoods(&y, &ranges);
                let (plain, n_plain) = packed.log_likelihoods_plain(&y, &ranges);
                let full = full_log_likelihoods(&packed, &y, &ranges);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&fast), bits(&full));
                assert_eq!(bits(&plain), bits(&full));
                assert_eq!(n, n_plain);
                assert!((6..=36).contains(&n));
                if near {
                    scored += n;
                    total += 36;
                } else {
                    scored_far += n;
                    total_far += 36;
                }
            }
        }
        assert!(scored < total / 2, "{scored} of {total} members scored");
        assert!(
            scored_far > scored,
            "{scored_far} of {total_far} members scored"
        );
        // An empty hypothesis is −∞ and scores nothing.
        let packed = Packed::new(&[], 0, 0, &[]);
        assert_eq!(
            packed.log_likelihoods(&[], std::slice::from_ref(&(0..0))),
            (vec![f64::NEG_INFINITY], 0)
        );
    }

    /// A hypothesis with one member scored takes that score plus 0 without the exponential and
    /// logarithm of the log-sum-exp: the same bits as the log-sum-exp of its scores (the others
    /// −∞), for any finite score.
    #[test]
    fn one_score_alone_is_its_log_sum_exp_bit_for_bit() {
        let mut rng = crate::random::stream(17, 0);
        let mut values = vec![0.0, -0.0, 1e-300, -1e-300, 5e-324, 1e300, -1e300, f64::MAX];
        values.extend((0..200).map(|_| rng.random_range(-1e6..1e6)));
        for x in values {
            for at in 0..3 {
                let mut v = [f64::NEG_INFINITY; 3];
                v[at] = x;
                assert_eq!(log_sum_exp(&v).to_bits(), (x + 0.0).to_bits(), "{x}");
            }
        }
    }

    /// The log-likelihoods compiled for AVX2 (where the CPU has it) are those of the plain loops
    /// and of every member scored, bit for bit: the dispatch changes the registers, not the
    /// arithmetic.
    #[test]
    fn member_scores_are_the_same_on_every_code_path() {
        use crate::mechanics::{PartModel, Support};
        use crate::sensing::templates::{simulate, PushSetup};
        let poly = crate::geometry::part_from_spec("tripoly1").unwrap();
        let model = PartModel::new(&poly, &Support::Uniform).unwrap();
        let setup = PushSetup::nominal(poly.clone(), -0.2);
        let members: Vec<Vec<_>> = [45.0, 135.0, 260.0]
            .iter()
            .map(|&deg| {
                [-0.25, -0.2, -0.15]
                    .iter()
                    .map(|&d| simulate(&setup, &model, deg, d, 0.5).signal)
                    .collect()
            })
            .collect();
        let templates = TemplateSet {
            labels: vec!["a".into(), "b".into(), "c".into()],
            members,
        };
        let sensor = SensorSettings::default();
        let lik = Likelihood::new(&templates, &sensor, &ClassifierOptions::default());
        let mut rng = crate::random::stream(3, 1);
        let mut compared = 0;
        for deg in [50.0, 140.0, 250.0] {
            let pass = simulate(&setup, &model, deg, -0.2, 0.5);
            let r = reading::read(&pass.signal, &sensor, &mut rng).expect("a reading");
            let Some(y) = lik.block_sums(&r) else {
                continue;
            };
            let (plain, _) = lik.packed.log_likelihoods_plain(&y, &lik.ranges);
            let (used, _) = lik.packed.log_likelihoods(&y, &lik.ranges);
            let full = full_log_likelihoods(&lik.packed, &y, &lik.ranges);
            assert_eq!(plain.len(), 3);
            assert!(plain.iter().all(|x| x.is_finite()));
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&plain), bits(&used));
            assert_eq!(bits(&plain), bits(&full));
            compared += 1;
        }
        assert!(
            compared >= 2,
            "readings with a detected contact: {compared}"
        );
    }
}
