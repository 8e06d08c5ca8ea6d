//! What the sensor signal costs (issue "Sensor pins": the signal adds ≤ 10% to the push that makes
//! it). Three variants of the same 24 pushes per part, exact model: the bare push; the push with a
//! knot recorder and its `ContactSignal` built; and that plus one noisy 1 kHz F/T reading sampled
//! from it. Run: `cargo bench --features bench --bench signal`; figures in results/sensing.md.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use pinfeed::geometry::{part_from_spec, Pose, Vec2};
use pinfeed::mechanics::{push, ContactSettings, PartModel, Pin, Support};
use pinfeed::random::stream;
use pinfeed::sensing::reading::sample_ft;
use pinfeed::sensing::signal::{ContactSignal, KnotRecorder, SignalScale};
use pinfeed::sensing::SensorSettings;
use std::hint::black_box;

fn bench_signal(c: &mut Criterion) {
    let mut group = c.benchmark_group("signal");
    let scale = SignalScale {
        mass: 0.05,
        belt_speed: 0.05,
        height: 0.02,
        metres_per_unit: 1.0,
    };
    let sensor = SensorSettings::default();
    for part in ["tripoly1", "tripoly2", "square"] {
        let poly = part_from_spec(part).unwrap().scaled(0.02);
        let model = PartModel::new(&poly, &Support::Uniform).unwrap();
        let a = poly.radius();
        let cases: Vec<(f64, f64)> = (0..24)
            .map(|k| {
                (
                    k as f64 * 15.0 + 2.0,
                    -0.7 + 1.4 * ((k * 7 % 24) as f64) / 23.0,
                )
            })
            .collect();
        let settings = ContactSettings::default();
        let run = |mode: u8| {
            let mut acc = 0.0;
            for (i, &(th, d)) in cases.iter().enumerate() {
                let pose = Pose::new(0.0, 0.0, th.to_radians());
                let start = Vec2::new(1.01 * a, d * a);
                if mode == 0 {
                    let o = push(&model, pose, start, &Pin::point(), &settings, None);
                    acc += o.pose_final.theta_rad;
                    continue;
                }
                let mut rec = KnotRecorder::default();
                let o = push(
                    &model,
                    pose,
                    start,
                    &Pin::point(),
                    &settings,
                    Some(&mut rec),
                );
                let signal = ContactSignal::new(&o, &rec.samples, &scale);
                acc += o.pose_final.theta_rad + signal.duration();
                if mode == 2 {
                    if let Some(r) = sample_ft(&signal, &sensor, &mut stream(1, i as u64)) {
                        acc += r.values.len() as f64;
                    }
                }
            }
            acc
        };
        for (name, mode) in [
            ("push", 0u8),
            ("push+signal", 1),
            ("push+signal+reading", 2),
        ] {
            group.bench_with_input(BenchmarkId::new(name, part), &mode, |b, &m| {
                b.iter(|| black_box(run(m)))
            });
        }
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2));
    targets = bench_signal
}
criterion_main!(benches);
