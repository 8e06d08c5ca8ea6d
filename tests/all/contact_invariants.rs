//! Physics invariants of the contact model (docs/physics.md#one-instant), for every fidelity level.

use crate::common::*;
use pinfeed::geometry::{Polygon, Pose, Vec2};
use pinfeed::mechanics::{first_instant, mason_vote, ContactStatus, Fidelity, Pin};

const CASES: [(&str, f64, f64); 8] = [
    ("tripoly1", 10.0, 0.3),
    ("tripoly1", 200.0, -0.45),
    ("tripoly2", 30.0, 0.2),
    ("tripoly2", 120.0, -0.6),
    ("tripoly2", 260.0, 0.3),
    ("square", 20.0, 0.4),
    ("lshape", 75.0, -0.2),
    ("rect:2:1", 5.0, 0.15),
];

/// Every case of the table touches its part (an invariant checked on a miss proves nothing).
#[test]
fn every_case_touches() {
    for (name, th, d) in CASES {
        let p = poly(name);
        let o = run(
            &model(&p),
            &p,
            th,
            d,
            Pin::point(),
            &settings(Fidelity::Exact, 0.5),
        );
        assert!(
            o.contact && o.rotation_rad.abs() > 1e-3,
            "{name} θ0={th} d={d}"
        );
    }
}

/// μs scales forces only: the motion is bit-identical for any μs, and every recorded contact
/// force (units of m g) scales by exactly the ratio of the μs (9 here), at the same instants.
#[test]
fn mu_s_scales_forces_and_never_the_motion() {
    use pinfeed::mechanics::{push, TraceSample};
    for fid in FIDELITIES {
        for (name, th, d) in CASES {
            let p = poly(name);
            let m = model(&p);
            let mut s1 = settings(fid, 0.5);
            s1.mu_s = 0.1;
            let mut s2 = s1;
            s2.mu_s = 0.9;
            let a_len = p.radius();
            let pose = Pose::new(0.0, 0.0, th.to_radians());
            let start = Vec2::new(a_len * 1.01, d * a_len);
            let (mut ta, mut tb): (Vec<TraceSample>, Vec<TraceSample>) = (Vec::new(), Vec::new());
            let a = push(&m, pose, start, &Pin::point(), &s1, Some(&mut ta));
            let b = push(&m, pose, start, &Pin::point(), &s2, Some(&mut tb));
            assert_eq!(a, b, "{fid} {name} θ0={th} d={d}");
            assert_eq!(ta.len(), tb.len());
            assert!(!ta.is_empty());
            for (x, y) in ta.iter().zip(&tb) {
                assert_eq!((x.s, x.pose), (y.s, y.pose));
                assert!(x.force.norm() > 0.0, "{fid} {name}: zero force in contact");
                let ratio = y.force.norm() / x.force.norm();
                assert!(
                    (ratio - 9.0).abs() < 1e-12,
                    "{fid} {name}: force ratio {ratio}"
                );
                assert!(x.force.cross(y.force).abs() <= 1e-12 * y.force.norm2());
            }
        }
    }
}

/// Scaling the part (and the scene) leaves every angle unchanged and scales every length.
#[test]
fn scale_invariance() {
    for fid in FIDELITIES {
        for (name, th, d) in CASES {
            let p = poly(name);
            let base = run(&model(&p), &p, th, d, Pin::point(), &settings(fid, 0.5));
            for k in [1e-3, 7.5, 1e4] {
                let q = p.scaled(k);
                let o = run(&model(&q), &q, th, d, Pin::point(), &settings(fid, 0.5));
                assert_eq!(o.status, base.status, "{fid} {name} k={k}");
                assert!(
                    (o.rotation_rad - base.rotation_rad).abs() < 1e-9,
                    "{fid} {name} k={k}: {} vs {}",
                    o.rotation_rad,
                    base.rotation_rad
                );
                assert!((o.pose_final.x / k - base.pose_final.x).abs() < 1e-8);
                assert!((o.pose_final.y / k - base.pose_final.y).abs() < 1e-8);
                assert!((o.contact_length / k - base.contact_length).abs() < 1e-8);
            }
        }
    }
}

fn mirror(p: &Polygon) -> Polygon {
    p.mirrored_y()
}

/// Reflecting the part about the belt axis and negating d (and θ0) negates the rotation.
#[test]
fn mirror_symmetry() {
    for fid in FIDELITIES {
        for mu in [0.0, 0.3, 1.0] {
            for (name, th, d) in CASES {
                let p = poly(name);
                let q = mirror(&p);
                let a = run(&model(&p), &p, th, d, Pin::point(), &settings(fid, mu));
                let b = run(&model(&q), &q, -th, -d, Pin::point(), &settings(fid, mu));
                assert_eq!(a.contact, b.contact);
                assert!(
                    (a.rotation_rad + b.rotation_rad).abs() < 1e-7,
                    "{fid} μc={mu} {name} θ0={th} d={d}: {} vs {}",
                    a.rotation_rad.to_degrees(),
                    b.rotation_rad.to_degrees()
                );
                assert!((a.pose_final.y + b.pose_final.y).abs() < 1e-7);
                assert!((a.pose_final.x - b.pose_final.x).abs() < 1e-7);
            }
        }
    }
}

/// The sense of rotation at first contact agrees with Mason's vote whenever the vote is not a tie.
#[test]
fn mason_vote_agrees() {
    let mut checked = 0;
    for fid in FIDELITIES {
        for name in [
            "tripoly1", "tripoly2", "square", "lshape", "ngon:5", "rect:3:1",
        ] {
            let p = poly(name);
            let m = model(&p);
            let a = p.radius();
            for k in 0..36 {
                let th = k as f64 * 10.0 + 3.0;
                for d in [-0.8, -0.45, -0.1, 0.05, 0.3, 0.7] {
                    for mu in [0.0, 0.25, 0.8] {
                        let pose = Pose::new(0.0, 0.0, f64::to_radians(th));
                        let start = Vec2::new(1.01 * a, d * a);
                        let Some((g, inst)) =
                            first_instant(&m, pose, start, &Pin::point(), &settings(fid, mu))
                        else {
                            continue;
                        };
                        let vote = mason_vote(-g.p, g.n, g.v_pin, mu);
                        if vote == 0 || inst.twist[2].abs() < 1e-12 {
                            continue;
                        }
                        assert_eq!(
                            inst.twist[2].signum() as i32,
                            vote,
                            "{fid} {name} θ0={th} d={d} μc={mu} mode={:?}",
                            inst.mode
                        );
                        checked += 1;
                    }
                }
            }
        }
    }
    assert!(checked > 1000, "only {checked} votes checked");
}

/// Tightening the tolerance 100× moves the final angle by less than the stated accuracy (0.01°).
#[test]
fn self_convergence_under_tolerance() {
    for fid in FIDELITIES {
        for (name, th, d) in CASES {
            let p = poly(name);
            let m = model(&p);
            let mut s = settings(fid, 0.5);
            let a = run(&m, &p, th, d, Pin::point(), &s);
            s.tol *= 0.01;
            let b = run(&m, &p, th, d, Pin::point(), &s);
            let diff = ang_diff_deg(
                a.pose_final.theta_rad.to_degrees(),
                b.pose_final.theta_rad.to_degrees(),
            );
            assert!(diff.abs() < 0.01, "{fid} {name} θ0={th} d={d}: {diff}°");
        }
    }
}

/// A disc pin's result converges to the point pin's as ρ → 0.
#[test]
fn disc_pin_converges_to_point_pin() {
    for fid in FIDELITIES {
        for (name, th, d) in CASES {
            if name == "lshape" {
                continue; // a disc can touch both sides of the notch; covered in hard_cases
            }
            let p = poly(name);
            let m = model(&p);
            let s = settings(fid, 0.5);
            let point = run(&m, &p, th, d, Pin::point(), &s);
            let mut last = f64::INFINITY;
            for rho in [1e-2, 1e-3, 1e-4] {
                let pin = Pin {
                    radius: rho * p.radius(),
                    lateral_speed: 0.0,
                };
                let o = run(&m, &p, th, d, pin, &s);
                let diff = ang_diff_deg(
                    o.pose_final.theta_rad.to_degrees(),
                    point.pose_final.theta_rad.to_degrees(),
                )
                .abs();
                assert!(
                    diff <= last + 1e-6,
                    "{fid} {name}: ρ={rho} diff {diff} after {last}"
                );
                last = diff;
            }
            assert!(
                last < 0.05,
                "{fid} {name} θ0={th} d={d}: ρ=1e-4a still {last}° off"
            );
        }
    }
}

/// No exact-model case of the table fails numerically.
#[test]
fn statuses_are_ok_on_ordinary_cases() {
    for fid in FIDELITIES {
        for (name, th, d) in CASES {
            let p = poly(name);
            let o = run(&model(&p), &p, th, d, Pin::point(), &settings(fid, 0.5));
            assert!(
                matches!(o.status, ContactStatus::Ok),
                "{fid} {name} θ0={th} d={d}: {:?}",
                o.status
            );
            assert_finite(&o, name);
        }
    }
}

/// The tip model rotates no faster than the exact model over a push (it is the slowest COR).
#[test]
fn tip_rotates_slowest_initially() {
    for (name, th, d) in CASES {
        let p = poly(name);
        let m = model(&p);
        let a = p.radius();
        let pose = Pose::new(0.0, 0.0, th.to_radians());
        let start = Vec2::new(1.01 * a, d * a);
        let rate = |fid: Fidelity| {
            first_instant(&m, pose, start, &Pin::point(), &settings(fid, 0.0))
                .map(|(g, i)| i.twist[2].abs() / g.v_pin.norm())
        };
        if let (Some(t), Some(e)) = (rate(Fidelity::Tip), rate(Fidelity::Exact)) {
            assert!(
                t <= e * (1.0 + 1e-9),
                "{name} θ0={th} d={d}: tip {t} > exact {e}"
            );
        }
    }
}

/// The ellipsoid's accuracy gap (docs/physics.md#limit-surface): for near-central pushes (μc = 0) the exact uniform model has
/// (COR distance)·(force-line offset) → (1/A)∫x∥² dA (x∥ along the push), the ellipsoid c², so the
/// exact model turns c²/((1/A)∫x∥² dA) times faster: 1.757 on a square; on a 2×1 rectangle 1.056
/// when the pin strikes a short side (push along the long axis) and 4.22 when it strikes a long
/// side.
#[test]
fn ellipsoid_under_rotates_near_central_pushes() {
    // (part, θ0, length of the part along the push)
    for (name, theta, along) in [
        ("square", 0.0, 1.0),
        ("rect:2:1", 0.0, 2.0),
        ("rect:2:1", 90.0, 1.0),
    ] {
        let p = poly(name);
        let m = model(&p);
        let a = p.radius();
        let rate = |fid: Fidelity| {
            let pose = Pose::new(0.0, 0.0, f64::to_radians(theta));
            let start = Vec2::new(1.01 * a, 1e-4 * a);
            let (g, i) = first_instant(&m, pose, start, &Pin::point(), &settings(fid, 0.0))
                .expect("the pin strikes the face");
            i.twist[2] / g.v_pin.norm()
        };
        let ratio = rate(Fidelity::Exact) / rate(Fidelity::Ellipsoid);
        let c = m.ellipsoid_c() * a;
        let expected = c * c / (along * along / 12.0);
        assert!(
            (ratio - expected).abs() < 0.01 * expected,
            "{name} θ0={theta}: exact/ellipsoid rotation rate {ratio:.4}, formula {expected:.4}"
        );
    }
    // The numbers docs/physics.md#limit-surface quotes.
    let sq = model(&poly("square")).ellipsoid_c() * poly("square").radius();
    assert!((sq * sq * 12.0 - 1.757).abs() < 0.01);
    let r = model(&poly("rect:2:1")).ellipsoid_c() * poly("rect:2:1").radius();
    assert!((r * r * 12.0 - 4.223).abs() < 0.01);
}
