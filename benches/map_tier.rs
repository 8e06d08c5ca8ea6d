//! The map tier against the exact model on the same pushes (≥ 100× faster per
//! contact). tripoly2, a pin of radius 0.1 a, μc 0.5, tol 1e-6, the default grid (read from the
//! cache folder, built on the first run). Three measurements over 256 random pushes (θ0 uniform,
//! d uniform in ±0.6): `served` — the pushes the map answers (ray cast + interpolation),
//! `exact_served` — the same pushes by the exact model, `mixed` — every push through
//! `push_with_map` (the exact model where the map is not certified), `exact_all` — every push
//! exact. And the build (no cache): `build/query cell` — the one base cell a single query needs
//! (`contact --model map`: θ0 100°, d 0.3), `build/whole map 36x12x2` — every base cell of a
//! coarser grid than the default, `build/quickstart line, 2000 parts, empty map` — the bundled
//! quickstart on the map tier (default grid) from an empty map: the line builds the base cells its
//! parts reach as they reach them. Run: `cargo bench --features bench --bench map_tier`.

use criterion::{criterion_group, criterion_main, Criterion};
use pinfeed::engine::{self, contact_map, RunOptions};
use pinfeed::geometry::{part_from_spec, Pose, Vec2};
use pinfeed::maps::tier::{self, push_with_map, TierInputs, TierSpec};
use pinfeed::mechanics::{push_path, ContactSettings, PartModel, PinPath, Support};
use pinfeed::random::stream;
use rand::RngExt;
use std::hint::black_box;

const RADIUS: f64 = 0.1;

fn bench_map_tier(c: &mut Criterion) {
    let poly = part_from_spec("tripoly2").unwrap();
    let poly = poly.scaled(1.0 / poly.radius());
    let model = PartModel::new(&poly, &Support::Uniform).unwrap();
    let settings = ContactSettings::default();
    let inputs = TierInputs {
        model: &model,
        support: &Support::Uniform,
        radius: RADIUS,
        settings,
        spec: TierSpec::default(),
    };
    let loaded = tier::shared(&inputs, Some(&tier::default_cache_dir()));
    let map = loaded.map;
    let mut rng = stream(7, 0);
    let all: Vec<(Pose, Vec2)> = (0..256)
        .map(|_| {
            let pose = Pose::new(0.0, 0.0, rng.random::<f64>() * std::f64::consts::TAU);
            let d = (rng.random::<f64>() * 2.0 - 1.0) * 0.6;
            (pose, Vec2::new(2.5, d))
        })
        .collect();
    let served: Vec<(Pose, Vec2)> = all
        .iter()
        .copied()
        .filter(|&(pose, pin)| map.answer(&model, pose, pin, RADIUS).is_ok())
        .collect();
    println!(
        "map_tier: {} of {} pushes served by the map",
        served.len(),
        all.len()
    );
    let path = PinPath::constant(0.0);
    let exact = |set: &[(Pose, Vec2)]| {
        let mut acc = 0.0;
        for &(pose, pin) in set {
            acc += push_path(&model, pose, pin, RADIUS, &path, &settings, None).rotation_rad;
        }
        acc
    };
    let mut group = c.benchmark_group("map_tier");
    group.bench_function("served", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &(pose, pin) in &served {
                acc += map.answer(&model, pose, pin, RADIUS).unwrap().rotation_rad;
            }
            black_box(acc)
        })
    });
    group.bench_function("exact_served", |b| b.iter(|| black_box(exact(&served))));
    group.bench_function("mixed", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &(pose, pin) in &all {
                acc += push_with_map(&map, &model, pose, pin, RADIUS, &settings)
                    .0
                    .rotation_rad;
            }
            black_box(acc)
        })
    });
    group.bench_function("exact_all", |b| b.iter(|| black_box(exact(&all))));
    group.finish();
}

fn bench_build(c: &mut Criterion) {
    let poly = part_from_spec("tripoly2").unwrap();
    let poly = poly.scaled(1.0 / poly.radius());
    let model = PartModel::new(&poly, &Support::Uniform).unwrap();
    let inputs = TierInputs {
        model: &model,
        support: &Support::Uniform,
        radius: RADIUS,
        settings: ContactSettings::default(),
        spec: TierSpec::default(),
    };
    let pose = Pose::new(0.0, 0.0, 100f64.to_radians());
    let cell = tier::cell_of_query(&inputs, pose, Vec2::new(2.5, 0.3)).unwrap();
    let mut group = c.benchmark_group("map_tier_build");
    group.sample_size(10);
    group.bench_function("query cell", |b| {
        b.iter(|| {
            let loaded = tier::load_or_build_cells(&inputs, None, Some(&[cell]), &|_, _| {});
            black_box(loaded.map.stats.exact_samples)
        })
    });
    let coarse = TierInputs {
        spec: TierSpec {
            max_depth: 2,
            ..TierSpec::default()
        },
        ..inputs
    };
    group.bench_function("whole map 36x12x2", |b| {
        b.iter(|| black_box(tier::build(&coarse).stats.exact_samples))
    });
    let mut scene = pinfeed::scenario::load(std::path::Path::new("scenarios/quickstart.toml"))
        .expect("the bundled quickstart");
    scene.map_tier = Some(TierSpec::default());
    let opts = RunOptions {
        parts: 2000,
        ..RunOptions::from_scene(&scene)
    };
    group.bench_function("quickstart line, 2000 parts, empty map", |b| {
        b.iter(|| {
            // This process's maps forgotten, then an empty one (no cache folder) for the line.
            tier::lazy::forget_all();
            let pins = contact_map::load(&scene, None);
            let run = engine::run(&scene, &opts, &mut |_| {}).expect("the line runs");
            black_box((run.summary.parts_in, pins[0].map.built_now().0))
        })
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(std::time::Duration::from_secs(3));
    targets = bench_map_tier, bench_build
}
criterion_main!(benches);
