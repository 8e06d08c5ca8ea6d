//! `sensing::evaluate`: confusion matrices, accuracy intervals and mutual information, scored with
//! test-double classifiers (a nearest-template matcher and a constant), and their determinism
//! across thread counts.

use pinfeed::geometry::named;
use pinfeed::mechanics::{PartModel, Support};
use pinfeed::random::distribution::Distribution;
use pinfeed::sensing::classify::{BuildError, Classification, Classifier, Decision};
use pinfeed::sensing::evaluate::{
    evaluate_with, noise_sweep, Config, Confusion, Evaluation, Problem, TruthDraw,
};
use pinfeed::sensing::templates::{Hypotheses, PushSetup, TemplateSet, Uncertainty};
use pinfeed::sensing::{ContactSignal, Reading, SensorSettings};

/// Decides the hypothesis whose template members best match the reading's Fx and Fy (least
/// squares, aligned on the first sample above the timing threshold).
struct Nearest {
    templates: Vec<Vec<ContactSignal>>,
    threshold: f64,
}

impl Classifier for Nearest {
    fn name(&self) -> &'static str {
        "nearest"
    }
    fn classify(&self, reading: &Reading) -> Classification {
        let Reading::Ft(s) = reading else {
            return Classification::unknown();
        };
        let Some(k0) = s
            .values
            .iter()
            .position(|v| (v[0] * v[0] + v[1] * v[1]).sqrt() > self.threshold)
        else {
            return Classification::unknown();
        };
        let mut best = (f64::INFINITY, Decision::Unknown);
        for (h, members) in self.templates.iter().enumerate() {
            for m in members {
                let Some((b, _)) = m.span() else { continue };
                // The template's first instant above threshold, on the reading's sample grid.
                let tb = (0..100_000)
                    .map(|j| b + j as f64 * s.dt)
                    .find(|&t| m.force_magnitude(t) > self.threshold)
                    .unwrap_or(b);
                let err: f64 = s
                    .values
                    .iter()
                    .enumerate()
                    .map(|(k, v)| {
                        let c = m.at(tb + (k as f64 - k0 as f64) * s.dt);
                        (v[0] - c[0]).powi(2) + (v[1] - c[1]).powi(2)
                    })
                    .sum();
                if err < best.0 {
                    best = (err, Decision::Hypothesis(h));
                }
            }
        }
        Classification {
            decision: best.1,
            posterior: None,
        }
    }
}

/// Always decides hypothesis 0.
struct Constant;

impl Classifier for Constant {
    fn name(&self) -> &'static str {
        "constant"
    }
    fn classify(&self, _: &Reading) -> Classification {
        Classification {
            decision: Decision::Hypothesis(0),
            posterior: None,
        }
    }
}

fn factory(
    name: &str,
    t: &TemplateSet,
    s: &SensorSettings,
) -> Result<Box<dyn Classifier>, BuildError> {
    match name {
        "nearest" => Ok(Box::new(Nearest {
            templates: t.members.clone(),
            threshold: s.threshold,
        })),
        "constant" => Ok(Box::new(Constant)),
        other => Err(BuildError::Unknown { name: other.into() }),
    }
}

struct Fixture {
    setup: PushSetup,
    model: PartModel,
    hyps: Hypotheses,
}

fn tripoly1(d: f64) -> Fixture {
    let poly = named::part_from_spec("tripoly1").unwrap().scaled(0.02);
    let model = PartModel::new(&poly, &Support::Uniform).unwrap();
    let degrees: Vec<f64> = poly
        .stable_states()
        .iter()
        .map(|s| s.theta_rad.to_degrees())
        .collect();
    let hyps = Hypotheses::Orientations {
        labels: degrees.iter().map(|d| format!("{d:.0}")).collect(),
        degrees,
    };
    let setup = PushSetup::nominal(poly, d);
    Fixture { setup, model, hyps }
}

fn run(
    f: &Fixture,
    unc: &Uncertainty,
    sensor: &SensorSettings,
    factors: &[f64],
    trials: usize,
    truth: TruthDraw,
) -> Evaluation {
    let problem = Problem {
        setup: &f.setup,
        model: &f.model,
        hypotheses: &f.hyps,
        uncertainty: unc,
    };
    let names = vec!["nearest".to_string(), "constant".to_string()];
    let points = noise_sweep(sensor, factors, &names);
    let config = Config {
        templates_per_hypothesis: 3,
        trials,
        truth,
        seed: 11,
        options: Default::default(),
    };
    evaluate_with(&problem, &points, &config, &factory)
        .unwrap()
        .1
}

#[test]
fn confusion_rows_sum_to_the_trials_of_each_hypothesis() {
    let f = tripoly1(-0.2);
    let k = f.hyps.len();
    let unc = Uncertainty::none(0.5);
    let ev = run(
        &f,
        &unc,
        &SensorSettings::default(),
        &[0.0, 4.0],
        6 * k,
        TruthDraw::Cycle,
    );
    assert_eq!(ev.cells.len(), 4);
    for c in &ev.cells {
        assert_eq!(c.confusion.counts.len(), k);
        for (h, row) in c.confusion.counts.iter().enumerate() {
            assert_eq!(row.len(), k + 1, "k decisions and unknown");
            assert_eq!(row.iter().sum::<u64>(), 6, "row {h} of {}", c.classifier);
        }
        assert_eq!(c.trials, 6 * k as u64);
        let [lo, hi] = c.accuracy_ci95;
        assert!(0.0 <= lo && lo <= c.accuracy && c.accuracy <= hi && hi <= 1.0);
    }
    // Uniformly drawn truths: rows sum to the recorded truth counts, and those to the trials.
    let ev = run(
        &f,
        &unc,
        &SensorSettings::default(),
        &[1.0],
        20,
        TruthDraw::Uniform,
    );
    assert_eq!(ev.truth_counts.iter().sum::<u64>(), 20);
    for c in &ev.cells {
        for (h, &n) in ev.truth_counts.iter().enumerate() {
            assert_eq!(c.confusion.row_total(h), n);
        }
    }
}

#[test]
fn information_is_log2_k_for_a_perfect_classifier_and_zero_for_a_blind_one() {
    // No uncertainty and an ideal sensor: each trial's push is its hypothesis's template push,
    // so matching the templates is perfect (tripoly1's stable states differ at d = −0.2).
    let f = tripoly1(-0.2);
    let k = f.hyps.len();
    let unc = Uncertainty::none(0.5);
    let ideal = SensorSettings::default().ideal();
    let ev = run(&f, &unc, &ideal, &[0.0], 3 * k, TruthDraw::Cycle);
    let nearest = ev.of("nearest").next().unwrap();
    assert_eq!(nearest.accuracy, 1.0, "{:?}", nearest.confusion);
    let log2k = (k as f64).log2();
    assert!((nearest.mutual_information_bits - log2k).abs() < 1e-12);
    assert!((ev.state_entropy_bits - log2k).abs() < 1e-12);
    let constant = ev.of("constant").next().unwrap();
    assert_eq!(constant.mutual_information_bits, 0.0);
    assert!((constant.accuracy - 1.0 / k as f64).abs() < 1e-12);

    // A decision independent of the state, spread over several decisions: the plug-in estimate
    // is exactly 0 when the joint counts factorise.
    let labels: Vec<String> = vec!["a".into(), "b".into()];
    let mut c = Confusion::new(&labels);
    for truth in 0..2 {
        for _ in 0..5 {
            c.add(truth, Decision::Hypothesis(0));
            c.add(truth, Decision::Hypothesis(1));
            c.add(truth, Decision::Unknown);
        }
    }
    assert!(c.mutual_information_bits().abs() < 1e-12);
    assert_eq!(c.unknown(), 10);
}

#[test]
fn wilson_bounds() {
    let labels: Vec<String> = vec!["a".into(), "b".into()];
    let mut c = Confusion::new(&labels);
    for i in 0..10 {
        let d = if i < 8 { i % 2 } else { 1 - i % 2 };
        c.add(i % 2, Decision::Hypothesis(d));
    }
    assert_eq!(c.correct(), 8);
    // Wilson score interval for 8/10 at 95%: [0.4902, 0.9433] (textbook value).
    let [lo, hi] = c.accuracy_ci95();
    assert!(
        (lo - 0.4902).abs() < 1e-4 && (hi - 0.9433).abs() < 1e-4,
        "{lo} {hi}"
    );
    let mut all = Confusion::new(&labels);
    for i in 0..10 {
        all.add(i % 2, Decision::Hypothesis(i % 2));
    }
    assert!((all.accuracy_ci95()[1] - 1.0).abs() < 1e-12);
    assert!(all.accuracy_ci95()[0] < 1.0 && all.accuracy_ci95()[0] > 0.6);
    assert_eq!(Confusion::new(&labels).accuracy_ci95(), [0.0, 1.0]);
}

#[test]
fn the_same_bytes_on_one_and_two_threads() {
    let f = tripoly1(-0.2);
    let unc = Uncertainty {
        mu_c: Distribution::Uniform { min: 0.3, max: 0.7 },
        tripod: true,
        theta_sd_deg: 2.0,
        d_sd: 0.02,
    };
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                run(
                    &f,
                    &unc,
                    &SensorSettings::default(),
                    &[1.0, 8.0],
                    24,
                    TruthDraw::Uniform,
                )
            })
    };
    let (a, b) = (on(1), on(2));
    assert_eq!(a, b);
    assert_eq!(
        serde_json::to_string(&a).unwrap(),
        serde_json::to_string(&b).unwrap()
    );
}

#[test]
fn vertex_edge_truth_is_the_first_contact_feature() {
    // A point pin first meets the part on an edge (a vertex only at one exact offset), so the
    // pin gets a radius (3 mm; a = 3.2 cm): then corners hit it first too.
    let mut f = tripoly1(0.3);
    f.setup.pin_radius = 0.003;
    f.hyps = Hypotheses::VertexEdge {
        degrees: (0..36).map(|i| 10.0 * i as f64).collect(),
    };
    let unc = Uncertainty::none(0.5);
    let ev = run(
        &f,
        &unc,
        &SensorSettings::default(),
        &[1.0],
        36,
        TruthDraw::Cycle,
    );
    assert_eq!(ev.labels, vec!["vertex", "edge"]);
    assert_eq!(ev.truth_counts.iter().sum::<u64>() + ev.unscored, 36);
    assert!(
        ev.truth_counts.iter().all(|&n| n > 0),
        "both classes occur over a sweep of orientations: {:?}",
        ev.truth_counts
    );
}
