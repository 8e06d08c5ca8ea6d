//! Time per contact for each fidelity on the four reference parts (exact ≤ 50 µs median per
//! triangle contact at 0.01° self-accuracy; ellipsoid and tip ≤ 5 µs), and a batch of contacts as
//! `pinfeed contact --cases` runs it (1 200 exact contacts over 4 parts × 3 μc, from reading the
//! file to the last row: ≤ 15 µs per contact), beside the same contacts run one by one without
//! shared tables. Run: `cargo bench --features bench --bench contact`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use pinfeed::contact_case::batch::run_batch;
use pinfeed::contact_case::{compile_part, run_compiled, Case};
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

/// The cases of the batch: 4 parts × 3 μc × 100 (θ0, d) spread over the circle and ±0.9.
fn batch_rows() -> Vec<(&'static str, f64, f64, f64)> {
    let mut rows = Vec::new();
    for part in ["tripoly1", "tripoly2", "lshape", "square"] {
        for mu in [0.3, 0.5, 0.7] {
            for k in 0..100 {
                let theta = (k as f64 * 137.507_764) % 360.0;
                let d = -0.9 + 1.8 * ((k * 37 % 100) as f64) / 99.0;
                rows.push((part, theta, d, mu));
            }
        }
    }
    rows
}

fn bench_batch(c: &mut Criterion) {
    let rows = batch_rows();
    let file = std::env::temp_dir().join(format!("pinfeed-bench-batch-{}.csv", std::process::id()));
    let mut text = String::from("part,theta0,d,mu_c\n");
    for (p, t, d, mu) in &rows {
        text.push_str(&format!("{p},{t},{d},{mu}\n"));
    }
    std::fs::write(&file, text).unwrap();
    let defaults = Case::new("", 0.0, 0.0, 0.0);
    let mut group = c.benchmark_group("contact_batch");
    group.sample_size(10);
    group.bench_function("1200 cases (shared tabled models, parallel)", |b| {
        b.iter(|| {
            let mut out = Vec::with_capacity(1 << 18);
            run_batch(&defaults, &file, &mut out, &|f| f.to_string()).unwrap();
            black_box(out.len())
        })
    });
    group.bench_function("1200 cases (one by one, untabled, one thread)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            let mut compiled = std::collections::HashMap::new();
            for &(p, t, d, mu) in &rows {
                let c = Case::new(p, t, d, mu);
                let (poly, model) = compiled
                    .entry(p)
                    .or_insert_with(|| compile_part(p, "uniform").unwrap());
                acc += run_compiled(&c, poly, model, false).0.rotation_rad;
            }
            black_box(acc)
        })
    });
    group.finish();
    std::fs::remove_file(&file).unwrap();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2));
    targets = bench_contacts, bench_batch
}
criterion_main!(benches);
