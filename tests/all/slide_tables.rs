//! The exact model's slide tables (`mechanics::slide_table`, issue 15): contacts served by them
//! match the solves they replace within the integration error, and most far inside it, for point,
//! disc and moving pins and any μc; they do serve (the evaluations fall); and a scene that never slides on an
//! edge with the exact model builds none, while a line run with them gives the same outcomes as
//! without.

use pinfeed::engine::{self, RunOptions};
use pinfeed::geometry::{part_from_spec, Pose, Vec2};
use pinfeed::mechanics::{push, ContactSettings, Fidelity, PartModel, Pin, Support};
use pinfeed::scenario::{self, Scene};
use std::path::Path;

/// A reproducible stream of (θ0 in degrees, d in [−0.9, 0.9]).
fn cases(n: usize, seed: u64) -> Vec<(f64, f64)> {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| (360.0 * next(), -0.9 + 1.8 * next()))
        .collect()
}

#[test]
fn contacts_with_tables_match_the_solves_they_replace() {
    let mut checked = 0;
    for part in ["tripoly1", "lshape", "square"] {
        let poly = part_from_spec(part).unwrap();
        let a = poly.radius();
        let plain = PartModel::new(&poly, &Support::Uniform).unwrap();
        for mu_c in [0.0, 0.5, 1.0] {
            let tabled = plain.clone().with_slide_tables(&[mu_c]);
            let settings = ContactSettings {
                fidelity: Fidelity::Exact,
                mu_c,
                ..ContactSettings::default()
            };
            let pins = [
                Pin::point(),
                Pin {
                    radius: 0.1 * a,
                    ..Pin::point()
                },
                Pin {
                    lateral_speed: 0.3,
                    ..Pin::point()
                },
            ];
            for pin in pins {
                let (mut ev_plain, mut ev_tabled) = (0u64, 0u64);
                let mut dthetas = Vec::new();
                for (th, d) in cases(40, checked as u64 + 1) {
                    let pose = Pose::new(0.0, 0.0, th.to_radians());
                    let start = Vec2::new(1.2 * a, d * a);
                    let p = push(&plain, pose, start, &pin, &settings, None);
                    let t = push(&tabled, pose, start, &pin, &settings, None);
                    assert_eq!(
                        p.status.name(),
                        t.status.name(),
                        "{part} μc {mu_c} {pin:?} θ0 {th} d {d}"
                    );
                    assert_eq!(p.contacts, t.contacts);
                    let dtheta = (p.pose_final.theta_rad - t.pose_final.theta_rad).abs();
                    let dpos = ((p.pose_final.x - t.pose_final.x).powi(2)
                        + (p.pose_final.y - t.pose_final.y).powi(2))
                    .sqrt()
                        / a;
                    // Within the integration tolerance (1e-6) everywhere: a change of 1e-10 in
                    // a rate can move where the landing on an event stops, within its tolerance
                    // on the event function, and where that function only grazes zero (a pin
                    // leaving the part) the end of contact moves much more (worst here: 6e-7 a
                    // of travel and 2.6e-7 rad, a disc that rode round the L's vertex and
                    // then slid off an edge at μc 0)...
                    assert!(
                        dtheta < 1e-6 && dpos < 1e-6,
                        "{part} μc {mu_c} {pin:?} θ0 {th} d {d}: Δθ {dtheta:e} Δc {dpos:e}"
                    );
                    dthetas.push(dtheta);
                    ev_plain += p.evaluations;
                    ev_tabled += t.evaluations;
                    checked += 1;
                }
                // ... and far inside it on most contacts (a table is within 1e-10 of its solve).
                dthetas.sort_by(f64::total_cmp);
                let median = dthetas[dthetas.len() / 2];
                assert!(
                    median < 1e-9,
                    "{part} μc {mu_c} {pin:?}: median Δθ {median:e}"
                );
                // The tables serve: a large share of the solves costs no evaluation.
                assert!(
                    (ev_tabled as f64) < 0.75 * ev_plain as f64,
                    "{part} μc {mu_c} {pin:?}: {ev_tabled} evaluations with tables, {ev_plain} without"
                );
            }
            let st = tabled.slide_table_stats().unwrap();
            assert!(
                st.tables > 0 && st.uncertified == 0,
                "{part} μc {mu_c}: {st:?}"
            );
        }
    }
    assert_eq!(checked, 3 * 3 * 3 * 40);
}

#[test]
fn other_fidelities_and_other_mu_build_and_use_no_table() {
    let poly = part_from_spec("tripoly2").unwrap();
    let a = poly.radius();
    let tabled = PartModel::new(&poly, &Support::Uniform)
        .unwrap()
        .with_slide_tables(&[0.5]);
    for (fid, mu_c) in [
        (Fidelity::Tip, 0.5),
        (Fidelity::Ellipsoid, 0.5),
        (Fidelity::Exact, 0.4),
    ] {
        let s = ContactSettings {
            fidelity: fid,
            mu_c,
            ..ContactSettings::default()
        };
        for (th, d) in cases(30, 7) {
            let o = push(
                &tabled,
                Pose::new(0.0, 0.0, th.to_radians()),
                Vec2::new(1.2 * a, d * a),
                &Pin::point(),
                &s,
                None,
            );
            assert!(o.status.is_ok());
        }
    }
    assert_eq!(tabled.slide_table_stats().unwrap().tables, 0);
}

fn scene(fidelity: &str) -> Scene {
    let text = format!(
        r#"name = "tables"
[belt]
speed = 0.05
width = 0.1
length = 0.6
[part]
shape = "tripoly2"
scale = 0.02
[feed]
parts = 60
arrival = "periodic"
headway = 4.0
orientation = "stable"
weights = [1, 1, 1]
jitter = 3.0
[feed.lateral]
distribution = "uniform"
min = -0.003
max = 0.003
[[obstacles]]
kind = "pin"
x = 0.15
y = 0.004
radius = 0.002
[[obstacles]]
kind = "pin"
x = 0.30
y = -0.012
radius = 0.002
mu_c = 0.3
[model]
fidelity = "{fidelity}"
[goal]
any = true
"#
    );
    scenario::parse(Path::new("tables.toml"), &text).unwrap_or_else(|e| panic!("{e}"))
}

fn records(scene: &Scene) -> Vec<pinfeed::engine::PartRecord> {
    let opts = RunOptions {
        keep_records: true,
        ..RunOptions::from_scene(scene)
    };
    engine::run(scene, &opts, &mut |_| {}).unwrap().records
}

#[test]
fn a_line_builds_tables_only_for_the_exact_model_and_keeps_its_outcomes() {
    // Tip fidelity: the scene's model has tables for its pins' μc but never builds one.
    let tip = scene("tip");
    records(&tip);
    assert_eq!(tip.part.model.slide_table_stats().unwrap().tables, 0);

    // Exact: tables for both pins' μc are built as parts slide, and every part ends as it does
    // with the slides solved.
    let exact = scene("exact");
    let with = records(&exact);
    let st = exact.part.model.slide_table_stats().unwrap();
    assert!(st.tables > 0, "{st:?}");
    let mut solved = scene("exact");
    solved.part.model = PartModel::new(&solved.part.polygon, &Support::Uniform).unwrap();
    let without = records(&solved);
    assert_eq!(with.len(), without.len());
    for (w, s) in with.iter().zip(&without) {
        assert_eq!(
            (w.part, w.outcome, w.contacts),
            (s.part, s.outcome, s.contacts)
        );
        assert!(
            (w.theta_out_deg - s.theta_out_deg).abs() < 1e-6,
            "{w:?} {s:?}"
        );
        assert!((w.end_s - s.end_s).abs() < 1e-6);
    }
}

/// A pass's work budget counts the integrator's right-hand sides, not only limit-surface
/// evaluations: a contact the tables serve costs few evaluations, and a pass that crawls (steps
/// shrinking near an edge's end, as a planner met on random:18) must still stop at the budget
/// instead of running on.
#[test]
fn the_work_budget_bounds_a_pass_the_tables_serve() {
    use pinfeed::mechanics::ContactStatus;
    let poly = part_from_spec("tripoly1").unwrap();
    let a = poly.radius();
    let tabled = PartModel::new(&poly, &Support::Uniform)
        .unwrap()
        .with_slide_tables(&[0.0]);
    // Frictionless: every instant is a slide, and the tables serve nearly all of them.
    let free = ContactSettings {
        mu_c: 0.0,
        ..ContactSettings::default()
    };
    let tight = ContactSettings {
        max_evaluations: 40,
        ..free
    };
    let mut checked = 0;
    for (th, d) in cases(40, 7) {
        let pose = Pose::new(0.0, 0.0, th.to_radians());
        let start = Vec2::new(1.2 * a, d * a);
        let full = push(&tabled, pose, start, &Pin::point(), &free, None);
        // Contacts that need more than 40 right-hand sides but fewer than 40 evaluations: only
        // a budget that counts the right-hand sides stops them.
        if !(full.status == ContactStatus::Ok && full.evaluations < 40 && full.steps >= 8) {
            continue;
        }
        let cut = push(&tabled, pose, start, &Pin::point(), &tight, None);
        assert!(
            matches!(cut.status, ContactStatus::EvaluationLimit { evaluations } if evaluations > 40),
            "θ0 {th} d {d}: {:?} after {} evaluations",
            cut.status,
            cut.evaluations
        );
        checked += 1;
    }
    assert!(
        checked >= 5,
        "only {checked} contacts served mostly by the tables"
    );
}
