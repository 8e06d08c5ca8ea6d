//! Bands of a configuration map (thesis §2.17, eqs. 2-15, 2-16, 2-18 and 3-2; docs/physics.md#configuration-maps).
//!
//! **Grouping.** The final angles θf of the *contacting* samples are sorted around the circle and
//! neighbours in that order are compared (eq. 2-15: |θf,j+1 − θf,j| < T keeps them in one group).
//! Every gap of at least T between neighbours in sorted final angle ends a band. The comparison is
//! circular: the gap from the largest θf back round to the smallest (+360°) counts like any other,
//! so a band straddling 0°/360° is one band. If no gap reaches T, all contacting samples form one
//! band, cut at the largest gap. Neighbours are taken in sorted θf, not in θ0 order: a band is a
//! set of final orientations, and two θ0 runs that end in the same orientations (different K runs)
//! belong to one band, as in the thesis's Figure 3-3. Each contacting sample is therefore in exactly
//! one band; no-contact samples are in none (they form the NC intervals, see [`super::runs`]).
//!
//! **Angles of a band.** A band is an arc [final_min_deg, final_max_deg] read counter-clockwise,
//! both ends wrapped to [0°, 360°); when it straddles 0° the maximum is smaller than the minimum, and
//! `width_deg` is the arc length. Mean and standard deviation are those of the band's final angles
//! unwrapped onto that arc (so the wrap does not matter, and for a band away from 0° they are the
//! ordinary mean and sample standard deviation, n − 1 in the denominator like Matlab's `std`; 0 for
//! one sample). The adjusted band (eq. 3-2) is [mean − sd, mean + sd], also wrapped; it is not
//! clipped to the raw band. The COM range (eq. 2-18) is [min, max] of the final centroid y of the
//! band's samples (belt frame, part units).

use super::runs::circular_ranges;
use super::{Band, MapSample};
use crate::geometry::wrap_deg;

/// Group angles (degrees, any range) into circular clusters: neighbours in sorted order closer than
/// `threshold_deg` share a cluster. Each cluster lists indices into `angles_deg` in
/// counter-clockwise order from its lower end; clusters are ordered by that lower end (wrapped).
pub fn circular_clusters(angles_deg: &[f64], threshold_deg: f64) -> Vec<Vec<usize>> {
    let m = angles_deg.len();
    if m == 0 {
        return Vec::new();
    }
    let mut order: Vec<(f64, usize)> = angles_deg
        .iter()
        .enumerate()
        .map(|(i, &a)| (wrap_deg(a), i))
        .collect();
    order.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    // gap[k]: from sorted position k to k + 1 (the last one wraps round through 360°).
    let gap = |k: usize| -> f64 {
        if k + 1 < m {
            order[k + 1].0 - order[k].0
        } else {
            order[0].0 + 360.0 - order[m - 1].0
        }
    };
    let mut cuts: Vec<usize> = (0..m).filter(|&k| gap(k) >= threshold_deg).collect();
    if cuts.is_empty() {
        // One band round the whole circle: open it at the widest gap (the first, if tied).
        let widest = (0..m).fold(0, |best, k| if gap(k) > gap(best) { k } else { best });
        cuts.push(widest);
    }
    let mut clusters: Vec<Vec<usize>> = Vec::with_capacity(cuts.len());
    for (c, &cut) in cuts.iter().enumerate() {
        let next_cut = cuts[(c + 1) % cuts.len()];
        let first = (cut + 1) % m;
        let len = (next_cut + m - cut - 1) % m + 1;
        clusters.push((0..len).map(|i| order[(first + i) % m].1).collect());
    }
    clusters.sort_by(|x, y| {
        wrap_deg(angles_deg[x[0]])
            .total_cmp(&wrap_deg(angles_deg[y[0]]))
            .then(x[0].cmp(&y[0]))
    });
    clusters
}

/// Statistics of one band from its member samples (listed counter-clockwise from the lower end)
/// and the θ0 ranges `initial_ranges_deg` that feed it.
fn band_from_members(
    samples: &[MapSample],
    members: &[usize],
    initial_ranges_deg: Vec<[f64; 2]>,
) -> Band {
    let lo = samples[members[0]].theta_final_deg;
    // Offsets along the arc from its lower end, in [0, 360).
    let offsets: Vec<f64> = members
        .iter()
        .map(|&i| wrap_deg(samples[i].theta_final_deg - lo))
        .collect();
    let n = offsets.len() as f64;
    let width = offsets.iter().copied().fold(0.0, f64::max);
    let mean_offset = offsets.iter().sum::<f64>() / n;
    let sd = if offsets.len() > 1 {
        (offsets
            .iter()
            .map(|o| (o - mean_offset) * (o - mean_offset))
            .sum::<f64>()
            / (n - 1.0))
            .sqrt()
    } else {
        0.0
    };
    let mean = lo + mean_offset;
    let com = members.iter().map(|&i| samples[i].com_final_y);
    let com_y_min = com.clone().fold(f64::INFINITY, f64::min);
    let com_y_max = com.fold(f64::NEG_INFINITY, f64::max);
    Band {
        final_min_deg: lo,
        final_max_deg: wrap_deg(lo + width),
        width_deg: width,
        mean_deg: wrap_deg(mean),
        sd_deg: sd,
        adjusted_min_deg: wrap_deg(mean - sd),
        adjusted_max_deg: wrap_deg(mean + sd),
        initial_ranges_deg,
        com_y_min,
        com_y_max,
        samples: members.len(),
    }
}

/// The bands of one map: its contacting samples grouped with threshold `threshold_deg` (degrees),
/// ordered by their lower end, and for each sample (in grid order) the index of its band.
/// `samples` must be the whole θ0 grid in order (for the K_j runs).
pub fn find_bands(samples: &[MapSample], threshold_deg: f64) -> (Vec<Band>, Vec<Option<usize>>) {
    let contacting: Vec<usize> = (0..samples.len()).filter(|&i| samples[i].contact).collect();
    let finals: Vec<f64> = contacting
        .iter()
        .map(|&i| samples[i].theta_final_deg)
        .collect();
    let grid: Vec<f64> = samples.iter().map(|s| s.theta0_deg).collect();
    let mut band_of: Vec<Option<usize>> = vec![None; samples.len()];
    let mut bands = Vec::new();
    for (j, cluster) in circular_clusters(&finals, threshold_deg)
        .into_iter()
        .enumerate()
    {
        let members: Vec<usize> = cluster.iter().map(|&c| contacting[c]).collect();
        for &i in &members {
            band_of[i] = Some(j);
        }
        let mask: Vec<bool> = band_of.iter().map(|b| *b == Some(j)).collect();
        bands.push(band_from_members(
            samples,
            &members,
            circular_ranges(&mask, &grid),
        ));
    }
    (bands, band_of)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clusters_split_at_gaps_of_at_least_the_threshold() {
        let a = [10.0, 12.0, 14.0, 100.0, 103.0, 19.0];
        // 14 → 19 is a gap of 5 = T: a cut (eq. 2-15 groups differences strictly below T).
        let c = circular_clusters(&a, 5.0);
        assert_eq!(c, vec![vec![0, 1, 2], vec![5], vec![3, 4]]);
        let c = circular_clusters(&a, 5.5);
        assert_eq!(c, vec![vec![0, 1, 2, 5], vec![3, 4]]);
    }

    #[test]
    fn a_cluster_straddling_zero_is_one_cluster_listed_from_its_lower_end() {
        let a = [359.0, 1.0, 180.0, 357.5, 2.0, 0.0];
        let c = circular_clusters(&a, 5.0);
        assert_eq!(c, vec![vec![2], vec![3, 0, 5, 1, 4]]);
    }

    #[test]
    fn no_gap_reaching_the_threshold_gives_one_cluster_opened_at_the_widest_gap() {
        let a: Vec<f64> = (0..36)
            .map(|k| k as f64 * 10.0)
            .filter(|&x| x != 100.0)
            .collect();
        let c = circular_clusters(&a, 30.0);
        assert_eq!(c.len(), 1);
        assert_eq!(a[c[0][0]], 110.0);
        assert_eq!(a[*c[0].last().unwrap()], 90.0);
    }

    #[test]
    fn every_angle_lands_in_exactly_one_cluster() {
        let a: Vec<f64> = (0..200).map(|k| ((k * 37) % 360) as f64 * 0.73).collect();
        for t in [0.1, 1.0, 5.0, 20.0, 400.0] {
            let mut seen = vec![0; a.len()];
            for c in circular_clusters(&a, t) {
                for i in c {
                    seen[i] += 1;
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "T = {t}");
        }
    }
}
