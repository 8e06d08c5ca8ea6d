//! A synthetic measured-bands file the project makes itself: bands drawn from a hidden
//! parameter set, so that calibration and validation can be checked against a known truth.
//!
//! Row (d, input) of the design summarises `trials` trials; trial t of row r is one pass (pass 0)
//! of member r · trials + t of the *truth* ensemble seeded with `seed` — a fresh draw of μc, support
//! and pin radius per trial, with the pose jitter — and the row's band is the smallest arc holding
//! all its trials' final orientations, ends rounded outwards to 0.1°.

use crate::geometry::part_from_spec;
use crate::maps::arcs::Arc;
use crate::maps::ensemble::{members, stable_states_deg, EnsembleSpec, InputState};
use crate::mechanics::support::SupportChoice;
use crate::mechanics::Fidelity;
use crate::random::distribution::Distribution;
use rayon::prelude::*;

/// The seed of the bundled synthetic data set.
pub const SYNTHETIC_SEED: u64 = 16;

/// What to synthesise.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntheticDesign {
    /// The part spec.
    pub part: String,
    /// Contact parameters d of the rows (units of a).
    pub ds: Vec<f64>,
    /// Input states of the rows (every d gets each).
    pub inputs: Vec<InputState>,
    /// Trials per row.
    pub trials: u32,
    /// The hidden ensemble the trials are drawn from.
    pub truth: EnsembleSpec,
    /// Seed of the trials; the same seed gives the same data set.
    pub seed: u64,
}

impl SyntheticDesign {
    /// The hidden parameters φ* = [μc mean, μc sd, tripod share, pin radius] and the known σρ
    /// and jitter of the bundled data set.
    pub const TRUTH: [f64; 4] = [0.45, 0.08, 0.6, 0.12];
    /// The known σρ of the pin radius (part units).
    pub const PIN_RADIUS_SD: f64 = 0.03;
    /// The known pose jitter (degrees).
    pub const JITTER_DEG: f64 = 3.0;
}

impl Default for SyntheticDesign {
    /// The bundled data set: tripoly1, six d, three stable states and one θ0 arc, 20 trials a row.
    fn default() -> Self {
        let [m, s, t, r] = SyntheticDesign::TRUTH;
        SyntheticDesign {
            part: "tripoly1".into(),
            ds: vec![-0.7, -0.4, -0.1, 0.1, 0.4, 0.7],
            inputs: vec![
                InputState::State { index: 0 },
                InputState::State { index: 1 },
                InputState::State { index: 2 },
                InputState::Theta {
                    arc: Arc::from_ends(60.0, 80.0),
                },
            ],
            trials: 20,
            truth: EnsembleSpec {
                mu_c: Distribution::Normal {
                    mean: m,
                    sd: s,
                    lo: 0.0,
                    hi: 10.0,
                },
                support: SupportChoice::Tripod,
                support_share: t,
                pin_radius: Distribution::Normal {
                    mean: r,
                    sd: SyntheticDesign::PIN_RADIUS_SD,
                    lo: 0.0,
                    hi: 1e6,
                },
                jitter_deg: SyntheticDesign::JITTER_DEG,
                fidelity: Fidelity::Exact,
                tol: 1e-6,
            },
            seed: SYNTHETIC_SEED,
        }
    }
}

/// The smallest arc holding every angle (degrees): the complement of the widest gap between
/// neighbours round the circle.
pub fn smallest_arc(angles: &[f64]) -> Arc {
    let mut a: Vec<f64> = angles
        .iter()
        .map(|&x| crate::geometry::wrap_deg(x))
        .collect();
    a.sort_by(f64::total_cmp);
    let n = a.len();
    let gap = |k: usize| {
        if k + 1 < n {
            a[k + 1] - a[k]
        } else {
            a[0] + 360.0 - a[n - 1]
        }
    };
    let widest = (0..n).fold(n - 1, |b, k| if gap(k) > gap(b) { k } else { b });
    let lo = a[(widest + 1) % n];
    Arc {
        lo,
        width: 360.0 - gap(widest),
    }
}

/// Why a synthetic measured-bands file could not be made ([`synthesize`]).
#[derive(Debug, thiserror::Error)]
pub enum SynthesizeError {
    /// The design's part spec is refused.
    #[error("{0}")]
    Part(crate::geometry::PartSpecError),
    /// An ensemble member of the hidden truth could not be compiled.
    #[error("{0}")]
    Ensemble(crate::maps::ensemble::EnsembleError),
}

/// The design's measured-bands file (CSV text, with a comment header naming seed and design).
pub fn synthesize(design: &SyntheticDesign) -> Result<String, SynthesizeError> {
    let poly = part_from_spec(&design.part).map_err(SynthesizeError::Part)?;
    let states = stable_states_deg(&poly);
    let n_rows = design.ds.len() * design.inputs.len();
    let trials = design.trials as usize;
    let ms = members(&poly, &design.truth, design.seed, n_rows * trials)
        .map_err(SynthesizeError::Ensemble)?;
    let finals: Vec<f64> = (0..n_rows * trials)
        .into_par_iter()
        .map(|x| {
            let r = x / trials;
            let (d, input) = (
                design.ds[r / design.inputs.len()],
                &design.inputs[r % design.inputs.len()],
            );
            ms[x].pass(&poly, &design.truth, input, &states, d, 0)
        })
        .collect();
    let mut out = String::new();
    out.push_str(&format!(
        "# Synthetic measured bands: part {}, {} trials a row, seed {}.\n",
        design.part, design.trials, design.seed
    ));
    out.push_str("# Regenerate: pinfeed calibrate tests/fixtures/validate/synthetic.csv --synthesize --jitter 3\n");
    out.push_str("# (the jitter is known, not fitted: calibrate with --jitter 3)\n");
    out.push_str("# Drawn from (hidden from calibrate, which skips comments):\n");
    for line in design.truth.describe() {
        out.push_str(&format!("#   {line}\n"));
    }
    out.push_str("part,d,input,min_deg,max_deg,trials\n");
    for r in 0..n_rows {
        let arc = smallest_arc(&finals[r * trials..(r + 1) * trials]);
        let lo = crate::geometry::wrap_deg((arc.lo * 10.0).floor() / 10.0);
        let hi = crate::geometry::wrap_deg(((arc.lo + arc.width) * 10.0).ceil() / 10.0);
        out.push_str(&format!(
            "{},{},{},{lo:.1},{hi:.1},{}\n",
            design.part,
            design.ds[r / design.inputs.len()],
            design.inputs[r % design.inputs.len()].label(),
            design.trials
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smallest_arc_crosses_zero_when_it_should() {
        let a = smallest_arc(&[355.0, 2.0, 358.0, 5.0]);
        assert_eq!(a.lo, 355.0);
        assert!((a.width - 10.0).abs() < 1e-12);
        let b = smallest_arc(&[10.0, 20.0, 15.0]);
        assert_eq!((b.lo, b.width), (10.0, 10.0));
        assert_eq!(smallest_arc(&[42.0]).width, 0.0);
    }
}
