//! `timing`: the contact duration(s) against the templates' durations (thesis app. F).
//!
//! The thesis simulated the contact time of each initial state of TriPoly1 and TriPoly2 and
//! called two states distinguishable when their times differ by more than 1 s; it tested nothing.
//! Here the durations get a likelihood instead of a fixed margin:
//!
//! * each template member m of hypothesis h gives the sequence of its contact durations
//!   D_m = (d_1, …, d_n) as the sensor would report them without jitter — the crossings of
//!   |F| = threshold located exactly ([`reading::sample_timing`] with zero jitter);
//! * a reading's detected durations x = (x_1, …, x_n) have, given member m, independent Gaussian
//!   errors of variance V_h = 2·jitter² (begin and end each carry the sensor's jitter) + b_h² (a
//!   kernel bandwidth: Silverman's rule 1.06·sd·n^(−1/5) over the hypothesis's total durations,
//!   so a finite ensemble stands for the continuous spread the declared uncertainty gives) +
//!   floor² ([`FLOOR`], so zero jitter and a fixed ensemble still give a finite likelihood);
//! * members whose number of contacts differs from the reading's have likelihood 0;
//! * p(x | h) = mean over members of Π_i N(x_i; d_i, V_h), the posterior normalises these with
//!   equal priors, and the reject option answers Unknown below `reject_below`. No matching
//!   member anywhere → Unknown.
//!
//! On an F/T reading the contact is detected by the shared |F| threshold detector
//! ([`super::common`]): one duration, first to last sample above threshold; the templates'
//! durations are then measured the same way on noise-free samples (mean over four sampling
//! phases), and the error variance gets 2·dt²/12 for the sampling of both instants.
//!
//! With unbounded jitter the likelihood carries no information about the truth, so the decision
//! no longer depends on the true state and accuracy falls to chance.

use super::common::{self, decide, log_sum_exp};
use super::{Classification, Classifier, ClassifierOptions};
use crate::sensing::reading::{self, Reading};
use crate::sensing::settings::SensorSettings;
use crate::sensing::templates::TemplateSet;

/// Floor (s) of the duration error's standard deviation.
pub const FLOOR: f64 = 1e-6;

/// The `timing` classifier: the reported contact durations against the templates' durations.
pub struct Timing {
    /// Per hypothesis, per member: the durations a timing sensor reports without jitter.
    timing: Vec<Vec<Vec<f64>>>,
    /// Per hypothesis, per member: the span measured by the F/T detector on clean samples.
    ft: Vec<Vec<f64>>,
    var_timing: Vec<f64>,
    var_ft: Vec<f64>,
    sensor: SensorSettings,
    options: ClassifierOptions,
}

fn silverman_sq(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    if v.len() < 2 {
        return 0.0;
    }
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (1.06 * var.sqrt() * n.powf(-0.2)).powi(2)
}

impl Timing {
    /// Train on `templates` for `sensor` (any template set can be used).
    pub fn new(
        templates: &TemplateSet,
        sensor: &SensorSettings,
        options: &ClassifierOptions,
    ) -> Timing {
        let exact = SensorSettings {
            jitter: 0.0,
            ..*sensor
        };
        let mut rng = crate::random::stream(0, 0); // unused: zero jitter draws nothing that matters
        let thr = common::Detector::new(sensor);
        let dt = 1.0 / sensor.rate;
        let phases = 4;
        let mut timing = Vec::new();
        let mut ft = Vec::new();
        let mut var_timing = Vec::new();
        let mut var_ft = Vec::new();
        for members in &templates.members {
            let mut th = Vec::new();
            let mut fh = Vec::new();
            for s in members {
                th.push(reading::sample_timing(s, &exact, &mut rng).durations());
                let mut sum = 0.0;
                let mut got = 0;
                for p in 0..phases {
                    let phase = (p as f64 + 0.5) / phases as f64;
                    if let Some((_, v)) = reading::sample_clean(s, sensor, phase) {
                        if let Some((b, e)) = thr.detect(&v) {
                            sum += (e - b) as f64 * dt;
                            got += 1;
                        }
                    }
                }
                fh.push(if got > 0 { sum / got as f64 } else { f64::NAN });
            }
            let totals: Vec<f64> = th.iter().map(|d| d.iter().sum()).collect();
            var_timing.push(2.0 * sensor.jitter.powi(2) + silverman_sq(&totals) + FLOOR * FLOOR);
            let finite: Vec<f64> = fh.iter().copied().filter(|x| x.is_finite()).collect();
            var_ft.push(dt * dt / 6.0 + silverman_sq(&finite) + FLOOR * FLOOR);
            timing.push(th);
            ft.push(fh);
        }
        Timing {
            timing,
            ft,
            var_timing,
            var_ft,
            sensor: *sensor,
            options: *options,
        }
    }

    /// log p(durations | h) per hypothesis.
    fn log_likelihoods(&self, obs: &[f64], from_ft: bool) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.timing.len());
        let mut terms = Vec::new();
        for h in 0..self.timing.len() {
            let var = if from_ft {
                self.var_ft[h]
            } else {
                self.var_timing[h]
            };
            terms.clear();
            let n = self.timing[h].len();
            for m in 0..n {
                let ll = if from_ft {
                    let d = self.ft[h][m];
                    gauss(obs[0] - d, var)
                } else {
                    let d = &self.timing[h][m];
                    if d.len() != obs.len() {
                        f64::NEG_INFINITY
                    } else {
                        obs.iter().zip(d).map(|(x, d)| gauss(x - d, var)).sum()
                    }
                };
                terms.push(ll);
            }
            out.push(log_sum_exp(&terms) - (n as f64).ln());
        }
        out
    }
}

fn gauss(e: f64, var: f64) -> f64 {
    if !e.is_finite() {
        return f64::NEG_INFINITY;
    }
    -0.5 * e * e / var - 0.5 * (2.0 * std::f64::consts::PI * var).ln()
}

impl Classifier for Timing {
    fn name(&self) -> &'static str {
        "timing"
    }

    fn classify(&self, r: &Reading) -> Classification {
        let (obs, from_ft) = match r {
            Reading::Timing(ct) => {
                let d = ct.durations();
                if d.is_empty() || d.iter().any(|x| !x.is_finite()) {
                    return Classification::unknown();
                }
                (d, false)
            }
            Reading::Ft(s) => {
                let Some(v) = common::clean_values(s, &self.sensor) else {
                    return Classification::unknown();
                };
                let Some((b, e)) = common::Detector::new(&self.sensor).detect(&v) else {
                    return Classification::unknown();
                };
                (vec![(e - b) as f64 * s.dt], true)
            }
        };
        decide(
            common::posterior(&self.log_likelihoods(&obs, from_ft)),
            self.options.reject_below,
        )
    }
}
