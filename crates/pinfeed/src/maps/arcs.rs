//! Arcs of the circle of orientations (degrees) and the arithmetic measured bands are judged with:
//! containment, overlap, centres, the share of the circle a set of arcs covers, and the smallest
//! set of arcs that holds a given share of a sample of angles (a highest-density region).
//!
//! An arc starts at `lo` (wrapped to [0°, 360°)) and runs `width` degrees counter-clockwise
//! (0 ≤ width ≤ 360); its upper end `lo + width`, wrapped, is smaller than `lo` when the arc
//! straddles 0°/360°, the convention of the band tables ([`super::Band`]).

use super::runs::{circular_runs, run_indices};
use crate::geometry::wrap_deg;
use serde::Serialize;

/// A counter-clockwise arc of orientations (degrees).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Arc {
    /// Lower end, in [0, 360).
    pub lo: f64,
    /// Arc length, in [0, 360].
    pub width: f64,
}

impl Arc {
    /// The arc from `min` to `max` counter-clockwise (both in degrees, any range): `max < min`
    /// straddles 0°/360°; `min == max` is a single angle.
    pub fn from_ends(min: f64, max: f64) -> Arc {
        Arc {
            lo: wrap_deg(min),
            width: wrap_deg(max - min),
        }
    }

    /// The arc a user writes as [min, max] degrees (each in [0, 360]): [0, 360] (max − min = 360)
    /// is the whole circle, not the point at 0° that wrapping its ends would make.
    pub fn from_measured_ends(min: f64, max: f64) -> Arc {
        if max - min >= 360.0 {
            Arc::full()
        } else {
            Arc::from_ends(min, max)
        }
    }

    /// The whole circle.
    pub fn full() -> Arc {
        Arc {
            lo: 0.0,
            width: 360.0,
        }
    }

    /// Upper end, wrapped to [0, 360).
    pub fn hi(&self) -> f64 {
        wrap_deg(self.lo + self.width)
    }

    /// Midpoint of the arc, wrapped.
    pub fn centre(&self) -> f64 {
        wrap_deg(self.lo + self.width / 2.0)
    }

    /// Offset of `angle` from the lower end along the arc's direction, in [0, 360).
    fn offset(&self, angle: f64) -> f64 {
        wrap_deg(angle - self.lo)
    }

    /// Does the arc hold `angle` (ends included, to 1e-9°)?
    pub fn contains_angle(&self, angle: f64) -> bool {
        let o = self.offset(angle);
        o <= self.width + 1e-9 || 360.0 - o < 1e-9
    }

    /// Does the arc hold all of `other`?
    pub fn contains(&self, other: &Arc) -> bool {
        if self.width >= 360.0 {
            return true;
        }
        let o = self.offset(other.lo);
        let o = if 360.0 - o < 1e-9 { 0.0 } else { o };
        o + other.width <= self.width + 1e-9
    }

    /// Do the two arcs share at least one angle?
    pub fn overlaps(&self, other: &Arc) -> bool {
        self.contains_angle(other.lo) || other.contains_angle(self.lo)
    }

    /// The arc widened by `pad` degrees at each end (the whole circle once it closes).
    pub fn widened(&self, pad: f64) -> Arc {
        let width = self.width + 2.0 * pad;
        if width >= 360.0 {
            return Arc::full();
        }
        Arc {
            lo: wrap_deg(self.lo - pad),
            width: width.max(0.0),
        }
    }
}

/// Signed smallest rotation from `from` to `to` (degrees, in (−180, 180]).
pub fn signed_difference(from: f64, to: f64) -> f64 {
    let d = wrap_deg(to - from);
    if d > 180.0 {
        d - 360.0
    } else {
        d
    }
}

/// Share of the circle covered by the union of `arcs` (overlaps counted once), in [0, 1].
pub fn coverage_share(arcs: &[Arc]) -> f64 {
    // 3600 cells of 0.1°: exact enough for a share, and immune to how the arcs overlap.
    const CELLS: usize = 3600;
    let cell = 360.0 / CELLS as f64;
    let covered = (0..CELLS)
        .filter(|&c| {
            let mid = (c as f64 + 0.5) * cell;
            arcs.iter().any(|a| a.contains_angle(mid))
        })
        .count();
    covered as f64 / CELLS as f64
}

/// A predicted band: an arc and the share of the predicted angles that fall in it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MassArc {
    /// The arc of final angles.
    pub arc: Arc,
    /// Share of the predicted angles in it, in [0, 1].
    pub mass: f64,
}

/// The smallest set of arcs (to a resolution of `bin_deg`) that holds at least `mass` of the
/// weighted angles `values` (degrees): bins of the circle are taken in decreasing weight (ties: lower
/// bin first) until their total reaches `mass`; gaps narrower than `join_deg` between taken bins
/// are filled (like the band threshold T of a map, so that sampling noise does not split a band);
/// neighbouring taken bins join into arcs, and each arc is then shrunk to the angles it actually
/// holds. Arcs are ordered by their lower end. Zero total weight gives no arcs.
pub fn highest_density_arcs(
    values: &[f64],
    weights: &[f64],
    mass: f64,
    bin_deg: f64,
    join_deg: f64,
) -> Vec<MassArc> {
    let bins = (360.0 / bin_deg).round().max(1.0) as usize;
    let bin_of = |v: f64| ((wrap_deg(v) / 360.0 * bins as f64) as usize).min(bins - 1);
    let mut hist = vec![0.0; bins];
    for (&v, &w) in values.iter().zip(weights) {
        hist[bin_of(v)] += w;
    }
    let total: f64 = hist.iter().sum();
    if total <= 0.0 {
        return Vec::new();
    }
    let mut order: Vec<usize> = (0..bins).filter(|&b| hist[b] > 0.0).collect();
    order.sort_by(|&a, &b| hist[b].total_cmp(&hist[a]).then(a.cmp(&b)));
    let mut taken = vec![false; bins];
    let mut sum = 0.0;
    for b in order {
        if sum >= mass * total * (1.0 - 1e-12) {
            break;
        }
        taken[b] = true;
        sum += hist[b];
    }
    fill_gaps(&mut taken, (join_deg / bin_deg).round() as usize);
    let runs = circular_runs(&taken);
    let mut run_of: Vec<Option<usize>> = vec![None; bins];
    for (r, &run) in runs.iter().enumerate() {
        for b in run_indices(run, bins) {
            run_of[b] = Some(r);
        }
    }
    // Shrink each run to the angles it holds: offsets from the run's first bin.
    let start = |r: usize| runs[r].0 as f64 * 360.0 / bins as f64;
    let mut ext = vec![(f64::INFINITY, f64::NEG_INFINITY, 0.0); runs.len()];
    for (&v, &w) in values.iter().zip(weights) {
        if let (true, Some(r)) = (w > 0.0, run_of[bin_of(v)]) {
            let o = wrap_deg(v - start(r));
            let e = &mut ext[r];
            *e = (e.0.min(o), e.1.max(o), e.2 + w);
        }
    }
    let mut out: Vec<MassArc> = ext
        .iter()
        .enumerate()
        .map(|(r, &(lo, hi, m))| MassArc {
            arc: Arc {
                lo: wrap_deg(start(r) + lo),
                width: (hi - lo).max(0.0),
            },
            mass: m / total,
        })
        .collect();
    out.sort_by(|a, b| a.arc.lo.total_cmp(&b.arc.lo));
    out
}

/// Mark as taken every circular run of untaken bins shorter than `max_gap` bins that lies between
/// taken bins.
fn fill_gaps(taken: &mut [bool], max_gap: usize) {
    let gaps: Vec<bool> = taken.iter().map(|t| !t).collect();
    if taken.iter().all(|t| !t) {
        return;
    }
    for run in circular_runs(&gaps) {
        let len = run_indices(run, taken.len()).count();
        if len < max_gap {
            for b in run_indices(run, taken.len()).collect::<Vec<_>>() {
                taken[b] = true;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn containment_and_overlap_across_zero() {
        let band = Arc::from_ends(350.0, 10.0);
        assert_eq!(band.width, 20.0);
        assert!(band.contains(&Arc::from_ends(355.0, 5.0)));
        assert!(band.contains(&Arc::from_ends(0.0, 10.0)));
        assert!(!band.contains(&Arc::from_ends(345.0, 5.0)));
        assert!(band.overlaps(&Arc::from_ends(345.0, 351.0)));
        assert!(band.overlaps(&Arc::from_ends(9.0, 30.0)));
        assert!(!band.overlaps(&Arc::from_ends(11.0, 349.0)));
        assert!((band.centre() - 0.0).abs() < 1e-12);
        assert!((signed_difference(350.0, 10.0) - 20.0).abs() < 1e-12);
        assert!((signed_difference(10.0, 350.0) + 20.0).abs() < 1e-12);
    }

    #[test]
    fn coverage_counts_overlaps_once() {
        let arcs = [Arc::from_ends(350.0, 10.0), Arc::from_ends(0.0, 20.0)];
        assert!((coverage_share(&arcs) - 30.0 / 360.0).abs() < 1e-9);
        assert_eq!(coverage_share(&[Arc::full()]), 1.0);
        assert_eq!(coverage_share(&[]), 0.0);
    }

    #[test]
    fn highest_density_arcs_find_two_clusters_one_across_zero() {
        let mut v: Vec<f64> = (0..50).map(|k| 355.0 + k as f64 * 0.2).collect();
        v.extend((0..40).map(|k| 120.0 + k as f64 * 0.1));
        v.extend([200.0, 250.0]);
        let w = vec![1.0; v.len()];
        let arcs = highest_density_arcs(&v, &w, 0.95, 1.0, 0.0);
        assert_eq!(arcs.len(), 2, "{arcs:?}");
        assert!((arcs[0].arc.lo - 120.0).abs() < 1e-9);
        assert!((arcs[1].arc.lo - 355.0).abs() < 1e-9);
        assert!(arcs[1].arc.width > 9.0 && arcs[1].arc.width < 10.0);
        let held: f64 = arcs.iter().map(|a| a.mass).sum();
        assert!((held - 90.0 / 92.0).abs() < 1e-12, "{held}");
        // At 90% one tied bin of the cluster across 0° is left out: it splits in two, unless
        // gaps of a bin are filled.
        assert_eq!(highest_density_arcs(&v, &w, 0.9, 1.0, 0.0).len(), 3);
        assert_eq!(highest_density_arcs(&v, &w, 0.9, 1.0, 2.0).len(), 2);
    }
}
