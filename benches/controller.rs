//! What the online controller costs (issue 13: ≤ 5% of a sensed line's run time). The bundled
//! sensing line, 150 parts, three ways:
//! * `no_controller`: the moving pin stays home, no rules (the sensor still reads every part);
//! * `controller_home`: the controller runs — decisions, commands, the per-part service of the
//!   pin, replanning — but every rule sends the pin home, so the physics is that of
//!   `no_controller` and the difference is the controller's own work;
//! * `controller_rules`: the bundled rules (the pin moves; different pushes).
//!
//! `cargo bench --bench controller`; figures in `results/line-speed.md`.

use criterion::{criterion_group, criterion_main, Criterion};
use pinfeed::engine::{self, RunOptions};
use pinfeed::scenario::{self, Scene};
use std::path::Path;

fn scene(text: &str) -> Scene {
    scenario::parse(Path::new("bench.toml"), text).expect("bench scenario")
}

pub fn variants() -> Vec<(&'static str, Scene)> {
    let src = std::fs::read_to_string("scenarios/tripoly1_sensing.toml").expect("bundled scenario");
    let head = src.split("[controller]").next().unwrap();
    let goal = &src[src.find("[goal]").unwrap()..];
    let none = format!("{head}{goal}");
    let home = src
        .replace("y = 0.021\n", "y = 0.012\n")
        .replace("y = -0.006\n", "y = 0.012\n");
    vec![
        ("no_controller", scene(&none)),
        ("controller_home", scene(&home)),
        ("controller_rules", scene(&src)),
    ]
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("sensing_line_150_parts");
    g.sample_size(10);
    for (name, s) in variants() {
        let mut opts = RunOptions::from_scene(&s);
        opts.parts = 150;
        g.bench_function(name, |b| {
            b.iter(|| engine::run(&s, &opts, &mut |_| {}).unwrap().summary.outcomes)
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
