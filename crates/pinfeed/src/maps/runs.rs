//! Maximal runs of consecutive samples on a circular θ0 grid.
//!
//! Used for the initial-angle sets K_j of a band (thesis eq. 2-17, here allowed to be several runs)
//! and the no-contact intervals NC_j (thesis eq. 3-1). The grid closes on itself: a run that
//! contains both the last and the first sample is one run, reported as [θ_start, θ_end] with
//! θ_start > θ_end (it straddles 0°/360°).

/// Maximal runs of `true` in `mask`, read circularly, as inclusive index pairs (start, end) in
/// increasing order of start; a run through the end of the grid has end < start. A mask that is all
/// `true` is one run (0, n − 1).
pub fn circular_runs(mask: &[bool]) -> Vec<(usize, usize)> {
    let n = mask.len();
    if n == 0 {
        return Vec::new();
    }
    if mask.iter().all(|&m| m) {
        return vec![(0, n - 1)];
    }
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut k = 0;
    while k < n {
        if mask[k] {
            let start = k;
            while k + 1 < n && mask[k + 1] {
                k += 1;
            }
            runs.push((start, k));
        }
        k += 1;
    }
    // A run ending at the last sample continues into one starting at the first.
    if runs.len() > 1 && mask[0] && mask[n - 1] {
        let last = runs.pop().expect("at least two runs");
        runs[0].0 = last.0;
        let wrapped = runs.remove(0);
        runs.push(wrapped);
    }
    runs
}

/// The runs of `mask` as angle ranges `[grid[start], grid[end]]` (degrees).
pub fn circular_ranges(mask: &[bool], grid_deg: &[f64]) -> Vec<[f64; 2]> {
    circular_runs(mask)
        .into_iter()
        .map(|(s, e)| [grid_deg[s], grid_deg[e]])
        .collect()
}

/// The indices covered by a circular run (start, end) on a grid of `n` samples.
pub fn run_indices(run: (usize, usize), n: usize) -> impl Iterator<Item = usize> {
    let (s, e) = run;
    let len = if e >= s { e - s + 1 } else { n - s + e + 1 };
    (0..len).map(move |i| (s + i) % n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mask(s: &str) -> Vec<bool> {
        s.chars().map(|c| c == '1').collect()
    }

    #[test]
    fn plain_runs() {
        assert_eq!(circular_runs(&mask("0110010")), vec![(1, 2), (5, 5)]);
        assert_eq!(circular_runs(&mask("0000")), vec![]);
        assert_eq!(circular_runs(&mask("1111")), vec![(0, 3)]);
        assert_eq!(circular_runs(&[]), vec![]);
    }

    #[test]
    fn a_run_through_the_end_of_the_grid_is_one_run() {
        assert_eq!(circular_runs(&mask("1100111")), vec![(4, 1)]);
        assert_eq!(circular_runs(&mask("1011001")), vec![(2, 3), (6, 0)]);
        assert_eq!(circular_runs(&mask("1000")), vec![(0, 0)]);
        assert_eq!(circular_runs(&mask("0001")), vec![(3, 3)]);
    }

    #[test]
    fn runs_cover_exactly_the_true_samples() {
        let m = mask("110100111011");
        let mut covered = vec![false; m.len()];
        for r in circular_runs(&m) {
            for i in run_indices(r, m.len()) {
                assert!(!covered[i], "index {i} in two runs");
                covered[i] = true;
            }
        }
        assert_eq!(covered, m);
    }
}
