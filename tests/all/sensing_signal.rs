//! Physics of the sensor signal (docs/physics.md#sensing): the force the part puts on a sensor pin, taken from the
//! push itself, and the torques about the sensor origin.

use pinfeed::geometry::{named, Polygon, Vec2};
use pinfeed::mechanics::{
    push, ContactFeature, ContactSettings, Mode, PartModel, Pin, Support, TraceSample,
};
use pinfeed::random::stream;
use pinfeed::sensing::reading::sample_ft;
use pinfeed::sensing::signal::{channels, KnotRecorder, GRAVITY};
use pinfeed::sensing::templates::{simulate, PushSetup};
use pinfeed::sensing::SensorSettings;

const PARTS: [&str; 4] = ["tripoly1", "tripoly2", "square", "rect:2:1"];
const DS: [f64; 5] = [-0.5, -0.2, 0.0, 0.25, 0.6];
const THETAS: [f64; 4] = [0.0, 37.0, 135.0, 250.0];

fn setup(part: &str, scale: f64, mu_c: f64) -> (PushSetup, PartModel) {
    setup_poly(named::part_from_spec(part).unwrap().scaled(scale), mu_c)
}

fn setup_poly(poly: Polygon, mu_c: f64) -> (PushSetup, PartModel) {
    let model = PartModel::new(&poly, &Support::Uniform).unwrap();
    (
        PushSetup {
            mu_c,
            ..PushSetup::nominal(poly, 0.0)
        },
        model,
    )
}

/// Knots of one push with the trace samples (for the per-knot checks).
fn knots(s: &PushSetup, model: &PartModel, theta: f64, d: f64) -> Vec<TraceSample> {
    let a = s.polygon.radius();
    let mut rec = KnotRecorder::default();
    push(
        model,
        pinfeed::geometry::Pose::new(0.0, 0.0, theta.to_radians()),
        Vec2::new(a * 1.01 + s.pin_radius, d * a),
        &Pin {
            radius: s.pin_radius,
            lateral_speed: 0.0,
        },
        &ContactSettings {
            mu_c: s.mu_c,
            mu_s: s.mu_s,
            fidelity: s.fidelity,
            tol: s.tol,
            ..ContactSettings::default()
        },
        Some(&mut rec),
    );
    rec.samples
}

/// Recording only observes: the outcome with a recorder is bit-identical to the one without.
#[test]
fn recording_does_not_change_the_push() {
    for part in PARTS {
        let (s, model) = setup(part, 0.02, 0.5);
        let a = s.polygon.radius();
        for th in THETAS {
            for d in DS {
                let pose = pinfeed::geometry::Pose::new(0.0, 0.0, th.to_radians());
                let start = Vec2::new(a * 1.01, d * a);
                let settings = ContactSettings::default();
                let bare = push(&model, pose, start, &Pin::point(), &settings, None);
                let mut rec = KnotRecorder::default();
                let seen = push(
                    &model,
                    pose,
                    start,
                    &Pin::point(),
                    &settings,
                    Some(&mut rec),
                );
                assert_eq!(bare, seen, "{part} θ0={th} d={d}");
            }
        }
    }
}

/// At every knot the force on the part lies in the friction cone, pressing, and on the cone's edge
/// while sliding; with a frictionless pin it is normal to the contacted edge.
#[test]
fn force_obeys_coulomb_at_every_knot() {
    for mu in [0.0, 0.25, 0.5, 1.0] {
        for part in PARTS {
            let (s, model) = setup(part, 0.02, mu);
            for th in THETAS {
                for d in DS {
                    for k in knots(&s, &model, th, d) {
                        let f = k.force;
                        let fn_ = f.dot(k.normal);
                        let ft = f.dot(k.normal.perp());
                        let mag = f.norm();
                        if mag < 1e-12 {
                            continue;
                        }
                        assert!(fn_ >= -1e-9 * mag, "{part} pulling: {fn_}");
                        assert!(
                            ft.abs() <= mu * fn_ + 1e-3 * mag,
                            "{part} μc={mu} θ0={th} d={d}: outside the cone ({ft} vs {})",
                            mu * fn_
                        );
                        if matches!(k.mode, Mode::SlideLeft | Mode::SlideRight) && mu > 0.0 {
                            assert!(
                                (ft.abs() - mu * fn_).abs() <= 1e-6 * mag,
                                "{part} μc={mu}: sliding off the cone edge"
                            );
                        }
                        if mu == 0.0 {
                            if let ContactFeature::Edge(_) = k.feature {
                                assert!(ft.abs() <= 1e-9 * mag, "frictionless: tangential {ft}");
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The torques are r × F about the sensor origin (pin axis, height h): Tx = h·Fy, Ty = −h·Fx and,
/// on a disc pin, Tz = (p − c) × F; every channel in N and N·mm.
#[test]
fn torques_are_r_cross_f() {
    let (mut s, model) = setup("tripoly2", 0.02, 0.6);
    s.pin_radius = 0.003;
    let scale = s.scale();
    let mut seen_tz = false;
    for th in THETAS {
        for d in DS {
            for k in knots(&s, &model, th, d) {
                let c = channels(&k, &scale);
                let f = -(k.force * (s.mass * GRAVITY));
                assert!((c[0] - f.x).abs() < 1e-12 && (c[1] - f.y).abs() < 1e-12);
                assert_eq!(c[2], 0.0);
                let r = k.contact_point - k.pin_centre;
                let (rx, ry, rz) = (r.x, r.y, -s.height);
                // T = r × F with F = (Fx, Fy, 0), in N·mm.
                let t = [
                    (ry * 0.0 - rz * f.y) * 1e3,
                    (rz * f.x - rx * 0.0) * 1e3,
                    (rx * f.y - ry * f.x) * 1e3,
                ];
                for i in 0..3 {
                    assert!(
                        (c[3 + i] - t[i]).abs() < 1e-9,
                        "T{i}: {} vs {}",
                        c[3 + i],
                        t[i]
                    );
                }
                seen_tz |= c[5].abs() > 1e-6;
            }
        }
    }
    assert!(
        seen_tz,
        "a frictional disc pin feels a moment about its axis"
    );
}

/// Mirroring the part about the belt axis and negating d and θ0 negates Fy, Tx and Tz and keeps
/// Fx and Ty, at every instant.
#[test]
fn mirror_symmetry_of_the_signal() {
    for part in ["tripoly1", "tripoly2", "lshape"] {
        let (s, model) = setup(part, 0.02, 0.5);
        let (sm, model_m) = setup_poly(s.polygon.mirrored_y(), 0.5);
        for th in [10.0, 135.0, 225.0] {
            for d in [-0.3, 0.2] {
                let a = simulate(&s, &model, th, d, 0.5);
                let b = simulate(&sm, &model_m, -th, -d, 0.5);
                let Some((t0, t1)) = a.signal.span() else {
                    continue;
                };
                let (u0, u1) = b.signal.span().expect("the mirror image touches too");
                assert!((t0 - u0).abs() < 1e-9 && (t1 - u1).abs() < 1e-6);
                for k in 0..200 {
                    let t = t0 + (t1 - t0) * (k as f64 + 0.5) / 200.0;
                    let (x, y) = (a.signal.at(t), b.signal.at(t));
                    let tol = 1e-4 * (1.0 + x[0].abs());
                    for (c, sign) in [(0, 1.0), (1, -1.0), (3, -1.0), (4, 1.0), (5, -1.0)] {
                        assert!(
                            (x[c] - sign * y[c]).abs() < tol * 20.0,
                            "{part} θ0={th} d={d} channel {c} at {t}: {} vs {}",
                            x[c],
                            y[c]
                        );
                    }
                }
            }
        }
    }
}

/// Force scales with μs and with the mass; the timing (the contact intervals) does not change.
#[test]
fn force_scales_with_mu_s_and_mass_timing_does_not() {
    let (s, model) = setup("tripoly1", 0.02, 0.5);
    let base = simulate(&s, &model, 135.0, -0.2, 0.5);
    for (mu_s, mass) in [(0.6, 0.05), (0.3, 0.2), (0.15, 0.01)] {
        let t = PushSetup {
            mu_s,
            mass,
            ..s.clone()
        };
        let other = simulate(&t, &model, 135.0, -0.2, 0.5);
        assert_eq!(base.signal.contacts, other.signal.contacts);
        let k = (mu_s * mass) / (s.mu_s * s.mass);
        let (b, e) = base.signal.span().unwrap();
        for i in 0..100 {
            let tt = b + (e - b) * i as f64 / 99.0;
            let (x, y) = (base.signal.at(tt), other.signal.at(tt));
            for c in 0..6 {
                assert!((y[c] - k * x[c]).abs() <= 1e-12 * (1.0 + (k * x[c]).abs()));
            }
        }
    }
}

/// Scale invariance: a part k times larger on the same belt touches k times longer with the same
/// force profile in time scaled by k (forces depend on the mass only).
#[test]
fn signal_time_scales_with_part_size() {
    let (s1, m1) = setup("tripoly2", 0.02, 0.5);
    let (s2, m2) = setup("tripoly2", 0.08, 0.5);
    let a = simulate(&s1, &m1, 90.0, 0.2, 0.5);
    let b = simulate(&s2, &m2, 90.0, 0.2, 0.5);
    let (a0, a1) = a.signal.span().unwrap();
    let (b0, b1) = b.signal.span().unwrap();
    assert!((b0 - 4.0 * a0).abs() < 1e-9 && (b1 - 4.0 * a1).abs() < 1e-6 * b1);
    for i in 0..100 {
        let t = a0 + (a1 - a0) * (i as f64 + 0.5) / 100.0;
        let (x, y) = (a.signal.at(t), b.signal.at(4.0 * t));
        assert!((x[0] - y[0]).abs() < 1e-6 && (x[1] - y[1]).abs() < 1e-6);
    }
}

/// A sensor with no noise, bias, drift, quantisation or filter reads the clean signal exactly.
#[test]
fn zero_noise_reproduces_the_template() {
    let (s, model) = setup("tripoly1", 0.02, 0.5);
    let pass = simulate(&s, &model, 0.0, -0.2, 0.5);
    let sensor = SensorSettings::default().ideal();
    let r = sample_ft(&pass.signal, &sensor, &mut stream(3, 4)).unwrap();
    assert!(r.len() > 1000, "1 kHz over ~2 s of contact");
    for (k, v) in r.values.iter().enumerate() {
        assert_eq!(*v, pass.signal.at(r.time(k)));
    }
    // Quiet on both sides of the contact, force inside it.
    let (b, e) = pass.signal.span().unwrap();
    assert_eq!(r.values[0], [0.0; 6]);
    assert_eq!(*r.values.last().unwrap(), [0.0; 6]);
    assert!(r.t0 < b && r.time(r.len() - 1) > e);
    // And the noisy sensor's mean error over the contact is the bias.
    let noisy = SensorSettings {
        bias_force: 0.1,
        resolution_force: 0.0,
        ..SensorSettings::default()
    };
    let r = sample_ft(&pass.signal, &noisy, &mut stream(3, 4)).unwrap();
    let err: f64 = (0..r.len())
        .map(|k| r.values[k][0] - pass.signal.at(r.time(k))[0])
        .sum::<f64>()
        / r.len() as f64;
    assert!((err - 0.1).abs() < 3.0 * noisy.noise_force / (r.len() as f64).sqrt() + 1e-3);
}

/// Interpolating between the integrator's knots stays close to the push resolved finely: at the
/// default tolerance the signal is within a fifth of the F/T sensor's resolution (0.025 N) of the
/// one at 10⁻¹⁰ (measured: at most 1.9e-3 N, 1.3% of μs m g, over these 27 pushes). The knots are
/// the integrator's steps, whose length is set by the motion, so this error does not shrink much
/// with the tolerance: it is the price of not solving at every sample.
#[test]
fn interpolated_signal_converges_under_refinement() {
    for part in ["tripoly1", "tripoly2", "square"] {
        for th in [0.0, 135.0, 225.0] {
            for d in [-0.3, -0.1, 0.2] {
                let err_at = |tol: f64| {
                    let (mut s, model) = setup(part, 0.02, 0.5);
                    let fine = simulate(
                        &PushSetup {
                            tol: 1e-10,
                            ..s.clone()
                        },
                        &model,
                        th,
                        d,
                        0.5,
                    );
                    s.tol = tol;
                    let coarse = simulate(&s, &model, th, d, 0.5);
                    let Some((b, e)) = fine.signal.span() else {
                        return 0.0;
                    };
                    let mut worst: f64 = 0.0;
                    for i in 0..400 {
                        let t = b + (e - b) * (i as f64 + 0.5) / 400.0;
                        // Skip instants next to an event, where the two contacts switch at
                        // slightly different times.
                        if fine
                            .signal
                            .contacts
                            .iter()
                            .any(|&(x, y)| (t - x).abs() < 1e-3 || (t - y).abs() < 1e-3)
                        {
                            continue;
                        }
                        let (x, y) = (fine.signal.at(t), coarse.signal.at(t));
                        worst = worst.max((x[0] - y[0]).abs()).max((x[1] - y[1]).abs());
                    }
                    worst
                };
                let e6 = err_at(1e-6);
                assert!(e6 < 0.005, "{part} θ0={th} d={d}: {e6} N at tol 1e-6");
            }
        }
    }
}

/// Sampling a signal in one sweep gives exactly the values of `at` at every instant, across events,
/// gaps between contacts and the quiet either side, on real pushes and on a made-up pass with two
/// contacts.
#[test]
fn sweep_sampling_equals_pointwise_evaluation() {
    for part in ["tripoly1", "tripoly2", "lshape"] {
        let (s, model) = setup(part, 0.02, 0.5);
        for th in (0..24).map(|k| k as f64 * 15.0 + 1.0) {
            for d in [-0.8, -0.5, -0.2, 0.1, 0.4, 0.7] {
                let pass = simulate(&s, &model, th, d, 0.5);
                let Some((b, e)) = pass.signal.span() else {
                    continue;
                };
                let (t0, dt) = (b - 0.05, (e - b + 0.1) / 997.0);
                let swept = pass.signal.sample(t0, dt, 1000);
                for (k, v) in swept.iter().enumerate() {
                    assert_eq!(
                        *v,
                        pass.signal.at(t0 + k as f64 * dt),
                        "{part} θ0={th} d={d} k={k}"
                    );
                }
            }
        }
    }
    // Real pushes rarely strike twice; a made-up pass with two contacts, an event inside the
    // first (a mode switch: knots on both sides at one instant) and a gap between them.
    let knot = |s: f64, fx: f64, mode: Mode, feature: ContactFeature| TraceSample {
        s,
        pose: pinfeed::geometry::Pose::new(0.0, 0.0, 0.0),
        pin_centre: Vec2::new(0.0, 0.0),
        contact_point: Vec2::new(0.0, 0.0),
        force: Vec2::new(fx, 0.1 * fx),
        normal: Vec2::new(-1.0, 0.0),
        rotation_rate: 0.0,
        mode,
        feature,
    };
    let (e0, e1) = (ContactFeature::Edge(0), ContactFeature::Edge(1));
    let samples = vec![
        knot(1.0, -0.2, Mode::Stick, e0),
        knot(1.3, -0.5, Mode::Stick, e0),
        knot(1.5, -0.6, Mode::Stick, e0),
        knot(1.5, -0.6, Mode::SlideLeft, e0),
        knot(2.0, -0.3, Mode::SlideLeft, e0),
        knot(3.0, -0.4, Mode::Stick, e1),
        knot(3.6, -0.9, Mode::Stick, e1),
        knot(4.0, -0.1, Mode::Stick, e1),
    ];
    let seg = |a: f64, b: f64, mode: Mode, feature: ContactFeature| pinfeed::mechanics::Segment {
        feature,
        mode,
        s_begin: a,
        s_end: b,
        theta_begin_rad: 0.0,
        theta_end_rad: 0.0,
    };
    let mut outcome = push(
        &setup("square", 1.0, 0.5).1,
        pinfeed::geometry::Pose::new(0.0, 0.0, 0.0),
        Vec2::new(2.0, 0.0),
        &Pin::point(),
        &ContactSettings::default(),
        None,
    );
    outcome.segments = vec![
        seg(1.0, 1.5, Mode::Stick, e0),
        seg(1.5, 2.0, Mode::SlideLeft, e0),
        seg(3.0, 4.0, Mode::Stick, e1),
    ];
    let scale = PushSetup::nominal(named::part_from_spec("square").unwrap(), 0.0).scale();
    let made = pinfeed::sensing::ContactSignal::new(&outcome, &samples, &scale);
    assert_eq!(made.contacts.len(), 2);
    let (t0, dt) = (0.5 / 0.05, 4.0 / 0.05 / 1000.0);
    let swept = made.sample(t0, dt, 1000);
    for (k, v) in swept.iter().enumerate() {
        assert_eq!(*v, made.at(t0 + k as f64 * dt), "made-up pass, k={k}");
    }
    assert!(swept.iter().any(|v| v[0] == 0.0) && swept.iter().any(|v| v[0] > 0.0));
}
