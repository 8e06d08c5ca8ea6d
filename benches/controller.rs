//! What the online controller costs (≤ 5% of a sensed line's run time). The bundled
//! sensing line, 150 parts, three ways:
//! * `no_controller`: the moving pin stays home, no rules (the sensor still reads every part);
//! * `controller_home`: the controller runs — decisions, commands, the per-part service of the
//!   pin, replanning — but every rule sends the pin home, so the physics is that of
//!   `no_controller` and the difference is the controller's own work;
//! * `controller_rules`: the bundled rules (the pin moves; different pushes).
//!
//! `cargo bench --features bench --bench controller`; figures in `results/line-speed.md`.
//!
//! Also `ramp_pieces/N`: one push by a pin that accelerates across the belt during the contact,
//! the acceleration phase resolved into N constant-speed pieces (the accuracy of each N against
//! 256 pieces: `cargo test --release --test all moving_pin::piecewise -- --nocapture`).

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
            b.iter(|| {
                engine::run(&s, &opts, &mut |_| {})
                    .unwrap()
                    .summary
                    .outcomes
            })
        });
    }
    g.finish();
}

fn ramp(c: &mut Criterion) {
    use pinfeed::geometry::{part_from_spec, Pose, Vec2};
    use pinfeed::mechanics::{
        pin_first_touch, push_path, ContactSettings, PartModel, PinPath, Support,
    };
    let p = part_from_spec("tripoly2").unwrap();
    let m = PartModel::new(&p, &Support::Uniform).unwrap();
    let a = p.radius();
    let pose = Pose::new(0.0, 0.0, 0.3);
    let start = Vec2::new(1.5 * a, 0.15 * a);
    let touch = pin_first_touch(&m, pose, start, 0.0, &PinPath::constant(0.0)).unwrap();
    let settings = ContactSettings::default();
    let mut g = c.benchmark_group("ramp_pieces");
    for n in [1usize, 2, 8, 32, 256] {
        // The same ramp as tests/all/moving_pin.rs: 0 → −0.6 belt speeds over a travel of a.
        let path = PinPath::ramp(touch + 0.05 * a, a, -0.6, n).unwrap();
        g.bench_function(format!("{n}"), |b| {
            b.iter(|| push_path(&m, pose, start, 0.0, &path, &settings, None).pose_final)
        });
    }
    g.finish();
}

criterion_group!(benches, bench, ramp);
criterion_main!(benches);
