//! Ensemble maps: tripoly1, 200 members × 6 d × 360 θ0 (432 000 passes, exact model)
//! with μc, support, pin radius and pose all uncertain; the target is under a minute on 2 cores.
//! The timed CLI run and its figure are in results/validation.md.

use criterion::{criterion_group, criterion_main, Criterion};
use pinfeed::maps::ensemble::{ensemble_maps, EnsembleSpec};
use pinfeed::maps::theta_grid;
use pinfeed::mechanics::Fidelity;
use std::time::Duration;

fn ensemble_200x6x360(c: &mut Criterion) {
    let poly = pinfeed::geometry::part_from_spec("tripoly1").unwrap();
    let spec = EnsembleSpec::nominal(0.5, 0.0, Fidelity::Exact, 1e-6)
        .with_settings("mu_c=normal:0.5:0.1,support=tripod:0.5,pin_radius=uniform:0:0.1,jitter=2")
        .unwrap();
    let ds = [-0.9, -0.5, -0.1, 0.1, 0.5, 0.9];
    let grid = theta_grid(1.0).unwrap();
    let mut g = c.benchmark_group("ensemble");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(1))
        .measurement_time(Duration::from_secs(60));
    g.bench_function("tripoly1 200 members x 6 d x 360 theta0 (exact)", |b| {
        b.iter(|| {
            let maps = ensemble_maps(&poly, &spec, &ds, &grid, 1, 200).unwrap();
            assert_eq!(maps.theta_f.len(), 200 * 6 * 360);
        })
    });
    g.finish();
}

criterion_group!(benches, ensemble_200x6x360);
criterion_main!(benches);
