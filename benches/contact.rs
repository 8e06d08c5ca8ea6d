//! Time per contact for each fidelity on the four reference parts (issue: exact ≤ 50 µs median per
//! triangle contact at 0.01° self-accuracy; ellipsoid and tip ≤ 5 µs). Run: `cargo bench --bench contact`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use pinfeed::geometry::{part_from_spec, Pose, Vec2};
use pinfeed::mechanics::{push, ContactSettings, Fidelity, PartModel, Pin, Support};
use std::hint::black_box;

fn bench_contacts(c: &mut Criterion) {
    let mut group = c.benchmark_group("contact");
    for part in ["tripoly1", "tripoly2", "square", "lshape"] {
        let poly = part_from_spec(part).unwrap();
        let model = PartModel::new(&poly, &Support::Uniform).unwrap();
        let a = poly.radius();
        // 24 contacts spread over orientations and offsets (all of them make contact or pass).
        let cases: Vec<(f64, f64)> = (0..24)
            .map(|k| {
                (
                    k as f64 * 15.0 + 2.0,
                    -0.7 + 1.4 * ((k * 7 % 24) as f64) / 23.0,
                )
            })
            .collect();
        for fid in [Fidelity::Tip, Fidelity::Ellipsoid, Fidelity::Exact] {
            let settings = ContactSettings {
                fidelity: fid,
                ..ContactSettings::default()
            };
            group.bench_with_input(BenchmarkId::new(fid.name(), part), &cases, |b, cases| {
                b.iter(|| {
                    let mut acc = 0.0;
                    for &(th, d) in cases {
                        let pose = Pose::new(0.0, 0.0, th.to_radians());
                        let o = push(
                            &model,
                            pose,
                            Vec2::new(1.01 * a, d * a),
                            &Pin::point(),
                            &settings,
                            None,
                        );
                        acc += o.pose_final.theta_rad;
                    }
                    black_box(acc)
                })
            });
        }
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2));
    targets = bench_contacts
}
criterion_main!(benches);
