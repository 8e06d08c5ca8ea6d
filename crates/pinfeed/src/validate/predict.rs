//! What an ensemble predicts for each measured row: `passes` passes of every member from the
//! row's input state at the row's d ([`crate::maps::ensemble::Member::pass`]). Rows with the same
//! part, d and input (a thesis-style table's bands at one d) share one prediction: number the
//! distinct (part, d, input) in order of first appearance g = 0, 1, …; pass q of member i for
//! prediction g is pass number g · passes + q of that member, so its jitter and θ0 draw are fixed
//! by (seed, i, g, q) whatever the thread count. Members are compiled once per part; a member's
//! draw (μc, support choice, pin radius) is the same for every part.

use super::measured::Measured;
use crate::maps::ensemble::{
    members, serve_passes, stable_states_deg, table_groups, EnsembleError, EnsembleSpec, Member,
    MemberDraw, PassRequest,
};

/// The predicted final orientations of every row.
#[derive(Debug, Clone, PartialEq)]
pub struct Predictions {
    /// θf (degrees) per row, index member · passes + q.
    pub rows: Vec<Vec<f64>>,
    /// The members' draws, in member order.
    pub members: Vec<MemberDraw>,
    /// Passes per member and row.
    pub passes: usize,
    /// The pushes made: passes that are the same push (members sharing a compiled part, μc
    /// and pin radius passing from the same θ0) are made once.
    pub pushes: usize,
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
    let mut first_row: Vec<usize> = Vec::new();
    let group_of: Vec<usize> = measured
        .rows
        .iter()
        .enumerate()
        .map(|(r, row)| {
            let key = (row.part.as_str(), row.d.to_bits(), row.input.label());
            match groups.iter().position(|g| *g == key) {
                Some(g) => g,
                None => {
                    groups.push(key);
                    first_row.push(r);
                    groups.len() - 1
                }
            }
        })
        .collect();
    let tally = crate::progress::Tally::new((groups.len() * n * passes) as u64, progress);
    let mut predicted: Vec<Vec<f64>> = vec![vec![f64::NAN; n * passes]; groups.len()];
    let mut pushes = 0;
    for (name, ms, states) in &compiled {
        let poly = measured.polygon(name);
        let mine: Vec<usize> = (0..groups.len())
            .filter(|&g| groups[g].0 == name.as_str())
            .collect();
        // Every pass of a table group's members (member, prediction, pass in order).
        let tgroups = table_groups(ms);
        let requests_of = |x: usize| -> Vec<PassRequest> {
            let mut req = Vec::with_capacity(tgroups[x].len() * mine.len() * passes);
            for &i in &tgroups[x] {
                for &g in &mine {
                    let row = &measured.rows[first_row[g]];
                    for q in 0..passes {
                        let pass = (g * passes + q) as u64;
                        req.push((i, ms[i].theta0(spec, &row.input, states, pass), row.d));
                    }
                }
            }
            req
        };
        let mut deliver = |x: usize, f: &[f64]| {
            let mut at = f.iter();
            for &i in &tgroups[x] {
                for &g in &mine {
                    for q in 0..passes {
                        predicted[g][i * passes + q] = *at.next().expect("one θf a request");
                    }
                }
            }
        };
        pushes += serve_passes(
            ms,
            tgroups.len(),
            &requests_of,
            (poly, spec),
            &|| tally.add(1),
            &mut deliver,
        );
    }
    let rows = group_of.iter().map(|&g| predicted[g].clone()).collect();
    let draws = compiled
        .first()
        .map(|(_, ms, _)| ms.iter().map(|m| m.draw).collect())
        .unwrap_or_default();
    Ok(Predictions {
        rows,
        members: draws,
        passes,
        pushes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::maps::ensemble::EnsembleSpec;
    use crate::mechanics::Fidelity;

    fn rows() -> Measured {
        let text = "part,d,input,min_deg,max_deg,trials\n\
                    tripoly1,0.3,state:0,0,10,\n\
                    tripoly1,-0.5,theta:30:90,0,10,\n\
                    tripoly1,0.3,state:0,20,30,\n\
                    square,0.2,state:1,0,10,\n";
        crate::validate::measured::parse(std::path::Path::new("t.csv"), text, 0.2).unwrap()
    }

    /// Every row's predictions are its members' own passes, in member order, whichever way the
    /// passes are grouped and shared: rows of one (part, d, input) share one prediction, and
    /// members of one physics passing from a stable state without jitter make one push.
    #[test]
    fn predictions_are_the_members_own_passes() {
        let measured = rows();
        let uncertain = EnsembleSpec::nominal(0.5, 0.0, Fidelity::Exact, 1e-6)
            .with_settings("mu_c=normal:0.5:0.1,support=tripod:0.5,jitter=2")
            .unwrap();
        let fixed = EnsembleSpec::nominal(0.5, 0.0, Fidelity::Exact, 1e-6);
        for (spec, pushes) in [(&uncertain, 3 * 5 * 2), (&fixed, 1 + 5 * 2 + 1)] {
            let (n, passes) = (5, 2);
            let pred = predict(&measured, spec, 11, n, passes).unwrap();
            assert_eq!(pred.pushes, pushes);
            assert_eq!(pred.rows[0], pred.rows[2]);
            for (r, g) in [(0usize, 0usize), (1, 1), (3, 2)] {
                let row = &measured.rows[r];
                let poly = measured.polygon(&row.part);
                let states = stable_states_deg(poly);
                for i in 0..n {
                    let m = Member::new(poly, spec, 11, i as u64).unwrap();
                    for q in 0..passes {
                        let want = m.pass(
                            poly,
                            spec,
                            &row.input,
                            &states,
                            row.d,
                            (g * passes + q) as u64,
                        );
                        let got = pred.rows[r][i * passes + q];
                        assert_eq!(got.to_bits(), want.to_bits(), "row {r} member {i} pass {q}");
                    }
                }
            }
        }
    }
}
