//! Calibration of an ensemble against measurements, as `pinfeed calibrate
//! tests/fixtures/validate/synthetic.csv --jitter 3` runs it (2 000 proposal members, the
//! likelihood grid reweighting their predictions): the whole calibration, and its two parts —
//! the proposal's predictions (every member's pushes) and the grid (reweighting only).
//! Run: `cargo bench --features bench --bench calibrate`.

use criterion::{criterion_group, criterion_main, Criterion};
use pinfeed::validate::calibrate::{calibrate, CalibrationSettings};
use pinfeed::validate::input::load_measured;
use pinfeed::validate::predict::predict;
use std::hint::black_box;
use std::time::Duration;

fn bench_calibrate(c: &mut Criterion) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/validate/synthetic.csv"
    );
    let settings = CalibrationSettings {
        jitter_deg: 3.0,
        ..CalibrationSettings::default()
    };
    let measured = load_measured(std::path::Path::new(path), &settings.proposal(), None).unwrap();
    let mut g = c.benchmark_group("calibrate");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(1))
        .measurement_time(Duration::from_secs(20));
    g.bench_function("synthetic.csv --jitter 3 (whole)", |b| {
        b.iter(|| black_box(calibrate(&measured, &settings).unwrap().log_likelihood))
    });
    g.bench_function("synthetic.csv --jitter 3 (predictions only)", |b| {
        b.iter(|| {
            let p = predict(
                &measured,
                &settings.proposal(),
                settings.seed,
                settings.members,
                settings.passes,
            )
            .unwrap();
            black_box(p.rows.len())
        })
    });
    g.finish();
}

criterion_group!(benches, bench_calibrate);
criterion_main!(benches);
