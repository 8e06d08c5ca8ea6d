//! What the online controller costs (docs/physics.md#belief-and-online-replanning):
//! * `decision/*`: one decision on `scenarios/tripoly1_online.toml` (54 hypotheses, 28 joint
//!   commands): the sensor's classification, the reading's likelihood over the hypotheses (the
//!   channels its model calibrated in), the belief's update, and the choice of the joint command
//!   — what the controller computes when a reading arrives; the likelihood alone; the choice
//!   alone; `decision/tripoly2_*` the same on `scenarios/tripoly2_online.toml`, whose
//!   likelihood includes the matched filter over its 324 simulated members;
//! * `line_150_parts/*`: the same line driven by its rules and by the online controller (the
//!   model is built once, outside the timing); `tripoly2_line_150_parts/*` the same for
//!   tripoly2's line, whose model also uses the matched filter.
//!
//! `cargo bench --features bench --bench online`; figures in `results/online.md`.

use criterion::{criterion_group, criterion_main, Criterion};
use pinfeed::engine::{self, RunOptions};
use pinfeed::random::stream;
use pinfeed::scenario::{self, Obstacle, Scene};
use pinfeed::sensing::reading::read;
use pinfeed::sensing::templates::{simulate, PushSetup};
use std::path::Path;

fn load(path: &str) -> Scene {
    let text = std::fs::read_to_string(path).expect("bundled scenario");
    scenario::parse(Path::new(path), &text).expect("bundled scenario parses")
}

fn decision(c: &mut Criterion) {
    let mut g = c.benchmark_group("decision");
    for (name, path, d) in [
        ("", "scenarios/tripoly1_online.toml", -0.22),
        ("tripoly2_", "scenarios/tripoly2_online.toml", 0.3),
    ] {
        let scene = load(path);
        let model = pinfeed::engine::prepare::online_model(&scene)
            .unwrap()
            .expect("an online model")
            .0;
        let sm = &model.sensors[0];
        let Obstacle::Pin(pin) = &scene.obstacles[sm.obstacle] else {
            panic!("the sensor is a pin")
        };
        let settings = pin.sensor.as_ref().unwrap().settings;
        let classifier = pin.sensor.as_ref().unwrap().classifier.clone();
        // A reading of state 135° at offset d, read through the sensor's noise.
        let mut setup = PushSetup::nominal(scene.part.polygon.clone(), d);
        setup.pin_radius = pin.radius;
        setup.mass = scene.part.mass;
        let pass = simulate(&setup, &scene.part.model, 135.0, d, 0.5);
        let reading = read(&pass.signal, &settings, &mut stream(1, 7)).expect("a reading");
        g.bench_function(format!("{name}reading_update_choose"), |b| {
            b.iter(|| {
                let mut belief = model.prior.clone();
                let post = classifier.classify(&reading).posterior;
                let ll = sm.log_likelihood(Some(&reading), post.as_deref());
                belief.observe_reading(&sm.p_touch, ll.as_deref());
                model.choose(&belief).action
            })
        });
        let post = classifier.classify(&reading).posterior;
        g.bench_function(format!("{name}likelihood"), |b| {
            b.iter(|| sm.log_likelihood(Some(&reading), post.as_deref()))
        });
        let mut belief = model.prior.clone();
        let ll = sm.log_likelihood(Some(&reading), post.as_deref());
        belief.observe_reading(&sm.p_touch, ll.as_deref());
        g.bench_function(format!("{name}choose"), |b| {
            b.iter(|| model.choose(&belief).action)
        });
    }
    g.finish();
}

fn line(c: &mut Criterion) {
    let online = load("scenarios/tripoly1_online.toml");
    let text = std::fs::read_to_string("scenarios/tripoly1_online.toml").unwrap();
    let head = text.split("mode = \"online\"").next().unwrap();
    let rules_part = &text[text.find("# The bundled rules").unwrap()..];
    let rules = scenario::parse(Path::new("rules.toml"), &format!("{head}\n{rules_part}"))
        .expect("the rules variant parses");
    pair(c, "line_150_parts", &rules, &online);
    // tripoly2's line, where the model keeps the matched filter: the same layout with its rules.
    let online = load("scenarios/tripoly2_online.toml");
    let rules = load("results/online/uncertainty/designs/tripoly2_rules.toml");
    pair(c, "tripoly2_line_150_parts", &rules, &online);
}

/// 150 parts through the same line driven by its rules and by the online controller.
fn pair(c: &mut Criterion, group: &str, rules: &Scene, online: &Scene) {
    let mut g = c.benchmark_group(group);
    g.sample_size(10);
    for (name, s) in [("rules", rules), ("online", online)] {
        let mut opts = RunOptions::from_scene(s);
        opts.parts = 150;
        g.bench_function(name, |b| {
            b.iter(|| engine::run(s, &opts, &mut |_| {}).unwrap().summary.outcomes)
        });
    }
    g.finish();
}

criterion_group!(benches, decision, line);
criterion_main!(benches);
