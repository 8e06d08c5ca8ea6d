//! What the event trace (`pinfeed run --trace`) and the closed loop cost:
//! * `trace_quickstart_2000_parts/*`, `trace_tripoly1_loop_200_parts/*`: the run without a
//!   trace (`off`), with every event handed to a sink that only counts it (`noted`: the engine's
//!   own cost of the trace) and written to a JSON-lines file (`file`: what `--trace` does);
//! * `loop_vs_open_200_parts/*`: scenarios/tripoly1_loop.toml closed and the same scene open
//!   (`closed_loop = None`), in parts per second (the closed loop's parts include their passes).
//!
//! `cargo bench --features bench --bench trace`; figures in `results/trace-cost.md`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pinfeed::engine::{self, trace, RunOptions};
use pinfeed::scenario::{self, Scene};

fn load(path: &str) -> Scene {
    scenario::load(std::path::Path::new(path)).expect("bundled scenario")
}

fn options(scene: &Scene, parts: u64) -> RunOptions {
    RunOptions {
        parts,
        ..RunOptions::from_scene(scene)
    }
}

fn cost_of_the_trace(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("pinfeed-bench-trace-{}", std::process::id()));
    for (group, path, parts) in [
        (
            "trace_quickstart_2000_parts",
            "scenarios/quickstart.toml",
            2000,
        ),
        (
            "trace_tripoly1_loop_200_parts",
            "scenarios/tripoly1_loop.toml",
            200,
        ),
    ] {
        let scene = load(path);
        let opts = options(&scene, parts);
        let file = dir.join(format!("{group}.jsonl"));
        let mut g = c.benchmark_group(group);
        g.sample_size(10);
        g.bench_function("off", |b| {
            b.iter(|| {
                engine::run(&scene, &opts, &mut |_| {})
                    .unwrap()
                    .summary
                    .outcomes
            })
        });
        g.bench_function("noted", |b| {
            b.iter(|| {
                let mut n = 0u64;
                let r = trace::run_traced(&scene, &opts, &mut |_| {}, &mut |_| n += 1).unwrap();
                (r.summary.outcomes, n)
            })
        });
        g.bench_function("file", |b| {
            b.iter(|| {
                let r = trace::run_to_file(&scene, &opts, &mut |_| {}, &file).unwrap();
                r.summary.outcomes
            })
        });
        g.finish();
    }
    let _ = std::fs::remove_dir_all(&dir);
}

fn loop_beside_open(c: &mut Criterion) {
    let closed = load("scenarios/tripoly1_loop.toml");
    let open = Scene {
        closed_loop: None,
        ..closed.clone()
    };
    let mut g = c.benchmark_group("loop_vs_open_200_parts");
    g.sample_size(10).throughput(Throughput::Elements(200));
    for (name, scene) in [("closed", &closed), ("open", &open)] {
        let opts = options(scene, 200);
        g.bench_function(name, |b| {
            b.iter(|| {
                engine::run(scene, &opts, &mut |_| {})
                    .unwrap()
                    .summary
                    .outcomes
            })
        });
    }
    g.finish();
}

criterion_group!(benches, cost_of_the_trace, loop_beside_open);
criterion_main!(benches);
