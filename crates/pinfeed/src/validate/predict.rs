//! What an ensemble predicts for each measured row: `passes` passes of every member from the
//! row's input state at the row's d ([`crate::maps::ensemble::Member::pass`]). Rows with the same
//! part, d and input (a thesis-style table's bands at one d) share one prediction: number the
//! distinct (part, d, input) in order of first appearance g = 0, 1, …; pass q of member i for
//! prediction g is pass number g · passes + q of that member, so its jitter and θ0 draw are fixed
//! by (seed, i, g, q) whatever the thread count. Members are compiled once per part; a member's
//! draw (μc, support choice, pin radius) is the same for every part.

use super::measured::Measured;
use crate::maps::ensemble::{
    members, stable_states_deg, EnsembleError, EnsembleSpec, Member, MemberDraw,
};
use rayon::prelude::*;

/// The predicted final orientations of every row.
#[derive(Debug, Clone, PartialEq)]
pub struct Predictions {
    /// θf (degrees) per row, index member · passes + q.
    pub rows: Vec<Vec<f64>>,
    /// The members' draws, in member order.
    pub members: Vec<MemberDraw>,
    /// Passes per member and row.
    pub passes: usize,
}

impl Predictions {
    /// Member weights expanded to one weight per pass.
    pub fn pass_weights(&self, member_weights: &[f64]) -> Vec<f64> {
        member_weights
            .iter()
            .flat_map(|&w| std::iter::repeat_n(w, self.passes))
            .collect()
    }
}

/// Predict every row of `measured` with `n` members of the ensemble `spec` seeded with `seed`.
pub fn predict(
    measured: &Measured,
    spec: &EnsembleSpec,
    seed: u64,
    n: usize,
    passes: usize,
) -> Result<Predictions, EnsembleError> {
    predict_observed(measured, spec, seed, n, passes, &crate::progress::silent)
}

/// [`predict`], telling `progress` the passes run of all those needed.
pub fn predict_observed(
    measured: &Measured,
    spec: &EnsembleSpec,
    seed: u64,
    n: usize,
    passes: usize,
    progress: crate::progress::Report,
) -> Result<Predictions, EnsembleError> {
    let compiled: Vec<(String, Vec<Member>, Vec<f64>)> = measured
        .parts
        .iter()
        .map(|(name, poly)| {
            let m = members(poly, spec, seed, n)?;
            Ok((name.clone(), m, stable_states_deg(poly)))
        })
        .collect::<Result<_, EnsembleError>>()?;
    // The distinct (part, d, input) in order of first appearance, and each row's among them.
    let mut groups: Vec<(&str, u64, String)> = Vec::new();
    let group_of: Vec<usize> = measured
        .rows
        .iter()
        .map(|row| {
            let key = (row.part.as_str(), row.d.to_bits(), row.input.label());
            match groups.iter().position(|g| *g == key) {
                Some(g) => g,
                None => {
                    groups.push(key);
                    groups.len() - 1
                }
            }
        })
        .collect();
    let tally = crate::progress::Tally::new((groups.len() * n * passes) as u64, progress);
    let mut predicted: Vec<Option<Vec<f64>>> = vec![None; groups.len()];
    for (row, &g) in measured.rows.iter().zip(&group_of) {
        if predicted[g].is_some() {
            continue;
        }
        let (_, ms, states) = compiled
            .iter()
            .find(|(p, _, _)| *p == row.part)
            .expect("every row's part is compiled");
        let poly = measured.polygon(&row.part);
        predicted[g] = Some(
            (0..n * passes)
                .into_par_iter()
                .map(|x| {
                    let (i, q) = (x / passes, x % passes);
                    let pass = (g * passes + q) as u64;
                    let theta = ms[i].pass(poly, spec, &row.input, states, row.d, pass);
                    tally.add(1);
                    theta
                })
                .collect(),
        );
    }
    let rows = group_of
        .iter()
        .map(|&g| predicted[g].clone().expect("every group is predicted"))
        .collect();
    let draws = compiled
        .first()
        .map(|(_, ms, _)| ms.iter().map(|m| m.draw).collect())
        .unwrap_or_default();
    Ok(Predictions {
        rows,
        members: draws,
        passes,
    })
}
