//! Moving pins in the contact model (docs/physics.md#moving-and-retractable-pins): one push with the pin's true relative velocity,
//! its lateral speed piecewise constant in travel.

use crate::common::*;
use pinfeed::geometry::{Pose, Vec2};
use pinfeed::mechanics::{
    pin_first_touch, push_path, ContactOutcome, ContactSettings, PartModel, PinPath, TraceSample,
    Turn,
};

fn moving(
    m: &PartModel,
    pose: Pose,
    start: Vec2,
    rho: f64,
    path: &PinPath,
    s: &ContactSettings,
) -> (ContactOutcome, Vec<TraceSample>) {
    let mut trace = Vec::new();
    let o = push_path(m, pose, start, rho, path, s, Some(&mut trace));
    (o, trace)
}

fn rot(p: Pose, beta: f64) -> Pose {
    let c = p.position().rotate(beta);
    Pose::new(c.x, c.y, p.theta_rad + beta)
}

/// Galilean check (docs/physics.md#moving-and-retractable-pins): a pin moving at constant lateral speed w relative to the belt pushes
/// exactly as a still pin met by a belt moving along (V, −w): the same push seen in a frame turned
/// by atan w. Over parts, orientations, offsets, radii and all three fidelities.
#[test]
fn constant_lateral_speed_is_a_rotated_still_push() {
    let mut compared = 0;
    for name in ["tripoly1", "tripoly2", "rect:2:1", "lshape"] {
        let p = poly(name);
        let m = model(&p);
        let a = p.radius();
        for fid in FIDELITIES {
            let s = settings(fid, 0.5);
            for (i, w) in [-0.6, -0.2, 0.3, 1.0].into_iter().enumerate() {
                let theta0 = (37.0 + 71.0 * i as f64).to_radians();
                for d in [-0.3, 0.05, 0.4] {
                    for rho in [0.0, 0.05 * a] {
                        let pose = Pose::new(0.0, 0.0, theta0);
                        let start = Vec2::new(1.5 * a + rho, d * a);
                        let path = PinPath::constant(w);
                        let (mv, _) = moving(&m, pose, start, rho, &path, &s);
                        // The frame in which the pin's path (−1, w) runs along −x.
                        let beta = w.atan();
                        let still = push_path(
                            &m,
                            rot(pose, beta),
                            start.rotate(beta),
                            rho,
                            &PinPath::constant(0.0),
                            &s,
                            None,
                        );
                        assert_eq!(mv.contact, still.contact, "{name} {fid} w={w} d={d}");
                        if !(mv.status.is_ok() && still.status.is_ok()) {
                            continue;
                        }
                        let back = rot(still.pose_final, -beta);
                        let f = mv.pose_final;
                        let tol = 1e-4 * a;
                        assert!(
                            (f.x - back.x).abs() < tol
                                && (f.y - back.y).abs() < tol
                                && ang_diff_deg(
                                    f.theta_rad.to_degrees(),
                                    back.theta_rad.to_degrees()
                                ) < 1e-3,
                            "{name} {fid} w={w} d={d} ρ={rho}: {f:?} vs {back:?}"
                        );
                        compared += usize::from(mv.contact);
                    }
                }
            }
        }
    }
    assert!(compared > 100, "only {compared} touching cases compared");
}

/// A pin commanded to stop mid-contact: its push up to the stop is the moving push, and from the
/// stop on it is a still pin's push of the part where the stop left it.
#[test]
fn stop_mid_contact_is_a_moving_push_then_a_still_one() {
    let (mut checked, mut differs) = (0, 0);
    for name in ["tripoly1", "tripoly2", "rect:2:1"] {
        let p = poly(name);
        let m = model(&p);
        let a = p.radius();
        for fid in FIDELITIES {
            let s = settings(fid, 0.5);
            for (theta0, d, w) in [(10.0, 0.2, 0.5), (100.0, -0.1, -0.4), (250.0, 0.3, 0.8)] {
                let pose = Pose::new(0.0, 0.0, f64::to_radians(theta0));
                let start = Vec2::new(1.2 * a, d * a);
                let (first, _) = moving(&m, pose, start, 0.0, &PinPath::constant(w), &s);
                if !first.contact || !first.status.is_ok() {
                    continue;
                }
                // Stop halfway through the first contact.
                let s_stop = first.travel_to_contact
                    + 0.5
                        * first.segments[0]
                            .s_end
                            .min(first.travel_to_contact + first.contact_length)
                    - 0.5 * first.travel_to_contact;
                let stop = PinPath::new(w, vec![Turn { s: s_stop, w: 0.0 }]).unwrap();
                let (stopped, st) = moving(&m, pose, start, 0.0, &stop, &s);
                assert!(stopped.status.is_ok(), "{name} {fid}: {:?}", stopped.status);
                // Up to the stop: the moving push's trajectory (a turn to the same speed puts a
                // knot at the stop on the moving push too).
                let same = PinPath::new(w, vec![Turn { s: s_stop, w }]).unwrap();
                let (_, mt) = moving(&m, pose, start, 0.0, &same, &s);
                let knot = |tr: &[TraceSample]| -> TraceSample {
                    *tr.iter()
                        .find(|k| (k.s - s_stop).abs() <= 1e-9 * a)
                        .expect("the turn is recorded")
                };
                let (at, pa) = (knot(&st), knot(&mt));
                assert!(
                    (at.pose.theta_rad - pa.pose.theta_rad).abs() < 1e-12
                        && (at.pose.position() - pa.pose.position()).norm() < 1e-12 * a,
                    "{name} {fid}: {:?} vs {:?}",
                    at.pose,
                    pa.pose
                );
                assert!((at.pin_centre - pa.pin_centre).norm() < 1e-12 * a);
                // From there on: a still pin, backed off by 1e-7 a along the belt.
                let resumed = push_path(
                    &m,
                    at.pose,
                    at.pin_centre + Vec2::new(1e-7 * a, 0.0),
                    0.0,
                    &PinPath::constant(0.0),
                    &s,
                    None,
                );
                assert!(resumed.status.is_ok(), "{:?}", resumed.status);
                let (f, g) = (stopped.pose_final, resumed.pose_final);
                let dth = ang_diff_deg(f.theta_rad.to_degrees(), g.theta_rad.to_degrees());
                assert!(
                    dth < 1e-2 && (f.y - g.y).abs() < 1e-4 * a,
                    "{name} {fid} θ0={theta0}: stopped {f:?} vs resumed {g:?} ({dth}°)"
                );
                // And the stop matters: a pin that keeps moving mostly ends elsewhere.
                let kept = first.pose_final;
                if ang_diff_deg(kept.theta_rad.to_degrees(), f.theta_rad.to_degrees()) > 0.1
                    || (kept.y - f.y).abs() > 1e-2 * a
                {
                    differs += 1;
                }
                checked += 1;
            }
        }
    }
    assert!(checked >= 12, "only {checked} cases touched");
    assert!(
        2 * differs >= checked,
        "the stop changed only {differs} of {checked}"
    );
}

/// A trapezoid's acceleration phase resolved into more and more constant-speed pieces converges.
#[test]
fn piecewise_constant_acceleration_converges() {
    let p = poly("tripoly2");
    let m = model(&p);
    let a = p.radius();
    let s = settings(pinfeed::mechanics::Fidelity::Exact, 0.5);
    let pose = Pose::new(0.0, 0.0, 0.3);
    let start = Vec2::new(1.5 * a, 0.15 * a);
    let touch = pin_first_touch(&m, pose, start, 0.0, &PinPath::constant(0.0)).unwrap();
    // The pin speeds up from 0 to w = −0.6 over a travel of a, starting just after it touches.
    let ramp = |n: usize| PinPath::ramp(touch + 0.05 * a, a, -0.6, n).unwrap();
    let th = |n| {
        moving(&m, pose, start, 0.0, &ramp(n), &s)
            .0
            .pose_final
            .theta_rad
    };
    let o = moving(&m, pose, start, 0.0, &ramp(8), &s).0;
    assert!(o.contact && o.status.is_ok(), "{:?}", o.status);
    let fine = th(256);
    let one = (th(1) - fine).abs();
    let errs: Vec<f64> = [2, 8, 32].iter().map(|&n| (th(n) - fine).abs()).collect();
    eprintln!("one piece: {one} rad");
    eprintln!("ramp errors against 256 pieces: {errs:?}");
    assert!(errs[0] > 0.0, "the ramp changes nothing: {errs:?}");
    assert!(errs[1] < errs[0] && errs[2] < errs[1], "{errs:?}");
    assert!(errs[2] < 1e-3, "{errs:?}");
}

/// The line's first-touch query follows the pin's path: a pin that swerves into the part's way
/// touches it, one that swerves out of it does not.
#[test]
fn first_touch_follows_the_path() {
    let p = poly("square");
    let m = model(&p);
    let a = p.radius();
    let pose = Pose::new(0.0, 0.0, 0.0);
    // Starts 3a to the side, far upstream; moves in at w = −1 from travel 1a to 4a.
    let start = Vec2::new(10.0 * a, 3.0 * a);
    let still = PinPath::constant(0.0);
    assert_eq!(pin_first_touch(&m, pose, start, 0.0, &still), None);
    let swerve = PinPath::new(
        0.0,
        vec![Turn { s: a, w: -1.0 }, Turn { s: 4.0 * a, w: 0.0 }],
    )
    .unwrap();
    let s = pin_first_touch(&m, pose, start, 0.0, &swerve).expect("touches");
    // After the swerve the pin runs along y = 0 and meets the square's right side.
    let (o, _) = moving(
        &m,
        pose,
        start,
        0.0,
        &swerve,
        &settings(pinfeed::mechanics::Fidelity::Exact, 0.5),
    );
    assert!(o.contact);
    assert!(
        (o.travel_to_contact - s).abs() < 1e-9 * a,
        "{s} vs {}",
        o.travel_to_contact
    );
    assert!(s > 4.0 * a && s < 10.0 * a);
}
