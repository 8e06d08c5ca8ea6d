//! Classifier tests ("Classifiers" and the classifier bullets of "Acceptance"): zero
//! noise classifies the templates' own pushes, unbounded noise falls to chance or Unknown, the
//! posterior and the reject option, the zero-crossing rule on synthetic profiles, bad names.

use pinfeed::geometry::named;
use pinfeed::mechanics::*;
use pinfeed::random::stream;
use pinfeed::sensing::classify::zero_crossings::derivative_zero_crossings;
use pinfeed::sensing::classify::{
    build, BuildError, Classifier, ClassifierOptions, Decision, NAMES,
};
use pinfeed::sensing::reading::{read, Reading, Sampled};
use pinfeed::sensing::settings::{SensorKind, SensorSettings, CHANNELS};
use pinfeed::sensing::templates::*;

const SEED: u64 = 12;

fn setup(part: &str, d: f64) -> (PushSetup, PartModel) {
    let poly = named::part_from_spec(part).unwrap().scaled(0.02);
    let model = PartModel::new(&poly, &Support::Uniform).unwrap();
    let setup = PushSetup::nominal(poly, d);
    (setup, model)
}

fn orientations(deg: &[f64]) -> Hypotheses {
    Hypotheses::Orientations {
        labels: deg.iter().map(|d| format!("{d}°")).collect(),
        degrees: deg.to_vec(),
    }
}

/// Templates for `deg` with no uncertainty (`n` identical members each).
fn nominal(part: &str, d: f64, deg: &[f64], n: usize) -> (PushSetup, PartModel, TemplateSet) {
    let (s, m) = setup(part, d);
    let t = build_templates(&s, &m, &orientations(deg), &Uncertainty::none(0.5), n, SEED).unwrap();
    (s, m, t)
}

/// The true pushes of trial `i` for hypothesis `h` (streams apart from the templates').
fn trial_signal(
    s: &PushSetup,
    m: &PartModel,
    unc: &Uncertainty,
    deg: f64,
    i: u64,
) -> pinfeed::sensing::ContactSignal {
    draw_pass(s, m, unc, deg, SEED, TRIAL_STREAMS + i)
        .unwrap()
        .signal
}

/// Confusion counts: rows true, columns decided (last column Unknown).
fn confusion(
    c: &dyn Classifier,
    signals: &[(usize, pinfeed::sensing::ContactSignal)],
    sensor: &SensorSettings,
    reps: usize,
    k: usize,
) -> Vec<Vec<usize>> {
    let mut conf = vec![vec![0; k + 1]; k];
    let mut i = 0u64;
    for _ in 0..reps {
        for (h, sig) in signals {
            i += 1;
            let r = read(sig, sensor, &mut stream(SEED, i)).unwrap();
            let col = match c.classify(&r).decision {
                Decision::Hypothesis(j) => j,
                Decision::Unknown => k,
            };
            conf[*h][col] += 1;
        }
    }
    conf
}

fn correct(conf: &[Vec<usize>]) -> usize {
    (0..conf.len()).map(|h| conf[h][h]).sum()
}

#[test]
fn zero_noise_classifies_the_templates_own_pushes() {
    // tripoly2's stable states at d = ±0.2 all differ; tripoly1 at d = −0.2: 225° differs from 0°
    // and 135° (the thesis could not tell those two apart).
    let cases: [(&str, f64, &[f64]); 3] = [
        ("tripoly2", 0.2, &[0.0, 90.0, 206.565]),
        ("tripoly2", -0.2, &[0.0, 90.0, 206.565]),
        ("tripoly1", -0.2, &[0.0, 225.0]),
    ];
    for (part, d, deg) in cases {
        let (s, m, t) = nominal(part, d, deg, 2);
        let sensors = [
            SensorSettings::default().ideal(),
            SensorSettings {
                kind: SensorKind::Timing,
                ..SensorSettings::default().ideal()
            },
        ];
        let signals: Vec<_> = (0..deg.len())
            .map(|h| {
                (
                    h,
                    trial_signal(&s, &m, &Uncertainty::none(0.5), deg[h], h as u64),
                )
            })
            .collect();
        for name in ["sign-matrix", "timing", "likelihood"] {
            for sensor in &sensors {
                // Only `timing` reads a timing sensor.
                if name != "timing" && sensor.kind == SensorKind::Timing {
                    continue;
                }
                let c = build(name, &t, sensor, &ClassifierOptions::default()).unwrap();
                let conf = confusion(c.as_ref(), &signals, sensor, 5, deg.len());
                eprintln!("{part} d={d} {name} {:?}: {conf:?}", sensor.kind);
                assert_eq!(
                    correct(&conf),
                    5 * deg.len(),
                    "{part} d={d} {name} {:?}: {conf:?}",
                    sensor.kind
                );
            }
        }
    }
}

/// One-sided binomial tolerance: |hits − n/k| ≤ 4 σ.
fn near_chance(hits: usize, n: usize, k: usize) -> bool {
    let p = 1.0 / k as f64;
    let sd = (n as f64 * p * (1.0 - p)).sqrt();
    (hits as f64 - n as f64 * p).abs() <= 4.0 * sd
}

#[test]
fn unbounded_noise_falls_to_chance_or_unknown() {
    let deg = [0.0, 90.0, 206.565];
    let (s, m, t) = nominal("tripoly2", 0.2, &deg, 4);
    let signals: Vec<_> = (0..3)
        .map(|h| {
            (
                h,
                trial_signal(&s, &m, &Uncertainty::none(0.5), deg[h], h as u64),
            )
        })
        .collect();
    // Timing: jitter × 10⁴ (10 s on contacts of ~1 s) — the decision no longer depends on the
    // truth, so accuracy is 1/k.
    let timing = SensorSettings {
        kind: SensorKind::Timing,
        ..SensorSettings::default().with_noise_factor(1e4)
    };
    let c = build("timing", &t, &timing, &ClassifierOptions::default()).unwrap();
    let conf = confusion(c.as_ref(), &signals, &timing, 110, 3);
    let n: usize = conf.iter().flatten().sum();
    let unknown: usize = conf.iter().map(|r| r[3]).sum();
    eprintln!("timing at jitter ×1e4: {conf:?}");
    assert_eq!(n, 330);
    assert!(unknown < n / 10, "{conf:?}");
    assert!(near_chance(correct(&conf), n - unknown, 3), "{conf:?}");
    // Confusion rows sum to the trials.
    assert!(conf.iter().all(|r| r.iter().sum::<usize>() == 110));

    // F/T: noise × 10⁴ (σ = 125 N on ~0.1 N signals) — the detector sees no contact and every
    // F/T classifier answers Unknown rather than guessing.
    let ft = SensorSettings::default().with_noise_factor(1e4);
    for name in ["sign-matrix", "likelihood", "timing"] {
        let c = build(name, &t, &ft, &ClassifierOptions::default()).unwrap();
        let conf = confusion(c.as_ref(), &signals, &ft, 100, 3);
        let unknown: usize = conf.iter().map(|r| r[3]).sum();
        eprintln!("{name} at noise ×1e4: {conf:?}");
        assert!(unknown >= 297, "{name}: {conf:?}");
    }
}

#[test]
fn accuracy_under_model_uncertainty() {
    // μc ∈ [0.3, 0.7] in templates and trials alike (trials from their own streams), default
    // sensor: the likelihood and timing posteriors should still name tripoly2's state.
    let deg = [0.0, 90.0, 206.565];
    let (s, m) = setup("tripoly2", 0.2);
    let unc = Uncertainty {
        mu_c: pinfeed::random::distribution::Distribution::Uniform { min: 0.3, max: 0.7 },
        ..Uncertainty::none(0.5)
    };
    let t = build_templates(&s, &m, &orientations(&deg), &unc, 16, SEED).unwrap();
    let signals: Vec<_> = (0..30)
        .map(|i| (i % 3, trial_signal(&s, &m, &unc, deg[i % 3], i as u64)))
        .collect();
    let ft = SensorSettings::default();
    let timing = SensorSettings {
        kind: SensorKind::Timing,
        ..ft
    };
    for (name, sensor, min) in [
        ("likelihood", ft, 0.9),
        ("timing", timing, 0.8),
        ("sign-matrix", ft, 0.0),
    ] {
        let c = build(name, &t, &sensor, &ClassifierOptions::default()).unwrap();
        let conf = confusion(c.as_ref(), &signals, &sensor, 3, 3);
        let acc = correct(&conf) as f64 / 90.0;
        eprintln!("{name} under μc uncertainty: {conf:?} accuracy {acc:.3}");
        assert!(acc >= min, "{name}: {conf:?}");
        assert!(conf.iter().all(|r| r.iter().sum::<usize>() == 30));
    }
}

#[test]
fn posterior_sums_to_one_and_reject_gives_unknown() {
    // Two hypotheses with the same orientation (ensembles drawn from different streams) and a
    // third: a reading of the first two has a split posterior, which the reject option turns
    // into Unknown.
    let deg = [0.0, 0.0, 225.0];
    let (s, m) = setup("tripoly1", -0.2);
    let unc = Uncertainty {
        mu_c: pinfeed::random::distribution::Distribution::Uniform { min: 0.3, max: 0.7 },
        ..Uncertainty::none(0.5)
    };
    let hyps = Hypotheses::Orientations {
        labels: vec!["a".into(), "b".into(), "c".into()],
        degrees: deg.to_vec(),
    };
    let t = build_templates(&s, &m, &hyps, &unc, 8, SEED).unwrap();
    let sensor = SensorSettings::default();
    let timing = SensorSettings {
        kind: SensorKind::Timing,
        ..sensor
    };
    let readings: Vec<Reading> = (0..30u64)
        .map(|i| {
            let h = (i % 3) as usize;
            let sig = trial_signal(&s, &m, &unc, deg[h], i);
            read(&sig, &timing, &mut stream(SEED, i)).unwrap()
        })
        .collect();
    check_reject("timing", &t, &timing, &readings);

    // The likelihood's posterior is sharp at this sensor's noise, so a split one is made by
    // blending a noise-free reading of 0° with one of 225° (same sampling phase) in varying
    // proportions: the posterior moves from one to the other through split values.
    let zero = trial_signal(&s, &m, &Uncertainty::none(0.5), 0.0, 0);
    let other = trial_signal(&s, &m, &Uncertainty::none(0.5), 225.0, 1);
    let ideal = sensor.ideal();
    let a = pinfeed::sensing::reading::sample_ft(&zero, &ideal, &mut stream(SEED, 0)).unwrap();
    let b = pinfeed::sensing::reading::sample_ft(&other, &ideal, &mut stream(SEED, 0)).unwrap();
    let nominal_t = build_templates(
        &s,
        &m,
        &orientations(&[0.0, 225.0]),
        &Uncertainty::none(0.5),
        1,
        SEED,
    )
    .unwrap();
    let blend = |lam: f64| {
        let n = a.len().max(b.len());
        let values = (0..n)
            .map(|k| {
                let va = a.values.get(k).copied().unwrap_or([0.0; CHANNELS]);
                let vb = b.values.get(k).copied().unwrap_or([0.0; CHANNELS]);
                std::array::from_fn(|c| (1.0 - lam) * va[c] + lam * vb[c])
            })
            .collect();
        Reading::Ft(Sampled {
            t0: a.t0,
            dt: a.dt,
            values,
        })
    };
    // Bisect on the blend for the decision's flip: the readings met near it are split.
    let open = build(
        "likelihood",
        &nominal_t,
        &sensor,
        &ClassifierOptions::default(),
    )
    .unwrap();
    let dec = |lam: f64| open.classify(&blend(lam)).decision;
    assert_eq!(dec(0.0), Decision::Hypothesis(0));
    assert_eq!(dec(1.0), Decision::Hypothesis(1));
    let (mut lo, mut hi) = (0.0, 1.0);
    let mut readings = vec![blend(0.0), blend(1.0)];
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        readings.push(blend(mid));
        if dec(mid) == Decision::Hypothesis(0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    check_reject("likelihood", &nominal_t, &sensor, &readings);
}

/// Posteriors sum to 1; with the threshold at the median posterior maximum, exactly the readings
/// whose maximum is below it become Unknown and the others keep their decision.
fn check_reject(name: &str, t: &TemplateSet, sen: &SensorSettings, readings: &[Reading]) {
    let open = build(name, t, sen, &ClassifierOptions::default()).unwrap();
    let open_out: Vec<_> = readings.iter().map(|r| open.classify(r)).collect();
    let mut maxima = Vec::new();
    for a in &open_out {
        let p = a.posterior.clone().expect("a posterior");
        assert_eq!(p.len(), t.labels.len());
        assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-9, "{p:?}");
        assert!(p.iter().all(|x| (0.0..=1.0).contains(x)));
        maxima.push(p.iter().copied().fold(0.0, f64::max));
    }
    let mut sorted = maxima.clone();
    sorted.sort_by(f64::total_cmp);
    let thr = sorted[sorted.len() / 2];
    assert!(
        sorted[0] < thr,
        "{name}: every posterior max equal: {sorted:?}"
    );
    let strict = build(name, t, sen, &ClassifierOptions { reject_below: thr }).unwrap();
    let mut rejected = 0;
    for ((r, a), max) in readings.iter().zip(&open_out).zip(&maxima) {
        let b = strict.classify(r);
        assert_eq!(a.posterior, b.posterior);
        if *max < thr {
            assert_eq!(b.decision, Decision::Unknown, "{name}: {:?}", a.posterior);
            rejected += 1;
        } else {
            assert_eq!(b.decision, a.decision);
        }
    }
    eprintln!(
        "{name}: {rejected}/{} rejected below {thr}; maxima {sorted:?}",
        readings.len()
    );
    assert!(rejected > 0);
}

fn synthetic(profile: impl Fn(f64) -> f64, n: usize, pad: usize) -> Reading {
    let mut values = vec![[0.0; CHANNELS]; n + 2 * pad];
    for k in 0..n {
        let u = k as f64 / (n - 1) as f64;
        values[pad + k][0] = profile(u);
    }
    Reading::Ft(Sampled {
        t0: 0.0,
        dt: 1e-3,
        values,
    })
}

#[test]
fn zero_crossing_rule_on_synthetic_profiles() {
    // Profiles whose derivative changes sign at known points: 0, 1, 2, 3 and 4 crossings.
    let cases: [(&dyn Fn(f64) -> f64, usize); 5] = [
        (&|u| 0.1 + 0.2 * u, 0),
        (&|u| 0.1 + 0.4 * u * (1.0 - u), 1),
        (&|u| 0.3 + (2.0 * std::f64::consts::PI * u).sin() * 0.1, 2),
        (&|u| 0.3 + (3.0 * std::f64::consts::PI * u).sin() * 0.1, 3),
        (&|u| 0.3 + (4.0 * std::f64::consts::PI * u).sin() * 0.1, 4),
    ];
    for (f, want) in cases {
        let y: Vec<f64> = (0..500).map(|k| f(k as f64 / 499.0)).collect();
        assert_eq!(derivative_zero_crossings(&y), Some(want));
    }
    assert_eq!(derivative_zero_crossings(&[1.0, 2.0]), None);
    assert_eq!(derivative_zero_crossings(&[f64::NAN; 20]), None);

    // Through the classifier: ≥ 3 crossings → vertex.
    let t = TemplateSet {
        labels: vec!["vertex".into(), "edge".into()],
        members: vec![vec![], vec![]],
    };
    let sensor = SensorSettings::default().ideal();
    let c = build("zero-crossings", &t, &sensor, &ClassifierOptions::default()).unwrap();
    let spike = synthetic(
        |u| 0.3 + (3.0 * std::f64::consts::PI * u).sin() * 0.1,
        800,
        40,
    );
    let smooth = synthetic(|u| 0.1 + 0.4 * u * (1.0 - u), 800, 40);
    assert_eq!(c.classify(&spike).decision, Decision::Hypothesis(0));
    assert_eq!(c.classify(&smooth).decision, Decision::Hypothesis(1));
    assert_eq!(c.classify(&spike).posterior, None);
}

#[test]
fn vertex_edge_by_both_rules() {
    // Vertex/edge hypotheses from the contact model's own first feature; the likelihood
    // alternative must classify noise-free pushes; the thesis's rule is reported.
    // A pin of 4 mm radius: a point pin almost never meets a vertex first.
    let (mut s, m) = setup("tripoly2", 0.2);
    s.pin_radius = 0.004;
    let deg: Vec<f64> = (0..24).map(|i| i as f64 * 15.0).collect();
    let hyps = Hypotheses::VertexEdge {
        degrees: deg.clone(),
    };
    let unc = Uncertainty::none(0.5);
    let t = build_templates(&s, &m, &hyps, &unc, 8, SEED).unwrap();
    assert!(
        t.members.iter().all(|m| !m.is_empty()),
        "both classes occur"
    );
    let sensor = SensorSettings::default().ideal();
    let lik = build("likelihood", &t, &sensor, &ClassifierOptions::default()).unwrap();
    let zc = build("zero-crossings", &t, &sensor, &ClassifierOptions::default()).unwrap();
    let mut lik_conf = [[0usize; 3]; 2];
    let mut zc_conf = [[0usize; 3]; 2];
    for (i, &d0) in deg.iter().enumerate() {
        let pass = draw_pass(&s, &m, &unc, d0, SEED, TRIAL_STREAMS + i as u64).unwrap();
        let Some(f) = pass.signal.first_feature else {
            continue;
        };
        let truth = vertex_edge_class(f);
        let r = read(&pass.signal, &sensor, &mut stream(SEED, i as u64)).unwrap();
        for (c, conf) in [(&lik, &mut lik_conf), (&zc, &mut zc_conf)] {
            let col = match c.classify(&r).decision {
                Decision::Hypothesis(j) => j,
                Decision::Unknown => 2,
            };
            conf[truth][col] += 1;
        }
    }
    eprintln!("vertex/edge likelihood {lik_conf:?}, zero-crossings {zc_conf:?}");
    // Every orientation's nominal push is one of the templates' pushes (the templates sweep the
    // same orientations), so the likelihood must get every one right.
    assert_eq!(lik_conf[0][0] + lik_conf[1][1], deg.len(), "{lik_conf:?}");
}

#[test]
fn bad_names_and_templates_are_refused() {
    let (_, _, t) = nominal("tripoly1", -0.2, &[0.0, 225.0], 1);
    let sensor = SensorSettings::default();
    let o = ClassifierOptions::default();
    let err = build("bayes", &t, &sensor, &o).err().unwrap();
    assert_eq!(
        err,
        BuildError::Unknown {
            name: "bayes".into()
        }
    );
    let err = err.to_string();
    for n in NAMES {
        assert!(err.contains(n), "{err}");
    }
    assert!(err.contains("bayes"));
    let err = build("zero-crossings", &t, &sensor, &o).err().unwrap();
    assert!(matches!(err, BuildError::ZeroCrossings(_)), "{err:?}");
    let err = err.to_string();
    assert!(err.contains("vertex"), "{err}");
    let empty = TemplateSet {
        labels: vec!["a".into(), "b".into()],
        members: vec![t.members[0].clone(), vec![]],
    };
    for name in ["sign-matrix", "timing", "likelihood"] {
        let err = build(name, &empty, &sensor, &o).err().unwrap();
        assert!(
            matches!(&err, BuildError::EmptyEnsemble { label, .. } if label == "b"),
            "{err:?}"
        );
        let err = err.to_string();
        assert!(err.contains("'b'"), "{err}");
    }
    let err = build(
        "likelihood",
        &t,
        &sensor,
        &ClassifierOptions { reject_below: 2.0 },
    )
    .err()
    .unwrap();
    assert!(
        matches!(err, BuildError::RejectBelow { value: 2.0, .. }),
        "{err:?}"
    );
    let err = err.to_string();
    assert!(err.contains("reject_below"), "{err}");
    for name in NAMES {
        assert!(build(name, &t, &sensor, &o).is_ok() || name == "zero-crossings");
    }
}

#[test]
fn bad_readings_give_unknown() {
    let (_, _, t) = nominal("tripoly1", -0.2, &[0.0, 225.0], 1);
    let sensor = SensorSettings::default();
    let o = ClassifierOptions::default();
    let vt = TemplateSet {
        labels: vec!["vertex".into(), "edge".into()],
        members: vec![vec![], vec![]],
    };
    let empty = Reading::Ft(Sampled {
        t0: 0.0,
        dt: 1e-3,
        values: vec![],
    });
    let nan = Reading::Ft(Sampled {
        t0: 0.0,
        dt: 1e-3,
        values: vec![[f64::NAN; CHANNELS]; 50],
    });
    let quiet = Reading::Ft(Sampled {
        t0: 0.0,
        dt: 1e-3,
        values: vec![[0.0; CHANNELS]; 50],
    });
    let no_contact = Reading::Timing(Default::default());
    let bad_timing = Reading::Timing(pinfeed::sensing::ContactTimes {
        intervals: vec![(f64::NAN, 1.0)],
    });
    for name in NAMES {
        let ts = if name == "zero-crossings" { &vt } else { &t };
        let c = build(name, ts, &sensor, &o).unwrap();
        for r in [&empty, &nan, &quiet, &no_contact, &bad_timing] {
            assert_eq!(c.classify(r).decision, Decision::Unknown, "{name}: {r:?}");
        }
    }
}
