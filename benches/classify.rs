//! Time per classification (one likelihood classification of 3 hypotheses × 64
//! templates ≤ 50 µs). Run: `cargo bench --features bench --bench classify`.

use criterion::{criterion_group, criterion_main, Criterion};
use pinfeed::geometry::named;
use pinfeed::mechanics::{PartModel, Support};
use pinfeed::random::distribution::Distribution;
use pinfeed::random::stream;
use pinfeed::sensing::classify::{build, ClassifierOptions};
use pinfeed::sensing::reading::read;
use pinfeed::sensing::settings::{SensorKind, SensorSettings};
use pinfeed::sensing::templates::*;
use std::hint::black_box;

fn bench_classify(c: &mut Criterion) {
    let poly = named::part_from_spec("tripoly1").unwrap().scaled(0.02);
    let model = PartModel::new(&poly, &Support::Uniform).unwrap();
    let setup = PushSetup::nominal(poly.clone(), -0.2);
    let deg = [0.0, 135.0, 225.0];
    let hyps = Hypotheses::Orientations {
        labels: deg.iter().map(|d| format!("{d}")).collect(),
        degrees: deg.to_vec(),
    };
    let unc = Uncertainty {
        mu_c: Distribution::Uniform { min: 0.3, max: 0.7 },
        ..Uncertainty::none(0.5)
    };
    let t = build_templates(&setup, &model, &hyps, &unc, 64, 1).unwrap();
    let mut group = c.benchmark_group("classify_3x64");
    for (name, kind) in [
        ("likelihood", SensorKind::Ft),
        ("sign-matrix", SensorKind::Ft),
        ("timing", SensorKind::Timing),
    ] {
        let sensor = SensorSettings {
            kind,
            ..SensorSettings::default()
        };
        let clf = build(name, &t, &sensor, &ClassifierOptions::default()).unwrap();
        let readings: Vec<_> = (0..8u64)
            .map(|i| {
                let pass = draw_pass(
                    &setup,
                    &model,
                    &unc,
                    deg[i as usize % 3],
                    1,
                    TRIAL_STREAMS + i,
                )
                .unwrap();
                read(&pass.signal, &sensor, &mut stream(1, i)).unwrap()
            })
            .collect();
        let mut k = 0;
        group.bench_function(name, |b| {
            b.iter(|| {
                k = (k + 1) % readings.len();
                black_box(clf.classify(black_box(&readings[k])))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_classify);
criterion_main!(benches);
